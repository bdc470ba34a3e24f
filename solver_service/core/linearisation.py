"""Where the linearised rocking model is off: the shipped linearisation-error map.

``benchmarks/linearisation_map.py`` measures the relative error of the linearised model
against Housner's nonlinear block (``nonlinear.simulate_nonlinear``) on a grid of slenderness
``alpha`` and pulse frequency ratio ``Omega = omega_p / p`` (and on El Centro 1940 for
records) and writes ``solver_service/data/linearisation_map.npz``. This module reads that
table and turns it into an estimate per case and into the warnings that ``exact.simulate``
attaches to its results (docs/numerics.md).

It sits below both ``exact`` and ``nonlinear`` so that neither imports the other for it.
"""

from __future__ import annotations

import bisect
import functools
import math
from pathlib import Path
from typing import Any, Optional

import numpy as np

from .model import RockingModel, check_positive

__all__ = [
    "LINEARISATION_MAP_PATH",
    "WARN_LINEARISATION",
    "linearisation_estimate",
    "linearisation_warnings",
]

#: Relative linearisation error above which results carry a warning [-] (issue 7: 10 %).
WARN_LINEARISATION = 0.10
#: The linearisation error map (``benchmarks/linearisation_map.py`` writes it).
LINEARISATION_MAP_PATH = Path(__file__).resolve().parents[1] / "data" / "linearisation_map.npz"


@functools.lru_cache(maxsize=1)
def _linearisation_map() -> Optional[dict[str, Any]]:
    """Load the shipped map as arrays; None when the file is absent (then no warnings)."""
    if not LINEARISATION_MAP_PATH.exists():
        return None
    with np.load(LINEARISATION_MAP_PATH) as data:
        out: dict[str, Any] = {k: np.asarray(data[k]) for k in data.files}
    # Smallest alpha at which any error of the map exceeds the warning level: below it no
    # lookup is needed (keeps the check out of the exact integrator's hot path).
    # Records: the typical (median over the map's p) error. A single record's peak is
    # sensitive to any change of the model (many impacts), so the largest value over p
    # scatters from case to case; the median shows the systematic part.
    out["record_typical"] = _row_medians(np.nan_to_num(out["record_error"], nan=np.inf))
    worst = np.maximum(
        np.nan_to_num(out["amplitude_error"], nan=np.inf).max(axis=1), out["record_typical"]
    )
    over = np.flatnonzero(worst > WARN_LINEARISATION)
    out["alpha_warn"] = float(out["alpha"][max(over[0] - 1, 0)]) if over.size else math.inf
    # Plain lists: the lookup runs inside exact.simulate, where numpy calls cost more than
    # the integration of a pulse.
    out["alpha_list"] = [float(x) for x in out["alpha"]]
    out["omega_list"] = [float(x) for x in out["omega"]]
    out["amplitude_list"] = np.nan_to_num(out["amplitude_error"], nan=np.inf).tolist()
    out["record_list"] = [float(x) for x in out["record_typical"]]
    return out


def _row_medians(values: Any) -> Any:
    """Median of each row of a 2-D array without NaN: ``np.median(values, axis=1)``, bit for bit.

    ``np.median`` looks for NaN through ``np.ma``, whose import costs a one-pulse ``rockmech
    pulse`` more than its integration (#38); the middle of the sorted row (the mean of the
    two middle values for an even length) is the same number.
    """
    ordered = np.sort(values, axis=1)
    half = ordered.shape[1] // 2
    if ordered.shape[1] % 2:
        return ordered[:, half]
    return (ordered[:, half - 1] + ordered[:, half]) / 2


def _bracket(grid: list[float], value: float) -> tuple[int, int]:
    """Return the indices of the grid nodes around ``value`` (clamped to the grid)."""
    i = bisect.bisect_left(grid, value)
    return max(i - 1, 0), min(i, len(grid) - 1)


