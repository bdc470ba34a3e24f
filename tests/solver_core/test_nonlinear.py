"""Tests of Housner's nonlinear rocking block (time-stepping reference)."""

from __future__ import annotations

import math
import pathlib

import numpy as np
import pytest
from scipy.integrate import quad

from shared_schema.errors import InputError
from solver_service.core.excitation import Pulse, SampledAccel
from solver_service.core.model import G
from solver_service.core.nonlinear import HousnerBlock, linearisation_error, simulate_nonlinear
from solver_service.core.reference import simulate_ivp

# The public-domain El Centro 1940 N-S record bundled with the project.
ELCENTRO = pathlib.Path(__file__).resolve().parents[2] / "examples" / "records" / "elcentro_NS.dat"


def zeros(duration: float, dt: float = 0.05) -> SampledAccel:
    return SampledAccel(np.zeros(round(duration / dt) + 1), dt)


def pulse(block: HousnerBlock, amp: float, omega_ratio: float) -> Pulse:
    """Sine pulse with a_p = amp * G tan(alpha) and omega_p = omega_ratio * p."""
    return Pulse(a_p=amp * G * math.tan(block.alpha), f_p=omega_ratio * block.p / (2 * math.pi))


def quarter_period(block: HousnerBlock, phi0: float) -> float:
    """Exact time [s] from release at rest at phi0 to the impact (elliptic integral).

    Energy: phi'²/(2p²) = cos(alpha - phi0) - cos(alpha - phi); with u = phi0 - phi the
    difference is 2 sin(alpha - phi0 + u/2) sin(u/2), and the u**-1/2 singularity is left to
    quad's algebraic weight.
    """
    a = block.alpha

    def f(u: float) -> float:
        return 1.0 / math.sqrt(2.0 * math.sin(a - phi0 + 0.5 * u) * np.sinc(u / (2 * math.pi)))

    val, _ = quad(f, 0.0, phi0, weight="alg", wvar=(-0.5, 0.0), epsabs=0.0, epsrel=1e-13)
    return val / block.p


def excursion_peaks(ratio: np.ndarray) -> list[float]:
    """max |x| of each complete excursion (impacts are exact zeros in the dense output)."""
    z = np.flatnonzero(ratio == 0.0)
    return [float(np.max(np.abs(ratio[z[k] : z[k + 1] + 1]))) for k in range(len(z) - 1)]


# -- free rocking: analytic and energy ----------------------------------------------------------


@pytest.mark.parametrize(("alpha", "x0"), [(0.3, 0.5), (0.6, 0.9), (1.2, 0.3), (0.05, 0.5)])
def test_time_to_first_impact_is_the_elliptic_quarter_period(alpha: float, x0: float) -> None:
    block = HousnerBlock(p=2.0, alpha=alpha, eta=0.85)
    r = simulate_nonlinear(block, zeros(3.0), x0=x0, dense=True)
    assert r.t is not None and r.ratio is not None
    t_impact = float(r.t[np.flatnonzero(r.ratio == 0.0)[0]])
    assert t_impact == pytest.approx(quarter_period(block, x0 * alpha), rel=1e-8)


def test_quarter_period_tends_to_housners_linearised_formula() -> None:
    # Housner (1963): T/4 = acosh(1/(1 - theta0/alpha))/p for slender blocks only.
    housner = math.acosh(1.0 / (1.0 - 0.5)) / 2.0
    slender = quarter_period(HousnerBlock(p=2.0, alpha=0.05, eta=0.9), 0.5 * 0.05)
    stocky = quarter_period(HousnerBlock(p=2.0, alpha=0.6, eta=0.9), 0.5 * 0.6)
    assert slender == pytest.approx(housner, rel=1e-4)
    assert abs(stocky / housner - 1.0) > 2e-3


