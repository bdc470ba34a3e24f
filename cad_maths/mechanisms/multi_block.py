"""Three blocks and four hinges: the planar four-bar linkage (theory §2.4, Eq. 24; §3.4).

Pure planar maths in the rocking plane: ``x`` horizontal, ``z`` up [m]. No CAD here; the
pipeline supplies the blocks' mass properties and the hinge points.

Notation (theory §0, §2.4)
--------------------------
A, D : ground hinges; B, C : internal hinges [m]
block 1 = AB (turns about A), block 2 = BC (the coupler), block 3 = DC (turns about D)
L1, L2, L3 : lengths |AB|, |BC|, |DC| [m]
theta : rotation of block 1, the generalised coordinate [rad]
omega2, omega3 : d theta_2 / d theta, d theta_3 / d theta (velocity ratios) [-]
V : potential energy g sum m_k z_Gk [J]; Q : sum m_k dx_Gk/d theta, collapse direction [kg m]
M : generalised inertia sum [I_Gk omega_k² + m_k |dr_Gk/d theta|²] [kg m²]
I0, K, Q, phi_cr, M_F, p_eq, lam, phi_ov : the kinematic constants (Eqs. 1-6)

Sign convention
---------------
``direction = +1`` means collapse towards +x, ``-1`` towards -x. ``theta`` is positive when
hinge B starts to move towards ``+x * direction`` (for a column-like block 1 with B above A
and ``direction = +1`` that is a clockwise rotation in the x-z plane). ``Q`` is measured
along ``+x * direction`` and reported as a magnitude. The velocity ratios ``omega2`` and
``omega3`` compare rotations taken in the same sense, so they do not depend on ``direction``.

``PlanarBody`` (mass [kg], com (x, z) [m], i_g [kg m²]) is the two-block module's; it is
re-exported here. The blocks are validated again on entry, so a duck-typed body with the
same attributes gets errors that name ``blocks[k]``.

Method
------
For a given ``theta``, C is where the circle of radius L2 about B meets the circle of radius
L3 about D, on the side of line BD where it lies at rest (the branch can only change
through tangency, which is where the linkage locks). The velocity ratios and their
derivatives are solved from the closure ``r + u - w = const`` with ``r = B - A``,
``u = C - B``, ``w = C - D``, which is theory §2.4's angle form written with vectors::

    omega2 u - omega3 w = -r
    omega2' u - omega3' w = -J (r + omega2² u - omega3² w)       (J: +90° rotation)

Eq. 24 is solved by scanning ``dV/dtheta`` from rest (where the weight resists, so it is
positive) in steps of ``SCAN_STEP`` and bisecting the first sign change. Bisection, not
``scipy.optimize.brentq``, because Rhino's Python may lack scipy; it runs to adjacent
floats in about 60 cheap evaluations. A critical rotation narrower than ``SCAN_STEP``
(two roots in one step) would be missed.
"""

import math
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

from cad_maths.mechanisms.two_block import LinkageResult, PlanarBody, rest_virtual_work
from shared_schema.errors import GeometryError, InputError
from shared_schema.rules import G

__all__ = [
    "SCAN_STEP",
    "FourBar",
    "FourBarResult",
    "FourBarState",
    "PlanarBody",
    "four_bar_constants",
    "four_bar_restitution",
    "portal_frame",
]

#: Step of the scan for the first sign change of dV/dtheta [rad].
SCAN_STEP = 2e-3
#: Hinges closer than this, relative to the linkage's size, coincide.
COINCIDENT_RTOL = 1e-9
#: |sin| of the angle at C between CB and CD below which the linkage counts as locked at rest.
LOCKED_SIN_TOL = 1e-9
#: Halvings used to approach a lock angle when looking for a root just before it.
LOCK_APPROACH_STEPS = 60
#: Upper bound on bisection steps (the loop stops earlier, at adjacent floats).
MAX_BISECT = 200

Point2 = Tuple[float, float]
Hinges = Tuple[Point2, Point2, Point2, Point2]
HINGE_NAMES = ("A", "B", "C", "D")


