"""The mechanism families: candidate crack lines, discrete combinations, continuous refinement.

For each façade and direction the search lists candidate hinge lines (the base, sills,
lintels, level heights, outline corners and optional extra lines) and, per line, the
combinations a family allows; each combination has at most two continuous parameters,
refined by ``refine.minimise`` on the exact λ0 (``multiplier``):

* ``overturning`` / ``partial_overturning``: the façade above a hinge line turns about it
  (outward about the outer face, inward about the inner face); no parameter;
* ``gable`` / ``parapet``: the same above the top level (a sloped or a straight top);
* ``wedge_overturning``: the same with a wedge of each return wall whose connection is
  good, cut by a crack from the junction at the hinge line at angle β from the vertical,
  ``β >= atan(l_u / 2 h_u)``; one parameter per such end (a poor connection parts along the
  junction, a tied one holds the façade);
* ``vertical_flexure``: the two-block wall between the ground and a tied level at the
  top (theory §2.3); the hinge height ``h1`` is the parameter;
* ``corner``: the corner of a façade and a flush return wall with a good connection, cut by
  a crack in each wall from the base, turning about the horizontal axis through the outer
  corner across the diagonal; two angles.

A wedge crack separates the wedge without friction (the classical macro-block model: the
crack opens and slides freely), and a hinge joint does not slide; ``sliding_check`` says
where the joint's friction would not hold the rocking multiplier.

Python 3.9-clean: imported by Rhino 8.
"""

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from cad_maths.geometry.massprops import mass_properties
from cad_maths.mechanisms.loaded import BEARING_ANGLE, largest_contact
from cad_maths.mechanisms.single import find_objects
from cad_maths.search.model import (
    Building,
    LevelContact,
    RegionTable,
    ReturnWall,
    TiePoint,
    Wall,
)
from cad_maths.search.multiplier import Force, rotation_multiplier, two_block_multiplier
from cad_maths.search.prism import (
    FirstMoments,
    Lump,
    clip_point_rings,
    clip_rings,
    point_lump,
    ring_first_moments,
    ring_moments,
)
from cad_maths.search.refine import minimise
from shared_schema.errors import InputError
from shared_schema.rules import G

__all__ = [
    "Budget",
    "Candidate",
    "Piece",
    "WorkEstimate",
    "enumerate_candidates",
    "ground_height",
    "hinge_lines",
    "work_estimate",
]

Plane = Tuple[np.ndarray, np.ndarray]  # (point [m], normal): keeps normal·(x - point) >= 0

#: Relative tolerance on heights (relative to the building's size).
HEIGHT_RTOL = 1e-9
#: Largest crack angle from the vertical searched [rad].
BETA_MAX = math.radians(80.0)
#: Range of the two-block hinge height searched, as fractions of the wall's height.
H1_RANGE = (0.02, 0.98)
#: A block lighter than this fraction of its wall is no block (a sliver at an edge).
MIN_MASS_FRACTION = 1e-9
#: Where a given overburden force acts without ``xi``: on the wall's centre line, as a
#: fraction of the thickness from the outer face (theory §2.3: the resultant at rest of a
#: load spread over the whole top; the builder's rule for a force).
OVERBURDEN_XI_DEFAULT = 0.5
#: The limit of a two-block wall's λ0 as its hinge reaches the top is evaluated this close
#: to it (as a fraction of the wall's height) to report it where the search stops short.
H1_LIMIT_GAP = 1e-6


class Budget:
    """A cap on the λ0 evaluations of one search (the work limit).

    It is checked before each refinement starts, so that a search too large for the limit
    stops before doing that work.
    """

    def __init__(self, limit: Optional[int] = None) -> None:
        self.limit = limit
        self.used = 0

    def reserve(self, n: int, what: str) -> None:
        """Count the seed grid of the next refinement (raise past the limit)."""
        if self.limit is not None and self.used + n > self.limit:
            raise InputError(
                f"the search needs more than {self.limit} evaluations of λ0 (at {what}); "
                "ask for fewer families or directions, a coarser candidates.grid or no "
                "candidates.spacing, or raise the work limit",
                "work_limit",
            )

    def spend(self, n: int) -> None:
        """Count the evaluations a refinement made."""
        self.used += n


@dataclass
class Piece:
    """The part of one wall that moves with a mechanism.

    Attributes
    ----------
    wall : Wall
        The wall.
    planes : list of (point, normal)
        Half-spaces whose intersection with the wall is the part (each plane contains the
        wall's thickness direction).
    """

    wall: Wall
    planes: List[Plane]

    def lump(self) -> Lump:
        """Return the part's mass moments."""
        return self.wall.lump(self.planes)

    def rings(self) -> List[np.ndarray]:
        """Return the part's elevation in the wall's frame."""
        return self.wall.region(self.planes)


@dataclass
class LevelLoad:
    """A level as one mechanism carries it (where the builder finds it).

    Attributes
    ----------
    contact : LevelContact
        The level and one wall it touches (``contact.level`` is the spec's level).
    point : (3,) float
        Centroid of its largest contact with the moving parts [m].
    area : float
        That contact's area [m²].
    mass : float
        The wall's share of its mass (``tributary``) [kg].
    bearing : bool
        Its weight acts (a horizontal contact, or a roof).
    thrust : float
        Outward roof thrust [N] (0 for floors and tied trusses).
    """

    contact: LevelContact
    point: np.ndarray
    area: float
    mass: float
    bearing: bool
    thrust: float

    @property
    def level(self) -> Any:
        """The spec's level."""
        return self.contact.level


