"""Three blocks, four hinges (theory §2.4, Eq. 24; restitution §3.4) against exact references.

References: Makris & Vassiliou's exact equivalence for the symmetric rocking frame, an
independent brute-force closure (written here) differentiated by Richardson-extrapolated
finite differences, theory §2.4's closed forms in angle notation, and Housner's Eq. 25.
"""

from __future__ import annotations

import math
import re
from typing import Any, Callable, NamedTuple, Sequence

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from cad_maths.mechanisms import multi_block
from cad_maths.mechanisms.multi_block import (
    FourBar,
    PlanarBody,
    four_bar_constants,
    four_bar_restitution,
    portal_frame,
)
from cad_maths.mechanisms.restitution import housner_general
from shared_schema.errors import GeometryError, InputError

G = 9.80665


# -- references ------------------------------------------------------------------------------
def rect(m: float, x0: float, z0: float, b: float, h: float) -> PlanarBody:
    return PlanarBody(m, (x0 + b / 2, z0 + h / 2), m * (b * b + h * h) / 12)


def mv_frame(b: float, h: float, gamma: float, span: float = 2.5) -> tuple[Any, Any, Any]:
    """Two b x h columns (1000 kg) and a beam of mass 2 gamma m_col pinned on their tops."""
    m_col = 1000.0
    left = rect(m_col, 0.0, 0.0, b, h)
    right = rect(m_col, b + span, 0.0, b, h)
    # The beam translates, so its own inertia and the height of its centre do not matter.
    beam = PlanarBody(2 * gamma * m_col, (b + span / 2, h + 0.37), 777.0)
    pos = ((b, 0.0), (0.0, h), (b + span, h), (2 * b + span, 0.0))
    neg = ((0.0, 0.0), (b, h), (2 * b + span, h), (b + span, 0.0))
    return (left, beam, right), pos, neg


def mv_reference(b: float, h: float, gamma: float) -> dict[str, float]:
    """Makris & Vassiliou (2013): the frame is Housner's block with p scaled (theory §2.4)."""
    alpha = math.atan(b / h)
    big_r = 0.5 * math.hypot(b, h)
    p = math.sqrt(3 * G / (4 * big_r))
    return {
        "alpha": alpha,
        "p_eq": p * math.sqrt((1 + 2 * gamma) / (1 + 3 * gamma)),
        "eta": (1 - 1.5 * math.sin(alpha) ** 2 + 3 * gamma * math.cos(2 * alpha)) / (1 + 3 * gamma),
    }


def rot(t: float) -> np.ndarray:
    return np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])


def cross2(p: np.ndarray, q: np.ndarray) -> float:
    return float(p[0] * q[1] - p[1] * q[0])


def angle_of(v: np.ndarray) -> float:
    return math.atan2(v[1], v[0])


def brute(blocks: Sequence[PlanarBody], hinges: Sequence[Any], t: float) -> dict[str, Any]:
    """Configuration after block 1 turns by t anticlockwise: C by the law of cosines."""
    a, b0, c0, d = (np.asarray(p, dtype=float) for p in hinges)
    l2, l3 = np.linalg.norm(c0 - b0), np.linalg.norm(c0 - d)
    b = a + rot(t) @ (b0 - a)
    bd = d - b
    dist = np.linalg.norm(bd)
    beta = math.acos((l2 * l2 + dist * dist - l3 * l3) / (2 * l2 * dist))
    side = math.copysign(1.0, cross2(d - b0, c0 - b0))
    c = b + l2 * (rot(side * beta) @ (bd / dist))
    t2 = angle_of(c - b) - angle_of(c0 - b0)
    t3 = angle_of(c - d) - angle_of(c0 - d)
    t2 = (t2 + math.pi) % (2 * math.pi) - math.pi
    t3 = (t3 + math.pi) % (2 * math.pi) - math.pi
    g = [np.asarray(k.com, dtype=float) for k in blocks]
    coms = [a + rot(t) @ (g[0] - a), b + rot(t2) @ (g[1] - b0), d + rot(t3) @ (g[2] - d)]
    return {"B": b, "C": c, "G": coms, "angles": np.array([t, t2, t3])}


def d1(f: Callable[[float], Any], x: float, h: float = 4e-3) -> Any:
    """Central first difference, one Richardson step (error O(h^4))."""

    def c(s: float) -> Any:
        return (f(x + s) - f(x - s)) / (2 * s)

    return (4 * c(h / 2) - c(h)) / 3


