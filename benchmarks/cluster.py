"""IDA on one thread, on in-process threads and on Dask at 1, 2, ... workers: parallel efficiency.

What is measured
----------------
One IDA, ``N_RECORDS`` records × ``N_LEVELS`` scale factors (0.1-5) × the ten example
mechanisms of ``records_speed.mechanisms`` (10^6 runs; the records are the real ones of
``records_speed.derived_records``, stretched, negated and reversed), ratio criterion, run
through ``run_ida`` on every path:

1. one thread (``jobs=1``), cut as the planner cuts it for ``MODEL_WORKERS`` workers (the
   results do not depend on the cutting; the per-task times feed the model below);
2. in-process threads, one per core (``jobs=cores``);
3. a dask.distributed ``LocalCluster`` of 1, 2, ... worker processes (up to the cores), one
   thread each, with rockmech's Dask settings (``ida.DASK_SETTINGS``, as docs/cluster.md
   sets them up), started before the timing and warmed up (kernels loaded) by a small run;
4. the same on all the cores with Dask's default settings, for comparison.

After each Dask case the cluster is left idle ``IDLE_S`` seconds and the CPU time Dask's
processes take meanwhile (their background work: event-loop ticks, heartbeats, profiler) is
measured.

Each case runs ``REPEATS`` times (``--repeats``) and the best wall time is kept: the machine may
be shared.
Printed per case: wall time, CPU time (this process, plus the Dask workers' own, read with
``resource.getrusage`` on each worker), parallel efficiency ``t(1 thread) / (n t(n))``, the
number of tasks, the mean task time and the per-task overhead (``run_ida``'s
``backend``: time in a task outside the kernels plus the gap before the next task on that
worker thread) as a fraction of the task time. Every result must equal the one-thread one
(counts bit for bit, fits identical).

The overhead model
------------------
No 16-core machine is at hand here, so Dask on ``MODEL_WORKERS`` workers is predicted from
inputs measured in this run: the time of every task of the ``MODEL_WORKERS``-worker cutting
on one thread (the CPU time of this process between the progress calls of case 1, taken in
the order the tasks are submitted, times the one-thread run's wall time over its CPU time:
1 on a quiet machine; on a shared one the waits for a core are thus spread evenly over the
tasks, like the waits in the other inputs, where the wall time between the calls lays them
on whichever task ran while another session was busy), the gap between tasks on a Dask worker
thread (``gap_per_task_s`` of the 2-worker run) and the fixed cost of a Dask run (its wall
time less the span from its first task's start to its last task's end: connecting, checking
the workers, broadcasting the constants, scattering the records, gathering the last result).
The tasks are list-scheduled, longest first as ``run_ida`` submits them, on
``MODEL_WORKERS`` lanes, each taking its measured time plus the gap, stretched by the
background CPU per worker of the all-core cluster (its idle CPU over its number of workers:
the scheduler's share is thus counted once per worker, an upper bound); the fixed cost is
added. Threads on the same machine get the same schedule with the local gap and fixed cost.
On Dask, lane ``j`` starts only once the client has sent it its first task, ``(j + 1)``
times the client's time to scatter one task's records (measured), and no task starts before
it is sent. As the model gives every lane a core of its own, it leaves out what the cores
share (memory bandwidth, the clock a chip holds with all cores busy) and, for threads, the
GIL, which the Python part of each task (its time outside the kernels) holds: the threads'
time is also bounded below by the sum of those parts, printed beside.

Run ``.venv/bin/python benchmarks/cluster.py`` to rewrite the ``cluster`` section of
``docs/benchmarks.md``; ``--quick`` is a smoke run (40 records) that prints the section
and writes nothing;
``--repeats 1`` runs each case once (a busy machine, a quick look).
"""

from __future__ import annotations

import argparse
import heapq
import os
import sys
import time
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from _docs import (  # noqa: E402  (benchmarks/ is not a package)
    DOC_MD,
    fmt_time,
    load_average,
    machine_info,
    md_table,
    text_table,
    write_section,
)
from records_speed import autogroup, derived_records, mechanisms  # noqa: E402

