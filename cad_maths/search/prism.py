"""Walls as prisms: elevation polygons, half-plane clips and exact mass moments.

The search works on walls that are right prisms: an elevation polygon (outer boundary and
the openings as holes) in the wall's own frame, extruded through its thickness. A crack
whose plane contains the wall's thickness direction (a horizontal bed joint, a diagonal
through a return wall) cuts the prism along a line of the elevation, so every block the
search weighs is a clipped polygon times a thickness, and its mass moments are exact
polynomial integrals (Green's theorem), equal to the mesh integrals of the constants
builder (``cad_maths.geometry.massprops``) to rounding.

Notation
--------
s, n, z : wall frame coordinates: along the wall, through the thickness (0 on the outer
    face, ``t`` on the inner face, ``e_n`` pointing inward), and height [m]
rings : list of (k, 2) float arrays of (s, z) vertices; the outer boundary counter-clockwise,
    holes clockwise, so that every integral is the sum over the rings
Lump : mass [kg], first moment ``S = ∫ x dm`` [kg m] and second moment
    ``C = ∫ x xᵀ dm`` [kg m²] about the model origin; lumps add

Python 3.9-clean: imported by Rhino 8.
"""

import math
from dataclasses import dataclass
from typing import Any, List, NamedTuple, Optional, Sequence, Tuple, cast

import numpy as np

from shared_schema.errors import GeometryError

__all__ = [
    "PIER_ASPECT_MIN",
    "PLUMB_TOL_DEG",
    "FirstMoments",
    "Lump",
    "WallAxes",
    "WallFrame",
    "clip_point_rings",
    "clip_rings",
    "point_lump",
    "ring_first_moments",
    "ring_moments",
    "rings_area",
    "segment_intervals",
    "winding",
]

Ring = np.ndarray
Rings = List[np.ndarray]
#: A frame's axes and origin as plain lists (for the per-evaluation arithmetic).
Axes = Tuple[List[float], List[float], List[float], List[float]]

#: Rings up to this many vertices are integrated and clipped in plain Python (faster than
#: numpy's per-call overhead on the few vertices of a block); longer ones (scans) in numpy.
LOOP_MAX = 64
#: Faces within this angle of the vertical are a wall's sides [deg]: an old wall's lean, or a
#: survey's tilt, of a few degrees is read as the wall it is (idealised plumb, with a note);
#: beyond it the lean is the wall's geometry (a mechanism's, not a drawing's), and is refused.
PLUMB_TOL_DEG = 5.0
#: Faces flatter than this from the vertical are tops and bottoms (a gable's slopes) [deg].
SIDE_TILT_MAX_DEG = 45.0
#: A wall's thickness direction comes from its side faces within this angle of their mean
#: direction [deg] (its two long faces, not oblique or mitred ends, nor reveals).
SIDE_WINDOW_DEG = 20.0
#: A footprint whose least enclosing rectangle has sides in a ratio below this is a pier: the
#: doubled-angle average of its faces, (a - b) / (a + b) of their area, is under a fifth and
#: vanishes on a square, so its thickness is read across the rectangle's shorter side.
PIER_ASPECT_MIN = 1.5
#: A pier's section filling its least rectangle to this fraction is that rectangle (chamfered
#: arrises, a survey's relief); less is a round or polygonal pier or several walls.
PIER_FILL_RTOL = 0.02
#: A pier's sides equal to this relative tolerance make it square (rounding of a turned plan).
PIER_SQUARE_RTOL = 1e-6
#: A face leaning on e_n by at least this cosine is one of the two faces whose lean is measured.
FACE_LEAN_COS = 0.5
#: The mid-height section moves off a vertex height closer than this fraction of the height.
SECTION_RTOL = 1e-9