def test_energy_is_conserved_between_and_through_elastic_impacts() -> None:
    block = HousnerBlock(p=2.0, alpha=0.4, eta=1.0)
    r = simulate_nonlinear(block, zeros(15.0), x0=0.7, rtol=1e-12, dense=True)
    assert r.ratio is not None
    peaks = excursion_peaks(r.ratio)
    assert len(peaks) >= 5
    # With eta = 1 every excursion turns at the release angle (same potential energy).
    np.testing.assert_allclose(peaks, 0.7, rtol=0, atol=1e-9)


@pytest.mark.parametrize("eta", [0.8, 0.5])
def test_each_impact_scales_kinetic_energy_by_eta_squared(eta: float) -> None:
    block = HousnerBlock(p=2.0, alpha=0.4, eta=eta)
    x0 = 0.7
    r = simulate_nonlinear(block, zeros(6.0), x0=x0, rtol=1e-12, dense=True)
    assert r.ratio is not None
    # Excursions well above the tolerance floor (atol 1e-12), before the Zeno tail.
    peaks = [x0, *(pk for pk in excursion_peaks(r.ratio) if pk > 1e-3)]
    assert len(peaks) >= 4
    a = block.alpha
    # Kinetic energy at impact = potential drop from the turning point: cos(a - phi_k) - cos a.
    ke = np.array([math.cos(a - a * pk) - math.cos(a) for pk in peaks])
    np.testing.assert_allclose(ke[1:] / ke[:-1], eta**2, rtol=1e-9)


# -- uplift ------------------------------------------------------------------------------------


def test_block_stays_at_rest_below_g_tan_alpha() -> None:
    block = HousnerBlock(p=2.0, alpha=0.6, eta=0.9)
    for sign in (1.0, -1.0):
        r = simulate_nonlinear(block, pulse(block, sign * 0.99, 2.0))
        assert r.peak_ratio == 0.0 and r.n_impacts == 0 and r.n_steps == 0


def test_block_moves_just_above_g_tan_alpha() -> None:
    block = HousnerBlock(p=2.0, alpha=0.6, eta=0.9)
    for sign in (1.0, -1.0):
        r = simulate_nonlinear(block, pulse(block, sign * 1.01, 2.0))
        assert r.peak_ratio > 1e-4


def test_uplift_between_g_alpha_and_g_tan_alpha_moves_only_the_linear_model() -> None:
    block = HousnerBlock(p=2.0, alpha=0.6, eta=0.9)
    a_p = -G * 0.5 * (block.alpha + math.tan(block.alpha))
    exc = Pulse(a_p=a_p, f_p=1.0)
    assert simulate_nonlinear(block, exc).peak_ratio == 0.0
    assert simulate_ivp(block.linearised(), exc).peak_ratio > 0.0


# -- linear vs nonlinear ----------------------------------------------------------------------


def test_slender_block_agrees_with_linearisation_and_stocky_one_does_not() -> None:
    slender = HousnerBlock(p=2.0, alpha=0.05, eta=0.9)
    stocky = HousnerBlock(p=2.0, alpha=0.6, eta=0.9)
    e_slender = linearisation_error(slender, pulse(slender, 1.5, 4.0))
    e_stocky = linearisation_error(stocky, pulse(stocky, 1.5, 4.0))
    for e in (e_slender, e_stocky):
        assert e["same_outcome"]
        assert not e["nonlinear"]["collapsed"]
        diff = abs(e["linear"]["peak_ratio"] - e["nonlinear"]["peak_ratio"])
        assert e["peak_ratio_error"] == pytest.approx(diff)
        assert e["relative_error"] == pytest.approx(diff / e["nonlinear"]["peak_ratio"])
    # Measured: 0.4 % for alpha = 0.05 and 74 % for alpha = 0.6.
    assert e_slender["relative_error"] < 0.02
    assert e_stocky["relative_error"] > 0.2
    assert e_stocky["relative_error"] > 10 * e_slender["relative_error"]
    assert e_slender["nonlinear"]["method"] == "nonlinear:DOP853"


