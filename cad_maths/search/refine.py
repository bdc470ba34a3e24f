"""Deterministic bounded minimisation of λ0 over at most two continuous parameters.

A seeded grid (both bounds included) finds the basin; then, in one parameter, Brent's
method on the grid bracket and a root of the central-difference derivative (brentq) that
fixes the minimiser to about 1e-11 of the range (a minimum located from function values
alone is only known to about sqrt(eps)); in two, Nelder-Mead from the best grid point and
one-parameter polishes in turn. A minimum on a bound is reported exactly on it: the grid
holds the bounds, and a one-sided difference decides whether λ0 rises into the interior.

Everything is deterministic: no random seeds, no threads; the same input gives the same
numbers bit for bit.

Python 3.9-clean: imported by Rhino 8.
"""

import math
from dataclasses import dataclass, field
from typing import Callable, List, Sequence, Tuple

import numpy as np

__all__ = ["GRID_POINTS", "Minimum", "minimise"]

#: Seed-grid points per parameter (bounds included).
GRID_POINTS = 13
#: Step of the central differences of the derivative polish, relative to the range.
DIFF_STEP = 1e-5
#: Tolerance of the derivative root, relative to the range.
ROOT_XTOL = 1e-13
#: Relative difference of λ0 within which the derivative's root is preferred to Brent's point.
ROOT_FTOL = 1e-12
#: A parameter this close to a bound (relative to the range) is tried on the bound itself.
SNAP_RTOL = 1e-7
#: ... and put there when λ0 on the bound is at most this fraction above (rounding: λ0 of a
#: scene a kilometre from the origin is known to a few 1e-10).
SNAP_FTOL = 1e-9
#: Alternating one-parameter polishes after Nelder-Mead (two parameters).
POLISH_ROUNDS = 3

Objective = Callable[[Sequence[float]], float]


@dataclass
class Minimum:
    """Result of ``minimise``.

    Attributes
    ----------
    x : list of float
        The minimiser (one value per parameter, inside the bounds).
    value : float
        λ0 there (``inf`` when no admissible point was found).
    n_evaluations : int
        Objective evaluations (work counter).
    on_bound : list of bool
        Per parameter, whether the minimum lies on a bound.
    grid : list of (x, value)
        The seed grid's points and values (for plots and checks).
    """

    x: List[float]
    value: float
    n_evaluations: int
    on_bound: List[bool] = field(default_factory=list)
    grid: List[Tuple[List[float], float]] = field(default_factory=list)


class _Counted:
    def __init__(self, fun: Objective) -> None:
        self.fun = fun
        self.n = 0

    def __call__(self, x: Sequence[float]) -> float:
        self.n += 1
        v = float(self.fun(list(x)))
        return v if math.isfinite(v) else math.inf


def _line(
    f: Callable[[float], float], lo: float, hi: float, xs: np.ndarray, vals: np.ndarray
) -> Tuple[float, float, bool]:
    """Minimise a one-parameter function seeded by its values on ``xs`` (sorted, ends = bounds)."""
    from scipy.optimize import brentq, minimize_scalar  # scipy: loaded with the search only

    k = int(np.argmin(vals))
    best, fbest = float(xs[k]), float(vals[k])
    span = hi - lo
    if span <= 0.0 or not math.isfinite(fbest):
        return best, fbest, True
    h = DIFF_STEP * span
    if k in (0, len(xs) - 1):
        inward = h if k == 0 else -h
        if f(best + inward) >= fbest:
            return best, fbest, True  # rises into the interior: the bound is the minimum
        a, b = (xs[0], xs[1]) if k == 0 else (xs[-2], xs[-1])
    else:
        a, b = xs[k - 1], xs[k + 1]
    res = minimize_scalar(
        f, bounds=(float(a), float(b)), method="bounded", options={"xatol": 1e-12 * span}
    )
    x0 = float(res.x)
    fx0 = float(res.fun)
    if fx0 < fbest:
        best, fbest = x0, fx0

    def slope(x: float) -> float:
        return (f(x + h) - f(x - h)) / (2.0 * h)

    lo_b, hi_b = max(float(a), lo + h), min(float(b), hi - h)
    if lo_b < hi_b:
        try:
            s_lo, s_hi = slope(lo_b), slope(hi_b)
            if math.isfinite(s_lo) and math.isfinite(s_hi) and s_lo < 0.0 < s_hi:
                root = float(brentq(slope, lo_b, hi_b, xtol=ROOT_XTOL * span, rtol=1e-15))
                froot = f(root)
                # Near a smooth minimum λ0 is flat to rounding: the derivative's root is the
                # better estimate of the minimiser whenever its value is as low to rounding.
                if froot <= fbest + ROOT_FTOL * abs(fbest):
                    best, fbest = root, froot
        except ValueError:  # no sign change after all: keep Brent's point
            pass
    return best, fbest, False


