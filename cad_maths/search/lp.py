"""The global check: a rocking-only upper-bound linear programme over all candidate lines.

The catalogue (``families``) only finds the mechanisms it lists. This check cuts the façade
and its return walls along every candidate line at once (the hinge lines, the bond-limit
diagonals from the junction at each hinge line, and the lines of every refined candidate)
into macro-blocks, gives each block a small rigid motion (6 unknowns: velocity ``u`` of
its centre of mass and rotation rate ``θ``) and lets scipy's HiGHS find the motion of least
load multiplier (upper-bound theorem of limit analysis, no dissipation for rigid,
no-tension blocks)::

    min  Σ m v_z(G) - Σ F·v(p)/g            (work of the weights and static forces)
    s.t. Σ m* d·v(G) = 1                    (unit work of the horizontal load)
         n·Δv >= 0 at every interface vertex (joints open, never interpenetrate)
         t·Δv  = 0 at hinge joints           (rocking only: bed joints do not slide)
         d·v  <= 0 where a tied level holds the wall

Interfaces, as in the catalogue: bed joints and horizontal cracks hinge without sliding;
a crack through a return wall, and a poor junction, part without friction (the
macro-block model of the wedge); a good junction does not part (the crack must run at
least at the bond angle); a tied junction does not part; a return wall's far end is held
by the wall it meets. The optimum's multiplier is at most every catalogue mechanism's
whose lines it holds, and equal to the least of them when the catalogue holds the optimal
mechanism (V3); where it is more than 1 % lower, the catalogue missed a mechanism, and the
LP's mechanism (the moving blocks) is returned.

An associative-friction variant (``friction=μ``: ``n·Δv >= μ |t_k·Δv|`` at the hinge
joints instead of ``t·Δv = 0``, an outer pyramid of the friction cone) tells where sliding
would govern.

Python 3.9-clean: imported by Rhino 8.
"""

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from cad_maths.search.families import hinge_lines, overburden_load
from cad_maths.search.model import Building, Wall
from cad_maths.search.prism import Lump, clip_rings, ring_moments, segment_intervals, winding
from shared_schema.errors import GeometryError, SolverError
from shared_schema.rules import G

__all__ = ["LPBlock", "LPModel", "LPResult", "facade_lp_model", "solve_lp"]

#: Interface kinds: hinge (no sliding), free (parts without friction), crack (opens as the
#: catalogue's wedge does: turning about the façade's hinge line at the crack's root height),
#: glued (no motion).
KINDS = ("hinge", "free", "crack", "glued")
#: Offset of the probes that find the material on each side of a line, relative to size.
PROBE_RTOL = 1e-9
#: A block smaller than this (area relative to its wall's) is dropped.
SLIVER_RTOL = 1e-10
#: A contact shorter than this (relative to the building's size) is a touch at a vertex, not
#: an interface (the side probes see such touches as slivers about as long as their offset).
CONTACT_RTOL = 1e-6
#: Candidate lines closer than this are one line: heights relative to the building's size,
#: crack angles in radians. (Refined candidates of one mechanism may sit 1e-9 apart in a
#: scene far from the origin; two such lines would cut slivers the probes cannot see.)
LINE_RTOL = 1e-6
#: A block moves in the LP's mechanism when its speed exceeds this fraction of the largest.
MOVING_RTOL = 1e-7

HalfPlane = Tuple[float, float, float]  # a s + b z + c >= 0


@dataclass
class LPBlock:
    """One macro-block.

    Attributes
    ----------
    wall : str
        The wall it belongs to.
    rings : list of (k, 2) float
        Its elevation in the wall's frame [m].
    lump : Lump
        Its mass moments.
    strip : int
        Index of its horizontal strip.
    constraints : list of (a, b, c)
        The diagonal half-planes that bound it inside its strip.
    """

    wall: str
    rings: List[np.ndarray]
    lump: Lump
    strip: int
    constraints: List[HalfPlane] = field(default_factory=list)


@dataclass
class LPInterface:
    """Contact between block ``i`` and block ``j`` (-1: a fixed support).

    ``normal`` points from ``i`` into ``j``; ``points`` are the contact's vertices [m]. A
    crack carries the ``axis`` (a point and a direction) about which its two sides may turn
    relative to each other: the façade's hinge line at the crack's root height.
    """

    i: int
    j: int
    points: np.ndarray
    normal: np.ndarray
    kind: str
    axis: Optional[Tuple[np.ndarray, np.ndarray]] = None


@dataclass
class LPModel:
    """Blocks, interfaces, restraints and loads of one façade's check.

    Attributes
    ----------
    blocks, interfaces
        The macro-blocks and their contacts.
    restraints : list of (block, point, direction)
        ``direction·v(point) <= 0``: a tied level holds the block there.
    bearing, abutting : list of (block, mass [kg], point)
        Masses whose weight (bearing) or only inertia (abutting) the block carries.
    forces : list of (block, force [N], point)
        Static forces, on any motion (thrusts).
    d : (3,) float
        Load direction.
    facade, direction : str
        What it checks.
    lines : dict
        The candidate lines used (for the output).
    ties : list of (block, force [N], point)
        Tie-bars' pulls: tension-only, each doing work only where the motion stretches its
        bar (moves its point against the pull); slack otherwise.
    """

    blocks: List[LPBlock]
    interfaces: List[LPInterface]
    restraints: List[Tuple[int, np.ndarray, np.ndarray]]
    bearing: List[Tuple[int, float, np.ndarray]]
    abutting: List[Tuple[int, float, np.ndarray]]
    forces: List[Tuple[int, np.ndarray, np.ndarray]]
    d: np.ndarray
    facade: str
    direction: str
    lines: Dict[str, Any] = field(default_factory=dict)
    ties: List[Tuple[int, np.ndarray, np.ndarray]] = field(default_factory=list)


@dataclass
class LPResult:
    """Solution of the check.

    Attributes
    ----------
    lam : float
        Least load multiplier of the LP [-] (``inf`` when nothing can move).
    status : str
        ``"optimal"``, ``"infeasible"`` (no mechanism at all) or HiGHS's message.
    moving : list of int
        Blocks that move in the optimal mechanism.
    bodies : list of list of int
        The moving blocks grouped into rigid bodies.
    velocities : (n, 6) float
        ``u`` and ``θ`` of every block (normalised: unit work of the load).
    n_blocks, n_rows, n_columns : int
        Size of the programme (work counters).
    runtime_s : float
        Solve time [s].
    friction : float or None
        μ of the associative-friction variant, None for rocking only.
    from_friction : bool
        A rocking-only result read off the friction programme's optimum, at which no joint
        slides (``solve_check``): ``n_rows``, ``n_columns`` and ``runtime_s`` are that
        programme's.
    """

    lam: float
    status: str
    moving: List[int]
    bodies: List[List[int]]
    velocities: np.ndarray
    n_blocks: int
    n_rows: int
    n_columns: int
    runtime_s: float
    friction: Optional[float] = None
    from_friction: bool = False


