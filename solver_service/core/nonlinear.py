"""Housner's nonlinear rocking block, integrated with ``scipy.integrate.solve_ivp``.

The linearised model of theory §1 replaces ``sin``/``cos`` of Housner's equation by their
values near ``phi = alpha``. This module integrates the full equation for one rigid block on a
rigid base, so that the linearisation error of a case can be measured (theory §6.5 caveat).

Notation
--------
t : time [s]
phi : rotation of the block, positive in the collapse direction [rad]
alpha : slenderness angle, between the vertical and the line from pivot to centre of mass [rad]
R : distance from pivot to centre of mass [m]
p : frequency parameter ``sqrt(M g R / I_O)`` [rad/s]
eta : coefficient of restitution on the angular velocity at impact [-]
a_g : ground acceleration [m/s²]; positive opposes positive rotation (Housner)
x : ``phi/alpha`` [-], the ratio reported (comparable with ``phi/phi_ov`` of the linear
    model, where ``phi_ov = lam = alpha``)
s : side in motion, +1 or -1
G : standard gravity [m/s²]

Equation of motion (theory §2.1, mirrored for ``phi < 0``)::

    phi'' = -p**2 * (s sin(alpha - s phi) + a_g/G cos(alpha - s phi)),   s = sgn(phi)

The integrator is the engine of ``reference.py`` with this equation plugged in, so the uplift,
impact, rest and collapse rules are the same as in the linear reference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal, Optional

import numpy as np

from shared_schema.errors import InputError, SolverError
from solver_service.core.exact import simulate as simulate_exact
from solver_service.core.excitation import SampledAccel
from solver_service.core.integrator import (
    Accel,
    Array,
    Event,
    Excitation,
    FreeOutcome,
    Integrator,
    Physics,
    Rhs,
    first_sign,
)
from solver_service.core.linearisation import (
    LINEARISATION_MAP_PATH,
    WARN_LINEARISATION,
    linearisation_estimate,
    linearisation_warnings,
)
from solver_service.core.model import G, RockingModel, check_positive
from solver_service.core.reference import (
    MAX_IMPACTS,
    ZENO_VREL,
    Forcing,
    check_ivp_inputs,
    integrate_events,
    solve_segment,
)
from solver_service.core.result import RockingResult

__all__ = [
    "LINEARISATION_MAP_PATH",
    "WARN_LINEARISATION",
    "HousnerBlock",
    "linearisation_error",
    "linearisation_estimate",
    "linearisation_warnings",
    "simulate_nonlinear",
]

#: Longest free motion integrated after the excitation, in units of ``1/p`` [-]. The time to
#: approach the unstable top grows only like ``log(1/(E - 1))``, so this is never reached in
#: practice.
FREE_T_MAX = 1000.0

#: Default ``solve_ivp`` method and tolerances: the setting ``benchmarks/stiff.py``
#: recommends for stiff event sequences (docs/numerics.md).
DEFAULT_METHOD = "DOP853"
DEFAULT_RTOL = 1e-12
DEFAULT_ATOL = 1e-14


@dataclass(frozen=True)
class HousnerBlock:
    """A rigid block rocking on a rigid base (Housner 1963).

    Parameters
    ----------
    p : float
        Frequency parameter ``sqrt(M g R / I_O)`` [rad/s], > 0.
    alpha : float
        Slenderness angle [rad], in ``(0, pi/2)``.
    eta : float
        Coefficient of restitution [-]: in ``[0, 1]`` (two-sided) or ``[-1, 0]`` (one-sided
        rebound off a restraint).
    name : str
        Identifier used in messages.
    one_sided : bool
        The block can only rotate positively and rebounds off a restraint at ``phi = 0``.
    """

    p: float
    alpha: float
    eta: float
    name: str = "block"
    one_sided: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "p", check_positive(self.p, "p"))
        alpha = check_positive(self.alpha, "alpha")
        if not alpha < 0.5 * math.pi:
            raise InputError(f"must be in (0, pi/2) [rad], got {self.alpha!r}", "alpha")
        object.__setattr__(self, "alpha", alpha)
        if isinstance(self.eta, bool) or not isinstance(self.eta, (int, float)):
            raise InputError(f"must be a number, got {self.eta!r}", "eta")
        eta = float(self.eta)
        lo, hi = (-1.0, 0.0) if self.one_sided else (0.0, 1.0)
        if not lo <= eta <= hi:
            kind = "one-sided" if self.one_sided else "two-sided"
            raise InputError(f"must be in [{lo:g}, {hi:g}] for a {kind} block, got {eta}", "eta")
        object.__setattr__(self, "eta", eta)

    @classmethod
    def rectangular(cls, b: float, h: float, eta: Optional[float] = None) -> HousnerBlock:
        """Build a solid rectangular block of full width ``b`` [m] and height ``h`` [m].

        Parameters
        ----------
        b, h : float
            Full width and height [m], > 0.
        eta : float, optional
            Coefficient of restitution [-]; defaults to Housner's ``1 - 1.5 sin²alpha``.

        Notes
        -----
        ``R = sqrt(b² + h²)/2``, ``I_O = 4/3 M R²`` so ``p = sqrt(3 G / (4 R))``,
        ``alpha = atan(b/h)`` (theory §2.1); ``eta`` from Eq. 25 (theory §3.1).

        Examples
        --------
        >>> blk = HousnerBlock.rectangular(0.5, 2.0)
        >>> round(blk.alpha, 4), round(blk.p, 4), round(blk.eta, 4)
        (0.245, 2.6712, 0.9118)
        """
        b_f = check_positive(b, "b")
        h_f = check_positive(h, "h")
        r = 0.5 * math.hypot(b_f, h_f)
        alpha = math.atan2(b_f, h_f)
        eta_f = 1.0 - 1.5 * math.sin(alpha) ** 2 if eta is None else eta
        return cls(p=math.sqrt(3.0 * G / (4.0 * r)), alpha=alpha, eta=eta_f)

    def linearised(self) -> RockingModel:
        """Return the linearised model: ``p_eq = p``, ``lam = phi_ov = alpha`` (theory §2.1)."""
        return RockingModel.symmetric(
            p_eq=self.p, lam=self.alpha, eta=self.eta, one_sided=self.one_sided, name=self.name
        )


class _HousnerPhysics(Physics):
    """Housner's equation in ``x = phi/alpha`` for the shared engine (theory §2.1)."""

    def __init__(self, block: HousnerBlock, method: str, rtol: float, atol: float) -> None:
        self.block = block
        self.one_sided = block.one_sided
        self.eta = block.eta
        self._method, self._rtol, self._atol = method, rtol, atol

    def p(self, s: int) -> float:
        """Frequency parameter [rad/s] (both sides)."""
        return self.block.p

    def uplift_accel(self, s: int) -> float:
        """``G tan(alpha)`` [m/s²] (theory §1.8)."""
        return G * math.tan(self.block.alpha)

    def rhs(self, s: int, accel: Accel) -> Rhs:
        """``x'' = -(p²/alpha)(s sin(alpha - s alpha x) + a_g/G cos(alpha - s alpha x))``."""
        alpha = self.block.alpha
        k = self.block.p**2 / alpha
        sf = float(s)

        def fun(t: float, y: Array) -> Array:
            u = alpha - sf * alpha * y[0]
            return np.array([y[1], -k * (sf * math.sin(u) + accel(t) / G * math.cos(u))])

        return fun

    def collapse_level(self, s: int, amax: float) -> float:
        """``min(alpha + atan(amax/G), pi/2) / alpha`` (theory §10)."""
        alpha = self.block.alpha
        return min(alpha + math.atan(amax / G), 0.5 * math.pi) / alpha

    def impact(self, s: int, v: float) -> tuple[int, float]:
        """Return the new side and ``v`` [1/s]: ``phi' -> eta phi'`` (theory §1.8)."""
        return (1 if self.one_sided else -s), self.eta * v

    def energy(self, s: int, x: float, v: float) -> float:
        """Energy over ``M g R`` [-]: ``(alpha v)²/(2 p²) + cos(alpha - s alpha x)``."""
        alpha = self.block.alpha
        return 0.5 * (alpha * v / self.block.p) ** 2 + math.cos(alpha - s * alpha * x)

    def _leg(
        self, s: int, x: float, v: float, stop: Literal["cross", "turn", "impact"]
    ) -> tuple[float, float, float, int]:
        """Free motion from ``(x, v)`` on side ``s`` until ``stop``; ``(dt, x, v, nfev)``."""
        sf = float(s)
        rhs = self.rhs(s, lambda t: 0.0)
        y0 = np.array([x, v])
        acc0 = float(rhs(0.0, y0)[1])
        if stop == "cross":
            ev = Event(lambda t, y: sf * float(y[0]) - 1.0, True, 1.0, 0.0, sf * x - 1.0)
        elif stop == "turn":
            ev = Event(lambda t, y: float(y[1]), True, -sf, 0.0, v or first_sign(acc0, sf))
        else:
            ev = Event(lambda t, y: float(y[0]), True, -sf, 0.0, x or first_sign(v, acc0, sf))
        sol = solve_segment(
            rhs,
            (0.0, FREE_T_MAX / self.block.p),
            y0,
            self._method,
            self._rtol,
            self._atol,
            [ev],
            np.inf,
        )
        if sol.status != 1:
            raise SolverError(f"free rocking did not reach its {stop!r} event")
        return float(sol.t[-1]), float(sol.y[0, -1]), float(sol.y[1, -1]), int(sol.nfev)

    def free(self, s: int, x: float, v: float, zeno_vrel: float) -> FreeOutcome:
        """Outcome of the free nonlinear motion, decided by energy (at most two excursions).

        Notes
        -----
        The energy ``E = (alpha v)²/(2p²) + cos(alpha - |phi|)`` is conserved between impacts
        and the top of the potential is ``E = 1`` at ``|phi| = alpha``. Outward motion with
        ``E > 1`` overturns; past the top, the body overturns unless it moves back inward with
        ``E > 1``. An impact multiplies the kinetic energy by ``eta²``, so the excursion after
        the next impact is the last one that can be larger (theory §1.8, nonlinear analogue).
        """
        nfev = 0
        y, w = s * x, s * v
        e = self.energy(s, x, v)
        peak, dt_peak = abs(x), 0.0
        if y >= 1.0:
            if w > 0.0 or e <= 1.0:
                return FreeOutcome(True, 0.0, 1.0, 0.0)
        elif w > 0.0:
            if e > 1.0:
                dt, _, _, nf = self._leg(s, x, v, "cross")
                return FreeOutcome(True, dt, 1.0, 0.0, nf)
            dt_peak, xt, _, nfev = self._leg(s, x, v, "turn")
            peak = max(peak, abs(xt))
        dt_ret, _, vi, nf = self._leg(s, x, v, "impact")
        nfev += nf
        s1, v1 = self.impact(s, vi)
        if abs(v1) < zeno_vrel * self.block.p:
            return FreeOutcome(False, math.nan, peak, dt_peak, nfev)
        if self.energy(s1, 0.0, v1) > 1.0:
            dt, _, _, nf = self._leg(s1, 0.0, v1, "cross")
            return FreeOutcome(True, dt_ret + dt, 1.0, 0.0, nfev + nf)
        dt2, x2, _, nf = self._leg(s1, 0.0, v1, "turn")
        nfev += nf
        if abs(x2) > peak:
            return FreeOutcome(False, math.nan, abs(x2), dt_ret + dt2, nfev)
        return FreeOutcome(False, math.nan, peak, dt_peak, nfev)


