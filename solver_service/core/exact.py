"""Exact (closed-form, event-driven) integration of the linearised rocking equation.

Between impacts the motion is solved in closed form: exactly for one-sine and one-cosine
pulses, and exactly for sampled records taken as piecewise-linear acceleration. Impact,
uplift, turning-point and ``|phi|/phi_ov = 1`` times are found to machine precision
(theory §1.8, §6.3, §10; the argument that no event is missed is in ``_closed_form``).

Rules (all documented in theory §1.8 and §10):

* uplift from rest when the drive exceeds the static multiplier, ``-a_g > g lam+`` or
  ``a_g > g lam-``; the crossing time is exact;
* at an impact the angular velocity is multiplied by ``eta`` (by the restitution of the
  direction entered, ``RockingModel.eta_into``, when the two directions differ; and by
  ``phi_ov_old/phi_ov_new`` in the normalised variable, for asymmetric mechanisms);
  one-sided mechanisms rebound (``eta <= 0``) and stay on the positive side;
* **rest rule**: an impact whose outgoing speed is below ``V_REST_REL * p`` ends in rest.
  This ends Zeno sequences after finitely many impacts; the excursions it drops are
  smaller than ``V_REST_REL**2 / 2`` in ``|phi|/phi_ov``;
* **sub-resolution uplift**: an uplift followed by a return at below the rest speed in
  the same closed-form segment holds the body at rest to the end of that segment;
* after the excitation the free-rocking outcome is computed exactly (``freemotion``).

Every result carries ``error_estimate``: the propagated rounding error of the state
(a first-order covariance carried through the closed-form flow and the impact saltation
maps), times ``ERR_SAFETY``, at the time of the peak. Where first-order propagation
breaks down (near-grazing impacts, long chattering) the covariance is capped at the span
of the motion (``ERR_CAP``), so an estimate of order 1 or more means the peak is not
resolved: the trajectory is too sensitive for any double-precision integrator.
"""

from __future__ import annotations

import contextlib
import functools
import math
import threading
import time
import warnings
import weakref
from collections import OrderedDict
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any, Optional

import numpy as np
from numpy.typing import ArrayLike, NDArray

from shared_schema.errors import InputError, wrong_type
from shared_schema.rules import CRITERIA, G

from . import _kernels as _k
from ._compile import JIT, python_twins
from .excitation import Pulse, SampledAccel, accel_hint
from .integrator import V_REST_REL, Excitation, Integrator
from .jit import first_use
from .linearisation import linearisation_warnings
from .model import RockingModel, check_positive, require_model, require_models
from .result import STATUS_MESSAGES, RockingResult

__all__ = [
    "BACKENDS",
    "V_REST_REL",
    "BatchResult",
    "Cells",
    "cells_for",
    "kernels",
    "simulate",
    "simulate_batch",
    "single_threaded",
]


#: Pulses whose cells ``simulate`` keeps for reuse.
PULSE_CELLS_CACHE = 256
#: Records whose cells ``simulate`` and ``simulate_batch`` keep (the last used ones).
RECORD_CELLS_CACHE = 4
#: Default impact cap per simulation.
MAX_IMPACTS = 1_000_000
#: Kernel back ends: numba-compiled, or the same source as plain Python.
BACKENDS = ("auto", "numba", "python")
#: Closed-form segments per pulse quarter when a time series is asked for.
DENSE_PER_QUARTER = 50
#: An error estimate of the peak ratio at or above this [-] means the peak is not resolved
#: (the covariance reached its cap, ``_kernels.ERR_CAP``): the result says so.
UNRESOLVED_ERROR = 0.1
#: Most closed-form segments one run may need (``p_eq`` × duration / ``MAX_PH`` plus one per
#: cell); beyond it a run takes minutes, so the input is refused with its valid range.
MAX_SEGMENTS = 5e7
#: ``p_eq`` [rad/s] above which no masonry body is plausible (a block of half-diagonal
#: 0.1 mm); a run too long to compute names ``p_eq`` above it, the excitation below it.
P_EQ_PLAUSIBLE = 1e3
#: Largest ratio of the scaled peak ground acceleration to the uplift acceleration
#: ``g · lam`` [-]: the top of the range the extreme-case sweep verifies
#: (``benchmarks/extremes.py``); far past it every mechanism overturns at once, and the
#: closed forms lose their meaning as the numbers approach overflow.
MAX_AMPLITUDE_RATIO = 1e6
#: Most impacts kept in an impact log (``impact_log=True``); later ones are counted only.
IMPACT_LOG_CAP = 1_000_000