@dataclass(frozen=True)
class FourBarResult(LinkageResult):
    """Kinematic constants of one hinge set (theory §2.4, Eqs. 1-6).

    Attributes
    ----------
    I0 : float
        Generalised inertia at ``phi_cr`` [kg m²].
    K : float
        ``-V''(phi_cr)`` [N m/rad], positive.
    Q : float
        ``|sum m_k dx_Gk/dtheta|`` at ``phi_cr`` [kg m].
    phi_cr : float
        Critical rotation of block 1, Eq. 24 [rad].
    M_F : float
        Moment of static forces [N m]; 0 here.
    p_eq, lam, phi_ov : float
        ``sqrt(K/I0)`` [1/s], ``(K phi_cr - M_F)/(g Q)`` [-], ``phi_cr - M_F/K`` [rad].
    details : dict
        ``omega2``, ``omega3``, ``domega2``, ``domega3`` (per radian of theta) at
        ``phi_cr``; ``dV0`` [N m] and ``Q0`` [kg m] at rest and the exact static multiplier
        ``lam_static = dV0/(g Q0)``; where every block carries ``j_z``, ``S0`` [kg m],
        ``J0`` [kg m²] and ``mass0`` [kg] at rest (theory §11.1); ``L1``, ``L2``, ``L3``
        [m]; ``sense`` (+1 when theta is anticlockwise in the x-z plane, -1 when
        clockwise); ``xC``, ``zC`` at ``phi_cr``.
    """


@dataclass(frozen=True)
class FourBarState:
    """Configuration and derivatives at one ``theta`` (all derivatives per radian of theta).

    Attributes
    ----------
    theta : float
        Rotation of block 1 [rad].
    B, C : (2,) float
        Positions of the moving hinges [m].
    com : list of (2,) float
        Centres of mass of blocks 1-3 [m].
    omega : (3,) float
        ``d theta_k / d theta`` (``omega[0] = 1``).
    domega : (3,) float
        ``d omega_k / d theta`` (``domega[0] = 0``) [1/rad].
    u : list of (2,) float
        ``d r_Gk / d theta`` [m/rad].
    V, dV, d2V : float
        Potential energy and its first two derivatives [J, N m, N m/rad].
    Q : float
        ``sum m_k dx_Gk / dtheta`` along the collapse direction (signed) [kg m].
    M : float
        Generalised inertia [kg m²].
    """

    theta: float
    B: Point2
    C: Point2
    com: List[Point2]
    omega: Tuple[float, float, float]
    domega: Tuple[float, float, float]
    u: List[Point2]
    V: float
    dV: float
    d2V: float
    Q: float
    M: float


def _sub(p: Sequence[float], q: Sequence[float]) -> Point2:
    return (p[0] - q[0], p[1] - q[1])


def _cross(p: Sequence[float], q: Sequence[float]) -> float:
    return p[0] * q[1] - p[1] * q[0]


def _dot(p: Sequence[float], q: Sequence[float]) -> float:
    return p[0] * q[0] + p[1] * q[1]


def _perp(p: Sequence[float]) -> Point2:
    # J p: p turned by +90° in the x-z plane.
    return (-p[1], p[0])


def _rot(p: Sequence[float], angle: float) -> Point2:
    c, s = math.cos(angle), math.sin(angle)
    return (c * p[0] - s * p[1], s * p[0] + c * p[1])


def _norm(p: Sequence[float]) -> float:
    return math.hypot(p[0], p[1])


def _point(value: Sequence[float], where: str) -> Point2:
    try:
        x, z = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InputError(f"must be a point (x, z) [m], got {value!r}", where) from None
    if not (math.isfinite(x) and math.isfinite(z)):
        raise InputError(f"must be finite, got ({x}, {z})", where)
    return (x, z)