@dataclass
class Candidate:
    """One mechanism of the catalogue, refined.

    Attributes
    ----------
    family, facade, direction : str
        What it is.
    typology, rocking : str
        The mechanism spec's typology and rocking kind.
    params : dict of str to float
        The refined parameters (``hinge_height_m``, ``beta_start_rad``, ``beta_end_rad``,
        ``h1_m``, ``beta_facade_rad``, ``beta_return_rad``).
    bounds : dict of str to (float, float)
        Their search ranges.
    pieces : list of Piece
        The moving parts.
    axis : (2, 3) float
        Two points of the rotation axis (two-block: of the base hinge O) [m].
    direction_vector : (3,) float
        The horizontal collapse direction.
    lam0 : float
        Exact static load multiplier [-].
    contacts : list of LevelLoad
        The levels it carries, where the builder finds them.
    ties : list of TiePoint
        The tie-bars on it.
    overburden : dict, optional
        Two-block: ``N`` [N] and its ``x`` [m] in the rocking plane.
    lam0_negative : float, optional
        Two-block: λ0 of the mirrored (inward) side.
    n_evaluations : int
        λ0 evaluations of its refinement.
    on_bound : list of str
        Parameters whose optimum lies on a bound.
    notes : list of str
        What the candidate assumes.
    hinge_z : float
        Height of the base of the moving part (the hinge line; a two-block wall's or a
        corner's base) in the scene [m].
    z_base : float
        Z: that height above the ground (``ground_height``) [m], 0 at ground level.
    """

    family: str
    facade: str
    direction: str
    typology: str
    rocking: str
    params: Dict[str, float]
    bounds: Dict[str, Tuple[float, float]]
    pieces: List[Piece]
    axis: np.ndarray
    direction_vector: np.ndarray
    lam0: float
    contacts: List[LevelLoad] = field(default_factory=list)
    ties: List[TiePoint] = field(default_factory=list)
    overburden: Optional[Dict[str, Any]] = None
    lam0_negative: Optional[float] = None
    n_evaluations: int = 0
    on_bound: List[str] = field(default_factory=list)
    notes: List[str] = field(default_factory=list)
    hinge_z: float = 0.0
    z_base: float = 0.0

    @property
    def key(self) -> Tuple[Any, ...]:
        """What makes two candidates the same mechanism (for removing repeats)."""
        return (
            self.facade,
            self.direction,
            self.typology,
            tuple(sorted((k, round(v, 12)) for k, v in self.params.items())),
            tuple(p.wall.id for p in self.pieces),
        )

    def weight(self) -> float:
        """Weight of the moving parts [N]."""
        return G * sum(p.lump().mass for p in self.pieces)


def _tol(bld: Building) -> float:
    return HEIGHT_RTOL * max(bld.size, 1.0)


def ground_height(bld: Building) -> float:
    """Height of the ground [m]: the lowest base of the scene's walls.

    Z of a mechanism (the height of the base of its moving part, theory §7.2 and §11.5) is
    measured from it.
    """
    return min(w.z_lo for w in bld.walls.values())


def hinge_lines(bld: Building, wall: Wall, spacing: Optional[float] = None) -> List[float]:
    """Candidate hinge heights of a façade [m]: base, sills, lintels, levels, outline corners.

    Parameters
    ----------
    bld : Building
        The building.
    wall : Wall
        The façade.
    spacing : float, optional
        Add a line every ``spacing`` metres above the base (none inside a level's height).

    Returns
    -------
    list of float
        Sorted heights in ``[z_lo, z_hi)``; the base first.
    """
    tol = _tol(bld)
    zs = {wall.z_lo}
    for _, _, z0, z1 in wall.holes:
        zs.update((z0, z1))
    zs.update(float(z) for z in wall.rings[0][:, 1])
    spans = []
    for c in bld.contacts.get(wall.id, []):
        lo, hi = c.z_range
        zs.update((lo, hi))
        spans.append((lo, hi))
        if c.bearing:
            zs.add(float(c.point[2]))
    if spacing:
        z = wall.z_lo + spacing
        while z < wall.z_hi - tol:
            if not any(lo + tol < z < hi - tol for lo, hi in spans):
                zs.add(z)
            z += spacing
    out = sorted(z for z in zs if wall.z_lo - tol <= z < wall.z_hi - tol)
    merged: List[float] = []
    for z in out:
        if not merged or z - merged[-1] > tol:
            merged.append(z)
    merged[0] = wall.z_lo
    return merged


def _above(point: np.ndarray, z: float) -> Plane:
    """Keep what lies above the height ``z`` (a horizontal crack through ``point``'s column)."""
    return np.array([point[0], point[1], z]), np.array([0.0, 0.0, 1.0])


def _wedge_plane(facade: Wall, z: float, beta: float) -> Plane:
    """Keep the return wall's part within ``(z' - z) tan β`` of the façade's inner face."""
    f = facade.frame
    point = f.to_world(0.0, facade.inner_face, z)
    normal = -math.cos(beta) * f.e_n + math.sin(beta) * f.e_z
    return point, normal


def _corner_plane(facade: Wall, end: str, z: float, beta: float) -> Plane:
    """Keep the façade's part within ``(z' - z) tan β`` of its end ``end``."""
    f = facade.frame
    s_end = 0.0 if end == "start" else facade.length
    e_c = f.e_s if end == "start" else -f.e_s
    return f.to_world(s_end, 0.0, z), -math.cos(beta) * e_c + math.sin(beta) * f.e_z


