"""Size limits of a request and estimates of its work, shared by every front end.

The REST service refuses a request above these limits with 422 (its settings can change
them: ``ROCKMECH_MAX_SAMPLES`` and so on); the command line refuses it with exit status 2
unless ``--no-limits`` is given. Both count the work the same way, before any is done.
Both also stop work that runs too long: the service after ``ROCKMECH_COMPUTE_TIMEOUT_S``,
the command line after ``--time-limit`` seconds (``CLI_BUDGET_S`` by default; ``time_limit``),
with the same budget for the up-front estimate.

Light on purpose (standard library and ``shared_schema`` only): the service's app process
imports it.

Notes
-----
Work is counted in closed-form steps of the exact integrator, which cuts each record sample
interval (or a pulse of ``1/f_p`` seconds) into segments of at most ``1/p_eq`` seconds:

* a pulse: ``p_eq / f_p`` steps;
* exact envelopes: per mechanism side (both directions for one-sided rocking) and
  frequency, ``N_SCAN`` pulse runs of ``max(1, p_eq / f_p)`` steps;
* time histories: per mechanism side and scale factor, ``(n - 1) max(1, ceil(p_eq dt))``.

Exact envelopes of a mechanism with amplification data also evaluate the pulse response
spectrum at every frequency, on ``SPECTRUM_GRID_PER_PERIOD max(1, f_n / f_p)`` grid points
(``scale_factor_points``), counted at ``PULSE_POINTS_PER_CORE_S``.

Elastic response spectra cut each sample interval into at most ``T / SPECTRUM_SUBSTEPS``
long sub-steps (``spectrum_steps``), and an assessment page draws ``assess_figures``.

Each kind of work has its rate per core, measured by ``benchmarks/work_rates.py`` on the job
functions the compute processes run and recorded in ``docs/benchmarks.md`` (section
``work_rates``; ``tests/workflows/test_work_rates.py`` checks the constants against it). Work
is refused up front when it cannot finish within the budget even at ``RATE_MARGIN`` times
those rates on every core of the machine (``shortest_time``): a margin for faster cores than
the benchmark's, while the cores are counted where the work runs. What passes may still
run past the budget on a slower or busier machine; the budget stops it there.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import sys
import threading
import time
from collections.abc import Iterable, Iterator
from typing import TYPE_CHECKING, Any, Optional, Sequence

from shared_schema.errors import InputError

if TYPE_CHECKING:  # annotations only: the command line's --help reads the limits (#38)
    from shared_schema.constants import ConstantsFile
    from shared_schema.retrofit import RetrofitSpec
    from shared_schema.site import SiteFile

__all__ = [
    "ASSESS_ENVELOPE",
    "CLI_BUDGET_S",
    "DEFAULT_LIMITS",
    "ENVELOPE_STEPS_PER_CORE_S",
    "FIGURES_PER_S",
    "HISTORY_STEPS_PER_CORE_S",
    "NO_LIMITS",
    "N_SCAN",
    "PULSE_POINTS_PER_CORE_S",
    "P_EQ_PLAUSIBLE",
    "RATE_MARGIN",
    "RETROFIT_BISECTION_STEPS",
    "RETROFIT_CHECKS_PER_S",
    "RETROFIT_RECORD_PERIODS",
    "RETROFIT_RECORD_RUNS",
    "RETROFIT_SCALE_RUNS",
    "SPECTRUM_GRID_PER_PERIOD",
    "SPECTRUM_STEPS_PER_CORE_S",
    "SPECTRUM_SUBSTEPS",
    "TIME_LIMIT",
    "WORK_KINDS",
    "WORK_PER_SAMPLE",
    "TimeLimitExceeded",
    "active_time_limit",
    "check_count",
    "check_retrofit_work",
    "check_run",
    "cores",
    "directional",
    "envelope_steps",
    "history_steps",
    "mechanism_sides",
    "retrofit_checks",
    "retrofit_record_runs",
    "retrofit_reruns",
    "scale_factor_points",
    "shortest_time",
    "spectrum_steps",
    "time_limit",
    "work_words",
]

#: The fast mode's library grid of Omega = 2 pi f_p / p_eq: (first, last, points)
#: (``core.envelope.LIBRARY_OMEGA``; a test checks they agree). Frequencies outside it are
#: computed with the exact integrator.
LIBRARY_OMEGA = (0.05, 500.0, 533)
#: Margin of the up-front estimates over the rates below [-]: work is refused when it
#: cannot finish within the budget even this many times faster than measured, on every
#: core. 2: the newest desktop cores are up to about twice as fast per core as the
#: benchmark machine's (a shared 2-core AMD EPYC); the rates are per core, so more cores
#: are counted where the work runs (``cores``).
RATE_MARGIN = 2.0
#: The rates measured per core by ``benchmarks/work_rates.py``, to two significant digits
#: [unit/s]: the work divided by the CPU time of the job (all threads), best of 3, on the
#: benchmark machine (AMD EPYC, 2 cores); docs/benchmarks.md, section ``work_rates``, holds
#: the run (a test checks these against its table). Exact envelopes, closed-form steps
#: (the church's 8 mechanisms without amplification data, 200 frequencies): 2.59e6/s.
ENVELOPE_STEPS_PER_CORE_S = 2.6e6
#: The pulse scale factors' spectrum, grid points (``pulse_response_spectrum`` at the
#: church's ratios): 2.14e6/s.
PULSE_POINTS_PER_CORE_S = 2.1e6
#: Time histories, closed-form steps (the church on El Centro at 100 scale factors: runs at
#: rest, rocking and overturning): 7.39e7/s.
HISTORY_STEPS_PER_CORE_S = 7.4e7
#: Elastic response spectra, sub-steps (El Centro at 1000 periods): 1.82e8/s.
SPECTRUM_STEPS_PER_CORE_S = 1.8e8
#: The 2019 code checks of a retrofit's bisections, run one after another on one thread
#: (``benchmarks/retrofit.py``: the bundled church, each check of a mechanism with a trial
#: tie, its façades with 10 tie heights each): 1.45e3/s. Recorded in docs/benchmarks.md,
#: section ``retrofit`` (a test checks the constant against it).
RETROFIT_CHECKS_PER_S = 1.4e3
#: Exact runs at the design scale one record's search on the tie force plans (the
#: benchmark's target, ``benchmarks/retrofit.py``).
RETROFIT_RECORD_RUNS = 20
#: Periods of each record's response spectrum one code check of a retrofit with records
#: computes: the match to the site spectrum over the mechanism's band
#: (``assess.BAND_POINTS``) and the records' demand of C8.7.1.2.1.8
#: (``codes.circ2019.RECORD_POINTS``); a test checks the sum. Each period takes at least one
#: sub-step per sample.
RETROFIT_RECORD_PERIODS = 80
#: Exact runs one least overturning scale takes: the log grid of scales and the bisection
#: to ``scaling.SCALE_RTOL`` (about 12 halvings from the grid's ratio 1.124), and the run
#: at the design scale.
RETROFIT_SCALE_RUNS = 60 + 12 + 1
#: Bisection steps of one nonlinear criterion of a retrofit, at the least: the bracket
#: halves from half its passing end to ``workflows.retrofit.T_REL_TOL`` of it,
#: ``ceil(log2(0.5 / T_REL_TOL))`` (a test checks the copy).
RETROFIT_BISECTION_STEPS = 7
#: The assessment page's figures, drawn on one thread (the church_geometry page on El
#: Centro, 13 figures): 4.51/s.
FIGURES_PER_S = 4.5
#: Sub-steps per natural period of the elastic response spectrum
#: (``core.spectra.STEPS_PER_PERIOD``; a test checks the copy).
SPECTRUM_SUBSTEPS = 20
#: Pulse amplitudes scanned per frequency by an exact envelope (``core.envelope.N_SCAN``;
#: a test checks the copy).
N_SCAN = 300
#: Closed-form steps per record sample one run may take, on average: one run may take
#: ``WORK_PER_SAMPLE * max_samples`` steps.
WORK_PER_SAMPLE = 20
#: The default limits of one request (the service's settings start from these) [count, bytes].
DEFAULT_LIMITS: dict[str, int] = {
    "max_samples": 500_000,
    "max_mechanisms": 100,
    "max_scales": 100,
    "max_answer_bytes": 64 * 1024 * 1024,
}
#: Work budget of one command-line run [s]: work that cannot finish in it even at
#: ``RATE_MARGIN`` times the measured rates is refused (the service's budget is its compute
#: timeout).
CLI_BUDGET_S = 600.0
#: Grid points per period of the exact pulse response spectrum
#: (``core.amplification.GRID_PER_PERIOD``; a test checks the copy).
SPECTRUM_GRID_PER_PERIOD = 64
#: ``core.exact.P_EQ_PLAUSIBLE`` [rad/s] (a test checks the copy): the solver refuses a run
#: of a stiffer side itself, naming ``p_eq`` and its valid range, so ``check_run`` leaves
#: such sides to it rather than blaming the record.
P_EQ_PLAUSIBLE = 1e3
#: How a command-line user lifts the limits (named in every message).
NO_LIMITS = "--no-limits"
#: How a command-line user changes the time limit (``CLI_BUDGET_S`` by default).
TIME_LIMIT = "--time-limit"

#: Packages whose frames an exception must not be raised into from a signal handler: numba
#: calls back into Python while it compiles or loads a kernel, and an exception raised there
#: crashed the interpreter (a segmentation fault, 1 of 3 runs stopped at 1 s).
NO_INTERRUPT = ("numba", "llvmlite")
#: Interval at which the time limit is raised again past its time [s]: an exception raised
#: inside a callback the interpreter runs for itself (a weakref's, a ``__del__``) is printed
#: and dropped ("Exception ignored in ..."), seen in 1 of 24 stopped runs.
REPEAT_S = 0.5
#: The time limit of the run in progress [s], while ``time_limit`` holds one.
_active: list[float] = []


class TimeLimitExceeded(BaseException):
    """A command-line run went past its time limit (``time_limit``).

    A ``BaseException``, like ``KeyboardInterrupt``: no ``except Exception`` on the way (a
    mechanism reported as failed, a record skipped) may swallow it, while every ``finally``
    and ``except BaseException`` still removes its temporary files.
    """

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        super().__init__(
            f"time-limit: the run did not finish within its time limit of {seconds:g} s; give "
            f"{TIME_LIMIT} with more seconds, or {NO_LIMITS} to lift it"
        )


def active_time_limit() -> float:
    """Return the time limit of the run in progress [s] (``CLI_BUDGET_S`` outside one)."""
    return _active[-1] if _active else CLI_BUDGET_S


def _in_compiler(frame: Any) -> bool:
    """Return whether a frame of ``NO_INTERRUPT`` (or of no module) is on ``frame``'s stack."""
    while frame is not None:
        module = frame.f_globals.get("__name__")
        # A frame without a module is one numba made up for its compiled code.
        if module is None or module.split(".", 1)[0] in NO_INTERRUPT:
            return True
        frame = frame.f_back
    return False