def simulate_nonlinear(
    block: HousnerBlock,
    excitation: Excitation,
    *,
    scale: float = 1.0,
    method: str = DEFAULT_METHOD,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
    criterion: Optional[str] = None,
    zeno_vrel: float = ZENO_VREL,
    max_impacts: int = MAX_IMPACTS,
    dense: bool = False,
    x0: float = 0.0,
    restart_at_samples: bool = True,
) -> RockingResult:
    """Rocking response of a rigid block with Housner's nonlinear equation.

    Parameters
    ----------
    block : HousnerBlock
        The block.
    excitation : Pulse or SampledAccel
        Ground acceleration [m/s²] (Housner's sign convention).
    scale : float
        Factor on the acceleration [-], > 0.
    method : str
        ``solve_ivp`` method (``reference.IVP_METHODS``). Never use scipy's default
        tolerances here (theory §10).
    rtol, atol : float
        ``solve_ivp`` tolerances [-] on ``x = phi/alpha`` and [1/s] on ``dx/dt``. The
        defaults are the setting ``benchmarks/stiff.py`` recommends (docs/numerics.md): on
        stiff event sequences DOP853 at rtol 1e-12 is the most accurate of the equally cheap
        settings, since the restarts at samples and impacts dominate the cost.
    criterion : {"ratio", "exact"} or None
        Verdict reported as ``overturned``; None picks "exact" for a Pulse, "ratio" for a
        SampledAccel.
    zeno_vrel : float
        Rest rule: an impact leaving ``|dx/dt| < zeno_vrel * p`` puts the block at rest [-].
    max_impacts : int
        Hard cap on impacts; beyond it the run stops with status -1.
    dense : bool
        Return ``t`` [s] and signed ``ratio = phi/alpha`` [-] during the excitation.
    x0 : float
        Initial ``phi/alpha`` [-], ``|x0| < 1``, released from rest at the start.
    restart_at_samples : bool
        Restart the integrator at every sample of a record (see ``simulate_ivp``).

    Returns
    -------
    RockingResult
        ``peak_ratio`` is ``max |phi|/alpha``; ``ratio_exceeded`` means ``|phi| >= alpha``;
        ``method`` is ``"nonlinear:<method>"``; ``error_estimate`` is the tolerance-based
        estimate of ``simulate_ivp`` (``10 max(rtol * peak, atol) sqrt(1 + n_events)``), not
        a bound.

    Raises
    ------
    InputError
        A bad argument (the message names it).
    SolverError
        ``solve_ivp`` failed.

    Notes
    -----
    Equation of theory §2.1 mirrored for ``phi < 0``. Uplift from rest when
    ``|a_g| > G tan(alpha)`` in the opening direction (§1.8). Impact ``phi' -> eta phi'``
    (§1.8). During the excitation the block has certainly collapsed once it moves outward
    past ``alpha + atan(max|a_g|/G)``, capped at ``pi/2`` (§10); after it, the energy of the
    free motion decides (``_HousnerPhysics.free``).

    Examples
    --------
    >>> from solver_service.core.excitation import Pulse
    >>> blk = HousnerBlock(p=2.0, alpha=0.2, eta=0.9)
    >>> r = simulate_nonlinear(blk, Pulse(a_p=-0.25 * G, f_p=1.0))
    >>> r.method, round(r.peak_ratio, 4), r.n_impacts, r.collapsed
    ('nonlinear:DOP853', 0.2047, 1, False)
    """
    scale_f, rtol_f, atol_f, crit, zeno, cap, x0_f = check_ivp_inputs(
        excitation, scale, method, rtol, atol, criterion, zeno_vrel, max_impacts, x0
    )
    if not isinstance(block, HousnerBlock):
        raise InputError(f"must be a HousnerBlock, got {type(block).__name__}", "block")
    if block.one_sided and x0_f < 0.0:
        raise InputError(f"must be >= 0 for a one-sided block, got {x0_f}", "x0")
    return integrate_events(
        _HousnerPhysics(block, str(method), rtol_f, atol_f),
        Forcing(excitation, scale_f, bool(restart_at_samples)),
        x0=x0_f,
        method=str(method),
        rtol=rtol_f,
        atol=atol_f,
        criterion=crit,
        zeno_vrel=zeno,
        max_impacts=cap,
        dense=bool(dense),
        max_step=(
            excitation.dt
            if isinstance(excitation, SampledAccel) and not restart_at_samples
            else np.inf
        ),
        label=f"nonlinear:{method}",
    )


