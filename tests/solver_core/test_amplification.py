"""Verification of the pulse response spectrum and the Eq. 28 scale factor (theory §7)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from shared_schema.errors import InputError
from solver_service.core import amplification
from solver_service.core.amplification import (
    effective_height,
    pulse_response_spectrum,
    pulse_scale_factor,
    scale_factor,
    sdof_pulse_peak,
)

# theory §7.1 table, zeta = 0.05, one-cycle sine pulse (computed by another author).
TABLE_RATIOS = [0.1, 0.2, 0.3, 0.5, 0.7, 0.8, 0.9, 1.0, 1.2, 1.5, 2.0, 3.0, 5.0]
TABLE_PSEUDO = [1.04, 1.04, 1.35, 1.62, 2.58, 2.77, 2.79, 2.70, 2.34, 1.79, 1.15, 0.56, 0.21]
TABLE_RELATIVE = [0.09, 0.20, 0.36, 0.79, 1.99, 2.32, 2.54, 2.69, 2.35, 1.82, 1.73, 1.47, 1.21]
TABLE_TOL = 0.006  # the table prints 2 decimals

PHASES = {"sine": 0.0, "cosine": 0.5 * math.pi}


def reference_peaks(
    f_n: float, f_p: float, a_p: float, zeta: float, shape: str
) -> dict[str, float]:
    """Peak ``omega_n² |u|`` and ``|ü|`` [m/s²] by DOP853 on the pulse and after it.

    The pulse and the free vibration are integrated as two segments (the cosine pulse
    jumps at both ends). Every local maximum of the sampled peak quantity is refined
    on the dense output.
    """
    wn = 2 * math.pi * f_n
    wp = 2 * math.pi * f_p
    phase = PHASES[shape]
    t_end = 1.0 / f_p

    peaks = {"pseudo": 0.0, "relative": 0.0}
    y0 = np.zeros(2)
    for inside, (t0, t1) in ((True, (0.0, t_end)), (False, (t_end, t_end + 12.0 / f_n))):

        def rhs(t: float, y: np.ndarray, inside: bool = inside) -> list[float]:
            drive = a_p * math.sin(wp * t + phase) if inside else 0.0
            return [y[1], -drive - 2 * zeta * wn * y[1] - wn**2 * y[0]]

        sol = solve_ivp(
            rhs, (t0, t1), y0, method="DOP853", rtol=1e-11, atol=1e-13, dense_output=True
        )
        assert sol.success

        def pseudo(t: NDArray[np.float64], sol: Any = sol) -> NDArray[np.float64]:
            return np.asarray(np.abs(wn**2 * np.asarray(sol.sol(t))[0]), dtype=np.float64)

        def relative(
            t: NDArray[np.float64], sol: Any = sol, inside: bool = inside
        ) -> NDArray[np.float64]:
            u, v = np.asarray(sol.sol(t))
            drive = a_p * np.sin(wp * t + phase) if inside else 0.0
            return np.asarray(np.abs(-drive - 2 * zeta * wn * v - wn**2 * u), dtype=np.float64)

        n = int(400 * max((t1 - t0) * max(f_n, f_p), 1.0)) + 1
        grid = np.linspace(t0, t1, n)
        for name, q in (("pseudo", pseudo), ("relative", relative)):
            vals = q(grid)
            top = float(vals.max())
            padded = np.concatenate(([-1.0], vals, [-1.0]))
            local = (vals >= padded[:-2]) & (vals >= padded[2:]) & (vals > 0.99 * top)
            for i in np.flatnonzero(local).tolist():
                lo, hi = float(grid[max(i - 1, 0)]), float(grid[min(i + 1, n - 1)])
                res = minimize_scalar(
                    lambda t, q=q: -float(q(np.array([t]))[0]),
                    bounds=(lo, hi),
                    method="bounded",
                    options={"xatol": 1e-12 * (t1 - t0)},
                )
                top = max(top, -float(res.fun))
            peaks[name] = max(peaks[name], top)
        y0 = sol.y[:, -1]
    return peaks


# --- theory §7.1 table ----------------------------------------------------------------------


@pytest.mark.parametrize(("ratio", "expected"), list(zip(TABLE_RATIOS, TABLE_PSEUDO)))
def test_pseudo_spectrum_matches_theory_table(ratio: float, expected: float) -> None:
    got = pulse_response_spectrum(ratio, zeta=0.05, quantity="pseudo", shape="sine")
    assert float(got) == pytest.approx(expected, abs=TABLE_TOL)


@pytest.mark.parametrize(("ratio", "expected"), list(zip(TABLE_RATIOS, TABLE_RELATIVE)))
def test_relative_spectrum_matches_theory_table(ratio: float, expected: float) -> None:
    got = pulse_response_spectrum(ratio, zeta=0.05, quantity="relative", shape="sine")
    assert float(got) == pytest.approx(expected, abs=TABLE_TOL)


def test_spectrum_is_vectorised_and_keeps_shape() -> None:
    ratios = np.array([[0.5, 1.0], [2.0, 3.0]])
    got = pulse_response_spectrum(ratios)
    assert got.shape == (2, 2)
    assert got[0, 1] == pytest.approx(float(pulse_response_spectrum(1.0)), rel=1e-15)


# --- independent cross-check: DOP853 --------------------------------------------------------


@pytest.mark.parametrize("shape", ["sine", "cosine"])
@pytest.mark.parametrize("ratio", [0.25, 0.7, 1.0, 1.3, 2.5, 4.0])
def test_closed_form_agrees_with_dop853(ratio: float, shape: str) -> None:
    f_n, a_p = 2.0, 3.0
    ref = reference_peaks(f_n, ratio * f_n, a_p, 0.05, shape)
    for quantity in ("pseudo", "relative"):
        got = sdof_pulse_peak(f_n, ratio * f_n, a_p, zeta=0.05, quantity=quantity, shape=shape)
        assert got == pytest.approx(ref[quantity], rel=1e-6), quantity


@pytest.mark.parametrize("ratio", [0.6, 1.0])
def test_undamped_closed_form_agrees_with_dop853(ratio: float) -> None:
    ref = reference_peaks(1.0, ratio, 1.0, 0.0, "sine")
    for quantity in ("pseudo", "relative"):
        got = float(pulse_response_spectrum(ratio, zeta=0.0, quantity=quantity))
        assert got == pytest.approx(ref[quantity], rel=1e-6), quantity


# --- limits ----------------------------------------------------------------------------------


def test_undamped_resonance_is_finite_and_exact() -> None:
    # zeta = 0, r = 1: w = tau cos(tau)/2 - sin(tau)/2, so |w| reaches pi at the pulse end
    # with zero velocity and keeps that amplitude.
    assert float(pulse_response_spectrum(1.0, zeta=0.0)) == pytest.approx(math.pi, rel=1e-12)


def test_undamped_response_is_continuous_through_resonance() -> None:
    near = pulse_response_spectrum([1.0 - 1e-7, 1.0 + 1e-7], zeta=0.0)
    np.testing.assert_allclose(near, math.pi, rtol=1e-6)


def test_long_pulse_is_quasi_static() -> None:
    # r -> 0: u follows -a_g/omega_n², so the pseudo-acceleration tends to a_p, and the
    # relative acceleration to ~r a_p (the free vibration set off by the initial jerk).
    assert float(pulse_response_spectrum(0.01)) == pytest.approx(1.0, abs=1e-3)
    assert float(pulse_response_spectrum(0.01, quantity="relative")) < 0.011


@pytest.mark.parametrize(("ratio", "zeta"), [(2e-4, 0.05), (5e-3, 0.99)])
def test_a_pulse_long_enough_to_overflow_exp_is_still_exact(ratio: float, zeta: float) -> None:
    # zeta tau reaches 1571 and 1244 in the pulse: e**x overflowed past 709.78 (issue #19,
    # an OverflowError, a 500 from the service's exact envelopes for f_n = 500 Hz).
    ref = reference_peaks(1.0, ratio, 1.0, zeta, "sine")
    for quantity in ("pseudo", "relative"):
        got = float(pulse_response_spectrum(ratio, zeta=zeta, quantity=quantity))
        assert got == pytest.approx(ref[quantity], rel=1e-6), quantity
    assert float(pulse_response_spectrum(ratio, zeta=zeta)) == pytest.approx(1.0, abs=2 * ratio)


def test_a_ratio_below_the_closed_forms_range_is_refused_naming_it() -> None:
    with pytest.raises(InputError, match=r"must be >= 0\.0001") as err:
        pulse_response_spectrum([1.0, 5e-5])
    assert err.value.field == "ratio"
    with pytest.raises(InputError, match="raise f_min, or use the library") as err:
        pulse_scale_factor([0.01, 1.0], f_n=1000.0, h=3.0, h_e=2.0)
    assert err.value.field == "f_p"
    assert float(pulse_response_spectrum(amplification.RATIO_MIN)) == pytest.approx(1.0, abs=1e-6)


def test_short_pulse_response_vanishes_like_two_pi_over_r_squared() -> None:
    # r -> inf: the pulse has zero net impulse and leaves u = 2 pi a_p/(omega_n² r²) at rest.
    r = 1e3
    assert float(pulse_response_spectrum(r)) * r**2 == pytest.approx(2 * math.pi, rel=1e-2)
    assert float(pulse_response_spectrum(1e4)) < 1e-7


def test_peak_scales_with_amplitude_magnitude() -> None:
    base = sdof_pulse_peak(1.5, 1.2, 1.0)
    assert sdof_pulse_peak(1.5, 1.2, -2.5) == pytest.approx(2.5 * base, rel=1e-14)
    assert base == pytest.approx(float(pulse_response_spectrum(0.8)), rel=1e-14)


# --- Eq. 28 and the effective height ---------------------------------------------------------


def test_basantapur_scale_factor() -> None:
    assert scale_factor(0.19, 0.155, 4.60, 4.54) == pytest.approx(1.595, abs=5e-4)
    assert scale_factor(0.19, 0.158, 4.60, 4.54) == pytest.approx(1.576, abs=5e-4)


def test_scale_factor_is_one_at_the_base() -> None:
    assert scale_factor(0.5, 0.2, 0.0, 3.0) == 1.0
    np.testing.assert_array_equal(
        pulse_scale_factor([0.5, 2.0, 7.0], f_n=2.0, h=0.0, h_e=3.0), [1.0, 1.0, 1.0]
    )


def test_pulse_scale_factor_combines_spectrum_by_srss() -> None:
    f_p = np.array([1.0, 2.0, 4.0])
    got = pulse_scale_factor(f_p, f_n=2.0, h=3.0, h_e=2.0, quantity="relative")
    spec = pulse_response_spectrum(f_p / 2.0, quantity="relative")
    np.testing.assert_allclose(got, np.sqrt(1.0 + (1.5 * spec) ** 2), rtol=1e-14)


def test_effective_height_of_uniform_cantilever_and_tip_mass() -> None:
    n = 2000
    z = (np.arange(n) + 0.5) / n * 6.0
    assert effective_height(np.ones(n), z) == pytest.approx(4.0, rel=1e-6)
    assert effective_height([1e-9, 1.0], [2.0, 4.6]) == pytest.approx(4.6, rel=1e-9)


# --- validation ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"f_n": 0.0}, "f_n"),
        ({"f_n": -1.0}, "f_n"),
        ({"f_n": math.nan}, "f_n"),
        ({"h_e": 0.0}, "h_e"),
        ({"h_e": math.inf}, "h_e"),
        ({"h": -0.1}, "h"),
        ({"h": math.nan}, "h"),
        ({"zeta": 1.0}, "zeta"),
        ({"zeta": -0.01}, "zeta"),
        ({"zeta": math.nan}, "zeta"),
        ({"quantity": "absolute"}, "quantity"),
        ({"shape": "square"}, "shape"),
        ({"f_p": [1.0, math.inf]}, "f_p"),
        ({"f_p": 0.0}, "f_p"),
    ],
)
def test_pulse_scale_factor_rejects_bad_input(kwargs: dict[str, object], field: str) -> None:
    args: dict[str, object] = {"f_p": [1.0, 2.0], "f_n": 2.0, "h": 3.0, "h_e": 2.0}
    args.update(kwargs)
    f_p = args.pop("f_p")
    with pytest.raises(InputError) as err:
        pulse_scale_factor(f_p, **args)  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize(
    ("args", "field"),
    [
        ((0.19, 0.0, 4.6, 4.54), "pga_g"),
        ((0.19, math.nan, 4.6, 4.54), "pga_g"),
        ((-0.1, 0.155, 4.6, 4.54), "sa_g"),
        ((math.inf, 0.155, 4.6, 4.54), "sa_g"),
        ((0.19, 0.155, -4.6, 4.54), "h"),
        ((0.19, 0.155, 4.6, 0.0), "h_e"),
    ],
)
def test_scale_factor_rejects_bad_input(args: tuple[float, ...], field: str) -> None:
    with pytest.raises(InputError) as err:
        scale_factor(*args)
    assert err.value.field == field


def test_spectrum_and_peak_reject_bad_input() -> None:
    for bad in (0.0, -1.0, math.nan, [1.0, math.inf]):
        with pytest.raises(InputError) as err:
            pulse_response_spectrum(bad)
        assert err.value.field == "ratio"
    with pytest.raises(InputError) as err:
        sdof_pulse_peak(2.0, 1.0, math.nan)
    assert err.value.field == "a_p"
    with pytest.raises(InputError) as err:
        sdof_pulse_peak(2.0, -1.0, 1.0)
    assert err.value.field == "f_p"


@pytest.mark.parametrize(
    ("masses", "heights", "field"),
    [
        ([1.0, 2.0], [1.0], "heights"),
        ([1.0, -2.0], [1.0, 2.0], "masses"),
        ([1.0, 2.0], [1.0, math.nan], "heights"),
        ([0.0, 0.0], [1.0, 2.0], "masses"),
        ([], [], "masses"),
    ],
)
def test_effective_height_rejects_bad_input(
    masses: list[float], heights: list[float], field: str
) -> None:
    with pytest.raises(InputError) as err:
        effective_height(masses, heights)
    assert err.value.field == field