@contextlib.contextmanager
def time_limit(seconds: Optional[float]) -> Iterator[None]:
    """Stop the block with ``TimeLimitExceeded`` once it has run ``seconds`` [s].

    ``None`` sets no limit. The limit is kept with a real-time interval timer (``SIGALRM``),
    so it is enforced on POSIX, in the main thread (elsewhere the block runs unlimited). It
    interrupts Python code between bytecodes, never inside numba (``NO_INTERRUPT``): a call
    into a compiled kernel is stopped when it returns (an exact envelope, after each
    mechanism side). Past the limit it is raised again every ``REPEAT_S``, except while an
    exception is being handled (the cleanup on the way out). While the block runs,
    ``check_run`` refuses work that cannot finish in ``seconds`` up front.

    Raises
    ------
    InputError
        ``seconds`` is not a finite number > 0 (field ``time-limit``).
    TimeLimitExceeded
        When the block runs past ``seconds``.
    """
    if seconds is None:
        yield
        return
    if not (math.isfinite(seconds) and seconds > 0):
        raise InputError(f"must be a number of seconds > 0, got {seconds:g}", "time-limit")
    timer = getattr(signal, "setitimer", None)
    if timer is None or threading.current_thread() is not threading.main_thread():
        _active.append(seconds)
        try:
            yield
        finally:
            _active.pop()
        return

    fired: list[bool] = []
    profiler = sys.getprofile()

    def stop(frame: Any, event: str = "", arg: Any = None) -> None:
        if fired and sys.exc_info()[1] is not None:
            _restore_profile(profiler)  # the limit is on its way out: let the cleanup run
            return
        if _in_compiler(frame):
            # Inside compiled code's call back into Python: raise at the first event (a
            # call or a return) outside it, e.g. when the kernel returns to its caller.
            sys.setprofile(stop)
            return
        _restore_profile(profiler)
        fired.append(True)
        raise TimeLimitExceeded(seconds)

    def expire(signum: int, frame: Any) -> None:
        stop(frame)

    previous = signal.signal(signal.SIGALRM, expire)
    _active.append(seconds)
    start = time.monotonic()
    outer, _ = timer(signal.ITIMER_REAL, seconds, REPEAT_S)
    try:
        yield
    except BaseException as exc:
        # Raised inside compiled code (numba), the exception comes back wrapped in another
        # (a SystemError); it is still the time limit that stopped the run.
        if fired and not isinstance(exc, TimeLimitExceeded):
            raise TimeLimitExceeded(seconds) from None
        raise
    finally:
        timer(signal.ITIMER_REAL, 0)
        _restore_profile(profiler)
        signal.signal(signal.SIGALRM, previous)
        _active.pop()
        if outer > 0:  # an enclosing timer (a test runner's) gets its remaining time back
            timer(signal.ITIMER_REAL, max(outer - (time.monotonic() - start), 1e-3))


