"""Lognormal fragility fits: exact data, a brute-force likelihood grid, and edge cases."""

from __future__ import annotations

import doctest
import math

import numpy as np
import pytest

from shared_schema.errors import InputError
from solver_service.core import fragility
from solver_service.core.fragility import BETA_BOUNDS, fit_lognormal, lognormal_cdf


def test_doctests() -> None:
    assert doctest.testmod(fragility).failed == 0


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