@dataclass(frozen=True)
class Lump:
    """Mass moments of a body about the model origin; lumps of disjoint bodies add.

    Attributes
    ----------
    mass : float
        [kg].
    S : (3,) float
        First moment ``∫ x dm`` [kg m].
    C : (3, 3) float
        Second moment ``∫ x xᵀ dm`` [kg m²].
    """

    mass: float
    S: np.ndarray
    C: np.ndarray

    @staticmethod
    def zero() -> "Lump":
        """Return the empty lump."""
        return Lump(0.0, np.zeros(3), np.zeros((3, 3)))

    def __add__(self, other: "Lump") -> "Lump":
        return Lump(self.mass + other.mass, self.S + other.S, self.C + other.C)

    @property
    def com(self) -> np.ndarray:
        """Centre of mass [m]."""
        if not self.mass > 0.0:
            raise GeometryError("an empty block has no centre of mass")
        return self.S / self.mass

    def about(self, point: np.ndarray) -> np.ndarray:
        """Second moment ``∫ (x - p)(x - p)ᵀ dm`` about a point [kg m²]."""
        p = np.asarray(point, dtype=float)
        return self.C - np.outer(p, self.S) - np.outer(self.S, p) + self.mass * np.outer(p, p)

    def inertia_about_axis(self, point: np.ndarray, direction: np.ndarray) -> float:
        """Moment of inertia about a line through ``point`` along ``direction`` [kg m²].

        Notes
        -----
        ``I = tr(C_P) - uᵀ C_P u`` with ``C_P`` the second moment about the point.
        """
        u = np.asarray(direction, dtype=float)
        u = u / float(np.linalg.norm(u))
        c = self.about(point)
        return float(np.trace(c) - u @ c @ u)

    def inertia_com(self) -> np.ndarray:
        """Inertia tensor about the centre of mass, world axes [kg m²]."""
        c = self.about(self.com)
        return float(np.trace(c)) * np.eye(3) - c


def point_lump(mass: float, point: np.ndarray) -> Lump:
    """Lump of a point mass [kg] at ``point`` [m]."""
    p = np.asarray(point, dtype=float)
    return Lump(float(mass), mass * p, mass * np.outer(p, p))


def ring_moments(rings: Sequence[np.ndarray]) -> np.ndarray:
    """Area moments of a polygon with holes, by Green's theorem.

    Parameters
    ----------
    rings : sequence of (k, 2) float
        (s, z) vertices, not repeating the first; the outer boundary counter-clockwise and
        the holes clockwise (each ring adds its signed integrals).

    Returns
    -------
    (6,) float
        ``A, ∫s, ∫z, ∫s², ∫z², ∫sz`` over the area [m², m³, m³, m⁴, m⁴, m⁴].

    Examples
    --------
    A 2 x 1 rectangle:

    >>> ring_moments([np.array([[0.0, 0], [2, 0], [2, 1], [0, 1]])]).round(6).tolist()
    [2.0, 2.0, 1.0, 2.666667, 0.666667, 1.0]
    """
    a = ss = sz = sss = szz = ssz = 0.0
    for ring in rings:
        n = len(ring)
        if n < 3:
            continue
        if n > LOOP_MAX:
            s0, z0 = ring[:, 0], ring[:, 1]
            s1, z1 = np.roll(s0, -1), np.roll(z0, -1)
            c = s0 * z1 - s1 * z0
            a += float(np.sum(c))
            ss += float(np.sum((s0 + s1) * c))
            sz += float(np.sum((z0 + z1) * c))
            sss += float(np.sum((s0 * s0 + s0 * s1 + s1 * s1) * c))
            szz += float(np.sum((z0 * z0 + z0 * z1 + z1 * z1) * c))
            ssz += float(np.sum((s0 * z1 + 2.0 * s0 * z0 + 2.0 * s1 * z1 + s1 * z0) * c))
            continue
        pts = ring.tolist()
        p0, q0 = pts[-1]
        for p1, q1 in pts:
            c = p0 * q1 - p1 * q0
            a += c
            ss += (p0 + p1) * c
            sz += (q0 + q1) * c
            sss += (p0 * p0 + p0 * p1 + p1 * p1) * c
            szz += (q0 * q0 + q0 * q1 + q1 * q1) * c
            ssz += (p0 * q1 + 2.0 * p0 * q0 + 2.0 * p1 * q1 + p1 * q0) * c
            p0, q0 = p1, q1
    return np.array([a / 2.0, ss / 6.0, sz / 6.0, sss / 12.0, szz / 12.0, ssz / 24.0])