def test_linearisation_error_passes_x0_to_both_models() -> None:
    block = HousnerBlock(p=2.0, alpha=0.3, eta=0.9)
    e = linearisation_error(block, zeros(0.5), x0=0.5)
    # Released from rest, both peak at the release angle.
    assert e["linear"]["peak_ratio"] == pytest.approx(0.5)
    assert e["nonlinear"]["peak_ratio"] == pytest.approx(0.5)
    assert e["relative_error"] < 1e-9


@pytest.mark.parametrize("amp", [0.5, 0.6, 0.75, 1.0])
def test_free_motion_after_record_matches_integrating_through_zeros(amp: float) -> None:
    # The energy decision after the excitation must agree with plain integration.
    block = HousnerBlock(p=2.0, alpha=0.2, eta=0.9)
    shape = amp * G * np.array([0.0, -1.0, 1.0, 0.0])
    short = simulate_nonlinear(block, SampledAccel(shape, 0.25), criterion="exact")
    long_ = simulate_nonlinear(
        block, SampledAccel(np.concatenate([shape, np.zeros(400)]), 0.25), criterion="exact"
    )
    assert short.collapsed is long_.collapsed
    assert short.peak_ratio == pytest.approx(long_.peak_ratio, abs=1e-8)
    assert short.t_peak == pytest.approx(long_.t_peak, abs=1e-8)
    if long_.collapsed:
        assert short.t_collapse == pytest.approx(long_.t_collapse, abs=1e-8)


def test_strong_pulse_overturns_block() -> None:
    block = HousnerBlock(p=2.0, alpha=0.2, eta=0.9)
    r = simulate_nonlinear(block, pulse(block, 3.0, 2.0))
    assert r.collapsed and r.overturned and r.status == 1
    assert r.peak_ratio == 1.0
    assert r.t_collapse is not None and r.t_ratio_exceeded is not None
    assert r.t_ratio_exceeded <= r.t_collapse


@pytest.mark.parametrize(("amp", "omega_ratio"), [(1.2, 1.0), (1.5, 3.0)])
def test_response_is_antisymmetric(amp: float, omega_ratio: float) -> None:
    block = HousnerBlock(p=2.0, alpha=0.3, eta=0.85)
    a = simulate_nonlinear(block, pulse(block, amp, omega_ratio), dense=True)
    b = simulate_nonlinear(block, pulse(block, -amp, omega_ratio), dense=True)
    assert a.ratio is not None and b.ratio is not None
    assert a.n_impacts == b.n_impacts >= 1
    assert a.peak_ratio == pytest.approx(b.peak_ratio, rel=1e-12)
    np.testing.assert_allclose(a.ratio, -b.ratio, rtol=0, atol=1e-12)


def test_one_sided_block_rebounds_and_never_goes_negative() -> None:
    block = HousnerBlock(p=2.0, alpha=0.3, eta=-0.5, one_sided=True)
    r = simulate_nonlinear(block, pulse(block, -1.1, 1.0), dense=True)
    assert r.ratio is not None
    assert r.n_impacts >= 1
    assert r.ratio.min() >= 0.0 < r.peak_ratio


def test_elcentro_nonlinear_peak_converges_with_tolerance() -> None:
    data = np.loadtxt(ELCENTRO)
    rec = SampledAccel(data[:, 1] * G, 0.02, float(data[0, 0]))
    block = HousnerBlock.rectangular(0.4, 2.0)
    loose = simulate_nonlinear(block, rec, rtol=1e-10)
    tight = simulate_nonlinear(block, rec, rtol=1e-12)
    assert tight.n_impacts > 100 and loose.n_impacts == tight.n_impacts
    assert abs(loose.peak_ratio - tight.peak_ratio) < 1e-7


# -- the block object ------------------------------------------------------------------------


