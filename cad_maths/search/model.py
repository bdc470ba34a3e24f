"""A building for the search: walls as prisms, their junctions, levels and ties.

``building_from_scene`` reads the objects a search spec names and returns a
:class:`Building`:

* every wall is one solid, taken as a right prism: its elevation (outer boundary, openings
  as holes) in its own frame (``s`` along it, ``n`` through it from the outer face, ``z``
  up; ``e_n`` points into the building) and its thickness. A wall that is not an exact
  prism (a pocket, a scan's relief, an oblique end, a lean) is idealised as the prism on its
  base that keeps its mass and the lesser lever of its weight about the base's edges
  (theory §10.9), and a note says so; the builder still computes its constants from the
  real solid, and the search reports the difference;
* a wall B whose end face abuts the inner face of a façade A at one of A's ends is a
  return wall of A there, with the connection the spec gives (good: a crack through B runs
  at least at the bond angle ``atan(l_u / 2 h_u)`` from the vertical; poor: A parts from
  B; tied: A does not part from B). A return wall flush with A's end makes a corner;
* a level touches a wall along its largest contact (``mechanisms.loaded.largest_contact``,
  as the builder finds it): a horizontal contact bears, a vertical one abuts; a roof that
  is not tied thrusts outward (``thrust.roof_thrust``, span and rise from its bounding box
  in the wall's frame, as the builder computes them);
* a tie-bar meets a façade where its line crosses the façade's outer face;
* the ground is the lowest wall base: a wall stands on it (within ``GROUND_RTOL`` of its
  thickness) or on a level, read as fixed on the level, which is no load on it; a wall
  standing on nothing, or drawn on another wall's top, is refused (``_check_bases``).

Python 3.9-clean: imported by Rhino 8.
"""

import dataclasses
import math
import uuid
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Set, Tuple, cast

import numpy as np

from cad_maths.geometry.contact import contact_region
from cad_maths.geometry.frames import bounding_box_in_frame
from cad_maths.geometry.massprops import mass_properties
from cad_maths.geometry.mesh import TriMesh
from cad_maths.geometry.validate import check_solid
from cad_maths.mechanisms.loaded import BEARING_ANGLE, contact_tolerance
from cad_maths.mechanisms.single import find_objects
from cad_maths.mechanisms.thrust import roof_thrust
from cad_maths.scene_base import SceneObject
from cad_maths.search.plan import (
    FaceReading,
    Plan,
    footprint,
    least_width,
    outer_side,
    read_plan,
)
from cad_maths.search.prism import (
    PIER_ASPECT_MIN,
    PLUMB_TOL_DEG,
    FirstMoments,
    Lump,
    WallAxes,
    WallFrame,
    clip_rings,
    frame_from_mesh,
    ring_moments,
)
from cad_maths.search.scene import OPENINGS_SUFFIX, MemoryScene
from shared_schema.errors import GeometryError, InputError
from shared_schema.extras import require
from shared_schema.rules import G

__all__ = [
    "PRISM_RTOL",
    "Building",
    "LevelContact",
    "ReturnWall",
    "TiePoint",
    "Wall",
    "building_from_scene",
    "outer_face_crossing",
]

#: A wall whose volume equals its elevation area times its thickness to this relative
#: tolerance is an exact prism (the search's geometry is then the builder's, to rounding).
PRISM_RTOL = 1e-9
#: A wall whose top is offset from its base by less than this fraction of its thickness is
#: read as drawn (a scan's relief, a trowel's wander: it moves the bare wall's λ0 by less than
#: this fraction, and the builder's comparison still reports it); more is out of plumb, read
#: as the plumb prism on its base with a note (``_lean_note``).
LEAN_RTOL = 0.01
#: A wall that is not a prism has its base within this fraction of its height of its lowest
#: point: its idealised prism's outer face is the base's (where it rocks; a scan's relief above
#: it does not move the hinge), as the builder's axis must touch the base (``TOUCH_RTOL``).
BASE_RTOL = 1e-3
#: Smallest |cos| between a face normal and the thickness direction for a face of the outer
#: side (faces within 60 degrees).
FACE_COS = 0.5
#: An inner wall whose centre lies within this fraction of the building's size of the plan's
#: centre line (across the wall) is on it: its sides follow a fixed rule, said in a note.
CENTRE_RTOL = 1e-6
#: Largest angle between two walls' directions taken as perpendicular [rad].
SQUARE_TOL = 1e-3
#: Footprints sharing less than this fraction of the smaller one's area do not overlap (the
#: rounding of a shared face).
OVERLAP_RTOL = 1e-9
#: A wall whose base is within this fraction of its thickness of the ground (the lowest wall
#: base) stands on the ground, as walls that close join (``plan.GAP_RTOL``); higher, it must
#: stand on a level, or it is refused.
GROUND_RTOL = 0.1
#: Walls drawn further apart than the joining gap but within this fraction of the thinner
#: one's thickness nearly meet: a note gives the gap and reads them as not meeting.
NEAR_RTOL = 1.0
#: The name a wall trimmed where it ran into another wall gains.
TRIMMED = " (trimmed)"
#: Namespace of the ids of walls with openings cut out of them.
NAMESPACE = uuid.UUID("2b5d8c1e-6f0a-4f4e-9a3b-7d1c0e9f3a51")


@dataclass
class Wall:
    """One wall as a prism.

    Attributes
    ----------
    id : str
        The spec's wall id.
    selector : selector
        How the mechanism spec selects its solid.
    obj : SceneObject
        Its object in the search's scene.
    density : float
        [kg/m³].
    label : str or None
        Material name.
    is_facade : bool
        Whether its own mechanisms are searched.
    overburden : Overburden or None
        The spec's overburden for vertical flexure.
    frame : WallFrame
        Its frame (``e_n`` into the building) and thickness [m].
    rings : list of (k, 2) float
        Elevation (s, z) [m]: the outer boundary counter-clockwise, holes clockwise.
    length : float
        Extent along ``e_s`` [m] (``s`` in [0, length]).
    z_lo, z_hi : float
        Base and top heights [m].
    exact : bool
        Whether the solid is an exact prism.
    holes : list of (s0, s1, z0, z1)
        Bounding boxes of the openings in the elevation [m].
    volume : float
        Volume of the solid [m³].
    held_by : list of (str, float, float)
        Walls standing against the outer face: ``(wall id, s0, s1)`` with the stretch of the
        face they cover [m]; the wall cannot move outward (``plan.Plan.read_faces``).
    building : int
        Index of its building in the plan (several buildings in one scene).
    prism_density : float
        Density of its idealised prism [kg/m³]: ``density``, or for a wall that is not an
        exact prism the density that keeps its mass at the idealised thickness (0: the same).
    """

    id: str
    selector: Any
    obj: SceneObject
    density: float
    label: Optional[str]
    is_facade: bool
    overburden: Any
    frame: WallFrame
    rings: List[np.ndarray]
    length: float
    z_lo: float
    z_hi: float
    exact: bool
    holes: List[Tuple[float, float, float, float]]
    volume: float
    held_by: List[Tuple[str, float, float]] = field(default_factory=list)
    building: int = 0
    prism_density: float = 0.0

    @property
    def lump_density(self) -> float:
        """Density of the idealised prism [kg/m³] (the spec's for an exact prism)."""
        return self.prism_density or self.density

    @property
    def mesh(self) -> TriMesh:
        """The wall's solid [m]."""
        return cast(TriMesh, self.obj.geometry)

    def region(self, planes: Sequence[Tuple[np.ndarray, np.ndarray]]) -> List[np.ndarray]:
        """Return the elevation kept by half-spaces ``normal·(x - point) >= 0``.

        Each plane must contain the wall's thickness direction ``e_n``.

        Raises
        ------
        GeometryError
            A plane does not contain the wall's thickness direction.
        """
        rings = list(self.rings)
        for k, (point, normal) in enumerate(planes):
            line = self.frame.line_of_plane(point, normal)
            if line is None:
                raise GeometryError(
                    f"{self.id}: a crack plane cuts the wall obliquely through its thickness"
                )
            if k > 0:
                rings = clip_rings(rings, *line)
                continue
            # A mechanism's first plane (its hinge line's cut) is the same at every
            # evaluation of its refinement: the wall clipped by it is kept, by the line.
            clips: Dict[Tuple[float, float, float], List[np.ndarray]]
            clips = self.__dict__.setdefault("_first_clips", {})
            kept = clips.get(line)
            if kept is None:
                if len(clips) >= FIRST_CLIPS_MAX:
                    clips.clear()
                kept = clips[line] = clip_rings(rings, *line)
            rings = list(kept)
        return rings

    def lump(self, planes: Sequence[Tuple[np.ndarray, np.ndarray]]) -> Lump:
        """Mass moments of the part of the wall the half-spaces keep."""
        return self.frame.prism_lump(self.region(planes), self.lump_density)

    def first_moments(self, planes: Sequence[Tuple[np.ndarray, np.ndarray]]) -> FirstMoments:
        """Mass and first moment of the part of the wall the half-spaces keep (``lump``'s)."""
        return self.frame.prism_first_moments(self.region(planes), self.lump_density)

    @property
    def inner_face(self) -> float:
        """``n`` of the inner face of the solid [m] (the thickness, for a prism)."""
        cached = self.__dict__.get("_inner")
        if cached is None:
            cached = float(self.frame.to_frame(self.mesh.vertices)[:, 1].max())
            self.__dict__["_inner"] = cached
        return float(cached)

    def to_end(self, s: float) -> np.ndarray:
        """Plan point (2,) of the wall's centre line at ``s`` along it [m]."""
        return np.asarray(self.frame.to_world(s, 0.5 * self.frame.thickness, 0.0)[:2], dtype=float)

    @property
    def mass(self) -> float:
        """Mass of the idealised prism [kg]."""
        return float(self.lump_density * self.frame.thickness * ring_moments(self.rings)[0])