def ring_first_moments(rings: Sequence[Any]) -> Tuple[float, float, float]:
    """Return the first three of ``ring_moments``: ``A, ∫s, ∫z`` [m², m³, m³], the same sums.

    Each of ``ring_moments``' sums runs on its own, so these are its values to the bit; the
    second moments are not summed (the rigid multiplier needs only masses and first moments).
    The rings may be arrays or lists of [s, z] (``clip_point_rings``).

    Examples
    --------
    >>> ring_first_moments([np.array([[0.0, 0], [2, 0], [2, 1], [0, 1]])])
    (2.0, 2.0, 1.0)
    """
    a = ss = sz = 0.0
    for ring in rings:
        n = len(ring)
        if n < 3:
            continue
        if n > LOOP_MAX:
            arr = np.asarray(ring, dtype=float)
            s0, z0 = arr[:, 0], arr[:, 1]
            s1, z1 = np.roll(s0, -1), np.roll(z0, -1)
            c = s0 * z1 - s1 * z0
            a += float(np.sum(c))
            ss += float(np.sum((s0 + s1) * c))
            sz += float(np.sum((z0 + z1) * c))
            continue
        pts = ring.tolist() if isinstance(ring, np.ndarray) else ring
        p0, q0 = pts[-1]
        for p1, q1 in pts:
            c = p0 * q1 - p1 * q0
            a += c
            ss += (p0 + p1) * c
            sz += (q0 + q1) * c
            p0, q0 = p1, q1
    return a / 2.0, ss / 6.0, sz / 6.0


class FirstMoments(NamedTuple):
    """Mass and first moment of a body about the model origin (a ``Lump`` without ``C``).

    Attributes
    ----------
    mass : float
        [kg].
    S : (3,) float
        ``∫ x dm`` [kg m].
    """

    mass: float
    S: np.ndarray


def rings_area(rings: Sequence[np.ndarray]) -> float:
    """Area of a polygon with holes [m²] (the first of ``ring_moments``)."""
    return float(ring_moments(rings)[0])


def clip_rings(rings: Sequence[np.ndarray], a: float, b: float, c: float) -> Rings:
    """Keep the part of a polygon with holes where ``a s + b z + c >= 0``.

    Each ring is clipped on its own (Sutherland-Hodgman against one half-plane). A
    non-convex ring may come back with edges doubled along the clip line; they cancel in
    every boundary integral, so ``ring_moments`` of the result are those of the clipped
    region exactly.

    Parameters
    ----------
    rings : sequence of (k, 2) float
        The polygon's rings.
    a, b, c : float
        The half-plane.

    Returns
    -------
    list of (k, 2) float
        The clipped rings (those left empty are dropped).
    """
    out: Rings = []
    for ring in rings:
        pts = ring.tolist()
        kept = _clip_points(pts, a, b, c)
        if kept is pts:
            out.append(ring)
        elif kept:
            out.append(np.array(kept, dtype=float))
    return out


Points = List[List[float]]


def clip_point_rings(rings: Sequence[Points], a: float, b: float, c: float) -> List[Points]:
    """``clip_rings`` on rings given as lists of [s, z] (the same arithmetic, no arrays).

    For the loops that clip one region by several half-planes in a row (``contact_hits``):
    the rings stay Python lists between the clips.
    """
    out: List[Points] = []
    for pts in rings:
        kept = _clip_points(pts, a, b, c)
        if kept:
            out.append(kept)
    return out


def _clip_points(pts: Points, a: float, b: float, c: float) -> Optional[Points]:
    """Clip one ring (Sutherland-Hodgman): ``pts`` itself where wholly kept, None if empty."""
    f = [a * p + b * q + c for p, q in pts]
    if min(f) >= 0.0:
        return pts
    if max(f) <= 0.0:
        return None
    kept: Points = []
    n = len(pts)
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        fi, fj = f[i], f[j]
        if fi >= 0.0:
            kept.append([pts[i][0], pts[i][1]])
        if (fi > 0.0 and fj < 0.0) or (fi < 0.0 and fj > 0.0):
            w = fi / (fi - fj)
            kept.append(
                [pts[i][0] + w * (pts[j][0] - pts[i][0]), pts[i][1] + w * (pts[j][1] - pts[i][1])]
            )
    return kept if len(kept) >= 3 else None