# --- geometry of the arrangement -------------------------------------------------------------


def _eval(h: HalfPlane, s: float, z: float) -> float:
    return h[0] * s + h[1] * z + h[2]


def _clip_segment(
    p0: np.ndarray, p1: np.ndarray, constraints: Sequence[HalfPlane]
) -> Optional[Tuple[float, float]]:
    """Parameter interval of the segment p0 -> p1 inside every half-plane (None if empty)."""
    lo, hi = 0.0, 1.0
    s0, z0, s1, z1 = float(p0[0]), float(p0[1]), float(p1[0]), float(p1[1])
    for h in constraints:
        f0 = h[0] * s0 + h[1] * z0 + h[2]  # _eval, inlined: the same sums
        f1 = h[0] * s1 + h[1] * z1 + h[2]
        if f0 < 0.0 and f1 < 0.0:
            return None
        if f0 < 0.0:
            lo = max(lo, f0 / (f0 - f1))
        elif f1 < 0.0:
            hi = min(hi, f0 / (f0 - f1))
    return (lo, hi) if hi > lo else None


def _intervals_both_sides(
    rings: Sequence[np.ndarray], p0: np.ndarray, p1: np.ndarray, offset: np.ndarray
) -> List[Tuple[float, float]]:
    """Intervals of p0 -> p1 with material just on both sides (probes shifted by ±offset)."""
    a = segment_intervals(rings, p0 + offset, p1 + offset)
    b = segment_intervals(rings, p0 - offset, p1 - offset)
    out = []
    for lo_a, hi_a in a:
        for lo_b, hi_b in b:
            lo, hi = max(lo_a, lo_b), min(hi_a, hi_b)
            if hi > lo:
                out.append((lo, hi))
    return out


def _intervals_one_side(
    rings: Sequence[np.ndarray], p0: np.ndarray, p1: np.ndarray, offset: np.ndarray
) -> List[Tuple[float, float]]:
    return segment_intervals(rings, p0 + offset, p1 + offset)


def _cells(
    wall: Wall, heights: Sequence[float], diagonals: Sequence[Tuple[float, HalfPlane]]
) -> List[LPBlock]:
    """Cut a wall into strips between ``heights`` and split each by the diagonals crossing it.

    ``diagonals`` are ``(start height, half-plane)``: a diagonal crosses the strips above its
    start; its half-plane is positive on the junction's side (the wedge).
    """
    zs = sorted({wall.z_lo, wall.z_hi, *[z for z in heights if wall.z_lo < z < wall.z_hi]})
    blocks: List[LPBlock] = []
    area = float(ring_moments(wall.rings)[0])
    for k in range(len(zs) - 1):
        lo, hi = zs[k], zs[k + 1]
        strip = clip_rings(clip_rings(wall.rings, 0.0, 1.0, -lo), 0.0, -1.0, hi)
        pieces: List[Tuple[List[np.ndarray], List[HalfPlane]]] = [(strip, [])]
        for z_s, h in diagonals:
            if z_s > lo + 1e-12 * max(abs(lo), 1.0):
                continue
            nxt = []
            for rings, cons in pieces:
                for sign in (1.0, -1.0):
                    hp = (sign * h[0], sign * h[1], sign * h[2])
                    part = clip_rings(rings, *hp)
                    if float(ring_moments(part)[0]) > SLIVER_RTOL * area:
                        nxt.append((part, [*cons, hp]))
            pieces = nxt
        for rings, cons in pieces:
            if float(ring_moments(rings)[0]) > SLIVER_RTOL * area:
                blocks.append(
                    LPBlock(
                        wall.id, rings, wall.frame.prism_lump(rings, wall.lump_density), k, cons
                    )
                )
    return blocks


def _quad(wall: Wall, s0: float, z0: float, s1: float, z1: float) -> np.ndarray:
    """World vertices of a contact along the elevation segment, through the thickness."""
    f = wall.frame
    t = f.thickness
    return np.array(
        [
            f.to_world(s0, 0.0, z0),
            f.to_world(s1, 0.0, z1),
            f.to_world(s1, t, z1),
            f.to_world(s0, t, z0),
        ]
    )


def _wall_interfaces(
    wall: Wall,
    blocks: List[int],
    all_blocks: List[LPBlock],
    size: float,
    kinds: Dict[str, str],
    axes: Dict[HalfPlane, Tuple[np.ndarray, np.ndarray]],
) -> List[LPInterface]:
    """Contacts between a wall's blocks, and with the ground.

    Parameters
    ----------
    wall : Wall
        The wall.
    blocks : list of int
        Its blocks' indices into ``all_blocks``.
    all_blocks : list of LPBlock
        Every block of the building.
    size : float
        The building's size [m], the scale of the probes and of the shortest contact.
    kinds : dict of str to str
        The interface kind of each joint family (``"diagonal"``).
    axes : dict
        A diagonal crack's half-plane -> its interface's hinge axis, where it has one.

    Returns
    -------
    list of LPInterface
        The ground's contacts, then the bed joints, then the diagonal cracks.
    """
    eps = PROBE_RTOL * size
    s_lo = float(wall.rings[0][:, 0].min()) - 1.0
    s_hi = float(wall.rings[0][:, 0].max()) + 1.0
    by_strip: Dict[int, List[int]] = {}
    for b in blocks:
        by_strip.setdefault(all_blocks[b].strip, []).append(b)
    strips = sorted(by_strip)
    zs: Dict[int, float] = {}
    for b in blocks:
        blk = all_blocks[b]
        z_min = min(float(r[:, 1].min()) for r in blk.rings)
        zs.setdefault(blk.strip, z_min)
        zs[blk.strip] = min(zs[blk.strip], z_min)
    up = np.array([0.0, eps])
    out = _ground_interfaces(wall, by_strip.get(strips[0], []), all_blocks, s_lo, s_hi, up, size)
    out += _bed_interfaces(wall, by_strip, strips, zs, all_blocks, s_lo, s_hi, up, size)
    out += _diagonal_interfaces(wall, by_strip, strips, all_blocks, eps, size, kinds, axes)
    return out


