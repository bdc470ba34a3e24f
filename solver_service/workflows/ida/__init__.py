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

Modules: ``plan`` (the work estimate and the tasks), ``task`` (one task's runs and their
reduction), ``local`` (threads of this process), ``dask`` (a dask.distributed cluster),
``peaks`` (the Parquet writer), ``document`` (the reduction, the fragility fits, the CSV) and
``run`` (``run_ida``). The command line's level parsing lives with the command
(``solver_service.cli.ida``).
"""

from __future__ import annotations

from shared_schema.rules import IM_MEASURES, PEAKS_FILE

from .dask import CONNECT_TIMEOUT_S, DASK_SETTINGS
from .document import ida_csv
from .plan import (
    MIN_TASK_S,
    TASK_S,
    TASK_STEPS_PER_S,
    Task,
    available_cores,
    plan_tasks,
    record_costs,
    task_seconds,
)
from .run import run_ida
from .task import run_record, run_task

__all__ = [
    "CONNECT_TIMEOUT_S",
    "DASK_SETTINGS",
    "IM_MEASURES",
    "MIN_TASK_S",
    "PEAKS_FILE",
    "TASK_S",
    "TASK_STEPS_PER_S",
    "Task",
    "available_cores",
    "ida_csv",
    "plan_tasks",
    "record_costs",
    "run_ida",
    "run_record",
    "run_task",
    "task_seconds",
]
