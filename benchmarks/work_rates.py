"""The rates behind every up-front work estimate (``solver_service.workflows.limits``).

The service and the command line refuse work that cannot finish within the time budget
before starting it. They count the work of a request in the units of the solver's own loops
and divide it by a rate per unit of work; this script measures those rates, in the same
units, on the job functions the compute processes run:

========================  ==========================================  ===================
work                      unit (as ``workflows.limits`` counts it)    run
========================  ==========================================  ===================
exact envelopes           closed-form steps (``envelope_steps``)      ``EnvelopeJob``, the
                                                                      church without
                                                                      amplification data
pulse scale factors       spectrum grid points                        ``pulse_response_
                          (``scale_factor_points``)                   spectrum`` over the
                                                                      church's ratios
time histories            closed-form steps (``history_steps``)       ``HistoryJob``, the
                                                                      church on El Centro
elastic spectra           sub-steps (``spectrum_steps``)              ``response_spectrum``
                                                                      of El Centro
assessment page figures   figures (``assess_figures``)                ``AssessHtmlJob``
========================  ==========================================  ===================

Each rate is per core: the work divided by the CPU time of the process (``time.process_time``,
all threads), best of ``REPEATS`` after a warm-up, so the machine's load (other processes on
the same cores) changes it little; the figures are drawn on one thread, so theirs is also
the rate of one process. ``workflows.limits`` holds each rate as a constant (two significant
digits of the value measured here) and refuses work that would take longer than the budget even at
``RATE_MARGIN`` times that rate on every core of the machine; ``tests/workflows/
test_work_rates.py`` checks that the constants agree with the table this script writes.

Run ``.venv/bin/python benchmarks/work_rates.py`` to rewrite the ``work_rates`` section of
``docs/benchmarks.md``; ``--quick`` is a smoke run that writes nothing.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from _docs import DOC_MD, load_average, machine_info, md_table, write_section  # noqa: E402

from shared_schema.constants import parse_constants  # noqa: E402
from solver_service.api.estimates import assess_figures  # noqa: E402
from solver_service.api.jobs import run_job  # noqa: E402
from solver_service.api.jobspec import JOB  # noqa: E402
from solver_service.core.amplification import pulse_response_spectrum  # noqa: E402
from solver_service.core.records import GroundMotion  # noqa: E402
from solver_service.core.spectra import response_spectrum  # noqa: E402
from solver_service.workflows import limits  # noqa: E402
from solver_service.workflows.documents import frequency_grid  # noqa: E402

EXAMPLES = REPO / "examples"
CHURCH = EXAMPLES / "constants" / "church.json"
GEOMETRY = EXAMPLES / "constants" / "church_geometry.json"
RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
SITE = EXAMPLES / "sites" / "ntc_site.json"
#: Timed runs of each case; the best (least CPU time) counts.
REPEATS = 3
#: Envelope frequencies (0.1-10 Hz), history scale factors, spectrum periods.
N_FREQUENCIES = 200
N_SCALES = 100
N_PERIODS = 1000
#: Limits handed to the job functions: large enough for every case.
LIMITS: dict[str, Any] = {
    "max_samples": 10**7,
    "max_mechanisms": 1000,
    "max_scales": 1000,
    "max_answer_bytes": 2**31,
}


def _cpu(run: Callable[[], Any], repeats: int) -> tuple[float, float]:
    """(least CPU time, its wall time) of ``repeats`` runs of ``run`` [s], after a warm-up."""
    run()
    best = (float("inf"), float("inf"))
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        run()
        best = min(best, (time.process_time() - cpu, time.perf_counter() - wall))
    return best


def _job(doc: dict[str, Any]) -> Callable[[], Any]:
    job = JOB.validate_python(doc)

    def run() -> None:
        out = run_job(job, [], LIMITS)
        assert out.status == 200, out.body[:500]

    return run


def _elcentro() -> tuple[GroundMotion, dict[str, Any]]:
    motion = GroundMotion.from_file(str(RECORD), units="g")
    rows = [line.split() for line in RECORD.read_text().splitlines() if line.strip()]
    samples = {"accel": [float(r[1]) for r in rows], "dt": motion.dt, "units": "g"}
    return motion, samples


def measure(repeats: int) -> list[dict[str, Any]]:
    """Measure every rate; return one row per kind of work."""
    church = json.loads(CHURCH.read_text())
    plain = {**church, "mechanisms": [dict(m) for m in church["mechanisms"]]}
    for mech in plain["mechanisms"]:
        mech.pop("amplification", None)
    motion, samples = _elcentro()
    rows = []

    # Exact envelopes: closed-form steps, without the pulse scale factors' spectrum.
    cf = parse_constants(json.dumps(plain))
    steps = limits.envelope_steps(cf, 0.1, 10.0, N_FREQUENCIES)
    env = {"kind": "envelope", "constants": plain, "exact": True, "n": N_FREQUENCIES}
    cpu, wall = _cpu(_job(env), repeats)
    rows.append(
        (
            "envelope",
            "closed-form steps",
            steps,
            cpu,
            wall,
            "exact envelopes of the "
            f"church's {len(cf.mechanisms)} mechanisms (no amplification data), "
            f"{N_FREQUENCIES} frequencies 0.1-10 Hz",
        )
    )

    # The pulse scale factors' spectrum: grid points of pulse_response_spectrum.
    amplified = parse_constants(json.dumps(church))
    f_p = frequency_grid(0.1, 10.0, N_FREQUENCIES * 10)
    f_ns = [m.amplification.f_n for m in amplified.mechanisms if m.amplification is not None]
    ratios = np.concatenate([f_p / f_n for f_n in f_ns])
    points = limits.scale_factor_points(amplified, 0.1, 10.0, f_p.size)
    cpu, wall = _cpu(lambda: pulse_response_spectrum(ratios), repeats)
    rows.append(
        (
            "pulse_spectrum",
            "spectrum grid points",
            points,
            cpu,
            wall,
            f"pulse_response_spectrum at {f_p.size} frequencies for each of the "
            f"church's {len(f_ns)} natural frequencies",
        )
    )

    # Time histories: closed-form steps of every side at every scale.
    church_cf = parse_constants(json.dumps(church))
    scales = [round(0.02 * (k + 1), 2) for k in range(N_SCALES)]
    steps = limits.history_steps(church_cf, motion.accel.n, motion.dt, N_SCALES)
    hist = {"kind": "history", "constants": church, "record": samples, "scales": scales}
    cpu, wall = _cpu(_job(hist), repeats)
    rows.append(
        (
            "history",
            "closed-form steps",
            steps,
            cpu,
            wall,
            "time histories of the "
            f"church's {len(church_cf.mechanisms)} mechanisms on El Centro 1940 N-S "
            f"({motion.accel.n} samples) at {N_SCALES} scale factors",
        )
    )

    # Elastic response spectra: sub-steps of each period.
    periods = np.geomspace(0.02, 10.0, N_PERIODS)
    steps = sum(limits.spectrum_steps(motion.accel.n, motion.dt, float(t)) for t in periods)
    cpu, wall = _cpu(lambda: response_spectrum(motion.accel.acc, motion.dt, periods), repeats)
    rows.append(
        (
            "spectrum",
            "sub-steps",
            steps,
            cpu,
            wall,
            f"5 % response spectrum of El Centro at {N_PERIODS} periods 0.02-10 s",
        )
    )

    # The assessment page: figures drawn (one thread).
    geometry = json.loads(GEOMETRY.read_text())
    page = {
        "kind": "assess_html",
        "constants": geometry,
        "site": json.loads(SITE.read_text()),
        "records": [samples],
        "multiples": [1.0],
    }
    figures = assess_figures(len(geometry["mechanisms"]), 1)
    cpu, wall = _cpu(_job(page), repeats)
    rows.append(
        (
            "figures",
            "figures",
            figures,
            cpu,
            wall,
            f"the HTML assessment page of church_geometry.json on El Centro ({figures} figures)",
        )
    )

    return [
        {"kind": k, "unit": u, "work": w, "cpu_s": c, "wall_s": t, "case": case, "rate": w / c}
        for k, u, w, c, t, case in rows
    ]


#: The constant of ``workflows.limits`` that holds each measured rate.
CONSTANTS = {
    "envelope": "ENVELOPE_STEPS_PER_CORE_S",
    "pulse_spectrum": "PULSE_POINTS_PER_CORE_S",
    "history": "HISTORY_STEPS_PER_CORE_S",
    "spectrum": "SPECTRUM_STEPS_PER_CORE_S",
    "figures": "FIGURES_PER_S",
}


def markdown(rows: list[dict[str, Any]], info: dict[str, str], before: str, after: str) -> str:
    """Return the ``work_rates`` section of ``docs/benchmarks.md``."""
    table = md_table(
        [
            "work",
            "unit",
            "case",
            "work units",
            "CPU time",
            "wall time",
            "rate (measured)",
            "constant",
        ],
        [
            [
                r["kind"],
                r["unit"],
                r["case"],
                f"{r['work']:.4g}",
                f"{r['cpu_s']:.3f} s",
                f"{r['wall_s']:.3f} s",
                f"{r['rate']:.3g} /s" + ("" if r["kind"] == "figures" else " per core"),
                f"`{CONSTANTS[r['kind']]}`",
            ]
            for r in rows
        ],
    )
    return "\n".join(
        [
            "## Work rates of the up-front estimates (`benchmarks/work_rates.py`)",
            "",
            "`.venv/bin/python benchmarks/work_rates.py` "
            f"({info['date']}, commit {info['commit']}; "
            f"{info['cpu']}, {info['nproc']} cores, load {before} before, {after} after; "
            f"numba {info.get('numba', '?')}; best of {REPEATS} by CPU time, after a warm-up).",
            "",
            "Each rate is the work, in the units `solver_service.workflows.limits` counts, divided "
            "by the CPU time of the process (all threads): a rate per core, little changed by "
            "other load on the machine. The figures of the HTML page are drawn on one thread: "
            "theirs is also the rate of one process. The constants in the code are these rates "
            "to two significant digits (`tests/workflows/test_work_rates.py` checks them "
            "against this table). Work is refused up front when it would take longer than the "
            "budget even at "
            f"`RATE_MARGIN` = {limits.RATE_MARGIN:g} times these rates on every core of the "
            "machine (the figures: on one).",
            "",
            table,
            "",
        ]
    )


def main(argv: list[str] | None = None) -> None:
    """Measure the rates; rewrite the ``work_rates`` section (not with ``--quick``)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one repeat; write nothing")
    args = parser.parse_args(argv)
    before = load_average()
    rows = measure(1 if args.quick else REPEATS)
    after = load_average()
    for r in rows:
        print(
            f"{r['kind']:15s} {r['work']:12.4g} {r['unit']:22s} cpu {r['cpu_s']:7.3f} s "
            f"wall {r['wall_s']:7.3f} s  rate {r['rate']:.3g}/s  "
            f"({CONSTANTS[r['kind']]} = {getattr(limits, CONSTANTS[r['kind']]):.2g})"
        )
    if not args.quick:
        info = machine_info()
        path = write_section(DOC_MD, "work_rates", markdown(rows, info, before, after))
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