def _ground_interfaces(
    wall: Wall,
    bottom: List[int],
    all_blocks: List[LPBlock],
    s_lo: float,
    s_hi: float,
    up: np.ndarray,
    size: float,
) -> List[LPInterface]:
    """Find a wall's contacts with the ground: its bottom strip's blocks along ``z_lo``.

    Parameters
    ----------
    wall : Wall
        The wall.
    bottom : list of int
        The blocks of its bottom strip (indices into ``all_blocks``).
    all_blocks : list of LPBlock
        Every block of the building.
    s_lo, s_hi : float
        Along-wall bounds past the wall's ends [m].
    up : numpy.ndarray
        The probe offset above the line, ``(0, eps)`` [m].
    size : float
        The building's size [m].

    Returns
    -------
    list of LPInterface
        One hinge per contact span longer than ``CONTACT_RTOL * size``.
    """
    f = wall.frame
    out: List[LPInterface] = []
    for b in bottom:
        blk = all_blocks[b]
        p0, p1 = np.array([s_lo, wall.z_lo]), np.array([s_hi, wall.z_lo])
        for lo, hi in _intervals_one_side(blk.rings, p0, p1, up):
            seg = _clip_segment(p0 + lo * (p1 - p0), p0 + hi * (p1 - p0), blk.constraints)
            if seg is None:
                continue
            q0 = p0 + lo * (p1 - p0)
            q1 = p0 + hi * (p1 - p0)
            a, c = q0 + seg[0] * (q1 - q0), q0 + seg[1] * (q1 - q0)
            if c[0] - a[0] > CONTACT_RTOL * size:
                out.append(
                    LPInterface(-1, b, _quad(wall, a[0], a[1], c[0], c[1]), f.e_z.copy(), "hinge")
                )
    return out


def _bed_interfaces(
    wall: Wall,
    by_strip: Dict[int, List[int]],
    strips: List[int],
    zs: Dict[int, float],
    all_blocks: List[LPBlock],
    s_lo: float,
    s_hi: float,
    up: np.ndarray,
    size: float,
) -> List[LPInterface]:
    """Find a wall's bed joints: contacts between the blocks of strips one above the other.

    Parameters
    ----------
    wall : Wall
        The wall.
    by_strip : dict of int to list of int
        Each strip's blocks (indices into ``all_blocks``).
    strips : list of int
        The strips, bottom up.
    zs : dict of int to float
        Each strip's lowest height [m], its bed joint's.
    all_blocks : list of LPBlock
        Every block of the building.
    s_lo, s_hi : float
        Along-wall bounds past the wall's ends [m].
    up : numpy.ndarray
        The probe offset above the line, ``(0, eps)`` [m].
    size : float
        The building's size [m].

    Returns
    -------
    list of LPInterface
        One hinge per contact span longer than ``CONTACT_RTOL * size``.
    """
    f = wall.frame
    out: List[LPInterface] = []
    for k_lo, k_hi in zip(strips[:-1], strips[1:]):
        z = zs[k_hi]
        p0, p1 = np.array([s_lo, z]), np.array([s_hi, z])
        spans = _intervals_both_sides(wall.rings, p0, p1, up)
        for lo_b in by_strip[k_lo]:
            for hi_b in by_strip[k_hi]:
                cons = all_blocks[lo_b].constraints + all_blocks[hi_b].constraints
                for lo, hi in spans:
                    q0, q1 = p0 + lo * (p1 - p0), p0 + hi * (p1 - p0)
                    seg = _clip_segment(q0, q1, cons)
                    if seg is None:
                        continue
                    a, c = q0 + seg[0] * (q1 - q0), q0 + seg[1] * (q1 - q0)
                    if c[0] - a[0] > CONTACT_RTOL * size:
                        out.append(
                            LPInterface(
                                lo_b,
                                hi_b,
                                _quad(wall, a[0], a[1], c[0], c[1]),
                                f.e_z.copy(),
                                "hinge",
                            )
                        )
    return out


def _diagonal_interfaces(
    wall: Wall,
    by_strip: Dict[int, List[int]],
    strips: List[int],
    all_blocks: List[LPBlock],
    eps: float,
    size: float,
    kinds: Dict[str, str],
    axes: Dict[HalfPlane, Tuple[np.ndarray, np.ndarray]],
) -> List[LPInterface]:
    """Find a wall's diagonal cracks: contacts of two blocks of a strip that one cut parts.

    Parameters
    ----------
    wall : Wall
        The wall.
    by_strip : dict of int to list of int
        Each strip's blocks (indices into ``all_blocks``).
    strips : list of int
        The strips, bottom up.
    all_blocks : list of LPBlock
        Every block of the building.
    eps : float
        The probe distance off the crack's line [m].
    size : float
        The building's size [m].
    kinds : dict of str to str
        The interface kind of each joint family (``"diagonal"``).
    axes : dict
        A crack's half-plane -> its interface's hinge axis, where it has one.

    Returns
    -------
    list of LPInterface
        One per contact span longer than ``CONTACT_RTOL * size``, its normal from the
        negative side's block into the positive side's.
    """
    f = wall.frame
    out: List[LPInterface] = []
    for k in strips:
        members = by_strip[k]
        for ii, bi in enumerate(members):
            for bj in members[ii + 1 :]:
                ci, cj = all_blocks[bi].constraints, all_blocks[bj].constraints
                diff = [m for m, (x, y) in enumerate(zip(ci, cj)) if x != y]
                if len(diff) != 1:
                    continue
                m = diff[0]
                h = ci[m]  # positive in block bi
                others = [x for n, x in enumerate(ci) if n != m]
                z_a = min(min(float(r[:, 1].min()) for r in all_blocks[b].rings) for b in (bi, bj))
                z_b = max(max(float(r[:, 1].max()) for r in all_blocks[b].rings) for b in (bi, bj))
                if abs(h[0]) < 1e-15:
                    continue
                p0 = np.array([-(h[1] * z_a + h[2]) / h[0], z_a])
                p1 = np.array([-(h[1] * z_b + h[2]) / h[0], z_b])
                nrm = np.array([h[0], h[1]]) / math.hypot(h[0], h[1])
                for lo, hi in _intervals_both_sides(wall.rings, p0, p1, eps * nrm):
                    q0, q1 = p0 + lo * (p1 - p0), p0 + hi * (p1 - p0)
                    seg = _clip_segment(q0, q1, others)
                    if seg is None:
                        continue
                    a, c = q0 + seg[0] * (q1 - q0), q0 + seg[1] * (q1 - q0)
                    if float(np.hypot(*(c - a))) <= CONTACT_RTOL * size:
                        continue
                    # normal from bj (negative side) into bi (positive side)
                    n3 = nrm[0] * f.e_s + nrm[1] * f.e_z
                    out.append(
                        LPInterface(
                            bj,
                            bi,
                            _quad(wall, a[0], a[1], c[0], c[1]),
                            n3,
                            kinds["diagonal"],
                            axes.get(h),
                        )
                    )
    return out


