"""Plots of rocking results (PNG or SVG, chosen by the file suffix).

matplotlib is imported inside each function, with the non-interactive Agg back end, so
importing this module costs nothing and works on machines without a display.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Union

import numpy as np

from shared_schema.atomic import write_atomic
from shared_schema.documents.ida import IdaDocument

from ..core.fragility import lognormal_cdf
from ..core.model import G
from ..core.result import RockingResult

__all__ = [
    "plain",
    "plot_envelopes",
    "plot_fragility",
    "plot_ratio_histories",
    "plot_record",
    "plot_time_histories",
]


def load_pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plain(text: str) -> str:
    r"""Return user text (an id, a record name, a title) escaped so that it is drawn as written.

    matplotlib reads text between two ``$`` as mathtext. The tick labels of log axes need it
    (their formatter writes ``$\mathdefault{10^{0}}$``), so it stays on; every ``$`` of user
    text is escaped instead (``\$`` draws a dollar sign), so that an id never starts
    mathtext, whose parser recurses without bound on nested braces.

    Examples
    --------
    >>> plain("W$1{}$")
    'W\\$1{}\\$'
    """
    return str(text).replace("$", r"\$")


def write_figure_atomic(fig: Any, path: Union[str, Path], *, tight: bool = True) -> Path:
    """Render a figure in memory and write it atomically (format from the suffix).

    ``tight`` crops the image to what is drawn (``bbox_inches="tight"``, which draws the
    figure twice); a figure laid out in fixed margins is drawn once with ``tight=False``.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    buf = io.BytesIO()
    fmt = out.suffix.lstrip(".") or "png"
    fig.savefig(buf, dpi=120, bbox_inches="tight" if tight else None, format=fmt)
    write_atomic(out, buf.getvalue())
    return out


def plot_time_histories(
    results: Sequence[tuple[str, RockingResult]],
    path: Union[str, Path],
    *,
    record_t: Union[np.ndarray[Any, Any], None] = None,
    record_a_g: Union[np.ndarray[Any, Any], None] = None,
    title: str = "",
) -> Path:
    """Plot ``phi/phi_ov`` against time for several runs, over the ground motion.

    Parameters
    ----------
    results : sequence of (label, RockingResult)
        Runs made with ``dense=True``.
    path : str or Path
        Output file (.png or .svg); written atomically.
    record_t, record_a_g : (n,) float, optional
        Ground motion to draw underneath: time [s] and acceleration [g].
    title : str
        Figure title.

    Returns
    -------
    Path
        The written file.
    """
    plt = load_pyplot()
    nrows = 2 if record_t is not None else 1
    fig, axes = plt.subplots(
        nrows,
        1,
        figsize=(9, 3.2 * nrows),
        sharex=True,
        squeeze=False,
        gridspec_kw={"height_ratios": [2, 1][:nrows]},
    )
    ax = axes[0, 0]
    for label, res in results:
        if res.t is None or res.ratio is None:
            raise ValueError(f"result {label!r} has no time series; run with dense=True")
        verdict = " (overturned)" if res.overturned else ""
        text = f"{plain(label)}: peak {res.peak_ratio:.3f}{verdict}"
        ax.plot(res.t, res.ratio, lw=1.0, label=text)
    for level in (1.0, -1.0):
        ax.axhline(level, color="crimson", ls="--", lw=0.8)
    ax.set_ylabel("φ / φ_ov  [-]")
    ax.set_ylim(-1.25, 1.25)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    if title:
        ax.set_title(plain(title))
    if record_t is not None and record_a_g is not None:
        axr = axes[1, 0]
        axr.plot(record_t, record_a_g, color="0.3", lw=0.6)
        axr.set_ylabel("ground acc. [g]")
        axr.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    fig.tight_layout()
    try:
        return write_figure_atomic(fig, path)
    finally:
        plt.close(fig)


def _log_plottable(values: np.ndarray[Any, Any]) -> np.ndarray[Any, Any]:
    """Return the values with the non-finite and non-positive ones as NaN (gaps in a log plot)."""
    v = np.asarray(values, dtype=float)
    return np.where(np.isfinite(v) & (v > 0), v, np.nan)