def test_rectangular_block_constants() -> None:
    block = HousnerBlock.rectangular(0.5, 2.0)
    r = 0.5 * math.hypot(0.5, 2.0)
    assert block.alpha == pytest.approx(math.atan(0.25))
    assert block.p == pytest.approx(math.sqrt(3 * G / (4 * r)))
    assert block.eta == pytest.approx(1 - 1.5 * math.sin(math.atan(0.25)) ** 2)
    assert HousnerBlock.rectangular(0.5, 2.0, eta=0.7).eta == 0.7
    model = block.linearised()
    assert model.positive.p_eq == block.p
    assert model.positive.lam == model.positive.phi_ov == block.alpha
    assert model.eta == block.eta and model.is_symmetric


@pytest.mark.parametrize(
    ("kw", "field"),
    [
        ({"p": 0.0, "alpha": 0.2, "eta": 0.9}, "p"),
        ({"p": 2.0, "alpha": 0.0, "eta": 0.9}, "alpha"),
        ({"p": 2.0, "alpha": math.pi / 2, "eta": 0.9}, "alpha"),
        ({"p": 2.0, "alpha": 0.2, "eta": 1.1}, "eta"),
        ({"p": 2.0, "alpha": 0.2, "eta": -0.5}, "eta"),
        ({"p": 2.0, "alpha": 0.2, "eta": 0.5, "one_sided": True}, "eta"),
    ],
)
def test_bad_block_raises_input_error_naming_field(kw: dict[str, object], field: str) -> None:
    with pytest.raises(InputError) as info:
        HousnerBlock(**kw)  # type: ignore[arg-type]
    assert info.value.field == field


def test_bad_rectangle_and_arguments_are_rejected() -> None:
    with pytest.raises(InputError) as info:
        HousnerBlock.rectangular(-1.0, 2.0)
    assert info.value.field == "b"
    block = HousnerBlock(p=2.0, alpha=0.2, eta=0.9)
    for kw, field in (({"rtol": 0.0}, "rtol"), ({"method": "X"}, "method"), ({"x0": -1.5}, "x0")):
        with pytest.raises(InputError) as info:
            simulate_nonlinear(block, zeros(1.0), **kw)  # type: ignore[arg-type]
        assert info.value.field == field


# -- impact log and error estimate (issue 7) ----------------------------------------------------


def test_impact_log_scales_angular_velocity_by_eta_and_alternates_sides() -> None:
    block = HousnerBlock(p=3.0, alpha=0.3, eta=0.8)
    r = simulate_nonlinear(block, zeros(6.0), x0=0.9)
    assert r.impacts is not None and r.impacts.shape[1] == r.n_impacts >= 5
    t, side, v_in, v_out = r.impacts
    moving = v_out != 0.0
    np.testing.assert_allclose(v_out[moving], 0.8 * v_in[moving], rtol=1e-15)
    assert np.all(side[1:] == -side[:-1])
    assert np.all(np.diff(t) > 0.0)
    # Free motion conserves energy between impacts: |v| arriving = |v| leaving the previous
    # (to the integrator's tolerances, atol = 1e-12 on x and its rate).
    np.testing.assert_allclose(np.abs(v_in[1:]), np.abs(v_out[:-1]), rtol=1e-8, atol=1e-12)
    # The first impact happens at the closed-form quarter period.
    assert t[0] == pytest.approx(quarter_period(block, 0.9 * block.alpha), rel=1e-9)


def test_error_estimate_grows_with_the_number_of_events() -> None:
    block = HousnerBlock(p=3.0, alpha=0.3, eta=0.8)
    r = simulate_nonlinear(block, zeros(6.0), x0=0.9, rtol=1e-8, atol=1e-10)
    n_events = r.n_impacts + r.n_uplifts
    assert r.error_estimate == pytest.approx(
        10.0 * max(1e-8 * r.peak_ratio, 1e-10) * math.sqrt(1 + n_events)
    )
