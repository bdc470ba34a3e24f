"""Verification of the exact (Nigam–Jennings) response spectrum (spectra.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from shared_schema.errors import InputError
from solver_service.core import spectra
from solver_service.core.excitation import SampledAccel
from solver_service.core.model import G
from solver_service.core.records import GroundMotion
from solver_service.core.spectra import _recurrence, response_spectrum

BACKENDS = [
    "numpy",
    pytest.param(
        "numba",
        marks=pytest.mark.skipif(not spectra._numba_available(), reason="numba not installed"),
    ),
]


def _short_record() -> tuple[NDArray[np.float64], float]:
    """A 2 s broadband record (m/s²), rough enough to excite every period below."""
    rng = np.random.default_rng(7)
    return 3.0 * rng.standard_normal(101), 0.02


def _reference_psa(acc: NDArray[np.float64], dt: float, T_n: float, zeta: float) -> float:
    """DOP853 on each sample interval (the forcing is smooth there), peaks at v = 0 events."""
    w = 2.0 * np.pi / T_n
    y = np.zeros(2)
    best = 0.0

    def vel(_t: float, s: NDArray[np.float64]) -> float:
        return float(s[1])

    for i in range(acc.size - 1):
        a0, slope = acc[i], (acc[i + 1] - acc[i]) / dt

        def rhs(
            t: float, s: NDArray[np.float64], a0: float = a0, slope: float = slope
        ) -> list[float]:
            return [s[1], -(a0 + slope * t) - 2 * zeta * w * s[1] - w * w * s[0]]

        sol = solve_ivp(rhs, (0.0, dt), y, method="DOP853", rtol=1e-12, atol=1e-16, events=vel)
        for ys in [sol.y[:, -1], *sol.y_events[0]]:
            best = max(best, abs(ys[0]))
        y = sol.y[:, -1]

    def free(_t: float, s: NDArray[np.float64]) -> list[float]:
        return [s[1], -2 * zeta * w * s[1] - w * w * s[0]]

    sol = solve_ivp(free, (0.0, 3 * T_n), y, method="DOP853", rtol=1e-12, atol=1e-16, events=vel)
    for ys in sol.y_events[0]:
        best = max(best, abs(ys[0]))
    return best * w * w


@pytest.mark.parametrize("backend", BACKENDS)
def test_spectrum_matches_dop853_on_a_linear_interpolated_record(backend: str) -> None:
    acc, dt = _short_record()
    periods = [0.05, 0.4, 3.0]
    spec = response_spectrum(acc, dt, periods, 0.05, backend=backend)
    ref = [_reference_psa(acc, dt, T, 0.05) for T in periods]
    np.testing.assert_allclose(spec.psa, ref, rtol=1e-6)
    np.testing.assert_allclose(spec.sd * (2 * np.pi / spec.periods) ** 2, spec.psa, rtol=1e-14)


def test_backends_agree() -> None:
    if not spectra._numba_available():
        pytest.skip("numba not installed")
    acc, dt = _short_record()
    periods = np.logspace(-2, 1, 25)
    a = response_spectrum(acc, dt, periods, 0.02, backend="numpy").psa
    b = response_spectrum(acc, dt, periods, 0.02, backend="numba").psa
    np.testing.assert_allclose(a, b, rtol=1e-9)


def test_recurrence_equals_the_closed_form_nigam_jennings_matrices() -> None:
    # Nigam & Jennings (1969), u-v form, at omega dt = 0.9 where the closed form is accurate.
    zeta, w, dt = 0.05, 2 * np.pi / 0.7, 0.1
    wd = w * np.sqrt(1 - zeta**2)
    e, s, c = np.exp(-zeta * w * dt), np.sin(wd * dt), np.cos(wd * dt)
    r = zeta / np.sqrt(1 - zeta**2)
    k1, k2 = (2 * zeta**2 - 1) / (w * w * dt), 2 * zeta / (w**3 * dt)
    a11, a12 = e * (r * s + c), e * s / wd
    a21, a22 = -w / np.sqrt(1 - zeta**2) * e * s, e * (c - r * s)
    b11 = e * ((k1 + zeta / w) * s / wd + (k2 + 1 / w**2) * c) - k2
    b12 = -e * (k1 * s / wd + k2 * c) - 1 / w**2 + k2
    b21 = e * ((k1 + zeta / w) * (c - r * s) - (k2 + 1 / w**2) * (wd * s + zeta * w * c)) + 1 / (
        w * w * dt
    )
    b22 = -e * (k1 * (c - r * s) - k2 * (wd * s + zeta * w * c)) - 1 / (w * w * dt)
    # Scaled state (x, x') = (w² u, w u̇).
    expected = [a11, a12 * w, a21 / w, a22, b11 * w * w, b21 * w, b12 * w * w, b22 * w]
    np.testing.assert_allclose(_recurrence(np.array([w * dt]), zeta)[0], expected, rtol=1e-12)


def test_elcentro_spectrum_matches_pyrotd(elcentro_path: Path) -> None:
    pyrotd = pytest.importorskip("pyrotd")
    gm = GroundMotion.from_two_column(elcentro_path)
    acc, dt = np.asarray(gm.accel.acc), gm.dt
    periods = np.logspace(-2, 1, 60)
    spec = response_spectrum(acc, dt, periods, 0.05)
    # pyrotd works in the frequency domain (circular): pad with 120 s of zeros so the free
    # vibration does not wrap round onto the record.
    padded = np.concatenate([acc, np.zeros(int(120 / dt))])
    ref = pyrotd.calc_spec_accels(dt, padded / G, 1 / periods, 0.05).spec_accel
    rel = np.abs(spec.psa_g / ref - 1)
    long = periods >= 0.3
    print(
        f"worst vs pyrotd: {100 * rel[long].max():.2f} % (T >= 0.3 s), "
        f"{100 * rel[~long].max():.1f} % (T < 0.3 s, not asserted)"
    )
    # Published comparisons of spectrum programs agree within about 1 % for T >= 0.3 s.
    assert rel[long].max() < 0.01


def test_very_short_period_gives_the_pga(elcentro_path: Path) -> None:
    gm = GroundMotion.from_two_column(elcentro_path)
    spec = response_spectrum(gm.accel.acc, gm.dt, [1e-3], 0.05)
    assert spec.psa[0] == pytest.approx(gm.pga, rel=1e-3)
    assert spec.psa_g[0] == pytest.approx(gm.pga_g, rel=1e-3)


def test_late_peak_in_free_vibration_is_not_missed() -> None:
    # A short kick, then rest: a 5 s oscillator peaks long after the record ends.
    acc = np.array([0.0, 1.0, 0.0])
    spec = response_spectrum(acc, 0.01, [5.0], 0.05)
    assert spec.psa[0] == pytest.approx(_reference_psa(acc, 0.01, 5.0, 0.05), rel=1e-6)


def test_sa_at_is_computed_exactly_off_the_grid() -> None:
    acc, dt = _short_record()
    spec = response_spectrum(acc, dt, [0.2, 0.4])
    assert spec.sa_at(0.4) == pytest.approx(spec.psa[1], rel=1e-12)
    assert spec.sa_at(0.3) == pytest.approx(response_spectrum(acc, dt, [0.3]).psa[0], rel=1e-12)
    assert spec.psv[0] == pytest.approx(spec.sd[0] * 2 * np.pi / 0.2)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"periods": [0.5, 0.0]}, "periods"),
        ({"periods": [-1.0]}, "periods"),
        ({"periods": []}, "periods"),
        ({"zeta": 1.0}, "zeta"),
        ({"zeta": -0.1}, "zeta"),
        ({"dt": 0.0}, "dt"),
        ({"dt": float("nan")}, "dt"),
        ({"acc": [0.0, float("inf"), 1.0]}, "acc"),
        ({"acc": [1.0]}, "acc"),
        ({"backend": "fortran"}, "backend"),
    ],
)
def test_invalid_inputs_name_the_field(kwargs: dict[str, object], field: str) -> None:
    args: dict[str, object] = {"acc": [0.0, 1.0, 0.0], "dt": 0.01, "periods": [0.5]}
    args.update(kwargs)
    with pytest.raises(InputError) as info:
        response_spectrum(**args)  # type: ignore[arg-type]
    assert info.value.field == field
    if field == "periods" and kwargs["periods"]:
        assert "T_n must be > 0" in str(info.value)


def test_a_non_finite_sample_is_named_alike_everywhere() -> None:
    # One check (excitation.check_finite_samples) for records, spectra and SampledAccel:
    # plain numbers in the message, the first bad sample and the count.
    acc = [0.0, 1.0, float("inf"), float("nan")]
    with pytest.raises(InputError) as spec_err:
        response_spectrum(acc, 0.01, [0.5])
    with pytest.raises(InputError) as rec_err:
        SampledAccel(np.array(acc), 0.01)
    for err, field in ((spec_err, "acc"), (rec_err, "record")):
        assert err.value.field == field
        assert "sample 2 is not finite (inf); 2 non-finite sample(s) in all" in str(err.value)
        assert "np.float64" not in str(err.value)
