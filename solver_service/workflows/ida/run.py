"""``run_ida``: an IDA from the constants, the records and the levels to its document.

Checks the options, plans the tasks (``plan``), runs them on threads of this process
(``local``) or on a Dask cluster (``dask``), streams the peaks where asked (``peaks``) and
reduces the tasks into the document (``document``).
"""

from __future__ import annotations

import time
import uuid
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Optional

from shared_schema.constants import ConstantsFile
from shared_schema.documents.ida import IdaDocument
from shared_schema.errors import InputError
from shared_schema.rules import IM_MEASURES

from ...core.model import check_positive
from ..adapter import to_rocking_model
from ..documents import time_domain_mechanisms
from ..scaling import Building
from ..units import stamp
from .dask import CONNECT_TIMEOUT_S, run_on_cluster
from .document import Totals, ida_document
from .local import run_local
from .peaks import PeakWriter
from .plan import available_cores, plan_tasks, record_costs, task_seconds

__all__ = ["run_ida"]


def _levels(levels: Sequence[float]) -> list[float]:
    if len(levels) == 0:
        raise InputError("needs at least one intensity level", "scales")
    out = [check_positive(v, f"scales[{j}]") for j, v in enumerate(levels)]
    if len(set(out)) != len(out):
        raise InputError("has repeated levels", "scales")
    return sorted(out)


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
    if scheduler is not None:
        return run_on_cluster(ctx, records, costs, scheduler, timeout, task_s, on_part)
    n_jobs = jobs if jobs is not None else available_cores()
    n_levels = len(ctx["levels"])
    packs, tasks = plan_tasks(costs, n_levels, task_s or task_seconds(sum(costs), n_jobs))
    run_local(ctx, records, packs, tasks, n_jobs, on_part)
    return {"kind": "local", "jobs": n_jobs, "tasks": len(tasks)}


def _check_options(measure: str, motions: Sequence[Any], jobs: Optional[int], task_s: Any) -> None:
    if measure not in IM_MEASURES:
        raise InputError(f"must be one of {list(IM_MEASURES)}, got {measure!r}", "measure")
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
    measure: str = "scale",
    sf: str = "none",
    building: Optional[Building] = None,
    criterion: Optional[str] = None,
    scheduler: Optional[str] = None,
    progress: Optional[Callable[[int, int], None]] = None,
    timeout: float = CONNECT_TIMEOUT_S,
    jobs: Optional[int] = None,
    peaks: Optional[Path] = None,
    task_s: Optional[float] = None,
) -> IdaDocument:
    """Incremental dynamic analysis with lognormal fragility fits: the IDA document.

    Parameters
    ----------
    cf : ConstantsFile
        The mechanisms; one without ``eta`` is left out and listed in ``skipped``.
    motions : sequence of GroundMotion
        The records, at least one.
    levels : sequence of float
        Intensity levels, each > 0 and distinct: scale factors [-] or PGAs [g] (``measure``).
    measure : {"scale", "pga"}
        The intensity measure (the document's ``intensity.measure``).
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
    IdaDocument
        As ``rockmech ida --json`` prints it (``to_dict()``; the fields are described in
        ``shared_schema.documents.ida``): ``intensity``, ``records``, per mechanism
        (``find(id)``) ``n_overturned``, ``fraction``, ``first_overturning_level`` (per
        record) and ``fragility`` (median, beta), plus ``runs``, ``runtime_s``,
        ``compute_s`` (inside the kernels, all tasks), ``max_error_estimate`` and
        ``backend``: ``kind``, ``jobs`` or the Dask ``scheduler``, ``n_workers`` and
        ``threads``, the number of ``tasks`` and worker threads that ran them (``lanes``),
        the mean ``task_s``, the mean ``overhead_per_task_s`` (time in a task outside the
        kernels, plus the gap before the next task on the same worker thread) and its
        ``overhead_fraction`` of the task time, the gap alone (``gap_per_task_s``) and
        ``span_s``, from the first task's start to the last one's end (on the workers'
        clocks); on Dask, ``settings_differ`` where the workers run other values of
        ``DASK_SETTINGS`` (one line each). With ``peaks``, ``peaks`` (``file``, ``rows``).

    Raises
    ------
    InputError
        No records, a bad level, an unknown ``measure``, a bad ``jobs`` or ``task_s``, or a
        scheduler that is malformed, unreachable, without workers or with workers that run
        another rockmech (field ``scheduler``, with the address).
    MissingExtra
        ``scheduler`` without dask.distributed, ``peaks`` without pyarrow.
    """
    _check_options(measure, motions, jobs, task_s)
    lv = _levels(levels)
    building = building or Building()
    cf, skipped = time_domain_mechanisms(cf)
    for mech in cf.mechanisms:
        to_rocking_model(mech).require_eta()
    names = [str(m.name) for m in motions]
    ids = [m.id for m in cf.mechanisms]
    writer = None if peaks is None else PeakWriter(Path(peaks), names, ids, lv, measure)
    ctx = {
        "token": uuid.uuid4().hex,
        "constants": cf.model_dump(mode="json", exclude_none=True),
        "levels": lv,
        "measure": measure,
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
    totals = Totals(len(motions), len(ids), len(lv), len(motions) * len(ids) * len(lv))

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
    doc = ida_document(cf, motions, lv, measure, totals)
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
    return IdaDocument.model_validate(stamp(doc, "ida"))