def _check_blocks(blocks: Sequence[PlanarBody]) -> Tuple[PlanarBody, PlanarBody, PlanarBody]:
    if len(blocks) != 3:
        raise InputError(f"a four-bar linkage needs exactly 3 blocks, got {len(blocks)}", "blocks")
    for k, body in enumerate(blocks):
        where = f"blocks[{k}]"
        if not (math.isfinite(body.mass) and body.mass > 0.0):
            raise InputError(f"mass must be positive and finite, got {body.mass}", where)
        if not (math.isfinite(body.i_g) and body.i_g >= 0.0):
            raise InputError(
                f"i_g (inertia about the centre of mass) must be >= 0 and finite, got {body.i_g}",
                where,
            )
        _point(body.com, f"{where}.com")
    return blocks[0], blocks[1], blocks[2]


def _check_hinges(points: Sequence[Sequence[float]], prefix: str = "hinge ") -> Hinges:
    if len(points) != 4:
        raise InputError(f"need 4 hinges (A, B, C, D), got {len(points)}", "hinges")
    a, b, c, d = (_point(p, prefix + n) for p, n in zip(points, HINGE_NAMES))
    size = max(_norm(_sub(p, q)) for p in (a, b, c, d) for q in (a, b, c, d))
    tol = COINCIDENT_RTOL * size
    pairs = [
        ("B", "A", b, a, "block 1 (AB) has zero length"),
        ("C", "B", c, b, "block 2 (BC) has zero length"),
        ("C", "D", c, d, "block 3 (DC) has zero length"),
        ("D", "A", d, a, "the ground link AD has zero length: this is not a four-bar"),
    ]
    for name, other, p, q, what in pairs:
        if size == 0.0 or _norm(_sub(p, q)) <= tol:
            raise InputError(f"coincides with hinge {other}: {what}", prefix + name)
    return a, b, c, d