# --- the model ---------------------------------------------------------------------------------


def _strip_of(blocks: List[LPBlock], ids: Sequence[int], z: float, below: bool) -> Optional[int]:
    """Return the block of ``ids`` whose height range holds ``z`` (the lower one on a joint)."""
    best = None
    for b in ids:
        zs = np.concatenate([r[:, 1] for r in blocks[b].rings])
        lo, hi = float(zs.min()), float(zs.max())
        if lo - 1e-12 <= z <= hi + 1e-12:
            if best is None:
                best = b
            elif below and lo < min(float(r[:, 1].min()) for r in blocks[best].rings):
                best = b
            elif not below and lo > min(float(r[:, 1].min()) for r in blocks[best].rings):
                best = b
    return best


def facade_lp_model(
    bld: Building,
    facade: str,
    direction: str,
    heights: Sequence[float] = (),
    angles: Optional[Mapping[str, Sequence[float]]] = None,
    overburden: Optional[Tuple[float, float]] = None,
    loads: Sequence[Any] = (),
) -> LPModel:
    """Cut a façade and its return walls along every candidate line into macro-blocks.

    Parameters
    ----------
    bld : Building
        The building.
    facade : str
        The façade's id.
    direction : {"outward", "inward"}
        The load direction.
    heights : sequence of float
        Extra horizontal lines [m] (refined hinge heights), besides ``families.hinge_lines``.
    angles : dict of str to sequence of float, optional
        Extra crack angles [rad] per return wall id, besides the bond limit.
    overburden : (N [N], n [m]), optional
        A vertical load on the façade's top at ``n`` from its outer face (default: the
        wall's spec overburden, on the centre line for a force, at its contact otherwise).
    loads : sequence of LevelLoad
        Where the best catalogue mechanism carries its levels (``families.level_loads``):
        those levels load the blocks there, so that the programme holds that mechanism
        exactly; the other levels load the façade at their contact with it.

    Returns
    -------
    LPModel
    """
    wall = bld.walls[facade]
    f = wall.frame
    d = -f.e_n if direction == "outward" else f.e_n.copy()
    zs = _merged([*hinge_lines(bld, wall, bld.spec.candidates.spacing), *heights], bld.size)
    returns = bld.returns.get(facade, []) if direction == "outward" else []
    blocks: List[LPBlock] = list(_cells(wall, zs, []))
    wall_blocks: Dict[str, List[int]] = {facade: list(range(len(blocks)))}
    lines: Dict[str, Any] = {"heights": [float(z) for z in zs], "diagonals": {}}
    crack_axes: Dict[HalfPlane, Tuple[np.ndarray, np.ndarray]] = {}
    n_face = 0.0 if direction == "outward" else wall.inner_face
    for r in returns:
        betas = set(angles.get(r.wall.id, ()) if angles else ())
        if r.connection == "good":
            betas.add(r.beta_bond)
        kept = _merged(betas, 1.0)
        diag = _diagonals(wall, r, zs, kept, n_face, crack_axes)
        lines["diagonals"][r.wall.id] = kept
        start = len(blocks)
        blocks.extend(_cells(r.wall, zs, diag))
        wall_blocks[r.wall.id] = list(range(start, len(blocks)))
    interfaces: List[LPInterface] = []
    for w_id, ids in wall_blocks.items():
        interfaces.extend(
            _wall_interfaces(
                bld.walls[w_id], ids, blocks, bld.size, {"diagonal": "crack"}, crack_axes
            )
        )
    for r in returns:
        interfaces.extend(_junction_interfaces(bld, wall, r, blocks, wall_blocks))
    model = LPModel(blocks, interfaces, [], [], [], [], d, facade, direction, lines)
    _load(bld, wall, model, wall_blocks, loads, overburden)
    return model


def _merged(values: Any, size: float) -> List[float]:
    """Return the values sorted, those within ``LINE_RTOL * size`` of a kept one dropped."""
    out: List[float] = []
    for v in sorted(float(x) for x in values):
        if not out or v - out[-1] > LINE_RTOL * size:
            out.append(v)
    return out


def _diagonals(
    wall: Wall,
    r: Any,
    zs: Sequence[float],
    betas: Sequence[float],
    n_face: float,
    crack_axes: Dict[HalfPlane, Tuple[np.ndarray, np.ndarray]],
) -> List[Tuple[float, HalfPlane]]:
    """Cracks through a return wall from the junction at every line height, every angle."""
    f = wall.frame
    diag: List[Tuple[float, HalfPlane]] = []
    for z_s in zs:
        for beta in betas:
            point = f.to_world(0.0, wall.inner_face, z_s)
            normal = -math.cos(beta) * f.e_n + math.sin(beta) * f.e_z
            h = r.wall.frame.line_of_plane(point, normal)
            if h is not None:
                diag.append((z_s, h))
                crack_axes[h] = (f.to_world(0.0, n_face, z_s), f.e_s.copy())
    return diag


def _edge_spans(
    blk: LPBlock, s: float, z_lo: float, z_hi: float, probe: np.ndarray, size: float
) -> List[Tuple[float, float]]:
    """Height intervals along the vertical line ``s`` where a block has material beside it."""
    p0, p1 = np.array([s, z_lo]), np.array([s, z_hi])
    out = []
    for lo, hi in _intervals_one_side(blk.rings, p0, p1, probe):
        q0, q1 = p0 + lo * (p1 - p0), p0 + hi * (p1 - p0)
        seg = _clip_segment(q0 + probe, q1 + probe, blk.constraints)
        if seg is None:
            continue
        z0 = q0[1] + seg[0] * (q1[1] - q0[1])
        z1 = q0[1] + seg[1] * (q1[1] - q0[1])
        if z1 - z0 > CONTACT_RTOL * size:
            out.append((float(z0), float(z1)))
    return out


