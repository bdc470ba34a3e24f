"""Candidate ties drawn in the scene: the retrofit spec's ``tie_lines`` (docs/theory.md §11.12).

Each line object the selectors of ``tie_lines`` match is read as the search reads a tie-bar
(``cad_maths.search.model.outer_face_crossing``: where the line meets a wall's outer face,
within the wall's length and height) and must be horizontal (``TIE_LINE_SLOPE_MAX``: the
tie model is). It is a candidate tie of every mechanism of the first search that turns
outward the wall it crosses and whose moving part holds the crossing: above the hinge and
not above the moving part's top (the wall's top, or the constants' top if lower). Its height
is the crossing's ``z`` less the hinge's, on the outer face, as the designed tie is placed
back (``retrofit_scene.place_ties``).

A line that meets no wall is refused, naming the nearest wall and the gap; a line that
meets a wall only where no mechanism's moving part is gets a note on each mechanism of that
wall saying why it is not a candidate, and a line crossing only walls that no mechanism
turns gets a note in the document's decisions: none is dropped in silence.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from cad_maths.scene_base import BaseScene, SceneObject
from cad_maths.search.model import Wall, outer_face_crossing
from shared_schema.errors import InputError, RockmechError
from shared_schema.retrofit import RetrofitSpec

from .retrofit import HEIGHT_SAME_M, top_height
from .search import SearchRun

__all__ = ["TIE_LINE_SLOPE_MAX", "LineCandidates", "tie_line_candidates"]

#: A tie line may rise by at most this over its horizontal length [-] (0.5 %: 5 mm per m);
#: steeper is refused, the tie model being a horizontal force.
TIE_LINE_SLOPE_MAX = 0.005
#: A crossing within this of the hinge [m] is at the hinge: not above it.
AT_HINGE_M = 1e-9


@dataclass
class LineCandidates:
    """The candidate ties the scene's tie lines give.

    Attributes
    ----------
    heights : dict of str to list of (float, str)
        Per mechanism id of the first search: the candidate heights above its hinge [m], in
        ascending order, each with its source (the line's name, id and layer); lines within
        ``HEIGHT_SAME_M`` of one height are one candidate naming each.
    notes : dict of str to list of str
        Per mechanism id: the lines crossing its wall that are not its candidates, and why.
    decisions : list of str
        The lines that cross only walls no mechanism turns.
    """

    heights: dict[str, list[tuple[float, str]]] = field(default_factory=dict)
    notes: dict[str, list[str]] = field(default_factory=dict)
    decisions: list[str] = field(default_factory=list)


def _words(obj: SceneObject) -> str:
    name = repr(obj.name) if obj.name else "(unnamed)"
    return f"tie line {name} (id {obj.id}, layer {obj.layer or '(none)'})"


def _lines(scene: BaseScene, selectors: Sequence[Any]) -> list[tuple[SceneObject, Any, str]]:
    """Return each line the selectors match once, its end points [m] and its field."""
    out: list[tuple[SceneObject, Any, str]] = []
    seen: set[str] = set()
    for k, sel in enumerate(selectors):
        where = f"tie_lines[{k}]"
        try:
            objs = scene.find(sel)
        except InputError as exc:
            raise InputError(exc.reason, where) from None
        for obj in objs:
            if obj.id in seen:
                continue
            seen.add(obj.id)
            try:
                a, b = scene.line(obj)
            except RockmechError as exc:
                raise InputError(
                    f"{sel!r} matches {exc}; a tie line is a line object", where
                ) from None
            out.append((obj, (np.asarray(a, float), np.asarray(b, float)), where))
    return out


def _horizontal(obj: SceneObject, ends: Any, where: str) -> None:
    a, b = ends
    d = b - a
    run = math.hypot(float(d[0]), float(d[1]))
    if run == 0.0 or abs(float(d[2])) > TIE_LINE_SLOPE_MAX * run:
        slope = "vertical" if run == 0.0 else f"slope {float(d[2]) / run:.4g} (rise over run)"
        raise InputError(
            f"{_words(obj)} is not horizontal: {slope}; the tie model is a horizontal force, "
            f"so a tie line may rise by at most {TIE_LINE_SLOPE_MAX:g} of its length: draw it "
            "level",
            where,
        )


def _gap(wall: Wall, a: np.ndarray, b: np.ndarray) -> float:
    """Return the least distance [m] from the segment a-b to the wall's prism."""
    f = wall.frame
    lo = np.array([0.0, 0.0, wall.z_lo])
    hi = np.array([wall.length, f.thickness, wall.z_hi])
    p, q = np.asarray(f.to_frame(a), float), np.asarray(f.to_frame(b), float)

    def dist(u: float) -> float:
        x = p + u * (q - p)
        return float(np.linalg.norm(x - np.clip(x, lo, hi)))

    lo_u, hi_u = 0.0, 1.0  # the distance to a convex set is convex along the segment
    for _ in range(100):
        m1, m2 = lo_u + (hi_u - lo_u) / 3.0, hi_u - (hi_u - lo_u) / 3.0
        if dist(m1) <= dist(m2):
            hi_u = m2
        else:
            lo_u = m1
    return min(dist(0.0), dist(1.0), dist(0.5 * (lo_u + hi_u)))


def _crossings(
    walls: dict[str, Wall], obj: SceneObject, ends: Any, where: str
) -> list[tuple[Wall, np.ndarray]]:
    """Return the walls the line crosses (into the building) and the points [m]; or refuse."""
    a, b = ends
    out = []
    for wall in walls.values():
        hit = outer_face_crossing(wall, a, b)
        if hit is None:
            continue
        p = hit[0]
        if max(float((q - p) @ wall.frame.e_n) for q in (a, b)) <= 0.0:
            raise InputError(
                f"{_words(obj)} runs outward from wall {wall.id}'s outer face; a tie is "
                "anchored inside the building: draw it from the outer face into the building",
                where,
            )
        out.append((wall, p))
    if not out:
        gaps = sorted((_gap(w, a, b), w.id) for w in walls.values())
        gap, wid = gaps[0]
        raise InputError(
            f"{_words(obj)} misses every wall's outer face: the nearest wall is {wid}, "
            f"{gap:.3g} m from the line; draw the line through the wall it ties",
            where,
        )
    return out


def _top(run: SearchRun, mech: Any, wall: Wall, z_h: float) -> float:
    """Return the moving part's top above the hinge [m]: the wall's, or the constants' if lower."""
    top = wall.z_hi - z_h
    own, _ = top_height(mech)
    return top if own is None else min(top, own)


def _assign(
    run: SearchRun, obj: SceneObject, hits: list[tuple[Wall, np.ndarray]], out: LineCandidates
) -> None:
    """Give the line to each mechanism whose moving part its crossing is in, or say why not."""
    assert run.constants is not None
    by_id = run.candidates_by_id()
    for wall, p in hits:
        z = float(p[2])
        here = [
            m for m in run.constants.mechanisms if m.id in by_id and by_id[m.id].facade == wall.id
        ]
        for mech in here:
            geo: dict[str, Any] = mech.geometry if isinstance(mech.geometry, dict) else {}
            z_h = float(geo["positive"]["axis_point_m"][2])
            h, top = z - z_h, _top(run, mech, wall, z_h)
            why = None
            if by_id[mech.id].direction != "outward":
                why = f"the mechanism turns {by_id[mech.id].direction}: a tie is slack there"
            elif h <= AT_HINGE_M:
                why = (
                    f"it crosses wall {wall.id} at z = {z:.4g} m, at or below the hinge "
                    f"({z_h:.4g} m)"
                )
            elif h > top * (1.0 + 1e-9):
                why = (
                    f"it crosses wall {wall.id} {h:.4g} m above the hinge, above the moving "
                    f"part's top ({top:.4g} m)"
                )
            if why is not None:
                out.notes.setdefault(mech.id, []).append(f"{_words(obj)}: not a candidate, {why}")
                continue
            src = (
                f"{_words(obj)}, crossing wall {wall.id} at z = {z:.6g} m, {h:.6g} m above "
                "the hinge"
            )
            out.heights.setdefault(mech.id, []).append((h, src))
        if not here:
            out.decisions.append(
                f"{_words(obj)} crosses wall {wall.id}, which no mechanism of the search turns: "
                "it is a candidate of none"
            )


def tie_line_candidates(scene: BaseScene, run: SearchRun, rspec: RetrofitSpec) -> LineCandidates:
    """Read the retrofit spec's ``tie_lines`` from the scene as candidate tie heights.

    Parameters
    ----------
    scene : BaseScene
        The scene the first search read.
    run : SearchRun
        The first search (its building, candidates and constants).
    rspec : RetrofitSpec
        The retrofit spec, with ``tie_lines``.

    Returns
    -------
    LineCandidates
        Per mechanism id: the lines' heights above its hinge [m] with their sources, and
        notes on the lines that cross its wall but are not its candidates.

    Raises
    ------
    InputError
        A selector that matches nothing or an object that is no line, a line not horizontal
        (its slope), a line running outward from a wall, a line that meets no wall (the
        nearest wall and the gap [m]); field ``tie_lines[k]``.
    """
    out = LineCandidates()
    if not rspec.tie_lines or run.constants is None:
        return out
    walls = run.result.building.walls
    for obj, ends, where in _lines(scene, rspec.tie_lines):
        _horizontal(obj, ends, where)
        _assign(run, obj, _crossings(walls, obj, ends, where), out)
    for mid, got in out.heights.items():
        merged: list[tuple[float, str]] = []
        for h, src in sorted(got, key=lambda hs: hs[0]):
            if merged and h - merged[-1][0] <= HEIGHT_SAME_M:
                merged[-1] = (merged[-1][0], f"{merged[-1][1]}; and {src}")
            else:
                merged.append((h, src))
        out.heights[mid] = merged
    return out
