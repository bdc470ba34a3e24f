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

Run ``.venv/bin/python benchmarks/retrofit.py`` to rewrite the ``retrofit`` section of
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

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from _docs import DOC_MD, load_average, machine_info, md_table, write_section  # noqa: E402

from shared_schema.retrofit import parse_retrofit_spec, read_retrofit_spec  # noqa: E402
from solver_service.workflows import limits  # noqa: E402
from solver_service.workflows import retrofit as workflow  # noqa: E402
from solver_service.workflows.assess import read_site  # noqa: E402
from solver_service.workflows.inputs import read_constants  # noqa: E402

EXAMPLES = REPO / "examples"
#: Best of this many runs.
REPEATS = 5
#: Candidate tie heights per façade in the rate's case.
HEIGHTS = 10


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


def markdown(rows: list[dict[str, Any]], info: dict[str, str], before: str, after: str) -> str:
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
    args = parser.parse_args(argv)
    before = load_average()
    rows = measure(1 if args.quick else REPEATS)
    after = load_average()
    for r in rows:
        print(
            f"{r['case']:60s} planned {r['planned']:5d} run {r['checks']:5d} "
            f"cpu {r['cpu_s'] * 1e3:8.1f} ms  rate {r['rate']:.3g}/s"
        )
    print(f"RETROFIT_CHECKS_PER_S = {limits.RETROFIT_CHECKS_PER_S:.2g}")
    if not args.quick:
        path = write_section(DOC_MD, "retrofit", markdown(rows, machine_info(), before, after))
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