def d2(f: Callable[[float], Any], x: float, h: float = 4e-3) -> Any:
    """Central second difference, one Richardson step (error O(h^4))."""

    def c(s: float) -> Any:
        return (f(x + s) - 2 * f(x) + f(x - s)) / (s * s)

    return (4 * c(h / 2) - c(h)) / 3


def expected_sense(hinges: Sequence[Any], direction: int) -> int:
    """Documented convention: theta > 0 moves B towards +x * direction."""
    return -direction if hinges[1][1] > hinges[0][1] else direction


def asymmetric_frame() -> tuple[Any, Any, Any]:
    return portal_frame(0.5, 4.0, 3.0, 0.6, 2000.0, length=0.8, asymmetric=(0.8, 4.6))


def arch_like() -> tuple[Any, Any]:
    """A generic four-bar: leaning pier, heavy inclined coupler, short stocky pier."""
    blocks = (
        PlanarBody(1500.0, (-0.35, 1.4), 700.0),
        PlanarBody(900.0, (1.1, 3.3), 450.0),
        PlanarBody(1200.0, (3.05, 0.9), 380.0),
    )
    return blocks, ((0.0, 0.0), (-0.3, 3.0), (2.6, 2.2), (3.3, 0.1))


# -- Makris & Vassiliou's symmetric frame -------------------------------------------------------
MV_CASES = [(0.4, 4.0, 0.5), (1.0, 3.0, 0.3), (0.3, 6.0, 2.5), (0.8, 2.0, 1.0), (0.25, 5.0, 0.05)]


@pytest.mark.parametrize(("b", "h", "gamma"), MV_CASES)
def test_symmetric_frame_is_makris_vassiliou_equivalent_block(b, h, gamma):
    blocks, pos, neg = mv_frame(b, h, gamma)
    ref = mv_reference(b, h, gamma)
    for hinges, direction in ((pos, 1), (neg, -1)):
        res = four_bar_constants(blocks, *hinges, direction=direction)
        assert res.phi_cr == pytest.approx(ref["alpha"], abs=1e-10)
        assert res.lam == pytest.approx(ref["alpha"], rel=1e-10)
        assert res.phi_ov == pytest.approx(ref["alpha"], rel=1e-10)
        assert res.p_eq == pytest.approx(ref["p_eq"], rel=1e-10)
        assert res.M_F == 0.0
        # A parallelogram: the beam translates and the columns turn together.
        assert res.details["omega2"] == pytest.approx(0.0, abs=1e-12)
        assert res.details["omega3"] == pytest.approx(1.0, rel=1e-12)
        # The constants themselves: K = 2 g R (m_c + m_b), Q = 2 R (m_c + m_b),
        # I0 = 2 (4/3) m_c R^2 + m_b (2R)^2.
        m_c, m_b, big_r = blocks[0].mass, blocks[1].mass, 0.5 * math.hypot(b, h)
        assert res.K == pytest.approx(2 * G * big_r * (m_c + m_b), rel=1e-10)
        assert res.Q == pytest.approx(2 * big_r * (m_c + m_b), rel=1e-10)
        assert res.I0 == pytest.approx(8 / 3 * m_c * big_r**2 + 4 * m_b * big_r**2, rel=1e-10)
        assert res.details["lam_static"] == pytest.approx(b / h, rel=1e-12)  # tan(alpha)
    assert four_bar_restitution(blocks, pos, neg) == pytest.approx(ref["eta"], rel=1e-10)
    assert four_bar_restitution(blocks, neg, pos) == pytest.approx(ref["eta"], rel=1e-10)


@settings(max_examples=30, deadline=None)
@given(
    b=st.floats(0.1, 1.5),
    h=st.floats(1.0, 8.0),
    gamma=st.floats(0.02, 5.0),
    span=st.floats(0.5, 6.0),
)
def test_symmetric_frame_equivalence_holds_for_any_proportions(b, h, gamma, span):
    blocks, pos, neg = mv_frame(b, h, gamma, span)
    ref = mv_reference(b, h, gamma)
    res = four_bar_constants(blocks, *pos)
    assert res.phi_cr == pytest.approx(ref["alpha"], abs=1e-10)
    assert res.p_eq == pytest.approx(ref["p_eq"], rel=1e-10)
    assert four_bar_restitution(blocks, pos, neg) == pytest.approx(ref["eta"], rel=1e-10)