#: Per-thread switch of ``simulate_batch`` to the single-threaded grid (``single_threaded``).
_THREAD = threading.local()
#: Empty time-series and impact-log buffers (the kernels write nothing into them).
_NO_TRACE = np.empty((2, 0))
_NO_LOG = np.empty((4, 0))
#: ``RockingResult.method`` by back end (compiled or not).
_METHOD = {True: "exact:numba", False: "exact:python"}


def kernels(backend: str = "auto") -> ModuleType:
    """Return the kernel module for ``backend``.

    ``"numba"`` is the compiled module (an error if numba is missing); ``"python"`` is its
    pure-Python twin (``_compile.python_twins``: the same functions, uncompiled), so both
    paths run the same code; ``"auto"`` prefers numba.
    """
    if backend not in BACKENDS:
        raise InputError(f"must be one of {BACKENDS}, got {backend!r}", "backend")
    if backend == "auto":
        backend = "numba" if JIT else "python"
    if backend == "numba":
        if not JIT:
            raise InputError("numba is not installed; use backend='python'", "backend")
        return _k
    return python_twins(_k, *_k.MODULES)[_k.__name__]


@dataclass(frozen=True)
class Cells:
    """An excitation as the kernels see it (see ``_kernels`` module docstring).

    Attributes
    ----------
    data : (7, n) float
        Rows (``_kernels.CELL_ROWS``): kind (0 linear, 1 sinusoidal quarter period);
        ``c0, c1, c2`` (linear: ``a(t_start)`` [m/s²], slope [m/s³], unused; sinusoidal:
        amplitude [m/s²], circular frequency [rad/s], phase [rad]); ``t_start``, ``t_end``
        [s]; ``amax_after``, a bound on ``|a|`` from ``t_start`` to the end [m/s²].
    """

    data: NDArray[np.float64]

    @property
    def n(self) -> int:
        """Number of cells."""
        return int(self.data.shape[1])

    @property
    def t_end(self) -> float:
        """End of the excitation [s]."""
        return float(self.data[5, -1])

    @property
    def widths(self) -> NDArray[np.float64]:
        """Cell durations [s]."""
        return np.asarray(self.data[5] - self.data[4], dtype=np.float64)


def check_range(
    p_max: float, lam_min: float, cells: Cells, scale_max: float, pulse: bool, scale_field: str
) -> None:
    """Refuse up front a run the integrator cannot answer in bounded time or range.

    Parameters
    ----------
    p_max : float
        Largest ``p_eq`` of the mechanisms [rad/s].
    lam_min : float
        Smallest ``lam`` of the mechanisms [-].
    cells : Cells
        The excitation.
    scale_max : float
        Largest factor on the excitation [-].
    pulse : bool
        The excitation is a pulse (errors name ``f_p`` and ``a_p``, not the record).
    scale_field : str
        The field of the scale factors (``scale`` or ``scales``).

    Raises
    ------
    InputError
        When the run needs more than ``MAX_SEGMENTS`` closed-form segments (naming ``p_eq``
        if it is above ``P_EQ_PLAUSIBLE``, else the excitation's duration: ``f_p`` or
        ``record``); when the scaled peak is over ``MAX_AMPLITUDE_RATIO`` × ``g lam``.
    """
    data = cells.data
    duration = float(data[5, -1] - data[4, 0])
    segments = p_max * duration / _k.MAX_PH + data.shape[1]
    if segments > MAX_SEGMENTS:
        p_ok = (MAX_SEGMENTS - data.shape[1]) * _k.MAX_PH / duration
        field = "p_eq" if p_max > P_EQ_PLAUSIBLE else ("f_p" if pulse else "record")
        raise InputError(
            f"p_eq = {p_max:.4g} rad/s over {duration:.4g} s of excitation needs about "
            f"{segments:.2g} closed-form steps per run (at most {MAX_SEGMENTS:.0e}); for this "
            f"excitation p_eq must be at most {p_ok:.4g} rad/s, or the excitation shorter",
            field,
        )
    ratio = scale_max * float(data[6, 0]) / (G * lam_min)
    if ratio > MAX_AMPLITUDE_RATIO * (1.0 + 1e-9):  # the sweep's own 1e6 passes round-off
        raise InputError(
            f"the scaled peak acceleration is {ratio:.3g} times the uplift acceleration "
            f"g lam, beyond the solver's range (at most {MAX_AMPLITUDE_RATIO:.0e} times); any "
            "mechanism overturns at once at such a level",
            "a_p" if pulse else scale_field,
        )