def minimise(
    objective: Objective,
    bounds: Sequence[Tuple[float, float]],
    grid_points: int = GRID_POINTS,
) -> Minimum:
    """Minimise λ0 over 0, 1 or 2 bounded parameters, deterministically.

    Parameters
    ----------
    objective : callable
        ``objective([x1, ...]) -> λ0``; ``inf`` (or an exception-free non-finite value) marks
        an inadmissible point.
    bounds : sequence of (float, float)
        One ``(lo, hi)`` per parameter (``lo <= hi``); none for a fixed mechanism.
    grid_points : int
        Seed-grid points per parameter, >= 3.

    Returns
    -------
    Minimum

    Examples
    --------
    >>> m = minimise(lambda x: (x[0] - 0.3) ** 2 + 1.0, [(0.0, 1.0)])
    >>> round(m.x[0], 10), m.value
    (0.3, 1.0)
    >>> minimise(lambda x: 2.0 + x[0], [(0.5, 1.0)]).x
    [0.5]
    """
    f = _Counted(objective)
    n = max(int(grid_points), 3)
    if not bounds:
        return Minimum([], f([]), f.n)
    axes = [np.linspace(lo, hi, n) if hi > lo else np.array([lo]) for lo, hi in bounds]
    if len(bounds) == 1:
        vals = np.array([f([x]) for x in axes[0]])
        grid = [([float(x)], float(v)) for x, v in zip(axes[0], vals)]
        lo, hi = bounds[0]
        x1, v1, edge = _line(lambda t: f([t]), lo, hi, axes[0], vals)
        xs1, v1 = _snap(f, [x1], v1, bounds)
        return Minimum(xs1, v1, f.n, [edge or xs1[0] in (lo, hi)], grid)
    if len(bounds) != 2:
        raise ValueError("at most two continuous parameters")
    table = np.array([[f([a, b]) for b in axes[1]] for a in axes[0]])
    grid = [
        ([float(a), float(b)], float(table[i, j]))
        for i, a in enumerate(axes[0])
        for j, b in enumerate(axes[1])
    ]
    i, j = np.unravel_index(int(np.argmin(table)), table.shape)
    x = [float(axes[0][i]), float(axes[1][j])]
    v = float(table[i, j])
    if math.isfinite(v):
        x, v = _nelder_mead(
            f, x, v, bounds, [float(a[1] - a[0]) if a.size > 1 else 0.0 for a in axes]
        )
        for _ in range(POLISH_ROUNDS):
            before = list(x)
            for k in range(2):
                lo, hi = bounds[k]
                if hi <= lo:
                    continue

                def along(t: float, k: int = k) -> float:
                    y = list(x)
                    y[k] = t
                    return f(y)

                step = (hi - lo) / (n - 1)
                xs = np.unique(np.clip([x[k] - step, x[k], x[k] + step, lo, hi], lo, hi))
                xs = xs[(xs >= x[k] - step) & (xs <= x[k] + step)]
                vals = np.array([along(float(t)) for t in xs])
                t, vt, _ = _line(along, float(xs[0]), float(xs[-1]), xs, vals)
                if vt <= v:
                    x[k], v = t, vt
            if x == before:
                break
    x, v = _snap(f, x, v, bounds)
    on_bound = [x[k] in bounds[k] for k in range(2)]
    return Minimum(x, v, f.n, on_bound, grid)


def _snap(
    f: _Counted, x: List[float], v: float, bounds: Sequence[Tuple[float, float]]
) -> Tuple[List[float], float]:
    """Put a parameter that ends within ``SNAP_RTOL`` of a bound exactly on it, if no worse.

    No worse: λ0 on the bound at most ``SNAP_FTOL`` (relative) above. Nelder-Mead and the
    polishes approach a minimum on a bound from inside; λ0 there is flat to rounding, so the
    last ulps are decided by the value at the bound itself.
    """
    for k, (lo, hi) in enumerate(bounds):
        span = hi - lo
        for b in (lo, hi):
            if x[k] != b and abs(x[k] - b) <= SNAP_RTOL * max(span, abs(b), 1e-300):
                y = list(x)
                y[k] = b
                vy = f(y)
                if vy <= v + SNAP_FTOL * abs(v):
                    x, v = y, vy
    return x, v


def _nelder_mead(
    f: _Counted,
    x0: List[float],
    v0: float,
    bounds: Sequence[Tuple[float, float]],
    steps: Sequence[float],
) -> Tuple[List[float], float]:
    """Nelder-Mead from the best grid point, one grid step wide; bounds clip the points."""
    from scipy.optimize import minimize  # scipy: loaded with the search only

    simplex = [list(x0)]
    for k in range(2):
        y = list(x0)
        hi = bounds[k][1]
        y[k] = x0[k] + steps[k] if x0[k] + steps[k] <= hi else x0[k] - steps[k]
        simplex.append(y)
    res = minimize(
        lambda y: f(list(y)),
        np.array(x0),
        method="Nelder-Mead",
        bounds=list(bounds),
        options={
            "initial_simplex": np.array(simplex),
            "xatol": 1e-12 * max(max(steps), 1e-300),
            "fatol": 1e-15 * max(abs(v0), 1e-300),
            "maxiter": 400,
        },
    )
    if float(res.fun) < v0:
        return [float(t) for t in res.x], float(res.fun)
    return list(x0), v0