def plot_ratio_histories(
    panels: Sequence[tuple[float, Sequence[tuple[str, RockingResult]]]],
    path: Union[str, Path],
    *,
    title: str = "",
) -> Path:
    """Plot ``phi/phi_ov`` of several mechanisms against time, one panel per scale factor.

    Parameters
    ----------
    panels : sequence of (scale, [(label, RockingResult), ...])
        Runs made with ``dense=True``; a mechanism keeps its colour in every panel.
    path : str or Path
        Output file (.png or .svg); written atomically.
    title : str
        Figure title.

    Returns
    -------
    Path
        The written file.
    """
    plt = load_pyplot()
    n = max(len(panels), 1)
    fig, axes = plt.subplots(n, 1, figsize=(9, 1.2 + 2.1 * n), sharex=True, squeeze=False)
    cmap = plt.get_cmap("tab10")
    colours: dict[str, Any] = {}
    for ax, (scale, runs) in zip(axes[:, 0], panels):
        for label, res in runs:
            if res.t is None or res.ratio is None:
                raise ValueError(f"result {label!r} has no time series; run with dense=True")
            colour = colours.setdefault(label, cmap(len(colours) % 10))
            mark = " ×" if res.overturned else ""
            ax.plot(res.t, res.ratio, lw=0.9, color=colour, label=f"{plain(label)}{mark}")
            if res.overturned and res.t_overturn is not None:
                ax.axvline(res.t_overturn, color=colour, ls=":", lw=0.8)
        for level in (1.0, -1.0):
            ax.axhline(level, color="crimson", ls="--", lw=0.7)
        ax.set_ylim(-1.2, 1.2)
        ax.set_ylabel(f"φ/φ_ov  (×{scale:g})")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right", ncol=min(len(runs), 5))
    axes[-1, 0].set_xlabel("time [s]")
    if title:
        axes[0, 0].set_title(f"{plain(title)}  (× overturned; dotted: time of overturning)")
    fig.tight_layout()
    try:
        return write_figure_atomic(fig, path)
    finally:
        plt.close(fig)


def plot_record(
    motion: Any, path: Union[str, Path], *, spectrum: Any, pulses: Sequence[Any]
) -> Path:
    """Plot a record with its largest sine pulse, and its elastic response spectrum.

    Parameters
    ----------
    motion : GroundMotion
        The record.
    path : str or Path
        Output file (.png or .svg); written atomically.
    spectrum : Spectrum
        Its elastic response spectrum (``core.spectra.response_spectrum``).
    pulses : sequence of ExtractedPulse
        Its pulses, largest first (``core.pulses.extract_pulses``); the first is drawn.

    Returns
    -------
    Path
        The written file.
    """
    plt = load_pyplot()
    fig, (ax_a, ax_s) = plt.subplots(
        1, 2, figsize=(11, 3.6), gridspec_kw={"width_ratios": [1.7, 1]}
    )
    ax_a.plot(motion.accel.time, motion.accel.acc / G, color="0.35", lw=0.6)
    if pulses:
        p = pulses[0]
        ax_a.axvspan(p.t_start, p.t_start + p.duration, color="crimson", alpha=0.12, lw=0)
        tp = np.linspace(p.t_start, p.t_start + p.duration, 200)
        ax_a.plot(
            tp,
            p.a_p_g * np.sin(2 * np.pi * p.f_p * (tp - p.t_start)),
            color="crimson",
            lw=1.6,
            label=f"largest sine pulse: {abs(p.a_p_g):.3f} g at {p.f_p:.2f} Hz",
        )
        ax_a.legend(fontsize=8, loc="upper right")
    ax_a.set_xlabel("time [s]")
    ax_a.set_ylabel("ground acceleration [g]")
    ax_a.set_title(f"{plain(motion.name)}: PGA {motion.pga_g:.3f} g, dt {motion.dt:g} s")
    ax_a.grid(alpha=0.3)
    ax_s.plot(spectrum.periods, spectrum.psa_g, color="navy", lw=1.2)
    ax_s.set_xscale("log")
    ax_s.set_xlabel("natural period T_n [s]")
    ax_s.set_ylabel(f"PSA [g] ({100 * spectrum.zeta:g} % damping)")
    ax_s.set_title("elastic response spectrum (exact)")
    ax_s.grid(which="both", alpha=0.3)
    fig.tight_layout()
    try:
        return write_figure_atomic(fig, path)
    finally:
        plt.close(fig)