class FourBar:
    """A planar four-bar linkage A-B-C-D carrying three rigid blocks (theory §2.4).

    Parameters
    ----------
    blocks : (PlanarBody, PlanarBody, PlanarBody)
        Block 1 (AB), block 2 (BC) and block 3 (DC), in the rest configuration.
    A, B, C, D : (2,) float
        Hinges at rest [m]; A and D are on the ground.
    direction : {+1, -1}
        Collapse towards +x or -x (see the module's sign convention).
    sense : {+1, -1}, optional
        Override the sense of theta: +1 anticlockwise, -1 clockwise in the x-z plane. By
        default it follows from ``direction`` (B moves towards ``+x * direction``).

    Raises
    ------
    InputError
        Bad mass, inertia or point (the message names ``blocks[k]`` or ``hinge X``),
        coincident hinges, B level with A (the sense of theta is then undefined).
    GeometryError
        B, C and D collinear at rest: the linkage is locked before it moves.
    """

    def __init__(
        self,
        blocks: Sequence[PlanarBody],
        A: Sequence[float],
        B: Sequence[float],
        C: Sequence[float],
        D: Sequence[float],
        *,
        direction: int = 1,
        sense: Optional[int] = None,
    ) -> None:
        if direction not in (1, -1):
            raise InputError(f"must be +1 or -1, got {direction!r}", "direction")
        if sense not in (None, 1, -1):
            raise InputError(f"must be +1, -1 or None, got {sense!r}", "sense")
        self.blocks = _check_blocks(blocks)
        self.A, self.B0, self.C0, self.D = _check_hinges((A, B, C, D))
        self.direction = int(direction)
        self.L1 = _norm(_sub(self.B0, self.A))
        self.L2 = _norm(_sub(self.C0, self.B0))
        self.L3 = _norm(_sub(self.C0, self.D))
        # Horizontal velocity of B per unit anticlockwise rotation is -(B_z - A_z).
        rise = self.B0[1] - self.A[1]
        if sense is not None:
            self.sense = int(sense)
        elif abs(rise) <= COINCIDENT_RTOL * self.L1:
            raise InputError(
                "is level with hinge A, so B moves vertically at rest and `direction` cannot "
                "fix the sense of theta",
                "hinge B",
            )
        else:
            self.sense = -self.direction if rise > 0.0 else self.direction
        u0, w0 = _sub(self.C0, self.B0), _sub(self.C0, self.D)
        sin_c = _cross(u0, w0) / (self.L2 * self.L3)
        if abs(sin_c) <= LOCKED_SIN_TOL:
            raise GeometryError(
                "the linkage is locked at rest: hinges B, C and D are collinear, so block 1 "
                "cannot turn (the coupler BC and block DC are aligned)"
            )
        # Branch: the side of line BD on which C lies at rest.
        self.branch = 1.0 if _cross(_sub(self.D, self.B0), _sub(self.C0, self.B0)) > 0 else -1.0
        self._rel = [
            _sub(self.blocks[0].com, self.A),
            _sub(self.blocks[1].com, self.B0),
            _sub(self.blocks[2].com, self.D),
        ]

    # -- closure -----------------------------------------------------------------------
    def _b_at(self, theta: float) -> Point2:
        r = _rot(_sub(self.B0, self.A), self.sense * theta)
        return (self.A[0] + r[0], self.A[1] + r[1])

    def _slack(self, theta: float) -> float:
        """h² of the circle intersection [m²]; <= 0 when the circles no longer cross."""
        b = self._b_at(theta)
        d = _norm(_sub(self.D, b))
        if d == 0.0:
            return -1.0
        a = (d * d + self.L2 * self.L2 - self.L3 * self.L3) / (2.0 * d)
        return self.L2 * self.L2 - a * a

    def closure(self, theta: float) -> Optional[Tuple[Point2, Point2]]:
        """Hinges B and C at ``theta`` [m], or None where the linkage cannot reach."""
        b = self._b_at(theta)
        bd = _sub(self.D, b)
        d = _norm(bd)
        if d == 0.0:
            return None
        a = (d * d + self.L2 * self.L2 - self.L3 * self.L3) / (2.0 * d)
        h2 = self.L2 * self.L2 - a * a
        if h2 <= 0.0:
            return None
        h = self.branch * math.sqrt(h2)
        e = (bd[0] / d, bd[1] / d)
        n = _perp(e)
        return b, (b[0] + a * e[0] + h * n[0], b[1] + a * e[1] + h * n[1])

    def state(self, theta: float) -> FourBarState:
        """Return the configuration, velocity ratios and energy derivatives at ``theta``.

        Raises
        ------
        GeometryError
            The linkage cannot reach ``theta`` (the circles about B and D do not meet).
        """
        st = self._state(theta)
        if st is None:
            raise GeometryError(f"the linkage cannot reach theta = {theta:.6g} rad (it locks)")
        return st

    def _state(self, theta: float) -> Optional[FourBarState]:
        hinges = self.closure(theta)
        if hinges is None:
            return None
        b, c = hinges
        s = float(self.sense)
        r, u, w = _sub(b, self.A), _sub(c, b), _sub(c, self.D)
        det = _cross(u, w)
        if det == 0.0:
            return None
        # omega2 u - omega3 w = v, solved by Cramer's rule (derivatives per unit anticlockwise
        # rotation t = sense * theta; the ratios themselves are sense-free).
        v1 = (-r[0], -r[1])
        om2 = _cross(v1, w) / det
        om3 = -_cross(u, v1) / det
        rhs = (
            r[0] + om2 * om2 * u[0] - om3 * om3 * w[0],
            r[1] + om2 * om2 * u[1] - om3 * om3 * w[1],
        )
        v2 = (rhs[1], -rhs[0])  # -J rhs
        dom2 = _cross(v2, w) / det
        dom3 = -_cross(u, v2) / det
        th2 = math.atan2(_cross(_sub(self.C0, self.B0), u), _dot(_sub(self.C0, self.B0), u))
        th3 = math.atan2(_cross(_sub(self.C0, self.D), w), _dot(_sub(self.C0, self.D), w))
        t = s * theta
        g1 = _rot(self._rel[0], t)
        g2 = _rot(self._rel[1], th2)
        g3 = _rot(self._rel[2], th3)
        com = [
            (self.A[0] + g1[0], self.A[1] + g1[1]),
            (b[0] + g2[0], b[1] + g2[1]),
            (self.D[0] + g3[0], self.D[1] + g3[1]),
        ]
        # d r_G / dt and d² r_G / dt² (theory §2.4, vector form).
        jr, jg1, jg2, jg3 = _perp(r), _perp(g1), _perp(g2), _perp(g3)
        vel = [
            jg1,
            (jr[0] + om2 * jg2[0], jr[1] + om2 * jg2[1]),
            (om3 * jg3[0], om3 * jg3[1]),
        ]
        acc = [
            (-g1[0], -g1[1]),
            (-r[0] + dom2 * jg2[0] - om2 * om2 * g2[0], -r[1] + dom2 * jg2[1] - om2 * om2 * g2[1]),
            (dom3 * jg3[0] - om3 * om3 * g3[0], dom3 * jg3[1] - om3 * om3 * g3[1]),
        ]
        omega = (1.0, om2, om3)
        masses = [body.mass for body in self.blocks]
        big_v = G * sum(m * p[1] for m, p in zip(masses, com))
        dv = s * G * sum(m * v[1] for m, v in zip(masses, vel))
        d2v = G * sum(m * a[1] for m, a in zip(masses, acc))
        q = self.direction * s * sum(m * v[0] for m, v in zip(masses, vel))
        big_m = sum(
            body.i_g * om * om + body.mass * _dot(v, v)
            for body, om, v in zip(self.blocks, omega, vel)
        )
        return FourBarState(
            theta=theta,
            B=b,
            C=c,
            com=com,
            omega=omega,
            domega=(0.0, s * dom2, s * dom3),
            u=[(s * v[0], s * v[1]) for v in vel],
            V=big_v,
            dV=dv,
            d2V=d2v,
            Q=q,
            M=big_m,
        )

    # -- Eq. 24 ------------------------------------------------------------------------
    def _dv(self, theta: float) -> Optional[float]:
        st = self._state(theta)
        return None if st is None else st.dV

    def _bisect_root(self, lo: float, hi: float) -> float:
        """Root of dV/dtheta with dV(lo) > 0 >= dV(hi), to adjacent floats."""
        for _ in range(MAX_BISECT):
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            f = self._dv(mid)
            if f is None:  # cannot happen inside a reachable bracket; be safe
                hi = mid
            elif f > 0.0:
                lo = mid
            else:
                hi = mid
        f_lo, f_hi = self._dv(lo), self._dv(hi)
        if f_lo is not None and f_hi is not None and abs(f_hi) < abs(f_lo):
            return hi
        return lo

    def _lock_angle(self, lo: float, hi: float) -> float:
        """Last reachable theta between a reachable ``lo`` and an unreachable ``hi``."""
        for _ in range(MAX_BISECT):
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            if self.closure(mid) is not None and self._slack(mid) > 0.0:
                lo = mid
            else:
                hi = mid
        return lo

    def critical_rotation(self, theta_max: float = 0.5 * math.pi) -> float:
        """Solve Eq. 24, ``dV/dtheta = 0``, for the first root after rest [rad].

        Raises
        ------
        GeometryError
            The weight does not resist rotation at rest, the linkage locks first, or there
            is no root in ``(0, theta_max]``.
        """
        dv0 = self._dv(0.0)
        assert dv0 is not None  # reachable at rest by construction
        if dv0 <= 0.0:
            raise GeometryError(
                f"the weight does not resist the rotation at rest (dV/dtheta = {dv0:.6g} N m "
                "<= 0): the mechanism would collapse under its own weight in this direction; "
                "check `direction` and the hinge set"
            )
        n = max(1, math.ceil(theta_max / SCAN_STEP))
        lo = 0.0
        for i in range(1, n + 1):
            hi = min(i * SCAN_STEP, theta_max)
            f = self._dv(hi)
            if f is None:
                lock = self._lock_angle(lo, hi)
                # Near the lock the velocity ratios blow up, so dV may change sign there:
                # approach it geometrically.
                for j in range(1, LOCK_APPROACH_STEPS + 1):
                    probe = lock - (lock - lo) * 0.5**j
                    if probe <= lo:
                        continue
                    fp = self._dv(probe)
                    if fp is None:
                        break
                    if fp <= 0.0:
                        return self._bisect_root(lo, probe)
                    lo = probe
                raise GeometryError(
                    f"the linkage locks at theta = {lock:.6g} rad before reaching a critical "
                    "rotation (hinges B, C and D come into line)"
                )
            if f <= 0.0:
                return self._bisect_root(lo, hi)
            lo = hi
        raise GeometryError(
            f"no critical rotation in (0, theta_max = {theta_max:.6g}] rad: dV/dtheta stays "
            "positive (the weight resists throughout)"
        )