@pytest.mark.parametrize(("b", "h", "span", "depth"), [(0.5, 4.0, 3.0, 0.6), (0.9, 3.0, 5.0, 0.4)])
def test_portal_frame_builds_the_makris_vassiliou_frame(b, h, span, depth):
    blocks, pos, neg = portal_frame(b, h, span, depth, 1900.0, length=0.7)
    left, beam, _ = blocks
    assert left.mass == pytest.approx(1900.0 * 0.7 * b * h, rel=1e-14)
    assert beam.mass == pytest.approx(1900.0 * 0.7 * (2 * b + span) * depth, rel=1e-14)
    assert beam.com == pytest.approx((b + span / 2, h + depth / 2), rel=1e-14)
    gamma = beam.mass / (2 * left.mass)
    ref = mv_reference(b, h, gamma)
    res_pos = four_bar_constants(blocks, *pos, direction=1)
    res_neg = four_bar_constants(blocks, *neg, direction=-1)
    for res in (res_pos, res_neg):
        assert res.phi_cr == pytest.approx(ref["alpha"], abs=1e-10)
        assert res.p_eq == pytest.approx(ref["p_eq"], rel=1e-10)
    assert four_bar_restitution(blocks, pos, neg) == pytest.approx(ref["eta"], rel=1e-10)


# -- asymmetric linkages against the brute-force closure -----------------------------------
def linkages() -> list[tuple[str, Any, Any, int]]:
    blocks, pos, neg = asymmetric_frame()
    arch_blocks, arch_hinges = arch_like()
    return [
        ("frame+", blocks, pos, 1),
        ("frame-", blocks, neg, -1),
        ("arch", arch_blocks, arch_hinges, 1),
    ]


@pytest.mark.parametrize(("name", "blocks", "hinges", "direction"), linkages())
def test_energy_derivatives_match_finite_differences_of_brute_force_closure(
    name, blocks, hinges, direction
):
    res = four_bar_constants(blocks, *hinges, direction=direction)
    sense = expected_sense(hinges, direction)
    assert res.details["sense"] == sense
    masses = np.array([k.mass for k in blocks])
    i_g = np.array([k.i_g for k in blocks])

    def pos(theta: float) -> dict[str, Any]:
        return brute(blocks, hinges, sense * theta)

    def big_v(theta: float) -> float:
        return G * float(masses @ np.array([g[1] for g in pos(theta)["G"]]))

    def x_mass(theta: float) -> float:
        return direction * float(masses @ np.array([g[0] for g in pos(theta)["G"]]))

    def coords(theta: float) -> np.ndarray:
        p = pos(theta)
        return np.concatenate([np.ravel(p["G"]), p["angles"] * sense])

    scale_dv = G * masses.sum() * res.details["L1"]
    link = FourBar(blocks, *hinges, direction=direction)
    for theta in (0.0, 0.3 * res.phi_cr, 0.8 * res.phi_cr, res.phi_cr, 1.3 * res.phi_cr):
        s = link.state(theta)
        assert s.dV == pytest.approx(d1(big_v, theta), rel=1e-7, abs=1e-7 * scale_dv), name
        assert s.d2V == pytest.approx(d2(big_v, theta), rel=1e-7), name
        assert s.Q == pytest.approx(d1(x_mass, theta), rel=1e-7), name
        # Generalised inertia from the kinetic energy: velocities of G and block rotations.
        rates = d1(coords, theta)
        u, w = rates[:6].reshape(3, 2), rates[6:]
        kinetic = float(masses @ np.sum(u * u, axis=1) + i_g @ (w * w))
        assert s.M == pytest.approx(kinetic, rel=1e-7), name
        assert w[0] == pytest.approx(1.0, rel=1e-9)
        assert s.omega[1:] == pytest.approx(tuple(w[1:]), rel=1e-7, abs=1e-9)
        assert np.allclose(s.C, pos(theta)["C"], rtol=0, atol=1e-12)
    # The constants are the state at phi_cr.
    at_cr = link.state(res.phi_cr)
    assert abs(at_cr.dV) <= 1e-9 * scale_dv
    assert res.K == -at_cr.d2V and res.I0 == at_cr.M and res.Q == abs(at_cr.Q)
    assert res.K > 0 and res.Q > 0
    assert res.lam == pytest.approx(res.K * res.phi_cr / (G * res.Q), rel=1e-14)
    assert res.p_eq == pytest.approx(math.sqrt(res.K / res.I0), rel=1e-14)