@dataclass
class ReturnWall:
    """A wall meeting a façade at one of its ends.

    Attributes
    ----------
    wall : Wall
        The return wall.
    end : {"start", "end"}
        The façade's end (``s = 0`` or ``s = length``).
    connection : {"good", "poor", "tied"}
        From the spec.
    beta_bond : float
        Smallest crack angle from the vertical the bond allows [rad] (0 unless good).
    corner : bool
        The return wall is flush with the façade's end (a free corner).
    span : (float, float)
        The return wall's extent along the façade's ``s`` [m].
    reach : float
        Its length into the building from the façade's inner face [m].
    far_end_wall : str or None
        The wall its far end abuts, if any.
    """

    wall: Wall
    end: str
    connection: str
    beta_bond: float
    corner: bool
    span: Tuple[float, float]
    reach: float
    far_end_wall: Optional[str] = None


@dataclass
class LevelContact:
    """A level's largest contact with a wall.

    Attributes
    ----------
    level : Level
        The spec's level.
    index : int
        Its index in the spec's ``levels``.
    wall : str
        The wall id.
    bearing : bool
        A horizontal contact (within ``BEARING_ANGLE``): its weight share acts on the wall.
    area : float
        [m²].
    point : (3,) float
        Contact centroid [m].
    mass : float
        Share carried by the wall, ``tributary`` times the mass of the level's solids that
        touch it (a level drawn as several slabs loads each wall with the slabs on it) [kg].
    thrust : float
        Outward roof thrust at the contact [N] (0 for floors and tied trusses).
    z_range : (float, float)
        Lowest and highest point of the level's solids [m].
    regions : list of ContactPlane
        Every contact of the level's solids with the wall (``contact.contact_region``),
        which a mechanism clips to its moving parts as the builder finds them.
    meshes : list of TriMesh
        The level's solids.
    weight : float
        The level's whole weight [N].
    objects : list of selector
        The level's objects that touch the wall (``{"id": ...}``), where they are fewer
        than the level's; empty: all of them.
    """

    level: Any
    index: int
    wall: str
    bearing: bool
    area: float
    point: np.ndarray
    mass: float
    thrust: float
    z_range: Tuple[float, float] = (0.0, 0.0)
    regions: List[Any] = field(default_factory=list)
    meshes: List[TriMesh] = field(default_factory=list)
    weight: float = 0.0
    objects: List[Any] = field(default_factory=list)


@dataclass
class TiePoint:
    """Where a tie-bar meets a façade's outer face.

    Attributes
    ----------
    index : int
        Its index in the spec's ``tie_bars``.
    tie : TieBar
        The spec's tie-bar.
    wall : str
        The façade's id.
    point : (3,) float
        The crossing with the outer face [m].
    s, z : float
        The point in the façade's elevation [m].
    pull : (3,) float
        Horizontal unit vector of its pull on the façade: the façade's inward normal, towards
        its anchorage inside the building.
    """

    index: int
    tie: Any
    wall: str
    point: np.ndarray
    s: float
    z: float
    pull: np.ndarray


#: Walls clipped by a first plane kept per wall (``Wall.region``), at most.
FIRST_CLIPS_MAX = 512


@dataclass
class RegionTable:
    """A wall's level contact regions, stacked for screening (``Building.region_table``).

    Attributes
    ----------
    entries : list of (LevelContact, int, ContactPlane)
        Each region with its contact and its index in the contact's ``regions``.
    vertices : (n, 3) float
        Every region's ring vertices in world coordinates [m], region after region.
    starts : (k,) int
        Index in ``vertices`` of each region's first vertex.
    scale : float
        Largest coordinate magnitude of the vertices, at least 1 [m].
    moments : list of (float, float, float) or None
        Each whole region's area [m²] and first moments [m³] in its own (u, v), once
        computed.
    rings : list of list of [s, z]
        Each region's rings as Python lists (``prism.clip_point_rings``) [m].
    axes : list of (list, list, list)
        Each region's ``u``, ``v`` and ``origin`` as Python lists.
    extents : list of float
        Each region's larger side of its bounding box in its own (u, v) [m].
    """

    entries: List[Tuple["LevelContact", int, Any]]
    vertices: np.ndarray
    starts: np.ndarray
    scale: float
    moments: List[Optional[Tuple[float, ...]]] = field(default_factory=list)
    rings: List[List[List[List[float]]]] = field(default_factory=list)
    axes: List[Tuple[List[float], List[float], List[float]]] = field(default_factory=list)
    extents: List[float] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.moments:
            self.moments = [None] * len(self.entries)
        regions = [region for _, _, region in self.entries]
        self.rings = [[ring.tolist() for ring in region.rings] for region in regions]
        self.axes = [(g.u.tolist(), g.v.tolist(), g.origin.tolist()) for g in regions]
        self.extents = []
        for region in regions:
            pts = np.vstack(list(region.rings))
            self.extents.append(float(max(np.ptp(pts[:, 0]), np.ptp(pts[:, 1]))))


@dataclass
class Building:
    """What the search knows of the building.

    Attributes
    ----------
    scene : MemoryScene
        The objects used, in metres.
    walls : dict of str to Wall
        By id, in spec order.
    returns : dict of str to list of ReturnWall
        Per façade, its return walls.
    contacts : dict of str to list of LevelContact
        Per wall, the levels touching it.
    ties : dict of str to list of TiePoint
        Per façade, the tie-bars meeting it.
    notes : list of str
        What the reading assumed or idealised.
    spec : SearchSpec
        The search spec.
    """

    scene: MemoryScene
    walls: Dict[str, Wall]
    returns: Dict[str, List[ReturnWall]]
    contacts: Dict[str, List[LevelContact]]
    ties: Dict[str, List[TiePoint]]
    notes: List[str]
    spec: Any
    level_objects: Dict[str, List[SceneObject]] = field(default_factory=dict)
    contact_tol: float = 0.0
    _thrusts: Dict[Tuple[int, Tuple[float, ...]], float] = field(default_factory=dict)
    _region_tables: Dict[str, "RegionTable"] = field(default_factory=dict)

    def roof_thrust(self, contact: "LevelContact", d: np.ndarray) -> float:
        """Outward thrust of a roof on a mechanism collapsing along ``d`` [N].

        Span along ``d`` and rise from the roof's bounding box in the mechanism's frame, as
        the builder computes them (``thrust.roof_thrust``, theory §5).
        """
        key = (contact.index, tuple(round(float(v), 15) for v in d))
        if key not in self._thrusts:
            axis = np.cross(np.array([0.0, 0.0, 1.0]), d)
            boxes = [bounding_box_in_frame(m, np.zeros(3), d, axis) for m in contact.meshes]
            lo = np.min([b[0] for b in boxes], axis=0)
            hi = np.max([b[1] for b in boxes], axis=0)
            ext = hi - lo
            self._thrusts[key] = roof_thrust(
                contact.weight, float(ext[0]), float(abs(ext[2])), not contact.level.pushes
            )
        return self._thrusts[key]

    def region_table(self, wall: str) -> "RegionTable":
        """Every level contact region of a wall with its vertices in world coordinates.

        Computed once per wall; ``families.contact_hits`` screens whole regions against a
        moving part's half-spaces with it before it clips any.
        """
        if wall not in self._region_tables:
            entries: List[Tuple[LevelContact, int, Any]] = []
            points: List[np.ndarray] = []
            starts: List[int] = []
            n = 0
            for c in self.contacts.get(wall, []):
                for j, region in enumerate(c.regions):
                    flat = np.vstack(list(region.rings))
                    world = region.origin + flat[:, :1] * region.u + flat[:, 1:2] * region.v
                    entries.append((c, j, region))
                    points.append(world)
                    starts.append(n)
                    n += len(world)
            vertices = np.vstack(points) if points else np.zeros((0, 3))
            scale = float(np.abs(vertices).max()) if len(vertices) else 0.0
            self._region_tables[wall] = RegionTable(
                entries, vertices, np.array(starts, dtype=np.intp), max(scale, 1.0)
            )
        return self._region_tables[wall]

    @property
    def size(self) -> float:
        """Diagonal of the walls' bounding box [m] (computed once for the same walls)."""
        key = tuple(id(w.mesh) for w in self.walls.values())
        cached = self.__dict__.get("_size")
        if cached is None or cached[0] != key:
            v = np.vstack([w.mesh.vertices for w in self.walls.values()])
            cached = (key, float(np.linalg.norm(v.max(axis=0) - v.min(axis=0))))
            self.__dict__["_size"] = cached
        return float(cached[1])

    def free_standing(self, wall: str) -> bool:
        """Tell whether nothing holds either face of a wall (no return walls, levels, ties)."""
        return not (self.returns.get(wall) or self.contacts.get(wall) or self.ties.get(wall))


