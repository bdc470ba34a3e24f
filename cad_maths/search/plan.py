"""The building's plan from the walls' footprints: outlines, courtyards, outer faces.

The search needs, for every wall, which of its two long faces is on the outside. The plan
gives it by topology, never from a centroid: each wall's footprint (the convex hull of its
solid projected on the ground) is grown by half the joining gap, and the union of the grown
footprints is the plan. Each connected part of it is one building, its exterior ring the
building's outline and its holes its courtyards. A wall's face is on the outside where a
point just beyond it (one joining gap out) lies outside the plan: beyond the outline, or in
a courtyard. So re-entrant walls of an L, the walls of a T, a U or a courtyard block, walls
meeting at any angle and several buildings in one scene each get their own outer face.

A face that another wall covers (a probe beyond it lands in that wall's footprint) cannot
move that way: the plan records which wall holds it and where (``covered``).

The spaces the walls enclose are rooms, filled in the plan, where the levels cover them (a
floor or a roof over at least ``ROOM_COVER`` of the space), and courtyards, holes of the
plan, where they do not; without levels every enclosed space is a room.

Walls closer than ``GAP_RTOL`` times the thinner wall's thickness join: the plan grows each
footprint by half that, so that such walls are one building (and their junction is read as
touching, ``joining_gap``).

Python 3.9-clean: imported by Rhino 8.
"""

from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from shared_schema.extras import require

__all__ = [
    "FACE_PROBES",
    "GAP_RTOL",
    "ROOM_COVER",
    "FaceReading",
    "Plan",
    "outer_side",
    "read_plan",
]

#: Walls closer than this fraction of the thinner wall's thickness are read as meeting (a
#: CAD corner drawn a few millimetres short); the notes give each such gap.
GAP_RTOL = 0.1
#: Points probed beyond each long face of a wall, evenly along its length.
FACE_PROBES = 41
#: A space the walls enclose is a room where the levels cover at least this fraction of its
#: plan area (a floor or a roof over it); less, it is a courtyard.
ROOM_COVER = 0.5


@dataclass
class FaceReading:
    """What lies beyond each long face of a wall.

    Attributes
    ----------
    exposed : (float, float)
        Fraction of the probes beyond the face at the lowest and at the highest ``n`` that lie
        outside the plan [-].
    courtyard : (bool, bool)
        Whether the exposed probes beyond each face lie in a courtyard of the building.
    covered : (list, list)
        Per face, ``(wall id, s0, s1)``: another wall's footprint beyond the face, over
        ``s0 <= s <= s1`` along the wall [m].
    building : int
        Index of the building (the plan's connected part) the wall belongs to.
    """

    exposed: Tuple[float, float]
    courtyard: Tuple[bool, bool]
    covered: Tuple[List[Tuple[str, float, float]], List[Tuple[str, float, float]]]
    building: int


