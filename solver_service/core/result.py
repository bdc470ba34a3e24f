"""Result object of a rocking simulation (scipy's ``OdeResult`` pattern).

Two overturning verdicts are reported, because the method and the physics differ:

``ratio_exceeded``
    The method's criterion (Mehrotra & DeJong): ``|phi|/phi_ov >= 1`` at some time.
``collapsed``
    The exact outcome: the body can no longer come back. During the excitation this is
    certain once it moves outward past ``1 + max|a_g|/(g lam)`` (in ``x``); after the
    excitation the free-rocking invariant of theory §1.8 decides exactly.

``overturned`` follows ``criterion``: ``"ratio"`` (the default for records) or ``"exact"``
(the default for pulses, theory §10, since a decelerating pulse can pull a body back).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np
from numpy.typing import NDArray

__all__ = ["STATUS_MESSAGES", "RockingResult"]

#: Status codes and their meaning.
STATUS_MESSAGES = {
    0: "The excitation ended and the body did not collapse.",
    1: "The body collapsed: it can no longer return (exact outcome).",
    -1: "Stopped: the impact limit was reached (see max_impacts); the result is incomplete.",
    -2: "Stopped: the state became non-finite; the result is unreliable.",
}


@dataclass
class RockingResult:
    """Outcome of one simulation of one mechanism under one excitation.

    Attributes
    ----------
    status : int
        See ``STATUS_MESSAGES``; negative means the run did not complete.
    message : str
        Human-readable status.
    success : bool
        ``status >= 0``.
    peak_ratio : float
        Peak ``|phi|/phi_ov`` over the motion, including free rocking after the excitation
        ends [-]. When the body collapses it is reported as 1.0 (beyond that point the
        ratio grows without bound).
    t_peak : float
        Time of the peak [s].
    overturned : bool
        Verdict under ``criterion``.
    t_overturn : float or None
        When ``|phi|/phi_ov`` first reached 1 (ratio criterion), or reached 1 on the
        excursion that collapses (exact criterion) [s].
    criterion : str
        ``"ratio"`` or ``"exact"``.
    ratio_exceeded, t_ratio_exceeded : bool, float or None
        The method's criterion and when it was first met [s].
    collapsed, t_collapse : bool, float or None
        The exact outcome and when ``|phi|/phi_ov`` reached 1 on the collapsing excursion [s].
    n_impacts : int
        Number of impacts during the excitation.
    n_steps : int
        Work counter: closed-form segments (exact integrator) or right-hand-side
        evaluations (time-stepping references).
    error_estimate : float
        Estimated absolute error of ``peak_ratio`` [-].
    runtime_s : float
        Wall-clock time of the computation [s].
    method : str
        Integrator that produced the result.
    t, ratio : (m,) float or None
        Time series when asked for: times [s] and signed ``phi/phi_ov`` (negative while
        rocking on the negative side).
    n_uplifts, n_rests : int
        Work counters: uplifts from rest, and impacts that ended in rest (the rest rule that
        ends Zeno sequences, or ``eta = 0``).
    impacts : (4, n) float or None
        Impact log: rows time [s], side before the impact (+1/-1), ``d(phi/phi_ov)/dt``
        arriving and leaving [1/s] (leaving is 0 when the impact ends in rest). The exact
        integrator returns it when asked (``exact.simulate(..., impact_log=True)``); the
        time-stepping references always do.
    warnings : list of str
        Conditions a user should know about (an unresolved peak, a case where the
        linearised model is far from the nonlinear block, ...); also appended to
        ``message``.
    """

    status: int
    peak_ratio: float
    t_peak: float
    criterion: str
    ratio_exceeded: bool
    t_ratio_exceeded: Optional[float]
    collapsed: bool
    t_collapse: Optional[float]
    n_impacts: int
    n_steps: int
    error_estimate: float
    runtime_s: float
    method: str
    t: Optional[NDArray[np.float64]] = field(default=None, repr=False)
    ratio: Optional[NDArray[np.float64]] = field(default=None, repr=False)
    n_uplifts: int = 0
    n_rests: int = 0
    impacts: Optional[NDArray[np.float64]] = field(default=None, repr=False)
    warnings: list[str] = field(default_factory=list)

    @property
    def success(self) -> bool:
        """True when the run completed (``status >= 0``)."""
        return self.status >= 0

    @property
    def message(self) -> str:
        """Human-readable status, followed by the warnings if there are any."""
        return " ".join([STATUS_MESSAGES[self.status], *self.warnings])

    @property
    def overturned(self) -> bool:
        """Overturning verdict under ``criterion``."""
        return self.ratio_exceeded if self.criterion == "ratio" else self.collapsed

    @property
    def t_overturn(self) -> Optional[float]:
        """Time of overturning under ``criterion`` [s], or None."""
        return self.t_ratio_exceeded if self.criterion == "ratio" else self.t_collapse

    def summary(self) -> dict[str, Any]:
        """Return the scalar outputs as a JSON-ready dict (no time series)."""
        return {
            "peak_ratio": self.peak_ratio,
            "t_peak": self.t_peak,
            "overturned": self.overturned,
            "t_overturn": self.t_overturn,
            "criterion": self.criterion,
            "ratio_exceeded": self.ratio_exceeded,
            "collapsed": self.collapsed,
            "n_impacts": self.n_impacts,
            "n_steps": self.n_steps,
            "error_estimate": self.error_estimate,
            "runtime_s": self.runtime_s,
            "status": self.status,
            "message": self.message,
            "warnings": list(self.warnings),
            "method": self.method,
        }
