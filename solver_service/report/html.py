"""One self-contained HTML report of a run: constants, envelopes, time histories, spectrum.

The page needs nothing outside itself: the plots are PNG images inside it (``data:`` URIs),
the style sheet is inline, and a few lines of script only record, once the page has loaded,
how many of its plots the browser could decode (``<html data-plots-loaded="k/n">``), which
the tests read back from headless Chromium.

Sections: inputs and their provenance (file names, SHA-256, sizes, the constants' own
provenance, the record's metadata, the analysis options and software versions); the
kinematic constants; the overturning envelopes with the critical bands; with a record, the
record with its elastic spectrum and the time histories of every mechanism at every scale
factor, with every mechanism they leave out and why; and the error estimates of every result.

Units: SI; pulse amplitudes and accelerations in g where the heading says so.

This module renders what ``solver_service.workflows.pages.build_report`` computed (the
documents, the runs and the record's spectrum in a ``ReportContent``) and runs no analysis.
"""

from __future__ import annotations

import base64
import datetime
import functools
import hashlib
import html
import json
import math
import platform
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional, Union

import numpy as np

from shared_schema.atomic import write_atomic
from shared_schema.documents.envelope import EnvelopeDocument, ExactMethod, LibraryMethod
from shared_schema.documents.history import HistoryDocument
from shared_schema.errors import InputError, RockmechError
from shared_schema.paths import PathLike, as_path

from ..core.model import G
from .plots import plot_envelopes, plot_record, plot_time_histories

__all__ = [
    "MAX_TRACES",
    "SPECTRUM_PERIODS",
    "ReportContent",
    "input_source",
    "render_report",
    "write_report",
]

#: Mechanisms drawn per time-history figure (more are split over several figures).
MAX_TRACES = 6
#: Periods of the report's response spectrum [s] (log-spaced: first, last, count).
SPECTRUM_PERIODS = (0.02, 10.0, 150)