def _simulate_linear(
    model: RockingModel, excitation: Excitation, scale: float, kw: dict[str, Any]
) -> RockingResult:
    """Run the exact linear integrator with the ``criterion`` and ``x0`` of ``kw``."""
    criterion = kw.get("criterion")
    x0 = float(kw.get("x0", 0.0))
    return simulate_exact(model, excitation, scale=scale, criterion=criterion, x0=x0)


def linearisation_error(
    block: HousnerBlock, excitation: Excitation, *, scale: float = 1.0, **kw: Any
) -> dict[str, Any]:
    """Compare the linearised and the nonlinear block on the same input.

    Parameters
    ----------
    block : HousnerBlock
        The block; its linear model is ``block.linearised()``.
    excitation : Pulse or SampledAccel
        Ground acceleration [m/s²].
    scale : float
        Factor on the acceleration [-].
    **kw
        Passed to ``simulate_nonlinear``; ``criterion`` and ``x0`` are also used for the
        linear run.

    Returns
    -------
    dict
        ``"linear"`` and ``"nonlinear"``: ``RockingResult.summary()`` of each run;
        ``"peak_ratio_error"``: ``|peak_lin - peak_nl|`` [-]; ``"relative_error"``: that over
        ``peak_nl`` [-] (0 when both are 0, inf when only the nonlinear peak is 0);
        ``"same_outcome"``: both runs give the same ``overturned`` verdict.

    Notes
    -----
    The linear run uses the exact integrator (``exact.simulate``). Both models share
    ``p`` and ``phi_ov = alpha`` but not the uplift threshold (``G alpha`` linear,
    ``G tan alpha`` nonlinear, theory §1.8), which is part of the linearisation error.
    """
    nl = simulate_nonlinear(block, excitation, scale=scale, **kw)
    lin = _simulate_linear(block.linearised(), excitation, scale, kw)
    err = abs(lin.peak_ratio - nl.peak_ratio)
    if nl.peak_ratio > 0.0:
        rel = err / nl.peak_ratio
    else:
        rel = 0.0 if err == 0.0 else math.inf
    return {
        "linear": lin.summary(),
        "nonlinear": nl.summary(),
        "peak_ratio_error": err,
        "relative_error": rel,
        "same_outcome": lin.overturned == nl.overturned,
    }


#: The entry satisfies the integrators' contract (mypy checks this assignment).
_CONTRACT: Integrator[HousnerBlock] = simulate_nonlinear