@pytest.mark.parametrize(("name", "blocks", "hinges", "direction"), linkages())
def test_constants_match_theory_closed_forms_in_angle_notation(name, blocks, hinges, direction):
    """Theory §2.4's formulas (theta anticlockwise) evaluated on the brute-force geometry."""
    res = four_bar_constants(blocks, *hinges, direction=direction)
    sense = expected_sense(hinges, direction)
    t = sense * res.phi_cr
    p = brute(blocks, hinges, t)
    a_pt, d_pt = np.asarray(hinges[0], float), np.asarray(hinges[3], float)
    b_pt, c_pt = p["B"], p["C"]
    m1, m2, m3 = (k.mass for k in blocks)
    l1, l2, l3 = (np.linalg.norm(v) for v in (b_pt - a_pt, c_pt - b_pt, c_pt - d_pt))
    a1, a2, a3 = (angle_of(v) for v in (b_pt - a_pt, c_pt - b_pt, c_pt - d_pt))
    rel = [p["G"][0] - a_pt, p["G"][1] - b_pt, p["G"][2] - d_pt]
    r1, r2, r3 = (np.linalg.norm(v) for v in rel)
    b1, b2, b3 = (angle_of(v) for v in rel)
    om2 = l1 * math.sin(a3 - a1) / (l2 * math.sin(a2 - a3))
    om3 = l1 * math.sin(a2 - a1) / (l3 * math.sin(a2 - a3))

    def e(a: float) -> np.ndarray:
        return np.array([math.cos(a), math.sin(a)])

    def e_perp(a: float) -> np.ndarray:
        return np.array([-math.sin(a), math.cos(a)])

    lhs = np.column_stack([l2 * e_perp(a2), -l3 * e_perp(a3)])
    rhs = l1 * e(a1) + l2 * om2**2 * e(a2) - l3 * om3**2 * e(a3)
    dom2, dom3 = np.linalg.solve(lhs, rhs)
    i_a1 = blocks[0].i_g + m1 * r1**2
    i_b2 = blocks[1].i_g + m2 * r2**2
    i_d3 = blocks[2].i_g + m3 * r3**2
    eq24 = G * (
        m1 * r1 * math.cos(b1)
        + m2 * (l1 * math.cos(a1) + r2 * om2 * math.cos(b2))
        + m3 * r3 * om3 * math.cos(b3)
    )
    i0 = i_a1 + m2 * l1**2 + i_b2 * om2**2 + 2 * m2 * l1 * r2 * om2 * math.cos(a1 - b2)
    i0 += i_d3 * om3**2
    k = -G * (
        -m1 * r1 * math.sin(b1)
        + m2 * (-l1 * math.sin(a1) - r2 * om2**2 * math.sin(b2) + r2 * dom2 * math.cos(b2))
        + m3 * r3 * (-(om3**2) * math.sin(b3) + dom3 * math.cos(b3))
    )
    q = abs(
        m1 * r1 * math.sin(b1)
        + m2 * (l1 * math.sin(a1) + r2 * om2 * math.sin(b2))
        + m3 * r3 * om3 * math.sin(b3)
    )
    assert abs(eq24) <= 1e-10 * G * (m1 + m2 + m3) * l1
    assert res.I0 == pytest.approx(i0, rel=1e-12)
    assert res.K == pytest.approx(k, rel=1e-12)
    assert res.Q == pytest.approx(q, rel=1e-12)
    assert res.details["omega2"] == pytest.approx(om2, rel=1e-12, abs=1e-14)
    assert res.details["omega3"] == pytest.approx(om3, rel=1e-12)
    # d omega / d theta changes sign with the sense of theta; omega does not.
    assert res.details["domega2"] == pytest.approx(sense * dom2, rel=1e-10, abs=1e-13)
    assert res.details["domega3"] == pytest.approx(sense * dom3, rel=1e-10, abs=1e-13)