# --- reading -------------------------------------------------------------------------------


def _find(scene: Any, selectors: Sequence[Any], where: str) -> List[SceneObject]:
    """``find_objects``, with a miss named by the search spec's field."""
    try:
        return find_objects(scene, selectors, where)
    except InputError as exc:
        if exc.field == "selector":
            raise InputError(exc.reason, where) from None
        raise


def _solid(scene: Any, obj: SceneObject, selector: Any, where: str) -> Tuple[TriMesh, List[str]]:
    """Return the object's checked solid, naming its selector when it is no solid.

    ``where`` is the spec's field (``walls[0].object``) and ``selector`` what it gave: the
    message says what the selector matched (a line, an open mesh) and what to select.
    """
    try:
        return check_solid(scene.mesh(obj))
    except GeometryError as exc:
        raise GeometryError(f"{where}: {selector!r} matches {exc}") from None


def _line(scene: Any, obj: SceneObject, selector: Any, where: str) -> Tuple[np.ndarray, np.ndarray]:
    """Return the object's end points, naming its selector when it is no line."""
    try:
        start, end = scene.line(obj)
    except GeometryError as exc:
        raise GeometryError(f"{where}: {selector!r} matches {exc}") from None
    return np.asarray(start, dtype=float), np.asarray(end, dtype=float)


def _one_object(scene: Any, selector: Any, where: str) -> SceneObject:
    objs = _find(scene, [selector], where)
    if len(objs) != 1:
        names = ", ".join(o.label() for o in objs[:6])
        raise InputError(
            f"{selector!r} matches {len(objs)} objects ({names}); a wall is one solid: select "
            "one object (join the pieces of a wall into one solid)",
            where,
        )
    return objs[0]


def _boundary_rings(v2: np.ndarray, faces: np.ndarray) -> List[np.ndarray]:
    """Boundary loops of a set of triangles, as rings of 2-D points."""
    edges: Dict[Tuple[int, int], int] = {}
    for a, b, c in faces:
        for e in ((a, b), (b, c), (c, a)):
            edges[(int(e[0]), int(e[1]))] = 1
    nxt: Dict[int, int] = {}
    for a, b in edges:
        if (b, a) not in edges:
            nxt[a] = b
    rings: List[np.ndarray] = []
    seen = set()
    for start in sorted(nxt):
        if start in seen:
            continue
        loop = [start]
        seen.add(start)
        cur = nxt[start]
        while cur != start:
            if cur in seen or cur not in nxt:
                raise GeometryError("the wall's face has a non-manifold outline")
            loop.append(cur)
            seen.add(cur)
            cur = nxt[cur]
        pts = v2[loop]
        rings.append(_drop_collinear(pts))
    return [r for r in rings if len(r) >= 3]


def _drop_collinear(pts: np.ndarray) -> np.ndarray:
    keep = []
    n = len(pts)
    scale = float(np.max(np.abs(pts))) if n else 1.0
    for i in range(n):
        a, b, c = pts[i - 1], pts[i], pts[(i + 1) % n]
        cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
        if abs(cross) > 1e-14 * max(scale, 1.0) ** 2:
            keep.append(b)
    return np.array(keep, dtype=float)


def _signed_area(ring: np.ndarray) -> float:
    return float(ring_moments([ring])[0])


