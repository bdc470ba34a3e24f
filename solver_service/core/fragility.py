"""Lognormal fragility curves from incremental dynamic analysis (multiple-stripe data).

At each intensity level ``x_j`` (a scale factor, or a PGA in g) ``z_j`` of ``n_j`` records
overturn a mechanism. The fragility ``P(overturn | x) = Phi(ln(x/theta)/beta)`` is fitted by
maximum likelihood on the binomial counts (Baker 2015, "Efficient analytical fragility
function fitting using dynamic structural analysis", Earthquake Spectra 31(1)):

    max over (theta, beta) of  sum_j [ z_j ln Phi(u_j) + (n_j - z_j) ln(1 - Phi(u_j)) ],
    u_j = ln(x_j/theta)/beta.

The log-probabilities are evaluated with ``scipy.special.log_ndtr``, so the tails stay
finite. Written as ``u_j = a + b ln x_j`` (``b = 1/beta``, ``a = -ln(theta)/beta``) this is a
probit regression, whose log-likelihood is concave in ``(a, b)``: Newton's method finds its
one maximum to rounding in about ten steps. Where the data have no maximum inside the bounds
of ``(theta, beta)`` (a step from none to all overturning, fractions that fall as the level
rises, a median far outside the levels), a bounded Nelder-Mead search gives the best values
within the bounds (the fit's ``note`` says where they lie on one); docs/theory.md §10.8.
``theta`` is the median (the intensity that overturns half the records) and ``beta`` the
logarithmic standard deviation [-].
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np
from numpy.typing import ArrayLike

from shared_schema.errors import InputError

__all__ = ["BETA_BOUNDS", "FragilityFit", "fit_lognormal", "lognormal_cdf"]

#: Search bounds of beta [-]: below 0.01 the curve is a step, above 5 it is flat.
BETA_BOUNDS = (0.01, 5.0)
#: Beta [-] Newton's method starts from (with the median at the first level where half the
#: records overturn).
BETA_START = 0.4
#: Newton iterations allowed before the bounded search takes over (it converges
#: quadratically: about ten are used).
NEWTON_ITERATIONS = 100


@dataclass(frozen=True)
class FragilityFit:
    """A fitted lognormal fragility curve, or why none could be fitted.

    Attributes
    ----------
    median : float or None
        ``theta``, the intensity at which half the records overturn (units of the levels).
    beta : float or None
        Logarithmic standard deviation [-].
    log_likelihood : float or None
        The maximised binomial log-likelihood.
    note : str
        How to read the fit (e.g. a sharp step that pins ``beta`` at its bound), or why
        there is no fit.
    """

    median: Optional[float]
    beta: Optional[float]
    log_likelihood: Optional[float]
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        """Return a JSON-ready dict (absent values omitted)."""
        doc: dict[str, Any] = {"method": "binomial maximum likelihood (Baker 2015)"}
        if self.median is not None:
            doc.update(median=self.median, beta=self.beta, log_likelihood=self.log_likelihood)
        if self.note:
            doc["note"] = self.note
        return doc


def lognormal_cdf(x: ArrayLike, median: float, beta: float) -> np.ndarray[Any, Any]:
    """Return ``Phi(ln(x/median)/beta)`` at intensities ``x`` (> 0)."""
    from scipy.special import ndtr

    return np.asarray(ndtr(np.log(np.asarray(x, dtype=float) / median) / beta))


def fit_lognormal(levels: ArrayLike, n_overturned: ArrayLike, n_records: ArrayLike) -> FragilityFit:
    """Fit a lognormal fragility curve to counts of overturning records per intensity level.

    Parameters
    ----------
    levels : (k,) array_like of float
        Intensity levels, each finite and > 0 (any units; the median has the same).
    n_overturned : (k,) array_like of int
        Records that overturned the mechanism at each level, ``0 <= z_j <= n_j``.
    n_records : (k,) array_like of int or int
        Records run at each level, >= 1.

    Returns
    -------
    FragilityFit
        ``median`` and ``beta`` are None, with a note, when no record overturns at any
        level or every record overturns at every level (the median then lies outside the
        levels run).

    Raises
    ------
    InputError
        Levels not finite and > 0 (field ``levels``), or counts out of range
        (``n_overturned``, ``n_records``).

    Examples
    --------
    >>> x = np.array([0.1, 0.2, 0.4, 0.8])
    >>> fit = fit_lognormal(x, (1000 * lognormal_cdf(x, 0.3, 0.5)).round(), 1000)
    >>> round(fit.median, 2), round(fit.beta, 2)
    (0.3, 0.5)
    """
    x = np.atleast_1d(np.asarray(levels, dtype=float))
    z = np.atleast_1d(np.asarray(n_overturned, dtype=float))
    n = np.broadcast_to(np.asarray(n_records, dtype=float), x.shape).copy()
    if x.ndim != 1 or x.size == 0 or not np.all(np.isfinite(x) & (x > 0)):
        raise InputError("must be a non-empty list of finite levels > 0", "levels")
    if z.shape != x.shape or np.any((z < 0) | (z > n)) or np.any(z != np.round(z)):
        raise InputError(
            "must be whole counts between 0 and n_records, one per level", "n_overturned"
        )
    if np.any(n < 1):
        raise InputError("must be >= 1 at every level", "n_records")
    if not np.any(z > 0):
        return FragilityFit(None, None, None, f"no record overturned it (median > {x.max():g})")
    if np.all(z == n):
        return FragilityFit(None, None, None, f"every record overturned it (median < {x.min():g})")
    lx = np.log(x)
    start, bounds = _start_and_bounds(lx, z, n)
    found = _probit_newton(lx, z, n, start)
    if found is not None and _inside(found, bounds):
        ln_theta, beta, loglik = found
    else:
        ln_theta, beta, loglik = _bounded_search(lx, z, n, start, bounds)
    note = ""
    if beta <= BETA_BOUNDS[0] * (1 + 1e-6):
        note = "the data step from none to all overturning: beta is not resolved by the levels"
    elif ln_theta <= bounds[0][0] + 1e-9 or ln_theta >= bounds[0][1] - 1e-9:
        note = "the median lies far outside the levels run: extrapolated"
    return FragilityFit(math.exp(ln_theta), beta, loglik, note)


def _start_and_bounds(
    lx: np.ndarray[Any, Any], z: np.ndarray[Any, Any], n: np.ndarray[Any, Any]
) -> tuple[float, list[tuple[float, float]]]:
    """Where both searches start (``ln theta`` [-]) and the bounds of ``(ln theta, beta)``.

    ``ln theta`` starts at the first level where half the records overturn (else the
    highest) and is bounded to twice the span of the levels (at least 1) beyond them.
    """
    above = np.flatnonzero(z / n >= 0.5)
    start = float(lx[above[0]] if above.size else lx.max())
    span = max(float(lx.max() - lx.min()), 1.0)
    return start, [(float(lx.min()) - 2 * span, float(lx.max()) + 2 * span), BETA_BOUNDS]


def _loglik(u: np.ndarray[Any, Any], z: np.ndarray[Any, Any], n: np.ndarray[Any, Any]) -> float:
    """Binomial log-likelihood of ``z`` of ``n`` at ``u = ln(x/theta)/beta``."""
    from scipy.special import log_ndtr

    return float(np.sum(z * log_ndtr(u) + (n - z) * log_ndtr(-u)))


def _probit_newton(
    lx: np.ndarray[Any, Any], z: np.ndarray[Any, Any], n: np.ndarray[Any, Any], start: float
) -> Optional[tuple[float, float, float]]:
    """Find the likelihood's maximum by Newton's method: ``(ln theta, beta, log-likelihood)``.

    Written as ``u = a + b ln x`` (``b = 1/beta``, ``a = -ln(theta)/beta``), the
    log-likelihood is a probit regression's: concave in ``(a, b)`` (``d2L/du2 < 0``
    everywhere), so Newton's method with a backtracking line search climbs to its one
    maximum, converging quadratically. None where it finds none: the data step from none to
    all overturning (``b`` grows without bound), fall as the level rises (``b <= 0``), or
    the iteration does not settle (then ``_bounded_search`` takes over).
    """
    from scipy.special import log_ndtr

    log_phi0 = -0.5 * math.log(2.0 * math.pi)
    a, b = -start / BETA_START, 1.0 / BETA_START
    current = _loglik(a + b * lx, z, n)
    for _ in range(NEWTON_ITERATIONS):
        u = a + b * lx
        log_phi = log_phi0 - 0.5 * u * u
        up = np.exp(log_phi - log_ndtr(u))  # phi(u)/Phi(u), finite in both tails
        down = np.exp(log_phi - log_ndtr(-u))  # phi(u)/Phi(-u)
        g = z * up - (n - z) * down  # dL/du
        w = z * up * (u + up) + (n - z) * down * (down - u)  # -d2L/du2 > 0
        grad = np.array([g.sum(), (g * lx).sum()])
        hess = np.array([[w.sum(), (w * lx).sum()], [(w * lx).sum(), (w * lx * lx).sum()]])
        try:
            step = np.linalg.solve(hess, grad)
        except np.linalg.LinAlgError:
            return None
        if not np.all(np.isfinite(step)):
            return None
        t = 1.0
        while True:
            trial = _loglik(a + t * step[0] + (b + t * step[1]) * lx, z, n)
            if trial >= current or t < 1e-12:
                break
            t *= 0.5
        if trial < current:  # no ascent left in Newton's direction: at the maximum
            break
        a, b, current = a + t * step[0], b + t * step[1], trial
        if abs(b) > 10.0 / BETA_BOUNDS[0]:  # towards a step: no maximum at a finite beta
            return None
        if abs(t * step[0]) <= 1e-13 * (1.0 + abs(a)) and abs(t * step[1]) <= 1e-13 * abs(b):
            break
    else:
        return None
    if b <= 0.0:  # the fraction falls as the level rises: no fragility curve inside
        return None
    return float(-a / b), float(1.0 / b), current


def _inside(found: tuple[float, float, float], bounds: list[tuple[float, float]]) -> bool:
    """Whether a maximum lies strictly inside the search bounds (so it is theirs too)."""
    (lo_t, hi_t), (lo_b, hi_b) = bounds
    ln_theta, beta, _ = found
    return lo_t < ln_theta < hi_t and lo_b * (1 + 1e-6) < beta < hi_b


def _bounded_search(
    lx: np.ndarray[Any, Any],
    z: np.ndarray[Any, Any],
    n: np.ndarray[Any, Any],
    start: float,
    bounds: list[tuple[float, float]],
) -> tuple[float, float, float]:
    """Find the best ``(ln theta, beta, log-likelihood)`` within ``bounds`` by Nelder-Mead.

    Started from three values of beta.

    For the data whose maximum lies on a bound (a step: beta at its lower bound) or outside
    them, where ``_probit_newton`` finds no interior one.
    """
    from scipy.optimize import minimize

    def nll(p: np.ndarray[Any, Any]) -> float:
        return -_loglik((lx - p[0]) / p[1], z, n)

    best = min(
        (
            minimize(
                nll,
                np.array([start, b0]),
                method="Nelder-Mead",
                bounds=bounds,
                options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 2000},
            )
            for b0 in (0.1, 0.4, 1.0)
        ),
        key=lambda r: float(r.fun),
    )
    ln_theta, beta = (float(v) for v in best.x)
    return ln_theta, beta, -float(best.fun)