N_RECORDS = 2000
N_LEVELS = 50
REPEATS = 3
#: Workers the overhead model predicts for.
MODEL_WORKERS = 16
#: Targets: Dask on all cores within this factor of the threads; overhead per task.
TARGET_DASK_VS_THREADS = 1.10
TARGET_OVERHEAD = 0.05
#: Targets of the model: efficiency against one thread on ``MODEL_WORKERS`` workers.
TARGET_MODEL_EFFICIENCY = 0.75
#: Load average (1 min, per core) at the start above which the machine is called shared.
SHARED_LOAD = 0.5
#: Seconds the Dask cluster is left idle to measure its own background CPU.
IDLE_S = 5.0
#: What must not differ between two runs of the same IDA.
RESULT_KEYS = ("intensity", "records", "criterion", "mechanisms", "runs", "max_error_estimate")


def cpu_seconds(client: Any = None) -> float:
    """CPU time [s] of this process, plus that of every Dask worker of ``client``."""
    import resource

    own = resource.getrusage(resource.RUSAGE_SELF)
    total = own.ru_utime + own.ru_stime
    if client is not None:
        total += sum(client.run(_worker_cpu).values())
    return total


def _worker_cpu() -> float:
    import resource

    use = resource.getrusage(resource.RUSAGE_SELF)
    return use.ru_utime + use.ru_stime


def best_run(
    run: Callable[[Optional[Callable[[int, int], None]]], Any],
    client: Any = None,
    trace: bool = False,
    repeats: int = REPEATS,
) -> dict[str, Any]:
    """Run ``repeats`` times; return the fastest: its document, wall and CPU time, load.

    With ``trace``, also the (wall time, CPU time of this process, runs done) of every
    progress call of that run.
    """
    best: dict[str, Any] = {}
    for _ in range(repeats):
        calls: list[tuple[float, float, int]] = []

        def note(done: int, total: int, calls: list[tuple[float, float, int]] = calls) -> None:
            calls.append((time.perf_counter(), time.process_time(), done))

        before = load_average()
        c0 = cpu_seconds(client)
        t0 = time.perf_counter()
        doc = run(note if trace else None)
        wall = time.perf_counter() - t0
        cpu = cpu_seconds(client) - c0
        doc = doc.to_dict()  # the IDA document's JSON form, as ida.json holds it
        if not best or wall < best["wall"]:
            best = {"doc": doc, "wall": wall, "cpu": cpu, "load": f"{before} / {load_average()}"}
            best["calls"] = calls
    return best


def task_times(calls: list[tuple[float, float, int]], clock: int = 1) -> list[float]:
    """Return the times of a one-thread run's tasks, from its progress calls, in run order [s].

    ``clock`` 1: CPU time of the process (the one thread's: the main thread waits); 0: wall.
    """
    return [b[clock] - a[clock] for a, b in zip(calls, calls[1:])]


def list_schedule(durations: list[float], lanes: int, feed_s: float = 0.0) -> float:
    """Return the makespan [s] of list scheduling ``durations``, in order, on ``lanes`` lanes.

    Lane ``j`` gets its first task ``(j + 1) feed_s`` after the start (the client sends the
    first tasks one by one), and no task starts before the client has sent it.
    """
    heap = [(j + 1) * feed_s for j in range(lanes)]
    heapq.heapify(heap)
    for k, d in enumerate(durations):
        free = heapq.heappop(heap)
        heapq.heappush(heap, max(free, (k + 1) * feed_s) + d)
    return max(heap)


def feed_seconds(client: Any, records: list[Any], packs: list[list[int]]) -> float:
    """Return the client's time to scatter one task's records to a worker [s] (mean of 20)."""
    worker = next(iter(client.nthreads()))
    sample = packs[: min(20, len(packs))]
    t0 = time.perf_counter()
    for pack in sample:
        data = [(i, records[i].accel.acc, float(records[i].dt), records[i].name) for i in pack]
        [future] = client.scatter([data], workers=[worker], hash=False)
        del future
    return (time.perf_counter() - t0) / len(sample)