def _region_mass(wall: Wall, planes: Sequence[Plane]) -> float:
    return float(ring_moments(wall.region(planes))[0]) * wall.frame.thickness * wall.lump_density


Hits = Dict[int, Tuple[float, np.ndarray, LevelContact, Any]]


#: A vertex within this fraction of the regions' largest coordinate of a half-space's plane
#: is clipped exactly rather than screened (the screen's rounding differs from the clip's).
SCREEN_RTOL = 1e-9


def _screen(
    table: RegionTable, planes: Sequence[Plane]
) -> Tuple[List[int], List[bool], List[List[bool]]]:
    """Which regions may meet the half-spaces' intersection, and which lie wholly inside it.

    One product of the regions' vertices with the planes' normals replaces a clip per
    region and plane; vertices near a plane (``SCREEN_RTOL``) leave the region to the clip.
    Returns the regions not wholly outside one half-space, whether each lies wholly inside
    every half-space, and per plane whether it lies wholly inside that half-space: clipping
    by it keeps the region as it is (every point of the region, and of any part of it cut
    by the other planes, is well inside), so it is not clipped by it.
    """
    k = len(table.entries)
    if not planes:
        return list(range(k)), [True] * k, [[] for _ in range(k)]
    normals = np.array([n for _, n in planes], dtype=float)
    offsets = np.einsum("ij,ij->i", normals, np.array([p for p, _ in planes], dtype=float))
    f = table.vertices @ normals.T - offsets
    margin = SCREEN_RTOL * table.scale * float(np.abs(normals).sum(axis=1).max())
    lo = np.minimum.reduceat(f, table.starts, axis=0)
    hi = np.maximum.reduceat(f, table.starts, axis=0)
    todo = np.flatnonzero(~np.any(hi < -margin, axis=1))
    inside = lo[todo] > margin
    whole: List[bool] = np.all(inside, axis=1).tolist()
    return todo.tolist(), whole, inside.tolist()


def contact_hits(bld: Building, pieces: Sequence[Piece], best: Optional[Hits] = None) -> Hits:
    """Each level's largest contact with the moving parts: level -> (area, centroid, ...).

    Every contact of a level with a wall is clipped to that wall's moving part (the plane
    of the contact, cut by the part's half-spaces); ``best`` (the hits of other parts) is
    extended, not changed.
    """
    tol = max(bld.contact_tol, 0.0)
    out: Hits = dict(best or {})
    for piece in pieces:
        table = bld.region_table(piece.wall.id)
        if not table.entries:
            continue
        # the half-spaces' coefficients as floats, once per piece (not once per region)
        planes = [
            (float(n[0]), float(n[1]), float(n[2]), float(p[0]), float(p[1]), float(p[2]))
            for p, n in piece.planes
        ]
        # the regions left out have every vertex well outside one half-space: none moves
        todo, whole, inside = _screen(table, piece.planes)
        for r, r_whole, r_inside in zip(todo, whole, inside):
            c, _, region = table.entries[r]
            rings = table.rings[r]
            if r_whole:
                moments = table.moments[r]
                if moments is None:
                    moments = table.moments[r] = ring_first_moments(rings)
                area, su, sv = moments
            else:
                u, v, o = table.axes[r]
                for (m0, m1, m2, p0, p1, p2), keeps in zip(planes, r_inside):
                    if keeps:
                        continue  # the clip would keep every vertex: the rings as they are
                    rings = clip_point_rings(
                        rings,
                        m0 * u[0] + m1 * u[1] + m2 * u[2],
                        m0 * v[0] + m1 * v[1] + m2 * v[2],
                        m0 * (o[0] - p0) + m1 * (o[1] - p1) + m2 * (o[2] - p2),
                    )
                area, su, sv = ring_first_moments(rings)
            if not area > 0.0:
                continue
            # clipping only shrinks a region: past the whole region's extent the touch
            # test passes without measuring the clipped part
            if area <= tol * table.extents[r]:
                pts = np.array([q for ring in rings for q in ring], dtype=float)
                extent = float(max(np.ptp(pts[:, 0]), np.ptp(pts[:, 1])))
                if area <= tol * extent:
                    continue  # a touch along a line (the builder's MIN_WIDTH_FACTOR)
            k = c.index
            if k not in out or area > out[k][0]:
                centroid = region.origin + (su / area) * region.u + (sv / area) * region.v
                out[k] = (area, centroid, c, region)
    return out


def level_loads(
    bld: Building, pieces: Sequence[Piece], d: np.ndarray, hits: Optional[Hits] = None
) -> Tuple[List[LevelLoad], Optional[str]]:
    """Return the levels a mechanism's moving parts carry, as the constants builder finds them.

    A level acts at the centroid of its largest contact with the moving parts (each of its
    contacts with a wall clipped to that wall's moving part), bears if that contact is
    horizontal (a roof always bears), and a roof that is not a tied truss thrusts along the
    collapse direction ``d`` (span and rise from its bounding box in the mechanism's frame),
    as ``mechanisms.loaded.loaded_side`` computes them. ``hits`` are the contacts of other
    moving parts already found (``contact_hits``).

    Returns
    -------
    loads : list of LevelLoad
        In the order of the spec's levels.
    held : str or None
        The id of a tied level the moving parts touch (the mechanism is then held).
    """
    best = contact_hits(bld, pieces, hits)
    loads: List[LevelLoad] = []
    held = None
    for k in sorted(best):
        area, point, c, region = best[k]
        if c.level.tied:
            held = held or c.level.id
            continue
        bearing = c.level.kind == "roof" or abs(float(region.normal[2])) >= math.cos(BEARING_ANGLE)
        thrust = 0.0
        if c.level.kind == "roof" and c.level.pushes:
            thrust = bld.roof_thrust(c, d)
        loads.append(LevelLoad(c, point, area, c.mass, bearing, thrust))
    return loads, held


