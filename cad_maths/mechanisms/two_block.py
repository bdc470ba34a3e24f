"""Two-block (vertical spanning strip) mechanism as planar rigid-body maths (theory §2.3, §3.4, §4).

Everything here lives in the rocking plane: x horizontal, positive in the direction of
collapse (outward), z up [m]. There is no CAD here; the pipeline passes planar bodies and
hinge points.

Notation (theory §0, §2.3)
--------------------------
O : base hinge of block 1 (fixed) [m]
C : hinge between block 1 (lower) and block 2 (upper) [m]
H : top hinge of block 2, restrained horizontally and free vertically [m]
P : point of block 2 where the overburden N acts, vertically downwards (default: H) [m]
phi : rotation of block 1 about O, positive when C moves outward (+x) [rad]
phi2 : rotation of block 2, positive in the sense opposite to phi, so that the bulging
    mode has ``omega2 = dphi2/dphi > 0`` (theory's convention) [rad]
m_k, I_Gk : mass [kg] and centroidal moment of inertia [kg m²] of block k
R1, alpha1 : distance O-G1 and its angle from the vertical [m, rad]
R2, alpha2 : distance H-G2 and its angle from the vertical [m, rad]
V : potential energy ``g (m1 z_G1 + m2 z_G2) + N z_P`` [J]
I0, K, Q, phi_cr, M_F, p_eq, lam, phi_ov : the constants of Eqs. 1-6.

Kinematics. Block 1 turns about O by phi. Block 2 is pinned to block 1 at C and turns by
its own angle so that x_H stays at its rest value. The constraint is solved in closed form
(one arcsine) on the branch that is continuous from rest; the velocity ratio
``omega2 = dphi2/dphi`` and its derivative follow by implicit differentiation, as for the
four-bar of theory §2.4. Then (theory §1.1)::

    M(phi) = sum_k I_Gk (dphi_k/dphi)² + m_k |dr_Gk/dphi|²,    Q(phi) = sum_k m_k dx_Gk/dphi

and the critical rotation is the first maximum of V (dV/dphi = 0, found by bracketing and
bisection). For rectangles with N at H it is the collinear configuration of O, C, H
(Eq. 19, ``phi_cr = alpha1``), and the constants equal Eqs. 18-22.

Eccentric overburden. When N acts at a point P other than H, two documented treatments are
offered (``ECCENTRICITY_OPTIONS``):

* ``"static_moment"`` (default, theory Eq. 23): V holds N at H; the eccentric part of N,
  ``N (z_P - z_H)``, enters as the static moment
  ``M_F = -N d(z_P - z_H)/dphi`` at phi_cr, which for a rectangle is
  ``N xi b cos(alpha2) R1/R2``;
* ``"potential"`` (exact linearisation): V holds N at P, phi_cr is the maximum of that V,
  and ``M_F = 0``.

docs/theory.md reports the two within about 1 % of each other for ``xi`` from 0.5 to 1.
"""

import math
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

from shared_schema.errors import GeometryError, InputError
from shared_schema.rules import G, check_non_negative, check_positive

__all__ = [
    "ECCENTRICITY_OPTIONS",
    "PlanarBody",
    "TwoBlockResult",
    "hinge_height",
    "rectangular_bodies",
    "rectangular_hinges",
    "rectangular_two_block",
    "rest_virtual_work",
    "two_block_constants",
    "two_block_restitution",
]

#: Treatments of an eccentric overburden (see the module docstring), for provenance.
ECCENTRICITY_OPTIONS = {
    "static_moment": "N at H inside V; eccentric part as M_F = -N d(z_P - z_H)/dphi (Eq. 23)",
    "potential": "N at its point inside V (exact linearisation); M_F = 0",
}
#: Largest rotation of block 1 searched for the critical rotation [rad] (block 1 lying flat).
PHI_SEARCH_MAX = 0.5 * math.pi
#: Number of scan intervals over (0, PHI_SEARCH_MAX]; the grid is quadratic, fine near rest.
N_SCAN = 400
#: Hinges closer than this, relative to the size of the mechanism, count as coincident.
COINCIDENT_RTOL = 1e-9
#: Smallest |cos| of block 2's hinge line at which the top constraint still fixes phi2.
LOCK_TOL = 1e-12

