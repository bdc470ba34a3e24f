"""The assessment report a client reads: code checks beside rocking dynamics, per mechanism.

``render_assessment`` turns an assessment document (``workflows.assess.assessment_doc``),
the site spectrum and the time histories run for it (``workflows.pages.assess_report``
computes them; this module runs no analysis) into one self-contained HTML page through a
jinja2 template (autoescaped). Page one carries the project, site, engineer and date and the
verdict table (code check linear and nonlinear, rocking dynamics on the records, pulse-
envelope margin, governing mechanism); then one section per mechanism (constants to 4
significant figures, the check worked out, the capacity curve against the site spectrum, the
envelope with the records' pulses, time histories at the design scale cropped to the
motion); then provenance as tables. Print CSS keeps a mechanism's section on one page where
it fits. ``print_pdf`` prints the page to PDF with headless Chromium.

With a retrofit (``rockmech assess --retrofit``: a retrofit spec, or the ``retrofit.json``
``rockmech retrofit`` wrote), page one ends with the retrofit table: per mechanism the tie
that makes it pass (bars, diameter, grade, height, ``T*``, the governing criterion) and its
least ``a_g,X/a_g`` before and with the tie, a mark where the records raise the demand above
the spectrum's the tie was sized on; a section after page one gives one sentence each, the
steel and the anchorage's source. The document then holds the retrofit under ``retrofit``.

A folder given as ``template_dir`` overrides the packaged ``assess.html.j2`` (a firm's
layout); it receives the same context.
"""

from __future__ import annotations

import base64
import datetime
import functools
import math
import platform
import shlex
import shutil
import subprocess
import tempfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional, Union

import numpy as np

from shared_schema.constants import ConstantsFile
from shared_schema.documents.assess import AssessDocument
from shared_schema.documents.check import (
    AssessEnvelope,
    CheckMechanism,
    CheckSite,
    LimitStateCheck,
    Linear2009,
    Linear2019,
    LinearCheck,
    MechanismVerdict,
    NoCurve2019,
    Nonlinear2009,
    Nonlinear2019,
    NonlinearCheck,
    NotRun,
    PulseMargin,
    Ties,
)
from shared_schema.errors import InputError, RockmechError
from shared_schema.retrofit import RetrofitDoc
from shared_schema.site import SiteFile
from shared_schema.version import __version__

from ..core.model import G
from .labels import least_margin_pulse, ratio_label
from .plots import load_pyplot, plain, write_figure_atomic
from .retrofit import records_notes, retrofit_summary

__all__ = [
    "TEMPLATE_NAME",
    "HistoryRun",
    "check_template",
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


@dataclass(frozen=True)
class HistoryRun:
    """One time history of a mechanism on a record at its design scale, for its figure.

    Attributes
    ----------
    caption : str
        The figure's caption.
    label : str
        The mechanism's id (the trace's label).
    motion : GroundMotion, optional
        The record.
    scale : float
        The design scale factor on the record [-] (the ground trace drawn).
    result : RockingResult, optional
        The run with its time series (``dense``); None where it was not run.
    note : str, optional
        Why there is no figure (``not run: ...``, ``not drawn: ...``).
    file : str
        The figure's file name.
    """

    caption: str
    label: str = ""
    motion: Optional[Any] = None
    scale: float = 1.0
    result: Optional[Any] = None
    note: Optional[str] = None
    file: str = "history.png"


def sig(value: Any, digits: int = 4) -> str:
    """Format a number to ``digits`` significant figures ("–" for None or non-finite).

    A number below 1e5 keeps all its integer digits (a mass of 72 522 kg reads so, not as
    7.252e+04); from 1e5 up, and below 1e-3, it is written with an exponent.

    Examples
    --------
    >>> sig(2.0), sig(0.123456), sig(12345.678), sig(123456.7), sig(None)
    ('2.000', '0.1235', '12346', '1.235e+05', '–')
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
    plt = load_pyplot()
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
        return write_figure_atomic(fig, path)
    finally:
        plt.close(fig)


def _plot_limit_state(ax: Any, name: str, color: str, ls: LimitStateCheck) -> float:
    """Draw one limit state of the 2019 check on the ADRS axes; return its demand's ``a``.

    Parameters
    ----------
    ax : matplotlib Axes
        The capacity curve's axes (d [m], a [m/s²]).
    name : str
        ``"SLV"`` or ``"SLC"``.
    color : str
        The limit state's colour.
    ls : LimitStateCheck
        The check's limit state (``adrs``, ``T_<name>``, ``demand_code``,
        ``demand_records``, ``d``, ``a``, ``capacity_ratio``, ``passes``...).

    Returns
    -------
    float
        The code demand's acceleration ``d (2π/T)²`` [m/s²] (for the axes' top).
    """
    word = _word(ls.passes)
    ax.plot(
        ls.adrs.d,
        ls.adrs.a,
        color=color,
        lw=0.9,
        alpha=0.7,
        label=f"{name} demand spectrum (ξ = {ls.xi_percent:g} %)",
    )
    t = _period(ls, name)
    demand_code = _given(ls.demand_code)
    a_dem: float = demand_code * (2.0 * math.pi / t) ** 2
    ax.plot(
        [demand_code],
        [a_dem],
        "o",
        color=color,
        label=f"{name} code demand {demand_code:.3g} m at T = {t:.3g} s",
    )
    if ls.demand_records is not None:
        ax.plot(
            [ls.demand_records],
            [a_dem],
            "x",
            color=color,
            label=f"{name} records' demand {ls.demand_records:.3g} m",
        )
    bound = " (a_g,SLD bound)" if ls.lower_bound_applied else ""
    ax.axvline(
        ls.d,
        color=color,
        ls="--",
        lw=1.0,
        label=f"d_{name} = {ls.d:.3g} m: {word}, ratio {ls.capacity_ratio:.3g}{bound}",
    )
    ax.plot([ls.d], [ls.a], "s", color=color, ms=5)
    return a_dem


def _given(value: Optional[float]) -> float:
    """Return a figure a drawing needs; a check without it cannot be drawn (its note says so)."""
    if value is None:
        raise ValueError("a figure of the check is missing")
    return float(value)


def _period(ls: LimitStateCheck, name: str) -> float:
    """Return the secant period of a limit state, ``T_SLV`` or ``T_SLC`` [s]."""
    return _given(ls.T_SLV if name == "SLV" else ls.T_SLC)


def _plot_linear(ax: Any, lin: LinearCheck) -> list[float]:
    """Draw the linear check's capacity ``a0*`` and its demand; return both (or none) [m/s²]."""
    if isinstance(lin, NotRun):
        return []
    a0_star, demand = _given(lin.a0_star), _given(lin.demand)
    ax.axhline(
        a0_star,
        color="tab:blue",
        lw=0.9,
        label=f"linear: a0* = {a0_star:.3g} m/s²",
    )
    ax.axhline(
        demand,
        color="tab:blue",
        ls=":",
        lw=1.0,
        label=f"linear demand/q = {demand:.3g}: {_word(lin.passes)}",
    )
    return [a0_star, demand]


