"""The figure of ``rockmech search``: the top mechanisms drawn on their façade.

Each panel shows a façade's elevation unfolded with its return walls (a return wall at the
façade's start is drawn to its left, one at its end to its right, as seen from outside),
the openings, the moving parts shaded, the cracks and the hinge line, with the mechanism's
λ0 and its overturning acceleration over the band. matplotlib is imported lazily: the
figure is a ``matplotlib.figure.Figure`` on an Agg canvas, without pyplot (whose import and
figure manager cost more than the drawing, #37).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Optional, Sequence, Union

import numpy as np

from .plots import write_figure_atomic

__all__ = ["plot_search"]

#: Panels per row of the figure.
COLUMNS = 3
#: Size of a panel's cell [in] (width, height).
PANEL = (5.0, 4.2)
#: Fixed margins [in]: left, right, bottom, top of the figure, then the gaps between
#: columns and rows (room for the y labels, the x labels and the two-line panel titles).
MARGINS = (0.75, 0.2, 0.6, 0.5, 0.85, 1.05)
#: Height added above the panels for the figure's title [in].
TITLE_BAND = 0.4


def _size(cols: int, rows: int, title: str) -> tuple[float, float]:
    """Return the figure's size [in]: the panels, their margins and the title's band."""
    return (PANEL[0] * cols, PANEL[1] * rows + (TITLE_BAND if title else 0.0))


def _margins(cols: int, rows: int, title: str) -> dict[str, float]:
    """Return the fixed layout of the panels (``GridSpec`` fractions of the figure).

    The margins are fixed in inches (``MARGINS``), so that every panel's title, axis labels
    and tick labels fit without measuring the text (which ``tight_layout`` and a tight
    bounding box do by drawing the figure once more).
    """
    width, height = _size(cols, rows, title)
    left, right, bottom, top, gap_w, gap_h = MARGINS
    top += TITLE_BAND if title else 0.0
    axis_w = (width - left - right - (cols - 1) * gap_w) / cols
    axis_h = (height - bottom - top - (rows - 1) * gap_h) / rows
    return {
        "left": left / width,
        "right": 1.0 - right / width,
        "bottom": bottom / height,
        "top": 1.0 - top / height,
        "wspace": gap_w / axis_w,
        "hspace": gap_h / axis_h,
    }


def _unfold(facade: Any, wall: Any, returns: Sequence[Any]) -> Optional[Any]:
    """Map (s, z) of ``wall``'s elevation to the unfolded façade drawing's (x, z)."""
    if wall.id == facade.id:
        return lambda pts: pts
    for r in returns:
        if r.wall.id != wall.id:
            continue
        fa, fw = facade.frame, wall.frame
        # sigma (distance into the building from the façade's inner face) is affine in s
        s0 = float((fw.origin - fa.origin) @ fa.e_n) - facade.inner_face
        ds = float(fw.e_s @ fa.e_n)
        if r.end == "start":
            return lambda pts: np.column_stack([-(s0 + ds * pts[:, 0]), pts[:, 1]])
        return lambda pts: np.column_stack([facade.length + s0 + ds * pts[:, 0], pts[:, 1]])
    return None


def _draw_rings(ax: Any, rings: Sequence[np.ndarray], fmap: Any, **kw: Any) -> None:
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MPath

    verts: list[Any] = []
    codes: list[int] = []
    for r in rings:
        if len(r) < 3:
            continue
        p = fmap(np.asarray(r, dtype=float))
        verts.extend([*p.tolist(), p[0].tolist()])
        codes.extend(
            [int(MPath.MOVETO)] + [int(MPath.LINETO)] * (len(p) - 1) + [int(MPath.CLOSEPOLY)]
        )
    if verts:
        ax.add_patch(PathPatch(MPath(verts, codes), **kw))


def plot_search(
    run: Any, path: Union[str, Path], *, top: int = 6, title: str = ""
) -> Optional[Path]:
    """Draw the best ranked mechanisms (dynamic ranking, else static) on their façades.

    Parameters
    ----------
    run : SearchRun
        A search (``solver_service.workflows.search.search_run``).
    path : path
        The image to write (PNG or SVG by suffix).
    top : int
        How many mechanisms to draw.
    title : str
        Figure title.

    Returns
    -------
    Path or None
        The image, or None when there is no candidate to draw.
    """
    ranked = run.doc.ranked[:top]
    order = [d.id for d in ranked]
    if not order:
        return None
    index = {mid: k for k, mid in run.ids.items()}
    bld = run.result.building
    n = len(order)
    cols = min(COLUMNS, n)
    rows = math.ceil(n / cols)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=_size(cols, rows, title))
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, squeeze=False, gridspec_kw=_margins(cols, rows, title))
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    for ax, d in zip(axes.ravel(), ranked):
        mid = d.id
        cand = run.result.candidates[index[mid]]
        facade = bld.walls[cand.facade]
        returns = bld.returns.get(facade.id, [])
        walls = [facade] + [r.wall for r in returns]
        for w in walls:
            fmap = _unfold(facade, w, returns)
            if fmap is None:
                continue
            _draw_rings(ax, w.rings, fmap, facecolor="0.92", edgecolor="0.35", lw=0.8)
        for piece in cand.pieces:
            fmap = _unfold(facade, piece.wall, returns)
            if fmap is None:
                continue
            _draw_rings(ax, piece.rings(), fmap, facecolor="tab:red", alpha=0.45, lw=0)
        for crack in d.cracks:
            w = bld.walls[crack.wall]
            fmap = _unfold(facade, w, returns)
            if fmap is not None:
                seg = fmap(np.asarray(crack.segment, dtype=float))
                ax.plot(seg[:, 0], seg[:, 1], color="tab:red", lw=1.8)
        if cand.typology == "two_block":
            z = facade.z_lo + cand.params["h1_m"]
            ax.plot([0.0, facade.length], [z, z], "--", color="tab:blue", lw=1.5)
        elif cand.family != "corner":
            z = cand.hinge_z
            ax.plot([0.0, facade.length], [z, z], color="tab:blue", lw=2.2)
        score = None if d.overturning is None else d.overturning.band_score_g
        head = f"{mid} {cand.family.replace('_', ' ')} ({cand.facade}, {cand.direction})"
        sub = f"λ0 = {cand.lam0:.3g}" + ("" if score is None else f", a_p,min ≈ {score:.3g} g")
        ax.set_title(head + "\n" + sub, fontsize=9)
        ax.set_aspect("equal")
        ax.autoscale_view()
        ax.set_xlabel("along the façade, return walls unfolded [m]", fontsize=8)
        ax.set_ylabel("z [m]", fontsize=8)
        ax.tick_params(labelsize=7)
    if title:
        fig.suptitle(title)
    return write_figure_atomic(fig, path, tight=False)
