"""Speed of batch runs over many records (IDA), of the response spectrum, and Dask's overhead.

What is measured
----------------
1. IDA, locally: ``run_ida`` for ``N_RECORDS`` records × ``N_LEVELS`` scale factors ×
   ``N_MECHANISMS`` mechanisms (the ten of ``examples/constants``: the three rectangular
   walls and the church's seven with a coefficient of restitution), ratio criterion, in
   process: tasks of (record × block of levels), longest first, on ``jobs`` threads, each
   running the single-threaded batch kernel. Run with 1 worker thread and with 2 (all cores
   here); the scaling efficiency is ``t1 / (2 t2)``. Target <= ``TARGET_IDA_S`` with all
   cores. Wall and CPU time (``time.process_time``, all threads) of both runs and the load
   average around each are printed: on a shared machine the wall times and the efficiency
   fall with the load, while the CPU times (the work done) do not, so their ratio
   ``cpu2 / cpu1`` (1 = running on two threads costs no extra work) and ``cpu2 / 2`` (the
   wall time with two free cores and perfect balance) stay informative.
2. The same run on a dask.distributed ``LocalCluster`` (2 worker processes, 1 thread each),
   in the same process run; the overhead is the difference. Cluster start-up is timed apart
   (``benchmarks/cluster.py`` compares the paths on a run 20 times larger).
   The two results must be identical.
3. The response spectrum: ``response_spectrum`` at 100 log-spaced periods (0.02-10 s, 5 %)
   on a ``SPECTRUM_SAMPLES``-sample record; best of ``REPEATS``. Target <=
   ``TARGET_SPECTRUM_S``.

Records
-------
The real records of the project's shared records folder (beside the repository, not part
of a clone) when it exists, else the bundled
El Centro 1940 N-S; ``N_RECORDS`` distinct motions are made from them by time-stretching
(factors 0.6-1.6, which shifts their frequency content), negation and time reversal. They
are real accelerograms transformed, not synthetic noise; their lengths are in the table.

How
---
Times are ``time.perf_counter`` around the public call, after a warm-up run (numba
compilation or cache load) that is excluded. Run ``.venv/bin/python
benchmarks/records_speed.py`` to rewrite the ``records_speed`` section of
``docs/benchmarks.md``; ``--quick`` is a smoke run that writes nothing.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any, Optional

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from _docs import (  # noqa: E402  (benchmarks/ is not a package)
    DOC_MD,
    best_of,
    fmt_time,
    load_average,
    machine_info,
    md_table,
    text_table,
    write_section,
)

N_RECORDS = 100
N_LEVELS = 50
N_MECHANISMS = 10
TARGET_IDA_S = 3.0
SPECTRUM_SAMPLES = 5000
TARGET_SPECTRUM_S = 0.050
REPEATS = 7
SHARED_RECORDS = REPO.parent / "shared" / "data" / "records"


def base_records() -> list[Any]:
    """Real records: the shared set when present, else the bundled El Centro N-S."""
    from solver_service.core.records import GroundMotion

    if SHARED_RECORDS.is_dir():
        paths = sorted(SHARED_RECORDS.glob("*.AT2")) + sorted(SHARED_RECORDS.glob("*.dat"))
        return [GroundMotion.from_file(p, units=None if p.suffix == ".AT2" else "g") for p in paths]
    return [GroundMotion.from_file(REPO / "examples" / "records" / "elcentro_NS.dat", units="g")]


def derived_records(n: int) -> list[Any]:
    """``n`` distinct motions: stretched, negated and reversed versions of the real ones."""
    from solver_service.core.records import GroundMotion

    bases = base_records()
    stretches = np.linspace(0.6, 1.6, max(1, -(-n // (4 * len(bases)))))
    out = []
    for stretch in stretches:
        for base in bases:
            for sign in (1.0, -1.0):
                for reverse in (False, True):
                    acc = base.accel.acc[::-1] if reverse else base.accel.acc
                    tags = (" -" if sign < 0 else "") + (" rev" if reverse else "")
                    name = f"{base.name} x{stretch:.2f}{tags}"
                    out.append(GroundMotion.from_samples(sign * acc, base.dt * stretch, name=name))
    return out[:n]


def mechanisms() -> Any:
    """Return the ten example mechanisms that have a coefficient of restitution."""
    from shared_schema.constants import ConstantsFile
    from shared_schema.io import read_constants

    walls = read_constants(REPO / "examples" / "constants" / "rect_walls.json")
    church = read_constants(REPO / "examples" / "constants" / "church.json")
    mechs = [m for m in walls.mechanisms + church.mechanisms if m.eta is not None]
    return ConstantsFile.model_validate(
        {"mechanisms": [m.model_dump(exclude_none=True) for m in mechs[:N_MECHANISMS]]}
    )


def autogroup() -> bool:
    """Whether Linux autogroup scheduling (equal CPU shares per session) is on."""
    try:
        return Path("/proc/sys/kernel/sched_autogroup_enabled").read_text().strip() == "1"
    except OSError:
        return False


def timed(run: Any) -> tuple[Any, float, float, str]:
    """Call ``run()``; return its result, wall and CPU time [s] and the load before / after."""
    before = load_average()
    t0 = time.perf_counter()
    c0 = time.process_time()
    out = run()
    wall = time.perf_counter() - t0
    cpu = time.process_time() - c0
    return out, wall, cpu, f"{before} / {load_average()}"


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke run: 8 records, 10 levels")
    args = ap.parse_args(argv)
    from distributed import LocalCluster

    from solver_service.core.spectra import response_spectrum
    from solver_service.workflows.ida import run_ida

    n_rec, n_lev = (8, 10) if args.quick else (N_RECORDS, N_LEVELS)
    info = machine_info(("numpy", "scipy", "numba", "distributed"))
    records = derived_records(n_rec)
    cf = mechanisms()
    levels = list(np.geomspace(0.1, 5.0, n_lev))
    lengths = [len(r.accel.acc) for r in records]
    print(
        f"{n_rec} records ({min(lengths)}-{max(lengths)} samples), {n_lev} levels, "
        f"{len(cf.mechanisms)} mechanisms: {n_rec * n_lev * len(cf.mechanisms)} runs"
    )

    t0 = time.perf_counter()
    run_ida(cf, records[:2], levels[:2], jobs=1)
    run_ida(cf, records[:2], levels[:2], jobs=2)
    warm = time.perf_counter() - t0
    one, t_one, cpu_one, load_one = timed(lambda: run_ida(cf, records, levels, jobs=1))
    local, t_local, cpu_local, load_two = timed(lambda: run_ida(cf, records, levels, jobs=2))
    one, local = one.to_dict(), local.to_dict()  # the documents' JSON form, as ida.json
    same_jobs = all(one[k] == local[k] for k in ("mechanisms", "records", "max_error_estimate"))
    efficiency = t_one / (2.0 * t_local)
    print(
        f"IDA 1 thread: wall {fmt_time(t_one)}, CPU {fmt_time(cpu_one)} (load {load_one}); "
        f"2 threads: wall {fmt_time(t_local)}, CPU {fmt_time(cpu_local)} (load {load_two}); "
        f"efficiency {100 * efficiency:.0f} %, CPU ratio {cpu_local / cpu_one:.3f}, "
        f"cpu2 / 2 = {fmt_time(cpu_local / 2)}"
    )

    t0 = time.perf_counter()
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        t_start = time.perf_counter() - t0
        run_ida(cf, records[:2], levels[:2], scheduler=cluster.scheduler_address)  # warm workers
        t0 = time.perf_counter()
        remote = run_ida(cf, records, levels, scheduler=cluster.scheduler_address)
        t_dask = time.perf_counter() - t0
    remote = remote.to_dict()
    same = all(remote[k] == local[k] for k in ("mechanisms", "records", "max_error_estimate"))

    base = records[0]
    reps = int(np.ceil(SPECTRUM_SAMPLES / len(base.accel.acc)))
    acc = np.tile(base.accel.acc, reps)[:SPECTRUM_SAMPLES]
    periods = np.geomspace(0.02, 10.0, 100)
    response_spectrum(acc, base.dt, periods)
    t_spec, _, _ = best_of(lambda: response_spectrum(acc, base.dt, periods), REPEATS)

    runs = local["runs"]
    rows = [
        [
            "IDA, local, 1 worker thread (--jobs 1)",
            f"{runs} runs",
            f"{fmt_time(t_one)} (CPU {fmt_time(cpu_one)})",
            f"{1e3 * t_one / runs:.3f} ms/run",
            "-",
            "-",
        ],
        [
            "IDA, local, 2 worker threads (default: all cores)",
            f"{runs} runs",
            f"{fmt_time(t_local)} (CPU {fmt_time(cpu_local)})",
            f"{1e3 * t_local / runs:.3f} ms/run; scaling efficiency {100 * efficiency:.0f} %; "
            f"CPU ratio {cpu_local / cpu_one:.2f}; CPU / 2 = {fmt_time(cpu_local / 2)}",
            f"<= {TARGET_IDA_S:g} s, same numbers as 1 thread",
            "PASS" if (t_local <= TARGET_IDA_S or args.quick) and same_jobs else "FAIL",
        ],
        [
            "IDA, dask LocalCluster (2 workers x 1 thread)",
            f"{runs} runs",
            fmt_time(t_dask),
            f"overhead {'-' if t_dask < t_local else '+'}{fmt_time(abs(t_dask - t_local))} "
            f"({100 * (t_dask / t_local - 1):+.0f} %)",
            "same numbers as local",
            "PASS" if same else "FAIL",
        ],
        ["LocalCluster start-up (not in the row above)", "-", fmt_time(t_start), "-", "-", "-"],
        [
            f"response spectrum, 100 periods, {SPECTRUM_SAMPLES} samples",
            "-",
            fmt_time(t_spec),
            "-",
            f"<= {1e3 * TARGET_SPECTRUM_S:g} ms",
            "PASS" if t_spec <= TARGET_SPECTRUM_S else "FAIL",
        ],
    ]
    headers = ["case", "work", "time", "per unit", "target", "verdict"]
    print(text_table(headers, rows))
    print(f"warm-up (compile or cache load) excluded: {fmt_time(warm)}")
    if args.quick:
        return 0
    lines = [
        "## Batch runs over records (IDA), response spectrum, Dask overhead",
        "",
        "`.venv/bin/python benchmarks/records_speed.py` "
        f"({info['date']}, commit {info['commit']}; {info['cpu']}, {info['nproc']} cores, "
        f"load {info['load']}; numba {info['numba']}, distributed {info['distributed']}).",
        "",
        f"{n_rec} records ({min(lengths)}-{max(lengths)} samples, made from "
        f"{'the shared real records' if SHARED_RECORDS.is_dir() else 'El Centro N-S'} by "
        "time-stretching 0.6-1.6, negation and reversal) x "
        f"{n_lev} scale factors (0.1-5) x {len(cf.mechanisms)} example mechanisms, ratio "
        "criterion.",
        "",
        md_table(headers, rows),
        "",
        f"Warm-up excluded: {fmt_time(warm)}. Scaling efficiency = t(1 thread) / (2 t(2 "
        "threads)). `run_ida` groups the work into tasks of about a second by the work "
        "estimate (several records each; fewer seconds where that leaves under eight tasks "
        "per worker thread), started longest first; each record in a task is one compiled "
        "batch over all mechanisms x its levels on the single-threaded kernel, which "
        "releases the GIL, and the task hands back counts. The Dask run sends the same kind "
        f"of tasks ({local['backend']['tasks']} locally, {remote['backend']['tasks']} on "
        "Dask) to the workers as they free up, the constants broadcast once and each task's "
        "records scattered to its worker; its overhead (connecting, checking the workers, "
        "sending the records, gathering the counts) is measured in the same process run as "
        "the local one. `benchmarks/cluster.py` measures the paths at 10^6 runs.",
        "",
        f"Load average (1, 5, 15 min) before / after: 1 thread {load_one}; 2 threads "
        f"{load_two}. CPU time is `time.process_time` (all threads of the process): the "
        "machine's load inflates wall times and lowers the efficiency, not the CPU time. "
        f"CPU ratio = CPU(2 threads) / CPU(1 thread) = {cpu_local / cpu_one:.2f} (1: two "
        "threads do no extra work); CPU / 2 is the wall time two free cores would give with "
        "perfect balance."
        + (
            " Linux autogroup scheduling is on here (`/proc/sys/kernel/sched_autogroup_enabled`"
            " = 1): every session gets an equal share of the CPU, so while other sessions are "
            "busy a 2-thread run gets no more CPU per second than a 1-thread run, and the "
            "efficiency measures the load, not the code."
            if autogroup()
            else ""
        ),
    ]
    write_section(DOC_MD, "records_speed", "\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