def _plot_2009(ax: Any, non: Nonlinear2009, spectrum: Any) -> None:
    """Draw the 2009 check's forms: the 5 % site spectrum, ``d_u*`` and the demand."""
    t = np.linspace(0.02, 6.0, 600)
    ax.plot(spectrum.SDe(t), spectrum.Se(t) * G, color="0.5", lw=1.0, label="site spectrum (5 %)")
    ax.axvline(non.du_star, color="tab:blue", ls="--", lw=1, label="d_u* = 0.4 d_0* (2009)")
    ax.axvline(non.demand, color="crimson", ls="--", lw=1, label=f"demand: {_word(non.passes)}")
    ax.set_xlim(0.0, 1.15 * max(_given(non.d0_star), _given(non.demand)))
    ax.set_ylim(0.0, 1.2 * _given(non.a0_star))


def _plot_2019(ax: Any, lin: LinearCheck, non: Nonlinear2019) -> None:
    """Draw the 2019 check's limit states and the linear check; set the axes' limits."""
    tops = [max(_given(v) for v in non.curve.a)]
    for name, color, ls in (("SLV", "crimson", non.SLV), ("SLC", "tab:purple", non.SLC)):
        tops.append(_plot_limit_state(ax, name, color, ls))
    tops += _plot_linear(ax, lin)
    d0, slc_d = _given(non.d0), _given(non.SLC.d)
    d_top = max(d0, _given(non.SLV.demand), _given(non.SLC.demand), slc_d)
    d_top = min(d_top, 3.0 * max(d0, slc_d))
    ax.set_xlim(0.0, 1.2 * d_top)
    ax.set_ylim(0.0, 1.25 * max(tops))


