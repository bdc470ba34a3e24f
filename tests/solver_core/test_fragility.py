"""Lognormal fragility fits: exact data, a brute-force likelihood grid, and edge cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shared_schema.errors import InputError
from solver_service.core import fragility
from solver_service.core.fragility import BETA_BOUNDS, fit_lognormal, lognormal_cdf


@pytest.mark.parametrize(("median", "beta"), [(0.35, 0.3), (1.2, 0.6), (0.05, 1.1)])
def test_noise_free_fractions_give_back_the_curve(median: float, beta: float) -> None:
    x = median * np.geomspace(0.2, 5.0, 15)
    n = 10**7
    z = np.round(n * lognormal_cdf(x, median, beta))
    fit = fit_lognormal(x, z, n)
    assert fit.median == pytest.approx(median, rel=1e-3)
    assert fit.beta == pytest.approx(beta, rel=1e-3)
    assert fit.note == ""


def _phi(u: float) -> float:
    return 0.5 * (1.0 + math.erf(u / math.sqrt(2.0)))


def test_maximum_likelihood_beats_a_brute_force_grid() -> None:
    levels = [0.1, 0.2, 0.3, 0.5, 0.8, 1.2, 2.0]
    counts = [0, 1, 3, 2, 6, 9, 10]  # ten records, not monotone: real IDA data often is not
    fit = fit_lognormal(levels, counts, 10)

    def loglik(theta: float, beta: float) -> float:
        total = 0.0
        for x, z in zip(levels, counts):
            p = min(max(_phi(math.log(x / theta) / beta), 1e-300), 1 - 1e-16)
            total += z * math.log(p) + (10 - z) * math.log(1 - p)
        return total

    grid = [
        (loglik(t, b), t, b)
        for t in np.geomspace(0.2, 1.5, 161)
        for b in np.linspace(0.1, 1.5, 141)
    ]
    best, t_best, b_best = max(grid)
    assert fit.log_likelihood is not None and fit.median is not None and fit.beta is not None
    assert fit.log_likelihood >= best - 1e-9
    assert fit.log_likelihood == pytest.approx(loglik(fit.median, fit.beta), rel=1e-12)
    assert fit.median == pytest.approx(t_best, rel=0.02)
    assert fit.beta == pytest.approx(b_best, abs=0.02)


def test_cases_without_a_fit_or_with_a_step() -> None:
    none = fit_lognormal([0.1, 0.2], [0, 0], 5)
    assert none.median is None and "no record overturned it (median > 0.2)" in none.note
    assert "median" not in none.to_dict()
    every = fit_lognormal([0.1, 0.2], [5, 5], 5)
    assert every.median is None and "every record overturned it" in every.note
    step = fit_lognormal([0.1, 0.2, 0.4, 0.8], [0, 0, 5, 5], 5)
    assert step.beta == pytest.approx(BETA_BOUNDS[0])
    assert step.median is not None and 0.2 < step.median < 0.4
    assert "step" in step.note


def test_bad_input() -> None:
    with pytest.raises(InputError, match="levels"):
        fit_lognormal([0.1, -0.2], [0, 1], 2)
    with pytest.raises(InputError, match="n_overturned"):
        fit_lognormal([0.1, 0.2], [0, 3], 2)
    with pytest.raises(InputError, match="n_overturned"):
        fit_lognormal([0.1, 0.2], [0, 1.5], 2)
    with pytest.raises(InputError, match="n_records"):
        fit_lognormal([0.1, 0.2], [0, 0], 0)


def _reference(levels: np.ndarray, z: np.ndarray, n: int) -> tuple[float, float, float]:
    """The bounded Nelder-Mead search alone, from the starts ``fit_lognormal`` uses."""
    lx = np.log(levels)
    zf, nf = z.astype(float), np.full(z.shape, float(n))
    start, bounds = fragility._start_and_bounds(lx, zf, nf)
    return fragility._bounded_search(lx, zf, nf, start, bounds)


def test_newton_finds_the_maximum_the_bounded_search_finds_on_random_ida_data() -> None:
    # Binomial draws from lognormal curves: 5-50 levels, 5-3000 records, medians inside
    # and outside the levels, beta 0.05-2.
    rng = np.random.default_rng(20261127)
    newton = 0
    for _ in range(120):
        m, n = int(rng.integers(5, 50)), int(rng.integers(5, 3000))
        x = np.sort(rng.choice(np.geomspace(0.01, 10.0, 400), m, replace=False))
        theta = math.exp(rng.uniform(math.log(x[0]) - 0.5, math.log(x[-1]) + 0.5))
        z = rng.binomial(n, lognormal_cdf(x, theta, rng.uniform(0.05, 2.0)))
        fit = fit_lognormal(x, z, n)
        if fit.median is None:
            continue
        assert fit.beta is not None and fit.log_likelihood is not None
        ln_t, beta, loglik = _reference(x, z, n)
        # Never a worse likelihood than the search's, and the same curve where the search
        # found an interior maximum.
        assert fit.log_likelihood >= loglik - 1e-9 * abs(loglik)
        if fit.note == "" and BETA_BOUNDS[0] * 1.01 < beta < BETA_BOUNDS[1] * 0.99:
            newton += 1
            assert math.log(fit.median) == pytest.approx(ln_t, abs=1e-6)
            assert fit.beta == pytest.approx(beta, rel=1e-5)
    assert newton > 80  # most of these data have an interior maximum


def test_the_newton_fit_is_a_stationary_point_of_the_likelihood() -> None:
    levels = np.geomspace(0.05, 2.0, 40)
    counts = np.random.default_rng(7).binomial(500, lognormal_cdf(levels, 0.4, 0.45))
    fit = fit_lognormal(levels, counts, 500)
    assert fit.median is not None and fit.beta is not None and fit.log_likelihood is not None
    lx, z, n = np.log(levels), counts.astype(float), np.full(levels.shape, 500.0)

    def loglik(ln_theta: float, beta: float) -> float:
        return fragility._loglik((lx - ln_theta) / beta, z, n)

    ln_t, beta = math.log(fit.median), fit.beta
    assert loglik(ln_t, beta) == pytest.approx(fit.log_likelihood, rel=1e-14)
    h = 1e-5
    # Central differences: truncation ~ h^2 times the third derivative (~1e5 here), rounding
    # ~ 1e-16 |L| / h; both far below the bound.
    assert abs(loglik(ln_t + h, beta) - loglik(ln_t - h, beta)) / (2 * h) < 1e-4
    assert abs(loglik(ln_t, beta + h) - loglik(ln_t, beta - h)) / (2 * h) < 1e-4
    for step in (1e-3, 1e-5, 1e-7):
        for dt, db in ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, 1), (1, -1), (-1, -1)):
            assert loglik(ln_t + step * dt, beta + step * db) <= fit.log_likelihood