@dataclass
class Plan:
    """The plan of the walls: footprints, their union, the buildings.

    Attributes
    ----------
    origin : (2,) float
        The plan's local origin [m] (the walls' bounding-box centre; shapely works relative
        to it so that georeferenced coordinates keep their precision).
    footprints : dict of str to Polygon
        Each wall's footprint, relative to ``origin``.
    grown : dict of str to Polygon
        The footprints grown by half the joining gap.
    parts : list of Polygon
        The buildings: connected parts of the union of the grown footprints, with the rooms
        they enclose filled and their courtyards as holes.
    gap : float
        The joining gap [m] (``GAP_RTOL`` times the thinnest wall's thickness).
    courtyards : int
        Number of courtyards (spaces the walls enclose that no level covers).
    """

    origin: np.ndarray
    footprints: Dict[str, Any]
    grown: Dict[str, Any]
    parts: List[Any]
    gap: float
    courtyards: int = 0

    def building_of(self, wall: str) -> int:
        """Index of the building (in ``parts``) that holds a wall's footprint."""
        fp = self.footprints[wall]
        for k, part in enumerate(self.parts):
            if part.intersects(fp):
                return k
        return -1  # pragma: no cover - every footprint lies in the union

    def read_faces(
        self, wall: str, e_n: np.ndarray, e_s: np.ndarray, xy: np.ndarray
    ) -> FaceReading:
        """Probe beyond the two long faces of a wall.

        Parameters
        ----------
        wall : str
            The wall's id.
        e_n, e_s : (3,) float
            Its thickness and length directions (horizontal unit vectors).
        xy : (k, 2) float
            Its vertices' plan coordinates [m], world frame.
        """
        shapely = require("shapely", "geometry", "to read the plan of a search")
        pts = xy - self.origin
        n_dir, s_dir = np.asarray(e_n[:2], dtype=float), np.asarray(e_s[:2], dtype=float)
        n, s = pts @ n_dir, pts @ s_dir
        s_lo, s_hi = float(s.min()), float(s.max())
        margin = min(self.gap, 0.25 * (s_hi - s_lo))
        probes = np.linspace(s_lo + margin, s_hi - margin, FACE_PROBES)
        building = self.building_of(wall)
        shell = shapely.Polygon(self.parts[building].exterior) if building >= 0 else None
        exposed: List[float] = []
        yard: List[bool] = []
        covers: List[List[Tuple[str, float, float]]] = []
        for face, sign in ((float(n.min()), -1.0), (float(n.max()), 1.0)):
            at = face + sign * self.gap
            points = [shapely.Point(*(si * s_dir + at * n_dir)) for si in probes]
            inside = [any(p.within(part) for part in self.parts) for p in points]
            out = [p for p, hit in zip(points, inside) if not hit]
            exposed.append(len(out) / len(points))
            yard.append(bool(out) and shell is not None and all(p.within(shell) for p in out))
            covers.append(self._covers(wall, probes, points, inside))
        return FaceReading(
            (exposed[0], exposed[1]), (yard[0], yard[1]), (covers[0], covers[1]), building
        )

    def _covers(
        self, wall: str, probes: np.ndarray, points: Sequence[Any], inside: Sequence[bool]
    ) -> List[Tuple[str, float, float]]:
        """Return the walls whose grown footprints hold the probes inside the plan."""
        spans: Dict[str, List[float]] = {}
        for si, p, hit in zip(probes, points, inside):
            if not hit:
                continue
            for other, fp in self.grown.items():
                if other != wall and p.within(fp):
                    spans.setdefault(other, []).append(float(si))
        return [(w, min(v), max(v)) for w, v in sorted(spans.items())]


def read_plan(
    walls: Sequence[Tuple[str, np.ndarray]], levels: Sequence[Tuple[np.ndarray, np.ndarray]] = ()
) -> Plan:
    """Read the plan of walls given by id and vertices.

    Parameters
    ----------
    walls : sequence of (str, (k, 3) float)
        Each wall's id and its solid's vertices [m].
    levels : sequence of ((k, 3) float, (m, 3) int)
        The vertices [m] and triangles of each level's solid: a space the walls enclose is
        a room where levels cover at least ``ROOM_COVER`` of it, else a courtyard. Without
        levels every enclosed space is a room.

    Returns
    -------
    Plan
    """
    shapely = require("shapely", "geometry", "to read the plan of a search")
    xy_all = np.vstack([v[:, :2] for _, v in walls])
    origin = 0.5 * (xy_all.min(axis=0) + xy_all.max(axis=0))
    footprints: Dict[str, Any] = {}
    thick: List[float] = []
    for wid, v in walls:
        hull = footprint(v, origin)
        footprints[wid] = hull
        thick.append(least_width(hull))
    gap = GAP_RTOL * max(min(thick), 0.0)
    grown = {
        w: fp.buffer(0.5 * gap, join_style="mitre") if gap > 0.0 else fp
        for w, fp in footprints.items()
    }
    union = shapely.unary_union(list(grown.values()))
    roofed = _level_plan(shapely, levels, origin) if levels else None
    # The spaces the walls enclose: the bounded parts of the complement of the walls. A
    # space is a room (filled: part of its building) where the levels cover it, else a
    # courtyard; nested rings (a courtyard's walls inside the outer walls) join through the
    # rooms between them.
    lo_x, lo_y, hi_x, hi_y = union.bounds
    pad = max(hi_x - lo_x, hi_y - lo_y)
    frame = shapely.box(lo_x - pad, lo_y - pad, hi_x + pad, hi_y + pad)
    rooms = []
    yards = 0
    for space in getattr(frame.difference(union), "geoms", [frame.difference(union)]):
        if space.exterior.coords[0] in frame.exterior.coords or space.touches(frame.exterior):
            continue  # the outside
        if roofed is None or space.intersection(roofed).area >= ROOM_COVER * space.area:
            rooms.append(space)
        else:
            yards += 1
    region = shapely.unary_union([union, *rooms])
    parts = list(getattr(region, "geoms", [region]))
    return Plan(origin, footprints, grown, parts, gap, yards)


