"""Incremental dynamic analysis: many records × many intensities × many mechanisms.

The unit of work is one record at a block of intensity levels (``run_record``): every
mechanism at every level of the block in one compiled batch (``exact.simulate_batch``).
``run_ida`` cuts the work into tasks of (record × block of levels), enough for every worker
to get several, and runs them longest first, in-process on ``jobs`` threads (by default one
per core the process may use; the kernels release the GIL), or maps the same function over
the tasks on a dask.distributed cluster when a scheduler address is given (only plain data,
arrays and the function's import path travel to the workers). The results do not depend on
the cutting or the order: every run is independent. The fraction of records that overturn
each mechanism at each level is then fitted with a lognormal fragility curve
(``core.fragility``).

Intensity measures: ``"scale"`` (the levels are scale factors on every record, [-]) or
``"pga"`` (the levels are target peak ground accelerations [g]; each record is scaled to
them).
"""

from __future__ import annotations

import math
import os
import re
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor, as_completed
from typing import Any, Optional

import numpy as np

from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError
from shared_schema.extras import require

from .core.exact import single_threaded
from .core.fragility import fit_lognormal
from .core.model import check_positive
from .core.records import GroundMotion
from .workflows.adapter import to_rocking_model
from .workflows.documents import time_domain_mechanisms
from .workflows.scaling import Building, run_scaled

__all__ = ["IM_MEASURES", "ida_csv", "parse_levels", "run_ida", "run_record"]

#: Intensity measures and their units.
IM_MEASURES = {"scale": "-", "pga": "g"}

#: Seconds to wait for a Dask scheduler before giving up.
CONNECT_TIMEOUT_S = 10.0
#: Tasks per worker aimed at when records are cut into blocks of levels (load balance).
TASKS_PER_WORKER = 4


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
    opts = dict(options or {})
    cf = ConstantsFile.model_validate(constants)
    motion = GroundMotion.from_samples(acc, dt, name=name)
    if im == "pga":
        scales = [level / motion.pga_g for level in levels]
    else:
        scales = list(levels)
    models = [to_rocking_model(m) for m in cf.mechanisms]
    factors, batches = run_scaled(
        cf,
        models,
        motion,
        scales,
        opts.get("sf", "none"),
        Building(**opts.get("building", {})),
        opts.get("criterion"),
    )
    shape = (len(models), len(scales))
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


def _levels(levels: Sequence[float]) -> list[float]:
    if len(levels) == 0:
        raise InputError("needs at least one intensity level", "scales")
    out = [check_positive(v, f"scales[{j}]") for j, v in enumerate(levels)]
    if len(set(out)) != len(out):
        raise InputError("has repeated levels", "scales")
    return sorted(out)


