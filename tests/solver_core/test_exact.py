"""Verification of the exact integrator against closed forms and published values."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from shared_schema.errors import InputError
from solver_service.core.exact import kernels, simulate, simulate_batch
from solver_service.core.excitation import Pulse, SampledAccel
from solver_service.core.model import G, RockingModel, RockingSide
from solver_service.core.records import GroundMotion
from solver_service.core.result import STATUS_MESSAGES

P, LAM = 2.0, 0.2
BACKENDS = ["numba", "python"]


def pulse(a_ratio: float, omega: float, sign: float = -1.0, shape: str = "sine") -> Pulse:
    """Pulse of amplitude ``a_ratio * g * LAM`` and frequency ``omega * P``."""
    return Pulse(a_p=sign * a_ratio * G * LAM, f_p=omega * P / (2 * math.pi), shape=shape)


def collapses(model: RockingModel, a_ratio: float, omega: float, sign: float = -1.0) -> bool:
    return simulate(model, pulse(a_ratio, omega, sign)).collapsed


def boundary(model: RockingModel, lo: float, hi: float, omega: float) -> float:
    """Bisect the overturning boundary in A between ``lo`` and ``hi`` to 1e-12."""
    c_lo = collapses(model, lo, omega)
    assert c_lo != collapses(model, hi, omega)
    while hi - lo > 1e-12 * hi:
        mid = 0.5 * (lo + hi)
        if collapses(model, mid, omega) == c_lo:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def zeros(duration: float = 8.0, dt: float = 0.01) -> SampledAccel:
    return SampledAccel(np.zeros(round(duration / dt) + 1), dt)


# --- Zhang & Makris (2001), theory §6.5: eta = 0.9, Omega = 5 -------------------------------


def test_zhang_makris_first_overturning_amplitude() -> None:
    model = RockingModel.symmetric(P, LAM, 0.9)
    assert boundary(model, 3.0, 3.03, 5.0) == pytest.approx(3.0186, abs=0.5e-4)


def test_zhang_makris_safe_band_edges() -> None:
    model = RockingModel.symmetric(P, LAM, 0.9)
    assert boundary(model, 6.30, 6.33, 5.0) == pytest.approx(6.3181, abs=0.5e-4)
    assert boundary(model, 7.15, 7.18, 5.0) == pytest.approx(7.1681, abs=0.5e-4)
    # Inside the band the body passes |phi|/phi_ov = 1 and still comes back.
    inside = simulate(model, pulse(7.0, 5.0))
    assert inside.ratio_exceeded and not inside.collapsed and inside.peak_ratio > 1.0


def _closed_form(omega: float, case: str) -> float:
    """Mode-2 (no impact) overturning amplitude, theory §6.3 (a) and (b)."""
    if case == "a":
        f = lambda s: omega * math.sin(s) - math.cos(s) + math.exp(-(2 * math.pi - s) / omega)  # noqa: E731
    else:
        f = lambda s: omega * math.sin(s) - math.cos(s) - math.exp(-(math.pi - s) / omega)  # noqa: E731
    return 1.0 / math.sin(brentq(f, 1e-12, math.pi / 2, xtol=1e-15))


@pytest.mark.parametrize("omega", [0.5, 1.0, 2.0, 5.0, 8.0])
@pytest.mark.parametrize(("case", "sign"), [("a", -1.0), ("b", 1.0)])
def test_mode2_closed_forms_bound_overturning(omega: float, case: str, sign: float) -> None:
    # One-sided with eta = 0: every impact ends the motion, so only mode 2 can overturn.
    model = RockingModel.symmetric(P, LAM, 0.0, one_sided=True)
    a_crit = _closed_form(omega, case)
    assert not collapses(model, a_crit * (1 - 1e-8), omega, sign)
    assert collapses(model, a_crit * (1 + 1e-8), omega, sign)


def test_mode2_table_values() -> None:
    # theory §6.5 table: one-sided (b) and no-impact (a) columns.
    assert _closed_form(2.0, "b") == pytest.approx(1.801, abs=5e-4)
    assert _closed_form(2.0, "a") == pytest.approx(2.350, abs=5e-4)
    assert _closed_form(10.0, "a") == pytest.approx(21.600, abs=5e-4)


# --- Free rocking: analytic period, invariant, restitution -----------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_free_rocking_quarter_period_and_rebound_peak(backend: str) -> None:
    x0, eta = 0.5, 0.8
    model = RockingModel.symmetric(P, LAM, eta)
    res = simulate(model, zeros(2.0), x0=x0, dense=True, backend=backend)
    assert res.t is not None and res.ratio is not None
    first_impact = res.t[np.flatnonzero((res.ratio == 0.0) & (res.t > 0))[0]]
    assert first_impact == pytest.approx(math.acosh(1 / (1 - x0)) / P, rel=1e-13)
    # After the impact the speed is eta times the arrival speed p*sqrt(1 - (1 - x0)^2).
    expected_peak = 1 - math.sqrt(1 - eta**2 * (1 - (1 - x0) ** 2))
    assert -res.ratio.min() == pytest.approx(expected_peak, rel=1e-12)


def test_free_rocking_asymmetric_velocity_rescaling() -> None:
    x0, eta = 0.6, 0.9
    pos = RockingSide(p_eq=2.0, lam=0.20, phi_ov=0.20)
    neg = RockingSide(p_eq=3.0, lam=0.25, phi_ov=0.30)
    model = RockingModel(pos, neg, eta=eta)
    res = simulate(model, zeros(2.0), x0=x0, dense=True)
    assert res.ratio is not None
    v_arrive = 2.0 * math.sqrt(1 - (1 - x0) ** 2)  # in units of phi_ov+ per second
    v_new = eta * (0.20 / 0.30) * v_arrive  # same angular velocity sense, in phi_ov- units
    assert -res.ratio.min() == pytest.approx(1 - math.sqrt(1 - (v_new / 3.0) ** 2), rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(x0=st.floats(0.05, 0.95), eta=st.floats(0.3, 1.0), p=st.floats(0.5, 20.0))
def test_invariant_conserved_in_flight_and_lost_at_impacts(x0: float, eta: float, p: float) -> None:
    """Successive excursion peaks follow E conservation and v -> eta v exactly."""
    model = RockingModel.symmetric(p, 0.1, eta)
    res = simulate(model, zeros(20.0 / p, dt=0.05 / p), x0=x0, dense=True)
    assert res.ratio is not None
    peaks = []
    sign = 1.0
    for r in res.ratio:  # excursion peaks, alternating sides
        if r * sign < 0:
            sign = -sign
            peaks.append(0.0)
        if peaks and abs(r) > peaks[-1]:
            peaks[-1] = abs(r)
    peaks.insert(0, x0)
    peaks = peaks[:-1]  # the last excursion may be cut off by the end of the record
    assert len(peaks) >= 3
    for before, after in zip(peaks[:-1], peaks[1:]):
        # E_before = -(1 - P_k)^2; at x = 0 speed^2/p^2 = 1 + E; after impact eta^2 (1 + E).
        predicted = 1 - math.sqrt(1 - eta**2 * (1 - (1 - before) ** 2))
        assert after == pytest.approx(predicted, rel=1e-9, abs=1e-12)
        assert after <= before * (1 + 1e-12)  # an impact never adds energy (to rounding)


def test_zeno_sequence_ends_in_rest() -> None:
    model = RockingModel.symmetric(P, LAM, 0.5)
    res = simulate(model, zeros(10.0), x0=0.9)
    # Peaks shrink by ~eta^2 per impact; the rest rule stops the sequence finitely.
    assert res.success and res.status == 0
    assert 5 < res.n_impacts < 200
    assert res.peak_ratio == pytest.approx(0.9)


# --- Thresholds and symmetry -------------------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(
    p=st.floats(0.1, 50.0),
    lam=st.floats(1e-3, 1.4),
    eta=st.floats(0.0, 1.0),
    a_ratio=st.floats(0.0, 0.999999),
    omega=st.floats(0.01, 100.0),
    shape=st.sampled_from(["sine", "cosine"]),
    sign=st.sampled_from([-1.0, 1.0]),
)
def test_no_motion_below_uplift_threshold(
    p: float, lam: float, eta: float, a_ratio: float, omega: float, shape: str, sign: float
) -> None:
    model = RockingModel.symmetric(p, lam, eta)
    exc = Pulse(a_p=sign * a_ratio * G * lam, f_p=omega * p / (2 * math.pi), shape=shape)
    res = simulate(model, exc)
    assert res.peak_ratio == 0.0 and res.n_impacts == 0 and not res.collapsed


@settings(max_examples=40, deadline=None)
@given(
    a_ratio=st.floats(1.0, 30.0),
    omega=st.floats(0.1, 20.0),
    eta=st.floats(0.0, 1.0),
    shape=st.sampled_from(["sine", "cosine"]),
)
def test_antisymmetry_under_reversed_ground_motion(
    a_ratio: float, omega: float, eta: float, shape: str
) -> None:
    model = RockingModel.symmetric(P, LAM, eta)
    up = simulate(model, pulse(a_ratio, omega, 1.0, shape), dense=True)
    down = simulate(model, pulse(a_ratio, omega, -1.0, shape), dense=True)
    assert up.peak_ratio == down.peak_ratio
    assert up.collapsed == down.collapsed and up.n_impacts == down.n_impacts
    assert up.ratio is not None and down.ratio is not None
    np.testing.assert_array_equal(up.ratio, -down.ratio)


def test_antisymmetry_on_el_centro(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    rec = GroundMotion.from_two_column(elcentro_path).accel
    flipped = SampledAccel(-rec.acc, rec.dt)
    model = RockingModel.symmetric(2.0, 0.15, 0.9)
    a, b = simulate(model, rec, dense=True), simulate(model, flipped, dense=True)
    assert a.peak_ratio == b.peak_ratio and a.n_impacts == b.n_impacts > 100
    assert a.ratio is not None and b.ratio is not None
    np.testing.assert_array_equal(a.ratio, -b.ratio)


def test_record_below_threshold_gives_no_motion(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    motion = GroundMotion.from_two_column(elcentro_path)
    lam = motion.pga_g * 1.0001
    res = simulate(RockingModel.symmetric(2.0, lam, 0.9), motion.accel)
    assert res.peak_ratio == 0.0 and res.n_impacts == 0


# --- One-sided rocking ------------------------------------------------------------------------


def test_one_sided_rebounds_and_never_crosses_the_restraint() -> None:
    model = RockingModel.symmetric(P, LAM, -0.5, one_sided=True)
    res = simulate(model, pulse(2.0, 3.0, -1.0), dense=True, t_extra=5.0)
    assert res.ratio is not None
    assert res.ratio.min() >= 0.0
    assert res.n_impacts >= 2 and not res.collapsed


def test_one_sided_with_zero_restitution_rests_after_impact() -> None:
    model = RockingModel.symmetric(P, LAM, 0.0, one_sided=True)
    res = simulate(model, pulse(2.0, 3.0, -1.0), dense=True, t_extra=5.0)
    assert res.t is not None and res.ratio is not None
    assert res.n_impacts == 1
    t_hit = res.t[np.flatnonzero((res.ratio == 0) & (res.t > 0.5))[0]]
    assert np.all(res.ratio[res.t >= t_hit] == 0.0)


def test_one_sided_ignores_pulses_towards_the_restraint() -> None:
    # A record that only ever pushes the body against its restraint (a_g > 0), hard.
    t = np.linspace(0, 2, 201)
    rec = SampledAccel(5.0 * G * LAM * np.abs(np.sin(3 * t)), 0.01)
    res = simulate(RockingModel.symmetric(P, LAM, -0.6, one_sided=True), rec)
    assert res.peak_ratio == 0.0 and res.n_impacts == 0


# --- Back ends, batching, status ----------------------------------------------------------------


def test_backends_agree_on_el_centro(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    rec = GroundMotion.from_two_column(elcentro_path).accel
    model = RockingModel(RockingSide(2.2, 0.15, 0.15), RockingSide(1.8, 0.18, 0.2), eta=0.85)
    fast = simulate(model, rec, scale=1.3, backend="numba")
    slow = simulate(model, rec, scale=1.3, backend="python")
    assert fast.method == "exact:numba" and slow.method == "exact:python"
    assert fast.peak_ratio == pytest.approx(slow.peak_ratio, rel=1e-12)
    assert fast.n_impacts == slow.n_impacts > 50


def test_python_backend_has_no_numba() -> None:
    assert kernels("python").JIT is False


def test_batch_equals_single_runs(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    rec = GroundMotion.from_two_column(elcentro_path).accel
    models = [
        RockingModel.symmetric(2.0, 0.15, 0.9, name="a"),
        RockingModel.symmetric(1.5, 0.25, -0.5, one_sided=True, name="b"),
    ]
    scales = [0.5, 1.0, 2.5]
    batch = simulate_batch(models, rec, scales)
    assert batch.peak_ratio.shape == (2, 3)
    for i, m in enumerate(models):
        for j, sc in enumerate(scales):
            one = simulate(m, rec, scale=sc)
            assert batch.peak_ratio[i, j] == one.peak_ratio
            assert batch.overturned[i, j] == one.overturned
            assert batch.n_impacts[i, j] == one.n_impacts
    rows = batch.rows()
    assert len(rows) == 6 and rows[0]["mechanism"] == "a" and rows[3]["scale"] == 0.5


def test_records_made_one_after_another_are_never_confused() -> None:
    # simulate and simulate_batch keep the cells of the records last used, keyed by identity:
    # a new record (often at a freed record's address) must get its own. Each run is
    # compared with a run on a record just built from the same samples.
    rng = np.random.default_rng(3)
    model = RockingModel.symmetric(2.0, 0.15, 0.9)
    for k in range(12):
        acc = G * 0.4 * np.sin(np.arange(800) * (0.02 + 0.01 * k)) * rng.uniform(0.5, 1.5)
        res = simulate_batch([model], SampledAccel(acc, 0.01), [1.0, 2.0])
        fresh = [simulate(model, SampledAccel(acc.copy(), 0.01), scale=sc) for sc in (1.0, 2.0)]
        assert res.peak_ratio[0].tolist() == [r.peak_ratio for r in fresh]
        assert res.n_impacts[0].tolist() == [r.n_impacts for r in fresh]


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_bad_batch_scale_names_its_index(bad: float) -> None:
    with pytest.raises(InputError) as err:
        simulate_batch([RockingModel.symmetric(2.0, 0.2, 0.9)], zeros(1.0), [1.0, 2.0, bad])
    assert err.value.field == "scales[2]"


def test_strong_pulse_collapses_with_status_1() -> None:
    res = simulate(RockingModel.symmetric(P, LAM, 0.9), pulse(20.0, 2.0))
    assert res.status == 1 and res.success and res.collapsed and res.peak_ratio == 1.0
    assert res.t_collapse is not None and 0 < res.t_collapse < 2 * math.pi / (2.0 * P)


def test_impact_cap_stops_with_status_minus_1(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    rec = GroundMotion.from_two_column(elcentro_path).accel
    res = simulate(RockingModel.symmetric(2.0, 0.15, 0.9), rec, max_impacts=5)
    assert res.status == -1 and not res.success and res.n_impacts == 5


def test_error_estimate_is_small_and_positive(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    rec = GroundMotion.from_two_column(elcentro_path).accel
    res = simulate(RockingModel.symmetric(2.0, 0.15, 0.9), rec)
    assert 0.0 < res.error_estimate < 1e-8


# --- Bad input --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"p_eq": float("nan"), "lam": 0.2}, "p_eq"),
        ({"p_eq": -1.0, "lam": 0.2}, "p_eq"),
        ({"p_eq": 2.0, "lam": 0.0}, "lam"),
        ({"p_eq": 2.0, "lam": -0.1}, "lam"),
        ({"p_eq": 2.0, "lam": 0.2, "eta": 1.3}, "eta"),
        ({"p_eq": 2.0, "lam": 0.2, "eta": 0.5, "one_sided": True}, "eta"),
    ],
)
def test_bad_model_input_names_the_field(kwargs: dict, field: str) -> None:  # type: ignore[type-arg]
    with pytest.raises(InputError) as err:
        RockingModel.symmetric(**kwargs)
    assert err.value.field == field


def test_time_history_of_one_sided_mechanism_needs_eta() -> None:
    model = RockingModel.symmetric(2.0, 0.2, None, one_sided=True, name="F1")
    with pytest.raises(InputError, match=r"F1\.eta"):
        simulate(model, zeros(1.0))


@pytest.mark.parametrize("scale", [0.0, -1.0, float("inf"), float("nan")])
def test_bad_scale_is_rejected(scale: float) -> None:
    with pytest.raises(InputError, match="scale"):
        simulate(RockingModel.symmetric(2.0, 0.2, 0.9), zeros(1.0), scale=scale)


# --- Extreme parameters: never NaN, never a hang, never a failure status -------------------


@settings(max_examples=150, deadline=None)
@given(
    p=st.floats(0.05, 100.0),
    lam=st.floats(1e-4, 1.4),
    eta=st.floats(-1.0, 1.0),
    a_ratio=st.floats(1.0 + 1e-12, 1e6),
    omega=st.floats(1e-3, 1e3),
    shape=st.sampled_from(["sine", "cosine"]),
    sign=st.sampled_from([-1.0, 1.0]),
)
def test_extreme_pulses_give_finite_complete_results(
    p: float, lam: float, eta: float, a_ratio: float, omega: float, shape: str, sign: float
) -> None:
    model = RockingModel.symmetric(p, lam, eta, one_sided=eta < 0)
    exc = Pulse(a_p=sign * a_ratio * G * lam, f_p=omega * p / (2 * math.pi), shape=shape)
    res = simulate(model, exc)
    assert res.status in (0, 1)
    for value in (res.peak_ratio, res.t_peak, res.error_estimate):
        assert math.isfinite(value)
    assert 0.0 <= res.peak_ratio and (res.collapsed or res.peak_ratio < 1e3)
    assert res.n_impacts < 10_000


@pytest.mark.parametrize(("dt", "p"), [(1e-5, 2.0), (0.1, 100.0), (0.02, 0.05)])
def test_extreme_time_steps_and_frequencies(dt: float, p: float) -> None:
    rng = np.random.default_rng(7)
    rec = SampledAccel(rng.normal(0.0, 0.3 * G, 20_000), dt)
    for eta, one_sided in [(0.9, False), (-0.95, True), (0.0, False)]:
        res = simulate(RockingModel.symmetric(p, 0.1, eta, one_sided=one_sided), rec)
        assert res.status in (0, 1)
        assert math.isfinite(res.peak_ratio) and math.isfinite(res.error_estimate)


# --- Impact log, work counters and warnings (issue 7) ---------------------------------------


def test_impact_log_is_identical_on_both_backends(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    rec = GroundMotion.from_two_column(elcentro_path).accel
    model = RockingModel.symmetric(2.0, 0.15, 0.9)
    a, b = (simulate(model, rec, impact_log=True, backend=be) for be in BACKENDS)
    assert a.impacts is not None and b.impacts is not None
    assert a.impacts.shape == b.impacts.shape
    # Every counted impact is logged, and so is every sub-threshold one (it ends in rest).
    assert a.n_impacts <= a.impacts.shape[1] <= a.n_impacts + a.n_rests
    np.testing.assert_allclose(a.impacts, b.impacts, rtol=1e-12, atol=1e-15)
    assert (a.n_uplifts, a.n_rests) == (b.n_uplifts, b.n_rests)
    assert simulate(model, rec).impacts is None  # the log is opt-in


def test_impact_log_follows_the_impact_rule_and_loses_energy(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    rec = GroundMotion.from_two_column(elcentro_path).accel
    res = simulate(RockingModel.symmetric(2.0, 0.15, 0.9), rec, impact_log=True)
    assert res.impacts is not None
    t, side, v_in, v_out = res.impacts
    moving = v_out != 0.0
    np.testing.assert_allclose(v_out[moving], 0.9 * v_in[moving], rtol=1e-15)
    assert np.all(side * v_in <= 0.0)  # arrives moving towards phi = 0
    assert np.all(np.diff(t) > 0.0)
    # theory §1.8 at x = 0: E = (x'/p)^2 - 1 never increases at an impact.
    assert np.all((v_out / 2.0) ** 2 <= (v_in / 2.0) ** 2)


def test_counters_of_a_free_zeno_sequence() -> None:
    res = simulate(RockingModel.symmetric(P, LAM, 0.5), zeros(10.0), x0=0.9, impact_log=True)
    assert res.impacts is not None
    # Released in flight: no uplift; one rest ends the Zeno sequence; every impact logged.
    assert res.n_uplifts == 0 and res.n_rests == 1
    assert res.impacts.shape[1] == res.n_impacts + (1 if abs(res.impacts[2, -1]) < 1e-9 * P else 0)
    assert res.impacts[3, -1] == 0.0
    # Free motion conserves E between impacts: the speed leaving one impact is the speed
    # arriving at the next.
    np.testing.assert_allclose(np.abs(res.impacts[3, :-1]), np.abs(res.impacts[2, 1:]), rtol=1e-9)


def test_one_sided_rebound_log_points_outward() -> None:
    model = RockingModel.symmetric(P, LAM, -0.7, one_sided=True)
    res = simulate(model, zeros(10.0), x0=0.8, impact_log=True)
    assert res.impacts is not None and res.impacts.shape[1] >= 5
    _, side, v_in, v_out = res.impacts
    assert np.all(side == 1.0) and np.all(v_in < 0.0) and np.all(v_out >= 0.0)
    np.testing.assert_allclose(v_out[v_out > 0], 0.7 * np.abs(v_in[v_out > 0]), rtol=1e-15)


def test_unresolved_peak_is_said_in_warnings_and_message() -> None:
    rng = np.random.default_rng(102)
    acc = rng.normal(0.0, 1.0, 2001)
    rec = SampledAccel(acc * 0.8 * G / np.max(np.abs(acc)), 1e-3)
    model = RockingModel.symmetric(20.0, 0.2, -1.0, one_sided=True)
    res = simulate(model, rec)
    assert res.error_estimate >= 0.1
    assert any("not resolved" in w for w in res.warnings)
    assert "not resolved" in res.message and res.message.startswith(STATUS_MESSAGES[res.status])
    assert res.summary()["warnings"] == res.warnings
    calm = simulate(RockingModel.symmetric(2.0, 0.15, 0.9), pulse(1.3, 3.0))
    assert calm.warnings == [] and calm.message == STATUS_MESSAGES[calm.status]


def test_stocky_mechanism_carries_a_linearisation_warning() -> None:
    stocky = RockingModel.symmetric(2.0, 1.0, 0.0)
    res = simulate(stocky, Pulse(a_p=-2.0 * G, f_p=5.0 * 2.0 / (2 * math.pi)))
    assert any("linearised model may be off" in w for w in res.warnings)
    slender = RockingModel.symmetric(2.0, 0.05, 0.9)
    res = simulate(slender, Pulse(a_p=-0.1 * G, f_p=1.0))
    assert not any("linearised" in w for w in res.warnings)


def test_batch_rows_flag_an_unresolved_peak() -> None:
    from solver_service.core.exact import UNRESOLVED_ERROR, BatchResult

    one = np.ones((1, 2))
    batch = BatchResult(
        names=["M"],
        scales=np.array([1.0, 2.0]),
        peak_ratio=0.5 * one,
        t_peak=one,
        ratio_exceeded=np.zeros((1, 2), dtype=bool),
        t_ratio_exceeded=np.full((1, 2), np.nan),
        collapsed=np.zeros((1, 2), dtype=bool),
        t_collapse=np.full((1, 2), np.nan),
        n_impacts=np.ones((1, 2), dtype=np.int64),
        n_steps=np.ones((1, 2), dtype=np.int64),
        error_estimate=np.array([[1e-12, UNRESOLVED_ERROR]]),
        status=np.zeros((1, 2), dtype=np.int64),
        criterion="ratio",
        runtime_s=0.0,
        method="exact",
    )
    first, second = batch.rows()
    assert "warnings" not in first
    assert second["warnings"] and "not resolved" in second["warnings"][0]