def _loads(
    contacts: Sequence[LevelLoad], ties: Sequence[TiePoint], d: np.ndarray
) -> Tuple[Lump, Lump, List[Force], List[Force]]:
    """Bearing and abutting masses, static forces and tie-bars' pulls of a rigid mechanism.

    A tie pulls its façade towards its anchorage (``TiePoint.pull``); the multiplier counts
    it only on a motion that stretches it (``rotation_multiplier``'s ``ties``).
    """
    weighing = Lump.zero()
    abutting = Lump.zero()
    forces: List[Force] = []
    for c in contacts:
        lump = point_lump(c.mass, c.point)
        if c.bearing:
            weighing = weighing + lump
        else:
            abutting = abutting + lump
        if c.thrust > 0.0:
            forces.append((c.thrust * d, c.point))
    pulls: List[Force] = [(tie.tie.force * tie.pull, tie.point) for tie in ties]
    return weighing, abutting, forces, pulls


def _first_loads(
    contacts: Sequence[LevelLoad], ties: Sequence[TiePoint], d: np.ndarray
) -> Tuple[FirstMoments, FirstMoments, List[Force], List[Force]]:
    """Return ``_loads`` with masses and first moments only (the same sums, no second ones)."""
    w_m, w_s = 0.0, np.zeros(3)
    a_m, a_s = 0.0, np.zeros(3)
    forces: List[Force] = []
    for c in contacts:
        s = c.mass * np.asarray(c.point, dtype=float)  # point_lump's first moment
        if c.bearing:
            w_m, w_s = w_m + float(c.mass), w_s + s
        else:
            a_m, a_s = a_m + float(c.mass), a_s + s
        if c.thrust > 0.0:
            forces.append((c.thrust * d, c.point))
    pulls: List[Force] = [(tie.tie.force * tie.pull, tie.point) for tie in ties]
    return FirstMoments(w_m, w_s), FirstMoments(a_m, a_s), forces, pulls