def linearisation_estimate(alpha: float, omega: Optional[float] = None) -> float:
    """Estimated relative error of the linearised model for a block of slenderness ``alpha``.

    Parameters
    ----------
    alpha : float
        Slenderness [rad]; for a mechanism, its ``lam`` (the equivalent block of theory §1.4).
    omega : float, optional
        Pulse frequency ratio ``omega_p / p`` [-]. Given: the error of the minimum
        overturning amplitude of a one-sine pulse. None: the error of the peak rotation on
        El Centro 1940 N-S (median over the map's ``p``: the systematic part, since single
        peaks on a record scatter), an indication for records.

    Returns
    -------
    float
        The largest ``|error|`` [-] at the map's grid nodes around the point (so it errs high),
        clamped to the map's range (alpha 0.01 to 1.2, Omega 0.1 to 20); NaN when the map is
        not installed.

    Notes
    -----
    The map is measured by ``benchmarks/linearisation_map.py`` with Housner's restitution
    ``eta = max(0, 1 - 1.5 sin²alpha)`` and is published in ``docs/numerics.md``.

    Examples
    --------
    >>> linearisation_estimate(0.05, 2.0) < 0.10
    True
    """
    table = _linearisation_map()
    a = check_positive(alpha, "alpha")
    om = None if omega is None else check_positive(omega, "omega")
    if table is None:
        return math.nan
    return _estimate(table, a, om)


def _estimate(table: dict[str, Any], alpha: float, omega: Optional[float]) -> float:
    """``linearisation_estimate`` without input checks (hot path of ``exact.simulate``)."""
    i0, i1 = _bracket(table["alpha_list"], alpha)
    if omega is None:
        rec: list[float] = table["record_list"]
        return max(rec[i0], rec[i1])
    j0, j1 = _bracket(table["omega_list"], omega)
    amp: list[list[float]] = table["amplitude_list"]
    return max(amp[i0][j0], amp[i0][j1], amp[i1][j0], amp[i1][j1])


def linearisation_warnings(model: RockingModel, omega_p: Optional[float] = None) -> list[str]:
    """Warnings for a case where the linearised model may be off by more than 10 %.

    Parameters
    ----------
    model : RockingModel
        The mechanism; ``alpha`` is taken as ``lam`` of each side (for a single block
        ``lam = alpha``, theory §2.1; for other mechanisms the equivalent block of §1.4).
    omega_p : float, optional
        Circular pulse frequency [rad/s]; each side is looked up at ``omega_p / p_eq``.
        None for records.

    Returns
    -------
    list of str
        Empty when every side's estimate (``linearisation_estimate``) is at most
        ``WARN_LINEARISATION``.

    Examples
    --------
    >>> linearisation_warnings(RockingModel.symmetric(2.0, 0.05, 0.9), omega_p=4.0)
    []
    """
    # The common case (every side below the map's first warning) costs no hashing.
    table = _linearisation_map()
    lam_max = model.positive.lam if model.one_sided else max(model.positive.lam, model.neg.lam)
    if table is None or lam_max < table["alpha_warn"]:
        return []
    return list(_warnings_cached(model, omega_p))


@functools.lru_cache(maxsize=4096)
def _warnings_cached(model: RockingModel, omega_p: Optional[float]) -> tuple[str, ...]:
    """``linearisation_warnings`` memoised: ``exact.simulate`` asks for every run."""
    table = _linearisation_map()
    sides = [model.positive] if model.one_sided else [model.positive, model.neg]
    if table is None or max(sd.lam for sd in sides) < table["alpha_warn"]:
        return ()
    worst = 0.0
    for sd in sides:
        om = None if omega_p is None else omega_p / sd.p_eq
        worst = max(worst, _estimate(table, sd.lam, om))
    if not worst > WARN_LINEARISATION:
        return ()
    what = "pulse overturning amplitude" if omega_p is not None else "peak rotation on a record"
    lams = " / ".join(f"{sd.lam:g}" for sd in sides)
    return (
        f"The linearised model may be off by about {100 * worst:.0f} % here ({what}, lam = "
        f"{lams}): compare with Housner's nonlinear block (simulate_nonlinear); see "
        "docs/numerics.md.",
    )