Point2 = Tuple[float, float]


@dataclass(frozen=True)
class PlanarBody:
    """A rigid body in the rocking plane.

    Attributes
    ----------
    mass : float
        Mass [kg], > 0.
    com : (float, float)
        Centre of mass (x, z) [m].
    i_g : float
        Moment of inertia about the axis through the centre of mass, normal to the plane
        [kg m²], >= 0.
    j_z : float, optional
        Second moment of the mass about the horizontal plane through the centre of mass,
        ``∫ (z - z_G)² dm`` [kg m²], >= 0; needed only for the code check's virtual-work
        quantities (theory §11.1), which are omitted when a block lacks it.
    """

    mass: float
    com: Tuple[float, float]
    i_g: float
    j_z: Optional[float] = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.mass) and self.mass > 0.0):
            raise InputError(f"must be finite and > 0, got {self.mass!r}", "mass")
        if not (math.isfinite(self.i_g) and self.i_g >= 0.0):
            raise InputError(f"must be finite and >= 0, got {self.i_g!r}", "i_g")
        if self.j_z is not None and not (math.isfinite(self.j_z) and self.j_z >= 0.0):
            raise InputError(f"must be finite and >= 0, got {self.j_z!r}", "j_z")
        _point(self.com, "com")


@dataclass(frozen=True)
class LinkageResult:
    """Kinematic constants of a linkage mechanism about ``phi = phi_cr`` (theory §1.2).

    Attributes
    ----------
    I0, K, Q, phi_cr, M_F : float
        Eq. 1's constants [kg m²], [N m/rad], [kg m], [rad], [N m].
    p_eq, lam, phi_ov : float
        Eqs. 4-6 [1/s], [-], [rad].
    details : dict of str to float
        Mechanism-specific diagnostics (see the subclasses).
    """

    I0: float
    K: float
    Q: float
    phi_cr: float
    M_F: float
    p_eq: float
    lam: float
    phi_ov: float
    details: Dict[str, float] = field(default_factory=dict)

    def constants(self, side: str = "positive") -> Dict[str, float]:
        """Return the constants as the kinematic-constants file stores them for ``side``.

        Parameters
        ----------
        side : {"positive", "negative"}
            The side of the mechanism this result describes. A result is computed in that
            side's own frame, where ``M_F > 0`` drives *that* side towards collapse. The
            file signs ``M_F`` in the mechanism's positive sense on both sides
            (``shared_schema.constants``, theory §1.8), so on the negative side it changes
            sign; the other constants are magnitudes and are stored as they are.

        Returns
        -------
        dict
            ``I0`` [kg m²], ``K`` [N m/rad], ``Q`` [kg m], ``phi_cr`` [rad], ``M_F`` [N m].
        """
        if side not in ("positive", "negative"):
            raise InputError(f"must be 'positive' or 'negative', got {side!r}", "side")
        m_f = self.M_F if side == "positive" else 0.0 - self.M_F  # no -0.0
        return {"I0": self.I0, "K": self.K, "Q": self.Q, "phi_cr": self.phi_cr, "M_F": m_f}


@dataclass(frozen=True)
class TwoBlockResult(LinkageResult):
    """Kinematic constants of a two-block mechanism about ``phi = phi_cr`` (theory §1.2).

    Attributes
    ----------
    I0 : float
        Generalised inertia M(phi_cr) [kg m²].
    K : float
        Stiffness ``-V''(phi_cr)`` [N m/rad], > 0.
    Q : float
        Ground-motion coefficient ``sum m_k dx_Gk/dphi`` at phi_cr [kg m].
    phi_cr : float
        Critical rotation of block 1 [rad].
    M_F : float
        Static moment (the eccentric overburden under ``"static_moment"``) [N m].
    p_eq, lam, phi_ov : float
        Eqs. 4-6 [1/s], [-], [rad].
    details : dict of str to float
        ``R1``, ``alpha1``, ``R2``, ``alpha2`` (rest geometry); ``L_OC``, ``L_CH`` (hinge
        distances) [m]; ``I_O1`` (block 1 about O), ``I_O2`` (block 2 about H, theory's
        name) [kg m²];
        ``phi2_cr`` [rad], ``omega2`` (dphi2/dphi) and ``domega2`` (its derivative) at
        phi_cr; ``lam_static_exact``, the exact static multiplier ``V'(0)/(g Q(0))`` with N
        at its own point (theory §1.6); where both blocks carry ``j_z``, ``S0`` [kg m],
        ``J0`` [kg m²] and ``mass0`` [kg], the virtual-work quantities at rest (§11.1).
    eccentricity : str
        The treatment of an eccentric overburden that was used (``ECCENTRICITY_OPTIONS``).
    """

    eccentricity: str = "static_moment"