def _z_range(blk: LPBlock) -> Tuple[float, float]:
    """Lowest and highest point of a block [m]."""
    z = np.concatenate([q[:, 1] for q in blk.rings])
    return float(z.min()), float(z.max())


def _junction_interfaces(
    bld: Building,
    wall: Wall,
    r: Any,
    blocks: List[LPBlock],
    wall_blocks: Dict[str, List[int]],
) -> List[LPInterface]:
    """Contacts of a return wall with the façade, and with the wall its far end meets."""
    f, rf = wall.frame, r.wall.frame
    size = bld.size
    eps = PROBE_RTOL * size
    kind = {"good": "glued", "tied": "glued", "poor": "free"}[r.connection]
    s_mid = 0.5 * (r.span[0] + r.span[1])
    t_a = wall.inner_face
    # r's elevation coordinate at the façade's inner face (sigma = 0) and at its far end
    s_j = float(rf.to_frame(f.to_world(s_mid, t_a, 0.0))[0])
    s_far = float(rf.to_frame(f.to_world(s_mid, t_a + r.reach, 0.0))[0])
    inward = 1.0 if s_far > s_j else -1.0
    abutting = r.span[0] >= -1e-9 and r.span[1] <= wall.length + 1e-9
    out: List[LPInterface] = []
    r_range = {b: _z_range(blocks[b]) for b in wall_blocks[r.wall.id]}
    for a_b in wall_blocks[wall.id]:
        a_lo, a_hi = _z_range(blocks[a_b])
        for r_b in wall_blocks[r.wall.id]:
            blk = blocks[r_b]
            # blocks of other strips share no contact (the spans below would all be empty)
            r_lo, r_hi = r_range[r_b]
            if min(a_hi, r_hi) - max(a_lo, r_lo) <= CONTACT_RTOL * size:
                continue
            if abutting:  # r's end face on the façade's inner face
                probe = np.array([inward * eps, 0.0])
                for z0, z1 in _edge_spans(blk, s_j, a_lo, a_hi, probe, size):
                    pts = np.array(
                        [
                            f.to_world(r.span[k], t_a, z)
                            for k, z in ((0, z0), (1, z0), (1, z1), (0, z1))
                        ]
                    )
                    out.append(LPInterface(a_b, r_b, pts, f.e_n.copy(), kind))
                continue
            # the façade's end face on r's side face: r's blocks beside the end
            s_end = 0.0 if r.end == "start" else wall.length
            s_r = float(rf.to_frame(f.to_world(s_mid, 0.5 * t_a, 0.0))[0])
            if not _contains(blk, s_r, 0.5 * (a_lo + a_hi)):
                continue
            pts = np.array(
                [
                    f.to_world(s_end, n, z)
                    for n, z in ((0.0, a_lo), (t_a, a_lo), (t_a, a_hi), (0.0, a_hi))
                ]
            )
            out.append(
                LPInterface(a_b, r_b, pts, -f.e_s if r.end == "start" else f.e_s.copy(), kind)
            )
    if r.far_end_wall is not None:
        # The catalogue's wedge may reach the return wall's far end: there the wall it meets
        # holds it from outside but lets it part, as the catalogue assumes.
        probe = np.array([-inward * eps, 0.0])
        for r_b in wall_blocks[r.wall.id]:
            blk = blocks[r_b]
            zr = np.concatenate([q[:, 1] for q in blk.rings])
            for z0, z1 in _edge_spans(blk, s_far, float(zr.min()), float(zr.max()), probe, size):
                pts = _quad(r.wall, s_far, z0, s_far, z1)
                out.append(LPInterface(r_b, -1, pts, inward * rf.e_s, "free"))
    return out


def _load(
    bld: Building,
    wall: Wall,
    model: LPModel,
    wall_blocks: Dict[str, List[int]],
    loads: Sequence[Any],
    overburden: Optional[Tuple[float, float]],
) -> None:
    """Put the levels, tie-bars, overburden and restraints on the model's blocks."""
    f, d, blocks = wall.frame, model.d, model.blocks
    ids = wall_blocks[wall.id]
    placed = set()
    for ld in loads:
        at = _cell_at(bld, blocks, wall_blocks, ld.point)
        if at is None or ld.level.tied:
            continue
        placed.add(ld.contact.index)
        (model.bearing if ld.bearing else model.abutting).append((at, ld.mass, ld.point))
        if ld.thrust > 0.0:
            model.forces.append((at, ld.thrust * d, ld.point))
    for c in bld.contacts.get(wall.id, []):
        b = _strip_of(blocks, ids, float(c.point[2]), below=c.bearing)
        if b is None or c.index in placed:
            continue
        if c.level.tied:
            # A tied level holds the wall; its weight enters, as in the two-block wall,
            # only through the wall's overburden.
            z = float(c.point[2])
            for s in (0.0, wall.length):
                for n in (0.0, wall.inner_face):
                    model.restraints.append((b, f.to_world(s, n, z), d))
            continue
        (model.bearing if c.bearing else model.abutting).append((b, c.mass, c.point))
        thrust = bld.roof_thrust(c, d) if c.level.kind == "roof" and c.level.pushes else 0.0
        if thrust > 0.0:
            model.forces.append((b, thrust * d, c.point))
    for t in bld.ties.get(wall.id, []):
        b = _strip_of(blocks, ids, t.z, below=False)
        if b is not None:
            model.ties.append((b, t.tie.force * t.pull, t.point))
    n_ob, x_ob, _ = overburden_load(bld, wall, -f.e_n)
    if overburden is not None:
        n_ob, x_ob = overburden[0], -overburden[1]
    if n_ob > 0.0 and any(c.level.tied for c in bld.contacts.get(wall.id, [])):
        b = _strip_of(blocks, ids, wall.z_hi, below=True)
        if b is not None:
            point = f.to_world(0.5 * wall.length, -x_ob, wall.z_hi)
            model.bearing.append((b, n_ob / G, point))


def _cell_at(
    bld: Building, blocks: List[LPBlock], wall_blocks: Dict[str, List[int]], point: np.ndarray
) -> Optional[int]:
    """Return the block holding a point of a wall's face (just below it on a top face), or None."""
    eps = 1e-7 * max(bld.size, 1.0)
    for w_id, ids in wall_blocks.items():
        w = bld.walls[w_id]
        s, n, z = (float(v) for v in w.frame.to_frame(point))
        if not -eps <= n <= w.inner_face + eps:
            continue
        for probe in (z - eps, z + eps):
            for b in ids:
                if _contains(blocks[b], s, probe):
                    return b
    return None