def main(argv: Optional[list[str]] = None) -> int:
    # long: one benchmark run end to end: the cases, the model, the tables and the section
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--quick",
        action="store_true",
        help="smoke run: 40 records, section printed, nothing written",
    )
    ap.add_argument("--repeats", type=int, default=REPEATS, help="runs per case (best kept)")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error(f"--repeats: must be >= 1, got {args.repeats}")
    repeats = args.repeats
    import dask
    from distributed import Client, LocalCluster

    from solver_service.workflows.ida import (
        DASK_SETTINGS,
        TASK_STEPS_PER_S,
        available_cores,
        plan_tasks,
        record_costs,
        run_ida,
        task_seconds,
    )

    n_rec = 40 if args.quick else N_RECORDS
    cores = available_cores()
    shared = os.getloadavg()[0] > SHARED_LOAD * cores  # before this script's own load
    info = machine_info(("numpy", "numba", "distributed"))
    records = derived_records(n_rec)
    cf = mechanisms()
    levels = [float(v) for v in np.geomspace(0.1, 5.0, N_LEVELS)]
    lengths = [len(r.accel.acc) for r in records]
    n_runs = n_rec * N_LEVELS * len(cf.mechanisms)
    costs = record_costs(cf, records, N_LEVELS)
    model_task_s = task_seconds(sum(costs), MODEL_WORKERS)
    model_packs, model_tasks = plan_tasks(costs, N_LEVELS, model_task_s)
    print(
        f"{n_rec} records ({min(lengths)}-{max(lengths)} samples) x {N_LEVELS} levels x "
        f"{len(cf.mechanisms)} mechanisms = {n_runs} runs; {cores} cores; best of {repeats}"
    )

    run_ida(cf, records[:2], levels[:2], jobs=1)  # kernels loaded or compiled
    one = best_run(
        lambda note: run_ida(cf, records, levels, jobs=1, task_s=model_task_s, progress=note),
        trace=True,
        repeats=repeats,
    )
    t1 = one["wall"]
    rate = sum(costs) * TASK_STEPS_PER_S / one["cpu"]  # estimated steps per CPU second
    print(f"1 thread: {fmt_time(t1)}; work estimate ran at {rate:.3g} steps/s")
    rows: list[dict[str, Any]] = [{"case": "1 thread (jobs=1)", "n": 1, **one}]
    threads = best_run(lambda note: run_ida(cf, records, levels, jobs=cores), repeats=repeats)
    rows.append({"case": f"in-process threads (jobs={cores})", "n": cores, **threads})
    print(f"threads: {fmt_time(threads['wall'])}")
    cases = [(n, DASK_SETTINGS) for n in range(1, cores + 1)] + [(cores, {})]
    for n, settings in cases:
        with (
            dask.config.set(settings),  # the nannies hand the settings to their workers
            LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None
            ) as cluster,
            Client(cluster, set_as_default=False) as client,
        ):
            address = cluster.scheduler_address
            run_ida(cf, records[:n], levels[:2], scheduler=address)  # warm every worker
            dask_run = best_run(
                lambda note, a=address: run_ida(cf, records, levels, scheduler=a),
                client,
                repeats=repeats,
            )
            if settings:
                feed_s = feed_seconds(client, records, model_packs)
            c0 = cpu_seconds(client)
            time.sleep(IDLE_S)
            case = f"Dask, {n} worker{'s' * (n > 1)} x 1 thread"
            if not settings:
                case += ", Dask's default settings"
            idle = (cpu_seconds(client) - c0) / IDLE_S  # Dask's CPU left idle, in cores
        rows.append({"case": case, "n": n, "idle": idle, **dask_run})
        print(f"{case}: {fmt_time(dask_run['wall'])}; idle CPU {100 * idle:.1f} % of a core")

    same = all(r["doc"][k] == one["doc"][k] for r in rows for k in RESULT_KEYS if k in one["doc"])
    dask_all, dask_default = rows[-2], rows[-1]
    local_backend = threads["doc"]["backend"]
    dask_backend = dask_all["doc"]["backend"]

    # The model: the one-thread run's tasks (cut for MODEL_WORKERS) on MODEL_WORKERS lanes:
    # their CPU times, each stretched by the run's waits for a core (none on a quiet machine).
    stretch = t1 / one["cpu"]
    cpu_times = task_times(one["calls"])
    durations = [stretch * d for d in cpu_times]
    walls = task_times(one["calls"], clock=0)
    assert len(durations) == len(model_tasks), (len(durations), len(model_tasks))
    spread = float(np.std(durations) / np.mean(durations))
    python_s = one["doc"]["runtime_s"] - one["doc"]["compute_s"]
    fixed_dask = dask_all["wall"] - dask_backend["span_s"]
    fixed_local = threads["wall"] - local_backend["span_s"]
    gap_dask, gap_local = dask_backend["gap_per_task_s"], local_backend["gap_per_task_s"]
    # Dask's background CPU per worker, stretching every task on its core.
    bg = dask_all["idle"] / dask_all["n"]
    bg_default = dask_default["idle"] / dask_default["n"]

    def dask_model(times: list[float], background: float) -> float:
        lanes = [(1 + background) * d + gap_dask for d in times]
        return float(fixed_dask + list_schedule(lanes, MODEL_WORKERS, feed_s))

    t_model_dask = dask_model(durations, bg)
    span_dask = t_model_dask - fixed_dask
    # What Dask adds over threads in the model: its background CPU, its fixed cost, and the
    # rest (the gaps between tasks and the client's feeding of the first ones).
    extra_bg = t_model_dask - dask_model(durations, 0.0)
    span_local = list_schedule([d + gap_local for d in durations], MODEL_WORKERS)
    t_model_threads = fixed_local + span_local
    eff_model = t1 / (MODEL_WORKERS * t_model_dask)
    # The same model with Dask's default settings (their background CPU; the same gaps).
    t_model_default = dask_model(durations, bg_default)
    eff_default = t1 / (MODEL_WORKERS * t_model_default)
    # The same model on the tasks' wall times (the model's input before #30's even cutting).
    t_wall_dask = dask_model(walls, bg)
    eff_wall = t1 / (MODEL_WORKERS * t_wall_dask)

    table = []
    for r in rows:
        backend = r["doc"]["backend"]
        eff = t1 / (r["n"] * r["wall"])
        table.append(
            [
                r["case"],
                fmt_time(r["wall"]),
                f"{fmt_time(r['cpu'])} ({r['cpu'] / one['cpu']:.2f})",
                f"{100 * eff:.0f} %",
                f"{backend['tasks']} x {fmt_time(backend['task_s'])}",
                f"{100 * backend['overhead_fraction']:.2f} %",
                f"{100 * r['idle']:.1f} %" if "idle" in r else "-",
                r["load"],
            ]
        )
    headers = [
        "case",
        "wall",
        "CPU (/ 1 thread)",
        "parallel efficiency",
        "tasks x mean time",
        "overhead per task",
        "Dask's CPU, idle",
        "load before / after",
    ]
    ratio = dask_all["wall"] / threads["wall"]
    ratio_default = dask_default["wall"] / threads["wall"]
    verdicts = [
        [
            f"Dask {cores} workers vs threads (jobs={cores}), wall",
            f"{ratio:.3f}",
            f"<= {TARGET_DASK_VS_THREADS:.2f}",
            "PASS" if ratio <= TARGET_DASK_VS_THREADS else "FAIL",
        ],
        [
            f"per-task overhead, Dask {cores} workers",
            f"{100 * dask_backend['overhead_fraction']:.2f} % of "
            f"{fmt_time(dask_backend['task_s'])}",
            f"< {100 * TARGET_OVERHEAD:.0f} %",
            "PASS" if dask_backend["overhead_fraction"] < TARGET_OVERHEAD else "FAIL",
        ],
        [
            f"model: Dask {MODEL_WORKERS} workers, efficiency vs 1 thread",
            f"{100 * eff_model:.0f} % ({fmt_time(t_model_dask)})",
            f">= {100 * TARGET_MODEL_EFFICIENCY:.0f} %",
            "PASS" if eff_model >= TARGET_MODEL_EFFICIENCY else "FAIL",
        ],
        [
            f"model: Dask vs threads, {MODEL_WORKERS} cores",
            f"{fmt_time(t_model_dask)} vs {fmt_time(t_model_threads)} (GIL bound "
            f"{fmt_time(python_s)})",
            "Dask not slower",
            "PASS" if t_model_dask <= max(t_model_threads, python_s) else "FAIL",
        ],
        ["results identical on every path", "-", "bit for bit", "PASS" if same else "FAIL"],
    ]
    vheaders = ["check", "measured", "target", "verdict"]
    print(text_table(headers, table))
    print(text_table(vheaders, verdicts))
    model_lines = [
        f"one thread, {len(durations)} tasks cut for {MODEL_WORKERS} workers "
        f"({fmt_time(model_task_s)} each by the estimate), CPU time x {stretch:.2f} (the "
        f"one-thread run's wall {fmt_time(t1)} / CPU {fmt_time(one['cpu'])}): "
        f"{fmt_time(min(durations))} to {fmt_time(max(durations))}, mean "
        f"{fmt_time(float(np.mean(durations)))}, coefficient of variation {spread:.2f}, sum "
        f"{fmt_time(sum(durations))} (wall time between the progress calls: "
        f"{fmt_time(min(walls))} to {fmt_time(max(walls))})",
        f"gap between tasks on a worker thread: Dask {fmt_time(gap_dask)}, threads "
        f"{fmt_time(gap_local)}",
        f"fixed cost of a run: Dask {fmt_time(fixed_dask)}, threads {fmt_time(fixed_local)}",
        f"client's time to send one task's records to a worker: {fmt_time(feed_s)} (the "
        f"first task of worker j starts (j + 1) times that after the start; the client can "
        f"send {1 / feed_s:.0f} tasks/s, the {MODEL_WORKERS} workers need "
        f"{MODEL_WORKERS / float(np.mean(durations)):.0f})",
        f"Python outside the kernels (holds the GIL), all tasks: {fmt_time(python_s)}",
        f"Dask's own background CPU (event-loop ticks, heartbeats, the workers' profilers; "
        f"the {cores}-worker cluster left idle {IDLE_S:g} s): {100 * dask_all['idle']:.1f} % "
        f"of a core with rockmech's settings, {100 * bg:.2f} % per worker, "
        f"{fmt_time(dask_all['idle'] * dask_all['wall'])} over the {cores}-worker run (its "
        f"extra CPU over one thread: {fmt_time(dask_all['cpu'] - one['cpu'])}); "
        f"{100 * dask_default['idle']:.1f} % with Dask's defaults, "
        f"{100 * bg_default:.2f} % per worker",
        f"Dask's default settings: {cores} workers against threads {ratio_default:.3f} (wall "
        f"{fmt_time(dask_default['wall'])}); the model for {MODEL_WORKERS} workers "
        f"{fmt_time(t_model_default)}, efficiency {100 * eff_default:.0f} %",
        f"Dask over threads in the model, {fmt_time(t_model_dask - t_model_threads)}: its "
        f"background CPU {fmt_time(extra_bg)}, its fixed cost {fmt_time(fixed_dask - fixed_local)}"
        f", the gaps between tasks and the feeding of the first ones "
        f"{fmt_time(t_model_dask - t_model_threads - extra_bg - fixed_dask + fixed_local)}",
        f"list schedule on {MODEL_WORKERS} lanes: Dask {fmt_time(span_dask)} + "
        f"{fmt_time(fixed_dask)} = {fmt_time(t_model_dask)}; threads {fmt_time(span_local)} "
        f"+ {fmt_time(fixed_local)} = {fmt_time(t_model_threads)}",
        f"the same model on the wall times between the progress calls (each task charged "
        f"the waits for a core that fell in it): {fmt_time(t_wall_dask)}, efficiency "
        f"{100 * eff_wall:.0f} %",
        f"work estimate's rate on this machine: {rate:.3g} steps/s (TASK_STEPS_PER_S = "
        f"{TASK_STEPS_PER_S:.3g})",
    ]
    print("\n".join(model_lines))
    options = "" if repeats == REPEATS else f" --repeats {repeats}"
    lines = [
        "## IDA on threads and on Dask: parallel efficiency, per-task overhead, the model",
        "",
        f"`.venv/bin/python benchmarks/cluster.py{options}` "
        f"({info['date']}, commit {info['commit']}; {info['cpu']}, {info['nproc']} cores, "
        f"load {info['load']}; numba {info['numba']}, distributed {info['distributed']}).",
        "",
        f"{n_rec} records ({min(lengths)}-{max(lengths)} samples, the real records stretched "
        f"0.6-1.6, negated and reversed) x {N_LEVELS} scale factors (0.1-5) x "
        f"{len(cf.mechanisms)} example mechanisms = {n_runs:,} runs, ratio criterion. Best "
        f"of {repeats} run{'s' * (repeats > 1)} per case. "
        + (
            "**The machine was shared** with other sessions while this ran (the load "
            "averages are in the table): wall times and efficiencies are lower than a quiet "
            "machine gives, CPU times much less so."
            if shared
            else "Nothing else ran on the machine (the load averages are in the table)."
        ),
        "",
        md_table(headers, table),
        "",
        md_table(vheaders, verdicts),
        "",
        "Parallel efficiency = t(1 thread) / (n t(n)). CPU = this process plus the Dask "
        "workers (`getrusage` on each), and its ratio to the one-thread run (1: no extra "
        "work). Overhead per task = time in a task outside the kernels (Python: the record, "
        "the scale factors, the reduction) plus the gap before the next task on the same "
        "worker thread (dispatch, transfer of the result), over the mean task time. Dask's "
        f"CPU, idle = the CPU time of the cluster's processes over {IDLE_S:g} s left idle "
        "after the case, in cores (this process's share included: its scheduler, nannies and "
        "client). The "
        "one-thread run is cut for "
        f"{MODEL_WORKERS} workers (the model's input); the others as `run_ida` cuts for "
        "their threads. Every run gave the one-thread run's numbers.",
        "",
        f"**Model for {MODEL_WORKERS} workers** (no machine with {MODEL_WORKERS} cores was "
        "available to this session; every input below was measured in this run, on this "
        "machine's cores, see the script's docstring):",
        "",
        *[f"- {line}" for line in model_lines],
        "",
        f"The model gives each of the {MODEL_WORKERS} lanes a core of its own and so "
        "leaves out what cores share (memory bandwidth, the all-core clock); for threads it "
        "also leaves out the GIL beyond the lower bound given. A machine slower per core "
        "than this one runs longer tasks (the cutting aims at seconds of this machine), "
        "which only lowers the share of the fixed cost and the gaps."
        + (
            " Linux autogroup scheduling is on here (`/proc/sys/kernel/sched_autogroup_"
            "enabled` = 1): while other sessions are busy, this one gets an equal share of "
            "the CPU whatever its number of threads, so the efficiencies measure the load "
            "as much as the code."
            if autogroup()
            else ""
        ),
    ]
    if args.quick:  # the section as it would be written, to check it; nothing written
        print("\n".join(lines))
        return 0
    write_section(DOC_MD, "cluster", "\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
