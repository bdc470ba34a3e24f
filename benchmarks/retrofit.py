"""Speed of ``rockmech retrofit`` and the rate behind its up-front work estimate.

Two cases, each timed in process (``retrofit_doc``), best of ``REPEATS`` by CPU time after a
warm-up:

* the bundled church (``examples/constants/church_geometry.json``, 4 mechanisms, on
  ``examples/sites/ntc_site.json`` with ``examples/specs/church.retrofit.json``): the issue's
  target is 5 s on one core;
* the rate: the church's two single-block façades with ``HEIGHTS`` candidate tie heights each,
  counting every code check the retrofit runs (each a ``check_doc`` of a mechanism with a
  trial tie). ``workflows.limits.RETROFIT_CHECKS_PER_S`` is this rate to two significant
  digits (``tests/test_cli_retrofit.py`` checks it against the table written here); the
  service and the command line refuse a retrofit whose planned checks
  (``limits.retrofit_checks``) cannot finish within the budget at ``RATE_MARGIN`` times it.

The records' term (issue #39: the church with 5 records in ≤ 5 s on one core, each tie
force from the records in ≤ 20 exact runs per record), in a second table:

* the bundled church on El Centro 1940 N-S (bundled) and the four PEER records of the
  project's shared folder (``--records DIR``; by default the records folder of the shared
  data beside the repository, ``SHARED_RECORDS``; the run stops, naming it, where they are
  absent: PEER's terms keep them out of the repository);
* the free wall of ``tests/test_retrofit_records.py`` (b 0.5 m, h 6 m, L 4 m, 1800 kg/m³,
  one tie at 5 m) on a site of a_g = 0.45 g, where El Centro overturns it at its design
  scale, so the search on the tie force runs.

Each row gives the exact runs of the searches on the tie force (the most for one record)
and all the exact runs (the least overturning scales before and after included).

Run ``.venv/bin/python benchmarks/retrofit.py`` to rewrite the ``retrofit`` section of
``docs/benchmarks.md``; ``--quick`` is a smoke run that writes nothing.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from _docs import DOC_MD, load_average, machine_info, md_table, write_section  # noqa: E402

from shared_schema.constants import parse_constants  # noqa: E402
from shared_schema.retrofit import parse_retrofit_spec, read_retrofit_spec  # noqa: E402
from shared_schema.site import parse_site  # noqa: E402
from solver_service.workflows import limits, retrofit_records  # noqa: E402
from solver_service.workflows import retrofit as workflow  # noqa: E402
from solver_service.workflows.assess import read_site  # noqa: E402
from solver_service.workflows.inputs import read_constants, read_record  # noqa: E402

EXAMPLES = REPO / "examples"
#: Best of this many runs.
REPEATS = 5
#: Candidate tie heights per façade in the rate's case.
HEIGHTS = 10
#: The project's shared records (PEER NGA-West2), beside the repository.
SHARED_RECORDS = REPO.parent / "shared" / "data" / "records"
#: The issue's targets for the records' term: CPU seconds, exact runs per record's search.
TARGET_S, TARGET_RUNS = 5.0, 20
G = 9.80665


def free_wall() -> Any:
    """Return the free wall's constants (one block about its outer toe, theory §2.1, Eq. 26)."""
    b, h, length, rho = 0.5, 6.0, 4.0, 1800.0
    mass = rho * b * h * length
    r = 0.5 * math.hypot(b, h)
    alpha = math.atan2(b, h)
    i_o = mass * (b * b + h * h) / 3.0
    mech = {
        "id": "W",
        "typology": "single_block",
        "rocking": "one_sided",
        "positive": {
            "I0": i_o,
            "K": mass * G * r,
            "Q": mass * r,
            "phi_cr": alpha,
            "M_F": 0.0,
            "virtual_work": {
                "alpha0": b / h,
                "mass": mass,
                "S": mass * h / 2.0,
                "J": mass * h * h / 3.0,
                "J_blocks": mass * (h / 2.0) ** 2,
            },
        },
        "eta": 1.0 - 2.0 * mass * r * r * math.cos(alpha) ** 2 / i_o,
        "geometry": {
            "mass_kg": mass,
            "com_m": [b / 2.0, length / 2.0, h / 2.0],
            "positive": {"axis_point_m": [0.0, 0.0, 0.0], "R_m": r, "alpha_rad": alpha},
        },
    }
    return parse_constants(json.dumps({"mechanisms": [mech]}))


def _record_runs(doc: Any) -> tuple[int, int]:
    """Return the runs of all the records' searches on the tie force, and the most of one."""
    runs = [t.runs for m in doc.mechanisms for o in m.options for t in o.records]
    return sum(runs), max(runs, default=0)


