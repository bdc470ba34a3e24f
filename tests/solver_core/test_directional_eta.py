"""Directional restitution: each impact uses the eta of the side it leads into (theory §1.8).

References are independent of the integrators: the free-rocking invariant of theory §1.8
gives the peak of every excursion in closed form, so the peak sequence of free rocking from
rest is a product of the two restitution values taken in turn.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver_service.core.envelope import DIRECTIONAL_NOTE, boundary_curve, mechanism_envelope
from solver_service.core.exact import simulate, simulate_batch
from solver_service.core.excitation import Pulse, SampledAccel
from solver_service.core.model import G, RockingModel, RockingSide
from solver_service.core.reference import simulate_ivp

P, LAM = 2.0, 0.2
ETA_NEG, ETA_POS = 0.9, 0.7
BACKENDS = ["numba", "python"]


def directional(to_neg: float, to_pos: float, negative: RockingSide | None = None) -> RockingModel:
    side = RockingSide(P, LAM)
    return RockingModel(
        side, negative, eta=max(to_neg, to_pos), eta_to_negative=to_neg, eta_to_positive=to_pos
    )


def free_peaks(x0: float, to_neg: float, to_pos: float, n: int) -> list[float]:
    """Peaks of free rocking from rest at ``x0 > 0`` (symmetric sides), by hand.

    Invariant E = (x'/p)**2 - (|x| - 1)**2: the body reaches x = 0 at speed
    ``p sqrt(1 - (1 - x0)**2)``; each impact multiplies the speed by the eta of the side
    entered (negative first); an excursion leaving at speed ``v`` peaks at
    ``1 - sqrt(1 - (v/p)**2)``.
    """
    peaks = [x0]
    q = math.sqrt(1.0 - (1.0 - x0) ** 2)  # speed / p at the first impact
    for k in range(n - 1):
        q *= to_neg if k % 2 == 0 else to_pos
        peaks.append(1.0 - math.sqrt(1.0 - q * q))
    return peaks


def excursion_peaks(t: np.ndarray, ratio: np.ndarray) -> list[float]:
    """Largest |x| between consecutive returns to x = 0 of a time series."""
    peaks, current = [], 0.0
    for x in ratio:
        if x == 0.0 and current > 0.0:
            peaks.append(current)
            current = 0.0
        current = max(current, abs(float(x)))
    return peaks


@pytest.mark.parametrize("backend", BACKENDS)
def test_free_rocking_peak_sequence_matches_closed_form(backend: str) -> None:
    x0 = 0.6
    model = directional(ETA_NEG, ETA_POS)
    rec = SampledAccel(np.zeros(1501), 0.01)
    res = simulate(model, rec, x0=x0, dense=True, backend=backend)
    assert res.t is not None and res.ratio is not None
    got = excursion_peaks(res.t, res.ratio)[:6]
    want = free_peaks(x0, ETA_NEG, ETA_POS, 6)
    np.testing.assert_allclose(got, want, rtol=1e-12)
    # The sides alternate: the second excursion is on the negative side.
    assert np.min(res.ratio) == pytest.approx(-want[1], rel=1e-12)
    # Swapped etas give the other sequence: the code does not just use one value.
    swapped = simulate(directional(ETA_POS, ETA_NEG), rec, x0=x0, dense=True, backend=backend)
    assert swapped.ratio is not None and swapped.t is not None
    other = excursion_peaks(swapped.t, swapped.ratio)[:3]
    np.testing.assert_allclose(other, free_peaks(x0, ETA_POS, ETA_NEG, 3), rtol=1e-12)
    assert abs(other[1] - got[1]) > 0.05


@pytest.mark.parametrize("backend", BACKENDS)
def test_impact_log_applies_the_eta_of_the_side_entered(backend: str) -> None:
    # Asymmetric sides: in x the rule is x' -> eta_new (phi_ov_old / phi_ov_new) x'.
    neg = RockingSide(2.5, 0.15, 0.12)
    model = directional(ETA_NEG, ETA_POS, neg)
    res = simulate(
        model, SampledAccel(np.zeros(1501), 0.01), x0=0.2, impact_log=True, backend=backend
    )
    log = res.impacts
    assert log is not None and log.shape[1] >= 4
    for t, side, v_in, v_out in log.T[:4]:
        eta, ratio = (ETA_NEG, LAM / 0.12) if side > 0 else (ETA_POS, 0.12 / LAM)
        assert v_out == pytest.approx(eta * ratio * v_in, rel=1e-14), t


def test_free_tail_uses_the_next_impact_eta() -> None:
    # The excitation ends at once; the analytic tail decides. Released at x0 on the positive
    # side, the body returns at x' = p+ sqrt(1 - (1 - x0)**2), leaves the impact into the
    # negative side at eta_to_negative (phi_ov+/phi_ov-) times that, and peaks at
    # 1 - sqrt(1 - (x'/p-)**2): above x0 for these constants, so it is the reported peak.
    neg = RockingSide(2.5, 0.15, 0.12)
    x0 = 0.3
    for to_neg in (0.95, 0.85):
        model = directional(to_neg, 0.3, neg)
        res = simulate(model, SampledAccel(np.zeros(3), 0.01), x0=x0)
        q = to_neg * (LAM / 0.12) * P * math.sqrt(1.0 - (1.0 - x0) ** 2) / 2.5
        assert res.peak_ratio == pytest.approx(1.0 - math.sqrt(1.0 - q * q), rel=1e-12)
        ref = simulate_ivp(model, SampledAccel(np.zeros(3), 0.01), x0=x0)
        assert ref.peak_ratio == pytest.approx(res.peak_ratio, rel=1e-12)


def pulse(a_ratio: float, omega: float, sign: float) -> Pulse:
    return Pulse(a_p=sign * a_ratio * G * LAM, f_p=omega * P / (2 * math.pi))


def test_pulse_distinguishes_the_two_etas_and_matches_the_reference() -> None:
    # Omega = 4 at A = 2.0: a pulse opening the positive side first overturns after one
    # impact into the negative side with eta 0.9, but not with 0.7 (theory §6.5 table:
    # A_min = 1.795 at eta 0.9, 5.239 at 0.7).
    exc = pulse(2.0, 4.0, -1.0)
    a = simulate(directional(0.9, 0.7), exc)
    b = simulate(directional(0.7, 0.9), exc)
    assert a.collapsed and not b.collapsed
    # The mirror image: the opposite pulse on the swapped model is the same motion.
    mirror = simulate(directional(0.9, 0.7), pulse(2.0, 4.0, 1.0))
    assert mirror.collapsed == b.collapsed and mirror.peak_ratio == pytest.approx(b.peak_ratio)
    ref = simulate_ivp(directional(0.7, 0.9), exc, rtol=1e-11, atol=1e-13)
    assert ref.collapsed == b.collapsed
    assert ref.peak_ratio == pytest.approx(b.peak_ratio, rel=1e-7)
    assert ref.n_impacts == b.n_impacts


def test_batch_mixes_directional_and_single_eta_models() -> None:
    rec = SampledAccel(np.sin(np.linspace(0.0, 12.0, 601)) * 0.5 * G * LAM, 0.01)
    models = [directional(ETA_NEG, ETA_POS), RockingModel.symmetric(P, LAM, 0.8)]
    scales = np.array([1.5, 2.5, 4.0])
    batch = simulate_batch(models, rec, scales)
    for i, m in enumerate(models):
        for j, sc in enumerate(scales):
            one = simulate(m, rec, scale=float(sc))
            assert batch.peak_ratio[i, j] == one.peak_ratio
            assert batch.n_impacts[i, j] == one.n_impacts


def test_equal_directional_etas_are_bit_identical_to_one_eta() -> None:
    rec = SampledAccel(np.sin(np.linspace(0.0, 12.0, 601)) * 0.5 * G * LAM, 0.01)
    plain = RockingModel.symmetric(P, LAM, 0.8)
    same = directional(0.8, 0.8)
    for sc in (1.5, 3.0, 6.0):
        a, b = simulate(plain, rec, scale=sc), simulate(same, rec, scale=sc)
        assert (a.peak_ratio, a.t_peak, a.n_impacts) == (b.peak_ratio, b.t_peak, b.n_impacts)
        assert a.error_estimate == b.error_estimate


def test_boundary_with_two_etas_mirrors_under_swap() -> None:
    om = np.array([0.6, 2.0, 4.0, 6.0])
    a = boundary_curve(om, 0.9, direction=-1, eta_neg=0.7).a_min
    b = boundary_curve(om, 0.7, direction=1, eta_neg=0.9).a_min
    np.testing.assert_array_equal(a, b)
    one = boundary_curve(om, 0.9).a_min
    assert not np.array_equal(a, one)


def test_directional_envelope_is_exact_and_says_so() -> None:
    model = directional(ETA_NEG, ETA_POS)
    f = np.array([0.2, 0.6, 1.3, 2.5])
    env = mechanism_envelope(model, f)
    assert env.notes == [DIRECTIONAL_NOTE.format(neg=ETA_NEG, pos=ETA_POS)]
    om = 2 * np.pi * f / P
    want = np.minimum(
        boundary_curve(om, ETA_POS, direction=1, eta_neg=ETA_NEG).a_min,
        boundary_curve(om, ETA_POS, direction=-1, eta_neg=ETA_NEG).a_min,
    )
    np.testing.assert_allclose(env.a_p_min_local_g, LAM * want, rtol=1e-12)
    # Between the single-eta envelopes: never below the larger eta's (on this grid), and
    # far above the smaller eta's where an impact decides.
    hi = mechanism_envelope(RockingModel.symmetric(P, LAM, ETA_NEG), f, exact=True)
    lo = mechanism_envelope(RockingModel.symmetric(P, LAM, ETA_POS), f, exact=True)
    assert np.all(env.a_p_min_local_g >= hi.a_p_min_local_g * (1 - 1e-9))
    assert np.all(env.a_p_min_local_g <= lo.a_p_min_local_g * (1 + 1e-9))
    assert mechanism_envelope(RockingModel.symmetric(P, LAM, 0.9), f).notes == []