def _level_plan(shapely: Any, levels: Sequence[Tuple[np.ndarray, np.ndarray]], origin: Any) -> Any:
    """Return the union of the levels' triangles projected on the ground (their real plan)."""
    tris = []
    for v, f in levels:
        xy = v[:, :2] - origin
        for a, b, c in f:
            tri = shapely.Polygon([tuple(xy[a]), tuple(xy[b]), tuple(xy[c])])
            if tri.area > 0.0:
                tris.append(tri)
    return shapely.unary_union(tris)


def footprint(vertices: np.ndarray, origin: np.ndarray) -> Any:
    """Return a solid's footprint: the convex hull of its vertices in plan, about ``origin``.

    Parameters
    ----------
    vertices : (k, 3) float
        The solid's vertices [m].
    origin : (2,) float
        The plan origin [m] the footprint is relative to (the scene's centre: small
        coordinates for a georeferenced scene).

    Returns
    -------
    shapely.Polygon
    """
    shapely = require("shapely", "geometry", "to read the plan of a search")
    return shapely.MultiPoint([tuple(p) for p in vertices[:, :2] - origin]).convex_hull


def least_width(poly: Any) -> float:
    """Return the smaller side of a footprint's least rotated rectangle [m] (0: a line)."""
    rect = poly.minimum_rotated_rectangle
    coords = np.asarray(getattr(rect, "exterior", rect).coords, dtype=float)
    if len(coords) < 4:
        return 0.0
    sides = np.linalg.norm(np.diff(coords[:3], axis=0), axis=1)
    return float(sides.min())


def outer_side(reading: FaceReading, name: str) -> Tuple[Optional[int], List[str]]:
    """Which face is outer: 0 (the lowest ``n``), 1 (the highest), or None (undecided).

    Returns the choice and the notes that explain a choice that is not plain (a face partly
    held by other walls, a courtyard face, a wall inside the building, a wall whose two
    faces are both outside).
    """
    lo, hi = reading.exposed
    notes: List[str] = []
    if lo > 0.0 and hi == 0.0:
        side = 0
    elif hi > 0.0 and lo == 0.0:
        side = 1
    elif lo == 0.0 and hi == 0.0:
        notes.append(
            f"{name}: both faces lie inside the building (an inner wall): its inner side is "
            "taken to face the centre of its building's plan"
        )
        return None, notes
    elif lo >= 1.0 and hi >= 1.0:
        return None, notes  # a lone wall: both faces wholly outside
    else:
        side = 0 if lo >= hi else 1
        notes.append(
            f"{name}: both faces are partly outside the building ({100 * lo:.0f} % and "
            f"{100 * hi:.0f} % of their length): its outer face is taken as the more exposed one"
        )
    if reading.courtyard[side]:
        notes.append(f"{name}: its outer face is on a courtyard of its building")
    return side, notes
