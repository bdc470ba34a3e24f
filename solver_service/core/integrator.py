"""The contract of the rocking integrators: what ``exact``, ``reference`` and ``nonlinear`` share.

Three integrators answer the same question (how far does a rocking body rotate under a
ground acceleration, and does it overturn):

* ``exact.simulate``: the linearised equation in closed form between exactly located events
  (the default; numba kernels);
* ``reference.simulate_ivp``: the same linearised equation by time stepping
  (``scipy.integrate.solve_ivp``), the independent check of the exact integrator;
* ``nonlinear.simulate_nonlinear``: Housner's nonlinear equation of one block by the same
  time-stepping engine, to measure the linearisation error.

Each public entry satisfies ``Integrator`` (in the manner of scipy's ``OdeSolver``: one call
signature, one result type): a mechanism and an ``Excitation`` in, a ``RockingResult`` out,
with ``status``, ``message``, ``success``, the work counters (``n_steps``, ``n_impacts``,
``n_uplifts``, ``n_rests``), an ``error_estimate`` and ``runtime_s``.

The time-stepping integrators plug an equation of motion into one engine
(``reference.integrate_events``) through ``Physics``: the right-hand side of the state
``y = [x, x']`` on each side, the uplift threshold, the impact map, the certain-collapse
level and the free motion after the excitation. The engine finds impacts, crossings of
``|x| = 1`` and turning points with the event functions of ``motion_events``. The exact
integrator applies the same rules in its kernels (``_kernels``; theory §1.8, §10), with the
same rest rule ``V_REST_REL``.

Notation
--------
x : normalised rotation ``phi/phi_ov`` (``phi/alpha`` for Housner's block) [-]
v : ``dx/dt`` [1/s]
s : side in motion, +1 or -1
a_g : ground acceleration [m/s²]; positive opposes positive rotation (Housner)
p : frequency parameter [rad/s]

Python 3.9-clean: Rhino 8 imports the solver through its flows.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Optional, Protocol, TypeVar, Union

import numpy as np
from numpy.typing import NDArray

from .excitation import Pulse, SampledAccel
from .result import RockingResult

__all__ = [
    "V_REST_REL",
    "Accel",
    "Array",
    "Event",
    "Excitation",
    "FreeOutcome",
    "Integrator",
    "Physics",
    "Rhs",
    "first_sign",
    "motion_events",
]

#: Rest rule of every integrator: an impact leaving at below ``V_REST_REL * p``
#: [1/s per rad/s] ends in rest (theory §10). The excursions it drops are smaller than
#: ``V_REST_REL**2 / 2`` in ``|x|``.
V_REST_REL = 1e-9

#: A ground motion: a pulse or a sampled record.
Excitation = Union[Pulse, SampledAccel]
#: A state or a time series [-] or [1/s].
Array = NDArray[np.float64]
#: Right-hand side ``(t, [x, v]) -> [v, x'']`` of the equation of motion on one side.
Rhs = Callable[[float, Array], Array]
#: Ground acceleration [m/s²] as a function of time [s].
Accel = Callable[[float], float]

M_contra = TypeVar("M_contra", contravariant=True)


class Integrator(Protocol[M_contra]):
    """The public entry of an integrator (``exact.simulate``, ``reference.simulate_ivp``...).

    Parameters
    ----------
    model : M_contra
        The mechanism (a ``RockingModel``, or a ``HousnerBlock`` for the nonlinear block);
        positional.
    excitation : Pulse or SampledAccel
        Ground acceleration [m/s²]; positional.
    scale : float
        Factor on the acceleration [-], > 0.
    criterion : {"ratio", "exact"} or None
        Verdict reported as ``overturned``; None picks "exact" for a Pulse, "ratio" for a
        SampledAccel.
    dense : bool
        Return the time series ``t`` [s] and signed ``ratio`` [-].
    x0 : float
        Initial ``x`` [-], ``|x0| < 1``, released from rest at the start.
    max_impacts : int
        Cap on impacts; beyond it the run stops with status -1.

    Returns
    -------
    RockingResult
        With its status, work counters and error estimate.
    """

    def __call__(
        self,
        model: M_contra,
        excitation: Excitation,
        /,
        *,
        scale: float = ...,
        criterion: Optional[str] = ...,
        dense: bool = ...,
        x0: float = ...,
        max_impacts: int = ...,
    ) -> RockingResult:
        """Integrate the motion of ``model`` under ``excitation``."""
        ...


@dataclass(frozen=True)
class FreeOutcome:
    """Outcome of the free motion after the excitation (see ``freemotion.free_rocking``).

    Attributes
    ----------
    collapses : bool
        The body overturns.
    dt_cross : float
        Time from the end of the excitation to the crossing of ``|x| = 1`` [s] (NaN when
        it does not collapse).
    peak : float
        Largest ``|x|`` of the free motion [-].
    dt_peak : float
        Time from the end of the excitation to that peak [s].
    nfev : int
        Right-hand-side evaluations spent on it.
    """

    collapses: bool
    dt_cross: float
    peak: float
    dt_peak: float
    nfev: int = 0


class Physics:
    """An equation of motion in ``x`` units, as the time-stepping engine needs it.

    Attributes
    ----------
    one_sided : bool
        The body rotates only positively and rebounds off a restraint at ``x = 0``.
    eta : float
        Coefficient of restitution [-].
    """

    one_sided: bool
    eta: float

    def p(self, s: int) -> float:
        """Frequency parameter of side ``s`` [rad/s] (scales the rest rule)."""
        raise NotImplementedError

    def uplift_accel(self, s: int) -> float:
        """Magnitude of the ground acceleration that uplifts a body into side ``s`` [m/s²]."""
        raise NotImplementedError

    def rhs(self, s: int, accel: Accel) -> Rhs:
        """Right-hand side ``(t, [x, v]) -> [v, x'']`` on side ``s``."""
        raise NotImplementedError

    def collapse_level(self, s: int, amax: float) -> float:
        """``s*x`` beyond which outward motion cannot come back while ``|a_g| <= amax``."""
        raise NotImplementedError

    def impact(self, s: int, v: float) -> tuple[int, float]:
        """Return the new side and ``v`` [1/s] after an impact at ``x = 0`` arriving with ``v``."""
        raise NotImplementedError

    def free(self, s: int, x: float, v: float, zeno_vrel: float) -> FreeOutcome:
        """Outcome of the free motion from ``(x, v)`` on side ``s`` once the excitation ends."""
        raise NotImplementedError


class Event:
    """An event function with scipy's ``terminal``/``direction`` attributes.

    ``value0`` replaces the value at the segment start ``t0``. An event that is exactly zero
    at ``t0`` (``x = 0`` after an impact or uplift, ``v = 0`` after uplift or release) is
    given the sign it takes just after ``t0``; otherwise scipy may count the start as a
    crossing, and with interpolants that do not reproduce ``y(t0)`` exactly (LSODA) its root
    bracket fails.

    Parameters
    ----------
    fun : callable
        ``(t, y) -> float``, zero at the event.
    terminal : bool
        The integration stops at the event.
    direction : float
        Only zeros crossed in this direction count (0: both).
    t0 : float
        Start of the segment [s].
    value0 : float
        The value used at ``t0``.
    """

    def __init__(
        self,
        fun: Callable[[float, Array], float],
        terminal: bool,
        direction: float,
        t0: float,
        value0: float,
    ) -> None:
        self.fun = fun
        self.terminal = terminal
        self.direction = direction
        self.t0 = t0
        self.value0 = value0

    def __call__(self, t: float, y: Array) -> float:
        """Value of the event at ``t`` for the state ``y`` (``value0`` at ``t0``)."""
        return self.value0 if t == self.t0 else self.fun(t, y)


def first_sign(*values: float) -> float:
    """Sign (+-1) of the first non-zero value: the sign of a Taylor series near its start.

    Examples
    --------
    >>> first_sign(0.0, -2.0, 5.0), first_sign(0.0, 0.0)
    (-1.0, 1.0)
    """
    for val in values:
        if val != 0.0:
            return math.copysign(1.0, val)
    return 1.0


def motion_events(s: int, level: float, t0: float, y0: Array, acc0: float) -> list[Event]:
    """Impact (terminal), certain collapse (terminal), ``|x| = 1`` and turning points.

    Parameters
    ----------
    s : int
        Side in motion, +1 or -1.
    level : float
        ``s*x`` of certain collapse (``Physics.collapse_level``) [-].
    t0 : float
        Start of the segment [s].
    y0 : (2,) float
        ``[x, v]`` at ``t0``.
    acc0 : float
        ``x''`` at ``t0`` [1/s²]; when both ``v`` and ``x''`` vanish there (uplift at the
        exact threshold), the motion still starts outward, towards side ``s``.

    Returns
    -------
    list of Event
        In this order: impact ``x = 0``, collapse ``s x = level``, ``s x = 1``, ``v = 0``.
    """
    sf = float(s)
    x0, v0 = float(y0[0]), float(y0[1])
    return [
        Event(lambda t, y: float(y[0]), True, -sf, t0, x0 or first_sign(v0, acc0, sf)),
        Event(lambda t, y: sf * float(y[0]) - level, True, 1.0, t0, sf * x0 - level),
        Event(lambda t, y: sf * float(y[0]) - 1.0, False, 0.0, t0, sf * x0 - 1.0),
        Event(lambda t, y: float(y[1]), False, 0.0, t0, v0 or first_sign(acc0, sf)),
    ]