def _point(p: Sequence[float], name: str) -> Point2:
    try:
        x, z = (float(v) for v in p)
    except (TypeError, ValueError) as exc:
        raise InputError(f"must be a pair of numbers (x, z), got {p!r}", name) from exc
    if not (math.isfinite(x) and math.isfinite(z)):
        raise InputError(f"must be finite, got {p!r}", name)
    return (x, z)


def hinge_height(h: float, weight: float, overburden: float, f_mt: float, area: float) -> float:
    """Height of the intermediate hinge of a vertically spanning strip (Eq. 17).

    Parameters
    ----------
    h : float
        Height of the wall between its supports [m], > 0.
    weight : float
        Self-weight W of the wall [N], >= 0.
    overburden : float
        Axial load N on top of the wall [N], >= 0.
    f_mt : float
        Flexural tensile strength of the masonry [Pa], >= 0.
    area : float
        Cross-section ``l * b`` [m²], >= 0.

    Returns
    -------
    float
        h_c, the hinge height measured from the base [m].

    Raises
    ------
    InputError
        A negative or non-finite input, or ``N + W + f_mt A = 0`` (nothing loads the wall).

    Notes
    -----
    theory §4, Eq. 17: the crack forms at the height z that minimises the lateral load
    ``w(z) ∝ (f_mt A + N + W (h - z)/h) / (z (h - z))``, which gives::

        h_c = h / (1 + sqrt((N + f_mt A) / (N + W + f_mt A)))

    Examples
    --------
    >>> hinge_height(3.0, weight=0.0, overburden=1e4, f_mt=0.0, area=0.3)
    1.5
    >>> hinge_height(3.0, weight=1e4, overburden=0.0, f_mt=0.0, area=0.3)
    3.0
    """
    h = check_positive(h, "h")
    w = check_non_negative(weight, "weight")
    n = check_non_negative(overburden, "overburden")
    f = check_non_negative(f_mt, "f_mt")
    a = check_non_negative(area, "area")
    top = n + f * a
    if top + w <= 0.0:
        raise InputError("N + W + f_mt A must be > 0 (nothing loads the wall)", "weight")
    return h / (1.0 + math.sqrt(top / (top + w)))


# --- kinematics ---------------------------------------------------------------------------


def _rot(v: Point2, phi: float) -> Point2:
    # Rotation by phi, positive clockwise in (x, z): a point above the pivot moves to +x.
    c, s = math.cos(phi), math.sin(phi)
    return (v[0] * c + v[1] * s, -v[0] * s + v[1] * c)


def _perp(v: Point2) -> Point2:
    # d/dphi of _rot(v, phi) is _perp(_rot(v, phi)).
    return (v[1], -v[0])


def _sub(a: Point2, b: Point2) -> Point2:
    return (a[0] - b[0], a[1] - b[1])


def _add(a: Point2, b: Point2) -> Point2:
    return (a[0] + b[0], a[1] + b[1])


def _scale(k: float, a: Point2) -> Point2:
    return (k * a[0], k * a[1])


def _dot(a: Point2, b: Point2) -> float:
    return a[0] * b[0] + a[1] * b[1]


