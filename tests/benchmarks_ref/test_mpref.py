"""Checks of the 30-digit mpmath reference (benchmarks/mpref.py) against closed forms.

The benchmark measures the exact integrator against this reference, so the reference itself
is verified here, independently of the project's solvers: free-rocking times in closed form,
the Zhang & Makris (2001) mode-1 overturning onset and the closed-form mode-2 onset
(theory §6.3, §6.5).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

mpmath = pytest.importorskip("mpmath", reason="mpmath is needed for the benchmark reference")
from mpmath import mp, mpf  # noqa: E402

from solver_service.core.excitation import Pulse, SampledAccel  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import mpref  # noqa: E402

P_EQ = 2.0
G = 9.80665


def sine_pulse(amp: float, omega_ratio: float, lam: float) -> Pulse:
    """``A = |a_p|/(g lam)``, ``a_p < 0``: the pulse first drives positive rotation."""
    return Pulse(a_p=-amp * G * lam, f_p=omega_ratio * P_EQ / (2.0 * math.pi))


@pytest.mark.parametrize("x0", [0.3, 0.5, 0.9])
def test_free_rocking_quarter_period_is_acosh(x0: float) -> None:
    # x'' = p^2 (x - 1) from rest at x0: x = 1 - (1 - x0) cosh(p t) reaches 0 at
    # t = acosh(1/(1 - x0))/p.
    model = mpref.MPModel.symmetric(P_EQ, 0.2, 0.9)
    res = mpref.simulate_mp(model, SampledAccel(np.zeros(101), 0.02), x0=x0)
    with mp.workdps(40):
        expected = mp.acosh(1 / (1 - mpf(x0))) / P_EQ
        assert abs(res.t_impacts[0] - expected) < mpf(10) ** -26


@pytest.mark.parametrize(("a0", "slope"), [(0.5, 0.0), (0.5, 1.0), (-0.25, -0.5)])
def test_first_impact_under_linear_acceleration_matches_textbook_form(
    a0: float, slope: float
) -> None:
    # Dyadic samples on an exact line, so the record is that line. Textbook solution
    # x = 1 + q0 + q1 t + A cosh(p t) + B sinh(p t) with x(0) = x0, x'(0) = 0, solved
    # independently at 40 digits (the reference uses the anchor form at 30).
    lam, x0, dt = 0.25, 0.5, 0.25
    acc = a0 + slope * dt * np.arange(41)
    model = mpref.MPModel.symmetric(P_EQ, lam, 0.9)
    res = mpref.simulate_mp(model, SampledAccel(acc, dt), x0=x0)
    with mp.workdps(40):
        gl = mpf(mpref.G_EXACT) * mpf(lam)
        q0, q1, p = mpf(a0) / gl, mpf(slope) / gl, mpf(P_EQ)
        ca, cb = mpf(x0) - 1 - q0, -q1 / p

        def x(t: mpf) -> mpf:
            return 1 + q0 + q1 * t + ca * mp.cosh(p * t) + cb * mp.sinh(p * t)

        t1 = mp.findroot(x, (mpf(0), mpf(3)), solver="bisect", maxsteps=300, verify=False)
        assert abs(res.t_impacts[0] - t1) < mpf(10) ** -25


def test_no_motion_below_the_uplift_threshold() -> None:
    model = mpref.MPModel.symmetric(P_EQ, 0.2, 0.9)
    res = mpref.simulate_mp(model, sine_pulse(0.99, 3.0, 0.2))
    assert res.peak == 0
    assert res.n_impacts == 0
    assert not res.collapsed


def test_zhang_makris_mode1_onset_at_eta_09_omega_5() -> None:
    # theory §6.5: first overturning (one impact) at A = 3.019 (Zhang & Makris: 3.01);
    # bisection on the collapse verdict to a bracket of 1e-4.
    model = mpref.MPModel.symmetric(P_EQ, 0.2, 0.9)

    def collapses(amp: float) -> bool:
        return mpref.simulate_mp(model, sine_pulse(amp, 5.0, 0.2)).collapsed

    lo, hi = 2.95, 3.05
    assert not collapses(lo)
    assert collapses(hi)
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        if collapses(mid):
            hi = mid
        else:
            lo = mid
    onset = 0.5 * (lo + hi)
    assert f"{onset:.4g}" == "3.019"
    assert abs(onset - 3.0186) < 1e-4


def test_mode2_onset_matches_closed_form_to_1e10() -> None:
    # theory §6.3(a) (Zhang & Makris 2001 Eq. 47): overturning without impact starts at
    # A = 1/sin(psi), Omega sin(psi) - cos(psi) = -exp(-(2 pi - psi)/Omega). Just below it
    # lies the "safe cape" (theory §6.5), so the verdict flips across the closed form.
    omega = 5.0
    with mp.workdps(30):
        om = mpf(omega)
        psi = mp.findroot(
            lambda s: om * mp.sin(s) - mp.cos(s) + mp.exp(-(2 * mp.pi - s) / om), mpf("0.14")
        )
        a_crit = float(1 / mp.sin(psi))
    assert abs(a_crit - 7.168) < 1e-3
    model = mpref.MPModel.symmetric(P_EQ, 0.2, 0.9)
    below = mpref.simulate_mp(model, sine_pulse(a_crit * (1 - 1e-10), omega, 0.2))
    above = mpref.simulate_mp(model, sine_pulse(a_crit * (1 + 1e-10), omega, 0.2))
    assert not below.collapsed
    assert below.n_impacts == 0
    assert below.peak > 1  # it passes phi_ov and still comes back
    assert above.collapsed
    assert above.n_impacts == 0
