"""Code checks (theory §11): closed forms for a rectangular block, a loaded wall by hand,
and the elastic spectra of NTC 2018 and EN 1998-1 at hand-computed points."""

import math

import numpy as np
import pytest

from cad_maths.geometry.massprops import MassProps
from cad_maths.mechanisms.loaded import _constants
from cad_maths.mechanisms.single import Body, rocking_side
from shared_schema.errors import InputError
from solver_service.codes.circ2009 import (
    Building,
    VirtualWork,
    linear_check,
    nonlinear_check,
    participating_mass,
)
from solver_service.codes.hazard import ec8_spectrum, ntc_spectrum

G = 9.80665


def block(b: float, h: float, rho: float = 1800.0) -> VirtualWork:
    m = rho * b * h
    return VirtualWork(alpha0=b / h, mass=m, S=m * h / 2, J=m * h * h / 3)


def test_rectangular_block_linear_check_follows_the_circolare() -> None:
    b, h, fc, q = 0.5, 3.0, 1.35, 2.0
    vw = block(b, h)
    m_star, e_star = participating_mass(vw)
    assert e_star == pytest.approx(0.75, abs=1e-12)
    assert m_star == pytest.approx(0.75 * vw.mass, rel=1e-12)
    sp = ntc_spectrum(0.25, 2.4, 0.3, soil="C")
    out = linear_check(vw, sp, FC=fc, q=q)
    assert out["a0_star"] == pytest.approx((b / h) * G / (0.75 * fc), rel=1e-12)
    assert out["demand_ground"] == pytest.approx(0.25 * 1.34 * G / q, rel=1e-12)
    assert out["passes"] is (out["a0_star"] >= out["demand_ground"])
    assert out["demand_height"] is None


def test_height_demand_uses_psi_gamma_and_the_spectrum_at_t1() -> None:
    vw = block(0.5, 3.0)
    sp = ntc_spectrum(0.25, 2.4, 0.3, soil="C")
    bld = Building(H=12.0, N=3, T1=0.3)
    out = linear_check(vw, sp, FC=1.0, Z=9.0, building=bld)
    # T1 = 0.3 s lies on the plateau: S_e = a_g S F0.
    se = 0.25 * 1.34 * 2.4 * G
    assert out["demand_height"] == pytest.approx(se * (9 / 12) * (9 / 7) / 2.0, rel=1e-12)
    assert out["demand"] == max(out["demand_ground"], out["demand_height"])
    missing = linear_check(vw, sp, FC=1.0, Z=9.0)
    assert missing["passes"] is None and "building" in missing["note"]
    with pytest.raises(InputError, match="outside the building"):
        linear_check(vw, sp, FC=1.0, Z=20.0, building=bld)


def test_rectangular_block_nonlinear_check_closed_form() -> None:
    b, h, fc = 0.5, 3.0, 1.2
    vw = block(b, h)
    alpha = math.atan(b / h)
    sp = ntc_spectrum(0.25, 2.4, 0.3, soil="C")
    out = nonlinear_check(vw, alpha, sp, FC=fc)
    a0 = (b / h) * G / (0.75 * fc)
    d0 = alpha * 2 * h / 3
    ds = 0.16 * d0
    ts = 2 * math.pi * math.sqrt(ds / (a0 * 0.84))
    assert out["d0_star"] == pytest.approx(d0, rel=1e-12)
    assert out["du_star"] == pytest.approx(0.4 * d0, rel=1e-12)
    assert out["Ts"] == pytest.approx(ts, rel=1e-12)
    # Ts lies between T_C and T_D: S_De = a_g S F0 (T_C / Ts) g Ts² / (4 pi²).
    assert sp.T_C < ts < sp.T_D
    sde = 0.25 * 1.34 * 2.4 * sp.T_C * ts * G / (4 * math.pi**2)
    assert out["demand_ground"] == pytest.approx(sde, rel=1e-12)
    assert out["curve"]["a_star"][0] == pytest.approx(a0, rel=1e-12)
    assert out["curve"]["a_star"][-1] == pytest.approx(0.0, abs=1e-12)
    assert out["passes"] is (out["du_star"] >= sde)


