"""The assessment report a client reads: code checks beside rocking dynamics, per mechanism.

``render_assessment`` turns an assessment document (``workflows.assess.assessment_doc``) into
one self-contained HTML page through a jinja2 template (autoescaped). Page one carries the
project, site, engineer and date and the verdict table (code check linear and nonlinear,
rocking dynamics on the records, pulse-envelope margin, governing mechanism); then one
section per mechanism (constants to 4 significant figures, the check worked out, the
capacity curve against the site spectrum, the envelope with the records' pulses, time
histories at the design scale cropped to the motion); then provenance as tables. Print CSS
keeps a mechanism's section on one page where it fits. ``print_pdf`` prints the page to PDF
with headless Chromium.

A folder given as ``template_dir`` overrides the packaged ``assess.html.j2`` (a firm's
layout); it receives the same context.
"""

from __future__ import annotations

import base64
import datetime
import functools
import math
import platform
import shutil
import subprocess
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Optional

import numpy as np

from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError, RockmechError
from shared_schema.site import SiteFile

from ..core.exact import simulate
from ..core.model import G
from ..workflows.adapter import to_rocking_model
from ..workflows.assess import assessment_doc, site_spectrum
from ..workflows.scaling import mechanism_scale_factor
from .plots import _pyplot, _save_atomic, plain

__all__ = [
    "TEMPLATE_NAME",
    "assess_report",
    "chromium",
    "print_pdf",
    "render_assessment",
    "sig",
]

#: The packaged template (a user folder may hold a file of this name to override it).
TEMPLATE_NAME = "assess.html.j2"
#: Where the packaged templates live.
TEMPLATE_DIR = Path(__file__).resolve().parent / "templates"
#: Time-history crop: seconds kept before the first motion and after the motion dies out.
CROP_BEFORE, CROP_AFTER = 1.0, 3.0
#: A sample counts as motion when |phi/phi_ov| exceeds this fraction of the peak.
MOTION_FRACTION = 1e-3
#: Seconds allowed for Chromium to print a page.
PDF_TIMEOUT_S = 120


def sig(value: Any, digits: int = 4) -> str:
    """Format a number to ``digits`` significant figures ("–" for None or non-finite).

    Examples
    --------
    >>> sig(2.0), sig(0.123456), sig(12345.678), sig(None)
    ('2.000', '0.1235', '1.235e+04', '–')
    """
    if value is None or isinstance(value, str):
        return "–" if value is None else value
    if isinstance(value, bool):
        return "yes" if value else "no"
    x = float(value)
    if not math.isfinite(x):
        return "–"
    if x == 0.0:
        return "0"
    exp = math.floor(math.log10(abs(x)))
    if exp >= 5 or exp < -3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{max(digits - 1 - exp, 0)}f}"


def _embed(draw: Callable[[], Path], caption: str) -> dict[str, str]:
    try:
        path = draw()
    except (ValueError, ArithmeticError, RockmechError) as exc:
        return {"caption": caption, "note": f"not drawn: {exc}"}
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return {"caption": caption, "src": f"data:image/png;base64,{data}"}


def _plot_spectrum(spectrum: Any, path: Path) -> Path:
    plt = _pyplot()
    t = np.linspace(0.0, 4.0, 401)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.2))
    ax1.plot(t, spectrum.Se(t), color="k", lw=1.2)
    for name in ("T_B", "T_C", "T_D"):
        ax1.axvline(getattr(spectrum, name), color="0.6", ls=":", lw=0.8)
    ax1.set_xlabel("T [s]")
    ax1.set_ylabel("S_e [g]")
    ax1.set_title("elastic acceleration spectrum (5 %)")
    ax1.grid(alpha=0.3)
    ax2.plot(t, spectrum.SDe(t), color="k", lw=1.2)
    ax2.set_xlabel("T [s]")
    ax2.set_ylabel("S_De [m]")
    ax2.set_title("elastic displacement spectrum")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    try:
        return _save_atomic(fig, path)
    finally:
        plt.close(fig)