class _Chain:
    """Closed-form kinematics of the chain O-C-H with H_x fixed.

    Block 1 turns by ``phi`` about O; block 2 by ``beta`` (same clockwise sense, so
    ``beta = -phi2``) about C. The constraint ``x_H = x_H(0)`` reads
    ``L sin(gamma + beta) = L sin(gamma) - (x_C(phi) - x_C(0))`` with ``(L, gamma)`` the
    length and angle from the vertical of C->H at rest.
    """

    def __init__(self, o: Point2, c: Point2, h: Point2) -> None:
        self.O, self.C0, self.H0 = o, c, h
        self.oc = _sub(c, o)
        ch = _sub(h, c)
        self.L = math.hypot(ch[0], ch[1])
        self.gamma = math.atan2(ch[0], ch[1])
        self.up = math.cos(self.gamma) > 0.0  # branch of the arcsine continuous from rest
        if abs(math.cos(self.gamma)) < LOCK_TOL:
            raise GeometryError(
                "the mechanism locks at rest: C and H are level, so the horizontal "
                "restraint at H does not fix the rotation of block 2"
            )

    def beta(self, phi: float) -> Optional[Tuple[float, float, float]]:
        """``(beta, dbeta/dphi, d²beta/dphi²)``, or None where the chain cannot close."""
        c = _rot(self.oc, phi)
        s = (self.L * math.sin(self.gamma) - (c[0] - self.oc[0])) / self.L
        if not abs(s) < 1.0:
            return None
        psi = math.asin(s) if self.up else math.pi - math.asin(s)
        cos_psi = math.cos(psi)
        if abs(cos_psi) < LOCK_TOL:
            return None
        # Implicit differentiation of L sin(psi) = const - x_C(phi), psi = gamma + beta.
        dxc = _perp(c)[0]
        d2xc = -c[0]
        b1 = -dxc / (self.L * cos_psi)
        b2 = (-d2xc + self.L * math.sin(psi) * b1 * b1) / (self.L * cos_psi)
        return psi - self.gamma, b1, b2

    def motion(
        self, point: Point2, block: int, phi: float, bet: Tuple[float, float, float]
    ) -> Tuple[Point2, Point2, Point2]:
        """Position, d/dphi and d²/dphi² of a material point of block 1 or 2."""
        r1 = _rot(_sub(point if block == 1 else self.C0, self.O), phi)
        p1, d1 = _add(self.O, r1), _perp(r1)
        a1 = _scale(-1.0, r1)
        if block == 1:
            return p1, d1, a1
        b, b1, b2 = bet
        r2 = _rot(_sub(point, self.C0), b)
        pos = _add(p1, r2)
        vel = _add(d1, _scale(b1, _perp(r2)))
        acc = _add(_add(a1, _scale(b2, _perp(r2))), _scale(-b1 * b1, r2))
        return pos, vel, acc


@dataclass
class _State:
    beta: Tuple[float, float, float]
    dV: float  # dV/dphi [N m]
    d2V: float  # d²V/dphi² [N m]
    M: float  # generalised inertia [kg m²]
    Q: float  # sum m dx_G/dphi [kg m]
    dz_ecc: float  # d(z_P - z_H)/dphi [m]


def _state(
    chain: _Chain,
    lower: PlanarBody,
    upper: PlanarBody,
    n: float,
    p_load: Point2,
    phi: float,
    p_ecc: Optional[Point2] = None,
) -> Optional[_State]:
    # N enters V at p_load; p_ecc (default p_load) is where it really acts.
    bet = chain.beta(phi)
    if bet is None:
        return None
    _, v1, a1 = chain.motion(lower.com, 1, phi, bet)
    _, v2, a2 = chain.motion(upper.com, 2, phi, bet)
    _, vp, ap = chain.motion(p_load, 2, phi, bet)
    _, ve, _ = chain.motion(p_load if p_ecc is None else p_ecc, 2, phi, bet)
    _, vh, _ = chain.motion(chain.H0, 2, phi, bet)
    dV = G * (lower.mass * v1[1] + upper.mass * v2[1]) + n * vp[1]
    d2V = G * (lower.mass * a1[1] + upper.mass * a2[1]) + n * ap[1]
    M = lower.i_g + lower.mass * _dot(v1, v1) + upper.i_g * bet[1] ** 2 + upper.mass * _dot(v2, v2)
    Q = lower.mass * v1[0] + upper.mass * v2[0]
    return _State(bet, dV, d2V, M, Q, ve[1] - vh[1])