def _record_cells(rec: SampledAccel, t_extra: float) -> Cells:
    acc = rec.acc
    times = rec.time
    data = np.zeros((7, acc.size - 1))
    data[1] = acc[:-1]
    data[2] = np.diff(acc) / rec.dt
    data[4] = times[:-1]
    data[5] = times[1:]
    data[6] = np.maximum.accumulate(np.abs(acc)[::-1])[::-1][:-1]
    return _append_rest(Cells(data), t_extra)


@functools.lru_cache(maxsize=PULSE_CELLS_CACHE)
def _pulse_cells_shared(pulse: Pulse, per_quarter: int, t_extra: float) -> Cells:
    """``_pulse_cells`` memoised for ``simulate`` (the kernels never write to the cells).

    Repeated runs of one pulse (scans over mechanisms or scales) skip building them; the
    cells are never handed to callers, who get fresh ones from ``cells_for``.
    """
    return _pulse_cells(pulse, per_quarter, t_extra)


_record_memo: OrderedDict[int, tuple[weakref.ref[SampledAccel], Cells]] = OrderedDict()
_record_memo_lock = threading.Lock()


def _record_cells_shared(rec: SampledAccel) -> Cells:
    """``_record_cells`` (no extra time) memoised for ``simulate`` and ``simulate_batch``.

    Repeated runs on one record (levels, mechanisms, scales) skip building them: a
    ``SampledAccel`` is immutable (frozen, its samples read-only). Kept for the last
    ``RECORD_CELLS_CACHE`` records, keyed by identity and checked through a weak reference
    (a reused identity is rebuilt); the kernels never write to the cells, which are never
    handed to callers, who get fresh ones from ``cells_for``.
    """
    key = id(rec)
    with _record_memo_lock:
        hit = _record_memo.get(key)
        if hit is not None and hit[0]() is rec:
            _record_memo.move_to_end(key)
            return hit[1]
    cells = _record_cells(rec, 0.0)
    with _record_memo_lock:
        _record_memo[key] = (weakref.ref(rec), cells)
        _record_memo.move_to_end(key)
        while len(_record_memo) > RECORD_CELLS_CACHE:
            _record_memo.popitem(last=False)
    return cells


def _shared_cells(excitation: Excitation, dense: bool, t_extra: float) -> Cells:
    """``cells_for`` for the solver's own use: memoised where possible, never handed out."""
    if isinstance(excitation, Pulse):
        per_quarter = DENSE_PER_QUARTER if dense else 1
        return _pulse_cells_shared(excitation, per_quarter, float(t_extra))
    if isinstance(excitation, SampledAccel) and t_extra <= 0.0:
        return _record_cells_shared(excitation)
    return cells_for(excitation, dense=dense, t_extra=t_extra)


def _pulse_cells(pulse: Pulse, per_quarter: int, t_extra: float) -> Cells:
    # Quarter periods hold every extremum of both shapes on a boundary, so the
    # acceleration is monotone in each cell (built in the kernels: a few microseconds
    # less per call than numpy on arrays this small).
    data = _k.pulse_cells(
        pulse.a_p, pulse.omega_p, pulse.phase, pulse.duration, per_quarter, float(t_extra)
    )
    return Cells(data)


def _append_rest(cells: Cells, t_extra: float) -> Cells:
    """Append ``t_extra`` seconds of zero acceleration (free motion in the time series)."""
    if t_extra <= 0.0:
        return cells
    t0 = cells.t_end
    rest = np.array([[0.0], [0.0], [0.0], [0.0], [t0], [t0 + t_extra], [0.0]])
    return Cells(np.hstack([cells.data, rest]))