@dataclass
class Template:
    """A rigid mechanism before refinement: fixed pieces, pieces set by the parameters.

    Attributes
    ----------
    family, rocking : str
        What the refined candidate will be.
    names : list of str
        Parameter names.
    bounds : list of (float, float)
        Their ranges.
    fixed : list of Piece
        Parts that do not depend on the parameters.
    variable : callable
        ``variable(x) -> list of Piece``: the parts the parameters set.
    point : (3,) float
        A point of the axis [m].
    d : (3,) float
        The collapse direction.
    bld : Building
        The building (its levels load the moving parts where they touch them).
    ties : list of TiePoint
        The tie-bars on the moving parts.
    axis : (2, 3) float
        Two points of the axis [m].
    hinge_z : float
        Height of the hinge line [m].
    """

    family: str
    rocking: str
    names: List[str]
    bounds: List[Tuple[float, float]]
    fixed: List[Piece]
    variable: Callable[[Sequence[float]], List[Piece]]
    point: np.ndarray
    d: np.ndarray
    bld: Building
    ties: List[TiePoint]
    axis: np.ndarray
    hinge_z: float
    notes: List[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        lump = Lump.zero()
        for p in self.fixed:
            lump = lump + p.lump()
        self._fixed_lump = lump
        self._fixed_hits = contact_hits(self.bld, self.fixed)

    def pieces(self, x: Sequence[float]) -> List[Piece]:
        """Return every moving part at parameters ``x``."""
        return self.fixed + self.variable(x)

    def lam(self, x: Sequence[float]) -> float:
        """Return λ0 at parameters ``x`` (``inf`` where nothing moves, or a tied level holds).

        The rigid multiplier needs only masses and first moments: they are summed as the
        lumps' (``Lump.__add__``, in the same order), without the second moments.
        """
        variable = self.variable(x)
        mass, first = self._fixed_lump.mass, self._fixed_lump.S
        for p in variable:
            m, s = p.wall.first_moments(p.planes)
            mass, first = mass + m, first + s
        if not mass > 0.0:
            return math.inf
        loads, held = level_loads(self.bld, variable, self.d, self._fixed_hits)
        if held is not None:
            return math.inf
        (w_m, w_s), (a_m, a_s), forces, pulls = _first_loads(loads, self.ties, self.d)
        w = FirstMoments(mass + w_m, first + w_s)
        inertial = FirstMoments(w.mass + a_m, w.S + a_s)
        return rotation_multiplier(w, inertial, self.point, self.d, forces, pulls)

    def refine(
        self, facade: str, direction: str, grid: int, budget: Optional[Budget] = None
    ) -> Optional[Candidate]:
        """Minimise λ0 over the parameters; None where no admissible point exists."""
        if budget is not None:
            budget.reserve(grid ** len(self.bounds), f"{facade} {direction} {self.family}")
        res = minimise(self.lam, self.bounds, grid)
        if budget is not None:
            budget.spend(res.n_evaluations)
        if not math.isfinite(res.value):
            return None
        params = {"hinge_height_m": self.hinge_z} if self.family != "corner" else {}
        params.update(zip(self.names, res.x))
        pieces = self.pieces(res.x)
        loads, _ = level_loads(self.bld, pieces, self.d)
        typology = "single_block_loaded" if (loads or self.ties) else "single_block"
        return Candidate(
            self.family,
            facade,
            direction,
            typology,
            self.rocking,
            params,
            dict(zip(self.names, self.bounds)),
            pieces,
            self.axis,
            self.d,
            res.value,
            loads,
            self.ties,
            n_evaluations=res.n_evaluations,
            on_bound=[n for n, b in zip(self.names, res.on_bound) if b],
            notes=list(self.notes),
            hinge_z=self.hinge_z,
        )


def _direction(wall: Wall, direction: str) -> Tuple[np.ndarray, float]:
    """Collapse direction and the face (n) its hinge lies on."""
    f = wall.frame
    if direction == "outward":
        return -f.e_n, 0.0
    return f.e_n.copy(), wall.inner_face


def _label(bld: Building, wall: Wall, z_h: float, wedges: bool, tol: float) -> str:
    if wedges:
        return "wedge_overturning"
    if z_h <= wall.z_lo + tol:
        return "overturning"
    tops = [c.z_range[1] for c in bld.contacts.get(wall.id, [])]
    if tops and z_h >= max(tops) - tol:
        # a gable's outline above the line is no rectangle (sloped edges), a parapet's is
        above = clip_rings([wall.rings[0]], 0.0, 1.0, -z_h)
        if not above:
            return "parapet"
        pts = np.vstack(above)
        box = float(np.ptp(pts[:, 0]) * np.ptp(pts[:, 1]))
        sloped = float(ring_moments(above)[0]) < (1.0 - 1e-9) * box
        return "gable" if sloped else "parapet"
    return "partial_overturning"


@dataclass
class _Plan:
    """What a hinge line admits before any λ0 is evaluated (``_overturning_plan``)."""

    why: str
    family: str = ""
    planes: List[Plane] = field(default_factory=list)
    cut: Optional[Plane] = None
    params: List[Tuple[str, ReturnWall, float, float]] = field(default_factory=list)
    ties: List[TiePoint] = field(default_factory=list)

    @property
    def seeds(self) -> int:
        """Exponent of the seed grid: the parameters whose range is not a point."""
        return sum(1 for _, _, lo, hi in self.params if hi > lo)


def _overturning_plan(bld: Building, wall: Wall, direction: str, z_h: float) -> _Plan:
    """Admissibility, family, cut and wedge parameters of the overturning above ``z_h``."""
    tol = _tol(bld) * 1e3
    free = bld.free_standing(wall.id)
    if direction == "inward" and not free:
        return _Plan("the building (return walls, levels or ties) holds the wall's inner face")
    if direction == "outward" and wall.held_by:
        holders = sorted({h[0] for h in wall.held_by})
        verb = "stands" if len(holders) == 1 else "stand"
        return _Plan(f"{' and '.join(holders)} {verb} against the wall's outer face")
    f = wall.frame
    returns = bld.returns.get(wall.id, []) if direction == "outward" else []
    contacts = [c for c in bld.contacts.get(wall.id, []) if c.point[2] > z_h + tol]
    tied = [c for c in contacts if c.level.tied]
    if tied:
        return _Plan(
            f"the tied level {tied[0].level.id} holds the wall at z = {tied[0].point[2]:.3f} m"
        )
    held = [r.wall.id for r in returns if r.connection == "tied"]
    if held:
        return _Plan(f"the tied junction with {held[0]} holds the façade")
    ties = [t for t in bld.ties.get(wall.id, []) if t.z > z_h + tol]
    cut = _above(f.origin, z_h)
    planes = [cut] if z_h > wall.z_lo + tol else []
    if _region_mass(wall, planes) <= MIN_MASS_FRACTION * wall.mass:
        return _Plan("nothing of the wall lies above the hinge line")
    params: List[Tuple[str, ReturnWall, float, float]] = []
    for r in returns:
        if r.connection != "good":
            continue
        if _region_mass(r.wall, [cut]) <= MIN_MASS_FRACTION * r.wall.mass:
            continue  # the return wall stops below the hinge line
        dz = max(r.wall.z_hi - z_h, tol)
        hi = min(max(r.beta_bond, math.atan(r.reach / dz)), BETA_MAX)
        lo = min(r.beta_bond, hi)
        params.append((f"beta_{r.end}_rad", r, lo, hi))
    family = _label(bld, wall, z_h, bool(params), tol)
    return _Plan("", family, planes, cut, params, ties)


def overturning_template(
    bld: Building, wall: Wall, direction: str, z_h: float
) -> Tuple[Optional[Template], str]:
    """Build the overturning of a façade's part above ``z_h``, with its admissible wedges.

    Parameters
    ----------
    bld : Building
        The building.
    wall : Wall
        The façade.
    direction : {"outward", "inward"}
        The collapse direction.
    z_h : float
        Height of the hinge line [m] (the base for full-height overturning).

    Returns
    -------
    template : Template or None
        None where the mechanism is not admissible.
    why : str
        Why not (empty when admissible).
    """
    plan = _overturning_plan(bld, wall, direction, z_h)
    if plan.why:
        return None, plan.why
    assert plan.cut is not None
    cut, params = plan.cut, plan.params
    d, n_face = _direction(wall, direction)
    f = wall.frame

    def variable(x: Sequence[float]) -> List[Piece]:
        return [
            Piece(r.wall, [cut, _wedge_plane(wall, z_h, b)]) for (_, r, _, _), b in zip(params, x)
        ]

    point = f.to_world(0.0, n_face, z_h)
    axis = np.array([point, f.to_world(wall.length, n_face, z_h)])
    rocking = "two_sided" if bld.free_standing(wall.id) else "one_sided"
    tmpl = Template(
        plan.family,
        rocking,
        [p[0] for p in params],
        [(p[2], p[3]) for p in params],
        [Piece(wall, plan.planes)],
        variable,
        point,
        d,
        bld,
        plan.ties,
        axis,
        z_h,
    )
    return tmpl, ""


def _rigid_candidates(
    bld: Building,
    wall: Wall,
    direction: str,
    families: Sequence[str],
    grid: int,
    notes: List[str],
    budget: Budget,
) -> List[Candidate]:
    out: List[Candidate] = []
    said = set()
    for z_h in hinge_lines(bld, wall, bld.spec.candidates.spacing):
        tmpl, why = overturning_template(bld, wall, direction, z_h)
        if tmpl is None:
            if why and why not in said:
                said.add(why)
                notes.append(f"{wall.id} {direction}: no overturning where {why}")
            continue
        if tmpl.family not in families:
            continue
        cand = tmpl.refine(wall.id, direction, grid, budget)
        if cand is not None:
            out.append(cand)
    return out


def overburden_load(bld: Building, wall: Wall, d: np.ndarray) -> Tuple[float, float, List[str]]:
    """N [N] on the wall's top and its position x [m] along ``d`` from the outer face.

    Where N acts (theory §2.3): at ``xi b`` from the outer face where the overburden gives
    ``xi``; else on the wall's centre line for a force (``OVERBURDEN_XI_DEFAULT``), at the
    centroid of the objects' contact with the wall's top for objects (as the builder).
    """
    ob = wall.overburden
    b = wall.frame.thickness
    if ob is None:
        return 0.0, -OVERBURDEN_XI_DEFAULT * b, []
    xi = getattr(ob, "xi", None)
    notes: List[str] = []
    if ob.force is not None:
        n = float(ob.force)
        if xi is None:
            notes.append(
                f"{wall.id}.overburden.xi not given: N acts on the wall's centre line "
                f"(xi = {OVERBURDEN_XI_DEFAULT:g}, the resultant of a load spread over the "
                "whole top at rest; theory §2.3)"
            )
            return n, -OVERBURDEN_XI_DEFAULT * b, notes
        return n, -float(xi) * b, notes
    objs = find_objects(bld.scene, ob.objects, f"{wall.id}.overburden")
    meshes = [bld.scene.mesh(o) for o in objs]
    n = ob.tributary * G * sum(mass_properties(m, ob.density).mass for m in meshes)
    if "tributary" not in ob.model_fields_set:
        notes.append(
            f"{wall.id}.overburden: tributary not given; the wall carries the default "
            f"{ob.tributary:g} of the overburden's weight (N = {n:.6g} N)"
        )
    if xi is not None:
        return n, -float(xi) * b, notes
    _, point, _ = largest_contact(meshes, [wall.mesh], f"{wall.id}.overburden", 1e-6)
    x = float((np.asarray(point) - wall.frame.origin) @ d)
    return n, x, notes


def two_block_lam(
    wall: Wall, h1: float, d: np.ndarray, n: float, x_n: float, mirrored: bool = False
) -> float:
    """λ0 of the façade as a two-block wall with its hinge at ``h1`` above the base.

    Parameters
    ----------
    wall : Wall
        The façade.
    h1 : float
        Height of the intermediate hinge above the base [m].
    d : (3,) float
        Outward direction (the positive side).
    n, x_n : float
        Overburden [N] and its position along ``d`` from the outer face [m].
    mirrored : bool
        The inward side: hinges mirrored about the wall's mid-plane.
    """
    f = wall.frame
    b = f.thickness
    h = wall.z_hi - wall.z_lo
    z_c = wall.z_lo + h1
    lo = wall.lump([(f.to_world(0.0, 0.0, z_c), -f.e_z)])
    up = wall.lump([(f.to_world(0.0, 0.0, z_c), f.e_z)])
    if not (lo.mass > 0.0 and up.mass > 0.0):
        return math.inf
    o = f.to_world(0.0, 0.0, wall.z_lo)

    def planar(lump: Lump) -> Tuple[float, float, float]:
        g = lump.com - o
        x = float(g @ d)
        return lump.mass, (-b - x if mirrored else x), float(g[2])

    x_p = -b - x_n if mirrored else x_n
    return two_block_multiplier(planar(lo), planar(up), (0.0, 0.0), (-b, h1), (0.0, h), n, (x_p, h))


def _flexure_top(bld: Building, wall: Wall) -> Tuple[Optional[LevelContact], str]:
    """Return the tied level that holds a wall's top for vertical flexure, or why none.

    Returns
    -------
    top : LevelContact or None
        The tied level at the wall's top (None: no two-block wall).
    why : str
        Why the family is not searched although a tied level holds the top (levels or
        tie-bars load the wall between its restraints); empty otherwise.
    """
    tol = _tol(bld) * 1e3
    contacts = bld.contacts.get(wall.id, [])
    top = [c for c in contacts if c.level.tied and c.z_range[1] >= wall.z_hi - tol]
    if not top:
        return None, ""
    others = [c for c in contacts if c not in top]
    if others or bld.ties.get(wall.id):
        ties = [f"tie_bars[{t.index}]" for t in bld.ties.get(wall.id, [])]
        what = ", ".join([c.level.id for c in others] + ties)
        return None, (
            f"{wall.id} vertical_flexure: not searched, {what} load the wall between its "
            "restraints and the two-block wall carries only its overburden"
        )
    return top[0], ""


def _flexure_candidates(
    bld: Building, wall: Wall, grid: int, notes: List[str], budget: Budget
) -> List[Candidate]:
    """Refine the two-block wall of a façade, each side asked for over its own h1.

    The outward side turns about the outer face's base edge (hinges O, C, H of theory
    §2.3 on the outer, inner, outer face), the inward side about the inner one (mirrored);
    each is refined on its own hinge height, and its ``lam0_negative`` is the other side at
    that height (what the builder computes for the mechanism's negative side).
    """
    top, why = _flexure_top(bld, wall)
    if why:
        notes.append(why)
    if top is None:
        return []
    f = wall.frame
    d = -f.e_n
    n, x_n, ob_notes = overburden_load(bld, wall, d)
    b = f.thickness
    h = wall.z_hi - wall.z_lo
    bounds = (H1_RANGE[0] * h, H1_RANGE[1] * h)
    out: List[Candidate] = []
    for direction in bld.spec.directions:
        inward = direction == "inward"

        def lam(x: Sequence[float], inward: bool = inward) -> float:
            return two_block_lam(wall, x[0], d, n, x_n, mirrored=inward)

        budget.reserve(grid, f"{wall.id} {direction} vertical_flexure")
        res = minimise(lam, [bounds], grid)
        budget.spend(res.n_evaluations)
        if not math.isfinite(res.value):
            continue
        h1 = res.x[0]
        face = wall.inner_face if inward else 0.0
        axis = np.array(
            [f.to_world(0.0, face, wall.z_lo), f.to_world(wall.length, face, wall.z_lo)]
        )
        cand_notes = [
            *ob_notes,
            f"{wall.id}: held at the top by {top.level.id}; the two-block wall spans "
            "between the ground and that level (its return walls' restraint of the strip's "
            "edges is not counted)",
        ]
        if res.on_bound[0] and h1 >= bounds[1]:
            limit = lam([h * (1.0 - H1_LIMIT_GAP)])
            cand_notes.append(
                f"{wall.id} {direction} vertical_flexure: λ0 falls as the hinge rises (N = "
                f"{n:.6g} N at {-x_n / b if not inward else 1.0 + x_n / b:.3g} b from this "
                f"side's top hinge); the search stops at h1 = {H1_RANGE[1]:g} h = {h1:.6g} m "
                f"(λ0 = {res.value:.6g}), {100.0 * (res.value / limit - 1.0):.3g} % above the "
                f"limit {limit:.6g} as h1 → h, which no mechanism reaches: there the middle "
                "hinge C meets the restrained top hinge H and the strip locks (theory §2.3)"
            )
        out.append(
            Candidate(
                "vertical_flexure",
                wall.id,
                direction,
                "two_block",
                "two_sided",
                {"h1_m": h1},
                {"h1_m": bounds},
                [Piece(wall, [])],
                axis,
                f.e_n.copy() if inward else d,
                res.value,
                overburden={"N": n, "x": x_n, "xi": -x_n / b},
                lam0_negative=two_block_lam(wall, h1, d, n, x_n, mirrored=not inward),
                n_evaluations=res.n_evaluations,
                on_bound=["h1_m"] if res.on_bound[0] else [],
                notes=cand_notes,
                hinge_z=wall.z_lo,
            )
        )
    return out


def _corner_bounds(wall: Wall, r: ReturnWall) -> List[Tuple[float, float]]:
    """Ranges of the corner's two crack angles [rad]: from the bond limit to the far edges."""
    h = wall.z_hi - wall.z_lo
    hi_a = min(max(r.beta_bond, math.atan(wall.length / h)), BETA_MAX)
    dz = max(r.wall.z_hi - wall.z_lo, 1e-9)
    hi_b = min(max(r.beta_bond, math.atan(r.reach / dz)), BETA_MAX)
    return [(min(r.beta_bond, hi_a), hi_a), (min(r.beta_bond, hi_b), hi_b)]


def _corner_candidates(
    bld: Building, wall: Wall, grid: int, notes: List[str], budget: Budget
) -> List[Candidate]:
    out: List[Candidate] = []
    f = wall.frame
    for r in bld.returns.get(wall.id, []):
        if not r.corner or r.connection != "good" or wall.held_by or r.wall.held_by:
            continue  # a held outer face: said where the plan is read
        if bld.ties.get(wall.id) or bld.ties.get(r.wall.id):
            notes.append(
                f"{wall.id}/{r.wall.id} corner: not searched, tie-bars cross the corner's walls "
                "and the builder takes a tie-bar on the plane through the diagonal axis"
            )
            continue
        o = -f.e_s if r.end == "start" else f.e_s
        d = -f.e_n + o
        d = d / float(np.linalg.norm(d))
        s_corner = min(0.0, r.span[0]) if r.end == "start" else max(wall.length, r.span[1])
        point = f.to_world(s_corner, 0.0, wall.z_lo)
        bounds = _corner_bounds(wall, r)

        def pieces(x: Sequence[float], r: ReturnWall = r) -> List[Piece]:
            return [
                Piece(wall, [_corner_plane(wall, r.end, wall.z_lo, x[0])]),
                Piece(r.wall, [_wedge_plane(wall, wall.z_lo, x[1])]),
            ]

        u = np.cross(np.array([0.0, 0.0, 1.0]), d)
        tmpl = Template(
            "corner",
            "one_sided",
            ["beta_facade_rad", "beta_return_rad"],
            bounds,
            [],
            pieces,
            point,
            d,
            bld,
            [],
            np.array([point, point + u]),
            wall.z_lo,
            [f"corner of {wall.id} and {r.wall.id} at {wall.id}'s {r.end}"],
        )
        cand = tmpl.refine(wall.id, "outward", grid, budget)
        if cand is not None:
            out.append(cand)
    return out


@dataclass
class WorkEstimate:
    """The least work a search will do, counted before any λ0 is evaluated.

    Attributes
    ----------
    evaluations : int
        Seed-grid evaluations of λ0 the refinements make at least (each refinement starts
        with its whole seed grid, ``grid ** k`` for ``k`` parameters; the polish adds more).
    lines : int
        Candidate hinge lines, summed over the façades and directions searched.
    refinements : int
        Mechanisms that will be refined (admissible lines of the families asked for, the
        two-block walls' sides, the corners).
    complete : bool
        False where the count stopped early, past ``limit`` (the numbers are then lower
        bounds of the real ones).
    """

    evaluations: int = 0
    lines: int = 0
    refinements: int = 0
    complete: bool = True

    def describe(self) -> str:
        """Return the estimate in words (for the work limit's message)."""
        least = "" if self.complete else "at least "
        return (
            f"{least}{self.evaluations} evaluations of λ0 (the seed grids of {least}"
            f"{self.refinements} refinements over {least}{self.lines} candidate hinge lines)"
        )


def _directions(bld: Building, wall: Wall) -> List[str]:
    """Return the directions searched for a façade (a free-standing wall's: one)."""
    dirs = list(bld.spec.directions)
    return dirs[:1] if bld.free_standing(wall.id) else dirs


def work_estimate(bld: Building, limit: Optional[int] = None) -> WorkEstimate:
    """Count the least λ0 evaluations a search needs, before it evaluates any.

    Parameters
    ----------
    bld : Building
        The building and its spec.
    limit : int, optional
        Stop counting once past it (a millimetre spacing of hinge lines is refused at once).

    Returns
    -------
    WorkEstimate
    """
    spec = bld.spec
    grid = spec.candidates.grid
    est = WorkEstimate()

    def add(n: int) -> bool:
        est.evaluations += n
        est.refinements += 1
        if limit is not None and est.evaluations > limit:
            est.complete = False
            return True
        return False

    for wall in bld.walls.values():
        if not wall.is_facade:
            continue
        for direction in _directions(bld, wall):
            lines = hinge_lines(bld, wall, spec.candidates.spacing)
            est.lines += len(lines)
            for z_h in lines:
                plan = _overturning_plan(bld, wall, direction, z_h)
                if plan.why or plan.family not in spec.families:
                    continue
                if add(grid**plan.seeds):
                    return est
        if "vertical_flexure" in spec.families and _flexure_top(bld, wall):
            for _ in spec.directions:
                if add(grid):
                    return est
        if "corner" in spec.families and "outward" in spec.directions:
            for r in bld.returns.get(wall.id, []):
                if not r.corner or r.connection != "good" or wall.held_by or r.wall.held_by:
                    continue
                if bld.ties.get(wall.id) or bld.ties.get(r.wall.id):
                    continue  # not searched (``_corner_candidates``)
                if add(grid ** sum(1 for lo, hi in _corner_bounds(wall, r) if hi > lo)):
                    return est
    return est


def enumerate_candidates(
    bld: Building, budget: Optional[Budget] = None
) -> Tuple[List[Candidate], List[str]]:
    """Every refined candidate of the families and directions the spec asks for.

    ``budget`` caps the λ0 evaluations (``InputError`` on field ``work_limit`` past it).

    Returns
    -------
    candidates : list of Candidate
        In a fixed order (façade, direction, family, hinge line); repeats removed.
    notes : list of str
        Families left out where they cannot apply, and why.
    """
    spec = bld.spec
    grid = spec.candidates.grid
    budget = budget if budget is not None else Budget()
    if budget.limit is not None:
        est = work_estimate(bld, budget.limit)
        if est.evaluations > budget.limit:
            raise InputError(
                f"the search needs {est.describe()}, more than the work limit's {budget.limit}; "
                "ask for fewer families or directions, a coarser candidates.grid or a wider "
                "candidates.spacing, or raise the work limit (counted before the search ran)",
                "work_limit",
            )
    notes: List[str] = []
    out: List[Candidate] = []
    for wall in bld.walls.values():
        if not wall.is_facade:
            continue
        free_done = False
        for direction in spec.directions:
            if bld.free_standing(wall.id):
                if free_done:
                    notes.append(
                        f"{wall.id} {direction}: the free-standing wall rocks two-sided; this "
                        "direction is the negative side of its mechanisms"
                    )
                    continue
                free_done = True
            out.extend(_rigid_candidates(bld, wall, direction, spec.families, grid, notes, budget))
        if "vertical_flexure" in spec.families:
            out.extend(_flexure_candidates(bld, wall, grid, notes, budget))
        if "corner" in spec.families and "outward" in spec.directions:
            out.extend(_corner_candidates(bld, wall, grid, notes, budget))
    ground = ground_height(bld)
    for c in out:
        z = c.hinge_z - ground
        c.z_base = z if z > _tol(bld) * 1e3 else 0.0
    seen = set()
    unique = []
    for c in out:
        if c.key not in seen:
            seen.add(c.key)
            unique.append(c)
    return unique, notes