def rest_virtual_work(
    bodies: Sequence[PlanarBody],
    u_x: Sequence[float],
    omega: Sequence[float],
    alpha0: float,
) -> Optional[Dict[str, float]]:
    """Virtual-work quantities at rest of a linkage (theory §11.1), or None without ``j_z``.

    Parameters
    ----------
    bodies : sequence of PlanarBody
        The blocks.
    u_x : sequence of float
        Horizontal velocity ratio ``dx_G/dphi`` of each block's centre at rest, towards
        collapse [m/rad].
    omega : sequence of float
        Rotation ratio ``dphi_k/dphi`` of each block at rest [-].
    alpha0 : float
        Exact static multiplier at rest [-].

    Notes
    -----
    A point of block k at height ``z`` moves by ``δx = u_x,k ± omega_k (z - z_Gk)``, so
    ``sum ∫ δx² dm = sum (m_k u_x,k² + omega_k² j_z,k)`` (the cross term vanishes about G).
    Circolare 2019 [C8.7.1.5] sums one term per block, at the centroid of its forces:
    ``J_blocks = sum m_k u_x,k²`` (docs/theory.md §11.1).
    """
    if any(b.j_z is None for b in bodies):
        return None
    s = sum(b.mass * u for b, u in zip(bodies, u_x))
    j = sum(b.mass * u * u + w * w * float(b.j_z or 0.0) for b, u, w in zip(bodies, u_x, omega))
    j_blocks = sum(b.mass * u * u for b, u in zip(bodies, u_x))
    mass = sum(b.mass for b in bodies)
    return {"alpha0": alpha0, "mass": mass, "S": s, "J": j, "J_blocks": j_blocks}


def _critical(
    chain: _Chain,
    lower: PlanarBody,
    upper: PlanarBody,
    n: float,
    p_load: Point2,
    p_ecc: Point2,
) -> Tuple[float, _State]:
    """First maximum of V on (0, PHI_SEARCH_MAX]: scan for dV/dphi going + to -, bisect."""
    s0 = _state(chain, lower, upper, n, p_load, 0.0)
    assert s0 is not None  # the chain closes at rest by construction
    if not s0.dV > 0.0:
        raise GeometryError(
            "the mechanism has no critical rotation: it is not stable at rest "
            f"(dV/dphi = {s0.dV:.6g} N m <= 0 at phi = 0)"
        )
    lo = 0.0
    hi = None
    for k in range(1, N_SCAN + 1):
        phi = PHI_SEARCH_MAX * (k / N_SCAN) ** 2
        s = _state(chain, lower, upper, n, p_load, phi)
        if s is None:
            raise GeometryError(
                "the mechanism locks before it reaches a critical rotation (block 2 "
                f"cannot keep H on its restraint beyond phi = {lo:.6g} rad)"
            )
        if s.dV <= 0.0:
            hi = phi
            break
        lo = phi
    if hi is None:
        raise GeometryError(
            "the mechanism has no critical rotation: dV/dphi stays positive up to "
            f"phi = {PHI_SEARCH_MAX:.6g} rad"
        )
    # Bisection to the last bit: dV/dphi is smooth, and the bracket is certain.
    while True:
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        s = _state(chain, lower, upper, n, p_load, mid)
        if s is None:  # cannot happen inside a bracket of closable configurations
            raise GeometryError("the mechanism locks inside the critical-rotation bracket")
        if s.dV > 0.0:
            lo = mid
        else:
            hi = mid
    phi_cr = 0.5 * (lo + hi)
    s_cr = _state(chain, lower, upper, n, p_load, phi_cr, p_ecc)
    assert s_cr is not None
    return phi_cr, s_cr


def _check_chain(points: List[Tuple[str, Point2]], bodies: Sequence[PlanarBody]) -> None:
    coords = [p for _, p in points] + [b.com for b in bodies]
    xs = [p[0] for p in coords]
    zs = [p[1] for p in coords]
    size = math.hypot(max(xs) - min(xs), max(zs) - min(zs))
    for i in range(len(points)):
        for j in range(i + 1, len(points)):
            (ni, pi), (nj, pj) = points[i], points[j]
            if math.hypot(pi[0] - pj[0], pi[1] - pj[1]) <= COINCIDENT_RTOL * size:
                raise GeometryError(
                    f"the hinges {ni} and {nj} coincide at {pi}: O, C and H must be "
                    "three distinct points of a chain"
                )