def four_bar_constants(
    blocks: Sequence[PlanarBody],
    A: Sequence[float],
    B: Sequence[float],
    C: Sequence[float],
    D: Sequence[float],
    *,
    direction: int = 1,
    theta_max: float = 0.5 * math.pi,
) -> FourBarResult:
    """Kinematic constants of a three-block, four-hinge mechanism (Eq. 24, theory §2.4).

    Parameters
    ----------
    blocks : (PlanarBody, PlanarBody, PlanarBody)
        Blocks AB, BC and DC at rest.
    A, B, C, D : (2,) float
        Hinges at rest (x, z) [m]; A and D are ground hinges.
    direction : {+1, -1}
        Collapse towards +x or -x; theta is positive when B moves towards ``+x * direction``.
    theta_max : float
        Largest rotation searched for the critical rotation [rad], in (0, pi].

    Returns
    -------
    FourBarResult

    Raises
    ------
    InputError
        Invalid blocks or hinges (named), ``direction`` or ``theta_max``.
    GeometryError
        Locked at rest, weight not resisting at rest, locking before the critical rotation,
        or no critical rotation in ``(0, theta_max]``.

    Notes
    -----
    Eq. 24: ``dV/dtheta = 0`` gives ``phi_cr``; then ``I0 = M(phi_cr)``,
    ``K = -V''(phi_cr)``, ``Q = |Q(phi_cr)|``, and Eqs. 4-6 with ``M_F = 0``:
    ``p_eq = sqrt(K/I0)``, ``lam = K phi_cr/(g Q)``, ``phi_ov = phi_cr``.

    Examples
    --------
    Makris & Vassiliou's frame: two 0.4 m x 4 m columns and a beam of twice a column's mass
    rocking as a parallelogram; ``phi_cr = alpha = atan(b/h)``:

    >>> col = 1000.0
    >>> left = PlanarBody(col, (0.2, 2.0), col * (0.4**2 + 4.0**2) / 12)
    >>> right = PlanarBody(col, (3.6, 2.0), col * (0.4**2 + 4.0**2) / 12)
    >>> beam = PlanarBody(2 * col, (1.9, 4.1), 1.0)
    >>> res = four_bar_constants((left, beam, right), (0.4, 0.0), (0.0, 4.0), (3.4, 4.0),
    ...                          (3.8, 0.0))
    >>> round(res.phi_cr, 12) == round(math.atan(0.1), 12)
    True
    >>> abs(res.details["omega2"]) < 1e-12, round(res.details["omega3"], 12)
    (True, 1.0)
    """
    if not (math.isfinite(theta_max) and 0.0 < theta_max <= math.pi):
        raise InputError(f"must be in (0, pi] rad, got {theta_max}", "theta_max")
    link = FourBar(blocks, A, B, C, D, direction=direction)
    at_rest = link.state(0.0)
    phi_cr = link.critical_rotation(theta_max)
    st = link.state(phi_cr)
    i0 = st.M
    k = -st.d2V
    if not k > 0.0:
        raise GeometryError(
            f"dV/dtheta vanishes at theta = {phi_cr:.6g} rad without a maximum of V "
            f"(-V'' = {k:.6g} N m/rad): a degenerate critical point"
        )
    q = abs(st.Q)
    if q == 0.0:
        raise GeometryError(
            f"the ground motion does not drive the mechanism at theta = {phi_cr:.6g} rad (Q = 0)"
        )
    m_f = 0.0
    details = {
        "omega2": st.omega[1],
        "omega3": st.omega[2],
        "domega2": st.domega[1],
        "domega3": st.domega[2],
        "dV0": at_rest.dV,
        "Q0": at_rest.Q,
        "L1": link.L1,
        "L2": link.L2,
        "L3": link.L3,
        "sense": float(link.sense),
        "xC": st.C[0],
        "zC": st.C[1],
    }
    if at_rest.Q != 0.0:
        details["lam_static"] = at_rest.dV / (G * at_rest.Q)
        # theory §11.1: the signs of u_x and omega drop out of J.
        rest = rest_virtual_work(
            link.blocks, [v[0] for v in at_rest.u], at_rest.omega, details["lam_static"]
        )
        if rest is not None and at_rest.Q > 0.0:
            # Q is sum m u_x along the collapse direction, the S of §11.1.
            details.update(
                {"S0": at_rest.Q, "J0": rest["J"], "Jb0": rest["J_blocks"], "mass0": rest["mass"]}
            )
    return FourBarResult(
        I0=i0,
        K=k,
        Q=q,
        phi_cr=phi_cr,
        M_F=m_f,
        p_eq=math.sqrt(k / i0),
        lam=(k * phi_cr - m_f) / (G * q),
        phi_ov=phi_cr - m_f / k,
        details=details,
    )