def _plot_capacity(non: dict[str, Any], spectrum: Any, path: Path) -> Path:
    """Capacity curve a*(d*) over the site spectrum in acceleration-displacement form."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    t = np.linspace(0.02, 6.0, 600)
    ax.plot(spectrum.SDe(t), spectrum.Se(t) * G, color="0.5", lw=1.0, label="site spectrum (ADRS)")
    ax.plot(non["curve"]["d_star"], non["curve"]["a_star"], color="k", lw=1.5, label="capacity")
    ax.axvline(non["du_star"], color="tab:blue", ls="--", lw=1, label="d_u* = 0.4 d_0*")
    ax.axvline(non["demand"], color="crimson", ls="--", lw=1, label="demand Δ_d")
    ax.plot([0.0, non["ds_star"]], [0.0, non["as_star"]], color="tab:green", lw=0.8)
    ax.plot([non["ds_star"]], [non["as_star"]], "o", color="tab:green", label="secant (T_s)")
    ax.set_xlim(0.0, 1.15 * max(non["d0_star"], non["demand"]))
    ax.set_ylim(0.0, 1.2 * non["a0_star"])
    ax.set_xlabel("d* [m]")
    ax.set_ylabel("a* [m/s²]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    try:
        return _save_atomic(fig, path)
    finally:
        plt.close(fig)


def _plot_envelope(env: dict[str, Any], path: Path) -> Path:
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    f = np.asarray(env["f_p"], dtype=float)
    a = np.array([np.nan if v is None else v for v in env["a_p_min_g"]], dtype=float)
    ax.loglog(f, a, color="k", lw=1.3, label="overturning envelope a_p,min")
    for p in env.get("pulses", []):
        text = f"{plain(p['record'])} pulse at design scale"
        ax.loglog([p["f_p"]], [p["a_p_g"]], "o", label=text)
    ax.set_xlabel("pulse frequency f_p [Hz]")
    ax.set_ylabel("amplitude [g]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.tight_layout()
    try:
        return _save_atomic(fig, path)
    finally:
        plt.close(fig)


def _crop(t: np.ndarray[Any, Any], ratio: np.ndarray[Any, Any]) -> tuple[float, float]:
    """Return the time window with motion in it, padded."""
    peak = float(np.max(np.abs(ratio))) if ratio.size else 0.0
    if peak == 0.0:
        return float(t[0]), float(t[-1])
    moving = np.nonzero(np.abs(ratio) > MOTION_FRACTION * peak)[0]
    if len(moving) == 0:
        return float(t[0]), float(t[-1])
    lo = max(float(t[0]), float(t[moving[0]]) - CROP_BEFORE)
    hi = min(float(t[-1]), float(t[moving[-1]]) + CROP_AFTER)
    return lo, hi


def _plot_history(
    label: str, res: Any, motion: Any, scale: float, path: Path
) -> tuple[Path, tuple[float, float]]:
    plt = _pyplot()
    t = np.asarray(res.t, dtype=float)
    ratio = np.asarray(res.ratio, dtype=float)
    lo, hi = _crop(t, ratio)
    fig, (ax, axr) = plt.subplots(
        2, 1, figsize=(9, 4.2), sharex=True, gridspec_kw={"height_ratios": [2, 1]}
    )
    verdict = "overturns" if res.overturned else "survives"
    text = f"{plain(label)}: peak {res.peak_ratio:.4g} ({verdict})"
    ax.plot(t, ratio, color="k", lw=1.0, label=text)
    for level in (1.0, -1.0):
        ax.axhline(level, color="crimson", ls="--", lw=0.8)
    ax.set_ylabel("φ / φ_ov [-]")
    ax.set_ylim(-1.25, 1.25)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    axr.plot(motion.accel.time, scale * motion.accel.acc / G, color="0.3", lw=0.6)
    axr.set_ylabel("ground acc. [g]")
    axr.set_xlabel("time [s]")
    axr.grid(alpha=0.3)
    axr.set_xlim(lo, hi)
    fig.tight_layout()
    try:
        return _save_atomic(fig, path), (lo, hi)
    finally:
        plt.close(fig)


def _history_png(label: str, model: Any, motion: Any, design: float, up: float, path: Path) -> Path:
    """Run one mechanism at ``design × up`` and plot its time history.

    Both happen inside the figure's guard (``_embed``): a run that fails becomes the
    figure's note, not a traceback.
    """
    res = simulate(model, motion.accel, scale=design * up, dense=True)
    return _plot_history(label, res, motion, design, path)[0]


def _history_figures(
    mech: Any, row: dict[str, Any], motions: Sequence[Any], folder: Path
) -> list[dict[str, str]]:
    out: list[dict[str, str]] = []
    try:
        model = to_rocking_model(mech)
    except RockmechError as exc:
        return [{"caption": "time histories", "note": f"not run: {exc}"}]
    for k, (motion, dyn) in enumerate(zip(motions, row.get("dynamics", []))):
        if "scale_factor" not in dyn:
            continue
        design = float(dyn["scale_factor"]["value"])
        caption = f"{mech.id} on {motion.name} at the design scale {sig(design)}"
        try:
            height = mechanism_scale_factor(mech, motion, "eq28")
        except (ValueError, ArithmeticError, RockmechError) as exc:
            out.append({"caption": caption, "note": f"not run: {exc}"})
            continue
        up = 1.0 if height is None else float(height["value"])
        caption += (
            f" × {sig(up)} up the structure (Eq. 28)" if height is not None else ""
        ) + "; time axis cropped to the motion"
        out.append(
            _embed(
                functools.partial(
                    _history_png,
                    mech.id,
                    model,
                    motion,
                    design,
                    up,
                    folder / f"{mech.id}_history_{k}.png",
                ),
                caption,
            )
        )
    return out


def _short(note: str) -> str:
    """Return the first clause of a note, for the verdict table (the section has it all)."""
    if not note:
        return ""
    head, _, rest = note.partition(": ")
    if rest and " " not in head:  # "<field>: <message>": keep the field and the first clause
        return f"{head}: {rest.split(';')[0].split(' (')[0]}"
    return head.split(" (")[0].split(";")[0]


def _verdict_cell(check: dict[str, Any], what: str) -> dict[str, str]:
    if check.get("status") != "ok":
        return {"text": "not run", "cls": "na", "note": _short(check.get("note", ""))}
    ratio = sig(check["capacity_ratio"], 3)
    if check["passes"] is None:
        return {"text": f"incomplete ({what} {ratio})", "cls": "na", "note": _short(check["note"])}
    word = "passes" if check["passes"] else "fails"
    return {
        "text": f"{word} ({what} {ratio})",
        "cls": "ok" if check["passes"] else "ko",
        "note": "",
    }


def _dynamics_cell(row: dict[str, Any]) -> dict[str, str]:
    dyn = row.get("dynamics") or []
    if not dyn:
        return {"text": "not run", "cls": "na", "note": row.get("dynamics_note", "")}
    parts, cls = [], "ok"
    notes = []
    for d in dyn:
        if "runs" not in d:
            parts.append(f"{d['record']}: not run")
            notes.append(_short(d.get("note", "").removeprefix("not run: ")))
            cls = "na"
            continue
        first = d["first_overturning_multiple"]
        state = "survives" if d["survives_design"] else "overturns"
        tail = "no overturning up to ×" + sig(max(r["multiple"] for r in d["runs"]), 3)
        if first is not None:
            tail = f"overturns at ×{sig(first, 3)}"
        parts.append(f"{d['record']}: {state} at design; {tail}")
        if not d["survives_design"]:
            cls = "ko"
    return {"text": "; ".join(parts), "cls": cls, "note": "; ".join(n for n in notes if n)}


def _margin_cell(row: dict[str, Any]) -> dict[str, str]:
    env = row.get("envelope") or {}
    if "note" in env:
        return {"text": "not run", "cls": "na", "note": _short(env["note"])}
    pulses = [p for p in env.get("pulses", []) if p.get("margin") is not None]
    if not pulses:
        return {"text": "–", "cls": "na", "note": "no pulse found in the records"}
    worst = min(pulses, key=lambda p: p["margin"])
    return {
        "text": f"{sig(worst['margin'], 3)} ({worst['record']}, {sig(worst['f_p'], 3)} Hz)",
        "cls": "ok" if worst["margin"] >= 1.0 else "ko",
        "note": "",
    }


def _constants_rows(mech: Any) -> list[list[str]]:
    rows = []
    sides = [("positive", mech.positive)]
    if mech.negative is not None:
        sides.append(("negative", mech.negative))
    for name, s in sides:
        rows.append(
            [
                name,
                sig(s.p_eq),
                sig(s.lam),
                sig(s.phi_ov),
                sig(s.I0),
                sig(s.K),
                sig(s.Q),
                sig(s.phi_cr),
                sig(s.M_F),
            ]
        )
    return rows


def _table_of(mapping: dict[str, Any]) -> list[tuple[str, str]]:
    """Readable key/value rows: no nulls, numbers to 4 figures, lists joined."""
    out = []
    for key, value in mapping.items():
        if value is None:
            continue
        if isinstance(value, (list, tuple)):
            text = ", ".join(sig(v) if isinstance(v, (int, float)) else str(v) for v in value)
        elif isinstance(value, dict):
            text = "; ".join(
                f"{k} = {sig(v) if isinstance(v, float) else v}"
                for k, v in value.items()
                if v is not None
            )
        elif isinstance(value, float):
            text = sig(value)
        else:
            text = str(value)
        out.append((str(key), text))
    return out


def _versions() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for pkg in ("rockmech", "numpy", "scipy", "pydantic", "matplotlib", "jinja2"):
        try:
            out[pkg] = version(pkg)
        except PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def _environment(template_dir: Optional[Path]) -> Any:
    try:
        import jinja2  # the report extra: imported only when a report is rendered
    except ImportError:
        raise InputError(
            "the assessment report needs jinja2: pip install 'rockmech[report]'", "report"
        ) from None
    loaders: list[Any] = []
    if template_dir is not None:
        if not template_dir.is_dir():
            raise InputError(f"not a folder: {template_dir}", "template_dir")
        loaders.append(jinja2.FileSystemLoader(str(template_dir)))
    loaders.append(jinja2.FileSystemLoader(str(TEMPLATE_DIR)))
    env = jinja2.Environment(
        loader=jinja2.ChoiceLoader(loaders),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.filters["sig"] = sig
    return env


def render_assessment(
    doc: dict[str, Any],
    cf: ConstantsFile,
    site: SiteFile,
    motions: Sequence[Any],
    *,
    sources: Sequence[dict[str, Any]] = (),
    options: Optional[dict[str, Any]] = None,
    template_dir: Optional[Path] = None,
) -> str:
    """Render the assessment document as one self-contained HTML page.

    Parameters
    ----------
    doc : dict
        ``workflows.assess.assessment_doc(cf, site, motions, ...)``.
    cf, site, motions
        The inputs of ``doc`` (for the figures).
    sources : sequence of dict
        Inputs' provenance (``report.html.input_source``: role, name, bytes, SHA-256).
    options : dict, optional
        The options the user chose, shown as a table.
    template_dir : Path, optional
        A folder whose ``assess.html.j2`` replaces the packaged template.

    Returns
    -------
    str
        The HTML page.
    """
    env = _environment(template_dir)
    spectrum = site_spectrum(site)
    by_id = {m.id: m for m in cf.mechanisms}
    with tempfile.TemporaryDirectory(prefix="rockmech-assess-") as tmp:
        folder = Path(tmp)
        spectrum_fig = _embed(
            functools.partial(_plot_spectrum, spectrum, folder / "spectrum.png"),
            f"Site spectrum ({doc['site']['code']}): a_g S = {sig(doc['site']['pga_g'])} g",
        )
        sections = []
        verdicts = []
        for row in doc["mechanisms"]:
            mech = by_id[row["id"]]
            non = row["nonlinear"]
            figs = []
            if non.get("status") == "ok":
                figs.append(
                    _embed(
                        functools.partial(
                            _plot_capacity, non, spectrum, folder / f"{row['id']}_capacity.png"
                        ),
                        f"{row['id']}: capacity curve and site spectrum (NTC nonlinear check)",
                    )
                )
            env_doc = row.get("envelope") or {}
            if "a_p_min_g" in env_doc:
                figs.append(
                    _embed(
                        functools.partial(
                            _plot_envelope, env_doc, folder / f"{row['id']}_envelope.png"
                        ),
                        f"{row['id']}: overturning envelope and the records' largest pulses "
                        "at design scale",
                    )
                )
            figs.extend(_history_figures(mech, row, motions, folder))
            cells = {
                "linear": _verdict_cell(row["linear"], "a0*/demand"),
                "nonlinear": _verdict_cell(row["nonlinear"], "du*/demand"),
                "dynamics": _dynamics_cell(row),
                "margin": _margin_cell(row),
            }
            verdicts.append({"row": row, "cells": cells})
            sections.append(
                {
                    "row": row,
                    "mech": mech,
                    "constants": _constants_rows(mech),
                    "figures": figs,
                    "cells": cells,
                }
            )
    project = site.project.model_dump()
    context = {
        "title": project.get("title") or "Seismic assessment of local collapse mechanisms",
        "project": project,
        "generated": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "site": doc["site"],
        "site_rows": _table_of(doc["site"]["params"]),
        "hazard_rows": _table_of(site.hazard.model_dump()),
        "building_rows": _table_of(site.building.model_dump()) if site.building else [],
        "spectrum_figure": spectrum_fig,
        "verdicts": verdicts,
        "sections": sections,
        "governing": doc["governing"],
        "records": doc.get("records", []),
        "multiples": doc.get("multiples", []),
        "sources": list(sources),
        "options_rows": _table_of(options or {}),
        "versions_rows": _table_of(_versions()),
    }
    return str(env.get_template(TEMPLATE_NAME).render(**context))


def assess_report(
    cf: ConstantsFile,
    site: SiteFile,
    motions: Sequence[Any],
    *,
    multiples: Sequence[float] = (0.5, 1.0, 1.5, 2.0),
    sources: Sequence[dict[str, Any]] = (),
    options: Optional[dict[str, Any]] = None,
    template_dir: Optional[Path] = None,
) -> tuple[dict[str, Any], str]:
    """Return the assessment document and its HTML page (for ``rockmech assess`` and REST).

    Parameters
    ----------
    cf, site, motions, multiples
        As ``workflows.assess.assessment_doc``.
    sources, options, template_dir
        As ``render_assessment``.

    Returns
    -------
    (dict, str)
        The JSON-ready document and the HTML page.
    """
    doc = assessment_doc(cf, site, motions, multiples=multiples)
    text = render_assessment(
        doc, cf, site, motions, sources=sources, options=options, template_dir=template_dir
    )
    return doc, text


def chromium() -> Optional[str]:
    """Path of a Chromium executable on this machine, or None."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


def print_pdf(html_path: Path, pdf_path: Path) -> Path:
    """Print an HTML file to PDF with headless Chromium (the page's print CSS applies).

    Raises
    ------
    InputError
        No Chromium on this machine, or Chromium failed.
    """
    exe = chromium()
    if exe is None:
        raise InputError("printing to PDF needs Chromium (Debian: apt-get install chromium)", "pdf")
    pdf_path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rockmech-chromium-") as profile:
        cmd = [
            exe,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            f"--user-data-dir={profile}",
            "--no-pdf-header-footer",
            f"--print-to-pdf={pdf_path}",
            html_path.resolve().as_uri(),
        ]
        try:
            subprocess.run(cmd, check=True, capture_output=True, timeout=PDF_TIMEOUT_S)
        except (subprocess.SubprocessError, OSError) as exc:
            raise InputError(f"Chromium could not print the report: {exc}", "pdf") from None
    if not pdf_path.is_file() or pdf_path.stat().st_size == 0:
        raise InputError("Chromium wrote no PDF", "pdf")
    return pdf_path