def measure_records(repeats: int, shared: Path) -> list[dict[str, Any]]:
    """Time the records' cases; return one row each."""
    if not shared.is_dir():
        raise SystemExit(f"the shared records are not at {shared}: give --records DIR")
    elcentro = read_record(EXAMPLES / "records" / "elcentro_NS.dat")
    peer = [read_record(p) for p in sorted(shared.glob("*.AT2"))]
    church = read_constants(EXAMPLES / "constants" / "church_geometry.json")
    church_site = read_site(EXAMPLES / "sites" / "ntc_site.json")
    bundled = read_retrofit_spec(EXAMPLES / "specs" / "church.retrofit.json")
    wall_site = parse_site(
        '{"hazard": {"code": "NTC2018", "a_g": 0.45, "F0": 2.4, "Tc_star": 0.3, "soil": "C",'
        ' "FC": 1.35}}'
    )
    wall_spec = parse_retrofit_spec(
        {
            "steel": {"grade": "S275", "diameters_mm": [12, 16, 20, 24, 30]},
            "anchorage": {"capacity_N": 6e4, "source": "benchmark: illustrative"},
            "mechanisms": {"W": {"heights_m": [5.0]}},
        }
    )
    cases = [
        (f"the bundled church, {1 + len(peer)} records", church, church_site, bundled,
         [elcentro, *peer]),
        ("the free wall, a_g 0.45 g, El Centro N-S", free_wall(), wall_site, wall_spec,
         [elcentro]),
    ]  # fmt: skip
    rows = []
    for case, cf, site, spec, motions in cases:

        def run(cf: Any = cf, site: Any = site, spec: Any = spec, motions: Any = motions) -> Any:
            return workflow.retrofit_doc(cf, site, spec, motions)

        cpu, wall = _cpu(run, repeats)
        counted = _exact_runs(run)
        searched, most = _record_runs(run())
        rows.append(
            {
                "case": case,
                "records": len(motions),
                "search_runs": searched,
                "most_runs": most,
                "exact_runs": counted,
                "cpu_s": cpu,
                "wall_s": wall,
            }
        )
    return rows


def _exact_runs(run: Callable[[], Any]) -> int:
    """Run ``run`` once, counting the exact runs of the records (``MechanismRecords.runs``)."""
    made: list[Any] = []
    cls = retrofit_records.MechanismRecords
    original = cls.__post_init__

    def post_init(self: Any) -> None:
        original(self)
        made.append(self)

    cls.__post_init__ = post_init  # type: ignore[method-assign]
    try:
        run()
    finally:
        cls.__post_init__ = original  # type: ignore[method-assign]
    return sum(m.runs for m in made)


def _cpu(run: Callable[[], Any], repeats: int) -> tuple[float, float]:
    """(least CPU time, its wall time) of ``repeats`` runs of ``run`` [s], after a warm-up."""
    run()
    best = (float("inf"), float("inf"))
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        run()
        best = min(best, (time.process_time() - cpu, time.perf_counter() - wall))
    return best


def _counted(run: Callable[[], Any]) -> int:
    """Run ``run`` once, counting the code checks of the retrofit (its trial ties)."""
    checker = workflow._Checker
    original = checker.row
    count = [0]

    def row(self: Any, *args: Any, **kwargs: Any) -> Any:
        count[0] += 1
        return original(self, *args, **kwargs)

    checker.row = row  # type: ignore[method-assign]
    try:
        run()
    finally:
        checker.row = original  # type: ignore[method-assign]
    return count[0]


def measure(repeats: int) -> list[dict[str, Any]]:
    """Time both cases; return one row each."""
    cf = read_constants(EXAMPLES / "constants" / "church_geometry.json")
    site = read_site(EXAMPLES / "sites" / "ntc_site.json")
    bundled = read_retrofit_spec(EXAMPLES / "specs" / "church.retrofit.json")
    data = json.loads(bundled.model_dump_json())
    heights = {"F1": (3.0, 8.0), "F2": (2.0, 6.3)}
    for mid, (lo, hi) in heights.items():
        step = (hi - lo) / (HEIGHTS - 1)
        data["mechanisms"][mid] = {"heights_m": [lo + k * step for k in range(HEIGHTS)]}
    many = parse_retrofit_spec(data)
    rows = []
    for case, spec in (
        ("the bundled church (church.retrofit.json)", bundled),
        (f"the church's façades F1, F2 with {HEIGHTS} tie heights each", many),
    ):

        def run(spec: Any = spec) -> Any:
            return workflow.retrofit_doc(cf, site, spec)

        cpu, wall = _cpu(run, repeats)
        checks = _counted(run)
        rows.append(
            {
                "case": case,
                "mechanisms": len(cf.mechanisms),
                "planned": limits.retrofit_checks(cf, site, spec),
                "checks": checks,
                "cpu_s": cpu,
                "wall_s": wall,
                "rate": checks / cpu,
            }
        )
    return rows