def _dask_client(distributed: Any, address: str, timeout: float) -> Any:
    try:
        return distributed.Client(address, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(
            f"cannot reach the Dask scheduler at {address} within {timeout:g} s ({exc})",
            "scheduler",
        ) from exc


def level_blocks(n_records: int, n_levels: int, n_workers: int) -> list[tuple[int, int]]:
    """Cut the levels into blocks ``[lo, hi)`` so that records × blocks >= 4 × workers.

    One worker gets one block per record.

    Parameters
    ----------
    n_records, n_levels, n_workers : int
        Records, intensity levels and workers (threads or Dask worker threads), each >= 1.

    Returns
    -------
    list of (int, int)
        Contiguous blocks covering ``range(n_levels)``, sizes equal to within one level.

    Examples
    --------
    >>> level_blocks(100, 50, 2)
    [(0, 50)]
    >>> level_blocks(1, 10, 2)
    [(0, 1), (1, 2), (2, 3), (3, 5), (5, 6), (6, 7), (7, 8), (8, 10)]
    """
    if n_workers <= 1:
        return [(0, n_levels)]  # one worker: nothing to balance
    want = -(-TASKS_PER_WORKER * n_workers // max(n_records, 1))
    n_blocks = max(1, min(n_levels, want))
    bounds = [b * n_levels // n_blocks for b in range(n_blocks + 1)]
    return list(zip(bounds[:-1], bounds[1:]))


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity where the system has one)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def _run_serial(payload: dict[str, Any]) -> dict[str, Any]:
    """``run_record`` with the batch kernels confined to the calling thread."""
    with single_threaded():
        return run_record(**payload)


def _merge(parts: list[dict[str, Any]]) -> dict[str, Any]:
    """Join the results of one record's level blocks (in level order) into one result."""
    out = dict(parts[0])
    for key in ("overturned", "peak_ratio", "error_estimate", "status"):
        out[key] = np.concatenate([p[key] for p in parts], axis=1)
    out["runtime_s"] = sum(p["runtime_s"] for p in parts)
    return out


def _tasks(payloads: list[dict[str, Any]], n_workers: int) -> list[tuple[int, dict[str, Any]]]:
    """(record index, payload for one block of levels) for every task."""
    levels = payloads[0]["levels"]
    blocks = level_blocks(len(payloads), len(levels), n_workers)
    return [
        (i, {**p, "levels": p["levels"][lo:hi]})
        for i, p in enumerate(payloads)
        for lo, hi in blocks
    ]


def _longest_first(tasks: list[tuple[int, dict[str, Any]]]) -> list[int]:
    """Task indices by decreasing work (samples × levels): the longest tasks start first.

    Greedy longest-first scheduling leaves the workers at most one short task apart at the
    end, where the submission order would leave them up to one long task apart.
    """
    cost = [len(p["acc"]) * len(p["levels"]) for _, p in tasks]
    return sorted(range(len(tasks)), key=lambda k: -cost[k])


def _gather(
    tasks: list[tuple[int, dict[str, Any]]],
    n_records: int,
    finished: Callable[[], Any],
    progress: Optional[Callable[[int, int], None]],
) -> list[dict[str, Any]]:
    """Collect task results as ``finished()`` yields ``(task index, result)``; merge per record."""
    parts: list[list[Any]] = [[] for _ in range(n_records)]
    left = [0] * n_records
    for rec, _ in tasks:
        left[rec] += 1
    done = 0
    for k, result in finished():
        rec = tasks[k][0]
        parts[rec].append((k, result))
        left[rec] -= 1
        if left[rec] == 0:
            done += 1
            if progress is not None:
                progress(done, n_records)
    return [_merge([r for _, r in sorted(p, key=lambda kr: kr[0])]) for p in parts]


def _collect(
    payloads: list[dict[str, Any]],
    scheduler: Optional[str],
    progress: Optional[Callable[[int, int], None]],
    timeout: float,
    jobs: Optional[int],
) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Run the (record × level block) tasks locally or on Dask; results in record order."""
    if scheduler is None:
        n_jobs = jobs if jobs is not None else available_cores()
        tasks = _tasks(payloads, n_jobs)
        with ThreadPoolExecutor(max_workers=n_jobs) as pool:
            pending = {pool.submit(_run_serial, tasks[k][1]): k for k in _longest_first(tasks)}

            def finished_local() -> Any:
                for future in as_completed(pending):
                    yield pending[future], future.result()

            try:
                results = _gather(tasks, len(payloads), finished_local, progress)
            except BaseException:
                # Stopped (time limit, Ctrl+C): drop the queued tasks, wait for the running ones.
                pool.shutdown(wait=False, cancel_futures=True)
                raise
        return results, {"kind": "local", "jobs": n_jobs, "tasks": len(tasks)}
    # Checked before anything else touches dask: a missing extra names its install line.
    distributed = require("dask.distributed", "dask", "for ida --scheduler")
    client = _dask_client(distributed, scheduler, timeout)
    try:
        workers = client.scheduler_info().get("workers", {})
        n_workers = len(workers)
        n_threads = sum(int(w.get("nthreads", 1)) for w in workers.values()) or 1
        tasks = _tasks(payloads, n_threads)
        order = _longest_first(tasks)
        futures = [client.submit(run_record, **tasks[k][1], pure=False) for k in order]
        index = {f.key: k for k, f in zip(order, futures)}

        def finished_dask() -> Any:
            with client.as_current():
                for future in distributed.as_completed(futures):
                    yield index[future.key], future.result()

        results = _gather(tasks, len(payloads), finished_dask, progress)
    finally:
        client.close()
    backend = {"kind": "dask", "scheduler": scheduler, "n_workers": n_workers}
    return results, {**backend, "tasks": len(tasks)}


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
        Called as ``progress(records_done, n_records)``.
    timeout : float
        Seconds to wait for the scheduler [s].
    jobs : int, optional
        Threads of the local run (default: one per core this process may use,
        ``available_cores``); ignored on Dask.

    Returns
    -------
    dict
        ``intensity``, ``records``, per mechanism ``n_overturned``, ``fraction``,
        ``first_overturning_level`` (per record) and ``fragility`` (median, beta), plus
        ``runs``, ``runtime_s``, ``max_error_estimate`` and ``backend`` (``kind``, and
        ``jobs`` or the Dask ``scheduler`` and ``n_workers``, and the number of ``tasks``).

    Raises
    ------
    InputError
        No records, a bad level, an unknown ``im``, or an unreachable scheduler (field
        ``scheduler``, with the address).
    """
    if im not in IM_MEASURES:
        raise InputError(f"must be one of {list(IM_MEASURES)}, got {im!r}", "im")
    if len(motions) == 0:
        raise InputError("needs at least one record", "records")
    lv = _levels(levels)
    if jobs is not None and (isinstance(jobs, bool) or int(jobs) != jobs or jobs < 1):
        raise InputError(f"must be a whole number >= 1, got {jobs!r}", "jobs")
    building = building or Building()
    cf, skipped = time_domain_mechanisms(cf)
    for mech in cf.mechanisms:
        to_rocking_model(mech).require_eta()
    constants = cf.model_dump(mode="json", exclude_none=True)
    options = {
        "sf": sf,
        "building": {
            "height": building.height,
            "soil_factor": building.soil_factor,
            "element_period": building.element_period,
        },
        "criterion": criterion,
    }
    payloads = [
        {
            "constants": constants,
            "acc": m.accel.acc,
            "dt": m.dt,
            "name": m.name,
            "levels": lv,
            "im": im,
            "options": options,
        }
        for m in motions
    ]
    start = time.perf_counter()
    results, backend = _collect(payloads, scheduler, progress, timeout, jobs)
    wall = time.perf_counter() - start
    overturned = np.stack([r["overturned"] for r in results])  # (records, mechs, levels)
    counts = overturned.sum(axis=0)
    n_rec = len(results)
    mechanisms = []
    for i, mech in enumerate(cf.mechanisms):
        first = []
        for r in results:
            hit = np.flatnonzero(r["overturned"][i])
            first.append(lv[int(hit[0])] if hit.size else None)
        entry: dict[str, Any] = {
            "id": mech.id,
            "n_overturned": [int(c) for c in counts[i]],
            "fraction": [float(c) / n_rec for c in counts[i]],
            "first_overturning_level": first,
            "fragility": fit_lognormal(lv, counts[i], n_rec).to_dict(),
        }
        factors = [r["scale_factors"].get(mech.id) for r in results]
        if any(f is not None for f in factors):
            entry["scale_factors"] = factors
        mechanisms.append(entry)
    status = np.stack([r["status"] for r in results])
    doc: dict[str, Any] = {
        "intensity": {"measure": im, "units": IM_MEASURES[im], "levels": lv},
        "records": [
            {"name": r["name"], "pga_g": r["pga_g"], "dt_s": r["dt_s"], "n_samples": r["n_samples"]}
            for r in results
        ],
        "criterion": results[0]["criterion"],
        "method": results[0]["method"],
        "mechanisms": mechanisms,
        "runs": int(overturned.size),
        "runtime_s": wall,
        "compute_s": float(sum(r["runtime_s"] for r in results)),
        "max_error_estimate": float(max(np.max(r["error_estimate"]) for r in results)),
        "backend": backend,
    }
    if sf != "none":
        doc["scale_factor_method"] = sf
    incomplete = int(np.count_nonzero(status < 0))
    if incomplete:
        doc["incomplete_runs"] = incomplete
    if skipped:
        doc["skipped"] = skipped
    return doc


def ida_csv(doc: dict[str, Any]) -> str:
    """Return the overturned fractions as CSV: level, then one column per mechanism."""
    head = f"{doc['intensity']['measure']}_{doc['intensity']['units']}"
    lines = [head + "," + ",".join(f"fraction_{m['id']}" for m in doc["mechanisms"])]
    for j, level in enumerate(doc["intensity"]["levels"]):
        cells = [f"{m['fraction'][j]:.6g}" for m in doc["mechanisms"]]
        lines.append(f"{level:.6g}," + ",".join(cells))
    return "\n".join(lines) + "\n"


def parse_levels(text: str) -> list[float]:
    """Parse intensity levels: ``"0.1,0.2,0.5"`` or a log range ``"0.1:3:20"`` (start:stop:n).

    Raises
    ------
    InputError
        Text that is neither form, or a list with an empty item (``0.5,,1``: the position is
        named, never skipped); field ``scales``.
    """
    try:
        if ":" in text:
            lo, hi, n = text.split(":")
            count = int(n)
            if count < 2 or not (0 < float(lo) < float(hi)) or not math.isfinite(float(hi)):
                raise ValueError
            return [float(v) for v in np.geomspace(float(lo), float(hi), count)]
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