def plot_envelopes(
    envelopes: Sequence[Any],
    bands: Sequence[dict[str, Any]],
    path: Union[str, Path],
    *,
    labels: Union[dict[str, str], None] = None,
    title: str = "",
    pulse_points: Union[Sequence[dict[str, Any]], None] = None,
    edges: Union[Sequence[dict[str, Any]], None] = None,
    fast: bool = False,
) -> Path:
    """Log-log overturning envelopes at ground level, with the critical bands shaded.

    Parameters
    ----------
    envelopes : sequence of Envelope
        One per mechanism (``solver_service.core.envelope.Envelope``).
    bands : sequence of dict
        Critical bands ``{"mechanism", "f_min", "f_max"}`` [Hz].
    path : str or Path
        Output file (.png or .svg); written atomically.
    labels : dict, optional
        Legend text per mechanism name.
    title : str
        Figure title.
    pulse_points : sequence of dict, optional
        A record's largest pulse at several scale factors, ``{"scale", "f_p_hz",
        "a_p_g"}`` (``|a_p|`` [g]); drawn as points joined by a line and labelled by scale.
    edges : sequence of dict, optional
        Where each band edge lies, ``{"f_low", "f_high"}`` [Hz] (``documents.band_edges``);
        drawn hatched, so that the reader sees the frequency tolerance of each edge.
    fast : bool
        The envelopes are the fast mode's (the library): said in the edges' legend entry.
    """
    plt = load_pyplot()
    fig, ax = plt.subplots(figsize=(9, 8))
    colours = {}
    cmap = plt.get_cmap("tab10")
    for k, env in enumerate(envelopes):
        colour = cmap(k % 10)
        colours[env.name] = colour
        y = _log_plottable(env.a_p_min_g)
        text = (labels or {}).get(env.name, env.name)
        ax.plot(env.f_p, y, color=colour, lw=1.4, label=plain(text))
    if envelopes:
        curves = np.stack([_log_plottable(e.a_p_min_g) for e in envelopes])
        lower = np.full(curves.shape[1], np.nan)
        some = ~np.all(np.isnan(curves), axis=0)
        lower[some] = np.nanmin(curves[:, some], axis=0)
        ax.plot(envelopes[0].f_p, lower, color="black", lw=2.6, alpha=0.35, label="governing")
    if pulse_points:
        fx = [p["f_p_hz"] for p in pulse_points]
        fy = [p["a_p_g"] for p in pulse_points]
        ax.plot(fx, fy, "k-", lw=0.7, marker="o", ms=5, mfc="gold", label="record's largest pulse")
        for p in pulse_points:
            ax.annotate(
                f"×{p['scale']:g}",
                (p["f_p_hz"], p["a_p_g"]),
                textcoords="offset points",
                xytext=(6, -3),
                fontsize=7,
            )
    ax.set_xscale("log")
    # A log axis needs at least one positive value (degenerate constants may give none).
    drawn = [np.asarray(line.get_ydata(), dtype=float) for line in ax.lines]
    ax.set_yscale("log" if any(np.any(np.isfinite(y)) for y in drawn) else "linear")
    ymax = ax.get_ylim()[1]
    for band in bands:
        colour = colours.get(band["mechanism"], "0.5")
        ax.axvspan(band["f_min"], band["f_max"], color=colour, alpha=0.10, lw=0)
        mid = float(np.sqrt(band["f_min"] * band["f_max"]))
        name = plain(band["mechanism"])
        ax.text(mid, ymax, name, ha="center", va="top", fontsize=8, color=colour)
    for k, edge in enumerate(edges or []):
        where = "within ×1.05 (fast mode)" if fast else "between two grid frequencies"
        ax.axvspan(
            edge["f_low"],
            edge["f_high"],
            facecolor="none",
            edgecolor="0.35",
            hatch="////",
            lw=0,
            label=f"band edge: the exact edge lies {where}" if k == 0 else None,
        )
    ax.set_xlabel("pulse frequency f_p [Hz]")
    ax.set_ylabel("minimum overturning pulse amplitude a_p [g] (ground level)")
    ax.grid(which="both", alpha=0.25)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0.0, -0.12), ncol=1, frameon=False)
    if title:
        ax.set_title(plain(title))
    fig.tight_layout()
    try:
        return write_figure_atomic(fig, path)
    finally:
        plt.close(fig)


def plot_fragility(doc: IdaDocument, path: Union[str, Path], *, title: str = "") -> Path:
    """Plot IDA results: overturned fraction per level and the fitted lognormal curves.

    Parameters
    ----------
    doc : IdaDocument
        The document of ``solver_service.workflows.ida.run_ida``.
    path : str or Path
        Output file (.png or .svg); written atomically.
    title : str
        Figure title.

    Returns
    -------
    Path
        The written file.
    """
    plt = load_pyplot()
    levels = np.asarray(doc.levels, dtype=float)
    fig, ax = plt.subplots(figsize=(8, 5))
    cmap = plt.get_cmap("tab10")
    x = np.geomspace(levels.min() / 1.5, levels.max() * 1.5, 300)
    for k, mech in enumerate(doc.mechanisms):
        colour = cmap(k % 10)
        fit = mech.fragility
        label = plain(mech.id)
        if fit.median is not None and fit.beta is not None:
            ax.plot(x, lognormal_cdf(x, fit.median, fit.beta), color=colour, lw=1.3)
            label += f": median {fit.median:.3g}, β {fit.beta:.2f}"
        ax.plot(levels, mech.fraction, "o", color=colour, ms=4, label=label)
    ax.set_xscale("log")
    ax.set_ylim(-0.03, 1.03)
    unit = doc.intensity.units
    name = "scale factor [-]" if doc.measure == "scale" else f"PGA [{unit}]"
    ax.set_xlabel(name)
    ax.set_ylabel(f"fraction of {len(doc.records)} records that overturn")
    ax.grid(which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title(plain(title) or "Fragility from incremental dynamic analysis (lognormal MLE)")
    fig.tight_layout()
    try:
        return write_figure_atomic(fig, path)
    finally:
        plt.close(fig)