def test_hand_worked_loaded_wall() -> None:
    """0.6 x 8 m wall, a bearing floor, an abutting floor and an outward thrust, by hand."""
    b, h, rho = 0.6, 8.0, 1800.0
    m_w = rho * b * 1.0 * h  # 8640 kg
    props = MassProps(
        b * h,
        m_w,
        [-b / 2, 0.5, h / 2],
        np.diag([m_w * (1 + h**2) / 12, m_w * (b**2 + h**2) / 12, m_w * (b**2 + 1) / 12]),
        rho,
    )
    corners = np.array(
        [[x, y, z] for x in (-b, 0.0) for y in (0.0, 1.0) for z in (0.0, h)], dtype=float
    )
    body = Body(props, [props], [], corners, ["wall"])
    side = rocking_side(body, np.array([0.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), where="W")
    bearing = [(2000.0, np.array([-0.45, 0.5, 4.0]), "floor")]
    nonbearing = [(1500.0, np.array([-0.6, 0.5, 6.0]), "abutting floor")]
    forces = [(2000.0, np.array([0.0, 0.5, 7.5]), "thrust")]
    _, summary, _ = _constants(body, side, bearing, nonbearing, forces, [], [])
    vw = summary["virtual_work"]
    # By hand: S = 8640*4 + 2000*4 + 1500*6; J = 8640*64/3 + 2000*16 + 1500*36.
    s_hand = 51560.0
    j_hand = 184320.0 + 32000.0 + 54000.0
    alpha0_hand = (G * (8640 * 0.3 + 2000 * 0.45) - 2000.0 * 7.5) / (G * s_hand)
    assert vw["S"] == pytest.approx(s_hand, rel=1e-9)
    assert vw["J"] == pytest.approx(j_hand, rel=1e-9)
    assert vw["mass"] == pytest.approx(12140.0, rel=1e-9)
    assert vw["alpha0"] == pytest.approx(alpha0_hand, rel=1e-9)
    # Circ. 2019 [C8.7.1.5] by blocks: the wall and what it carries are one term.
    assert vw["J_blocks"] == pytest.approx(s_hand**2 / 12140.0, rel=1e-9)
    # The 2009 forms (codes.circ2009) sum over the solid, as before.
    integral = VirtualWork(vw["alpha0"], vw["mass"], vw["S"], vw["J"])
    out = linear_check(integral, ntc_spectrum(0.15, 2.5, 0.3), FC=1.35)
    e_hand = s_hand**2 / j_hand / 12140.0
    assert out["e_star"] == pytest.approx(e_hand, rel=1e-9)
    assert out["a0_star"] == pytest.approx(alpha0_hand * G / (e_hand * 1.35), rel=1e-9)
    assert out["demand_ground"] == pytest.approx(0.15 * G / 2.0, rel=1e-12)


def test_ntc_spectrum_corners_by_hand() -> None:
    sp = ntc_spectrum(0.25, 2.4, 0.3, soil="C", topography="T2")
    c_c = 1.05 * 0.3**-0.33
    assert sp.params["C_C"] == pytest.approx(c_c, rel=1e-12)
    assert sp.T_C == pytest.approx(c_c * 0.3, rel=1e-12)
    assert sp.T_B == pytest.approx(c_c * 0.1, rel=1e-12)
    assert sp.S == pytest.approx(1.34 * 1.2, rel=1e-12)
    top = 0.25 * 1.34 * 1.2 * 2.4
    t = np.array([0.0, sp.T_B, sp.T_C, 1.0, sp.T_D, 3.0])
    want = [0.25 * 1.34 * 1.2, top, top, top * sp.T_C, top * sp.T_C / sp.T_D]
    assert sp.Se(t)[:5] == pytest.approx(want, rel=1e-12)
    assert sp.Se([3.0])[0] == pytest.approx(top * sp.T_C * sp.T_D / 9, rel=1e-12)
    # Soil-factor bounds: stiff soil B at high a_g hits the lower bound 1.0.
    assert ntc_spectrum(0.5, 3.0, 0.3, soil="B").params["S_S"] == 1.0
    assert sp.SDe([12.0])[0] == pytest.approx(0.025 * 0.25 * G * sp.S * sp.T_C * sp.T_D)


def test_ec8_type1_and_type2_plateaus() -> None:
    sp1 = ec8_spectrum(0.2, 1.2, "C", 1)
    assert sp1.Se([0.3])[0] == pytest.approx(0.24 * 1.15 * 2.5, rel=1e-12)
    assert sp1.Se([0.0])[0] == pytest.approx(0.24 * 1.15, rel=1e-12)
    sp2 = ec8_spectrum(0.1, 1.0, "D", 2)
    assert sp2.Se([0.2])[0] == pytest.approx(0.1 * 1.8 * 2.5, rel=1e-12)
    assert sp2.Se([1.0])[0] == pytest.approx(0.45 * 0.3 / 1.0, rel=1e-12)
    # 10 % damping: eta = sqrt(10/15).
    sp3 = ec8_spectrum(0.2, 1.0, "A", 1, xi_percent=10.0)
    assert sp3.Se([0.3])[0] == pytest.approx(0.2 * 2.5 * math.sqrt(10 / 15), rel=1e-12)
    with pytest.raises(InputError):
        ec8_spectrum(0.2, 1.0, "F", 1)


def test_a_degenerate_capacity_curve_is_an_input_error() -> None:
    # issue #25: e* below the smallest normal double made a0* infinite, Ts zero and the
    # demand zero: a ZeroDivisionError (500 on /check) before
    vw = VirtualWork(alpha0=362880.0, mass=1.6895145690793514e308, S=0.001, J=2.00001)
    sp = ntc_spectrum(0.25, 2.4, 0.3, soil="C")
    with pytest.raises(InputError, match=r"^virtual_work: the capacity curve is out of any"):
        nonlinear_check(vw, 2.845531763012203e-29, sp, FC=1.0)
    # an ordinary block at the same spectrum still runs
    assert nonlinear_check(block(0.5, 3.0), 0.165, sp, FC=1.0)["capacity_ratio"] > 0.0