def _mode(
    blocks: Sequence[PlanarBody], hinges: Sequence[Sequence[float]], which: str
) -> Tuple[List[Point2], Tuple[float, float, float]]:
    """``dr_Gk/dt`` and ``dtheta_k/dt`` at rest per unit anticlockwise rotation of block 1."""
    a, b, c, d = _check_hinges(hinges, prefix=f"{which} hinge ")
    st = FourBar(blocks, a, b, c, d, sense=1).state(0.0)
    return list(st.u), st.omega


def four_bar_restitution(
    blocks: Sequence[PlanarBody],
    hinges_old: Sequence[Sequence[float]],
    hinges_new: Sequence[Sequence[float]],
) -> float:
    """Coefficient of restitution by momentum projection (theory §3.4).

    Parameters
    ----------
    blocks : (PlanarBody, PlanarBody, PlanarBody)
        The blocks at the impact configuration (blocks[0] carries hinges A and B of both
        sets, blocks[2] hinges D and C).
    hinges_old, hinges_new : 4 x (2,) float
        Hinges (A, B, C, D) before and after the impact, at the impact configuration [m].

    Returns
    -------
    float
        ``eta``: block 1's angular velocity just after the impact over just before, both
        taken in the same sense (positive when the rotation keeps its sense, §1.8).

    Notes
    -----
    theory §3.4: the impulses act only at the new ground hinges and at internal hinges, which
    do no work in the new mode, so the generalised momentum along the new mode is conserved::

        eta = sum[m_k u_k⁻ . u_k⁺ + I_Gk w_k⁻ w_k⁺] / sum[m_k |u_k⁺|² + I_Gk (w_k⁺)²]

    with ``u_k = dr_Gk/dtheta`` and ``w_k = dtheta_k/dtheta`` for each hinge set, per unit
    rotation of block 1 in the same sense.
    """
    bodies = _check_blocks(blocks)
    u_old, w_old = _mode(bodies, hinges_old, "old")
    u_new, w_new = _mode(bodies, hinges_new, "new")
    num = sum(
        body.mass * _dot(uo, un) + body.i_g * wo * wn
        for body, uo, un, wo, wn in zip(bodies, u_old, u_new, w_old, w_new)
    )
    den = sum(
        body.mass * _dot(un, un) + body.i_g * wn * wn for body, un, wn in zip(bodies, u_new, w_new)
    )
    return num / den