@pytest.mark.parametrize("direction", [1, -1])
@pytest.mark.parametrize("hang", [False, True])
def test_positive_theta_moves_b_towards_the_collapse_direction(direction, hang):
    """The documented sign convention, also for a block 1 hanging below its ground hinge."""
    blocks, _ = arch_like()
    hinges = ((0.0, 0.0), (-0.3, 3.0), (2.6, 2.2), (3.3, 0.1))
    if hang:  # the whole linkage turned upside down
        hinges = tuple((x, -z) for x, z in hinges)
        blocks = tuple(PlanarBody(k.mass, (k.com[0], -k.com[1]), k.i_g) for k in blocks)
    link = FourBar(blocks, *hinges, direction=direction)
    st = link.state(1e-3)
    assert (st.B[0] - hinges[1][0]) * direction > 0
    assert st.Q * direction == pytest.approx(
        float(sum(k.mass * u[0] for k, u in zip(blocks, st.u))), rel=1e-14
    )


def test_mirrored_frame_positive_side_equals_negative_side():
    blocks, _, neg = asymmetric_frame()
    mirrored = tuple(PlanarBody(k.mass, (-k.com[0], k.com[1]), k.i_g) for k in blocks)
    mirrored_hinges = tuple((-x, z) for x, z in neg)
    a = four_bar_constants(blocks, *neg, direction=-1)
    b = four_bar_constants(mirrored, *mirrored_hinges, direction=1)
    for name in ("I0", "K", "Q", "phi_cr", "p_eq", "lam", "phi_ov"):
        assert getattr(a, name) == pytest.approx(getattr(b, name), rel=1e-12), name


def test_asymmetric_frame_sides_differ_and_restitution_dissipates():
    blocks, pos, neg = asymmetric_frame()
    res_pos = four_bar_constants(blocks, *pos, direction=1)
    res_neg = four_bar_constants(blocks, *neg, direction=-1)
    assert abs(res_pos.phi_cr - res_neg.phi_cr) > 1e-3
    # Each side's critical rotation lies between its columns' slendernesses.
    alphas = sorted([math.atan(0.5 / 4.0), math.atan(0.8 / 4.6)])
    for res in (res_pos, res_neg):
        assert alphas[0] - 0.02 < res.phi_cr < alphas[1] + 0.02
    # Momentum projection never adds energy: eta^2 M_new <= M_old (same rest configuration).
    m_pos = FourBar(blocks, *pos, direction=1).state(0.0).M
    m_neg = FourBar(blocks, *neg, direction=-1).state(0.0).M
    for old, new, m_old, m_new in ((pos, neg, m_pos, m_neg), (neg, pos, m_neg, m_pos)):
        eta = four_bar_restitution(blocks, old, new)
        assert 0.0 < eta < 1.0
        assert eta**2 * m_new < m_old


def polygon_body(verts: list[tuple[float, float]], rho: float) -> tuple[float, np.ndarray, float]:
    """Mass, centroid and centroidal polar inertia of a planar polygon (Green's theorem)."""
    v = np.asarray(verts, dtype=float)
    x, z = v[:, 0], v[:, 1]
    xn, zn = np.roll(x, -1), np.roll(z, -1)
    c = x * zn - xn * z
    area = c.sum() / 2
    cx = ((x + xn) * c).sum() / (6 * area)
    cz = ((z + zn) * c).sum() / (6 * area)
    ixx = ((z * z + z * zn + zn * zn) * c).sum() / 12  # about the origin
    izz = ((x * x + x * xn + xn * xn) * c).sum() / 12
    polar = ixx + izz - area * (cx * cx + cz * cz)
    return rho * area, np.array([cx, cz]), rho * polar


def test_portal_frame_mass_properties_match_polygon_integration():
    b, h, span, depth, rho, length = 0.5, 4.0, 3.0, 0.6, 2000.0, 0.8
    b_r, h_r = 0.8, 4.6
    blocks, pos, neg = portal_frame(b, h, span, depth, rho, length=length, asymmetric=(b_r, h_r))
    x_r = b + span
    lx = x_r + b_r
    shapes = [
        [(0, 0), (b, 0), (b, h), (0, h)],
        [(0, h), (lx, h_r), (lx, h_r + depth), (0, h + depth)],
        [(x_r, 0), (lx, 0), (lx, h_r), (x_r, h_r)],
    ]
    for body, shape in zip(blocks, shapes):
        m, com, i_g = polygon_body(shape, rho * length)
        assert body.mass == pytest.approx(m, rel=1e-12)
        assert body.com == pytest.approx(tuple(com), rel=1e-12)
        assert body.i_g == pytest.approx(i_g, rel=1e-12)
    # Hinges are corners of the columns: base pivots and the tops that carry the beam.
    assert pos == ((b, 0.0), (0.0, h), (x_r, h_r), (lx, 0.0))
    assert neg == ((0.0, 0.0), (b, h), (lx, h_r), (x_r, 0.0))