def two_block_constants(
    lower: PlanarBody,
    upper: PlanarBody,
    O: Sequence[float],  # noqa: E741 (theory's name of the base hinge)
    C: Sequence[float],
    H: Sequence[float],
    overburden: float = 0.0,
    overburden_point: Optional[Sequence[float]] = None,
    eccentricity: str = "static_moment",
) -> TwoBlockResult:
    """Kinematic constants of the two-block mechanism O-C-H (theory §2.3, Eqs. 1-6).

    Parameters
    ----------
    lower, upper : PlanarBody
        Block 1 (turns about O) and block 2 (pinned at C, top hinge H).
    O, C, H : (float, float)
        Base hinge, intermediate hinge and top hinge at rest (x outward, z up) [m]. H is
        held horizontally and free vertically.
    overburden : float
        Vertical load N on block 2, downward [N], >= 0.
    overburden_point : (float, float), optional
        Point of block 2 where N acts [m]; default H. theory's eccentric N sits at ``xi b``
        from H on the top face.
    eccentricity : {"static_moment", "potential"}
        Treatment of an eccentric N (module docstring, ``ECCENTRICITY_OPTIONS``). Equal
        when N acts at H.

    Returns
    -------
    TwoBlockResult

    Raises
    ------
    InputError
        Non-finite points, negative N, unknown ``eccentricity``.
    GeometryError
        Coincident hinges, a chain that locks, no maximum of V in ``(0, pi/2]``, or a
        ground-motion coefficient Q <= 0.

    Notes
    -----
    theory §1.1-1.7 with the general kinematics of the module docstring:
    ``I0 = M(phi_cr)``, ``K = -V''(phi_cr)``, ``Q = Q(phi_cr)``, ``p_eq = sqrt(K/I0)``,
    ``lam = (K phi_cr - M_F)/(g Q)``, ``phi_ov = phi_cr - M_F/K``. For rectangles with N at
    H these equal Eqs. 18-22 (``phi_cr = alpha1``, ``I0 = I_O1 + (R1/R2)² I_O2``, ...).

    Examples
    --------
    A 0.3 m x 4 m strip with the hinge at mid-height and no overburden has ``lam = 2 alpha1``
    (theory §2.3):

    >>> res = rectangular_two_block(0.3, 4.0, 2.0, length=1.0, density=1800.0)
    >>> round(res.lam / (2.0 * math.atan(0.3 / 2.0)), 12)
    1.0
    """
    if eccentricity not in ECCENTRICITY_OPTIONS:
        raise InputError(
            f"must be one of {sorted(ECCENTRICITY_OPTIONS)}, got {eccentricity!r}",
            "eccentricity",
        )
    for body, name in ((lower, "lower"), (upper, "upper")):
        if not isinstance(body, PlanarBody):
            raise InputError(f"must be a PlanarBody, got {type(body).__name__}", name)
    o, c, h = _point(O, "O"), _point(C, "C"), _point(H, "H")
    n = check_non_negative(overburden, "overburden")
    p_load = h if overburden_point is None else _point(overburden_point, "overburden_point")
    _check_chain([("O", o), ("C", c), ("H", h)], (lower, upper))
    chain = _Chain(o, c, h)

    # Under "static_moment" V holds N at H, and N's eccentric part becomes M_F (Eq. 23).
    p_in_v = p_load if eccentricity == "potential" else h
    phi_cr, s = _critical(chain, lower, upper, n, p_in_v, p_load)
    M_F = 0.0 if eccentricity == "potential" else -n * s.dz_ecc
    K = -s.d2V
    if not K > 0.0:
        raise GeometryError(f"the critical rotation is degenerate (K = {K:.6g} N m <= 0)")
    if not s.Q > 0.0:
        raise GeometryError(
            f"ground motion does not drive the mechanism outward (Q = {s.Q:.6g} kg m <= 0)"
        )
    s_rest = _state(chain, lower, upper, n, p_load, 0.0)
    assert s_rest is not None
    i_o1 = lower.i_g + lower.mass * _dot(_sub(lower.com, o), _sub(lower.com, o))
    i_h2 = upper.i_g + upper.mass * _dot(_sub(upper.com, h), _sub(upper.com, h))
    g1, g2 = _sub(lower.com, o), _sub(upper.com, h)
    details = {
        "R1": math.hypot(g1[0], g1[1]),
        "alpha1": math.atan2(-g1[0], g1[1]),
        "R2": math.hypot(g2[0], g2[1]),
        "alpha2": math.atan2(-g2[0], -g2[1]),
        "L_OC": math.hypot(*_sub(c, o)),
        "L_CH": chain.L,
        "I_O1": i_o1,
        "I_O2": i_h2,
        "phi2_cr": -s.beta[0],
        "omega2": -s.beta[1],
        "domega2": -s.beta[2],
        "lam_static_exact": s_rest.dV / (G * s_rest.Q),
    }
    _, v1_rest, _ = chain.motion(lower.com, 1, 0.0, s_rest.beta)
    _, v2_rest, _ = chain.motion(upper.com, 2, 0.0, s_rest.beta)
    rest = rest_virtual_work(
        (lower, upper), (v1_rest[0], v2_rest[0]), (1.0, s_rest.beta[1]), details["lam_static_exact"]
    )
    if rest is not None:
        details.update(
            {"S0": rest["S"], "J0": rest["J"], "Jb0": rest["J_blocks"], "mass0": rest["mass"]}
        )
    return TwoBlockResult(
        I0=s.M,
        K=K,
        Q=s.Q,
        phi_cr=phi_cr,
        M_F=M_F,
        p_eq=math.sqrt(K / s.M),
        lam=(K * phi_cr - M_F) / (G * s.Q),
        phi_ov=phi_cr - M_F / K,
        details=details,
        eccentricity=eccentricity,
    )