def _plot_capacity(
    lin: LinearCheck, non: Union[Nonlinear2019, Nonlinear2009], spectrum: Any, path: Path
) -> Path:
    """Plot the checks on the capacity curve in ADRS form: capacity, demand, verdict of each.

    Circolare 2019: the capacity curve ``a(d)``; the demand spectra of the SLV and SLC
    (the mechanism's damping, at its height) with their demand points at ``T_SLV`` and
    ``T_SLC``; the limit displacements ``d_SLV`` and ``d_SLC``; the linear check's capacity
    ``a0*`` against its demand ``demand_activation / q``. The legend gives each verdict.
    The 2009 forms: the curve, ``d_u*`` and the demand over the 5 % site spectrum.
    """
    plt = load_pyplot()
    fig, ax = plt.subplots(figsize=(6.8, 3.9))
    if isinstance(non, Nonlinear2019):
        ax.plot(non.curve.d, non.curve.a, color="k", lw=1.6, label="capacity a(d)")
        _plot_2019(ax, lin, non)
    else:
        ax.plot(non.curve.d_star, non.curve.a_star, color="k", lw=1.6, label="capacity a(d)")
        _plot_2009(ax, non, spectrum)
    ax.set_xlabel("d [m]")
    ax.set_ylabel("a [m/s²]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6, loc="upper right")
    fig.tight_layout()
    try:
        return write_figure_atomic(fig, path)
    finally:
        plt.close(fig)


def _word(passes: Any) -> str:
    return {True: "passes", False: "fails", None: "not evaluated"}[passes]


def _row(label: str, value: Any, unit: str, clause: str) -> dict[str, str]:
    return {"label": label, "value": sig(value), "unit": unit, "clause": clause}


def _add(rows: list[dict[str, str]], label: str, value: Any, unit: str, clause: str) -> None:
    """Append the row of a figure the check gives (none where it is absent or null)."""
    if value is not None:
        rows.append(_row(label, value, unit, clause))


def _check_rows(check: Union[LinearCheck, NonlinearCheck]) -> list[dict[str, str]]:
    """Return the worked-out rows of a check: quantity, value, unit and the clause of each."""
    if isinstance(check, NotRun):
        return []
    if isinstance(check, (Linear2009, Nonlinear2009)):
        return _rows_2009(check)
    if isinstance(check, NoCurve2019):  # no curve: the static forces alone overturn it
        return _ties_rows(check.ties)
    cl = check.clauses
    nonlinear = isinstance(check, Nonlinear2019)
    rows: list[dict[str, str]] = []
    _add(rows, "α0 of the capacity curve" if nonlinear else "α0", check.alpha0, "-",
         cl.get("alpha0", ""))  # fmt: skip
    if isinstance(check, Linear2019):
        _add(rows, "M*", check.M_star, "kg", cl.get("M_star", ""))
    _add(rows, "e*", check.e_star, "-", cl.get("e_star", ""))
    _add(rows, "FC", check.FC, "-", cl.get("FC", ""))
    _add(rows, "a0* at activation" if nonlinear else "a0* = α0 g/(e* FC)", check.a0_star,
         "m/s²", cl.get("a0_star", ""))  # fmt: skip
    if check.free_standing:
        rows.extend(_free_standing_rows(check))
    units = {"T1": "s", "T_k": "s", "xi_k_percent": "%", "a_Z_g": "g", "Se_Tk_g": "g"}
    floor = {} if check.floor is None else check.floor.model_dump(exclude_unset=True)
    for key, value in floor.items():  # the floor's terms, as the document gives them
        rows.append(_row(f"floor {key}", value, units.get(key, "-"), cl.get(f"floor.{key}", "")))
    if isinstance(check, Linear2019):
        return rows + _linear_rows(check)
    rows.extend(_ties_rows(check.ties))
    _add(rows, "J/S (d per unit rotation)", check.d_per_rad, "m/rad", cl.get("d_per_rad", ""))
    _add(rows, "φ0", check.phi0, "rad", cl.get("phi0", ""))
    _add(rows, "d0", check.d0, "m", cl.get("d0", ""))
    rows.extend(_limit_state_rows("SLV", check.SLV))
    rows.extend(_limit_state_rows("SLC", check.SLC))
    return rows


def _free_standing_rows(check: Union[Linear2019, Nonlinear2019]) -> list[dict[str, str]]:
    """Return the rows of a free-standing element's figures ([C8.7.1.7]): κ, L, t, λ, ..."""
    cl = check.clauses
    rows: list[dict[str, str]] = []
    for label, value, key, unit in (
        ("κ", check.kappa, "kappa", "-"),
        ("L", check.L, "L", "m"),
        ("t", check.t, "t", "m"),
        ("λ = L/t", check.lambda_, "lambda", "-"),
        ("W", check.W, "W", "N/m³"),
        ("E", check.E, "E", "Pa"),
        ("T0", check.T0, "T0", "s"),
    ):
        _add(rows, label, value, unit, cl.get(key, ""))
    if isinstance(check, Nonlinear2019):
        _add(rows, "d_y", check.d_y, "m", cl.get("d_y", ""))
        _add(rows, "a_y", check.a_y, "m/s²", cl.get("a_y", ""))
    return rows


def _linear_rows(check: Linear2019) -> list[dict[str, str]]:
    """Return the linear check's rows after the common ones: q, the demand and the ratio."""
    cl = check.clauses
    rows: list[dict[str, str]] = []
    _add(rows, "q", check.q, "-", cl.get("q", ""))
    rows.append(
        _row(
            "activation demand",
            check.demand_activation,
            "m/s²",
            f"{cl.get('demand_activation', '')}; {check.demand_rule}",
        )
    )
    _add(rows, "a_g,SLD", check.a_g_SLD, "g", cl.get("a_g_SLD", ""))
    _add(rows, "a_g,SLV = q a_g,SLD", check.a_g_SLV, "g", cl.get("a_g_SLV", ""))
    _add(rows, "a_g (SLV hazard)", check.a_g, "g", cl.get("a_g", ""))
    _add(rows, "a_g,SLV / a_g", check.capacity_ratio, "-", cl.get("capacity_ratio", ""))
    return rows


def _ties_rows(ties: Ties) -> list[dict[str, str]]:
    """Return the rows of a nonlinear check's ties: their treatment and φ0 with and without."""
    if not ties.present:
        return []
    rows = [{"label": "ties", "value": ties.treatment or "", "unit": "", "clause": ties.rule or ""}]
    for label, value in (("φ0 with the ties", ties.phi0_with), ("φ0 without", ties.phi0_without)):
        rows.append(_row(label, value, "rad", "theory §1.7 Eq. 6; C8.7.1.2.1.6"))
    return rows


def _limit_state_rows(name: str, ls: LimitStateCheck) -> list[dict[str, str]]:
    """Return the rows of one limit state (SLV or SLC) of a nonlinear check."""
    lcl = ls.clauses
    rows = [_row(f"d_{name}", ls.d, "m", f"{lcl.get('d', '')}: {ls.d_rule}")]
    _add(rows, f"a(d_{name})", ls.a, "m/s²", lcl.get("a", ""))
    period = ls.T_SLV if name == "SLV" else ls.T_SLC
    _add(rows, f"T_{name}", period, "s", lcl.get(f"T_{name}", ""))
    _add(rows, f"ξ ({name})", ls.xi_percent, "%", lcl.get("xi_percent", ""))
    rows.append(
        _row(
            f"demand {name} (code)",
            ls.demand_code,
            "m",
            f"{lcl.get('demand_code', '')}: {ls.demand_rule}",
        )
    )
    _add(rows, f"demand {name} (records)", ls.demand_records, "m", lcl.get("demand_records", ""))
    _add(rows, f"a_g,{name} (capacity)", ls.a_g_capacity, "g", lcl.get("a_g_capacity", ""))
    _add(rows, "a_g,SLD (lower bound)", ls.a_g_SLD, "g", lcl.get("a_g_SLD", ""))
    _add(rows, f"a_g ({name} hazard)", ls.a_g, "g", lcl.get("a_g", ""))
    _add(rows, f"a_g,{name} / a_g", ls.capacity_ratio, "-", lcl.get("capacity_ratio", ""))
    return rows


def _rows_2009(check: Union[Linear2009, Nonlinear2009]) -> list[dict[str, str]]:
    src = "Circolare 617/2009 C8A.4 (2009 forms, from memory; for comparison)"
    figures: list[tuple[str, Optional[float], str]]
    if isinstance(check, Linear2009):
        per = "m/s²"
        figures = [
            ("α0", check.alpha0, "-"),
            ("M*", check.M_star, "kg"),
            ("e*", check.e_star, "-"),
            ("a0*", check.a0_star, "m/s²"),
            ("demand at ground", check.demand_ground, per),
        ]
    else:
        per = "m"
        figures = [
            ("e*", check.e_star, "-"),
            ("a0*", check.a0_star, "m/s²"),
            ("demand at ground", check.demand_ground, per),
            ("d0*", check.d0_star, "m"),
            ("du* = 0.4 d0*", check.du_star, "m"),
            ("Ts", check.Ts, "s"),
        ]
    figures += [
        ("demand at height", check.demand_height, per),
        ("demand", check.demand, per),
        ("capacity/demand", check.capacity_ratio, "-"),
    ]
    rows: list[dict[str, str]] = []
    for label, value, unit in figures:
        _add(rows, label, value, unit, src)
    return rows


def _plot_envelope(env: AssessEnvelope, path: Path) -> Path:
    plt = load_pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    f = np.asarray(env.f_p, dtype=float)
    a = np.array([np.nan if v is None else v for v in env.a_p_min_g or []], dtype=float)
    ax.loglog(f, a, color="k", lw=1.3, label="overturning envelope a_p,min")
    for p in env.pulses or []:
        text = f"{plain(p.record)} pulse at design scale"
        ax.loglog([p.f_p], [p.a_p_g], "o", label=text)
    ax.set_xlabel("pulse frequency f_p [Hz]")
    ax.set_ylabel("amplitude [g]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.tight_layout()
    try:
        return write_figure_atomic(fig, path)
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
    plt = load_pyplot()
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
        return write_figure_atomic(fig, path), (lo, hi)
    finally:
        plt.close(fig)


def _history_png(run: HistoryRun, path: Path) -> Path:
    return _plot_history(run.label, run.result, run.motion, run.scale, path)[0]


def _history_figures(runs: Sequence[HistoryRun], folder: Path) -> list[dict[str, str]]:
    """Return the time-history figures of one mechanism, or the notes saying why there are none."""
    out: list[dict[str, str]] = []
    for run in runs:
        if run.note is not None or run.result is None:
            out.append({"caption": run.caption, "note": run.note or "not run"})
        else:
            out.append(_embed(functools.partial(_history_png, run, folder / run.file), run.caption))
    return out


def _short(note: str) -> str:
    """Return the first clause of a note, for the verdict table (the section has it all)."""
    if not note:
        return ""
    head, _, rest = note.partition(": ")
    if rest and " " not in head:  # "<field>: <message>": keep the field and the first clause
        return f"{head}: {rest.split(';')[0].split(' (')[0]}"
    return head.split(" (")[0].split(";")[0]


def _verdict_cell(check: Union[LinearCheck, NonlinearCheck], what: str) -> dict[str, str]:
    if isinstance(check, NotRun):
        return {"text": "not run", "cls": "na", "note": _short(check.note)}
    ratio = sig(check.capacity_ratio, 3)
    if check.passes is None:
        return {"text": f"incomplete ({what} {ratio})", "cls": "na", "note": _short(check.note)}
    word = "passes" if check.passes else "fails"
    return {
        "text": f"{word} ({what} {ratio})",
        "cls": "ok" if check.passes else "ko",
        "note": "",
    }


def _dynamics_cell(row: CheckMechanism) -> dict[str, str]:
    dyn = row.dynamics or []
    if not dyn:
        return {"text": "not run", "cls": "na", "note": row.dynamics_note or ""}
    parts, cls = [], "ok"
    notes = []
    for d in dyn:
        if d.runs is None:
            parts.append(f"{d.record}: not run")
            notes.append(_short((d.note or "").removeprefix("not run: ")))
            cls = "na"
            continue
        first = d.first_overturning_multiple
        state = "survives" if d.survives_design else "overturns"
        top = max((r.multiple for r in d.runs if r.multiple is not None), default=None)
        tail = "no overturning up to ×" + sig(top, 3)
        if first is not None:
            tail = f"overturns at ×{sig(first, 3)}"
        parts.append(f"{d.record}: {state} at design; {tail}")
        if not d.survives_design:
            cls = "ko"
    return {"text": "; ".join(parts), "cls": cls, "note": "; ".join(n for n in notes if n)}


def _worst_pulse(env: Optional[AssessEnvelope]) -> Optional[PulseMargin]:
    """Return the record pulse of a mechanism's envelope with the smallest margin, or None."""
    return least_margin_pulse((env.pulses if env is not None else None) or [], lambda p: p.margin)


def _margin_cell(row: CheckMechanism, verdict: MechanismVerdict) -> dict[str, str]:
    env = row.envelope
    if env is not None and env.note is not None:
        return {"text": "not run", "cls": "na", "note": _short(env.note)}
    worst = _worst_pulse(env)
    if worst is None or worst.margin is None:
        return {"text": "–", "cls": "na", "note": "no pulse found in the records"}
    text = f"{sig(worst.margin, 3)} ({worst.record}, {sig(worst.f_p, 3)} Hz)"
    if verdict.pulse_margin is not None:
        # It disagrees with the time history, which governs: shown, not coloured.
        return {"text": text, "cls": "na", "note": "screening only: the time history governs"}
    return {"text": text, "cls": "ok" if worst.margin >= 1.0 else "ko", "note": ""}


def _final_cell(verdict: MechanismVerdict) -> dict[str, str]:
    word = {"fails": "FAILS", "passes": "PASSES", "incomplete": "INCOMPLETE"}[verdict.verdict]
    cls = {"fails": "ko", "passes": "ok", "incomplete": "na"}[verdict.verdict]
    code = verdict.code_check
    if verdict.verdict == "incomplete":
        return {"text": word, "cls": cls, "note": _short(verdict.reason)}
    governs = verdict.governs or ""
    if governs.startswith("rocking"):
        detail = "governed by the rocking time history at design scale"
    elif code is not None:
        detail = (
            f"governed by the {code.check} check, {code.ratio_name} = {sig(code.capacity_ratio, 3)}"
        )
    else:
        detail = governs
    return {"text": word, "cls": cls, "note": detail}


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


#: The hazard table's rows from the site document's ``params``: key -> (quantity, symbol,
#: unit, source). Values computed by rockmech take their clause from ``site.clauses``.
_PARAM_ROWS: dict[str, tuple[str, str, str, str]] = {
    "a_g_g": ("reference peak ground acceleration on rock", "a<sub>g</sub>", "g",
              "site file: hazard.a_g (NTC) or γ<sub>I</sub> a<sub>gR</sub> (EN 1998-1 §3.2.1)"),
    "a_gR_g": ("reference peak ground acceleration", "a<sub>gR</sub>", "g",
               "site file: hazard.a_gR"),
    "gamma_I": ("importance factor", "γ<sub>I</sub>", "–", "site file: hazard.importance"),
    "F0": ("maximum spectral amplification", "F<sub>0</sub>", "–", "site file: hazard.F0"),
    "Tc_star_s": ("upper period of the plateau on rock", "T<sub>C</sub>*", "s",
                  "site file: hazard.Tc_star"),
    "soil": ("soil category", "–", "–", "site file: hazard.soil (NTC 2018 Tab. 3.2.II)"),
    "ground": ("ground type", "–", "–", "site file: hazard.ground (EN 1998-1 Tab. 3.1)"),
    "spectrum_type": ("spectrum type", "–", "–", "site file: hazard.spectrum_type "
                      "(EN 1998-1 §3.2.2.2)"),
    "topography": ("topographic category", "–", "–",
                   "site file: hazard.topography (NTC 2018 Tab. 3.2.III)"),
    "S_S": ("stratigraphic amplification", "S<sub>S</sub>", "–", "NTC 2018 Tab. 3.2.IV"),
    "S_T": ("topographic amplification", "S<sub>T</sub>", "–", "NTC 2018 Tab. 3.2.V"),
    "C_C": ("soil coefficient of T<sub>C</sub>", "C<sub>C</sub>", "–", "NTC 2018 Tab. 3.2.IV"),
    "xi_percent": ("viscous damping of the spectrum", "ξ", "%",
                   "site file: hazard.xi_percent (5 % unless given)"),
}  # fmt: skip
_DERIVED_ROWS: tuple[tuple[str, str, str, str], ...] = (
    ("S", "soil factor", "S", "–"),
    ("pga_g", "peak ground acceleration at the site", "a<sub>g</sub>S", "g"),
    ("F", "spectral amplification", "F", "–"),
    ("eta", "damping correction", "η", "–"),
    ("T_B", "start of the plateau", "T<sub>B</sub>", "s"),
    ("T_C", "end of the plateau", "T<sub>C</sub>", "s"),
    ("T_D", "start of the constant-displacement branch", "T<sub>D</sub>", "s"),
    ("FC", "confidence factor", "FC", "–"),
    ("q", "behaviour factor of the linear check", "q", "–"),
)


def hazard_table(site_doc: CheckSite) -> list[dict[str, str]]:
    """One row per hazard quantity: quantity, symbol, value, unit and source.

    Parameters
    ----------
    site_doc : CheckSite
        The check document's ``site`` block (``check_document``).

    Returns
    -------
    list of dict
        ``quantity``, ``symbol`` (HTML), ``value``, ``unit`` and ``source`` (the site
        file's field, or the clause that gives a derived value).
    """
    clauses = site_doc.clauses
    rows = [
        {"quantity": "code of the hazard", "symbol": "–", "value": str(site_doc.code),
         "unit": "–", "source": "site file: hazard.code"},
        {"quantity": "limit state of the checks", "symbol": "–",
         "value": str(site_doc.limit_state), "unit": "–",
         "source": "site file: hazard.limit_state"},
    ]  # fmt: skip
    for key, value in site_doc.params.model_dump(exclude_unset=True).items():
        if value is None or key not in _PARAM_ROWS:
            continue
        quantity, symbol, unit, source = _PARAM_ROWS[key]
        rows.append(
            {"quantity": quantity, "symbol": symbol, "value": sig(value), "unit": unit,
             "source": source}
        )  # fmt: skip
    derived = {
        "S": site_doc.S, "pga_g": site_doc.pga_g, "F": site_doc.F, "eta": site_doc.eta,
        "T_B": site_doc.T_B, "T_C": site_doc.T_C, "T_D": site_doc.T_D, "FC": site_doc.FC,
        "q": site_doc.q,
    }  # fmt: skip
    for key, quantity, symbol, unit in _DERIVED_ROWS:
        if derived[key] is None:
            continue
        rows.append(
            {"quantity": quantity, "symbol": symbol, "value": sig(derived[key]), "unit": unit,
             "source": clauses.get(key, "site file")}
        )  # fmt: skip
    states = site_doc.limit_states
    for name, ls in (("SLV", states.SLV), ("SLC", states.SLC)):
        if ls is None or name == site_doc.limit_state:
            continue
        rows.append(
            {"quantity": f"{name} hazard (for the {name} checks)", "symbol": "a<sub>g</sub>, F, "
             "T<sub>C</sub>", "value": f"{sig(ls.a_g)}, {sig(ls.F)}, {sig(ls.T_C)}",
             "unit": "g, –, s", "source": f"site file: {ls.source}"}
        )  # fmt: skip
    return rows + _building_rows(site_doc)


def _building_rows(site_doc: CheckSite) -> list[dict[str, str]]:
    """Return the hazard table's rows of the building: its height, storeys, damping, T1."""
    rows = []
    building = site_doc.building or {}  # the site file's block, as given
    for key, quantity, symbol, unit in (
        ("height", "height of the building", "H", "m"),
        ("storeys", "storeys", "–", "–"),
        ("xi_percent", "damping of the building (floor spectra)", "ξ<sub>k</sub>", "%"),
        ("period_elongation", "period elongation of the floor spectra", "–", "–"),
    ):
        if building.get(key) is not None:
            rows.append(
                {"quantity": quantity, "symbol": symbol, "value": sig(building[key]),
                 "unit": unit, "source": f"site file: building.{key}"}
            )  # fmt: skip
    if site_doc.T1 is not None:
        rows.append(
            {"quantity": "fundamental period of the building", "symbol": "T<sub>1</sub>",
             "value": sig(site_doc.T1), "unit": "s", "source": str(site_doc.T1_source)}
        )  # fmt: skip
    return rows


def reproduce_commands(
    sources: Sequence[dict[str, Any]], options: Optional[dict[str, Any]]
) -> list[dict[str, str]]:
    """Return the ``rockmech`` commands that give every number of the page again.

    Run in a folder holding the inputs under the names of the provenance table (their
    SHA-256 identify them). ``rockmech assess ... --json`` prints the whole document the
    page shows; ``rockmech check`` the code checks alone (without the records' demand).
    """
    names = {"constants": "constants.json", "site": "site.json"}
    records: list[str] = []
    retrofit: Optional[str] = None
    for src in sources:
        if src["role"] == "retrofit":
            retrofit = _file_name(src["name"], "retrofit.json")
        elif src["role"] in names:
            names[src["role"]] = _file_name(src["name"], names[src["role"]])
        elif src["role"] == "record":
            records.append(_file_name(src["name"], f"record{len(records) + 1}.csv"))
    opts = options or {}
    args = [f"--record {shlex.quote(r)}" for r in records]
    flags = (
        ("units", "--units"),
        ("format", "--format"),
        ("dt", "--dt"),
        ("channel", "--channel"),
        ("component", "--component"),
    )
    for key, flag in flags:
        if opts.get(key) is not None:
            args.append(f"{flag} {shlex.quote(str(opts[key]))}")
    args += [f"--multiple {sig(k)}" for k in opts.get("multiples", [])]
    if retrofit is not None:
        args.append(f"--retrofit {shlex.quote(retrofit)}")
    c, s = shlex.quote(names["constants"]), shlex.quote(names["site"])
    out = [
        {
            "what": "every number of this page (the assessment document as JSON)",
            "command": " ".join(["rockmech assess", c, s, *args, "-o report.html --json"]),
        },
        {
            "what": "the code checks alone, without the records' demand (C8.7.1.2.1.8)",
            "command": f"rockmech check {c} {s} --json",
        },
    ]
    if any("." not in src["name"] for src in sources):
        out.append(
            {
                "what": "inputs sent to the service rather than as files: save the request's "
                "constants, site and each record (two columns: time [s], acceleration in the "
                "units sent) under the names above first",
                "command": "",
            }
        )
    return out


def _file_name(name: str, default: str) -> str:
    """Return a source's name as a file name (an upload's name may be a bare word)."""
    return name if "." in name else default


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


def _template_error(exc: BaseException, template_dir: Optional[Path]) -> Optional[InputError]:
    """Return a one-line error naming a user template's file and line, or None (#25).

    ``exc`` is raised while loading or rendering the template: a jinja2 syntax error carries
    its file and line; any other error is placed by the template frame in its traceback
    (jinja2 rewrites tracebacks so that they show template lines). An error whose file is
    not in ``template_dir`` (the packaged template) is none of the user's: None.
    """
    if template_dir is None:
        return None
    if isinstance(exc, UnicodeDecodeError):
        return InputError(f"a template in {template_dir} is not UTF-8 text: {exc}", "template_dir")
    filename = getattr(exc, "filename", None)
    lineno = getattr(exc, "lineno", None)
    if not isinstance(filename, str) or not isinstance(lineno, int):
        filename, lineno = None, None
        tb = exc.__traceback__
        while tb is not None:
            code = tb.tb_frame.f_code.co_filename
            if Path(code).parent == template_dir or Path(code).suffix == ".j2":
                filename, lineno = code, tb.tb_lineno
            tb = tb.tb_next
    if filename is None or Path(filename).resolve().parent != template_dir.resolve():
        return None
    what = getattr(exc, "message", None) or str(exc) or type(exc).__name__
    if type(exc).__name__ in ("TemplateNotFound", "TemplatesNotFound"):
        what = f"includes {what}, which is neither in {template_dir} nor a packaged template"
    where = f"{filename}, line {lineno}" if lineno else filename
    return InputError(f"{where}: {what.splitlines()[0] if what else ''}", "template_dir")


def _render(template_dir: Optional[Path], context: Optional[dict[str, Any]] = None) -> str:
    """Load the template (and render it with ``context``), a user template's error in one line.

    Without ``context`` the template is only loaded and compiled, so that a syntax error in
    a user's template is found before the analysis runs.
    """
    env = _environment(template_dir)
    try:
        template = env.get_template(TEMPLATE_NAME)
        return "" if context is None else str(template.render(**context))
    except Exception as exc:  # a user's template can raise anything jinja2 or Python can
        error = _template_error(exc, template_dir)
        if error is None:
            raise
        raise error from None


def _mechanism_figures(
    row: CheckMechanism, spectrum: Any, runs: Sequence[HistoryRun], folder: Path
) -> list[dict[str, str]]:
    """Return a mechanism's figures: its checks on the capacity curve, envelope, histories."""
    non = row.nonlinear
    figs = []
    if isinstance(non, (Nonlinear2019, Nonlinear2009)):
        figs.append(
            _embed(
                functools.partial(
                    _plot_capacity,
                    row.linear,
                    non,
                    spectrum,
                    folder / f"{row.id}_capacity.png",
                ),
                f"{row.id}: the checks on the capacity curve (ADRS): capacity, "
                "demand and verdict of each (Circ. 2019 C8.7.1.2.1.7-8)",
            )
        )
    env_doc = row.envelope
    if env_doc is not None and env_doc.a_p_min_g is not None:
        figs.append(
            _embed(
                functools.partial(_plot_envelope, env_doc, folder / f"{row.id}_envelope.png"),
                f"{row.id}: overturning envelope and the records' largest pulses at design scale",
            )
        )
    figs.extend(_history_figures(runs, folder))
    return figs


def render_assessment(
    doc: AssessDocument,
    cf: ConstantsFile,
    site: SiteFile,
    spectrum: Any,
    histories: Mapping[str, Sequence[HistoryRun]],
    *,
    sources: Sequence[dict[str, Any]] = (),
    options: Optional[dict[str, Any]] = None,
    template_dir: Optional[Path] = None,
) -> str:
    """Render the assessment document as one self-contained HTML page.

    Parameters
    ----------
    doc : AssessDocument
        ``workflows.assess.assessment_document(cf, site, motions, ...)``.
    cf, site
        The inputs of ``doc`` (for the constants and the project).
    spectrum : Spectrum
        The site's elastic spectrum (``workflows.assess.site_spectrum(site)``), drawn with
        the capacity curves.
    histories : dict of str to sequence of HistoryRun
        Per mechanism id, its time histories at the design scale
        (``workflows.pages.assessment_histories``); a mechanism absent has none.
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
    check_template(template_dir)  # a user template's syntax error before any figure is drawn
    by_id = {m.id: m for m in cf.mechanisms}
    method = doc.method.name
    verdicts_by_id = {v.id: v for v in doc.conclusion.mechanisms}
    with tempfile.TemporaryDirectory(prefix="rockmech-assess-") as tmp:
        folder = Path(tmp)
        spectrum_fig = _embed(
            functools.partial(_plot_spectrum, spectrum, folder / "spectrum.png"),
            f"Site spectrum ({doc.site.code}): a_g S = {sig(doc.site.pga_g)} g",
        )
        sections = []
        verdicts = []
        for row in doc.mechanisms:
            figs = _mechanism_figures(row, spectrum, histories.get(row.id, ()), folder)
            verdict = verdicts_by_id[row.id]
            cells = {
                "verdict": _final_cell(verdict),
                "linear": _verdict_cell(row.linear, ratio_label(method, "linear")),
                "nonlinear": _verdict_cell(row.nonlinear, ratio_label(method, "nonlinear")),
                "dynamics": _dynamics_cell(row),
                "margin": _margin_cell(row, verdict),
            }
            verdicts.append({"row": row, "cells": cells, "verdict": verdict})
            sections.append(
                {
                    "row": row,
                    "mech": by_id[row.id],
                    "constants": _constants_rows(by_id[row.id]),
                    "figures": figs,
                    "cells": cells,
                    "linear_rows": _check_rows(row.linear),
                    "nonlinear_rows": _check_rows(row.nonlinear),
                }
            )
    project = site.project.model_dump()
    context = {
        "retrofit": _retrofit_context(doc.retrofit, doc.mechanisms),
        "title": project.get("title") or "Seismic assessment of local collapse mechanisms",
        "project": project,
        "generated": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "site": doc.site,
        "method": doc.method,
        "hazard_table": hazard_table(doc.site),
        "ratio_linear": ratio_label(method, "linear"),
        "ratio_nonlinear": ratio_label(method, "nonlinear"),
        "conclusion": doc.conclusion,
        "disagreements": [v for v in doc.conclusion.mechanisms if v.pulse_margin is not None],
        "commands": reproduce_commands(sources, options),
        "version": __version__,
        "spectrum_figure": spectrum_fig,
        "verdicts": verdicts,
        "sections": sections,
        "governing": doc.governing,
        "records": doc.records,
        "multiples": doc.multiples,
        "sources": list(sources),
        "options_rows": _table_of(options or {}),
        "versions_rows": _table_of(_versions()),
    }
    return _render(template_dir, context)


#: The colour of a retrofit status on page one (the others, in red: no tie makes it pass).
_RETROFIT_CLASS = {"designed": "ok", "passes": "ok", "not_checked": "na", "not_evaluated": "na"}


def _kn(value: Optional[float]) -> str:
    return "–" if value is None else sig(value / 1e3, 3)


def _upgrade_rows(rdoc: RetrofitDoc) -> list[dict[str, Any]]:
    """Return page one's rows of the connection upgrades (from a scene): one per upgrade.

    Each: the upgrade in words, the mechanism that governs the search again with it, its
    λ0 and the least margin before (the first search's) → after; then the row of every
    upgrade with the designed ties.
    """
    sa = rdoc.search_after
    if sa is None or not sa.upgrades:
        return []
    rows = []
    for key, u in [*((str(k), u) for k, u in enumerate(sa.upgrades)), ("together", sa.together)]:
        if u is None:
            continue
        words = " + ".join(w.replace("->", "→") for w in u.upgrades)
        governs = "no mechanism is left"
        if u.after is not None:
            lam0 = "–" if u.after_lam0 is None else sig(u.after_lam0, 3)
            governs = f"{u.after} governs (λ0 {lam0})"
        ok = u.after is None or (u.after_margin is not None and u.after_margin >= 1.0)
        rows.append(
            {
                "key": key,
                "words": words + (" + the designed ties" if u.with_ties else ""),
                "governs": governs,
                "before": "–" if sa.before_margin is None else sig(sa.before_margin, 3),
                "after": "–" if u.after_margin is None else sig(u.after_margin, 3),
                "label": u.after_criterion or "",
                "cls": "ok" if ok else "ko",
                "moved": u.moved,
            }
        )
    return rows


def _retrofit_context(
    rdoc: Optional[RetrofitDoc], mechanisms: Sequence[CheckMechanism]
) -> Optional[dict[str, Any]]:
    """Return page one's retrofit table (rows, sentences, steel and anchorage), or None.

    ``rdoc`` is the document's ``retrofit``, absent without ``--retrofit``; ``mechanisms``
    the assessment's rows (``records_notes``).
    """
    if rdoc is None:
        return None
    notes = records_notes(rdoc, mechanisms)
    rows = []
    for r in retrofit_summary(rdoc):
        o = r.option
        tie = "–"
        if o is not None and o.bar is not None:
            tie = f"{r.bar_text} at {o.height_m:.3g} m"
        elif o is not None:
            tie = f"at {o.height_m:.3g} m (no bar on offer)"
        per_bar = None if o is None or o.T_star_N is None else o.T_star_N / o.bars
        rows.append(
            {
                "id": r.id,
                "status": r.status,
                "status_words": r.status_words,
                "tie": tie,
                "T_star_kN": _kn(None if o is None else o.T_star_N),
                "T_bar_kN": _kn(per_bar),
                "governs": "–" if o is None or o.governing is None else o.governing,
                "before": "–" if r.before_ratio is None else sig(r.before_ratio, 3),
                "after": "–" if r.after_ratio is None else sig(r.after_ratio, 3),
                "label": (
                    r.before_label
                    if r.after_label in ("", r.before_label)
                    else f"{r.before_label} → {r.after_label}"
                ),
                "cls": _RETROFIT_CLASS.get(r.status, "ko"),
                "sentence": r.sentence,
                "records_note": notes.get(r.id, ""),
            }
        )
    anchorages = sorted(
        {
            (o.anchorage.capacity_N, o.anchorage.source)
            for m in rdoc.mechanisms
            for o in m.options
            if o.anchorage is not None
        }
    )
    return {
        "rows": rows,
        "upgrades": _upgrade_rows(rdoc),
        "records_ids": [r["id"] for r in rows if r["records_note"]],
        "grade": rdoc.steel.get("grade", ""),
        "gamma_M0": rdoc.steel.get("gamma_M0"),
        "anchorages": [{"capacity_kN": _kn(c), "source": src} for c, src in anchorages],
        "standard": rdoc.standard,
    }


def check_template(template_dir: Optional[Path]) -> None:
    """Refuse a user template that does not load or parse, before any work is done.

    Raises
    ------
    InputError
        The folder has no readable ``assess.html.j2`` or it has a syntax error (naming the
        file and line).
    """
    _render(template_dir)


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