def impulse_restitution(
    blocks: Sequence[PlanarBody], old: Sequence[Any], new: Sequence[Any]
) -> float:
    """Newton impact of three rigid bodies: impulses at the new hinges only (theory §3.4).

    Unknowns: post-impact (vx, vz, omega) of each block and the impulses at A', B', C', D'.
    The pre-impact state is the old hinge set's mode with block 1 turning at 1 rad/s.
    """
    pts = [[np.asarray(p, dtype=float) for p in hs] for hs in (old, new)]
    g = [np.asarray(k.com, dtype=float) for k in blocks]

    def point_velocity_rows(k: int, p: np.ndarray) -> np.ndarray:
        # v_P = v_G + omega J (P - G): rows acting on block k's (vx, vz, omega).
        rows = np.zeros((2, 9))
        rows[0, 3 * k], rows[1, 3 * k + 1] = 1.0, 1.0
        rows[0, 3 * k + 2], rows[1, 3 * k + 2] = -(p[1] - g[k][1]), p[0] - g[k][0]
        return rows

    def constraints(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
        return np.vstack(
            [
                point_velocity_rows(0, a),
                point_velocity_rows(0, b) - point_velocity_rows(1, b),
                point_velocity_rows(1, c) - point_velocity_rows(2, c),
                point_velocity_rows(2, d),
            ]
        )

    c_old = constraints(*pts[0])
    pick = np.zeros((1, 9))
    pick[0, 2] = 1.0
    q_before = np.linalg.solve(np.vstack([c_old, pick]), np.r_[np.zeros(8), 1.0])
    a, b, c, d = pts[1]
    # Impulse j (2 components) on block k at point p with sign s, as momentum rows.
    mass_rows = np.zeros((9, 8))
    for col, (k, p, sign) in enumerate(
        [(0, a, 1), (0, b, 1), (1, b, -1), (1, c, 1), (2, c, -1), (2, d, 1)]
    ):
        j = {0: 0, 1: 1, 2: 1, 3: 2, 4: 2, 5: 3}[col]
        mass_rows[3 * k : 3 * k + 2, 2 * j : 2 * j + 2] += sign * np.eye(2)
        r = p - g[k]
        mass_rows[3 * k + 2, 2 * j] += sign * -r[1]
        mass_rows[3 * k + 2, 2 * j + 1] += sign * r[0]
    inertia = np.diag([x for k in blocks for x in (k.mass, k.mass, k.i_g)])
    system = np.block([[inertia, -mass_rows], [constraints(a, b, c, d), np.zeros((8, 8))]])
    q_after = np.linalg.solve(system, np.r_[inertia @ q_before, np.zeros(8)])[:9]
    return float(q_after[2] / q_before[2])


def restitution_cases() -> list[tuple[str, Any, Any, Any]]:
    blocks, pos, neg = asymmetric_frame()
    arch_blocks, arch_hinges = arch_like()
    arch_new = ((0.25, 0.0), (0.2, 3.1), (2.4, 2.5), (3.0, 0.0))
    return [
        ("frame+-", blocks, pos, neg),
        ("frame-+", blocks, neg, pos),
        ("arch", arch_blocks, arch_hinges, arch_new),
    ]


@pytest.mark.parametrize(("name", "blocks", "old", "new"), restitution_cases())
def test_momentum_projection_equals_newton_impact_with_impulses_at_new_hinges(
    name, blocks, old, new
):
    eta = four_bar_restitution(blocks, old, new)
    assert eta == pytest.approx(impulse_restitution(blocks, old, new), rel=1e-12), name


def test_critical_rotation_just_before_the_lock_is_found():
    """dV/dtheta turns negative only as the velocity ratios blow up near the lock."""
    blocks, hinges = locking_linkage()
    blocks = (blocks[0], PlanarBody(50.0, (-0.3, 1.9), 5.0), blocks[2])
    res = four_bar_constants(blocks, *hinges)
    _, b0, c0, d = (np.asarray(p, float) for p in hinges)
    reach = np.linalg.norm(c0 - b0) + np.linalg.norm(c0 - d)
    lock = brentq(lambda t: np.linalg.norm(d - rot(-t) @ b0) - reach, 0.0, 0.1, xtol=1e-15)
    assert 0.0 < res.phi_cr < lock < multi_block.SCAN_STEP
    masses = np.array([k.mass for k in blocks])

    def big_v(theta: float) -> float:
        return G * float(masses @ np.array([p[1] for p in brute(blocks, hinges, -theta)["G"]]))

    step = 1e-3 * (lock - res.phi_cr)
    assert big_v(res.phi_cr) > max(big_v(res.phi_cr - step), big_v(res.phi_cr + step))


# -- restitution degenerating to Housner's single block ---------------------------------------
def test_restitution_reproduces_housner_when_the_other_blocks_are_massless():
    """Blocks 2 and 3 nearly massless: only block 1 matters, turning about A then A'."""
    b, h, m = 0.6, 2.4, 500.0
    tiny = 1e-13
    col = rect(m, 0.0, 0.0, b, h)
    blocks = (
        col,
        PlanarBody(m * tiny, (1.4, 2.6), m * tiny),
        PlanarBody(m * tiny, (2.5, 1.0), m * tiny),
    )
    old = ((b, 0.0), (0.0, h), (2.1, 2.3), (2.9, 0.0))
    new = ((0.0, 0.0), (b, h), (2.3, 2.5), (2.5, 0.0))
    eta = four_bar_restitution(blocks, old, new)
    alpha = math.atan(b / h)
    assert eta == pytest.approx(1 - 1.5 * math.sin(alpha) ** 2, rel=1e-10)  # Eq. 25, rectangle


def test_restitution_reproduces_general_housner_for_a_parallelogram_of_twin_blocks():
    """Two identical non-rectangular columns and a massless beam: each is Housner's block."""
    m, i_g, com = 800.0, 310.0, (0.23, 1.35)
    shift = 3.1
    blocks = (
        PlanarBody(m, com, i_g),
        PlanarBody(m * 1e-13, (1.8, 3.0), 1e-10),
        PlanarBody(m, (com[0] + shift, com[1]), i_g),
    )
    a_old, a_new = np.array([0.7, 0.0]), np.array([-0.1, 0.05])
    b_old, b_new = np.array([-0.05, 2.8]), np.array([0.6, 2.9])
    move = np.array([shift, 0.0])
    old = tuple(map(tuple, (a_old, b_old, b_old + move, a_old + move)))
    new = tuple(map(tuple, (a_new, b_new, b_new + move, a_new + move)))
    g = np.asarray(com)
    r_og, r_o2g = g - a_old, g - a_new
    ref = housner_general(m, i_g, [*r_og, 0], [*r_o2g, 0], i_g + m * float(r_o2g @ r_o2g))
    assert four_bar_restitution(blocks, old, new) == pytest.approx(ref, rel=1e-10)


# -- locking and no root -----------------------------------------------------------------------
def locking_linkage() -> tuple[Any, Any]:
    """B, C, D nearly in line at rest: B moving towards +x stretches BD to L2 + L3."""
    blocks = (
        PlanarBody(800.0, (-0.2, 1.0), 800.0 * (0.4**2 + 2.0**2) / 12),
        PlanarBody(50.0, (-0.05, 1.95), 5.0),
        PlanarBody(50.0, (-2.3, 0.6), 5.0),
    )
    return blocks, ((0.0, 0.0), (0.0, 2.0), (-1.0, 1.1), (-2.0, 0.1))


def test_linkage_that_locks_before_the_critical_rotation_raises():
    blocks, hinges = locking_linkage()
    with pytest.raises(GeometryError, match="locks at theta") as err:
        four_bar_constants(blocks, *hinges)
    # Independent lock angle: |D - B(theta)| = L2 + L3, B turning clockwise about A.
    _, b0, c0, d = (np.asarray(p, float) for p in hinges)
    reach = np.linalg.norm(c0 - b0) + np.linalg.norm(c0 - d)
    lock = brentq(lambda t: np.linalg.norm(d - rot(-t) @ b0) - reach, 0.0, 0.1, xtol=1e-15)
    found = float(re.search(r"theta = ([0-9.e+-]+) rad", str(err.value)).group(1))
    assert found == pytest.approx(lock, rel=1e-5)  # the message prints 6 digits
    assert lock < math.atan(0.2 / 1.0)  # block 1 alone would become critical later


def test_no_critical_rotation_below_theta_max_raises():
    blocks, pos, _ = mv_frame(0.4, 4.0, 1.0)
    with pytest.raises(GeometryError, match=r"no critical rotation in \(0, theta_max"):
        four_bar_constants(blocks, *pos, theta_max=0.5 * math.atan(0.1))


def test_wrong_direction_is_reported_as_weight_not_resisting():
    blocks, pos, _ = mv_frame(0.4, 4.0, 1.0)
    with pytest.raises(GeometryError, match="does not resist"):
        four_bar_constants(blocks, *pos, direction=-1)


def test_linkage_locked_at_rest_raises():
    blocks, _, _ = mv_frame(0.4, 4.0, 1.0)
    with pytest.raises(GeometryError, match="locked at rest"):
        four_bar_constants(blocks, (0.4, 0.0), (0.0, 4.0), (2.0, 2.0), (4.0, 0.0))


# -- bad input ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("hinges", "field"),
    [
        (((0.4, 0.0), (0.4, 0.0), (2.9, 4.0), (3.3, 0.0)), "hinge B"),
        (((0.4, 0.0), (0.0, 4.0), (0.0, 4.0), (3.3, 0.0)), "hinge C"),
        (((0.4, 0.0), (0.0, 4.0), (3.3, 0.0), (3.3, 0.0)), "hinge C"),
        (((0.4, 0.0), (0.0, 4.0), (2.9, 4.0), (0.4, 0.0)), "hinge D"),
        (((math.nan, 0.0), (0.0, 4.0), (2.9, 4.0), (3.3, 0.0)), "hinge A"),
        (((0.4, 0.0), (0.0, 0.0), (2.9, 4.0), (3.3, 0.0)), "hinge B"),  # B level with A
    ],
)
def test_bad_hinges_are_named(hinges, field):
    blocks, _, _ = mv_frame(0.4, 4.0, 1.0)
    with pytest.raises(InputError) as err:
        four_bar_constants(blocks, *hinges)
    assert err.value.field == field