def two_block_restitution(
    lower: PlanarBody,
    upper: PlanarBody,
    O: Sequence[float],  # noqa: E741 (theory's name of the base hinge)
    C: Sequence[float],
    H: Sequence[float],
    O2: Sequence[float],
    C2: Sequence[float],
    H2: Sequence[float],
) -> float:
    """Restitution of the two-block mechanism when the hinges switch at rest (theory §3.4).

    Parameters
    ----------
    lower, upper : PlanarBody
        Block 1 and block 2 at rest.
    O, C, H : (float, float)
        Hinges of the mode before the impact [m].
    O2, C2, H2 : (float, float)
        Hinges of the mode after it (the mirrored set: for a rectangular wall, O' at the
        base inner face, C' at h_c on the outer face, H' at the top inner face) [m].

    Returns
    -------
    float
        ``eta``, the ratio of block 1's angular velocity after / before the impact, both in
        the same absolute sense (``eta > 0``: the rotation keeps its sense).

    Notes
    -----
    theory §3.4: the impulses act only at the new hinges and at H' horizontally, which do
    no work in the new mode, so the generalised momentum along that mode is conserved::

        eta = sum_k [m_k u_k- . u_k+ + I_Gk w_k- w_k+] / sum_k [m_k |u_k+|² + I_Gk (w_k+)²]

    with ``u = dr_G/dphi`` and ``w = dphi_k/dphi`` at rest, both modes parametrised by block
    1's rotation in the same absolute sense. The overburden is a force without inertia
    here. For rectangles with N = 0 this equals theory §3.3's closed form.

    Examples
    --------
    theory §3.3: two 0.30 m x 2 m blocks.

    >>> lo, up = rectangular_bodies(0.3, 4.0, 2.0, length=1.0, density=1800.0)
    >>> before = rectangular_hinges(0.3, 4.0, 2.0)
    >>> after = rectangular_hinges(0.3, 4.0, 2.0, mirrored=True)
    >>> round(two_block_restitution(lo, up, *before, *after), 3)
    0.845
    """
    modes = []
    for names, pts in ((("O", "C", "H"), (O, C, H)), (("O2", "C2", "H2"), (O2, C2, H2))):
        o, c, h = (_point(p, nm) for p, nm in zip(pts, names))
        _check_chain(list(zip(names, (o, c, h))), (lower, upper))
        chain = _Chain(o, c, h)
        bet = chain.beta(0.0)
        assert bet is not None
        _, u1, _ = chain.motion(lower.com, 1, 0.0, bet)
        _, u2, _ = chain.motion(upper.com, 2, 0.0, bet)
        modes.append((u1, u2, bet[1]))
    (u1m, u2m, w2m), (u1p, u2p, w2p) = modes
    num = (
        lower.mass * _dot(u1m, u1p)
        + lower.i_g
        + upper.mass * _dot(u2m, u2p)
        + upper.i_g * w2m * w2p
    )
    den = lower.mass * _dot(u1p, u1p) + lower.i_g + upper.mass * _dot(u2p, u2p)
    den += upper.i_g * w2p * w2p
    return num / den


