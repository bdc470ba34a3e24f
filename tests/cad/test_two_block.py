"""Two-block mechanism: general planar maths against an independent brute-force model,
theory §2.3 closed forms (Eqs. 18-23), §3.3-3.4 restitution and §4 hinge height (Eq. 17).

The brute-force model here shares nothing with the module: polygon corners are moved as
complex numbers, the top-hinge constraint is solved with scipy's brentq, V and the centres of
mass are computed from the moved corners, and every derivative is an 8th-order central
finite difference.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from cad_maths.mechanisms import two_block as tb
from cad_maths.mechanisms.two_block import (
    PlanarBody,
    hinge_height,
    rectangular_bodies,
    rectangular_hinges,
    rectangular_two_block,
    two_block_constants,
    two_block_restitution,
)
from shared_schema.errors import GeometryError, InputError

G = 9.80665
RHO = 1800.0
LENGTH = 1.2
#: Claimed agreement of the general solution with the exact model (theory §2.3: "machine
#: precision"; the finite differences below resolve about 1e-10).
RTOL_EXACT = 1e-8

# 8th-order central finite-difference weights for f(x +- k h), k = 1..4.
D1 = (4 / 5, -1 / 5, 4 / 105, -1 / 280)
D2_0 = -205 / 72
D2 = (8 / 5, -1 / 5, 8 / 315, -1 / 560)
H_D1 = 1e-3  # step of first derivatives [rad]
H_D2 = 4e-3  # step of second derivatives [rad]


def d1(f: Callable[[float], complex], x: float, h: float = H_D1) -> complex:
    return sum(w * (f(x + k * h) - f(x - k * h)) for k, w in enumerate(D1, 1)) / h


def d2(f: Callable[[float], float], x: float, h: float = H_D2) -> float:
    s = D2_0 * f(x) + sum(w * (f(x + k * h) + f(x - k * h)) for k, w in enumerate(D2, 1))
    return s / (h * h)


def polygon_props(pts: Sequence[complex]) -> tuple[float, complex, float]:
    """Area, centroid and polar second moment about the centroid of a simple polygon."""
    area = cx = cz = jo = 0.0
    n = len(pts)
    for i in range(n):
        p, q = pts[i], pts[(i + 1) % n]
        cr = p.real * q.imag - q.real * p.imag
        area += cr / 2
        cx += (p.real + q.real) * cr / 6
        cz += (p.imag + q.imag) * cr / 6
        jo += cr * (p.real**2 + p.real * q.real + q.real**2) / 12
        jo += cr * (p.imag**2 + p.imag * q.imag + q.imag**2) / 12
    c = complex(cx / area, cz / area)
    if area < 0:
        area, jo = -area, -jo
    return area, c, jo - area * abs(c) ** 2


@dataclass
class BruteForce:
    """Exact two-block model from the corners of two polygons (x + i z)."""

    block1: list[complex]
    block2: list[complex]
    O: complex  # noqa: E741 (theory's hinge names)
    C: complex
    H: complex
    N: float = 0.0
    P: complex | None = None

    def __post_init__(self) -> None:
        a1, _, j1 = polygon_props(self.block1)
        a2, _, j2 = polygon_props(self.block2)
        self.m1, self.m2 = RHO * LENGTH * a1, RHO * LENGTH * a2
        self.i1, self.i2 = RHO * LENGTH * j1, RHO * LENGTH * j2
        if self.P is None:
            self.P = self.H
        self.gamma = cmath.phase(complex((self.H - self.C).imag, (self.H - self.C).real))

    def beta(self, phi: float) -> float:
        """Clockwise rotation of block 2 keeping Re(H) fixed (brentq on the rest branch)."""
        c = self.O + (self.C - self.O) * cmath.exp(-1j * phi)

        def gap(b: float) -> float:
            return (c + (self.H - self.C) * cmath.exp(-1j * b)).real - self.H.real

        lo, hi = -self.gamma - math.pi / 2 + 1e-9, -self.gamma + math.pi / 2 - 1e-9
        return brentq(gap, lo, hi, xtol=1e-300, rtol=8.9e-16, maxiter=500)

    def corners(self, phi: float) -> tuple[list[complex], list[complex], complex]:
        rot1 = cmath.exp(-1j * phi)
        c = self.O + (self.C - self.O) * rot1
        rot2 = cmath.exp(-1j * self.beta(phi))
        one = [self.O + (p - self.O) * rot1 for p in self.block1]
        two = [c + (p - self.C) * rot2 for p in self.block2]
        assert self.P is not None
        return one, two, c + (self.P - self.C) * rot2

    def com(self, k: int, phi: float) -> complex:
        return polygon_props(self.corners(phi)[k - 1])[1]

    def V(self, phi: float) -> float:
        _, _, p = self.corners(phi)
        z = self.m1 * self.com(1, phi).imag + self.m2 * self.com(2, phi).imag
        return G * z + self.N * p.imag

    def phi2(self, phi: float) -> float:
        # Block 2's rotation read off one of its moved edges, positive counter-clockwise.
        two = self.corners(phi)[1]
        return cmath.phase((two[1] - two[0]) / (self.block2[1] - self.block2[0]))

    def constants(self) -> dict[str, float]:
        def dV(x: float) -> float:
            return d1(self.V, x).real

        grid = np.linspace(1e-3, 1.2, 600)
        k = next(i for i in range(len(grid)) if dV(grid[i]) < 0)
        phi_cr = brentq(dV, grid[k - 1], grid[k], xtol=1e-15, rtol=8.9e-16)
        g1 = d1(lambda x: self.com(1, x), phi_cr)
        g2 = d1(lambda x: self.com(2, x), phi_cr)
        w2 = d1(self.phi2, phi_cr).real
        i0 = self.i1 + self.m1 * abs(g1) ** 2 + self.i2 * w2**2 + self.m2 * abs(g2) ** 2
        K = -d2(self.V, phi_cr)
        Q = self.m1 * g1.real + self.m2 * g2.real
        return {
            "phi_cr": phi_cr,
            "K": K,
            "Q": Q,
            "I0": i0,
            "omega2": w2,
            "lam": K * phi_cr / (G * Q),
        }

    def bodies(self) -> tuple[PlanarBody, PlanarBody]:
        out = []
        for pts, m, i in ((self.block1, self.m1, self.i1), (self.block2, self.m2, self.i2)):
            c = polygon_props(pts)[1]
            out.append(PlanarBody(m, (c.real, c.imag), i))
        return out[0], out[1]


def rect_model(b: float, h: float, h_c: float, N: float = 0.0, xi: float = 0.0) -> BruteForce:
    one = [0, b, complex(b, h_c), complex(0, h_c)]
    two = [complex(0, h_c), complex(b, h_c), complex(b, h), complex(0, h)]
    return BruteForce(
        one, two, O=complex(b, 0), C=complex(0, h_c), H=complex(b, h), N=N,
        P=complex(b - xi * b, h),
    )  # fmt: skip


def tapered_model(b0: float, bt: float, h: float, h_c: float, N: float) -> BruteForce:
    """Wall with a vertical inner face x = 0 and an outer face battered from b0 to bt."""
    xc = b0 + (bt - b0) * h_c / h
    one = [0, b0, complex(xc, h_c), complex(0, h_c)]
    two = [complex(0, h_c), complex(xc, h_c), complex(bt, h), complex(0, h)]
    return BruteForce(one, two, O=complex(b0, 0), C=complex(0, h_c), H=complex(bt, h), N=N)


def module_result(model: BruteForce, eccentricity: str = "potential") -> tb.TwoBlockResult:
    lower, upper = model.bodies()
    assert model.P is not None
    return two_block_constants(
        lower,
        upper,
        (model.O.real, model.O.imag),
        (model.C.real, model.C.imag),
        (model.H.real, model.H.imag),
        overburden=model.N,
        overburden_point=(model.P.real, model.P.imag),
        eccentricity=eccentricity,
    )


def closed_forms(b: float, h: float, h_c: float, N: float) -> dict[str, float]:
    """Theory Eqs. 18-22 for a rectangular strip with N at H."""
    h1, h2 = h_c, h - h_c
    m1, m2 = RHO * LENGTH * b * h1, RHO * LENGTH * b * h2
    r1, r2 = 0.5 * math.hypot(b, h1), 0.5 * math.hypot(b, h2)
    a1, a2 = math.atan(b / h1), math.atan(b / h2)
    assert math.isclose(r1, r2 * math.sin(a2) / math.sin(a1), rel_tol=1e-14)  # Eq. 18
    i_o1, i_o2 = m1 * (b * b + h1 * h1) / 3, m2 * (b * b + h2 * h2) / 3
    return {
        "R1": r1,
        "R2": r2,
        "alpha1": a1,
        "alpha2": a2,
        "phi_cr": a1,  # Eq. 19
        "I0": i_o1 + (r1 / r2) ** 2 * i_o2,  # Eq. 20
        "K": r1 * (G * (m1 + 2 * m2) + 2 * N + (G * m2 + 2 * N) * r1 / r2),  # Eq. 21
        "Q": (m1 + m2) * r1,  # Eq. 22
    }


# (b, h, h_c, N): equal and unequal blocks, with and without overburden.
RECT_CASES = [
    (0.30, 4.0, 2.0, 0.0),
    (0.30, 4.0, 2.0, 2.5e4),
    (0.45, 3.2, 1.9, 0.0),
    (0.25, 5.0, 2.2, 1.0e4),
    (0.60, 3.0, 1.1, 8.0e4),
]


@pytest.mark.parametrize(("b", "h", "h_c", "N"), RECT_CASES)
def test_rectangle_matches_brute_force_corner_model(b, h, h_c, N):
    model = rect_model(b, h, h_c, N)
    ref = model.constants()
    res = rectangular_two_block(b, h, h_c, LENGTH, RHO, overburden=N)
    for name in ("phi_cr", "K", "Q", "I0", "lam"):
        assert getattr(res, name) == pytest.approx(ref[name], rel=RTOL_EXACT), name
    assert res.details["omega2"] == pytest.approx(ref["omega2"], rel=RTOL_EXACT)
    assert res.M_F == 0.0
    assert res.phi_ov == res.phi_cr


@pytest.mark.parametrize(("b", "h", "h_c", "N"), RECT_CASES)
def test_rectangle_equals_theory_closed_forms_eqs_18_to_22(b, h, h_c, N):
    res = rectangular_two_block(b, h, h_c, LENGTH, RHO, overburden=N)
    ref = closed_forms(b, h, h_c, N)
    for name in ("phi_cr", "I0", "K", "Q"):
        assert getattr(res, name) == pytest.approx(ref[name], rel=1e-13), name
    for name in ("R1", "R2", "alpha1", "alpha2"):
        assert res.details[name] == pytest.approx(ref[name], rel=1e-13), name
    # At phi_cr the three hinges are collinear and phi2 = alpha2 (Eq. 19).
    assert res.details["phi2_cr"] == pytest.approx(ref["alpha2"], rel=1e-12)
    assert res.details["omega2"] == pytest.approx(ref["R1"] / ref["R2"], rel=1e-13)
    assert res.p_eq == pytest.approx(math.sqrt(ref["K"] / ref["I0"]), rel=1e-13)
    assert res.lam == pytest.approx(ref["K"] * ref["alpha1"] / (G * ref["Q"]), rel=1e-13)


def test_tapered_wall_matches_brute_force_and_is_not_the_collinear_configuration():
    model = tapered_model(b0=0.55, bt=0.3, h=4.2, h_c=2.4, N=1.5e4)
    ref = model.constants()
    res = module_result(model)
    for name in ("phi_cr", "K", "Q", "I0", "lam"):
        assert getattr(res, name) == pytest.approx(ref[name], rel=RTOL_EXACT), name
    # General geometry: the maximum of V is not where O, C and H line up.
    oc = complex(-0.55, 2.4) * cmath.exp(-1j * res.phi_cr)
    ch = complex(0.3, 4.2) - (complex(0.55, 0) + oc)
    assert abs(cmath.phase(oc / ch)) > 1e-3


@pytest.mark.parametrize("xi", [0.5, 1.0])
def test_eccentric_overburden_potential_option_matches_brute_force(xi):
    model = rect_model(0.3, 4.0, 2.4, N=1.2e4, xi=xi)
    ref = model.constants()
    res = module_result(model, eccentricity="potential")
    for name in ("phi_cr", "K", "Q", "I0", "lam"):
        assert getattr(res, name) == pytest.approx(ref[name], rel=RTOL_EXACT), name
    assert res.M_F == 0.0


def test_equal_blocks_without_overburden_give_lam_2alpha1_and_p_eq_squared_3g_over_2r1():
    b, h = 0.35, 4.4
    res = rectangular_two_block(b, h, h / 2, LENGTH, RHO)
    a1 = math.atan(b / (h / 2))
    r1 = 0.5 * math.hypot(b, h / 2)
    assert res.lam == pytest.approx(2 * a1, rel=1e-9)
    assert res.p_eq**2 == pytest.approx(3 * G / (2 * r1), rel=1e-9)
    # ... and the brute force agrees with the same limit.
    ref = rect_model(b, h, h / 2).constants()
    assert ref["lam"] == pytest.approx(2 * a1, rel=RTOL_EXACT)
    assert ref["K"] / ref["I0"] == pytest.approx(3 * G / (2 * r1), rel=RTOL_EXACT)


def test_static_moment_is_theory_eq_23():
    b, h, h_c, N, xi = 0.3, 4.0, 2.4, 1.2e4, 0.7
    res = rectangular_two_block(b, h, h_c, LENGTH, RHO, N, xi)
    ref = closed_forms(b, h, h_c, N)
    M_F = N * xi * b * math.cos(ref["alpha2"]) * ref["R1"] / ref["R2"]
    assert res.eccentricity == "static_moment"
    assert res.M_F == pytest.approx(M_F, rel=1e-13)
    assert res.phi_cr == pytest.approx(ref["alpha1"], rel=1e-13)
    assert res.K == pytest.approx(ref["K"], rel=1e-13)
    assert res.lam == pytest.approx((ref["K"] * ref["alpha1"] - M_F) / (G * ref["Q"]), rel=1e-13)
    assert res.phi_ov == pytest.approx(ref["alpha1"] - M_F / ref["K"], rel=1e-13)


def eccentric_pair(b, h, n_over_w, f_mt, xi):
    W = RHO * LENGTH * b * h * G
    N = n_over_w * W
    h_c = hinge_height(h, W, N, f_mt, LENGTH * b)
    static = rectangular_two_block(b, h, h_c, LENGTH, RHO, N, xi)
    exact = rectangular_two_block(b, h, h_c, LENGTH, RHO, N, xi, eccentricity="potential")
    return static, exact


# theory §2.3: "for xi = 0.5-1 the M_F treatment is within about 1 % of the exact
# linearisation". h_c from Eq. 17. This holds for slender strips (b/h = 1/30 for any N up to
# W, and b/h = 0.075 with f_mt = 0.1 MPa at xi = 0.5); see the next test for where it fails.
@pytest.mark.parametrize("xi", [0.5, 1.0])
@pytest.mark.parametrize(
    ("b", "h", "n_over_w", "f_mt"),
    [(0.2, 6.0, 0.1, 0.0), (0.2, 6.0, 0.5, 0.0), (0.2, 6.0, 1.0, 1e5), (0.3, 4.0, 0.1, 1e5)],
)
def test_static_moment_within_one_percent_of_exact_linearisation(b, h, n_over_w, f_mt, xi):
    static, exact = eccentric_pair(b, h, n_over_w, f_mt, xi)
    assert static.lam == pytest.approx(exact.lam, rel=0.01)
    assert static.phi_ov == pytest.approx(exact.phi_ov, rel=0.01)
    assert static.p_eq == pytest.approx(exact.p_eq, rel=0.01)


@pytest.mark.parametrize(
    ("b", "h", "n_over_w", "xi", "lam_excess"),
    [(0.3, 4.0, 0.1, 1.0, 0.0243), (0.3, 4.0, 0.5, 1.0, 0.0180), (0.45, 3.0, 0.1, 1.0, 0.0745)],
)
def test_static_moment_overestimates_lam_by_more_than_one_percent_for_thicker_walls(
    b, h, n_over_w, xi, lam_excess
):
    # Recorded limit of theory's 1 % claim (f_mt = 0, h_c from Eq. 17): the static-moment
    # treatment is unconservative, lam too high by 1.8-7.5 % for b/h = 0.075-0.15.
    static, exact = eccentric_pair(b, h, n_over_w, 0.0, xi)
    assert static.lam / exact.lam - 1 == pytest.approx(lam_excess, abs=5e-4)


def test_overburden_at_h_makes_both_eccentricity_options_equal():
    a = rectangular_two_block(0.3, 4.0, 2.4, LENGTH, RHO, 1e4, 0.0)
    b = rectangular_two_block(0.3, 4.0, 2.4, LENGTH, RHO, 1e4, 0.0, eccentricity="potential")
    assert (a.I0, a.K, a.Q, a.phi_cr, a.lam) == (b.I0, b.K, b.Q, b.phi_cr, b.lam)


def test_equal_blocks_reproduce_theory_table_lam_and_exact_static_multiplier():
    # theory §1.6 table, "two-block wall": lam = 0.2978 against the exact 0.3000. Virtual
    # work at rest for h1 = h2 without N gives the exact multiplier 2 b / h1 = 0.3.
    res = rectangular_two_block(0.3, 4.0, 2.0, LENGTH, RHO)
    assert round(res.lam, 4) == 0.2978
    assert res.details["lam_static_exact"] == pytest.approx(2 * 0.3 / 2.0, rel=1e-13)


# --- hinge height, Eq. 17 -----------------------------------------------------------------


def test_hinge_height_limits():
    h, A = 3.5, 0.3 * 1.2
    assert hinge_height(h, 1e-9, 2e4, 1e5, A) == pytest.approx(h / 2, rel=1e-12)
    assert hinge_height(h, 0.0, 2e4, 0.0, A) == h / 2
    assert hinge_height(h, 2e4, 0.0, 0.0, A) == h
    for W, N, f in [(1e4, 0.0, 1e5), (2e4, 5e3, 0.0), (5e4, 1e5, 3e5)]:
        assert h / 2 < hinge_height(h, W, N, f, A) < h


def test_hinge_height_minimises_the_lateral_load_of_theory_section_4():
    rng = np.random.default_rng(17)
    for _ in range(8):
        h = rng.uniform(2.0, 8.0)
        b, length = rng.uniform(0.15, 0.8), rng.uniform(0.5, 5.0)
        W = RHO * G * b * length * h
        N = rng.uniform(0.0, 2.0) * W
        f = rng.choice([0.0, rng.uniform(1e3, 2e5)])

        def w(z: float, h=h, W=W, N=N, f=f, A=b * length) -> float:
            return (f * A + N + W * (h - z) / h) / (z * (h - z))

        opt = minimize_scalar(w, bounds=(1e-6 * h, h * (1 - 1e-6)), method="bounded",
                              options={"xatol": 1e-12 * h})  # fmt: skip
        assert hinge_height(h, W, N, f, b * length) == pytest.approx(opt.x, rel=1e-6)


def test_hinge_height_rejects_negative_tensile_strength():
    with pytest.raises(InputError) as err:
        hinge_height(3.0, 1e4, 0.0, -1.0, 0.3)
    assert err.value.field == "f_mt"
    with pytest.raises(InputError):
        hinge_height(3.0, 0.0, 0.0, 0.0, 0.3)


# --- restitution, §3.3-3.4 ----------------------------------------------------------------


def eta_rect(b: float, h1: float, h2: float) -> float:
    lower, upper = rectangular_bodies(b, h1 + h2, h1, LENGTH, RHO)
    before = rectangular_hinges(b, h1 + h2, h1)
    after = rectangular_hinges(b, h1 + h2, h1, mirrored=True)
    return two_block_restitution(lower, upper, *before, *after)


def eta_theory_closed_form(b: float, h1: float, h2: float) -> float:
    """Theory §3.3 closed form for rectangles, N = 0, at theta = 0."""
    m1, m2 = b * h1, b * h2
    i1, i2 = m1 * (b * b + h1 * h1) / 12, m2 * (b * b + h2 * h2) / 12
    w = h1 / h2
    common = i1 + i2 * w**2 + m2 * h1**2 / 4
    cross = m1 * b**2 / 4 + m2 * b**2 * (1 + w / 2) ** 2
    return (common + m1 * h1**2 / 4 - cross) / (common + m1 * h1**2 / 4 + cross)


@pytest.mark.parametrize(("h1", "b", "table"), [(2.0, 0.30, 0.845), (1.5, 0.45, 0.504)])
def test_restitution_reproduces_theory_table(h1, b, table):
    eta = eta_rect(b, h1, h1)
    assert round(eta, 3) == table
    assert eta == pytest.approx(eta_theory_closed_form(b, h1, h1), rel=1e-13)


def test_restitution_matches_closed_form_for_unequal_blocks_and_never_gains_energy():
    rng = np.random.default_rng(3)
    for _ in range(20):
        b, h1, h2 = rng.uniform(0.1, 0.6), rng.uniform(0.8, 4.0), rng.uniform(0.8, 4.0)
        eta = eta_rect(b, h1, h2)
        assert eta == pytest.approx(eta_theory_closed_form(b, h1, h2), rel=1e-12)
        # Kinetic energy after / before = eta² M+ / M- <= 1 (projection on the new mode).
        lower, upper = rectangular_bodies(b, h1 + h2, h1, LENGTH, RHO)
        m = []
        for mirrored in (False, True):
            o, c, top = rectangular_hinges(b, h1 + h2, h1, mirrored)
            model = BruteForce(
                [complex(*p) for p in [(0, 0), (b, 0), (b, h1), (0, h1)]],
                [complex(*p) for p in [(0, h1), (b, h1), (b, h1 + h2), (0, h1 + h2)]],
                complex(*o), complex(*c), complex(*top),
            )  # fmt: skip
            g1 = d1(lambda x, mo=model: mo.com(1, x), 0.0)
            g2 = d1(lambda x, mo=model: mo.com(2, x), 0.0)
            w2 = d1(model.phi2, 0.0).real
            m.append(
                lower.i_g
                + lower.mass * abs(g1) ** 2
                + upper.i_g * w2**2
                + upper.mass * abs(g2) ** 2
            )
        assert 0 < eta**2 * m[1] / m[0] < 1


def test_restitution_is_one_when_the_hinges_do_not_change():
    lower, upper = rectangular_bodies(0.3, 4.0, 2.2, LENGTH, RHO)
    hinges = rectangular_hinges(0.3, 4.0, 2.2)
    assert two_block_restitution(lower, upper, *hinges, *hinges) == pytest.approx(1.0, rel=1e-15)


# --- bad input ----------------------------------------------------------------------------


def test_zero_mass_and_bad_inertia_are_rejected():
    with pytest.raises(InputError) as err:
        PlanarBody(0.0, (0.1, 1.0), 1.0)
    assert err.value.field == "mass"
    with pytest.raises(InputError):
        PlanarBody(1.0, (0.1, 1.0), -1.0)
    with pytest.raises(InputError):
        PlanarBody(1.0, (math.nan, 1.0), 1.0)


def test_coincident_hinges_are_rejected():
    lower, upper = rectangular_bodies(0.3, 4.0, 2.0, LENGTH, RHO)
    with pytest.raises(GeometryError, match="coincide"):
        two_block_constants(lower, upper, (0.3, 0.0), (0.3, 0.0), (0.3, 4.0))
    with pytest.raises(GeometryError, match="coincide"):
        two_block_constants(lower, upper, (0.3, 0.0), (0.0, 2.0), (0.0, 2.0))


def test_non_finite_or_negative_inputs_are_rejected():
    lower, upper = rectangular_bodies(0.3, 4.0, 2.0, LENGTH, RHO)
    with pytest.raises(InputError) as err:
        two_block_constants(lower, upper, (0.3, 0.0), (0.0, math.inf), (0.3, 4.0))
    assert err.value.field == "C"
    with pytest.raises(InputError) as err:
        two_block_constants(lower, upper, (0.3, 0.0), (0.0, 2.0), (0.3, 4.0), overburden=-1.0)
    assert err.value.field == "overburden"
    with pytest.raises(InputError) as err:
        rectangular_two_block(0.3, 4.0, 2.0, LENGTH, RHO, eccentricity="exact")
    assert err.value.field == "eccentricity"
    with pytest.raises(InputError):
        rectangular_two_block(0.3, 4.0, 4.5, LENGTH, RHO)


def test_level_c_and_h_lock_the_mechanism():
    lower, upper = rectangular_bodies(0.3, 4.0, 2.0, LENGTH, RHO)
    with pytest.raises(GeometryError, match="locks"):
        two_block_constants(lower, upper, (0.3, 0.0), (0.0, 2.0), (3.0, 2.0))


def test_chain_that_locks_before_its_critical_rotation_is_rejected():
    # A short, nearly horizontal upper link: the horizontal restraint at H cannot be kept
    # as C moves outward, long before V has a maximum.
    lower = PlanarBody(500.0, (0.15, 1.0), 60.0)
    upper = PlanarBody(50.0, (0.1, 2.0), 10.0)
    with pytest.raises(GeometryError, match="locks"):
        two_block_constants(lower, upper, (0.3, 0.0), (0.0, 2.0), (-0.4, 2.1))


def test_mechanism_unstable_at_rest_has_no_critical_rotation():
    # A heavy lower block whose centre of mass is outside the base hinge: V falls from rest.
    lower = PlanarBody(2000.0, (1.0, 1.0), 60.0)
    upper = PlanarBody(500.0, (0.15, 3.0), 60.0)
    with pytest.raises(GeometryError, match="no critical rotation"):
        two_block_constants(lower, upper, (0.3, 0.0), (0.0, 2.0), (0.3, 4.0))