def _contains(blk: LPBlock, s: float, z: float) -> bool:
    return winding(blk.rings, np.array([s, z])) != 0 and all(
        _eval(h, s, z) >= 0.0 for h in blk.constraints
    )


# --- the programme -----------------------------------------------------------------------------


def _cross(a: Any, b: Any) -> np.ndarray:
    """Return the cross product of two 3-vectors (``np.cross`` costs ~20 µs a call)."""
    a0, a1, a2 = float(a[0]), float(a[1]), float(a[2])
    b0, b1, b2 = float(b[0]), float(b[1]), float(b[2])
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _basis(n: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    n = n / math.sqrt(float(n[0]) ** 2 + float(n[1]) ** 2 + float(n[2]) ** 2)
    a = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    t1 = _cross(n, a)
    t1 /= math.sqrt(float(t1 @ t1))
    return t1, _cross(n, t1)


@dataclass
class _Rows:
    """Rows ``e·(v_j(p) - v_i(p)) (<=|=) rhs`` of the programme, collected as arrays."""

    j: List[int] = field(default_factory=list)
    i: List[int] = field(default_factory=list)
    p: List[np.ndarray] = field(default_factory=list)
    e: List[np.ndarray] = field(default_factory=list)

    twists: List[Tuple[int, int, int, np.ndarray]] = field(default_factory=list)

    def add(self, j: int, i: int, p: np.ndarray, e: np.ndarray) -> None:
        self.j.append(j)
        self.i.append(i)
        self.p.append(p)
        self.e.append(e)

    def twist(self, j: int, i: int, n: np.ndarray) -> None:
        """Add the row ``n·(θ_j - θ_i) = 0`` (no relative rotation about the normal)."""
        self.twists.append((len(self.e), j, i, n))
        self.add(-1, -1, np.zeros(3), np.zeros(3))

    def matrix(self, coms: np.ndarray, ncol: int) -> Any:
        """Return the sparse matrix: ``[e, (p - c) × e]`` on j's columns, minus on i's."""
        from scipy.sparse import coo_matrix

        n = len(self.e)
        if n == 0:
            return coo_matrix((0, ncol)).tocsr()
        e = np.array(self.e)
        p = np.array(self.p)
        rows_all, cols_all, vals_all = [], [], []
        for blocks, sign in ((np.array(self.j), 1.0), (np.array(self.i), -1.0)):
            ok = blocks >= 0
            if not np.any(ok):
                continue
            b = blocks[ok]
            coef = np.hstack([e[ok], np.cross(p[ok] - coms[b], e[ok])]) * sign
            rows_all.append(np.repeat(np.flatnonzero(ok), 6))
            cols_all.append((6 * b[:, None] + np.arange(6)[None, :]).ravel())
            vals_all.append(coef.ravel())
        for row, j, i, nrm in self.twists:
            for blk, sign in ((j, 1.0), (i, -1.0)):
                if blk >= 0:
                    rows_all.append(np.full(3, row))
                    cols_all.append(6 * blk + 3 + np.arange(3))
                    vals_all.append(sign * np.asarray(nrm, dtype=float))
        if not vals_all:
            return coo_matrix((n, ncol)).tocsr()
        return coo_matrix(
            (np.concatenate(vals_all), (np.concatenate(rows_all), np.concatenate(cols_all))),
            shape=(n, ncol),
        ).tocsr()


def _point_map(coms: np.ndarray, b: int, p: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Coefficients of ``e·v_b(p)`` on block b's six unknowns."""
    return np.concatenate([e, _cross(np.asarray(p) - coms[b], e)])


def _glued_bodies(model: LPModel) -> Tuple[List[int], List[int]]:
    """Merge the blocks that glued contacts join into bodies.

    Returns the body of each block (-1: held fixed) and the reference block of each body
    (the one whose centre is the body's velocity point).
    """
    parent = list(range(len(model.blocks) + 1))  # the last node is the fixed ground
    fixed = len(model.blocks)

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for itf in model.interfaces:
        if itf.kind == "glued":
            a = fixed if itf.i < 0 else itf.i
            b = fixed if itf.j < 0 else itf.j
            ra, rb = find(a), find(b)
            if ra != rb:
                # the fixed node always stays a root
                if ra == fixed:
                    parent[rb] = ra
                else:
                    parent[ra] = rb
    roots: Dict[int, int] = {}
    body = []
    refs: List[int] = []
    for b in range(len(model.blocks)):
        r = find(b)
        if r == find(fixed):
            body.append(-1)
            continue
        if r not in roots:
            roots[r] = len(refs)
            refs.append(b)
        body.append(roots[r])
    return body, refs


def solve_lp(model: LPModel, friction: Optional[float] = None) -> LPResult:
    """Solve the check's linear programme with scipy's HiGHS (dual simplex).

    Blocks joined by glued contacts share one rigid motion (and those glued to a support
    none). A hinge joint's no-sliding condition is written once per joint (no relative
    in-plane translation at its centre, no relative twist), which is the same as no
    tangential relative velocity at every vertex of the planar joint.

    Parameters
    ----------
    model : LPModel
        The blocks and their contacts.
    friction : float, optional
        μ: hinge joints may slide with associative friction (the sliding check).

    Returns
    -------
    LPResult

    Raises
    ------
    GeometryError
        The programme is unbounded (a block falls under its own weight).
    SolverError
        HiGHS fails for another reason than an infeasible programme.
    """
    return _run(model, _programme(model, friction))[0]


#: The no-sliding check is read off the friction programme's optimum where no joint slides
#: in it: every no-sliding row within this fraction of the row's largest term (theory §10.9).
SLIP_RTOL = 1e-9


def solve_check(model: LPModel, friction: float) -> Tuple[LPResult, LPResult]:
    """Solve the check without and with sliding, the friction programme first.

    The friction programme relaxes the rocking-only one (its joints may also slide), so
    where its optimum slides at no joint, that motion is feasible for the rocking-only
    programme and optimal there too: its result is the rocking-only one, and the second
    programme is not solved (``LPResult.from_friction``). Otherwise both are solved.

    Parameters
    ----------
    model : LPModel
        The blocks and their contacts.
    friction : float
        μ of the sliding check.

    Returns
    -------
    (LPResult, LPResult)
        The rocking-only check and the sliding check, as ``solve_lp`` gives them.
    """
    prog = _programme(model, friction)
    fric, x = _run(model, prog)
    if fric.status == "infeasible":
        # the rocking-only programme's motions are among the friction programme's
        return dataclasses.replace(fric, friction=None, from_friction=True), fric
    if x is not None and _slides_nowhere(prog.slip, x):
        return dataclasses.replace(fric, friction=None, from_friction=True), fric
    return solve_lp(model), fric


def _slides_nowhere(rows: Any, x: np.ndarray) -> bool:
    """Tell whether a motion meets every hinge joint's no-sliding rows (``SLIP_RTOL``)."""
    if rows is None or rows.shape[0] == 0:
        return True
    v = x[: rows.shape[1]]
    slip = np.abs(rows @ v)
    terms = abs(rows) @ np.abs(v)
    return float(slip.max()) <= SLIP_RTOL * max(float(terms.max()), 1e-300)


@dataclass
class _Programme:
    """The check's linear programme, assembled (``_programme``)."""

    cost: np.ndarray
    a_ub: Any
    a_eq: Any
    b_eq: np.ndarray
    n_ties: int
    body: List[int]
    coms: np.ndarray
    friction: Optional[float]
    slip: Any  # the rocking-only rows of the hinge joints (friction programme only)
    t0: float


def _programme(model: LPModel, friction: Optional[float]) -> _Programme:
    """Assemble the check's programme (``solve_lp``'s docstring).

    Parameters
    ----------
    model : LPModel
        The building's blocks, interfaces, loads and restraints.
    friction : float, optional
        The joints' friction coefficient [-]; ``None`` bars sliding.

    Returns
    -------
    _Programme
        The LP's cost, constraint rows and bookkeeping.
    """
    from scipy.sparse import csr_matrix, vstack

    t0 = time.perf_counter()
    body, refs = _glued_bodies(model)
    nbody = len(refs)
    ncol = 6 * nbody
    coms = np.array([model.blocks[r].lump.com for r in refs]) if nbody else np.zeros((0, 3))
    ub, eq, slip = _contact_rows(model, body, friction)
    a_ub = ub.matrix(coms, ncol)
    scale, norm, cost = _work_vectors(model, body, coms, ncol)
    ties = [(body[k], f, p) for k, f, p in model.ties if body[k] >= 0]
    n_ties = len(ties)
    cost, norm, a_ub, eq_rows = _tie_columns(
        ties, coms, scale, (cost, norm, a_ub, eq.matrix(coms, ncol))
    )
    a_eq = vstack([eq_rows, csr_matrix(norm.reshape(1, -1))]).tocsr()
    b_eq = np.zeros(a_eq.shape[0])
    b_eq[-1] = 1.0
    return _Programme(
        cost,
        a_ub,
        a_eq,
        b_eq,
        n_ties,
        body,
        coms,
        friction,
        slip.matrix(coms, ncol) if friction is not None else None,
        t0,
    )


def _contact_rows(
    model: LPModel, body: List[int], friction: Optional[float]
) -> Tuple[_Rows, _Rows, _Rows]:
    """Write the rows of the contacts and restraints: no overlap, no sliding, or friction.

    Parameters
    ----------
    model : LPModel
        The building's interfaces and restraints.
    body : list of int
        Each block's glued body (``-1``: the ground).
    friction : float, optional
        The joints' friction coefficient [-]; ``None`` bars sliding.

    Returns
    -------
    ub : _Rows
        The inequalities (``n·Δv >= 0`` at each contact point, the friction cone's faces,
        the restraints).
    eq : _Rows
        The equalities (a crack's hinge line, no sliding without friction).
    slip : _Rows
        The sliding rates of the contacts with friction (to report).
    """
    ub, eq, slip = _Rows(), _Rows(), _Rows()

    def bid(block: int) -> int:
        """Return the glued body of a block, ``-1`` for the ground."""
        return -1 if block < 0 else body[block]

    for itf in model.interfaces:
        bi, bj = bid(itf.i), bid(itf.j)
        if itf.kind == "glued" or bi == bj:
            continue
        t1, t2 = _basis(itf.normal)
        n = itf.normal / float(np.linalg.norm(itf.normal))
        minus_n = -n
        for p in itf.points:
            ub.add(bj, bi, p, minus_n)  # n·Δv >= 0
        if itf.kind == "free":
            continue
        if itf.kind == "crack":
            # the two sides turn about the crack's hinge line only (no other sliding)
            assert itf.axis is not None
            point, direction = itf.axis
            a1, a2 = _basis(direction)
            eq.twist(bj, bi, a1)
            eq.twist(bj, bi, a2)
            for e in np.eye(3):
                eq.add(bj, bi, point, e)
            continue
        if friction is None:
            c = itf.points.mean(axis=0)
            eq.add(bj, bi, c, t1)
            eq.add(bj, bi, c, t2)
            eq.twist(bj, bi, n)
            continue
        c = itf.points.mean(axis=0)
        slip.add(bj, bi, c, t1)
        slip.add(bj, bi, c, t2)
        slip.twist(bj, bi, n)
        # n·Δv >= μ |t·Δv|: an outer pyramid of the friction cone (its 4 faces, the same
        # at every point of the contact)
        cone = [e for tk in (t1, t2) for e in (-n + friction * tk, -n - friction * tk)]
        for p in itf.points:
            for e in cone:
                ub.add(bj, bi, p, e)
    for b, p, direction in model.restraints:
        if bid(b) >= 0:
            ub.add(bid(b), -1, p, direction)
    return ub, eq, slip


def _work_vectors(
    model: LPModel, body: List[int], coms: np.ndarray, ncol: int
) -> Tuple[float, np.ndarray, np.ndarray]:
    """Weigh the bodies' velocities: the horizontal load's work and the loads' cost.

    Parameters
    ----------
    model : LPModel
        The building's blocks, masses borne and abutting, and forces.
    body : list of int
        Each block's glued body (``-1``: the ground).
    coms : numpy.ndarray
        Each body's reference point, shape ``(nbody, 3)`` [m].
    ncol : int
        The unknowns, six per body.

    Returns
    -------
    scale : float
        One over the blocks' total mass [1/kg].
    norm : numpy.ndarray
        The horizontal load's work per unknown (its row is set to one), shape ``(ncol,)``.
    cost : numpy.ndarray
        The gravity loads' and forces' work per unknown, shape ``(ncol,)``.
    """
    # normalisation: unit work of the horizontal load. Masses enter as fractions of the
    # blocks' total, so that the unknowns are of order one (HiGHS's tolerances are absolute).
    d = model.d
    scale = 1.0 / max(sum(b.lump.mass for b in model.blocks), 1e-300)
    norm = np.zeros(ncol)
    cost = np.zeros(ncol)
    ez = np.array([0.0, 0.0, 1.0])
    for k, blk in enumerate(model.blocks):
        b = body[k]
        if b < 0:
            continue
        m = scale * blk.lump.mass
        norm[6 * b : 6 * b + 6] += m * _point_map(coms, b, blk.lump.com, d)
        cost[6 * b : 6 * b + 6] += m * _point_map(coms, b, blk.lump.com, ez)
    for k, mass, p in model.bearing + model.abutting:
        if body[k] >= 0:
            norm[6 * body[k] : 6 * body[k] + 6] += scale * mass * _point_map(coms, body[k], p, d)
    for k, mass, p in model.bearing:
        if body[k] >= 0:
            cost[6 * body[k] : 6 * body[k] + 6] += scale * mass * _point_map(coms, body[k], p, ez)
    for k, force, p in model.forces:
        f = np.asarray(force, dtype=float)
        size = float(np.linalg.norm(f))
        if size > 0.0 and body[k] >= 0:
            b = body[k]
            cost[6 * b : 6 * b + 6] -= scale * size * _point_map(coms, b, p, f / size) / G
    return scale, norm, cost


def _run(model: LPModel, prog: _Programme) -> Tuple[LPResult, Optional[np.ndarray]]:
    """Solve an assembled programme with HiGHS; the result and the solution vector."""
    from scipy.optimize import linprog  # scipy: loaded with the check only

    cost, a_ub, a_eq, b_eq = prog.cost, prog.a_ub, prog.a_eq, prog.b_eq
    n_ties, body, coms, friction = prog.n_ties, prog.body, prog.coms, prog.friction
    nb = len(model.blocks)
    ncol = cost.size - n_ties
    nbody = ncol // 6
    t0 = prog.t0
    n_ub = a_ub.shape[0]

    res = linprog(
        cost,
        A_ub=a_ub if n_ub else None,
        b_ub=np.zeros(n_ub) if n_ub else None,
        A_eq=a_eq,
        b_eq=b_eq,
        bounds=[(None, None)] * ncol + [(0.0, None)] * n_ties,
        method="highs-ds",
    )
    runtime = time.perf_counter() - t0
    rows = n_ub + a_eq.shape[0]
    if res.status == 2:  # infeasible: no motion does work against the load
        return (
            LPResult(
                math.inf,
                "infeasible",
                [],
                [],
                np.zeros((nb, 6)),
                nb,
                rows,
                ncol + n_ties,
                runtime,
                friction,
            ),
            None,
        )
    if res.status == 3:
        raise GeometryError(
            f"{model.facade} {model.direction}: the check's programme is unbounded: some block "
            "falls under its own weight (is every wall standing on the ground?)"
        )
    if res.status != 0:
        raise SolverError(f"{model.facade} {model.direction}: HiGHS: {res.message}")
    x = np.asarray(res.x, dtype=float)
    vel = _velocities(model, body, coms, x[:ncol].reshape(nbody, 6))
    moving, bodies = _bodies(model, vel)
    result = LPResult(
        float(res.fun), "optimal", moving, bodies, vel, nb, rows, ncol + n_ties, runtime, friction
    )
    return result, x


def _tie_columns(
    ties: List[Tuple[int, Any, Any]],
    coms: np.ndarray,
    scale: float,
    parts: Tuple[np.ndarray, np.ndarray, Any, Any],
) -> Tuple[np.ndarray, np.ndarray, Any, Any]:
    """Add the ties' columns to the programme's cost, normalisation and constraint rows.

    A tie does work only while stretched: one more unknown t >= 0 per tie with
    t >= -pull·v(p), its bar's stretch rate, and T t / g in the cost. At the optimum
    t = max(0, stretch), so a slack bar (its point moving towards the anchorage) costs 0.
    ``ties`` holds (body, force [N] as a vector along the pull, point [m]).
    """
    cost, norm, a_ub, eq_rows = parts
    if not ties:
        return cost, norm, a_ub, eq_rows
    from scipy.sparse import csr_matrix, hstack, vstack

    n_ties, ncol = len(ties), cost.size
    stretch = np.zeros((n_ties, ncol + n_ties))
    for r, (b, f, p) in enumerate(ties):
        stretch[r, 6 * b : 6 * b + 6] = -_point_map(coms, b, p, f / float(np.linalg.norm(f)))
        stretch[r, ncol + r] = -1.0
    cost = np.concatenate([cost, [scale * float(np.linalg.norm(f)) / G for _, f, _ in ties]])
    norm = np.concatenate([norm, np.zeros(n_ties)])
    a_ub = vstack([hstack([a_ub, csr_matrix((a_ub.shape[0], n_ties))]), csr_matrix(stretch)])
    eq_rows = hstack([eq_rows, csr_matrix((eq_rows.shape[0], n_ties))])
    return cost, norm, a_ub.tocsr(), eq_rows


def _velocities(model: LPModel, body: Any, coms: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Return each block's (centre-of-mass velocity, rotation rate) from its body's motion."""
    vel = np.zeros((len(model.blocks), 6))
    for k, blk in enumerate(model.blocks):
        b = body[k]
        if b >= 0:
            u, th = x[b, :3], x[b, 3:]
            vel[k, :3] = u + np.cross(th, blk.lump.com - coms[b])
            vel[k, 3:] = th
    return vel


def _bodies(model: LPModel, vel: np.ndarray) -> Tuple[List[int], List[List[int]]]:
    """Return the moving blocks, grouped into rigid bodies (same rotation, same velocity field)."""
    speed = []
    for b, blk in enumerate(model.blocks):
        size = max(float(np.ptp(np.concatenate([r[:, 0] for r in blk.rings]))), 1e-9)
        speed.append(float(np.linalg.norm(vel[b, :3])) + size * float(np.linalg.norm(vel[b, 3:])))
    top = max(speed) if speed else 0.0
    moving = [b for b, s in enumerate(speed) if s > MOVING_RTOL * top]
    bodies: List[List[int]] = []
    for b in moving:
        for body in bodies:
            ref = body[0]
            c = model.blocks[ref].lump.com
            vb = vel[b, :3] + np.cross(vel[b, 3:], c - model.blocks[b].lump.com)
            if np.allclose(vel[b, 3:], vel[ref, 3:], atol=1e-6 * top) and np.allclose(
                vb, vel[ref, :3], atol=1e-6 * top
            ):
                body.append(b)
                break
        else:
            bodies.append([b])
    return moving, bodies