def _elevation(mesh: TriMesh, frame: WallFrame, name: str) -> List[np.ndarray]:
    """Outer boundary (counter-clockwise) and holes (clockwise) of the outer face."""
    v = mesh.vertices
    tri = v[mesh.faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(normal, axis=1)
    ok = norm > 0.0
    cosn = np.zeros(len(norm))
    cosn[ok] = -(normal[ok] @ frame.e_n) / norm[ok]
    outer = mesh.faces[cosn > FACE_COS]
    if len(outer) == 0:
        raise GeometryError(f"{name}: no face looks out of the building")
    local = frame.to_frame(v)
    rings = _boundary_rings(local[:, [0, 2]], outer)
    if not rings:
        raise GeometryError(f"{name}: the outer face has no outline")
    areas = [abs(_signed_area(r)) for r in rings]
    k = int(np.argmax(areas))
    out = rings[k] if _signed_area(rings[k]) > 0.0 else rings[k][::-1]
    result = [out]
    for i, r in enumerate(rings):
        if i == k:
            continue
        if not np.all(
            (r[:, 0] >= out[:, 0].min() - 1e-9)
            & (r[:, 0] <= out[:, 0].max() + 1e-9)
            & (r[:, 1] >= out[:, 1].min() - 1e-9)
            & (r[:, 1] <= out[:, 1].max() + 1e-9)
        ):
            raise GeometryError(
                f"{name}: the outer face is in several pieces; a wall is one slab (split it "
                "into walls)"
            )
        result.append(r if _signed_area(r) < 0.0 else r[::-1])
    return result


def _orient(
    mesh: TriMesh,
    plan: Plan,
    size: float,
    name: str,
    levels: Optional[np.ndarray] = None,
) -> Tuple[WallFrame, List[np.ndarray], float, bool, List[str], Tuple[Any, int, float]]:
    """Return the wall's frame (e_n into the building), elevation, prism check and plan.

    The last item is what holds the outer face (``Wall.held_by``), the wall's building and
    the factor on its density that keeps the idealised prism's mass (1 for an exact prism).
    The outer face is the one the plan finds on the outside (``plan.outer_side``). A lone
    wall (both faces outside) faces the levels it carries with its inner side (issue #37),
    or, without levels, follows a fixed rule; an inner wall faces the centre of its
    building's plan with its inner side.
    """
    v = mesh.vertices
    com = v.mean(axis=0)
    axes = frame_from_mesh(v, mesh.faces, name, None if levels is None else levels - com)
    e_n, e_s = axes.e_n, axes.e_s
    reading = plan.read_faces(name, e_n, e_s, v[:, :2])
    flip, lone_notes = _outer_is_first(plan, reading, com, e_n, levels, size, name)
    if flip:
        axes = axes.flipped()
        e_n, e_s = axes.e_n, axes.e_s
    e_z = np.array([0.0, 0.0, 1.0])
    z_lo = float(v[:, 2].min())
    n = v @ e_n
    offset = abs(axes.lean) * (float(v[:, 2].max()) - z_lo)
    leans = offset > LEAN_RTOL * float(n.max() - n.min() - offset)
    if leans:  # out of plumb: read as the plumb prism on its base (n measured off the lean)
        n = n - axes.lean * (v[:, 2] - z_lo)
    else:
        axes = dataclasses.replace(axes, lean=0.0)
    s = v @ e_s
    t = float(n.max() - n.min())
    origin = float(s.min()) * e_s + float(n.min()) * e_n
    frame = WallFrame(origin, e_s, e_n, e_z, t)
    rings = _elevation(mesh, frame, name)
    area = float(ring_moments(rings)[0])
    props = mass_properties(mesh, 1.0)
    volume = float(props.volume)
    moments = ring_moments(rings)
    height = (float(v[:, 2].max()) - z_lo, float(moments[2] / moments[0]) - z_lo)
    prism = abs(volume - area * t) <= PRISM_RTOL * volume
    exact = prism and not leans
    t_eff, scale = t, 1.0
    if leans or not prism:
        # The idealised prism on the base keeps the solid's mass and the lesser of its
        # weight's two levers about the base's edges: twice that lever is its thickness, a
        # density keeps the mass (theory §10.9). It overturns as the solid does the way
        # the solid resists least, and no less than the solid the other way.
        base = v[:, 2] <= z_lo + BASE_RTOL * height[0]
        lo, hi = float(n[base].min()), float(n[base].max())
        origin = float(s.min()) * e_s + lo * e_n
        depth = float(props.com @ e_n) - lo  # the lean's shift included
        lever = min(depth, (hi - lo) - depth)
        t_eff = 2.0 * lever if lever > 0.0 else (t if leans else volume / area)
        scale = volume / (area * t_eff)
        frame = WallFrame(origin, e_s, e_n, e_z, t_eff)
    notes: List[str] = lone_notes + _axes_notes(axes, name, height, t, t_eff)
    if not prism:
        notes.append(
            f"{name}: not a prism of constant thickness (volume {volume:.6g} m³, outer face "
            f"{area:.6g} m² x {t:.6g} m): the search idealises it with the thickness "
            f"{t_eff:.6g} m, twice the lesser lever of its weight about its base's edges "
            f"(the centroid's depth behind the outer one, or before the inner one), and "
            f"{scale:.6g} times its density, so that the prism keeps its mass and overturns "
            "as the solid does the way it resists least; the constants come from the real "
            "solid and the search reports the difference"
        )
    held = _held_by(plan, reading.covered[1 if flip else 0], e_s if not flip else -e_s, frame)
    return frame, rings, volume, exact, notes, (held, reading.building, scale)


def _outer_is_first(
    plan: Plan,
    reading: FaceReading,
    com: np.ndarray,
    e_n: np.ndarray,
    levels: Optional[np.ndarray],
    size: float,
    name: str,
) -> Tuple[bool, List[str]]:
    """Tell whether the wall's frame is to be flipped so that e_n points into the building.

    The outer face is the one the plan finds on the outside (``plan.outer_side``); a lone
    wall faces the levels it carries with its inner side, or follows a fixed rule; an inner
    wall faces the centre of its building's plan (``_orient``).

    Parameters
    ----------
    plan : Plan
        The buildings' plans.
    reading : FaceReading
        The plan's reading of the wall's two faces (``plan.read_faces``).
    com : numpy.ndarray
        The wall's mean vertex [m].
    e_n : numpy.ndarray
        The frame's normal as found (unit).
    levels : numpy.ndarray, optional
        A point of the levels the wall carries [m].
    size : float
        The building's size [m].
    name : str
        The wall's name, for the notes.

    Returns
    -------
    flip : bool
        Flip the frame.
    notes : list of str
        How a lone or inner wall's sides were named.
    """
    outer, lone_notes = outer_side(reading, name)
    toward = None if levels is None else float((levels - com) @ e_n)
    if outer is not None:
        flip = outer == 1  # e_n points from the outer face into the building
    elif reading.exposed[0] == 0.0:  # an inner wall: inner side towards its plan's centre
        c = np.asarray(plan.parts[reading.building].centroid.coords[0]) + plan.origin
        ahead = float((c - com[:2]) @ e_n[:2])
        if abs(ahead) <= CENTRE_RTOL * size:
            # on the centre line: a fixed rule (e_n towards +x, else +y) names its sides
            flip = e_n[0] < -1e-12 or (abs(e_n[0]) <= 1e-12 and e_n[1] < 0.0)
            lone_notes.append(
                f"{name}: an inner wall on its building's centre line; its sides are named by "
                "a fixed rule (its inner side towards +x, else +y): 'outward' and 'inward' "
                "are the two directions across it"
            )
        else:
            flip = ahead < 0.0
    elif toward is not None and abs(toward) > 1e-9 * size:
        flip = toward < 0.0
        lone_notes.append(
            f"{name}: a lone wall; its inner side is taken to face the levels it carries "
            "(its outward mechanisms move away from them)"
        )
    else:
        # A lone wall without levels: a fixed rule (e_n towards +x, else +y) names its sides.
        flip = e_n[0] < -1e-12 or (abs(e_n[0]) <= 1e-12 and e_n[1] < 0.0)
    return flip, lone_notes


def _axes_notes(
    axes: WallAxes, name: str, height: Tuple[float, float], t: float, t_eff: float
) -> List[str]:
    """Return the notes of a pier's frame and of a wall read as plumb (``prism.frame_from_mesh``).

    ``height`` is the wall's height and its elevation's centroid height above its base [m];
    ``t`` the wall's thickness across (its plumb section) and ``t_eff`` its idealised
    prism's [m].
    """
    notes = []
    long_side, short_side = axes.plan
    if axes.square:
        rule = (
            "the side that faces the levels it carries"
            if axes.rule == "levels"
            else "the side nearer the x axis (a fixed rule)"
        )
        notes.append(
            f"{name}: a square pier ({long_side:.3f} x {short_side:.3f} m in plan), which "
            f"overturns alike across either side as a bare block: its thickness is taken "
            f"across {rule}, and only that direction is searched (a load that differs by "
            "direction, a roof's thrust, needs a mechanism spec for the other)"
        )
    elif axes.pier:
        notes.append(
            f"{name}: a pier ({long_side:.3f} x {short_side:.3f} m in plan, sides in a ratio "
            f"{long_side / short_side:.3g} below {PIER_ASPECT_MIN:g}): its thickness is read "
            f"across its shorter side ({short_side:.3f} m), about which the bare block "
            "overturns first; its overturning across the longer side (λ0 "
            f"{long_side / short_side:.3g} times as large for the bare block) is not searched"
        )
    if axes.lean != 0.0:
        notes.append(_lean_note(axes, name, height, t, t_eff))
    return notes


def _lean_note(
    axes: WallAxes, name: str, height: Tuple[float, float], t: float, t_eff: float
) -> str:
    """Return the note of a wall out of plumb, read as a plumb prism on its base (module doc).

    Notes
    -----
    The real solid's centre of mass lies ``lean * z_c`` off its base's middle along ``e_n``
    (``z_c`` the centroid's height above the base): for the whole wall overturning outward
    about its base as a bare wall, the real λ0 is ``(t + 2 lean z_c) / t`` times a plumb
    prism's ``t / h`` (above 1 for a lean inward). The idealised prism, ``t_eff`` thick,
    keeps the lesser of the weight's two levers about the base's edges (theory §10.9).
    """
    h, z_c = height
    deg = math.degrees(math.atan(abs(axes.lean)))
    way = "inward" if axes.lean > 0.0 else "outward"
    shift = axes.lean * z_c
    lo, hi = (math.degrees(math.atan(x)) for x in axes.lean_faces)
    faces = (
        f" (its outer face {lo:.2f} and its inner face {hi:.2f} degrees: a batter)"
        if abs(lo - hi) > 1e-6
        else ""
    )
    ratio = (t + 2.0 * shift) / t
    said = (
        f"{name}: {deg:.2f} degrees out of plumb{faces}, its top {abs(axes.lean) * h:.3f} m "
        f"{way} of its base over its {h:.3f} m height (within {PLUMB_TOL_DEG:g} degrees): the "
        f"search idealises it as a plumb prism standing on its base, of the same mass, "
        f"{t_eff:.3f} m thick: twice the lesser lever of its weight about its base's edges "
        f"(the wall is {t:.3f} m thick across, and its centre of mass lies {abs(shift):.3f} m "
        f"{way} of its base's middle); the builder's constants use the real solid, and the "
        f"search reports the difference (for the bare wall overturning outward about its "
        f"base, the real λ0 is {ratio:.3g} times a plumb {t:.3f} m prism's, "
        f"{(t + 2.0 * shift) / t_eff:.3g} times the idealised one's)"
    )
    if abs(shift) >= 0.5 * t:
        said += (
            f"; its centre of mass lies beyond its base's {'inner' if shift > 0.0 else 'outer'} "
            "edge: alone it would fall, and it stands only as the walls and levels around it "
            "hold it"
        )
    return said


def _held_by(
    plan: Plan, covers: List[Tuple[str, float, float]], e_s_plan: np.ndarray, frame: WallFrame
) -> List[Tuple[str, float, float]]:
    """Return the plan's covers of the outer face, with ``s`` in the wall's frame [m]."""
    out = []
    for other, a, b in covers:
        ends = []
        for si in (a, b):
            xy = plan.origin + si * np.asarray(e_s_plan[:2], dtype=float)
            ends.append(float(frame.to_frame(np.array([xy[0], xy[1], frame.origin[2]]))[0]))
        out.append((other, min(ends), max(ends)))
    return out


def _holes(rings: List[np.ndarray]) -> List[Tuple[float, float, float, float]]:
    out = []
    for r in rings[1:]:
        out.append(
            (float(r[:, 0].min()), float(r[:, 0].max()), float(r[:, 1].min()), float(r[:, 1].max()))
        )
    return out


def _cut_openings(
    wall_obj: SceneObject, mesh: TriMesh, openings: List[Tuple[SceneObject, TriMesh]], name: str
) -> Tuple[SceneObject, TriMesh, List[str]]:
    """Subtract the opening solids that cross a wall (manifold3d); the wall becomes new."""
    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    hits = [
        (o, m)
        for o, m in openings
        if np.all(m.vertices.max(axis=0) > lo) and np.all(m.vertices.min(axis=0) < hi)
    ]
    if not hits:
        return wall_obj, mesh, []
    obj, cut, notes = _subtract(wall_obj, mesh, hits, name, OPENINGS_SUFFIX)
    said = ", ".join(o.label() for o, _ in hits)
    notes.append(
        f"{name}: the openings {said} are cut out of the wall; the search's scene holds the "
        f"result as a new object {obj.name!r} (id {obj.id}), which the search spec selects"
    )
    return obj, cut, notes


def _subtract(
    wall_obj: SceneObject,
    mesh: TriMesh,
    cutters: List[Tuple[SceneObject, TriMesh]],
    name: str,
    suffix: str,
) -> Tuple[SceneObject, TriMesh, List[str]]:
    """Return the wall less the cutters' solids (manifold3d), as a new object of the scene."""
    manifold3d = require("manifold3d", "geometry", "to cut solids out of walls")
    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    ref = 0.5 * (lo + hi)

    def solid(m: TriMesh) -> Any:
        return manifold3d.Manifold(
            manifold3d.Mesh64(
                vert_properties=np.ascontiguousarray(m.vertices - ref),
                tri_verts=np.ascontiguousarray(m.faces, dtype=np.uint64),
            )
        )

    body = solid(mesh)
    for _, m in cutters:
        body = body - solid(m)
    out = body.to_mesh64()
    verts = np.asarray(out.vert_properties, dtype=np.float64)[:, :3] + ref
    faces = np.asarray(out.tri_verts, dtype=np.int64)
    new_id = str(uuid.uuid5(NAMESPACE, f"{wall_obj.id}/" + "/".join(o.id for o, _ in cutters)))
    base = wall_obj.name or name
    new_name = base if base.endswith(suffix) else base + suffix
    cut = TriMesh(verts, faces, new_name, {"id": new_id, "layer": wall_obj.layer, "kind": "mesh"})
    cut, notes = check_solid(cut)
    obj = SceneObject(new_id, new_name, wall_obj.layer, "mesh", dict(wall_obj.user_text), cut)
    return obj, cut, notes


def _trim_overlaps(raw: List[Tuple[Any, SceneObject, TriMesh, Any]], notes: List[str]) -> None:
    """Trim a wall drawn into another at its end (a CAD corner); refuse other overlaps.

    Walls whose footprints overlap share volume. Where the shared part lies at one wall's
    end and is no deeper along that wall than the other wall's thickness, the wall is read
    as meeting the other's face: it is trimmed there (``_subtract``) and a note gives the
    depth and the volume. Any other overlap is refused with both walls and the volume.
    """
    ref = np.vstack([m.vertices for _, _, m, _ in raw]).mean(axis=0)[:2]
    feet = [footprint(m.vertices, ref) for _, _, m, _ in raw]
    for i in range(len(raw)):
        for j in range(i + 1, len(raw)):
            shared = feet[i].intersection(feet[j])
            small = OVERLAP_RTOL * min(feet[i].area, feet[j].area)
            if shared.area <= small:
                continue
            zi, zj = raw[i][2].vertices[:, 2], raw[j][2].vertices[:, 2]
            dz = min(float(zi.max()), float(zj.max())) - max(float(zi.min()), float(zj.min()))
            if dz <= 0.0:
                continue
            volume = shared.area * dz
            for k, o in ((j, i), (i, j)):  # the later wall is trimmed first
                depth = _end_depth(feet[k], shared)
                if depth is not None and depth <= least_width(feet[o]) * (1.0 + 1e-9):
                    w, obj, mesh, _ = raw[k]
                    new, cut, warn = _subtract(obj, mesh, [(raw[o][1], raw[o][2])], w.id, TRIMMED)
                    notes.extend(warn)
                    notes.append(
                        f"{w.id} runs {depth:.3f} m into {raw[o][0].id} ({volume:.3g} m³ shared): "
                        f"read as meeting its face, and trimmed there; the search's scene holds "
                        f"the trimmed wall as a new object {new.name!r}, which the spec selects"
                    )
                    raw[k] = (w, new, cut, new.name)
                    feet[k] = footprint(cut.vertices, ref)
                    break
            else:
                raise GeometryError(
                    f"the walls {raw[i][0].id} and {raw[j][0].id} overlap by {volume:.3g} m³, "
                    "not at one wall's end within the other's thickness: redraw them to meet "
                    "face to face (a wall is one solid, and two walls share no volume)"
                )


def _end_depth(foot: Any, shared: Any) -> Optional[float]:
    """How far the shared part reaches into a wall from one of its ends [m], or None.

    None where the shared part does not start at an end of the wall's footprint (it lies
    in the wall's middle, or covers it all).
    """
    rect = np.asarray(foot.minimum_rotated_rectangle.exterior.coords, dtype=float)
    sides = np.diff(rect[:3], axis=0)
    axis = sides[int(np.argmax(np.linalg.norm(sides, axis=1)))]
    axis = axis / float(np.linalg.norm(axis))
    along = np.asarray(foot.exterior.coords, dtype=float) @ axis
    part = (
        np.asarray(shared.exterior.coords, dtype=float) @ axis
        if shared.geom_type == "Polygon"
        else None
    )
    if part is None:
        return None
    lo, hi = float(along.min()), float(along.max())
    a, b = float(part.min()), float(part.max())
    eps = 1e-9 * (hi - lo)
    if a <= lo + eps and b < hi - eps:
        return b - lo
    if b >= hi - eps and a > lo + eps:
        return hi - a
    return None


def _unit_angle(unit: Any) -> float:
    return math.atan(unit.length / (2.0 * unit.height))


def _junction(spec: Any, a: str, b: str) -> Tuple[str, Optional[Any], str]:
    found = spec.connection_of(a, b)
    if found is not None:
        return found
    raise InputError(
        f"the walls {a!r} and {b!r} meet, but the spec gives no connection for them; add "
        f'{{"walls": ["{a}", "{b}"], "connection": "good"|"poor"|"tied", ...}} to junctions, '
        "or a default_junction",
        "junctions",
    )


def _return_at(
    a: Wall, b: Wall, tol: float, join: float = 0.0
) -> Optional[Tuple[str, bool, Tuple[float, float], float, float]]:
    """Tell whether wall b meets façade a at one of a's ends.

    Returns ``(end, corner, span, reach, gap)`` or None. Two arrangements count: b's end
    face on a's inner face near a's end (b abuts a), or a's end face on b's side face (a
    butts into b, which runs past a's end). ``corner``: the two walls are flush at the
    outside. Faces up to ``join`` apart [m] (the plan's joining gap) meet; ``gap`` is how
    far apart they are drawn [m].
    """
    fa = a.frame
    if abs(abs(float(b.frame.e_n @ fa.e_s)) - 1.0) > SQUARE_TOL:
        return None
    near = max(tol, join)
    local = fa.to_frame(b.mesh.vertices)
    s0, s1 = float(local[:, 0].min()), float(local[:, 0].max())
    n0, n1 = float(local[:, 1].min()), float(local[:, 1].max())
    z0, z1 = float(local[:, 2].min()), float(local[:, 2].max())
    t_a = float(fa.to_frame(a.mesh.vertices)[:, 1].max())
    if z1 <= a.z_lo + tol or z0 >= a.z_hi - tol or n1 <= t_a + near:
        return None
    if abs(n0 - t_a) <= near and s0 >= -near and s1 <= a.length + near:
        gap = abs(n0 - t_a)
        if s0 <= fa.thickness + near:
            return "start", abs(s0) <= near, (s0, s1), n1 - t_a, gap
        if s1 >= a.length - fa.thickness - near:
            return "end", abs(s1 - a.length) <= near, (s0, s1), n1 - t_a, gap
        return "middle", False, (s0, s1), n1 - t_a, gap
    if n0 <= near:
        if abs(s1) <= near:
            return "start", abs(n0) <= near, (s0, s1), n1 - t_a, abs(s1)
        if abs(s0 - a.length) <= near:
            return "end", abs(n0) <= near, (s0, s1), n1 - t_a, abs(s0 - a.length)
    return None


def _returns(
    walls: Dict[str, Wall], spec: Any, tol: float, notes: List[str], plan: Plan
) -> Dict[str, List[ReturnWall]]:
    out: Dict[str, List[ReturnWall]] = {w: [] for w in walls}
    listed = {tuple(sorted(j.walls)) for j in spec.junctions}
    met: Set[Tuple[str, str]] = set()
    join = plan.gap
    for a in walls.values():
        for b in walls.values():
            if b.id == a.id:
                continue
            found = _return_at(a, b, tol, join)
            if found is None:
                continue
            end, corner, span, reach, gap = found
            pair = (min(a.id, b.id), max(a.id, b.id))
            if gap > tol and pair not in met:
                notes.append(
                    f"{b.id} and {a.id} are drawn {1000 * gap:.3g} mm apart: read as meeting "
                    f"(walls up to {1000 * join:.3g} mm apart join, a tenth of the thinnest "
                    "wall's thickness)"
                )
            met.add(pair)
            if not a.is_facade:
                continue
            if end == "middle":
                notes.append(
                    f"{b.id} meets {a.id} away from its ends (at s = {span[0]:.3f}-{span[1]:.3f} "
                    f"m): the search takes return walls at a façade's ends only, so "
                    f"{a.id}'s mechanisms leave {b.id} out"
                )
                continue
            connection, unit, _ = _junction(spec, a.id, b.id)
            beta = _unit_angle(unit) if connection == "good" and unit is not None else 0.0
            out[a.id].append(ReturnWall(b, end, connection, beta, corner, span, reach))
    _unjoined(walls, plan, tol, notes, met, listed)
    for pair in sorted(listed - met):
        raise InputError(
            f"the junction {list(pair)} is listed, but those walls do not meet (one wall's end "
            "face on the other's face)",
            "junctions",
        )
    # Far ends: a return wall whose far end meets another wall is held there.
    for a_id, rets in out.items():
        fa = walls[a_id].frame
        t_a = float(fa.to_frame(walls[a_id].mesh.vertices)[:, 1].max())
        for r in rets:
            for c in walls.values():
                if c.id in (a_id, r.wall.id):
                    continue
                local = fa.to_frame(c.mesh.vertices)
                near = float(local[:, 1].min()) - (t_a + r.reach)
                far = float(local[:, 1].max()) - (t_a + r.reach)
                lo, hi = float(local[:, 0].min()), float(local[:, 0].max())
                if near <= tol and far >= -tol and lo <= r.span[1] + tol and hi >= r.span[0] - tol:
                    r.far_end_wall = c.id
    return out


def _read_levels(scene: Any, spec: Any) -> List[Tuple[List[SceneObject], List[TriMesh], List[str]]]:
    """Each level's objects, checked solids and their warnings, in spec order."""
    out = []
    for k, level in enumerate(spec.levels):
        where = f"levels[{k}].objects"
        objs = _find(scene, level.objects, where)
        meshes, warns = [], []
        for obj, sel in zip(objs, _selectors_of(scene, level.objects, objs)):
            mesh, warn = _solid(scene, obj, sel, where)
            meshes.append(mesh)
            warns.extend(warn)
        out.append((objs, meshes, warns))
    return out


def _selectors_of(scene: Any, selectors: Sequence[Any], objs: Sequence[SceneObject]) -> List[Any]:
    """Return the selector that found each object (``_find`` keeps their order)."""
    out: List[Any] = []
    for sel in selectors:
        out.extend([sel] * len(scene.find(sel)))
    return out if len(out) == len(objs) else [list(selectors)] * len(objs)


def _level_contacts(
    spec: Any,
    walls: Dict[str, Wall],
    tol: float,
    notes: List[str],
    memory: MemoryScene,
    read: List[Tuple[List[SceneObject], List[TriMesh], List[str]]],
    plan: Plan,
) -> Tuple[
    Dict[str, List[LevelContact]],
    Dict[str, List[SceneObject]],
    Dict[str, List[Tuple[str, float]]],
]:
    """Return the levels' contacts per wall, their objects, and the levels walls stand on.

    A level whose top meets a wall's base (a horizontal contact, the level below) is what
    the wall stands on, not a load on it: the third item gives, per wall, ``(level id, area
    [m²])`` of such contacts.
    """
    out: Dict[str, List[LevelContact]] = {w: [] for w in walls}
    objects: Dict[str, List[SceneObject]] = {}
    under: Dict[str, List[Tuple[str, float]]] = {}
    for k, level in enumerate(spec.levels):
        where = f"levels[{k}]"
        objs, meshes, warns = read[k]
        notes.extend(f"{where}: {w}" for w in warns)
        for obj, mesh in zip(objs, meshes):
            memory.add(SceneObject(obj.id, obj.name, obj.layer, "mesh", dict(obj.user_text), mesh))
        objects[level.id] = objs
        masses = [mass_properties(m, level.density).mass for m in meshes]
        total = sum(masses)
        z_range = (
            float(min(m.vertices[:, 2].min() for m in meshes)),
            float(max(m.vertices[:, 2].max() for m in meshes)),
        )
        touched = []
        carried = []
        for wall in walls.values():
            regions = []
            on = []  # the level's solids that load this wall
            for i, m in enumerate(meshes):
                hit = contact_region(m, wall.mesh, tol=tol)
                if hit is None:
                    continue
                if _is_base(hit, wall, m, tol):
                    under.setdefault(wall.id, []).append((level.id, float(hit[0])))
                    carried.append(wall.id)
                else:
                    regions.append(hit)
                    on.append(i)
            if not regions:
                continue  # this level does not touch this wall, or only carries it
            area, point, normal, _ = max(regions, key=lambda r: r[0])
            # A roof's share always bears where it touches (as the builder takes it).
            bearing = level.kind == "roof" or abs(float(normal[2])) >= math.cos(BEARING_ANGLE)
            thrust = 0.0
            if level.kind == "roof" and level.pushes:
                thrust = _roof_push(level, wall, meshes, total)
            out[wall.id].append(
                LevelContact(
                    level,
                    k,
                    wall.id,
                    bearing,
                    float(area),
                    np.asarray(point, dtype=float),
                    level.tributary * sum(masses[i] for i in on),
                    thrust,
                    z_range,
                    [r[3] for r in regions],
                    meshes,
                    G * total,
                    [{"id": objs[i].id} for i in on] if len(on) < len(meshes) else [],
                )
            )
            touched.append(wall.id)
        if not touched:
            _no_wall_carries(f"{where} ({level.id})", carried, meshes, walls, plan, tol)
        if "tributary" not in level.model_fields_set:
            notes.append(
                f"{where} ({level.id}): tributary not given; each wall it touches carries the "
                f"default {level.tributary:g} of the weight and inertia of its solids on that wall"
            )
    return out, objects, under


def _roof_push(level: Any, wall: Wall, meshes: List[TriMesh], total: float) -> float:
    """Return the horizontal thrust of a pushing roof on a wall it touches [N].

    Parameters
    ----------
    level : LevelSpec
        The roof level (``pushes`` set).
    wall : Wall
        The wall it touches.
    meshes : list of TriMesh
        The roof's solids.
    total : float
        Their mass [kg].

    Returns
    -------
    float
        ``roof_thrust`` of the roof's weight over its span across the wall and its rise.
    """
    lo_hi = [
        bounding_box_in_frame(m, wall.frame.origin, -wall.frame.e_n, wall.frame.e_s) for m in meshes
    ]
    lo = np.min([p[0] for p in lo_hi], axis=0)
    hi = np.max([p[1] for p in lo_hi], axis=0)
    ext = hi - lo
    return roof_thrust(G * total, float(ext[0]), float(abs(ext[2])), not level.pushes)


def _no_wall_carries(
    label: str,
    carried: List[str],
    meshes: List[TriMesh],
    walls: Dict[str, Wall],
    plan: Plan,
    tol: float,
) -> None:
    """Refuse a level that rests on no wall, saying what it does touch.

    Parameters
    ----------
    label : str
        The level's place and id (``levels[k] (id)``).
    carried : list of str
        The walls that stand on it.
    meshes : list of TriMesh
        Its solids.
    walls : dict of str to Wall
        The walls.
    plan : Plan
        The buildings' plans (for the nearest wall).
    tol : float
        The contact tolerance [m].

    Raises
    ------
    GeometryError
        Always: walls stand on it, or it touches no wall.
    """
    if carried:
        raise GeometryError(
            f"{label}: the walls {', '.join(sorted(set(carried)))} stand on it, "
            "and it rests on no wall: a level is carried by walls (on their tops or against "
            "their faces); the ground or a foundation is not a level: remove it from levels"
        )
    raise GeometryError(
        f"{label}: touches no wall (no shared face with any wall solid "
        f"within {1000 * tol:.3g} mm); {_nearest_wall(meshes, walls, plan)}: draw it "
        "onto the walls that carry it (its underside on their tops, or its edge against "
        "their inner faces), or remove it from levels"
    )


def _is_base(hit: Tuple[Any, ...], wall: Wall, level: TriMesh, tol: float) -> bool:
    """Tell whether a level's contact with a wall is the wall's base on the level's top."""
    _, point, normal, _ = hit
    return (
        float(normal[2]) >= math.cos(BEARING_ANGLE)
        and abs(float(point[2]) - wall.z_lo) <= tol
        and float(level.vertices[:, 2].max()) <= wall.z_lo + tol
    )


def _separation(a: np.ndarray, b: np.ndarray, plan: Plan) -> Tuple[float, float, float]:
    """Distance between two solids given by their vertices, as vertical prisms [m].

    Returns ``(distance, in plan, in height)``: the footprints' distance (convex hulls in
    plan) and the gap between the height ranges (0 where they overlap); exact for solids
    that are vertical prisms on convex footprints, as walls and slabs are.
    """
    d_plan = float(footprint(a, plan.origin).distance(footprint(b, plan.origin)))
    lo_a, hi_a = float(a[:, 2].min()), float(a[:, 2].max())
    lo_b, hi_b = float(b[:, 2].min()), float(b[:, 2].max())
    dz = max(lo_b - hi_a, lo_a - hi_b, 0.0)
    return math.hypot(d_plan, dz), d_plan, dz


def _nearest_wall(meshes: Sequence[TriMesh], walls: Dict[str, Wall], plan: Plan) -> str:
    """Say which wall is nearest a level, how far, and which way."""
    v = np.vstack([m.vertices for m in meshes])
    best = min(walls.values(), key=lambda w: _separation(v, w.mesh.vertices, plan)[0])
    dist, d_plan, dz = _separation(v, best.mesh.vertices, plan)
    parts = []
    if dz > 0.0:
        above = float(v[:, 2].min()) >= best.z_hi
        parts.append(
            f"{dz:.3f} m {'above its top' if above else 'below its base'}"
            if above or float(v[:, 2].max()) <= best.z_lo
            else f"{dz:.3f} m apart in height"
        )
    if d_plan > 0.0:
        parts.append(f"{d_plan:.3f} m off it in plan")
    said = (
        " and ".join(parts)
        if parts
        else "overlapping it (solids that interpenetrate share no face)"
    )
    return f"the nearest wall, {best.id}, is {dist:.3f} m from it ({said})"


def _check_bases(
    walls: Dict[str, Wall],
    under: Dict[str, List[Tuple[str, float]]],
    levels: Sequence[TriMesh],
    plan: Plan,
    tol: float,
    notes: List[str],
) -> float:
    """Check that every wall stands on the ground or on a level; return the ground [m].

    The ground is the lowest wall base. A wall whose base is within ``GROUND_RTOL`` of its
    thickness of it stands on the ground; a higher one must stand on a level of the spec
    (read as fixed on it, with a note). A wall drawn on another wall's top, or standing on
    nothing, is refused.
    """
    ground = min(w.z_lo for w in walls.values())
    for k, w in enumerate(walls.values()):
        rise = w.z_lo - ground
        where = f"walls[{k}] ({w.id})"
        if rise <= max(tol, GROUND_RTOL * w.frame.thickness):
            if rise > tol:
                notes.append(
                    f"{w.id}: its base is {1000 * rise:.3g} mm above the ground (the lowest wall "
                    f"base, z = {ground:.3f} m): read as standing on the ground (a base within "
                    "a tenth of the wall's thickness of it does)"
                )
            continue
        said = (
            f"its base at z = {w.z_lo:.3f} m is {rise:.3f} m above the ground, the lowest wall "
            f"base (z = {ground:.3f} m)"
        )
        if w.id in under:
            ids = sorted({lv for lv, _ in under[w.id]})
            area = sum(a for _, a in under[w.id])
            foot = float(plan.footprints[w.id].area)
            cover = f" over {100 * min(area / foot, 1.0):.0f} % of its footprint" if foot else ""
            notes.append(
                f"{w.id}: stands on the level {', '.join(ids)}{cover}; {said}: its base is "
                f"read as fixed on it (its mechanisms rock about its base there, Z "
                f"{rise:.3f} m above the ground), and the level is no load on it; the walls "
                f"under the level do not carry {w.id}'s weight (the search loads a wall with "
                "the levels it carries only)"
            )
            continue
        for o in walls.values():
            if o.id == w.id or abs(o.z_hi - w.z_lo) > tol:
                continue
            hit = contact_region(o.mesh, w.mesh, tol=tol)
            if hit is not None and float(hit[2][2]) >= math.cos(BEARING_ANGLE):
                raise GeometryError(
                    f"{where}: stands on {o.id}'s top ({said}): the search "
                    f"reads a wall as one solid from the ground up (a wall drawn on another "
                    f"neither loads it nor moves with it): join {w.id} and {o.id} into one solid"
                )
        foot = plan.footprints[w.id]
        below = [
            (w.z_lo - float(m.vertices[:, 2].max()), label)
            for m, label in [(o.mesh, o.id) for o in walls.values() if o.id != w.id]
            + [(m, "a level") for m in levels]
            if float(m.vertices[:, 2].max()) <= w.z_lo + tol
            and footprint(m.vertices, plan.origin).intersection(foot).area
            > OVERLAP_RTOL * foot.area
        ]
        nearest = (
            f"the nearest solid under it, {min(below)[1]}, is {min(below)[0]:.3f} m below its base"
            if below
            else "nothing of the spec is drawn under it"
        )
        raise GeometryError(
            f"{where}: {said}, and it stands on no level or wall ({nearest}): the search reads "
            f"every wall from the ground up, or standing on a level of the spec: draw {w.id} "
            "down to the ground (the lowest wall base), or onto the level that carries it"
        )
    return ground


def _near_misses(walls: Dict[str, Wall], plan: Plan, tol: float, notes: List[str]) -> None:
    """Note the walls drawn apart by more than the joining gap but less than a thickness.

    Such walls are read as not meeting (each is free-standing where it stops short of the
    other); the note gives the gap, so that a corner drawn short does not pass unseen.
    """
    ws = list(walls.values())
    for i, a in enumerate(ws):
        for b in ws[i + 1 :]:
            if min(a.z_hi, b.z_hi) - max(a.z_lo, b.z_lo) <= tol:
                continue
            gap = float(plan.footprints[a.id].distance(plan.footprints[b.id]))
            near = NEAR_RTOL * min(a.frame.thickness, b.frame.thickness)
            if not max(plan.gap, tol) < gap <= near:
                continue
            # the wall whose end faces the other: its end nearest the other's footprint
            ends = []
            for x, y in ((a, b), (b, a)):
                for s in (0.0, x.length):
                    p = x.to_end(s)
                    d = float(plan.footprints[y.id].distance(_point(p - plan.origin)))
                    ends.append((d, x, y, s))
            _, x, y, s = min(ends, key=lambda e: e[0])
            notes.append(
                f"{x.id}'s end (s = {s:.3f} m) stops {1000 * gap:.3g} mm short of {y.id}, beyond "
                f"the joining gap ({1000 * plan.gap:.3g} mm, a tenth of the thinnest wall's "
                f"thickness): read as not meeting, {x.id} free-standing at that end (no junction "
                f"with {y.id}); draw {x.id} to meet {y.id} if the two are bonded or abut"
            )


def _unjoined(
    walls: Dict[str, Wall],
    plan: Plan,
    tol: float,
    notes: List[str],
    met: Set[Tuple[str, str]],
    listed: Set[Tuple[str, ...]],
) -> None:
    """Say which walls touch in plan but form no junction the search can use.

    The search reads a junction where one wall's end face stands on the other's face and the
    two are square (``_return_at``). Walls that meet at another angle, or along a joint face
    that is neither wall's (a mitre), are searched free at that corner: their mechanisms
    without the other wall, which a good connection could only make stronger. A junction the
    spec lists there is refused with the reason.
    """
    ws = list(walls.values())
    for i, a in enumerate(ws):
        for b in ws[i + 1 :]:
            pair = (min(a.id, b.id), max(a.id, b.id))
            if pair in met or min(a.z_hi, b.z_hi) - max(a.z_lo, b.z_lo) <= tol:
                continue
            shared = plan.grown[a.id].intersection(plan.grown[b.id])
            width = max(plan.gap, tol)
            if shared.area <= 0.5 * width * min(a.frame.thickness, b.frame.thickness):
                continue  # apart, or touching at a point
            cos = min(abs(float(a.frame.e_s @ b.frame.e_s)), 1.0)
            angle = math.degrees(math.acos(cos))
            if abs(cos) > math.sin(SQUARE_TOL):
                why = (
                    f"meet at {180.0 - angle:.1f}° / {angle:.1f}° (not square): the search's "
                    "wedge and corner families take square junctions only"
                )
            else:
                why = (
                    "touch, but neither's end face stands on the other's face (a mitred or "
                    "odd-shaped joint): the search reads no junction there; to search their "
                    "wedges, draw one wall through the corner and the other butting on it"
                )
            if pair in listed:
                raise InputError(
                    f"the junction {list(pair)} is listed, but the walls {why}; remove it from "
                    "junctions to search them free at that corner",
                    "junctions",
                )
            notes.append(
                f"{a.id} and {b.id} {why}; each is searched free at that corner (its "
                "mechanisms without the other wall, which a connection could only make stronger)"
            )


def _point(xy: np.ndarray) -> Any:
    shapely = require("shapely", "geometry", "to read the plan of a search")
    return shapely.Point(float(xy[0]), float(xy[1]))


def outer_face_crossing(
    wall: Wall, start: np.ndarray, end: np.ndarray
) -> Optional[Tuple[np.ndarray, float, float]]:
    """Return where a line meets a wall's outer face, as the search reads a tie-bar.

    Parameters
    ----------
    wall : Wall
        A wall of the building.
    start, end : (3,) float
        The line's end points [m].

    Returns
    -------
    (point, s, z) or None
        The crossing [m] and its place in the wall's elevation (``s`` along the wall,
        ``z`` up) [m]; None when the line (to 1e-3 of the wall's size beyond its ends) does
        not reach the outer face's plane, or reaches it outside the wall's length and height.
    """
    f = wall.frame
    d = end - start
    den = float(d @ f.e_n)
    if abs(den) < 1e-12 * max(float(np.linalg.norm(d)), 1.0):
        return None
    u = float((f.origin - start) @ f.e_n) / den
    v = wall.mesh.vertices
    size = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    tol = 1e-3 * size / max(float(np.linalg.norm(d)), 1e-12)
    if not -tol <= u <= 1.0 + tol:
        return None
    p = start + u * d
    s, _, z = (float(c) for c in f.to_frame(p))
    if not (-1e-9 <= s <= wall.length + 1e-9 and wall.z_lo - 1e-9 <= z <= wall.z_hi + 1e-9):
        return None
    return p, s, z


def _tie_points(
    scene: Any, spec: Any, walls: Dict[str, Wall], memory: MemoryScene
) -> Dict[str, List[TiePoint]]:
    out: Dict[str, List[TiePoint]] = {w: [] for w in walls}
    for k, tie in enumerate(spec.tie_bars):
        where = f"tie_bars[{k}]"
        obj = _find(scene, [tie.object], f"{where}.object")[0]
        start, end = _line(scene, obj, tie.object, f"{where}.object")
        memory.add(SceneObject(obj.id, obj.name, obj.layer, "line", {}, (start, end)))
        met = False
        for wall in walls.values():
            hit = outer_face_crossing(wall, start, end)
            if hit is None:
                continue
            p, s, z = hit
            f = wall.frame
            # the bar pulls the façade towards its anchorage, inside the building (+e_n); a
            # line with no part on that side is anchored outside. A line through the wall (a
            # tie across the building meets several walls) keeps the inward pull.
            if max(float((q - p) @ f.e_n) for q in (start, end)) <= 0.0:
                raise GeometryError(
                    f"{where}: the tie-bar runs outward from {wall.id}'s outer face; a tie-bar "
                    "is anchored inside the building and pulls the wall towards it: draw it "
                    "from the outer face into the building"
                )
            out[wall.id].append(TiePoint(k, tie, wall.id, p, s, z, f.e_n.copy()))
            met = True
        if not met:
            raise GeometryError(f"{where}: the tie-bar meets no wall's outer face")
    return out


def building_from_scene(scene: Any, spec: Any) -> Building:
    """Read the walls, junctions, levels and ties a search spec names.

    Parameters
    ----------
    scene : BaseScene
        The input scene (``read_scene``), in metres.
    spec : SearchSpec
        The search spec.

    Returns
    -------
    Building

    Raises
    ------
    InputError
        A selector that matches nothing (or several objects for a wall), a junction the
        spec does not give, a listed junction whose walls do not meet.
    GeometryError
        A wall that is not a vertical slab, a selector that matches no solid (or no line for
        a tie-bar), a level or tie-bar that touches no wall (with the gap to the nearest
        wall), a wall above the ground that stands on no level, a wall on another's top.
    """
    # the spec's implausible values are warnings of the search's document (issue #36), not notes
    notes: List[str] = []
    memory = MemoryScene([], path=scene.path, tolerance=scene.tolerance, source_units=scene.units)
    raw = _read_walls(scene, spec, memory, notes)
    _trim_overlaps(raw, notes)
    for _, obj, _, _ in raw:
        memory.add(obj)
    verts = np.vstack([m.vertices for _, _, m, _ in raw])
    size = float(np.linalg.norm(verts.max(axis=0) - verts.min(axis=0)))
    level_read = _read_levels(scene, spec)
    level_meshes = [m for _, meshes, _ in level_read for m in meshes]
    level_points = [m.vertices for m in level_meshes]
    plan = read_plan(
        [(w.id, m.vertices) for w, _, m, _ in raw], [(m.vertices, m.faces) for m in level_meshes]
    )
    if len(plan.parts) > 1:
        groups: Dict[int, List[str]] = {}
        for w, _, _, _ in raw:
            groups.setdefault(plan.building_of(w.id), []).append(w.id)
        said = "; ".join(", ".join(ids) for _, ids in sorted(groups.items()))
        notes.append(
            f"the walls stand in {len(plan.parts)} separate buildings ({said}): each has its "
            "own outline and outer faces"
        )
    levels = np.vstack(level_points).mean(axis=0) if level_points else None
    walls = _oriented_walls(raw, plan, size, levels, notes)
    tol = max(contact_tolerance(scene), 1e-9 * size)
    returns = _returns(walls, spec, tol, notes, plan)
    _near_misses(walls, plan, tol, notes)
    contacts, level_objects, under = _level_contacts(
        spec, walls, tol, notes, memory, level_read, plan
    )
    _check_bases(walls, under, level_meshes, plan, tol, notes)
    ties = _tie_points(scene, spec, walls, memory)
    return Building(memory, walls, returns, contacts, ties, notes, spec, level_objects, tol)


def _read_walls(
    scene: Any, spec: Any, memory: MemoryScene, notes: List[str]
) -> List[Tuple[Any, SceneObject, TriMesh, Any]]:
    """Read the spec's walls, with its openings cut out and their overburdens' solids.

    Parameters
    ----------
    scene : BaseScene
        The input scene, in metres.
    spec : SearchSpec
        The search spec (``openings``, ``walls``).
    memory : MemoryScene
        The building's scene; each overburden's solids are added to it.
    notes : list of str
        The search's notes, extended with the reading's.

    Returns
    -------
    list of (WallSpec, SceneObject, TriMesh, selector)
        Each wall's spec, object (its voids cut), solid and the selector that names it.
    """
    openings: List[Tuple[SceneObject, TriMesh]] = []
    for k, sel in enumerate(spec.openings):
        for obj in _find(scene, [sel], f"openings[{k}]"):
            mesh, warn = _solid(scene, obj, sel, f"openings[{k}]")
            notes.extend(warn)
            openings.append((obj, mesh))
    raw: List[Tuple[Any, SceneObject, TriMesh, Any]] = []
    for k, w in enumerate(spec.walls):
        where = f"walls[{k}] ({w.id})"
        obj = _one_object(scene, w.object, f"walls[{k}].object")
        mesh, warn = _solid(scene, obj, w.object, f"walls[{k}].object")
        notes.extend(warn)
        selector: Any = w.object
        if openings:
            new_obj, mesh, cut_notes = _cut_openings(obj, mesh, openings, where)
            notes.extend(cut_notes)
            if new_obj is not obj:
                # by name: the input scene has no such object, so its wall (without the
                # voids) cannot be used by mistake, and the message says which one is meant
                obj, selector = new_obj, new_obj.name
        if obj.geometry is not mesh:
            obj = SceneObject(obj.id, obj.name, obj.layer, obj.kind, dict(obj.user_text), mesh)
        if w.overburden is not None and w.overburden.objects is not None:
            at = f"walls[{k}].overburden.objects"
            for o in _find(scene, w.overburden.objects, at):
                m, warn = _solid(scene, o, w.overburden.objects, at)
                notes.extend(warn)
                memory.add(SceneObject(o.id, o.name, o.layer, "mesh", dict(o.user_text), m))
        raw.append((w, obj, mesh, selector))
    return raw


def _oriented_walls(
    raw: List[Tuple[Any, SceneObject, TriMesh, Any]],
    plan: Plan,
    size: float,
    levels: Optional[np.ndarray],
    notes: List[str],
) -> Dict[str, Wall]:
    """Orient each wall in the plan (``_orient``) and make its ``Wall``.

    Parameters
    ----------
    raw : list of (WallSpec, SceneObject, TriMesh, selector)
        The walls as read (``_read_walls``), their overlaps trimmed.
    plan : Plan
        The buildings' plans.
    size : float
        The building's size [m].
    levels : numpy.ndarray, optional
        The levels' mean vertex [m].
    notes : list of str
        The search's notes, extended with the walls' (and what stands against them).

    Returns
    -------
    dict of str to Wall
        The walls by id, in the spec's order.
    """
    walls: Dict[str, Wall] = {}
    for w, obj, mesh, selector in raw:
        frame, rings, volume, exact, wall_notes, (held, building, scale) = _orient(
            mesh, plan, size, w.id, levels
        )
        notes.extend(wall_notes)
        z = mesh.vertices[:, 2]
        length = float(frame.to_frame(mesh.vertices)[:, 0].max())
        walls[w.id] = Wall(
            w.id,
            selector,
            obj,
            w.density,
            w.label,
            w.facade,
            w.overburden,
            frame,
            rings,
            length,
            float(z.min()),
            float(z.max()),
            exact,
            _holes(rings),
            volume,
            held,
            building,
            w.density * scale if scale != 1.0 else 0.0,
        )
        for other, a, b in held:
            notes.append(
                f"{w.id}: {other} stands against its outer face (s = {a:.3f}-{b:.3f} m of "
                f"{length:.3f} m): {w.id} cannot move outward there, and its outward mechanisms "
                "(the whole façade above a hinge line, its corners) are not searched"
            )
    return walls