def _restore_profile(profiler: Any) -> None:
    """Put back the profile hook found before a time limit (``sys.getprofile()``'s).

    A Python-level hook (a function, or None) goes back through ``sys.setprofile``. A
    C-level profiler (``cProfile.Profile``: ``sys.getprofile()`` gives the object, which is
    not callable) is switched on again with its own ``enable()``, so that profiling a command
    neither breaks its time limit nor loses the rest of the profile.
    """
    if profiler is None or callable(profiler):
        sys.setprofile(profiler)
    elif callable(getattr(profiler, "enable", None)):
        profiler.enable()
    else:  # pragma: no cover - no other kind of profile hook is known
        sys.setprofile(None)


def cores() -> int:
    """Return the cores this process may run on (the compute processes' threads use them)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


#: The kinds of work the estimates count: (rate per core [unit/s], its words); the figures
#: are drawn on one thread.
WORK_KINDS: dict[str, tuple[float, str]] = {
    "envelope_steps": (ENVELOPE_STEPS_PER_CORE_S, "closed-form steps of exact envelopes"),
    "pulse_points": (PULSE_POINTS_PER_CORE_S, "grid points of pulse spectra"),
    "history_steps": (HISTORY_STEPS_PER_CORE_S, "closed-form steps of time histories"),
    "spectrum_steps": (SPECTRUM_STEPS_PER_CORE_S, "sub-steps of response spectra"),
    "figures": (FIGURES_PER_S, "figures"),
    "retrofit_checks": (RETROFIT_CHECKS_PER_S, "code checks of a retrofit's bisections"),
}
#: The kinds of work done on one thread, whatever the cores.
SERIAL_KINDS = ("figures", "retrofit_checks")


def _kinds(work: dict[str, float]) -> list[tuple[str, float]]:
    unknown = set(work) - set(WORK_KINDS)
    if unknown:
        raise TypeError(f"unknown kinds of work: {sorted(unknown)}")
    return [(kind, float(work.get(kind, 0.0))) for kind in WORK_KINDS]


def shortest_time(**work: float) -> float:
    """Return the least time the work can take [s].

    Parameters
    ----------
    **work : float
        Work by kind (``WORK_KINDS``: ``envelope_steps``, ``pulse_points``,
        ``history_steps``, ``spectrum_steps``, ``figures``).

    Notes
    -----
    Each kind at ``RATE_MARGIN`` times its measured rate per core, on every core (the
    ``SERIAL_KINDS`` on one).
    """
    seconds = 0.0
    for kind, amount in _kinds(work):
        rate = WORK_KINDS[kind][0] * RATE_MARGIN
        seconds += amount / (rate if kind in SERIAL_KINDS else rate * cores())
    return seconds


def work_words(**work: float) -> str:
    """Return the work in words, e.g. ``3.75e+08 closed-form steps of exact envelopes``."""
    words = [f"{amount:.3g} {WORK_KINDS[kind][1]}" for kind, amount in _kinds(work) if amount > 0]
    return " and ".join(words) if words else "no work"


def spectrum_steps(n_samples: int, dt: float, period: float) -> float:
    """Sub-steps of the elastic response spectrum of a record at one ``period`` [s]."""
    per_sample = SPECTRUM_SUBSTEPS * dt / period
    if not math.isfinite(per_sample):
        return math.inf
    return float(max(n_samples - 1, 0) * max(1.0, math.ceil(per_sample)))


def _positive(*values: Any) -> bool:
    return all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0
        for v in values
    )


def directional(mech: Any) -> bool:
    """Whether a mechanism restitutes differently per impact direction.

    Its envelope is always computed with the exact integrator, the pulse in both directions
    (``core.envelope.mechanism_envelope``; ``RockingModel.is_directional``).
    """
    neg = getattr(mech, "eta_to_negative", None)
    return neg is not None and neg != getattr(mech, "eta_to_positive", None)


def mechanism_sides(
    cf: ConstantsFile,
    p_max: float = math.inf,
    *,
    only_exact: bool = False,
    only_other: bool = False,
) -> Iterable[tuple[float, int]]:
    """(p_eq [rad/s], pulse directions) of every side with a valid ``p_eq`` up to ``p_max``.

    With ``only_exact``, only the sides of mechanisms whose envelope is exact anyway
    (``directional``); with ``only_other``, only the others.
    """
    for mech in cf.mechanisms:
        if (only_exact and not directional(mech)) or (only_other and directional(mech)):
            continue
        one_sided = mech.rocking == "one_sided"
        sides = (mech.positive,) if one_sided else (mech.positive, mech.negative)
        for side in sides:
            p = None if side is None else side.p_eq
            if p is not None and _positive(p) and p <= p_max:
                yield float(p), 2 if one_sided or directional(mech) else 1


def _grid_sum(p: float, f_min: float, f_max: float, n: int) -> float:
    """Sum of ``max(1, p / f)`` over ``n`` log-spaced frequencies in ``[f_min, f_max]``."""
    if n < 2 or not _positive(f_min, f_max) or f_max <= f_min:
        return 0.0  # an invalid grid: the compute refuses it with its own message
    return _index_sum(p, f_min, (f_max / f_min) ** (1.0 / (n - 1)), 0, n)


def _index_sum(p: float, f_min: float, ratio: float, i0: int, i1: int) -> float:
    """Sum of ``max(1, p / f_i)`` over ``i0 <= i < i1``, ``f_i = f_min ratio**i``."""
    if i1 <= i0:
        return 0.0
    # Frequencies below p contribute p/f (a geometric series), the others 1 each.
    k = max(0, math.ceil(math.log(p / f_min) / math.log(ratio))) if p > f_min else 0
    m = min(i1, max(i0, k))  # f_i < p for i < k: p / f_i; 1 from there on
    series = (p / f_min) * (ratio ** (-i0) - ratio ** (-m)) / (1.0 - 1.0 / ratio)
    return series + (i1 - m)


def _outside_sum(p: float, f_min: float, f_max: float, n: int) -> float:
    """``_grid_sum`` over the frequencies whose ``Omega = 2 pi f / p`` leaves the library.

    The fast mode computes those exactly (``core.envelope.library_curve``): the
    frequencies below ``p Omega_min / (2 pi)`` and above ``p Omega_max / (2 pi)``, the two
    ends of the log grid.

    Examples
    --------
    >>> _outside_sum(0.1, 0.1, 10.0, 3)  # Omega 6.3, 63, 628: the last is above 500
    1.0
    >>> _outside_sum(20.0, 0.1, 10.0, 3)  # Omega 0.031, 0.31, 3.1: the first is below 0.05
    200.0
    >>> _outside_sum(1.0, 0.1, 10.0, 3)  # Omega 0.63, 6.3, 63: all inside
    0.0
    """
    if n < 2 or not _positive(f_min, f_max, p) or f_max <= f_min:
        return 0.0
    ratio = (f_max / f_min) ** (1.0 / (n - 1))
    step = math.log(ratio)
    lo = math.log(p * LIBRARY_OMEGA[0] / (2.0 * math.pi) / f_min) / step
    hi = math.log(p * LIBRARY_OMEGA[1] / (2.0 * math.pi) / f_min) / step
    k_lo = min(n, max(0, math.ceil(lo)))  # i < k_lo: below the grid
    k_hi = max(k_lo, min(n, max(0, math.floor(hi) + 1)))  # i >= k_hi: above it
    return _index_sum(p, f_min, ratio, 0, k_lo) + _index_sum(p, f_min, ratio, k_hi, n)


#: The envelope margin of an assessment: its pulse frequencies (f_min [Hz], f_max [Hz], n),
#: exact envelopes of every mechanism (``workflows.assess.assessment_doc``).
ASSESS_ENVELOPE = (0.1, 10.0, 120)


def envelope_steps(
    cf: ConstantsFile,
    f_min: float,
    f_max: float,
    n: int,
    *,
    p_max: float = math.inf,
    exact: bool = True,
) -> float:
    """Closed-form steps of exact envelopes of every mechanism at ``n`` frequencies.

    Sides with ``p_eq`` above ``p_max`` [rad/s] are left out. With ``exact`` False (the
    fast mode, the library's envelopes), the mechanisms computed exactly anyway
    (``directional``) and the other sides' frequencies outside the library's grid
    (``LIBRARY_OMEGA``), which the fast mode also computes exactly.
    """
    steps = sum(
        N_SCAN * d * _grid_sum(p, f_min, f_max, n)
        for p, d in mechanism_sides(cf, p_max, only_exact=not exact)
    )
    if not exact:
        steps += sum(
            N_SCAN * d * _outside_sum(p, f_min, f_max, n)
            for p, d in mechanism_sides(cf, p_max, only_other=True)
        )
    return float(steps)


def scale_factor_points(cf: ConstantsFile, f_min: float, f_max: float, n: int) -> float:
    """Grid points of the exact pulse scale factors of every mechanism with amplification data.

    Per frequency ``f_p``, ``SPECTRUM_GRID_PER_PERIOD max(1, f_n / f_p)``
    (``core.amplification.pulse_response_spectrum``: a pulse longer than the natural
    period is bracketed on that many points per natural period).
    """
    return float(
        sum(
            SPECTRUM_GRID_PER_PERIOD * _grid_sum(m.amplification.f_n, f_min, f_max, n)
            for m in cf.mechanisms
            if m.amplification is not None and _positive(m.amplification.f_n)
        )
    )


def history_steps(
    cf: ConstantsFile,
    n_samples: int,
    dt: float,
    n_scales: int,
    *,
    worst: bool = False,
    p_max: float = math.inf,
) -> float:
    """Closed-form steps of time histories of every mechanism side at every scale factor.

    With ``worst``, the steps of the longest single run (the stiffest side) instead; sides
    with ``p_eq`` above ``p_max`` [rad/s] are left out.
    """
    per_sample = [
        max(1.0, math.ceil(p * dt)) if math.isfinite(p * dt) else math.inf
        for p, _ in mechanism_sides(cf, p_max)
    ]
    if not per_sample:
        return 0.0
    per_run = max(per_sample) if worst else sum(per_sample)
    return float(max(n_samples - 1, 0) * per_run * n_scales)


def check_count(count: int, limit: int, what: str, field: str) -> None:
    """Refuse ``count`` above ``limit`` with a message naming the option, limit and lift.

    Raises
    ------
    InputError
        ``count > limit``; e.g. ``n: 10000000 frequencies exceed the limit of 500000;
        give --no-limits to lift it``.
    """
    if count > limit:
        raise InputError(
            f"{count} {what} exceed the limit of {limit}; give {NO_LIMITS} to lift it", field
        )


def check_run(
    cf: Optional[ConstantsFile] = None,
    *,
    scales: int = 0,
    record: Optional[tuple[int, float]] = None,
    records: int = 1,
    envelope: Optional[tuple[float, float, int, bool]] = None,
    periods: int = 0,
    limits: Optional[dict[str, Any]] = None,
    budget_s: Optional[float] = None,
) -> None:
    """Refuse a command-line run above the service's size limits, before any work.

    Parameters
    ----------
    cf : ConstantsFile, optional
        The mechanisms (their count and ``p_eq`` [rad/s] set the work).
    scales : int
        Scale factors (or intensity levels) per record [-].
    record : (int, float), optional
        Samples [-] and time step [s] of the record (of the longest one, with ``records``).
    records : int
        Records run at each scale (IDA) [-].
    envelope : (float, float, int, bool), optional
        ``(f_min [Hz], f_max [Hz], n, exact)`` of the envelopes.
    periods : int
        Periods of a response spectrum [-].
    limits : dict, optional
        ``DEFAULT_LIMITS`` unless given.
    budget_s : float, optional
        Work that cannot finish in this time [s] at ``RATE_MARGIN`` times the measured
        rates (``shortest_time``) is refused; by default the time limit of the run
        (``active_time_limit``).

    Raises
    ------
    InputError
        Naming the option (``n``, ``scales``, ``record``, ``constants``, ``method``), the limit
        and ``--no-limits``.
    """
    lim = DEFAULT_LIMITS if limits is None else limits
    budget_s = active_time_limit() if budget_s is None else budget_s
    if cf is not None:
        check_count(len(cf.mechanisms), lim["max_mechanisms"], "mechanisms", "constants")
    check_count(scales, lim["max_scales"], "scale factors", "scales")
    check_count(periods, lim["max_samples"], "periods", "n")
    work = {"envelope_steps": 0.0, "pulse_points": 0.0, "history_steps": 0.0}
    if envelope is not None:
        f_min, f_max, n, exact = envelope
        check_count(n, lim["max_samples"], "frequencies", "n")
        if cf is not None:
            work["envelope_steps"] = envelope_steps(
                cf, f_min, f_max, n, p_max=P_EQ_PLAUSIBLE, exact=exact
            )
            work["pulse_points"] = scale_factor_points(cf, f_min, f_max, n) if exact else 0.0
    if record is not None:
        n_samples, dt = record
        check_count(n_samples, lim["max_samples"], "record samples", "record")
        if cf is not None:
            one = history_steps(cf, n_samples, dt, 1, worst=True, p_max=P_EQ_PLAUSIBLE)
            limit = WORK_PER_SAMPLE * lim["max_samples"]
            if one > limit:
                raise InputError(
                    f"one time history would take {one:.3g} closed-form steps, over the "
                    f"limit of {limit:.3g} ({WORK_PER_SAMPLE} per sample of the largest "
                    f"record); resample the record, or give {NO_LIMITS} to lift it",
                    "record",
                )
            runs = max(scales, 1)
            steps = history_steps(cf, n_samples, dt, runs, p_max=P_EQ_PLAUSIBLE) * records
            work["history_steps"] = steps
    seconds = shortest_time(**work)
    if seconds > budget_s:
        field = "record" if record is not None else "method"
        fast = "" if record is not None else " (--fast for the library's envelopes)"
        raise InputError(
            f"the run would take {work_words(**work)}, at least {seconds:.3g} s even at "
            f"{RATE_MARGIN:g} times the rates measured on all {cores()} cores, more than "
            f"its time limit of {budget_s:g} s; ask for less work{fast}, give {TIME_LIMIT} "
            f"with more seconds, or {NO_LIMITS} to lift the limit",
            field,
        )


def _candidates(mech: Any, spec: RetrofitSpec) -> int:
    """Return the candidate tie heights of a mechanism: the spec's, or the default's at most.

    The default is the top and each level (floor, roof) of the constants' loaded elements
    (``retrofit.default_heights``); levels that merge with another or lie outside the moving
    part make it fewer, never more.
    """
    ties = spec.mechanisms.get(mech.id)
    if ties is not None and ties.heights_m is not None:
        return len(ties.heights_m)
    geo = mech.geometry if isinstance(mech.geometry, dict) else {}
    loaded = geo.get("loaded")
    elements = loaded.get("elements") if isinstance(loaded, dict) else None
    levels = [
        e
        for e in (elements if isinstance(elements, list) else [])
        if isinstance(e, dict) and e.get("kind") in ("floor", "roof") and "at_m" in e
    ]
    return 1 + len(levels)


def retrofit_checks(cf: ConstantsFile, site: SiteFile, spec: RetrofitSpec) -> int:
    """Return the code checks a retrofit plans, before any is run.

    The plan counts every mechanism as failing every check (which fail is known only once
    the checks run): per candidate tie height (the spec's, or the default's: the top and
    each level the constants' loaded elements list, at most), the
    check after the tie and, per nonlinear limit state the site gives (SLV, and SLC where
    ``hazard.limit_states`` has it), the ``RETROFIT_BISECTION_STEPS`` checks a bisection on
    the tie force takes at the least.

    Examples
    --------
    >>> from shared_schema.constants import parse_constants
    >>> from shared_schema.retrofit import parse_retrofit_spec
    >>> from shared_schema.site import parse_site
    >>> cf = parse_constants('{"mechanisms": [{"id": "W", "p_eq": 2.0, "lam": 0.1}]}')
    >>> site = parse_site('{"hazard": {"code": "NTC2018", "a_g": 0.2, "F0": 2.4,'
    ...                   ' "Tc_star": 0.3, "soil": "C", "FC": 1.35}}')
    >>> spec = parse_retrofit_spec('{"steel": {"grade": "S275", "diameters_mm": [16]},'
    ...     ' "anchorage": {"capacity_N": 6e4, "source": "test R-1"},'
    ...     ' "mechanisms": {"W": {"heights_m": [3.0, 5.0]}}}')
    >>> retrofit_checks(cf, site, spec)  # 2 heights x (1 after + 7 bisection steps, SLV)
    16
    """
    states = 1 + int("SLC" in (getattr(site.hazard, "limit_states", None) or {}))
    per_option = 1 + states * RETROFIT_BISECTION_STEPS
    total = 0
    for mech in cf.mechanisms:
        total += _candidates(mech, spec) * per_option
    return total


def retrofit_record_runs(cf: ConstantsFile, spec: RetrofitSpec) -> int:
    """Return the exact runs of one record a retrofit plans, before any is run.

    Per mechanism (every one counted as failing): its least overturning scale as it stands
    (``RETROFIT_SCALE_RUNS``) and, per candidate tie height, the ``RETROFIT_RECORD_RUNS``
    of the search on the tie force and the overturning scale with the tie.

    Examples
    --------
    >>> from shared_schema.constants import parse_constants
    >>> from shared_schema.retrofit import parse_retrofit_spec
    >>> cf = parse_constants('{"mechanisms": [{"id": "W", "p_eq": 2.0, "lam": 0.1}]}')
    >>> spec = parse_retrofit_spec('{"steel": {"grade": "S275", "diameters_mm": [16]},'
    ...     ' "anchorage": {"capacity_N": 6e4, "source": "test R-1"},'
    ...     ' "mechanisms": {"W": {"heights_m": [3.0, 5.0]}}}')
    >>> retrofit_record_runs(cf, spec)  # 73 + 2 x (20 + 73)
    259
    """
    total = 0
    for mech in cf.mechanisms:
        n = _candidates(mech, spec)
        total += RETROFIT_SCALE_RUNS + n * (RETROFIT_RECORD_RUNS + RETROFIT_SCALE_RUNS)
    return total


def retrofit_reruns(spec: RetrofitSpec) -> int:
    """Return the searches a retrofit from a scene runs after the first one.

    One with the designed ties and, with connection upgrades, one per upgrade and one with
    them all and the ties.

    Examples
    --------
    >>> from shared_schema.retrofit import parse_retrofit_spec
    >>> spec = parse_retrofit_spec('{"steel": {"grade": "S275", "diameters_mm": [16]},'
    ...     ' "anchorage": {"capacity_N": 6e4, "source": "test R-1"},'
    ...     ' "upgrades": [{"level": "roof", "tied": true}, {"walls": ["F", "L"], "to": "tied"}]}')
    >>> retrofit_reruns(spec)  # the ties, 2 upgrades, all together
    4
    """
    n = len(spec.upgrades)
    return 1 + n + (1 if n else 0)


def check_retrofit_work(
    cf: ConstantsFile,
    site: SiteFile,
    spec: RetrofitSpec,
    budget_s: float,
    how: str,
    motions: Sequence[Any] = (),
    reruns: int = 0,
) -> None:
    """Refuse a retrofit whose planned code checks cannot finish within ``budget_s`` [s].

    Parameters
    ----------
    cf, site, spec
        The retrofit's inputs (``retrofit_checks`` counts the plan).
    motions : sequence of GroundMotion
        The records: each adds ``retrofit_record_runs`` runs of its longest mechanism and,
        per code check, ``RETROFIT_RECORD_PERIODS`` periods of its response spectrum.
    reruns : int
        Searches run again after the first (from a scene: ``retrofit_reruns``), each
        counted with as many mechanisms as ``cf`` has: per mechanism one code check and,
        per record, the ``RETROFIT_SCALE_RUNS`` of its least overturning scale. The
        searches' own work is bounded by their evaluation limits.
    budget_s : float
        The time budget [s]: the service's compute timeout, the command's time limit.
    how : str
        How the user lifts or raises the budget, ending the message.

    Raises
    ------
    InputError
        Naming ``spec`` (the tie heights set the work), the count and the budget.
    """
    again = reruns * len(cf.mechanisms)
    n = retrofit_checks(cf, site, spec) + again
    runs = retrofit_record_runs(cf, spec) + again * RETROFIT_SCALE_RUNS if motions else 0
    steps = sum(history_steps(cf, m.accel.n, m.dt, 1, worst=True) * runs for m in motions)
    # With records, every code check matches each record and takes its demand (C8.7.1.2.1.8).
    spectra = float(n * sum(RETROFIT_RECORD_PERIODS * max(m.accel.n - 1, 0) for m in motions))
    seconds = shortest_time(retrofit_checks=n, history_steps=steps, spectrum_steps=spectra)
    again_words = f", {reruns} searches again" if reruns else ""
    if seconds > budget_s and steps > 0:
        raise InputError(
            f"the retrofit plans {n} code checks and {runs} exact runs of each of "
            f"{len(motions)} records{again_words} "
            f"({work_words(retrofit_checks=n, history_steps=steps, spectrum_steps=spectra)}): "
            f"at least {seconds:.3g} s even at {RATE_MARGIN:g} times the rates measured, past "
            f"the budget of {budget_s:g} s; give fewer tie heights, mechanisms, records or "
            f"upgrades, or {how}",
            "spec",
        )
    if seconds > budget_s:
        raise InputError(
            f"the retrofit plans {n} code checks ({len(cf.mechanisms)} mechanisms counted as "
            f"failing, their tie heights, {RETROFIT_BISECTION_STEPS} bisection steps per limit "
            f"state{again_words}): at least {seconds:.3g} s even at {RATE_MARGIN:g} times the "
            f"{RETROFIT_CHECKS_PER_S:g} checks/s measured, past the budget of {budget_s:g} s; "
            f"give fewer tie heights, mechanisms or upgrades, or {how}",
            "spec",
        )