def segment_intervals(
    rings: Sequence[np.ndarray], p0: np.ndarray, p1: np.ndarray
) -> List[Tuple[float, float]]:
    """Parameter intervals of the segment ``p0 + u (p1 - p0)``, ``u`` in [0, 1], inside a region.

    Parameters
    ----------
    rings : sequence of (k, 2) float
        The region (outer boundary and holes).
    p0, p1 : (2,) float
        The segment's ends (s, z) [m].

    Returns
    -------
    list of (float, float)
        Sorted, disjoint intervals of ``u`` where the segment runs through the region's
        interior or along its boundary with material on at least one side.
    """
    if len(rings) == 0:
        return []
    p0 = np.asarray(p0, dtype=float)
    d = np.asarray(p1, dtype=float) - p0
    # every ring's edges at once: the cuts and the winding numbers are sums over edges
    a = np.concatenate(list(rings)) if len(rings) > 1 else np.asarray(rings[0])
    b = np.concatenate([x for ring in rings for x in (ring[1:], ring[:1])])
    e = b - a
    den = d[0] * e[:, 1] - d[1] * e[:, 0]
    w = a - p0
    ok = np.abs(den) > 1e-300
    safe = np.where(ok, den, 1.0)
    u = np.where(ok, (w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]) / safe, np.nan)
    v = np.where(ok, (w[:, 0] * d[1] - w[:, 1] * d[0]) / safe, np.nan)
    hit = ok & (v >= -1e-12) & (v <= 1.0 + 1e-12) & (u > 0.0) & (u < 1.0)
    cuts = sorted({0.0, 1.0, *u[hit].tolist()})
    pieces = [(lo, hi) for lo, hi in zip(cuts[:-1], cuts[1:]) if hi - lo > 1e-12]
    if not pieces:
        return []
    # the winding number at every piece's middle at once (``winding``'s rule, point-wise)
    mids = p0 + np.array([0.5 * (lo + hi) for lo, hi in pieces])[:, None] * d
    px, pz = mids[:, :1], mids[:, 1:]
    up = (a[:, 1] <= pz) & (b[:, 1] > pz)
    down = (a[:, 1] > pz) & (b[:, 1] <= pz)
    cross = (b[:, 0] - a[:, 0]) * (pz - a[:, 1]) - (px - a[:, 0]) * (b[:, 1] - a[:, 1])
    total = np.sum(up & (cross > 0.0), axis=1) - np.sum(down & (cross < 0.0), axis=1)
    spans: List[Tuple[float, float]] = []
    for (lo, hi), inside in zip(pieces, total.tolist()):
        if inside != 0:
            if spans and abs(spans[-1][1] - lo) <= 1e-12:
                spans[-1] = (spans[-1][0], hi)
            else:
                spans.append((lo, hi))
    return spans


def winding(rings: Sequence[np.ndarray], p: np.ndarray) -> int:
    """Return the winding number of a region (sum over rings) at a point (crossing-number rule)."""
    total = 0
    px, pz = float(p[0]), float(p[1])
    for ring in rings:
        a = ring
        b = np.concatenate((ring[1:], ring[:1]))
        up = (a[:, 1] <= pz) & (b[:, 1] > pz)
        down = (a[:, 1] > pz) & (b[:, 1] <= pz)
        cross = (b[:, 0] - a[:, 0]) * (pz - a[:, 1]) - (px - a[:, 0]) * (b[:, 1] - a[:, 1])
        total += int(np.sum(up & (cross > 0.0))) - int(np.sum(down & (cross < 0.0)))
    return total