def records_markdown(
    rows: list[dict[str, Any]], info: dict[str, str], before: str, after: str
) -> str:
    """Return the ``retrofit-records`` section of docs/benchmarks.md."""
    table = md_table(
        ["case", "records", "runs of the searches on T", "most for one record",
         "exact runs in all", "CPU time", "wall time"],
        [
            [
                r["case"],
                str(r["records"]),
                str(r["search_runs"]),
                str(r["most_runs"]),
                str(r["exact_runs"]),
                f"{r['cpu_s'] * 1e3:.1f} ms",
                f"{r['wall_s'] * 1e3:.1f} ms",
            ]
            for r in rows
        ],
    )  # fmt: skip
    church = rows[0]
    most = max(r["most_runs"] for r in rows)
    return "\n".join(
        [
            "## Retrofit with records: the church on 5 records (`benchmarks/retrofit.py`)",
            "",
            "`.venv/bin/python benchmarks/retrofit.py --only-records --records DIR` "
            f"({info['date']}, commit {info['commit']}; {info['cpu']}, {info['nproc']} cores, "
            f"load {before} before, {after} after; best of {REPEATS} by CPU time, after a "
            "warm-up; one thread).",
            "",
            "`retrofit_doc` in process, with records: the searches on the tie force run each "
            "record at its design scale (the exact solver); all the runs add the least "
            "overturning scale of each record before and after each tie (a grid of 60 scales, "
            "bisected to 0.1 %). The church's mechanisms survive every record at its design "
            "scale as they stand (the code checks size their ties): one run of each record's "
            "search; the free wall's search runs.",
            "",
            table,
            "",
            f"The church with {church['records']} records: {church['cpu_s']:.2f} s of CPU (target: "
            f"{TARGET_S:g} s on one core); the most exact runs of one record's search on the tie "
            f"force: {most} (target: {TARGET_RUNS}).",
            "",
        ]
    )


def markdown(
    rows: list[dict[str, Any]],
    info: dict[str, str],
    before: str,
    after: str,
) -> str:
    """Return the ``retrofit`` section of docs/benchmarks.md."""
    table = md_table(
        ["case", "mechanisms", "checks planned", "checks run", "CPU time", "wall time", "rate"],
        [
            [
                r["case"],
                str(r["mechanisms"]),
                str(r["planned"]),
                str(r["checks"]),
                f"{r['cpu_s'] * 1e3:.1f} ms",
                f"{r['wall_s'] * 1e3:.1f} ms",
                f"{r['rate']:.3g} /s",
            ]
            for r in rows
        ],
    )
    rate = rows[-1]["rate"]
    return "\n".join(
        [
            "## Retrofit: tie forces of the church (`benchmarks/retrofit.py`)",
            "",
            f"`.venv/bin/python benchmarks/retrofit.py` ({info['date']}, commit {info['commit']}; "
            f"{info['cpu']}, {info['nproc']} cores, load {before} before, {after} after; best of "
            f"{REPEATS} by CPU time, after a warm-up; one thread).",
            "",
            "`retrofit_doc` in process. A code check is one `check_doc` of a mechanism with a "
            "trial tie (the bisections on the tie force and the check after each tie); the "
            "plan is `workflows.limits.retrofit_checks`, which counts every mechanism as "
            "failing and the least steps of each bisection, so it is below the checks run "
            "where the mechanisms fail and above where they pass or take no tie.",
            "",
            table,
            "",
            f"The bundled church is retrofitted in {rows[0]['cpu_s'] * 1e3:.1f} ms of CPU "
            "(target: 5 s on one core). Rate of the code checks (last row): "
            f"{rate:.3g} /s (`RETROFIT_CHECKS_PER_S`).",
            "",
            "A retrofit is refused up front when its planned checks would take longer than "
            f"the budget even at `RATE_MARGIN` = {limits.RATE_MARGIN:g} times that rate on one "
            "thread (REST: 422; the command line: exit status 2, `--no-limits` lifts it).",
            "",
        ]
    )


def main(argv: list[str] | None = None) -> None:
    """Time the cases; rewrite the ``retrofit`` section (not with ``--quick``)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one repeat; write nothing")
    parser.add_argument(
        "--records", type=Path, default=SHARED_RECORDS, help="folder of the PEER records"
    )
    parser.add_argument(
        "--only-records",
        action="store_true",
        help="measure and rewrite the retrofit-records section only (the rate of the code "
        "checks, RETROFIT_CHECKS_PER_S, stays as it was measured)",
    )
    args = parser.parse_args(argv)
    before = load_average()
    rows = [] if args.only_records else measure(1 if args.quick else REPEATS)
    record_rows = measure_records(1 if args.quick else REPEATS, args.records)
    after = load_average()
    for r in rows:
        print(
            f"{r['case']:60s} planned {r['planned']:5d} run {r['checks']:5d} "
            f"cpu {r['cpu_s'] * 1e3:8.1f} ms  rate {r['rate']:.3g}/s"
        )
    for r in record_rows:
        print(
            f"{r['case']:60s} search runs {r['search_runs']:4d} (most {r['most_runs']:3d}) "
            f"exact runs {r['exact_runs']:5d} cpu {r['cpu_s'] * 1e3:8.1f} ms"
        )
    print(f"RETROFIT_CHECKS_PER_S = {limits.RETROFIT_CHECKS_PER_S:.2g}")
    if not args.quick:
        info = machine_info()
        if rows:
            write_section(DOC_MD, "retrofit", markdown(rows, info, before, after))
        text = records_markdown(record_rows, info, before, after)
        path = write_section(DOC_MD, "retrofit-records", text)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
