"""Incremental dynamic analysis: many records × many intensities × many mechanisms.

The unit of work is one record at a block of intensity levels: every mechanism at every
level of the block in one compiled batch (``exact.simulate_batch``). ``run_ida`` groups
these units into **tasks of about** ``TASK_S`` **seconds** by the work estimate the size
limits already use (``workflows.limits.history_steps``, at ``TASK_STEPS_PER_S``): several
short records in one task, or one long record cut into blocks of levels. The estimate
counts every sample of every run, while a run's true cost depends on how long it rocks, so
no task is made of runs alike (``plan_tasks``): the short records are dealt into the tasks
in a snake order by cost, so that each holds a share of every kind of record, and a long
record's blocks interleave its levels. A run too small to give every worker
``TASKS_PER_WORKER`` such tasks gets shorter ones (not below ``MIN_TASK_S``), so that every
worker has work to balance. The tasks start longest first:

* **locally**, on ``jobs`` threads (by default one per core the process may use);
* **on a dask.distributed cluster**, when a scheduler address is given. The constants and
  options travel to every worker once (broadcast); each worker thread holds ``IN_FLIGHT``
  tasks, and a task's records are scattered to the worker that runs it just before it is
  sent, once per worker, and released when their tasks are done (``_DaskFeed``); a task
  carries only their keys and its block of levels. A worker that finishes gets the next
  task, so slow and fast machines share the work by their speed; a task lost with a worker
  runs again.

Either way a task runs the **single-threaded** batch kernel (it releases the GIL): a worker
that runs ``k`` tasks at once (``k`` threads) uses ``k`` cores, and workers never start
numba threads of their own on top, so they never oversubscribe the cores.

Each task **reduces its runs** before they travel back: per mechanism and level the number
of its records that overturn, per record the first level that overturns each mechanism,
the largest error estimate and the number of incomplete runs. Sums of integers, minima and
maxima are exact in any order, so the document is the same, bit for bit, on every path and
every cutting of the work (tested). The fraction of records that overturn each mechanism
at each level is then fitted with a lognormal fragility curve (``core.fragility``). The
per-run peaks come back only when asked (``peaks``): they are streamed into a Parquet file
as the tasks finish (``pyarrow``, the ``parquet`` extra), so memory holds one task's runs,
not the whole analysis.

Intensity measures: ``"scale"`` (the levels are scale factors on every record, [-]) or
``"pga"`` (the levels are target peak ground accelerations [g]; each record is scaled to
them).
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import re
import secrets
import signal
import socket
import sys
import threading
import time
import traceback
import uuid
from collections.abc import Callable, Sequence
from concurrent.futures import CancelledError, ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import numpy as np

from shared_schema.atomic import temp_name
from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError
from shared_schema.extras import require
from shared_schema.rules import IM_MEASURES, PEAKS_FILE
from shared_schema.version import __version__

from ...core.exact import single_threaded
from ...core.fragility import fit_lognormal
from ...core.model import RockingModel, check_positive
from ...core.records import GroundMotion
from ..adapter import to_rocking_model
from ..documents import time_domain_mechanisms
from ..limits import P_EQ_PLAUSIBLE, history_steps
from ..scaling import Building, run_scaled

__all__ = [
    "IM_MEASURES",
    "PEAKS_FILE",
    "Task",
    "ida_csv",
    "parse_levels",
    "plan_tasks",
    "run_ida",
    "run_record",
    "run_task",
]

#: Seconds to wait for a Dask scheduler, and for its first worker, before giving up.
CONNECT_TIMEOUT_S = 10.0
#: Work of one task aimed at [s]: per-task costs (a few ms on Dask) stay under 1 % of it.
TASK_S = 1.0
#: Shortest task aimed at [s] where a run is cut finer to balance the workers.
MIN_TASK_S = 0.2
#: Tasks per worker thread aimed at, where the run is long enough: task times vary by a
#: factor of several around the estimate, and the last tasks to finish set the run's end.
TASKS_PER_WORKER = 8
#: Closed-form steps of the work estimate (``limits.history_steps``) per second of a task
#: on one core. The estimate counts every sample of every run, while runs at rest cost a
#: fraction of a step per sample and runs that overturn stop early: on the benchmark IDA
#: (``benchmarks/cluster.py``, which prints the rate it measures) it runs at about 1e8 per
#: second on one core of the 2-core machine of docs/benchmarks.md. A slower machine gets
#: longer tasks; the results do not depend on the cutting.
TASK_STEPS_PER_S = 1.0e8
#: Address schemes of a Dask scheduler that rockmech connects to.
SCHEMES = ("tcp", "tls", "ws", "wss")
#: Rows of the peaks file gathered before they are written as one row group.
ROW_GROUP_ROWS = 1 << 20
#: Tasks a Dask worker holds per thread (one running, the next ones ready).
IN_FLIGHT = 2
#: Times a task lost with a worker is run again before the run stops.
RETRIES = 3
#: Interval at which a Dask run reads the list of workers again [s].
REFRESH_S = 1.0
#: Prepared constants kept per process (a Dask worker keeps those of its latest runs).
SETUPS_KEPT = 4
#: Dask's settings for a rockmech cluster (docs/cluster.md, "Dask's settings"), in Dask's
#: dotted keys. Dask's defaults wake every process 50 times a second to time its event loop
#: (``tick``) and sample each worker thread's stack 100 times a second (``profile``): an idle
#: 2-worker cluster took 10-14 % of a core with them, 3.4 % with these settings
#: (``benchmarks/cluster.py``). The tick only feeds the "event loop was unresponsive" warning
#: (after 3 s), which a 1 s tick still gives; the profile feeds the dashboard's profile page.
DASK_SETTINGS: dict[str, Any] = {
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.profile.enabled": False,
}


@dataclass(frozen=True)
class _Setup:
    """What every task of one run shares, prepared once per process (``_setup``)."""

    cf: ConstantsFile
    models: list[RockingModel]
    levels: list[float]
    im: str
    sf: str
    building: Building
    criterion: Optional[str]
    peaks: bool

    @classmethod
    def build(
        cls,
        constants: dict[str, Any],
        levels: Sequence[float],
        im: str,
        options: Optional[dict[str, Any]],
        peaks: bool = False,
    ) -> _Setup:
        opts = dict(options or {})
        cf = ConstantsFile.model_validate(constants)
        return cls(
            cf=cf,
            models=[to_rocking_model(m) for m in cf.mechanisms],
            levels=[float(v) for v in levels],
            im=im,
            sf=opts.get("sf", "none"),
            building=Building(**opts.get("building", {})),
            criterion=opts.get("criterion"),
            peaks=peaks,
        )


_SETUPS: dict[str, _Setup] = {}
_SETUPS_LOCK = threading.Lock()


def _setup(ctx: dict[str, Any]) -> _Setup:
    """Return the prepared constants of run ``ctx["token"]``, validated once per process."""
    with _SETUPS_LOCK:
        found = _SETUPS.get(ctx["token"])
        if found is None:
            found = _Setup.build(
                ctx["constants"], ctx["levels"], ctx["im"], ctx["options"], ctx["peaks"]
            )
            _SETUPS[ctx["token"]] = found
            while len(_SETUPS) > SETUPS_KEPT:
                del _SETUPS[next(iter(_SETUPS))]
        return found


def _run_one(
    setup: _Setup, acc: np.ndarray[Any, Any], dt: float, name: str, levels: Sequence[float]
) -> dict[str, Any]:
    """One record against every mechanism at ``levels`` (see ``run_record``)."""
    motion = GroundMotion.from_samples(acc, dt, name=name)
    if setup.im == "pga":
        scales = [level / motion.pga_g for level in levels]
    else:
        scales = list(levels)
    factors, batches = run_scaled(
        setup.cf, setup.models, motion, scales, setup.sf, setup.building, setup.criterion
    )
    shape = (len(setup.models), len(scales))
    out = {
        "overturned": np.zeros(shape, dtype=bool),
        "peak_ratio": np.zeros(shape),
        "error_estimate": np.zeros(shape),
        "status": np.zeros(shape, dtype=np.int64),
    }
    for members, batch in batches:
        for key in out:
            out[key][members] = getattr(batch, key)
    return {
        **out,
        "name": name,
        "pga_g": motion.pga_g,
        "dt_s": dt,
        "n_samples": len(acc),
        "scale_factors": {k: float(v["value"]) for k, v in factors.items()},
        "criterion": batches[0][1].criterion,
        "method": batches[0][1].method,
        "runtime_s": sum(b.runtime_s for _, b in batches),
    }


def run_record(
    constants: dict[str, Any],
    acc: np.ndarray[Any, Any],
    dt: float,
    name: str,
    levels: list[float],
    im: str = "scale",
    options: Optional[dict[str, Any]] = None,
) -> dict[str, Any]:
    """Run one record against every mechanism at every intensity level.

    Parameters
    ----------
    constants : dict
        The kinematic-constants document (``ConstantsFile.model_dump()``).
    acc : (n,) float
        Ground acceleration [m/s²].
    dt : float
        Sampling interval [s].
    name : str
        Record name.
    levels : list of float
        Intensity levels, ascending (units of ``im``).
    im : {"scale", "pga"}
        Intensity measure.
    options : dict, optional
        ``sf``, ``building`` (dict of ``analysis.Building``) and ``criterion``.

    Returns
    -------
    dict
        ``overturned``, ``peak_ratio``, ``error_estimate`` and ``status`` as (m, k) arrays
        (mechanisms × levels), ``scale_factors`` per mechanism id, ``pga_g`` and
        ``runtime_s``.
    """
    return _run_one(_Setup.build(constants, levels, im, options), acc, dt, name, levels)


def run_task(
    ctx: dict[str, Any],
    pack: Sequence[tuple[int, np.ndarray[Any, Any], float, str]],
    lo: int,
    hi: int,
    stop: Optional[threading.Event] = None,
    step: int = 1,
) -> dict[str, Any]:
    """One task: every record of ``pack`` at levels ``range(lo, hi, step)``, its runs reduced.

    Runs the single-threaded batch kernel on the calling thread, one record after the other.

    Parameters
    ----------
    ctx : dict
        The run's shared data: ``token``, ``constants`` (JSON data), ``levels`` (all of
        them, ascending), ``im``, ``options`` and ``peaks`` (bool).
    pack : sequence of (int, ndarray, float, str)
        ``(record index, acceleration [m/s²], dt [s], name)`` of each record.
    lo, hi : int
        The block of levels, ``0 <= lo < hi <= len(levels)``.
    stop : threading.Event, optional
        Set by a stopped local run: the task ends after the record it is on.
    step : int
        Every ``step``-th level of the block, >= 1 (``plan_tasks``'s interleaved blocks).

    Returns
    -------
    dict
        ``records`` (indices), ``lo``, ``hi``, ``step``, ``counts`` ((m, k) records that
        overturn, ``k`` levels in the block), ``first`` ((records, m) index of the first
        level in the block that overturns, ``len(levels)`` where none does), ``max_error``,
        ``incomplete``,
        ``factors`` (per record, only in the block that starts at level 0), ``criterion``,
        ``method``, ``peaks`` (``peak_ratio``, ``overturned``, ``error_estimate``,
        ``status`` as (records, m, k) arrays, or None) and the timing: ``kernel_s``
        (inside the batches), ``start``, ``end`` (``time.time()`` of this process) and
        ``lane`` (host, process and thread).
    """
    start = time.time()
    setup = _setup(ctx)
    levels = setup.levels[lo:hi:step]
    n_mech, none = len(setup.models), len(setup.levels)
    counts = np.zeros((n_mech, len(levels)), dtype=np.int64)
    first = np.full((len(pack), n_mech), none, dtype=np.int64)
    max_error, incomplete, kernel_s = 0.0, 0, 0.0
    factors: Optional[list[dict[str, float]]] = [] if lo == 0 else None
    peaks: dict[str, list[Any]] = {k: [] for k in ("peak_ratio", "overturned", "error_estimate")}
    peaks["status"] = []
    criterion = method = ""
    with single_threaded():
        for j, (_, acc, dt, name) in enumerate(pack):
            if stop is not None and stop.is_set():
                break
            res = _run_one(setup, acc, dt, name, levels)
            over = res["overturned"]
            counts += over
            first[j] = np.where(over.any(axis=1), lo + step * over.argmax(axis=1), none)
            max_error = float(np.maximum(max_error, np.max(res["error_estimate"])))
            incomplete += int(np.count_nonzero(res["status"] < 0))
            kernel_s += res["runtime_s"]
            criterion, method = res["criterion"], res["method"]
            if factors is not None:
                factors.append(res["scale_factors"])
            if setup.peaks:
                for key, rows in peaks.items():
                    rows.append(res[key])
    return {
        "records": [int(index) for index, *_ in pack],
        "lo": lo,
        "hi": hi,
        "step": step,
        "counts": counts,
        "first": first,
        "max_error": max_error,
        "incomplete": incomplete,
        "factors": factors,
        "criterion": criterion,
        "method": method,
        "peaks": {k: np.stack(v) for k, v in peaks.items()} if setup.peaks else None,
        "kernel_s": kernel_s,
        "start": start,
        "end": time.time(),
        "lane": f"{socket.gethostname()}:{os.getpid()}:{threading.get_ident()}",
    }


def _levels(levels: Sequence[float]) -> list[float]:
    if len(levels) == 0:
        raise InputError("needs at least one intensity level", "scales")
    out = [check_positive(v, f"scales[{j}]") for j, v in enumerate(levels)]
    if len(set(out)) != len(out):
        raise InputError("has repeated levels", "scales")
    return sorted(out)


@dataclass(frozen=True)
class Task:
    """One task of a run: the records of pack ``pack`` at levels ``range(lo, hi, step)``.

    Attributes
    ----------
    pack : int
        Index into the packs of ``plan_tasks`` (a group of records).
    lo, hi, step : int
        Its intensity levels, ``range(lo, hi, step)``: all of them (``0, n_levels, 1``) or
        one of the interleaved blocks of a long record.
    cost_s : float
        Its work by the estimate [s].
    """

    pack: int
    lo: int
    hi: int
    step: int
    cost_s: float


def task_seconds(total_s: float, n_workers: int) -> float:
    """Work per task aimed at [s] for ``total_s`` seconds of work on ``n_workers`` threads.

    ``TASK_S``, or less where that leaves fewer than ``TASKS_PER_WORKER`` tasks per worker
    thread, down to ``MIN_TASK_S``.

    Examples
    --------
    >>> task_seconds(1000.0, 16), task_seconds(32.0, 16), task_seconds(1.0, 16)
    (1.0, 0.25, 0.2)
    """
    return min(TASK_S, max(MIN_TASK_S, total_s / (TASKS_PER_WORKER * max(n_workers, 1))))


def plan_tasks(
    costs: Sequence[float], n_levels: int, task_s: float
) -> tuple[list[list[int]], list[Task]]:
    """Cut a run into tasks of about ``task_s`` seconds, each a mix of cheap and dear runs.

    The estimate (``record_costs``) counts every sample of every run, while a run's true
    cost depends on how long it rocks: runs at rest cost little, runs that overturn stop
    early, a strong record rocks the mechanisms far longer than a weak one of the same
    length. So no task is made of runs alike:

    * a record that costs more than ``task_s`` at all levels forms a pack of its own, cut
      into ``n = min(n_levels, ceil(cost / task_s))`` **interleaved** blocks of levels:
      block ``b`` holds levels ``b, b + n, b + 2n, ...`` (a contiguous block of low levels,
      all at rest, would be cheap, one of middle levels, all rocking to the end, dear);
    * the other records are dealt, by decreasing cost, into ``max(1, round(sum / task_s))``
      packs in a snake order (``0, 1, ..., P - 1, P - 1, ..., 0, 0, 1, ...``), each run at
      all levels in one task: every pack holds records from across the range of costs and
      of kinds (a set of variants of one strong record all land in one pack otherwise), and
      the packs' estimates differ by at most about one record's.

    The tasks are listed by decreasing estimate (longest first). The results do not depend
    on the cutting.

    Parameters
    ----------
    costs : sequence of float
        Estimated work of each record at all ``n_levels`` levels [s], each >= 0.
    n_levels : int
        Intensity levels, >= 1.
    task_s : float
        Work per task aimed at [s], > 0.

    Returns
    -------
    packs : list of list of int
        Record indices of each pack.
    tasks : list of Task
        Every (pack, block of levels) by decreasing ``cost_s`` (ties in pack order).

    Examples
    --------
    >>> packs, tasks = plan_tasks([0.3, 2.5, 0.4, 0.2, 0.5, 0.6], 10, 1.0)
    >>> packs
    [[1], [5, 0, 3], [4, 2]]
    >>> [(t.pack, t.lo, t.hi, t.step) for t in tasks]
    [(1, 0, 10, 1), (0, 0, 10, 3), (2, 0, 10, 1), (0, 1, 10, 3), (0, 2, 10, 3)]
    """
    order = sorted(range(len(costs)), key=lambda i: -costs[i])
    packs: list[list[int]] = []
    tasks: list[Task] = []
    short: list[int] = []
    for i in order:
        if costs[i] <= task_s:
            short.append(i)
            continue
        packs.append([i])
        n_blocks = min(n_levels, math.ceil(costs[i] / task_s))
        for b in range(n_blocks):
            share = len(range(b, n_levels, n_blocks)) / n_levels
            tasks.append(Task(len(packs) - 1, b, n_levels, n_blocks, costs[i] * share))
    if short:
        total = sum(costs[i] for i in short)
        n_packs = min(len(short), max(1, round(total / task_s)))
        dealt: list[list[int]] = [[] for _ in range(n_packs)]
        for k, i in enumerate(short):
            turn, place = divmod(k, n_packs)
            dealt[place if turn % 2 == 0 else n_packs - 1 - place].append(i)
        for pack in dealt:
            packs.append(pack)
            tasks.append(Task(len(packs) - 1, 0, n_levels, 1, sum(costs[i] for i in pack)))
    tasks.sort(key=lambda t: -t.cost_s)  # stable: ties keep their order
    return packs, tasks


def record_costs(cf: ConstantsFile, motions: Sequence[Any], n_levels: int) -> list[float]:
    """Estimated work of each record at ``n_levels`` levels [s] (``TASK_STEPS_PER_S``).

    ``history_steps`` is linear in the record's intervals (samples - 1): it is evaluated once
    per sampling interval (records mostly share a few) and scaled, not once per record.
    """
    per_interval: dict[float, float] = {}
    costs = []
    for m in motions:
        dt = float(m.dt)
        if dt not in per_interval:
            one = history_steps(cf, 2, dt, n_levels, p_max=P_EQ_PLAUSIBLE)
            per_interval[dt] = one / TASK_STEPS_PER_S
        costs.append(max(len(m.accel.acc) - 1, 0) * per_interval[dt])
    return costs


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity where the system has one)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


class _PeakWriter:
    """Per-run peaks streamed into a Parquet file, one row per record × mechanism × level.

    Written under a temporary name beside the target (``shared_schema.atomic.temp_name``)
    and renamed over it when complete; removed if the run stops.
    """

    def __init__(
        self, path: Path, records: list[str], mechanisms: list[str], levels: list[float], im: str
    ) -> None:
        self.pa = require("pyarrow", "parquet", "for the per-run peaks of ida")
        self.pq = require("pyarrow.parquet", "parquet", "for the per-run peaks of ida")
        self.path = path
        self.tmp = path.parent / temp_name(path.name, os.getpid(), secrets.token_hex(4))
        self.records = self.pa.array(records, type=self.pa.string())
        self.mechanisms = self.pa.array(mechanisms, type=self.pa.string())
        self.levels = np.asarray(levels)
        pa = self.pa
        dictionary = pa.dictionary(pa.int32(), pa.string())
        self.schema = pa.schema(
            [
                ("record", pa.int32()),
                ("record_name", dictionary),
                ("mechanism", dictionary),
                ("level", pa.float64()),
                ("peak_ratio", pa.float64()),
                ("overturned", pa.bool_()),
                ("error_estimate", pa.float64()),
                ("status", pa.int8()),
            ],
            metadata={"intensity_measure": im, "units": IM_MEASURES[im], "rockmech": __version__},
        )
        self.writer = self.pq.ParquetWriter(str(self.tmp), self.schema, compression="zstd")
        self.buffer: list[Any] = []
        self.buffered = 0
        self.rows = 0

    def add(self, part: dict[str, Any]) -> None:
        """Add the runs of one task (``run_task`` with peaks)."""
        pa, peaks = self.pa, part["peaks"]
        n_rec, n_mech, n_lev = peaks["peak_ratio"].shape
        record = np.repeat(np.asarray(part["records"][:n_rec], dtype=np.int32), n_mech * n_lev)
        mech = np.tile(np.repeat(np.arange(n_mech, dtype=np.int32), n_lev), n_rec)
        level = np.tile(self.levels[part["lo"] : part["hi"] : part["step"]], n_rec * n_mech)
        columns = [
            pa.array(record),
            pa.DictionaryArray.from_arrays(pa.array(record), self.records),
            pa.DictionaryArray.from_arrays(pa.array(mech), self.mechanisms),
            pa.array(level),
            pa.array(peaks["peak_ratio"].ravel()),
            pa.array(peaks["overturned"].ravel()),
            pa.array(peaks["error_estimate"].ravel()),
            pa.array(peaks["status"].ravel().astype(np.int8)),
        ]
        self.buffer.append(pa.Table.from_arrays(columns, schema=self.schema))
        self.buffered += record.size
        if self.buffered >= ROW_GROUP_ROWS:
            self._flush()

    def _flush(self) -> None:
        if self.buffer:
            self.writer.write_table(self.pa.concat_tables(self.buffer))
            self.rows += self.buffered
            self.buffer, self.buffered = [], 0

    def close(self) -> int:
        """Write what is left, rename the file into place; return the number of rows."""
        self._flush()
        self.writer.close()
        with open(self.tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(self.tmp, self.path)
        return self.rows

    def abort(self) -> None:
        """Close and remove the unfinished file."""
        try:
            self.writer.close()
        finally:
            self.tmp.unlink(missing_ok=True)


class _Totals:
    """The reduction of a run's tasks: counts, first levels, error estimates, timing."""

    def __init__(self, n_records: int, n_mech: int, n_levels: int, n_runs: int) -> None:
        self.counts = np.zeros((n_mech, n_levels), dtype=np.int64)
        self.first = np.full((n_records, n_mech), n_levels, dtype=np.int64)
        self.factors: list[dict[str, float]] = [{} for _ in range(n_records)]
        self.max_error = 0.0
        self.incomplete = 0
        self.kernel_s = 0.0
        self.criteria: set[str] = set()
        self.methods: set[str] = set()
        self.timing: list[tuple[str, float, float, float]] = []
        self.runs_done = 0
        self.n_runs = n_runs

    def add(self, part: dict[str, Any]) -> None:
        block, idx = slice(part["lo"], part["hi"], part["step"]), part["records"]
        self.counts[:, block] += part["counts"]
        self.first[idx] = np.minimum(self.first[idx], part["first"])
        if part["factors"] is not None:
            for i, factors in zip(idx, part["factors"]):
                self.factors[i] = factors
        self.max_error = float(np.maximum(self.max_error, part["max_error"]))
        self.incomplete += part["incomplete"]
        self.kernel_s += part["kernel_s"]
        self.criteria.add(part["criterion"])
        self.methods.add(part["method"])
        self.timing.append((part["lane"], part["start"], part["end"], part["kernel_s"]))
        self.runs_done += len(idx) * part["counts"].size

    def task_stats(self) -> dict[str, Any]:
        """Mean task time and per-task overhead [s] (see ``run_ida``)."""
        lanes: dict[str, list[tuple[float, float, float]]] = {}
        for lane, start, end, kernel in self.timing:
            lanes.setdefault(lane, []).append((start, end, kernel))
        busy = gaps = kernel_s = 0.0
        for runs in lanes.values():
            runs.sort()
            busy += sum(end - start for start, end, _ in runs)
            kernel_s += sum(k for *_, k in runs)
            gaps += sum(max(0.0, b[0] - a[1]) for a, b in zip(runs, runs[1:]))
        n = max(len(self.timing), 1)
        overhead = (busy - kernel_s + gaps) / n
        task = busy / n
        starts = [start for _, start, _, _ in self.timing] or [0.0]
        ends = [end for _, _, end, _ in self.timing] or [0.0]
        return {
            "lanes": len(lanes),
            "task_s": task,
            "overhead_per_task_s": overhead,
            "overhead_fraction": overhead / task if task > 0 else 0.0,
            "gap_per_task_s": gaps / n,
            "span_s": max(ends) - min(starts),
        }


def _check_address(address: str) -> None:
    """Refuse a scheduler address that is not ``scheme://host:port`` (or ``host:port``)."""
    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    host, colon, port = rest.rpartition(":")
    problem = ""
    if scheme not in SCHEMES:
        problem = f"unknown scheme {scheme!r} (use one of {', '.join(SCHEMES)})"
    elif not colon or not host or not port.isdigit() or not 0 < int(port) < 65536:
        problem = "it needs a host and a port number 1-65535"
    if problem:
        raise InputError(
            f"expected a Dask scheduler address like tcp://host:8786, got {address!r}: {problem}",
            "scheduler",
        )


def _dask_client(distributed: Any, address: str, timeout: float) -> Any:
    _check_address(address)
    try:
        return distributed.Client(address, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(
            f"cannot reach the Dask scheduler at {address} within {timeout:g} s ({exc})",
            "scheduler",
        ) from exc


def worker_version() -> str:
    """Return this process's rockmech version (asked of every Dask worker before a run)."""
    return __version__


def worker_settings() -> dict[str, Any]:
    """Return this process's values of the keys of ``DASK_SETTINGS`` (asked of the workers)."""
    import dask

    return {key: dask.config.get(key, None) for key in DASK_SETTINGS}


def _same_setting(value: Any, wanted: Any) -> bool:
    """Whether a Dask setting has the value wanted (times compared as seconds)."""
    if isinstance(wanted, str):
        from dask.utils import parse_timedelta

        try:
            return bool(parse_timedelta(value) == parse_timedelta(wanted))
        except (TypeError, ValueError, KeyError):
            return False
    return bool(value == wanted)


def settings_differ(client: Any) -> list[str]:
    """Return the ``DASK_SETTINGS`` the cluster's workers run otherwise, one line each.

    Empty where every worker has rockmech's settings (or where they cannot be read: the run
    goes on, this only tells how fast it could go).
    """
    try:
        found = client.run(worker_settings)
    except Exception:  # only a hint about speed: what fails here, the run itself reports
        return []
    lines = []
    for key, wanted in DASK_SETTINGS.items():
        off = [str(v[key]) for v in found.values() if not _same_setting(v[key], wanted)]
        if off:
            values = " / ".join(sorted(set(off)))
            lines.append(
                f"{key}: {values} on {len(off)} of {len(found)} workers (rockmech: {wanted})"
            )
    return lines


def _wait_for_workers(client: Any, address: str, timeout: float, left: str) -> None:
    """Wait up to ``timeout`` [s] for a worker; else an error naming ``left`` (work left)."""
    try:
        client.wait_for_workers(1, timeout=timeout)
    except (OSError, TimeoutError) as exc:
        raise InputError(
            f"no worker {'is left on' if left else 'joined'} the Dask scheduler at {address} "
            f"within {timeout:g} s{f' ({left})' if left else ''}; start workers with "
            f"`dask worker {address}`",
            "scheduler",
        ) from exc


def _cluster_threads(client: Any, address: str, timeout: float) -> tuple[int, int]:
    """(workers, threads) of the cluster, once one worker is there and all run this rockmech.

    Raises
    ------
    InputError
        No worker within ``timeout``, a worker that cannot import rockmech, or one with
        another version (field ``scheduler``).
    """
    _wait_for_workers(client, address, timeout, "")
    try:
        versions = client.run(worker_version)
    except Exception as exc:  # any failure on a worker: one line, not a traceback
        raise InputError(
            f"the Dask workers at {address} cannot run rockmech ({type(exc).__name__}: {exc}); "
            f"install rockmech {__version__} with the dask extra on every worker",
            "scheduler",
        ) from exc
    other = {w: v for w, v in versions.items() if v != __version__}
    if other:
        worker, version = sorted(other.items())[0]
        raise InputError(
            f"worker {worker} runs rockmech {version}, this machine {__version__} "
            f"({len(other)} of {len(versions)} workers differ); install the same version on "
            "every worker",
            "scheduler",
        )
    threads = client.nthreads()
    return len(threads), sum(int(n) for n in threads.values())


def _run_local(
    ctx: dict[str, Any],
    records: list[tuple[int, Any, float, str]],
    packs: list[list[int]],
    tasks: list[Task],
    jobs: int,
    on_part: Callable[[dict[str, Any]], None],
) -> None:
    """Run the tasks on ``jobs`` threads of this process, longest first."""
    stop = threading.Event()
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = [
            pool.submit(
                run_task, ctx, [records[i] for i in packs[t.pack]], t.lo, t.hi, stop, t.step
            )
            for t in tasks
        ]
        try:
            for future in as_completed(futures):
                on_part(future.result())
        except BaseException:
            # Stopped (time limit, Ctrl+C, an error): drop the queued tasks; the running ones
            # end after their current record, and the pool waits for them.
            stop.set()
            pool.shutdown(wait=False, cancel_futures=True)
            raise


class _DaskFeed:
    """Tasks fed to the workers as they free up: each holds ``IN_FLIGHT`` per thread.

    A task goes to the worker with the most free places, and its records are scattered to
    that worker just before (once per worker: the blocks of levels of a long record that
    land on the same worker share them); a finished task frees its place there, so a slow
    worker gets fewer tasks, and records are in the cluster's memory only while their tasks
    are. Workers that join during the run get tasks from then on (the list of workers is
    read again every ``REFRESH_S``).
    """

    def __init__(
        self,
        client: Any,
        distributed: Any,
        ctx: dict[str, Any],
        records: list[tuple[int, Any, float, str]],
        packs: list[list[int]],
        tasks: list[Task],
    ) -> None:
        self.client, self.distributed = client, distributed
        self.records, self.packs, self.n = records, packs, len(tasks)
        self.retries: dict[Task, int] = {}
        self.queue = list(enumerate(tasks))[::-1]  # popped from the end: longest first
        self.left = [0] * len(packs)
        for task in tasks:
            self.left[task.pack] += 1
        self.held: dict[tuple[int, str], Any] = {}  # (pack, worker) -> scattered records
        self.places: dict[str, int] = {}  # worker -> free places
        self.running: dict[str, tuple[Task, str, Any]] = {}  # key -> (task, worker, future)
        self.done = distributed.as_completed()
        self.refreshed = -math.inf
        # In a list: a dict given alone would be scattered as one key per entry.
        [self.shared] = client.scatter([ctx], broadcast=True, hash=False)

    def refresh(self) -> None:
        """Read the workers again: new ones get places, those gone lose theirs."""
        if time.monotonic() - self.refreshed < REFRESH_S:
            return
        self.refreshed = time.monotonic()
        threads = self.client.nthreads()
        for worker, n in threads.items():
            if worker not in self.places:
                self.places[worker] = IN_FLIGHT * int(n)
        for worker in set(self.places) - set(threads):
            del self.places[worker]

    def fill(self) -> None:
        """Submit tasks, longest first, while a worker has a free place."""
        while self.queue and self.places:
            worker = max(self.places, key=lambda w: self.places[w])
            if self.places[worker] <= 0:
                return
            k, task = self.queue.pop()
            held = self.held.get((task.pack, worker))
            if held is None:
                data = [self.records[i] for i in self.packs[task.pack]]
                [held] = self.client.scatter([data], workers=[worker], hash=False)
                self.held[(task.pack, worker)] = held
            future = self.client.submit(
                run_task,
                self.shared,
                held,
                task.lo,
                task.hi,
                step=task.step,
                workers=[worker],
                allow_other_workers=True,  # a worker that leaves does not strand its tasks
                pure=False,
                priority=self.n - k,
            )
            self.places[worker] -= 1
            self.running[future.key] = (task, worker, future)
            self.done.add(future)

    def finish(self, future: Any) -> Optional[dict[str, Any]]:
        """Take a finished task's result; free its place; release records no task needs.

        A task lost with a worker (its records went with it, or the worker died while
        running it) is queued again, up to ``RETRIES`` times: None is returned for it.
        """
        task, worker, _ = self.running.pop(future.key)
        if worker in self.places:
            self.places[worker] += 1
        try:
            part: dict[str, Any] = future.result()
        except (CancelledError, self.distributed.KilledWorker) as exc:
            self.held.pop((task.pack, worker), None)
            self.retries[task] = self.retries.get(task, 0) + 1
            if self.retries[task] > RETRIES:
                raise InputError(
                    f"a task was lost {RETRIES + 1} times with the workers that ran it "
                    f"({type(exc).__name__}: {exc}); check that the workers stay up",
                    "scheduler",
                ) from exc
            self.queue.append((-1, task))  # next to start, first on its worker
            self.places.pop(worker, None)  # until the next refresh finds it alive
            return None
        self.left[task.pack] -= 1
        if self.left[task.pack] == 0:
            for key in [key for key in self.held if key[0] == task.pack]:
                del self.held[key]
        return part

    def cancel(self) -> None:
        """Cancel what this run has on the cluster: its tasks and its data."""
        futures = [f for *_, f in self.running.values()] + [*self.held.values(), self.shared]
        with contextlib.suppress(Exception):  # a lost connection: the scheduler drops them
            self.client.cancel(futures, force=True)


class _Interrupts:
    """Ctrl+C and the time limit on a Dask run, taken only where they cannot cut a call in half.

    On the main thread, where SIGINT raises ``KeyboardInterrupt`` (Python's own handler) and
    where the command line's time limit (``workflows.limits.time_limit``) handles SIGALRM:
    while the client scatters, submits, takes a result or cancels, either signal is held, and
    acted on when the client next waits (``taken``), Ctrl+C first; while it waits for a task
    to finish or for a worker, it is acted on at once. An interrupt inside distributed's calls
    left half-built futures and tracebacks after the one-line message. Elsewhere (another
    thread, other handlers) nothing changes.
    """

    def __init__(self) -> None:
        self.open = False
        self.held: dict[int, Any] = {}  # signal held -> the frame it came in
        self.previous: dict[int, Any] = {}

    def __enter__(self) -> _Interrupts:
        if threading.current_thread() is not threading.main_thread():
            return self
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            self.previous[signal.SIGINT] = signal.signal(signal.SIGINT, self._handler)
        alarm = getattr(signal, "SIGALRM", None)
        if alarm is not None and callable(signal.getsignal(alarm)):
            self.previous[alarm] = signal.signal(alarm, self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        for signum, handler in self.previous.items():
            signal.signal(signum, handler)
        if exc[0] is None:  # held to the end: acted on now
            self._release()

    def _handler(self, signum: int, frame: Any) -> None:
        if self.open:
            self._act(signum, frame)
        else:
            self.held[signum] = frame

    def _act(self, signum: int, frame: Any) -> None:
        if signum == signal.SIGINT:
            raise KeyboardInterrupt
        self.previous[signum](signum, frame)  # the time limit's: raises TimeLimitExceeded

    def _release(self) -> None:
        for signum in sorted(self.held, key=lambda s: s != signal.SIGINT):  # Ctrl+C first
            frame = self.held.pop(signum)
            self._act(signum, frame)

    @contextlib.contextmanager
    def taken(self) -> Any:
        """Act on a held signal now, and on one at once while the block runs (a wait)."""
        self._release()
        self.open = True
        try:
            yield
        finally:
            self.open = False


def _completed(done: Any, stops: _Interrupts) -> Any:
    """Yield the finished futures of ``done``, taking Ctrl+C only while waiting for one."""
    futures = iter(done)
    while True:
        with stops.taken():
            future = next(futures, None)
        if future is None:
            return
        yield future


class _OnPart(Exception):
    """An error of the caller's handling of a result, carried past the connection's errors."""

    def __init__(self, error: OSError) -> None:
        super().__init__(str(error))
        self.error = error


def _run_dask(
    client: Any,
    distributed: Any,
    address: str,
    timeout: float,
    ctx: dict[str, Any],
    records: list[tuple[int, Any, float, str]],
    packs: list[list[int]],
    tasks: list[Task],
    on_part: Callable[[dict[str, Any]], None],
    stops: _Interrupts,
) -> None:
    """Run the tasks on the cluster: constants broadcast, records scattered, each once."""
    feed: Optional[_DaskFeed] = None
    try:
        with client.as_current():
            feed = _DaskFeed(client, distributed, ctx, records, packs, tasks)
            feed.refresh()
            feed.fill()
            while True:
                for future in _completed(feed.done, stops):
                    part = feed.finish(future)
                    if part is not None:
                        try:
                            on_part(part)
                        except OSError as exc:  # writing the peaks, not the connection
                            raise _OnPart(exc) from exc
                    feed.refresh()
                    feed.fill()
                if not feed.queue:
                    break
                # Tasks left and none running: the workers left (or lost tasks); wait for one.
                with stops.taken():
                    _wait_for_workers(client, address, timeout, f"{len(feed.queue)} tasks to run")
                feed.refreshed = -math.inf
                feed.refresh()
                feed.fill()
    except _OnPart as wrapped:
        if feed is not None:
            feed.cancel()
        raise wrapped.error from None
    except (OSError, TimeoutError) as exc:  # the connection to the scheduler was lost
        if feed is not None:
            feed.cancel()
        raise InputError(
            f"lost the connection to the Dask scheduler at {address} during the run ({exc})",
            "scheduler",
        ) from exc
    except BaseException:
        # Stopped (time limit, Ctrl+C, a task's error): nothing of this run stays queued
        # or running on the cluster.
        if feed is not None:
            feed.cancel()
        raise


def _drop_interrupt_noise(record: logging.LogRecord) -> bool:
    """Drop the traceback distributed logs when Ctrl+C lands inside one of its calls.

    ``distributed.utils.sync`` schedules a cancel callback that reads a variable set only
    once its call started; an interrupt before that logs a ``NameError`` traceback through
    tornado after rockmech's own one-line message. The interrupt itself is handled (the
    run's tasks are cancelled), so that log says nothing to the user.
    """
    exc = record.exc_info[1] if record.exc_info else None
    if not isinstance(exc, NameError):
        return True
    frames = traceback.extract_tb(exc.__traceback__)
    return not (frames and "distributed" in frames[-1].filename)


class _QuietHalfBuilt:
    """``sys.unraisablehook`` that drops the error of a half-built distributed object's ``__del__``.

    Ctrl+C inside ``distributed.Future.__init__`` leaves an object whose ``__del__`` raises
    ``AttributeError`` when it is collected, printed as "Exception ignored in ..." after
    rockmech's one-line message. The interrupt itself is handled; every other unraisable error
    goes to the hook there was before.
    """

    def __init__(self, previous: Callable[[Any], Any]) -> None:
        self.previous = previous

    def __call__(self, unraisable: Any) -> None:
        module = getattr(unraisable.object, "__module__", "") or ""
        if isinstance(unraisable.exc_value, AttributeError) and module.startswith("distributed"):
            return
        self.previous(unraisable)


def _collect(
    ctx: dict[str, Any],
    motions: Sequence[Any],
    costs: list[float],
    scheduler: Optional[str],
    timeout: float,
    jobs: Optional[int],
    task_s: Optional[float],
    on_part: Callable[[dict[str, Any]], None],
) -> dict[str, Any]:
    """Plan the tasks for the workers there are and run them locally or on Dask."""
    records = [(i, m.accel.acc, float(m.dt), m.name) for i, m in enumerate(motions)]
    n_levels = len(ctx["levels"])
    if scheduler is None:
        n_jobs = jobs if jobs is not None else available_cores()
        packs, tasks = plan_tasks(costs, n_levels, task_s or task_seconds(sum(costs), n_jobs))
        _run_local(ctx, records, packs, tasks, n_jobs, on_part)
        return {"kind": "local", "jobs": n_jobs, "tasks": len(tasks)}
    # Checked before anything else touches dask: a missing extra names its install line.
    distributed = require("dask.distributed", "dask", "for ida --scheduler")
    client = _dask_client(distributed, scheduler, timeout)
    # Kept for the process: the callback may run after the run has ended.
    logging.getLogger("tornado.application").addFilter(_drop_interrupt_noise)
    if not isinstance(sys.unraisablehook, _QuietHalfBuilt):
        sys.unraisablehook = _QuietHalfBuilt(sys.unraisablehook)
    with _Interrupts() as stops:
        try:
            with stops.taken():  # waits for the first worker
                n_workers, n_threads = _cluster_threads(client, scheduler, timeout)
            differ = settings_differ(client)
            packs, tasks = plan_tasks(
                costs, n_levels, task_s or task_seconds(sum(costs), n_threads)
            )
            _run_dask(
                client, distributed, scheduler, timeout, ctx, records, packs, tasks, on_part, stops
            )
        finally:
            client.close()
    backend: dict[str, Any] = {"kind": "dask", "scheduler": scheduler, "n_workers": n_workers}
    backend.update(threads=n_threads, tasks=len(tasks))
    if differ:
        backend["settings_differ"] = differ
    return backend


def _check_options(im: str, motions: Sequence[Any], jobs: Optional[int], task_s: Any) -> None:
    if im not in IM_MEASURES:
        raise InputError(f"must be one of {list(IM_MEASURES)}, got {im!r}", "im")
    if len(motions) == 0:
        raise InputError("needs at least one record", "records")
    if jobs is not None and (isinstance(jobs, bool) or int(jobs) != jobs or jobs < 1):
        raise InputError(f"must be a whole number >= 1, got {jobs!r}", "jobs")
    if task_s is not None:
        check_positive(task_s, "task_s")


def run_ida(
    cf: ConstantsFile,
    motions: Sequence[Any],
    levels: Sequence[float],
    *,
    im: str = "scale",
    sf: str = "none",
    building: Optional[Building] = None,
    criterion: Optional[str] = None,
    scheduler: Optional[str] = None,
    progress: Optional[Callable[[int, int], None]] = None,
    timeout: float = CONNECT_TIMEOUT_S,
    jobs: Optional[int] = None,
    peaks: Optional[Path] = None,
    task_s: Optional[float] = None,
) -> dict[str, Any]:
    """Incremental dynamic analysis with lognormal fragility fits, as a JSON-ready document.

    Parameters
    ----------
    cf : ConstantsFile
        The mechanisms; one without ``eta`` is left out and listed in ``skipped``.
    motions : sequence of GroundMotion
        The records, at least one.
    levels : sequence of float
        Intensity levels, each > 0 and distinct: scale factors [-] or PGAs [g] (``im``).
    im : {"scale", "pga"}
        Intensity measure.
    sf : {"none", "eq28", "ec8", "nzs"}
        Scale factor up the structure for mechanisms with amplification data (per record;
        see ``analysis.mechanism_scale_factor``).
    building : Building, optional
        For the code scale factors.
    criterion : {"ratio", "exact"}, optional
        Overturning verdict (default: ``ratio``, the method's criterion for records).
    scheduler : str, optional
        Address of a dask.distributed scheduler (``tcp://host:8786``); None runs locally.
    progress : callable, optional
        Called as ``progress(runs_done, n_runs)`` after each task.
    timeout : float
        Seconds to wait for the scheduler, and for its first worker [s].
    jobs : int, optional
        Threads of the local run (default: one per core this process may use,
        ``available_cores``); ignored on Dask, where each worker runs as many tasks at once
        as it has threads.
    peaks : Path, optional
        Parquet file to write the per-run peaks to (needs ``pyarrow``, the ``parquet``
        extra): one row per record × mechanism × level with ``record`` (index into the
        document's ``records``), ``record_name``, ``mechanism``, ``level``, ``peak_ratio``,
        ``overturned``, ``error_estimate`` and ``status``, in the order the tasks finish.
        Written under a temporary name and renamed when complete. None: the runs are
        reduced to the counts on the workers and no peak travels.
    task_s : float, optional
        Work per task aimed at [s] (default ``task_seconds``); the results do not depend
        on it.

    Returns
    -------
    dict
        ``intensity``, ``records``, per mechanism ``n_overturned``, ``fraction``,
        ``first_overturning_level`` (per record) and ``fragility`` (median, beta), plus
        ``runs``, ``runtime_s``, ``compute_s`` (inside the kernels, all tasks),
        ``max_error_estimate`` and ``backend``: ``kind``, ``jobs`` or the Dask ``scheduler``,
        ``n_workers`` and ``threads``, the number of ``tasks`` and worker threads that ran
        them (``lanes``), the mean ``task_s``, the mean ``overhead_per_task_s`` (time in a
        task outside the kernels, plus the gap before the next task on the same worker
        thread) and its ``overhead_fraction`` of the task time, the gap alone
        (``gap_per_task_s``) and ``span_s``, from the first task's start to the last one's
        end (on the workers' clocks); on Dask, ``settings_differ`` where the workers run other
        values of ``DASK_SETTINGS`` (one line each). With ``peaks``, ``peaks`` (``file``,
        ``rows``).

    Raises
    ------
    InputError
        No records, a bad level, an unknown ``im``, a bad ``jobs`` or ``task_s``, or a
        scheduler that is malformed, unreachable, without workers or with workers that run
        another rockmech (field ``scheduler``, with the address).
    MissingExtra
        ``scheduler`` without dask.distributed, ``peaks`` without pyarrow.
    """
    _check_options(im, motions, jobs, task_s)
    lv = _levels(levels)
    building = building or Building()
    cf, skipped = time_domain_mechanisms(cf)
    for mech in cf.mechanisms:
        to_rocking_model(mech).require_eta()
    names = [str(m.name) for m in motions]
    ids = [m.id for m in cf.mechanisms]
    writer = None if peaks is None else _PeakWriter(Path(peaks), names, ids, lv, im)
    ctx = {
        "token": uuid.uuid4().hex,
        "constants": cf.model_dump(mode="json", exclude_none=True),
        "levels": lv,
        "im": im,
        "options": {
            "sf": sf,
            "building": {
                "height": building.height,
                "soil_factor": building.soil_factor,
                "element_period": building.element_period,
            },
            "criterion": criterion,
        },
        "peaks": writer is not None,
    }
    totals = _Totals(len(motions), len(ids), len(lv), len(motions) * len(ids) * len(lv))

    def on_part(part: dict[str, Any]) -> None:
        totals.add(part)
        if writer is not None:
            writer.add(part)
        if progress is not None:
            progress(totals.runs_done, totals.n_runs)

    start = time.perf_counter()
    if progress is not None:
        progress(0, totals.n_runs)
    try:
        costs = record_costs(cf, motions, len(lv))
        backend = _collect(ctx, motions, costs, scheduler, timeout, jobs, task_s, on_part)
        rows = None if writer is None else writer.close()
    except BaseException:
        if writer is not None:
            writer.abort()
        raise
    wall = time.perf_counter() - start
    if totals.runs_done != totals.n_runs:  # every run is in exactly one finished task
        raise RuntimeError(f"IDA ran {totals.runs_done} of {totals.n_runs} runs")
    doc = _document(cf, motions, lv, im, totals)
    doc.update(runtime_s=wall, compute_s=totals.kernel_s)
    doc["backend"] = {**backend, **totals.task_stats()}
    if writer is not None:
        doc["peaks"] = {"file": Path(peaks or "").name, "rows": rows}
    if sf != "none":
        doc["scale_factor_method"] = sf
    if totals.incomplete:
        doc["incomplete_runs"] = totals.incomplete
    if skipped:
        doc["skipped"] = skipped
    return doc


def _document(
    cf: ConstantsFile, motions: Sequence[Any], lv: list[float], im: str, totals: _Totals
) -> dict[str, Any]:
    """Build the IDA document from the reduced runs (counts, first levels, fits)."""
    n_rec = len(motions)
    mechanisms = []
    for i, mech in enumerate(cf.mechanisms):
        counts = totals.counts[i]
        entry: dict[str, Any] = {
            "id": mech.id,
            "n_overturned": [int(c) for c in counts],
            "fraction": [float(c) / n_rec for c in counts],
            "first_overturning_level": [
                lv[int(k)] if k < len(lv) else None for k in totals.first[:, i]
            ],
            "fragility": fit_lognormal(lv, counts, n_rec).to_dict(),
        }
        factors = [f.get(mech.id) for f in totals.factors]
        if any(f is not None for f in factors):
            entry["scale_factors"] = factors
        mechanisms.append(entry)
    return {
        "intensity": {"measure": im, "units": IM_MEASURES[im], "levels": lv},
        "records": [
            {
                "name": m.name,
                "pga_g": m.pga_g,
                "dt_s": float(m.dt),
                "n_samples": len(m.accel.acc),
            }
            for m in motions
        ],
        "criterion": ", ".join(sorted(totals.criteria)),
        "method": ", ".join(sorted(totals.methods)),
        "mechanisms": mechanisms,
        "runs": totals.n_runs,
        "max_error_estimate": totals.max_error,
    }


def ida_csv(doc: dict[str, Any]) -> str:
    """Return the overturned fractions as CSV: level, then one column per mechanism."""
    head = f"{doc['intensity']['measure']}_{doc['intensity']['units']}"
    lines = [head + "," + ",".join(f"fraction_{m['id']}" for m in doc["mechanisms"])]
    for j, level in enumerate(doc["intensity"]["levels"]):
        cells = [f"{m['fraction'][j]:.6g}" for m in doc["mechanisms"]]
        lines.append(f"{level:.6g}," + ",".join(cells))
    return "\n".join(lines) + "\n"


#: Most levels a log range ``start:stop:n`` may ask for: far above any analysis (the
#: command's work limit is ``max_scales``), below a count whose list would not fit in memory.
MAX_RANGE_LEVELS = 1_000_000


def _range_levels(text: str) -> list[float]:
    """Levels of a log range ``start:stop:n``; each fault is named (issue #36).

    Examples
    --------
    >>> [round(v, 6) for v in _range_levels("0.1:10:3")]
    [0.1, 1.0, 10.0]
    """
    parts = text.split(":")
    example = "e.g. 0.1:3:20 (20 levels from 0.1 to 3)"
    if len(parts) != 3:
        raise InputError(
            f"a log range is three numbers start:stop:n, {example}; got {text!r} "
            f"({len(parts)} parts)",
            "scales",
        )
    names = ("start", "stop")
    bounds = []
    for name, part in zip(names, parts[:2]):
        try:
            value = float(part)
        except ValueError:
            raise InputError(
                f"the range's {name} {part.strip()!r} is not a number, in {text!r}; {example}",
                "scales",
            ) from None
        if not math.isfinite(value):
            raise InputError(f"the range's {name} must be finite, got {part.strip()!r}", "scales")
        bounds.append(value)
    lo, hi = bounds
    try:
        count = int(parts[2])
    except ValueError:
        raise InputError(
            f"the range's n (the number of levels, its third number) must be a whole number, "
            f"got {parts[2].strip()!r} in {text!r}; {example}",
            "scales",
        ) from None
    if count < 2:
        raise InputError(
            f"the range {text!r} asks for {count} levels: n (its third number) must be at "
            f"least 2; for one level give the level itself ({parts[0].strip()})",
            "scales",
        )
    if count > MAX_RANGE_LEVELS:
        raise InputError(
            f"the range {text!r} asks for {count} levels, more than {MAX_RANGE_LEVELS:,}; "
            "n (its third number) is the number of levels",
            "scales",
        )
    if lo <= 0.0:
        raise InputError(
            f"the range {text!r} starts at {lo:g}: a log range's start must be > 0 (levels "
            "are spaced evenly on a log scale, and log 0 is -infinity); start at the smallest "
            "intensity of interest, e.g. 0.05",
            "scales",
        )
    if lo >= hi:
        fix = (
            f"write the smaller first, {parts[1].strip()}:{parts[0].strip()}:{count}"
            if lo > hi
            else "give a stop above the start"
        )
        raise InputError(
            f"the range {text!r} starts at {lo:g} and stops at {hi:g}: the start must be "
            f"below the stop; {fix}",
            "scales",
        )
    return [float(v) for v in np.geomspace(lo, hi, count)]


def parse_levels(text: str) -> list[float]:
    """Parse intensity levels: ``"0.1,0.2,0.5"`` or a log range ``"0.1:3:20"`` (start:stop:n).

    Raises
    ------
    InputError
        Text that is neither form, a list with an empty item (``0.5,,1``: the position is
        named, never skipped), or a range whose fault is named (``_range_levels``); field
        ``scales``.
    """
    if ":" in text:
        return _range_levels(text)
    try:
        items = re.split(r"\s*,\s*|\s+", text.strip()) if text.strip() else []
        empty = [k for k, item in enumerate(items, start=1) if not item]
        if not empty:
            return [float(v) for v in items]
    except ValueError:
        raise InputError(
            f"expected a list like 0.1,0.2,0.5 or a log range start:stop:n, got {text!r}",
            "scales",
        ) from None
    # issue #25: "0.5,,1" was read as 0.5,1
    raise InputError(
        f"item {empty[0]} of {text!r} is empty; give one number between each two commas",
        "scales",
    )