@dataclass(frozen=True)
class WallFrame:
    """A wall's frame: a point on its outer face and three unit axes.

    Attributes
    ----------
    origin : (3,) float
        Point ``s = n = z = 0`` [m] (``z`` is the world height: the origin lies at z = 0).
    e_s, e_n, e_z : (3,) float
        Along the wall, through it (outer face to inner face) and up; right-handed or not,
        as the wall's orientation gives.
    thickness : float
        ``t`` [m]: the inner face is at ``n = t``.
    """

    origin: np.ndarray
    e_s: np.ndarray
    e_n: np.ndarray
    e_z: np.ndarray
    thickness: float

    def to_world(self, s: float, n: float, z: float) -> np.ndarray:
        """World point of frame coordinates [m].

        Numbers are summed per coordinate on the axes as Python floats (the same sums as
        the arrays'); arrays of coordinates go through numpy.
        """
        if (
            isinstance(s, (float, int))
            and isinstance(n, (float, int))
            and isinstance(z, (float, int))
        ):
            es, en, ez, o = self._axes
            return np.array([o[k] + s * es[k] + n * en[k] + z * ez[k] for k in range(3)])
        return self.origin + s * self.e_s + n * self.e_n + z * self.e_z

    def to_frame(self, x: np.ndarray) -> np.ndarray:
        """Frame coordinates (s, n, z) of world points, shape (..., 3) [m]."""
        d = np.asarray(x, dtype=float) - self.origin
        return np.stack([d @ self.e_s, d @ self.e_n, d @ self.e_z], axis=-1)

    def line_of_plane(
        self, point: np.ndarray, normal: np.ndarray
    ) -> Optional[Tuple[float, float, float]]:
        """Return the plane ``normal·(x - point) >= 0`` as a half-plane ``a s + b z + c >= 0``.

        Returns None when the plane does not contain the thickness direction (it would cut
        the prism obliquely, which the elevation cannot represent).
        """
        m0, m1, m2 = float(normal[0]), float(normal[1]), float(normal[2])
        es, en, ez, o = self._axes
        if abs(m0 * en[0] + m1 * en[1] + m2 * en[2]) > 1e-9 * math.sqrt(
            m0 * m0 + m1 * m1 + m2 * m2
        ):
            return None
        a = m0 * es[0] + m1 * es[1] + m2 * es[2]
        b = m0 * ez[0] + m1 * ez[1] + m2 * ez[2]
        c = (
            m0 * (o[0] - float(point[0]))
            + m1 * (o[1] - float(point[1]))
            + m2 * (o[2] - float(point[2]))
        )
        return a, b, c

    @property
    def _axes(self) -> Axes:
        cached = self.__dict__.get("_axes_cache")
        if cached is None:
            cached = (
                self.e_s.tolist(),
                self.e_n.tolist(),
                self.e_z.tolist(),
                self.origin.tolist(),
            )
            object.__setattr__(self, "_axes_cache", cached)
        return cast(Axes, cached)

    def prism_lump(self, rings: Sequence[np.ndarray], density: float) -> Lump:
        """Lump of the prism of an elevation region through the whole thickness.

        Parameters
        ----------
        rings : sequence of (k, 2) float
            The region (s, z) [m].
        density : float
            [kg/m³].

        Notes
        -----
        In frame coordinates ``(s, n, z)`` with ``n`` in [0, t]: ``M = ρ t A``,
        ``∫ s dm = ρ t ∫s``, ``∫ n dm = ρ A t²/2``, ``∫ n² dm = ρ A t³/3``,
        ``∫ s n dm = ρ (t²/2) ∫s`` and so on; then rotated and moved to world axes.
        """
        A, Ss, Sz, Sss, Szz, Ssz = ring_moments(rings).tolist()
        t = self.thickness
        rho = float(density)
        m = rho * t * A
        first = np.array([rho * t * Ss, rho * A * t * t / 2.0, rho * t * Sz])
        h = rho * t * t / 2.0
        c = np.array(
            [
                [rho * t * Sss, h * Ss, rho * t * Ssz],
                [h * Ss, rho * A * t**3 / 3.0, h * Sz],
                [rho * t * Ssz, h * Sz, rho * t * Szz],
            ]
        )
        r = self._rotation
        o = self.origin
        s_world = r @ first
        c_world = r @ c @ r.T
        so = np.outer(o, s_world)
        c_world = c_world + so + so.T + m * np.outer(o, o)
        return Lump(m, m * o + s_world, c_world)

    def prism_first_moments(self, rings: Sequence[np.ndarray], density: float) -> FirstMoments:
        """Mass and first moment of ``prism_lump``'s prism, the same sums, without ``C``."""
        A, Ss, Sz = ring_first_moments(rings)
        t = self.thickness
        rho = float(density)
        m = rho * t * A
        first = np.array([rho * t * Ss, rho * A * t * t / 2.0, rho * t * Sz])
        return FirstMoments(m, m * self.origin + self._rotation @ first)

    @property
    def _rotation(self) -> np.ndarray:
        cached = self.__dict__.get("_rotation_cache")
        if cached is None:
            cached = np.column_stack([self.e_s, self.e_n, self.e_z])
            object.__setattr__(self, "_rotation_cache", cached)
        return cast(np.ndarray, cached)


@dataclass(frozen=True)
class WallAxes:
    """How a wall's solid stands in plan: its thickness direction, its lean, its footprint.

    Attributes
    ----------
    e_n, e_s : (3,) float
        Unit horizontal vectors: through the thickness (sign not yet fixed) and along the
        wall.
    lean : float
        ``dn/dz`` of the wall's mid-plane along ``e_n`` [-]: the tangent of its lean out of
        plumb (0 for a plumb wall), the mean of its two faces'.
    lean_faces : (float, float)
        ``dn/dz`` of the face at the lower ``n`` and of the face at the higher ``n`` [-].
    plan : (float, float)
        Longer and shorter side of the least rectangle holding the footprint at mid-height [m].
    pier : bool
        The footprint's sides are in a ratio below ``PIER_ASPECT_MIN``: ``e_n`` is read
        across its shorter side, not from its faces.
    square : bool
        A pier whose two sides are equal (``PIER_SQUARE_RTOL``): ``e_n`` follows the stated
        rule (``frame_from_mesh``).
    rule : {"", "levels", "fixed"}
        Which rule set a square pier's axis: towards its levels, or the fixed one.
    """

    e_n: np.ndarray
    e_s: np.ndarray
    lean: float = 0.0
    lean_faces: Tuple[float, float] = (0.0, 0.0)
    plan: Tuple[float, float] = (0.0, 0.0)
    pier: bool = False
    square: bool = False
    rule: str = ""

    def flipped(self) -> "WallAxes":
        """Return the axes with ``e_n`` and ``e_s`` reversed (the lean reads the other way)."""
        lo, hi = self.lean_faces
        return WallAxes(
            -self.e_n,
            -self.e_s,
            -self.lean,
            (-hi, -lo),
            self.plan,
            self.pier,
            self.square,
            self.rule,
        )