def cells_for(excitation: Excitation, *, dense: bool = False, t_extra: float = 0.0) -> Cells:
    """Cells of an excitation; ``dense`` subdivides pulses for a smooth time series."""
    if isinstance(excitation, Pulse):
        return _pulse_cells(excitation, DENSE_PER_QUARTER if dense else 1, t_extra)
    if isinstance(excitation, SampledAccel):
        return _record_cells(excitation, t_extra)
    raise wrong_type(excitation, "excitation", "a Pulse or a SampledAccel", accel_hint(excitation))


def _criterion(criterion: Optional[str], excitation: Excitation) -> str:
    if criterion is None:
        return "exact" if isinstance(excitation, Pulse) else "ratio"
    if criterion not in CRITERIA:
        raise InputError(f"must be one of {CRITERIA}, got {criterion!r}", "criterion")
    return criterion


def _params(model: RockingModel) -> NDArray[np.float64]:
    pos, neg = model.positive, model.neg
    return np.array(
        [
            pos.p_eq,
            neg.p_eq,
            pos.lam,
            neg.lam,
            pos.phi_ov,
            neg.phi_ov,
            model.require_eta(),
            1.0 if model.one_sided else 0.0,
            model.eta_into(-1),
            model.eta_into(1),
        ]
    )


def _nan_to_none(value: float) -> Optional[float]:
    return None if math.isnan(value) else float(value)


def _unresolved(err: float) -> str:
    return (
        f"The peak is not resolved: its error estimate is {err:.2g} (>= "
        f"{UNRESOLVED_ERROR:g}); the motion is too sensitive to its input (near-grazing "
        "impacts or long chattering) for any double-precision integrator."
    )


def _check_start(model: RockingModel, x0: float, t_extra: float, max_impacts: int) -> None:
    """Refuse a start ``x0`` (phi/alpha), a ``t_extra`` [s] or an impact cap out of range."""
    if isinstance(x0, bool) or not (math.isfinite(float(x0)) and abs(float(x0)) < 1.0):
        raise InputError(f"must be finite with |x0| < 1, got {x0!r}", "x0")
    if model.one_sided and x0 < 0.0:
        raise InputError("must be >= 0 for one-sided rocking", "x0")
    if not (math.isfinite(float(t_extra)) and t_extra >= 0.0):
        raise InputError(f"must be finite and >= 0, got {t_extra!r}", "t_extra")
    if int(max_impacts) < 1:
        raise InputError(f"must be >= 1, got {max_impacts!r}", "max_impacts")


