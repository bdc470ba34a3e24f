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

from ..core.result import RockingResult

__all__ = ["plot_envelopes", "plot_time_histories"]


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save_atomic(fig: Any, path: Union[str, Path]) -> Path:
    """Render a figure in memory and write it atomically (format from the suffix)."""
    from shared_schema.atomic import write_atomic

    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    buf = io.BytesIO()
    fig.savefig(buf, dpi=120, bbox_inches="tight", format=out.suffix.lstrip(".") or "png")
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
    plt = _pyplot()
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
        ax.plot(res.t, res.ratio, lw=1.0, label=f"{label}: peak {res.peak_ratio:.3f}{verdict}")
    for level in (1.0, -1.0):
        ax.axhline(level, color="crimson", ls="--", lw=0.8)
    ax.set_ylabel("φ / φ_ov  [-]")
    ax.set_ylim(-1.25, 1.25)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    if title:
        ax.set_title(title)
    if record_t is not None and record_a_g is not None:
        axr = axes[1, 0]
        axr.plot(record_t, record_a_g, color="0.3", lw=0.6)
        axr.set_ylabel("ground acc. [g]")
        axr.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    fig.tight_layout()
    try:
        return _save_atomic(fig, path)
    finally:
        plt.close(fig)


def plot_envelopes(
    envelopes: Sequence[Any],
    bands: Sequence[dict[str, Any]],
    path: Union[str, Path],
    *,
    labels: Union[dict[str, str], None] = None,
    title: str = "",
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
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(9, 8))
    colours = {}
    cmap = plt.get_cmap("tab10")
    for k, env in enumerate(envelopes):
        colour = cmap(k % 10)
        colours[env.name] = colour
        y = np.where(np.isfinite(env.a_p_min_g), env.a_p_min_g, np.nan)
        text = (labels or {}).get(env.name, env.name)
        ax.plot(env.f_p, y, color=colour, lw=1.4, label=text)
    if envelopes:
        lower = np.nanmin(
            np.stack([np.where(np.isfinite(e.a_p_min_g), e.a_p_min_g, np.nan) for e in envelopes]),
            axis=0,
        )
        ax.plot(envelopes[0].f_p, lower, color="black", lw=2.6, alpha=0.35, label="governing")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ymax = ax.get_ylim()[1]
    for band in bands:
        colour = colours.get(band["mechanism"], "0.5")
        ax.axvspan(band["f_min"], band["f_max"], color=colour, alpha=0.10, lw=0)
        mid = float(np.sqrt(band["f_min"] * band["f_max"]))
        ax.text(mid, ymax, band["mechanism"], ha="center", va="top", fontsize=8, color=colour)
    ax.set_xlabel("pulse frequency f_p [Hz]")
    ax.set_ylabel("minimum overturning pulse amplitude a_p [g] (ground level)")
    ax.grid(which="both", alpha=0.25)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0.0, -0.12), ncol=1, frameon=False)
    if title:
        ax.set_title(title)
    fig.tight_layout()
    try:
        return _save_atomic(fig, path)
    finally:
        plt.close(fig)