def frame_from_mesh(
    vertices: np.ndarray,
    faces: np.ndarray,
    name: str,
    prefer: Optional[np.ndarray] = None,
) -> WallAxes:
    """Thickness and length directions of a wall's solid, its lean and its footprint.

    A wall is a slab standing within ``PLUMB_TOL_DEG`` of plumb: its faces within that
    angle of the vertical are its sides. Its footprint is the horizontal section at
    mid-height, in its own principal frame (the least rectangle that holds it):

    * sides in a ratio of at least ``PIER_ASPECT_MIN``: a wall; the thickness direction is
      the horizontal axis of the side faces that carry the most area (its two large faces,
      whatever its openings), their horizontal normals averaged on the doubled angle (so
      that n and -n agree), then averaged again over the faces within ``SIDE_WINDOW_DEG``
      of that mean (so that oblique or mitred ends do not tilt it);
    * a smaller ratio: a pier, whose faces no longer tell its thickness (a square's
      doubled-angle average vanishes). A footprint that fills its rectangle (to
      ``PIER_FILL_RTOL``) is read across its shorter side, about which the bare block
      overturns first; a square one (sides equal to ``PIER_SQUARE_RTOL``) across the side
      that faces ``prefer`` (the levels it carries), else across the side nearer the x axis
      (a fixed rule: the two are alike for the bare block). Any other footprint (round,
      polygonal, several walls drawn as one solid) is refused.

    Parameters
    ----------
    vertices : (k, 3) float
        The solid's vertices [m].
    faces : (m, 3) int
        Its triangles, outward.
    name : str
        The wall's id, for the messages.
    prefer : (3,) float, optional
        A horizontal direction that picks a square pier's axis (towards its levels).

    Returns
    -------
    WallAxes

    Raises
    ------
    GeometryError
        Most of the object's side area leans beyond ``PLUMB_TOL_DEG`` (or none is within
        it: a sphere, a cone, a wall out of plumb), or its footprint is a pier's that is not
        a rectangle.
    """
    v = np.asarray(vertices, dtype=float)
    centre = v.mean(axis=0)
    tri = (v - centre)[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area2 = np.linalg.norm(normal, axis=1)
    ok = area2 > 0.0
    unit = np.zeros_like(normal)
    unit[ok] = normal[ok] / area2[ok, None]
    tilt = np.degrees(np.arcsin(np.clip(np.abs(unit[:, 2]), 0.0, 1.0)))
    vertical = ok & (tilt <= PLUMB_TOL_DEG)
    leaning = ok & (tilt > PLUMB_TOL_DEG) & (tilt < SIDE_TILT_MAX_DEG)
    _check_plumb(name, area2, tilt, vertical, leaning)
    section = _mid_section(v - centre, faces, unit)
    plan = (0.0, 0.0)
    pier = square = False
    rule = ""
    if section is not None:
        axis, long_side, short_side, filled = section
        plan = (long_side, short_side)
        if short_side > 0.0 and long_side < PIER_ASPECT_MIN * short_side:
            pier = True
            if filled < 1.0 - PIER_FILL_RTOL:
                raise GeometryError(
                    f"{name}: its footprint at mid-height ({long_side:.3f} x {short_side:.3f} m "
                    f"in plan, sides in a ratio {long_side / short_side:.3g} below "
                    f"{PIER_ASPECT_MIN:g}) fills {100 * filled:.0f} % of the least rectangle "
                    "holding it: a round or polygonal pier or tower, or several walls drawn as "
                    "one solid, whose thickness direction the search cannot tell (it reads "
                    "walls as slabs). Split it into walls (one solid per side), or analyse it "
                    "as a rigid block with a mechanism spec (`rockmech constants`)"
                )
            e_n, rule = _pier_axis(axis, long_side, short_side, prefer)
            square = bool(rule)
    if not pier:
        ang = np.arctan2(unit[vertical, 1], unit[vertical, 0])
        w = area2[vertical]
        theta = _doubled_mean(ang, w)
        # again on the long faces alone: oblique or mitred ends would tilt the mean
        off = np.abs(np.angle(np.exp(2j * (ang - theta)))) / 2.0
        near = off <= math.radians(SIDE_WINDOW_DEG)
        if np.any(near):
            theta = _doubled_mean(ang[near], w[near])
        e_n = np.array([math.cos(theta), math.sin(theta), 0.0])
    # Snap to the axes when the wall is drawn along them (exact frames for exact walls).
    for k in range(2):
        if abs(abs(e_n[k]) - 1.0) < 1e-12:
            e_n = np.zeros(3)
            e_n[k] = 1.0
    e_s = np.array([-e_n[1], e_n[0], 0.0])
    lo, hi = _face_leans(unit, area2, vertical, e_n)
    return WallAxes(e_n, e_s, 0.5 * (lo + hi), (lo, hi), plan, pier, square, rule)


def _doubled_mean(ang: np.ndarray, w: np.ndarray) -> float:
    """Return the weighted mean of axial directions (angles [rad], n and -n alike) [rad]."""
    c2 = float(np.sum(w * np.cos(2.0 * ang)))
    s2 = float(np.sum(w * np.sin(2.0 * ang)))
    return 0.5 * math.atan2(s2, c2)


def _check_plumb(
    name: str, area2: np.ndarray, tilt: np.ndarray, vertical: np.ndarray, leaning: np.ndarray
) -> None:
    """Refuse a solid whose side area leans mostly beyond ``PLUMB_TOL_DEG`` (module doc)."""
    a_vert = float(np.sum(area2[vertical]))
    a_lean = float(np.sum(area2[leaning]))
    if a_vert > 0.0 and a_lean <= a_vert:
        return
    if a_lean > 0.0:
        mean = float(np.sum(area2[leaning] * tilt[leaning]) / a_lean)
        share = 100.0 * a_lean / (a_lean + a_vert)
        said = (
            f"{share:.0f} % of its side faces lean more than {PLUMB_TOL_DEG:g} degrees from the "
            f"vertical ({mean:.1f} degrees on average)"
        )
    else:
        said = f"none of its faces is within {SIDE_TILT_MAX_DEG:g} degrees of the vertical"
    raise GeometryError(
        f"{name}: {said}; a wall is a slab standing within {PLUMB_TOL_DEG:g} degrees of plumb "
        "(read as plumb, with a note). Select the wall's own solid; redraw a wall whose lean is "
        "a drawing's error plumb; analyse a wall leaning more, or a block of another shape, "
        "with a mechanism spec (`rockmech constants`); give a roof, a vault or a dome as a "
        "level, not a wall"
    )


def _mid_section(
    v: np.ndarray, faces: np.ndarray, unit: np.ndarray
) -> Optional[Tuple[np.ndarray, float, float, float]]:
    """Return the solid's horizontal section at mid-height in its least enclosing rectangle.

    Returns ``(axis, long, short, filled)``: the unit direction (3,) of the rectangle's
    shorter side, its longer and shorter sides [m], and the section's area over the
    rectangle's [-]; None where no face crosses mid-height (a flat solid).

    Notes
    -----
    Each face crossing the plane ``z = z_m`` cuts it along a segment, oriented along
    ``e_z × m`` (``m`` the face's outward normal) so that the material lies on its left;
    the section's area is then ``Σ (p × q) / 2`` over the segments (Green's theorem).
    ``z_m`` is moved off any vertex height to the middle of the nearest gap.
    """
    z = v[:, 2]
    z_lo, z_hi = float(z.min()), float(z.max())
    z_m = 0.5 * (z_lo + z_hi)
    levels = np.unique(z)
    eps = SECTION_RTOL * (z_hi - z_lo)
    if np.any(np.abs(levels - z_m) <= eps):
        below = levels[levels < z_m - eps]
        if len(below) == 0:
            return None
        z_m = 0.5 * (float(below.max()) + float(levels[levels >= z_m - eps].min()))
    d = v[faces, 2] - z_m  # (m, 3): no vertex lies on the plane
    side = d > 0.0
    cut = np.flatnonzero(np.any(side, axis=1) & ~np.all(side, axis=1))
    if len(cut) == 0:
        return None
    seg = np.zeros((len(cut), 2, 2))
    for k, (f, dd) in enumerate(zip(faces[cut], d[cut])):
        pts = []
        for i in range(3):
            j = (i + 1) % 3
            if (dd[i] > 0.0) != (dd[j] > 0.0):
                w = dd[i] / (dd[i] - dd[j])
                pts.append(v[f[i], :2] + w * (v[f[j], :2] - v[f[i], :2]))
        seg[k] = pts
    m = unit[cut]
    along = np.column_stack([-m[:, 1], m[:, 0]])
    dirn = seg[:, 1] - seg[:, 0]
    flip = np.einsum("ij,ij->i", dirn, along) < 0.0
    seg[flip] = seg[flip][:, ::-1]
    p, q = seg[:, 0], seg[:, 1]
    area = 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))
    hull = _convex_hull(seg.reshape(-1, 2))
    if len(hull) < 3:
        return None
    best: Optional[Tuple[float, np.ndarray, float, float]] = None
    for a, b in zip(hull, np.roll(hull, -1, axis=0)):
        u = (b - a) / float(np.linalg.norm(b - a))
        w2 = np.array([-u[1], u[0]])
        ext_u = float(np.ptp(hull @ u))
        ext_w = float(np.ptp(hull @ w2))
        if best is None or ext_u * ext_w < best[0] * (1.0 - 1e-12):
            best = (ext_u * ext_w, u, ext_u, ext_w)
    assert best is not None
    rect, u, ext_u, ext_w = best
    short_dir = u if ext_u <= ext_w else np.array([-u[1], u[0]])
    axis = np.array([short_dir[0], short_dir[1], 0.0])
    return axis, max(ext_u, ext_w), min(ext_u, ext_w), area / rect if rect > 0.0 else 0.0