def _buffers(
    model: RockingModel, cells: Any, kern: Any, dense: bool, max_impacts: int, impact_log: bool
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the kernel's time-series and impact-log buffers (empty where not asked for)."""
    cap = 0
    if dense:
        p_max = max(model.positive.p_eq, model.neg.p_eq)
        n_seg = np.ceil(p_max * cells.widths / kern.MAX_PH).clip(min=1).sum()
        cap = int(n_seg) + 3 * min(max_impacts, 100_000) + 8
    trace = np.empty((2, cap)) if cap else _NO_TRACE
    n_log = min(max_impacts, IMPACT_LOG_CAP) + 2 if impact_log else 0
    log = np.empty((4, n_log)) if n_log else _NO_LOG
    return trace, log


def simulate(
    model: RockingModel,
    excitation: Excitation,
    *,
    scale: float = 1.0,
    criterion: Optional[str] = None,
    dense: bool = False,
    x0: float = 0.0,
    t_extra: float = 0.0,
    max_impacts: int = MAX_IMPACTS,
    backend: str = "auto",
    impact_log: bool = False,
) -> RockingResult:
    """Simulate one mechanism under one excitation, exactly.

    Parameters
    ----------
    model : RockingModel
        The mechanism; ``eta`` is required.
    excitation : Pulse or SampledAccel
        Ground acceleration [m/s²].
    scale : float
        Factor applied to the acceleration [-], > 0.
    criterion : {"ratio", "exact"}, optional
        Overturning verdict reported as ``overturned``; defaults to ``"exact"`` for pulses
        and ``"ratio"`` for records (theory §0.3).
    dense : bool
        Return the time series (``t``, ``ratio``): every segment end and event.
    x0 : float
        Initial ``phi/phi_ov``, released from rest [-]; ``|x0| < 1``.
    t_extra : float
        Seconds of free motion to integrate (and trace) after the excitation [s]; the
        analytic free-rocking outcome covers the time after that in any case.
    max_impacts : int
        Impact cap; reaching it gives status -1.
    backend : {"auto", "numba", "python"}
        Kernel back end (identical results up to rounding).
    impact_log : bool
        Return every impact in ``RockingResult.impacts`` (time, side, arriving and leaving
        ``x'``), up to ``IMPACT_LOG_CAP`` impacts; used to check energy at impacts.

    Returns
    -------
    RockingResult
        ``warnings`` says when the peak is not resolved (``error_estimate >=
        UNRESOLVED_ERROR``) and when the case lies where the linearised model is more than
        10 % off Housner's nonlinear block (``linearisation.linearisation_warnings``).

    Examples
    --------
    >>> from solver_service.core.excitation import Pulse
    >>> m = RockingModel.symmetric(p_eq=2.0, lam=0.2, eta=0.9)
    >>> pulse = Pulse(a_p=-0.1 * 9.80665, f_p=1.0)     # below the uplift threshold 0.2 g
    >>> simulate(m, pulse).peak_ratio
    0.0
    """
    t_start = time.perf_counter()
    if type(model) is not RockingModel:  # the common case costs nothing
        model = require_model(model)
    params = _params(model)
    if not (type(scale) is float and 0.0 < scale < math.inf):  # the common case costs nothing
        scale = check_positive(scale, "scale")
    crit = _criterion(criterion, excitation)
    _check_start(model, x0, t_extra, max_impacts)
    cells = _shared_cells(excitation, dense, t_extra)
    pos, neg = model.positive, model.neg
    check_range(
        max(pos.p_eq, neg.p_eq),
        min(pos.lam, neg.lam),
        cells,
        scale,
        isinstance(excitation, Pulse),
        "scale",
    )
    kern = kernels(backend)
    trace, log = _buffers(model, cells, kern, dense, int(max_impacts), impact_log)
    # One conversion of the output vector to Python floats (cheaper than one per field).
    compiled = first_use("simulate", backend)
    out = kern.simulate_cells_logged(
        cells.data, params, scale, float(x0), V_REST_REL, int(max_impacts), trace, log
    ).tolist()
    if compiled is not None:
        compiled()
    runtime = time.perf_counter() - t_start
    n_tr = int(out[_k.OUT_N_TRACE])
    notes = []
    err = out[_k.OUT_ERROR]
    if err >= UNRESOLVED_ERROR:
        notes.append(_unresolved(err))
    notes += linearisation_warnings(
        model, excitation.omega_p if isinstance(excitation, Pulse) else None
    )
    if out[_k.OUT_TRACE_FULL]:
        warnings.warn(
            f"time series truncated at {n_tr} points (more impacts than the buffer holds); "
            "the scalar results are complete",
            RuntimeWarning,
            stacklevel=2,
        )
    t_exceed = out[_k.OUT_T_EXCEED]
    return RockingResult(
        status=int(out[_k.OUT_STATUS]),
        peak_ratio=out[_k.OUT_PEAK],
        t_peak=out[_k.OUT_T_PEAK],
        criterion=crit,
        ratio_exceeded=not math.isnan(t_exceed),
        t_ratio_exceeded=_nan_to_none(t_exceed),
        collapsed=bool(out[_k.OUT_COLLAPSED]),
        t_collapse=_nan_to_none(out[_k.OUT_T_COLLAPSE]),
        n_impacts=int(out[_k.OUT_N_IMPACTS]),
        n_steps=int(out[_k.OUT_N_STEPS]),
        error_estimate=err,
        runtime_s=runtime,
        method=_METHOD[kern.JIT],
        t=trace[0, :n_tr].copy() if dense else None,
        ratio=trace[1, :n_tr].copy() if dense else None,
        n_uplifts=int(out[_k.OUT_N_UPLIFTS]),
        n_rests=int(out[_k.OUT_N_RESTS]),
        impacts=log[:, : int(out[_k.OUT_N_LOG])].copy() if impact_log else None,
        warnings=notes,
    )


@dataclass
class BatchResult:
    """Results of many mechanisms × many scale factors; arrays have shape (n_models, n_scales).

    Attributes
    ----------
    names : list of str
        Mechanism names, one per row.
    scales : (k,) float
        Scale factors, one per column [-].
    peak_ratio, t_peak, error_estimate : (m, k) float
        As in ``RockingResult`` [-], [s], [-].
    ratio_exceeded, collapsed, overturned : (m, k) bool
        Verdicts; ``overturned`` follows ``criterion``.
    t_ratio_exceeded, t_collapse, t_overturn : (m, k) float
        Times [s]; NaN where the event did not happen.
    n_impacts, n_steps, status : (m, k) int
        Work counters and status codes.
    criterion : str
        ``"ratio"`` or ``"exact"``.
    runtime_s : float
        Wall-clock time of the whole batch [s].
    method : str
        Integrator used.
    """

    names: list[str]
    scales: NDArray[np.float64]
    peak_ratio: NDArray[np.float64]
    t_peak: NDArray[np.float64]
    ratio_exceeded: NDArray[np.bool_]
    t_ratio_exceeded: NDArray[np.float64]
    collapsed: NDArray[np.bool_]
    t_collapse: NDArray[np.float64]
    n_impacts: NDArray[np.int64]
    n_steps: NDArray[np.int64]
    error_estimate: NDArray[np.float64]
    status: NDArray[np.int64]
    criterion: str
    runtime_s: float
    method: str

    @property
    def overturned(self) -> NDArray[np.bool_]:
        """Verdict under ``criterion``, shape (m, k)."""
        return self.ratio_exceeded if self.criterion == "ratio" else self.collapsed

    @property
    def t_overturn(self) -> NDArray[np.float64]:
        """Time of overturning under ``criterion`` [s], NaN where none; shape (m, k)."""
        return self.t_ratio_exceeded if self.criterion == "ratio" else self.t_collapse

    @classmethod
    def from_runs(
        cls, names: list[str], scales: Sequence[float], runs: list[list[RockingResult]]
    ) -> BatchResult:
        """Collect single runs (``runs[i][j]``: mechanism ``i`` at ``scales[j]``) as a batch.

        The batch kernel and ``simulate`` give the same numbers bit for bit, so a batch made
        of single runs (kept for their time series) reads exactly as a computed one.
        """
        flat = [r for row in runs for r in row]
        shape = (len(names), len(scales))

        def grid(key: str, dtype: Any = float) -> Any:
            values = [getattr(r, key) for r in flat]
            if dtype is float:
                values = [math.nan if v is None else v for v in values]
            return np.asarray(values, dtype=dtype).reshape(shape)

        return cls(
            names=list(names),
            scales=np.asarray(scales, dtype=float),
            peak_ratio=grid("peak_ratio"),
            t_peak=grid("t_peak"),
            ratio_exceeded=grid("ratio_exceeded", bool),
            t_ratio_exceeded=grid("t_ratio_exceeded"),
            collapsed=grid("collapsed", bool),
            t_collapse=grid("t_collapse"),
            n_impacts=grid("n_impacts", np.int64),
            n_steps=grid("n_steps", np.int64),
            error_estimate=grid("error_estimate"),
            status=grid("status", np.int64),
            criterion=flat[0].criterion,
            runtime_s=float(sum(r.runtime_s for r in flat)),
            method=flat[0].method,
        )

    def rows(self) -> list[dict[str, Any]]:
        """One JSON-ready dict per (mechanism, scale), mechanism-major.

        A row whose peak is not resolved (``error_estimate >= UNRESOLVED_ERROR``) says so in
        ``warnings``; the key is absent otherwise.
        """
        rows = []
        ov = self.overturned
        tov = self.t_overturn
        for i, name in enumerate(self.names):
            for j, sc in enumerate(self.scales):
                err = float(self.error_estimate[i, j])
                row: dict[str, Any] = {
                    "mechanism": name,
                    "scale": float(sc),
                    "peak_ratio": float(self.peak_ratio[i, j]),
                    "overturned": bool(ov[i, j]),
                    "t_overturn": _nan_to_none(float(tov[i, j])),
                    "ratio_exceeded": bool(self.ratio_exceeded[i, j]),
                    "collapsed": bool(self.collapsed[i, j]),
                    "n_impacts": int(self.n_impacts[i, j]),
                    "error_estimate": err,
                    "status": int(self.status[i, j]),
                    "message": STATUS_MESSAGES[int(self.status[i, j])],
                }
                if err >= UNRESOLVED_ERROR:
                    row["warnings"] = [_unresolved(err)]
                rows.append(row)
        return rows


@contextlib.contextmanager
def single_threaded() -> Iterator[None]:
    """Within this block, ``simulate_batch`` on this thread runs on this thread only.

    For callers that run many batches at once in their own threads (``ida.run_ida``): the
    kernels release the GIL, so the threads run in parallel without the compiled kernels
    starting threads of their own.
    """
    before = getattr(_THREAD, "serial", False)
    _THREAD.serial = True
    try:
        yield
    finally:
        _THREAD.serial = before


def simulate_batch(
    models: Sequence[RockingModel],
    excitation: Excitation,
    scales: ArrayLike,
    *,
    criterion: Optional[str] = None,
    max_impacts: int = MAX_IMPACTS,
    backend: str = "auto",
) -> BatchResult:
    """Simulate every mechanism at every scale factor in one compiled call.

    Parameters
    ----------
    models : sequence of RockingModel
        Mechanisms (each needs ``eta``); at least one.
    excitation : Pulse or SampledAccel
        Ground acceleration [m/s²].
    scales : array_like of float
        Scale factors [-], each finite and > 0; at least one.
    criterion, max_impacts, backend
        As in ``simulate``.

    Returns
    -------
    BatchResult
    """
    t_start = time.perf_counter()
    models = require_models(models)
    if len(models) == 0:
        raise InputError("needs at least one mechanism", "mechanisms")
    sc = np.atleast_1d(np.asarray(scales, dtype=float))
    if sc.ndim != 1 or sc.size == 0:
        raise InputError("needs at least one scale factor", "scales")
    bad = np.flatnonzero(~(np.isfinite(sc) & (sc > 0.0)))
    if bad.size:
        check_positive(float(sc[bad[0]]), f"scales[{bad[0]}]")
    params = np.stack([_params(m) for m in models])
    crit = _criterion(criterion, excitation)
    cells = _shared_cells(excitation, False, 0.0)
    check_range(
        max(max(m.positive.p_eq, m.neg.p_eq) for m in models),
        min(min(m.positive.lam, m.neg.lam) for m in models),
        cells,
        float(sc.max()),
        isinstance(excitation, Pulse),
        "scales",
    )
    kern = kernels(backend)
    grid = kern.simulate_grid_serial if getattr(_THREAD, "serial", False) else kern.simulate_grid
    compiled = first_use("batch", backend)
    out = grid(cells.data, params, sc, V_REST_REL, int(max_impacts))
    if compiled is not None:
        compiled()
    t_exc = out[..., _k.OUT_T_EXCEED]
    return BatchResult(
        names=[m.name for m in models],
        scales=sc,
        peak_ratio=out[..., _k.OUT_PEAK].copy(),
        t_peak=out[..., _k.OUT_T_PEAK].copy(),
        ratio_exceeded=~np.isnan(t_exc),
        t_ratio_exceeded=t_exc.copy(),
        collapsed=out[..., _k.OUT_COLLAPSED] != 0.0,
        t_collapse=out[..., _k.OUT_T_COLLAPSE].copy(),
        n_impacts=out[..., _k.OUT_N_IMPACTS].astype(np.int64),
        n_steps=out[..., _k.OUT_N_STEPS].astype(np.int64),
        error_estimate=out[..., _k.OUT_ERROR].copy(),
        status=out[..., _k.OUT_STATUS].astype(np.int64),
        criterion=crit,
        runtime_s=time.perf_counter() - t_start,
        method=_METHOD[kern.JIT],
    )


#: The entry satisfies the integrators' contract (mypy checks this assignment).
_CONTRACT: Integrator[RockingModel] = simulate