# --- rectangular walls --------------------------------------------------------------------


def _check_rect(b: float, h: float, h_c: float) -> Tuple[float, float, float]:
    b, h, h_c = check_positive(b, "b"), check_positive(h, "h"), check_positive(h_c, "h_c")
    if not h_c < h:
        raise InputError(f"must be in (0, h) = (0, {h}), got {h_c}", "h_c")
    return b, h, h_c


def rectangular_bodies(
    b: float, h: float, h_c: float, length: float, density: float
) -> Tuple[PlanarBody, PlanarBody]:
    """Blocks 1 (``0 <= z <= h_c``) and 2 (``h_c <= z <= h``) of a wall ``0 <= x <= b``.

    Parameters
    ----------
    b, h, h_c, length : float
        Thickness, height, hinge height and length of the wall [m].
    density : float
        [kg/m³].

    Returns
    -------
    (PlanarBody, PlanarBody)
        Lower and upper block; ``i_g = m (b² + h_k²) / 12``, ``j_z = m h_k² / 12``.
    """
    b, h, h_c = _check_rect(b, h, h_c)
    rho_l = check_positive(density, "density") * check_positive(length, "length")
    out = []
    for z0, hk in ((0.0, h_c), (h_c, h - h_c)):
        m = rho_l * b * hk
        i_g, j_z = m * (b * b + hk * hk) / 12.0, m * hk * hk / 12.0
        out.append(PlanarBody(m, (0.5 * b, z0 + 0.5 * hk), i_g, j_z))
    return out[0], out[1]


def rectangular_hinges(
    b: float, h: float, h_c: float, mirrored: bool = False
) -> Tuple[Point2, Point2, Point2]:
    """Hinges O, C, H of a rectangular wall with inner face x = 0 and outer face x = b.

    The outward mode (theory §2.3) has O at the base outer face, C at h_c on the inner face
    and H at the top outer face; ``mirrored=True`` gives the inward mode O', C', H' (base
    inner face, h_c outer face, top inner face) [m].
    """
    b, h, h_c = _check_rect(b, h, h_c)
    outer, inner = (0.0, b) if mirrored else (b, 0.0)
    return (outer, 0.0), (inner, h_c), (outer, h)


def rectangular_two_block(
    b: float,
    h: float,
    h_c: float,
    length: float,
    density: float,
    overburden: float = 0.0,
    xi: float = 0.0,
    eccentricity: str = "static_moment",
) -> TwoBlockResult:
    """Constants of a rectangular vertically spanning strip (theory §2.3).

    Parameters
    ----------
    b, h, h_c, length : float
        Thickness, height, hinge height (Eq. 17, ``hinge_height``) and length [m].
    density : float
        [kg/m³].
    overburden : float
        N on the top face [N], >= 0.
    xi : float
        N acts at ``xi b`` from H along the top face, in [0, 1].
    eccentricity : {"static_moment", "potential"}
        See ``two_block_constants``.

    Returns
    -------
    TwoBlockResult
        For ``xi = 0``: Eqs. 18-22; for ``xi > 0`` under ``"static_moment"``:
        ``M_F = N xi b cos(alpha2) R1/R2`` (Eq. 23).
    """
    xi = float(xi)
    if not (math.isfinite(xi) and 0.0 <= xi <= 1.0):
        raise InputError(f"must be in [0, 1], got {xi!r}", "xi")
    lower, upper = rectangular_bodies(b, h, h_c, length, density)
    o, c, top = rectangular_hinges(b, h, h_c)
    return two_block_constants(
        lower,
        upper,
        o,
        c,
        top,
        overburden=overburden,
        overburden_point=(top[0] - xi * b, top[1]),
        eccentricity=eccentricity,
    )