def _convex_hull(points: np.ndarray) -> np.ndarray:
    """Convex hull of 2-D points, counter-clockwise (Andrew's monotone chain)."""
    pts = np.unique(points, axis=0)
    if len(pts) < 3:
        return pts
    order = np.lexsort((pts[:, 1], pts[:, 0]))
    pts = pts[order].tolist()

    def cross(o: List[float], a: List[float], b: List[float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: List[List[float]] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0.0:
            lower.pop()
        lower.append(p)
    upper: List[List[float]] = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0.0:
            upper.pop()
        upper.append(p)
    return np.asarray(lower[:-1] + upper[:-1], dtype=float)


def _pier_axis(
    axis: np.ndarray, long_side: float, short_side: float, prefer: Optional[np.ndarray]
) -> Tuple[np.ndarray, str]:
    """Return a pier's thickness direction and, for a square one, the rule that chose it.

    Across its shorter side (rule ""); a square's across the side that faces ``prefer``
    ("levels"), else across the side nearer the x axis ("fixed"; at 45 degrees, the one
    whose normal has x and y of one sign).
    """
    if long_side - short_side > PIER_SQUARE_RTOL * long_side:
        return axis, ""
    other = np.array([-axis[1], axis[0], 0.0])
    if prefer is not None:
        a, b = abs(float(prefer @ axis)), abs(float(prefer @ other))
        if abs(a - b) > PIER_SQUARE_RTOL * max(a, b, 1e-300):
            return (axis if a > b else other), "levels"
    ax, bx = abs(float(axis[0])), abs(float(other[0]))
    if abs(ax - bx) > 1e-12:
        return (axis if ax > bx else other), "fixed"
    return (axis if axis[0] * axis[1] > 0.0 else other), "fixed"


def _face_leans(
    unit: np.ndarray, area2: np.ndarray, vertical: np.ndarray, e_n: np.ndarray
) -> Tuple[float, float]:
    """``dn/dz`` of the faces at the lower and at the higher ``n`` (area-weighted) [-].

    A face with outward unit normal ``m`` runs ``n(z) = (c - m_z z) / m_n``: ``dn/dz =
    -m_z / m_n``, with ``m_n = m · e_n``.
    """
    m_n = unit @ e_n
    out = []
    for sign in (-1.0, 1.0):
        pick = vertical & (sign * m_n >= FACE_LEAN_COS)
        if not np.any(pick):
            out.append(0.0)
            continue
        slope = -unit[pick, 2] / m_n[pick]
        out.append(float(np.sum(area2[pick] * slope) / np.sum(area2[pick])))
    return out[0], out[1]