class RawBody(NamedTuple):
    """A duck-typed body that skips PlanarBody's own checks (as a caller's object might)."""

    mass: float
    com: tuple[float, float]
    i_g: float


def test_planar_body_rejects_zero_mass():
    with pytest.raises(InputError, match="mass"):
        PlanarBody(0.0, (1.0, 4.0), 1.0)


@pytest.mark.parametrize(
    ("k", "body", "word"),
    [
        (1, RawBody(0.0, (1.0, 4.0), 1.0), "mass"),
        (0, RawBody(-5.0, (0.2, 2.0), 1.0), "mass"),
        (2, RawBody(10.0, (3.0, 2.0), -1.0), "i_g"),
        (2, RawBody(10.0, (3.0, math.inf), 1.0), "finite"),
    ],
)
def test_bad_blocks_are_named(k, body, word):
    blocks, pos, neg = mv_frame(0.4, 4.0, 1.0)
    bad = list(blocks)
    bad[k] = body
    with pytest.raises(InputError, match=word) as err:
        four_bar_constants(tuple(bad), *pos)
    assert err.value.field.startswith(f"blocks[{k}]")
    with pytest.raises(InputError) as err:
        four_bar_restitution(tuple(bad), pos, neg)
    assert err.value.field.startswith(f"blocks[{k}]")


def test_bad_arguments_are_named():
    blocks, pos, _ = mv_frame(0.4, 4.0, 1.0)
    cases = [
        (lambda: four_bar_constants(blocks, *pos, direction=0), "direction"),
        (lambda: four_bar_constants(blocks, *pos, theta_max=0.0), "theta_max"),
        (lambda: four_bar_constants(blocks[:2], *pos), "blocks"),
        (lambda: four_bar_restitution(blocks, pos, (pos[0], pos[0], *pos[2:])), "new hinge B"),
        (lambda: portal_frame(-0.4, 4.0, 3.0, 0.5, 2000.0), "b"),
        (lambda: portal_frame(0.4, 4.0, 3.0, 0.5, 2000.0, asymmetric=(0.5, 0.0)), "asymmetric[1]"),
    ]
    for call, field in cases:
        with pytest.raises(InputError) as err:
            call()
        assert err.value.field == field