@dataclass(frozen=True)
class ReportContent:
    """What the report shows, computed beforehand (``workflows.pages.build_report``).

    Attributes
    ----------
    cf : ConstantsFile
        The mechanisms.
    env : EnvelopeDocument
        The envelope document (``envelope_doc``).
    envelopes : list
        The envelopes it was made from, for the figure.
    motion : GroundMotion, optional
        The record, if any.
    hist : HistoryDocument, optional
        The time-history document (``history_doc``), with a record.
    top : float
        The largest scale factor [-]: the time histories drawn.
    runs : list of (str, RockingResult)
        The runs at ``top`` with their time series, labelled.
    runs_error : str, optional
        Why the runs could not be made again (then ``runs`` is empty).
    spectrum : Spectrum, optional
        The record's 5 % elastic response spectrum at ``SPECTRUM_PERIODS``.
    pulses : list of ExtractedPulse
        The record's largest sine pulse (or none).
    record_error : Exception, optional
        Why the record's spectrum or pulse could not be found (the figure says so).
    spectral : list of (str, float, float)
        Per mechanism with an amplification: its id, the structure's period T_n [s] and
        the record's S_a(T_n) [g].
    """

    cf: Any
    env: EnvelopeDocument
    envelopes: Sequence[Any]
    motion: Optional[Any] = None
    hist: Optional[HistoryDocument] = None
    top: float = 1.0
    runs: Sequence[tuple[str, Any]] = ()
    runs_error: Optional[str] = None
    spectrum: Optional[Any] = None
    pulses: Sequence[Any] = ()
    record_error: Optional[Exception] = None
    spectral: Sequence[tuple[str, float, float]] = field(default_factory=list)


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:2rem auto;
max-width:1100px;color:#222;line-height:1.4;padding:0 1rem}
h1{font-size:1.6rem;margin-bottom:.2rem}h2{border-bottom:1px solid #ccc;padding-bottom:.2rem;
margin-top:2rem}table{border-collapse:collapse;margin:.6rem 0;font-size:.85rem}
th,td{border:1px solid #ddd;padding:.25rem .5rem;text-align:right}
th{background:#f3f3f3}td.l,th.l{text-align:left}img{max-width:100%;height:auto;
border:1px solid #eee}figure{margin:1rem 0}figcaption{font-size:.85rem;color:#555}
.yes{color:#b00020;font-weight:600}.skipped{border-left:4px solid #b26a00;padding:.1rem .8rem;
background:#fff8e6}.muted{color:#666;font-size:.85rem}
pre{background:#f7f7f7;padding:.5rem;overflow:auto;font-size:.8rem}
"""

_SCRIPT = """
window.addEventListener('load', function () {
  var imgs = document.querySelectorAll('img.plot');
  var ok = 0;
  imgs.forEach(function (im) { if (im.complete && im.naturalWidth > 0) { ok += 1; } });
  document.documentElement.setAttribute('data-plots-loaded', ok + '/' + imgs.length);
});
"""


def input_source(role: str, name: str, data: bytes) -> dict[str, Any]:
    """Describe one input for the provenance table: role, name, size and SHA-256."""
    return {
        "role": role,
        "name": name,
        "bytes": len(data),
        "sha256": hashlib.sha256(data).hexdigest(),
    }


def _e(value: Any) -> str:
    return html.escape(str(value), quote=True)


def _num(value: Any, fmt: str = ".4g") -> str:
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return format(float(value), fmt) if math.isfinite(value) else "–"
    return _e(value)


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]], left: int = 1) -> str:
    head = "".join(
        f'<th class="l">{_e(h)}</th>' if i < left else f"<th>{_e(h)}</th>"
        for i, h in enumerate(headers)
    )
    body = "".join(
        "<tr>"
        + "".join(
            f'<td class="l">{c}</td>' if i < left else f"<td>{c}</td>" for i, c in enumerate(r)
        )
        + "</tr>"
        for r in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _figure(draw: Callable[[], Path], caption: str) -> str:
    """Draw a plot and embed it; on degenerate data say why there is no plot."""
    try:
        path = draw()
    except (ValueError, ArithmeticError, RockmechError) as exc:  # e.g. overflow on a log axis
        return (
            f"<p class='muted'>{_e(caption)}: not drawn ({_e(type(exc).__name__)}: {_e(exc)})</p>"
        )
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return (
        f'<figure><img class="plot" alt="{_e(caption)}" src="data:image/png;base64,{data}">'
        f"<figcaption>{_e(caption)}</figcaption></figure>"
    )


def _versions() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for pkg in ("rockmech", "numpy", "scipy", "numba", "pydantic", "matplotlib"):
        try:
            out[pkg] = version(pkg)
        except PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def _constants_section(cf: Any) -> str:
    rows = []
    for m in cf.mechanisms:
        sides = [("+", m.positive)] + ([("−", m.negative)] if m.negative is not None else [])
        for sign, side in sides:
            amp = m.amplification
            rows.append(
                [
                    _e(m.id) + (f" ({sign})" if m.negative is not None else ""),
                    _e(m.name),
                    _e(m.typology),
                    _e(m.rocking),
                    _num(side.p_eq),
                    _num(side.lam),
                    _num(side.phi_ov),
                    _num(m.eta),
                    _e(m.eta_source or "–"),
                    "–" if amp is None else f"{amp.f_n:g} Hz, h {amp.h:g} m, h_e {amp.h_e:g} m",
                ]
            )
    headers = ["id", "name", "typology", "rocking", "p_eq [rad/s]", "λ [-]", "φ_ov [rad]"]
    headers += ["η [-]", "η source", "amplification"]
    return "<h2>Kinematic constants</h2>" + _table(headers, rows, left=4)


def _envelope_section(doc: EnvelopeDocument, figure: str) -> str:
    bands = [[_e(b.mechanism), _num(b.f_min), _num(b.f_max)] for b in doc.critical]
    method = doc.method
    if isinstance(method, ExactMethod):
        how = (
            "Exact boundaries at every frequency: each amplitude simulated with the exact "
            "integrator and the exact overturning criterion; changes of outcome bisected to a "
            f"relative 1e-6 (search limit A_max = {method.a_max}). Each band edge "
            "lies between the last frequency of one band and the first of the next (hatched)."
        )
    else:
        bound = method.bound
        how = (
            f"Fast mode: library {_e(method.library_version or '')} "
            f"(generated {_e(method.generated or '')}), "
            f"{_e(method.interpolation)}; {_e(method.exact_points)} "
            "points computed exactly. Never above the exact value (to "
            f"{_num(bound.above_exact)}), at most "
            f"{_num(100 * bound.below_exact)} % below it; band edges within a "
            f"factor {_num(method.edge_ratio)} in frequency (hatched)."
        )
    return (
        "<h2>Overturning envelopes and critical mechanism</h2>"
        f"{figure}<p class='muted'>{how}</p>"
        "<h3>Critical bands (governing mechanism per pulse frequency)</h3>"
        + _table(["mechanism", "f_min [Hz]", "f_max [Hz]"], bands)
    )


def _history_table(doc: HistoryDocument) -> str:
    """Every mechanism at every scale; the scale factors up the structure, when used."""
    disp = doc.displacement
    headers = ["mechanism", "scale", "effective scale", "peak |φ|/φ_ov", "overturned"]
    headers += ["t_overturn [s]", "impacts", "error estimate", "status"]
    if disp is not None:
        headers.append(f"peak displacement at {disp.height_m:g} m [m]")
    rows = []
    for r in doc.results:
        verdict = '<span class="yes">yes</span>' if r.overturned else "no"
        given = "effective_scale" in r.model_fields_set  # as the JSON holds it
        row = [
            _e(r.mechanism),
            _num(r.scale),
            _num(r.effective_scale if given else r.scale),
            _num(r.peak_ratio),
            verdict,
            _num(r.t_overturn),
            _num(r.n_impacts),
            _num(r.error_estimate, ".1e"),
            _e(r.message),
        ]
        if disp is not None:
            row.append(_num(r.peak_displacement_m))
        rows.append(row)
    out = _table(headers, rows)
    factors = doc.scale_factors or {}
    if factors:
        sf_rows = [
            [
                _e(k),
                _num(v.value),
                _e(v.method),
                _e(v.formula),
                _e(json.dumps(v.to_dict()["inputs"])),
            ]
            for k, v in factors.items()
        ]
        out += "<h3>Scale factors up the structure</h3>" + _table(
            ["mechanism", "SF [-]", "method", "formula", "inputs"], sf_rows, left=1
        )
    return out


def _skipped_section(doc: HistoryDocument) -> str:
    """Every mechanism the time histories left out, and why (``doc.skipped``; #25)."""
    skipped = doc.skipped or []
    if not skipped:
        return ""
    items = "".join(
        f"<li><strong>{_e(s.mechanism)}</strong> skipped: {_e(s.reason)}</li>" for s in skipped
    )
    return (
        f"<div class='skipped'><p>{len(skipped)} mechanism(s) left out of the time histories "
        f"(their envelopes and constants are above):</p><ul>{items}</ul></div>"
    )


def _history_figures(content: ReportContent, folder: Path) -> list[str]:
    """Figures of the time histories at the largest scale, or a note on why there are none."""
    top, motion = content.top, content.motion
    assert motion is not None
    caption = f"φ/φ_ov against time at scale {top:g}"
    if content.runs_error is not None:
        return [f"<p class='muted'>{_e(caption)}: not drawn ({_e(content.runs_error)})</p>"]
    runs = list(content.runs)
    figures = []
    for k in range(0, len(runs), MAX_TRACES):
        part = runs[k : k + MAX_TRACES]
        names = ", ".join(label for label, _ in part)
        figures.append(
            _figure(
                functools.partial(
                    plot_time_histories,
                    part,
                    folder / f"history_{k}.png",
                    record_t=motion.accel.time,
                    record_a_g=top * motion.accel.acc / G,
                    title=f"{motion.name} × {top:g}",
                ),
                f"{caption}: {names}",
            )
        )
    return figures


def _raise(exc: Exception) -> Path:
    raise exc


def _record_section(content: ReportContent, folder: Path) -> str:
    motion = content.motion
    assert motion is not None
    if content.record_error is not None:
        draw: Callable[[], Path] = functools.partial(_raise, content.record_error)
    else:
        draw = functools.partial(
            plot_record,
            motion,
            folder / "record.png",
            spectrum=content.spectrum,
            pulses=content.pulses,
        )
    rows = [
        [_e(mech_id), _num(t_n), _num(sa), _num(sa / motion.pga_g)]
        for mech_id, t_n, sa in content.spectral
    ]
    table = ""
    if rows:
        table = "<h3>Spectral acceleration at the supporting structure's period</h3>" + _table(
            ["mechanism", "T_n [s]", "S_a(T_n) [g]", "S_a/PGA [-]"], rows
        )
    return (
        "<h2>Record and elastic response spectrum</h2>"
        + _figure(draw, f"{motion.name}: record, largest sine pulse and 5 % spectrum (exact)")
        + table
    )


def _provenance(
    cf: Any,
    motion: Optional[Any],
    sources: Sequence[dict[str, Any]],
    request: dict[str, Any],
    env_method: Union[ExactMethod, LibraryMethod],
) -> str:
    src_rows = [
        [_e(s["role"]), _e(s["name"]), _num(s["bytes"]), f"<code>{_e(s['sha256'])}</code>"]
        for s in sources
    ]
    parts = ["<h2>Inputs and provenance</h2>"]
    parts.append(_table(["input", "name", "bytes", "SHA-256"], src_rows, left=2))
    opts = [[_e(k), _e(json.dumps(v))] for k, v in request.items()]
    opts.append(["envelope method", _e(json.dumps(env_method.to_dict()))])
    parts.append("<h3>Analysis options</h3>" + _table(["option", "value"], opts, left=2))
    mech = []
    for m in cf.mechanisms:
        prov = json.dumps(m.provenance or {}, indent=1, sort_keys=True)
        mech.append([_e(m.id), _e(m.eta_source or "–"), f"<pre>{_e(prov)}</pre>"])
    parts.append(
        "<h3>Constants file</h3>"
        f"<p>schema version {_e(cf.schema_version)}, {len(cf.mechanisms)} mechanism(s)</p>"
        + _table(["mechanism", "η source", "provenance"], mech, left=3)
    )
    if motion is not None:
        meta = {"name": motion.name, "dt_s": motion.dt, "pga_g": motion.pga_g}
        meta.update({"duration_s": motion.duration, **motion.metadata})
        rows = [[_e(k), _e(v)] for k, v in meta.items()]
        parts.append("<h3>Record</h3>" + _table(["field", "value"], rows, left=2))
    sw = [[_e(k), _e(v)] for k, v in _versions().items()]
    parts.append("<h3>Software</h3>" + _table(["package", "version"], sw, left=2))
    return "".join(parts)


def _accuracy(hist: Optional[HistoryDocument]) -> str:
    items = [
        "<li>Time histories and pulses: exact closed-form integration between impacts, impacts "
        "located to machine precision; each result carries the estimated absolute error of "
        "its peak |φ|/φ_ov (an estimate of order 0.1 or more means the peak is not "
        "resolved).</li>",
        "<li>Response spectrum: exact for a record linear between samples (Nigam–Jennings); "
        "only roundoff remains.</li>",
    ]
    if hist is not None and hist.results:
        # as the JSON holds them: a value not finite is null there, and left out here
        errs = [
            r.error_estimate
            for r in hist.results
            if r.error_estimate is not None and math.isfinite(r.error_estimate)
        ]
        worst = max(errs) if errs else float("nan")
        items.append(
            f"<li>Largest error estimate in the time histories: {_num(worst, '.1e')}.</li>"
        )
    return "<h2>Error estimates</h2><ul>" + "".join(items) + "</ul>"


def render_report(
    content: ReportContent,
    *,
    title: str = "",
    sources: Sequence[dict[str, Any]] = (),
    request: Optional[dict[str, Any]] = None,
) -> str:
    """Return the HTML page of what a report shows.

    Parameters
    ----------
    content : ReportContent
        The documents, runs and record spectrum (``workflows.pages.build_report``).
    title : str
        Report title.
    sources : sequence of dict
        Inputs (``input_source``) for the provenance table.
    request : dict, optional
        Analysis options, shown as given.

    Returns
    -------
    str
        The page.
    """
    cf, env, motion, hist = content.cf, content.env, content.motion, content.hist
    title = title or "rockmech report"
    with tempfile.TemporaryDirectory(prefix="rockmech-report-") as tmp:
        folder = Path(tmp)
        draw = functools.partial(
            plot_envelopes,
            content.envelopes,
            [b.to_dict() for b in env.critical],
            folder / "envelope.png",
            labels={m.id: f"{m.id}: {m.name}" for m in cf.mechanisms},
            title="Minimum overturning one-sine pulse (ground level)",
        )
        body = [
            _constants_section(cf),
            _envelope_section(
                env, _figure(draw, "Envelopes a_p,min(f_p) with the critical bands shaded")
            ),
        ]
        if motion is not None and hist is not None:
            body.append(_record_section(content, folder))
            body.append(_history_section(hist, _history_figures(content, folder)))
        body.append(_accuracy(hist))
        body.append(_provenance(cf, motion, sources, dict(request or {}), env.method))
    when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return (
        '<!DOCTYPE html>\n<html lang="en" data-plots-loaded="pending"><head>'
        '<meta charset="utf-8"><meta name="viewport" content="width=device-width">'
        f"<title>{_e(title)}</title><style>{_CSS}</style><script>{_SCRIPT}</script></head>"
        f"<body><h1>{_e(title)}</h1>"
        f"<p class='muted'>rockmech {_e(_versions()['rockmech'])}, generated {when}. "
        "SI units; accelerations in g where stated.</p>" + "".join(body) + "</body></html>\n"
    )


def _history_section(hist: HistoryDocument, figures: list[str]) -> str:
    return (
        "<h2>Time histories</h2>"
        f"<p>criterion: {_e(hist.criterion)}; method: {_e(hist.method)}"
        + (
            f"; scale factor up the structure: {_e(hist.scale_factor_method)}"
            if hist.scale_factor_method is not None
            else ""
        )
        + "</p>"
        + _skipped_section(hist)
        + "".join(figures)
        + _history_table(hist)
    )


def write_report(page: str, path: PathLike) -> Path:
    """Write the report atomically and return its path.

    Parameters
    ----------
    page : str
        The page (``build_report``).
    path : str or os.PathLike
        The HTML file (its folder is created if missing); it is replaced atomically.
    text : str
        The page (``render_report``, ``workflows.pages.build_report``).

    Raises
    ------
    InputError
        ``page`` is not a ``str`` (field ``page``), ``path`` is not a ``str`` or
        ``os.PathLike``, is a folder, or cannot be written (field ``path``, naming it).
        The page comes first: a ``path`` that holds markup or a line break is refused as a
        page given in its place, never written as a file of that name.
    """
    if not isinstance(page, str):
        raise InputError(f"must be the HTML page (a str), got {type(page).__name__}", "page")
    if isinstance(path, str) and ("<" in path or "\n" in path):
        raise InputError(
            "looks like an HTML page, not a file name; the page comes first: "
            "write_report(page, path)",
            "path",
        )
    target = as_path(path, "path")
    if target.is_dir():
        raise InputError(f"is a folder, not a file: {target}", "path")
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(target, page)
    except OSError as exc:
        raise InputError(f"cannot write {target}: {exc.strerror or exc}", "path") from None
    return target