def _rect(density: float, length: float, x0: float, z0: float, w: float, h: float) -> PlanarBody:
    m = density * w * h * length
    return PlanarBody(m, (x0 + 0.5 * w, z0 + 0.5 * h), m * (w * w + h * h) / 12.0, m * h * h / 12.0)


def portal_frame(
    b: float,
    h: float,
    span: float,
    beam_depth: float,
    density: float,
    length: float = 1.0,
    asymmetric: Optional[Tuple[float, float]] = None,
) -> Tuple[Tuple[PlanarBody, PlanarBody, PlanarBody], Hinges, Hinges]:
    """Blocks and hinge sets of a rocking portal frame (theory §2.4; Makris & Vassiliou 2013).

    Two rectangular columns stand on the ground and carry a beam pinned on their tops. In
    the positive set (sway towards +x) both columns rock about their +x base corners (the
    left column's inner edge, the right column's outer edge) and carry the beam on their -x
    top corners, which rise; the negative set is the mirror (each column's other corners).
    For identical columns the linkage is a parallelogram: the beam translates.

    Parameters
    ----------
    b, h : float
        Width and height of the left column [m]; it occupies ``0 <= x <= b``.
    span : float
        Clear distance between the columns' inner faces [m].
    beam_depth : float
        Depth of the beam [m].
    density : float
        Density of all three blocks [kg/m³].
    length : float
        Out-of-plane length [m].
    asymmetric : (float, float), optional
        Width and height ``(b_r, h_r)`` of the right column; None for identical columns.

    Returns
    -------
    blocks : (PlanarBody, PlanarBody, PlanarBody)
        Left column, beam, right column.
    positive, negative : 4 x (2,) float
        Hinges (A, B, C, D) for ``direction = +1`` and ``direction = -1``.

    Notes
    -----
    The beam is the parallelogram with vertical ends whose lower edge joins the columns'
    outer top corners, ``b + span + b_r`` long and ``beam_depth`` deep (a rectangle when the
    columns are equally tall). With unequal heights the inner top corner of the right
    column is not exactly on the beam's lower edge; it is still taken as the pin.

    Examples
    --------
    >>> blocks, pos, neg = portal_frame(0.5, 4.0, 3.0, 0.5, 2000.0)
    >>> pos
    ((0.5, 0.0), (0.0, 4.0), (3.5, 4.0), (4.0, 0.0))
    >>> neg
    ((0.0, 0.0), (0.5, 4.0), (4.0, 4.0), (3.5, 0.0))
    """
    b_r, h_r = (b, h) if asymmetric is None else asymmetric
    values = {
        "b": b,
        "h": h,
        "span": span,
        "beam_depth": beam_depth,
        "density": density,
        "length": length,
        "asymmetric[0]": b_r,
        "asymmetric[1]": h_r,
    }
    for name, value in values.items():
        if not (math.isfinite(value) and value > 0.0):
            raise InputError(f"must be positive and finite, got {value}", name)
    x_r = b + span
    left = _rect(density, length, 0.0, 0.0, b, h)
    right = _rect(density, length, x_r, 0.0, b_r, h_r)
    lx = x_r + b_r
    slope = (h_r - h) / lx
    m_beam = density * lx * beam_depth * length
    # Sheared rectangle about its centroid: I = m (lx² (1 + slope²) + depth²) / 12 and
    # j_z = m (slope² lx² + depth²) / 12.
    beam = PlanarBody(
        m_beam,
        (0.5 * lx, 0.5 * (h + h_r) + 0.5 * beam_depth),
        m_beam * (lx * lx * (1.0 + slope * slope) + beam_depth * beam_depth) / 12.0,
        m_beam * (slope * slope * lx * lx + beam_depth * beam_depth) / 12.0,
    )
    positive: Hinges = ((b, 0.0), (0.0, h), (x_r, h_r), (x_r + b_r, 0.0))
    negative: Hinges = ((0.0, 0.0), (b, h), (x_r + b_r, h_r), (x_r, 0.0))
    return (left, beam, right), positive, negative
