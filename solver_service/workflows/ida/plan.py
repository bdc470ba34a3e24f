"""Planning an IDA: the work estimate of each record and its cutting into tasks.

A task is one pack of records at a block of intensity levels (``Task``); ``plan_tasks`` deals
the records into packs by their estimated cost (``record_costs``, from the size limits'
``workflows.limits.history_steps``) so that every task holds a share of every kind of record.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from shared_schema.constants import ConstantsFile

from ..limits import P_EQ_PLAUSIBLE, history_steps

__all__ = [
    "MIN_TASK_S",
    "TASKS_PER_WORKER",
    "TASK_S",
    "TASK_STEPS_PER_S",
    "Task",
    "available_cores",
    "plan_tasks",
    "record_costs",
    "task_seconds",
]

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
