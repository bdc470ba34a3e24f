"""Start-up of the ``rockmech`` command (issue #38): what a command pays beyond its own work.

What is measured
----------------
Wall-clock time of whole processes, each the best of ``REPEATS`` runs after one warm-up run
(which also compiles any solver kernel the command needs, so no run waits for numba, and
writes Python's bytecode caches, as an installed rockmech has them); the first three are
run in turn, one run of each per round:

1. ``python -c "import numpy"``: the yardstick, measured in the same run;
2. ``rockmech --help`` and ``rockmech --version`` (this one reads numba's version and the
   kernels' build stamps from files, without loading numba);
3. a one-pulse ``rockmech pulse --p-eq 2 --lam 0.2 --a-p-g 0.3 --f-p 1 --eta 0.9`` (the
   pure-Python kernels, without numba: ``kernel_cache.PLAIN_ETA_MAX``);
4. ``rockmech search examples/scenes/search_facade.3dm
   examples/specs/search_facade.search.json --out <dir>``, the figure included, beside the
   search's own ``total_s`` (``search.json``'s ``timings``: reading the scene, the search,
   the global check, the builder, the ranking, the records and the code check; not the
   interpreter's start-up, the imports, the files or the figure).

The issue's limits, as ratios: ``--help`` and ``--version`` at most 2 times the numpy
import, ``pulse`` at most 3 times; the search command at most ``2 total_s + start-up``,
where the start-up is the same run's ``rockmech --help`` (the interpreter, typer and the
command line, before a command loads its workflow).

Run ``.venv/bin/python benchmarks/cli_start.py``; it rewrites the ``cli_start`` section of
``docs/benchmarks.md`` (``--no-docs`` to only print).
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from _docs import DOC_MD, command_env, fmt_time, machine_info, md_table, write_section  # noqa: E402

SCENE = REPO / "examples" / "scenes" / "search_facade.3dm"
SPEC = REPO / "examples" / "specs" / "search_facade.search.json"
#: Timed runs of each command after its warm-up (best of).
REPEATS = 7
#: Timed runs of the search command (each takes seconds).
SEARCH_REPEATS = 3
#: The one-pulse command (a two-sided pulse needs eta).
PULSE = ["pulse", "--p-eq", "2", "--lam", "0.2", "--a-p-g", "0.3", "--f-p", "1", "--eta", "0.9"]
#: The issue's limits on the light commands, as multiples of the numpy import.
RATIO_LIMITS = {"help": 2.0, "version": 2.0, "pulse": 3.0}
#: The search command's limit: this many times its own total_s, plus the start-up.
SEARCH_FACTOR = 2.0


def _rockmech() -> str:
    """Return the ``rockmech`` command of this interpreter's environment."""
    exe = shutil.which("rockmech", path=str(Path(sys.executable).parent))
    if exe is None:
        raise SystemExit(
            f"no `rockmech` command beside {sys.executable}: install the project (make install)"
        )
    return exe


def _wall(argv: Sequence[str]) -> float:
    """Run ``argv`` once (output discarded); its wall-clock time [s]. A failure stops here."""
    t = time.perf_counter()
    proc = subprocess.run(list(argv), capture_output=True, text=True, cwd=REPO, env=command_env())
    wall = time.perf_counter() - t
    if proc.returncode != 0:
        raise SystemExit(f"`{' '.join(argv)}` failed ({proc.returncode}):\n{proc.stderr}")
    return wall


def best_walls(commands: dict[str, Sequence[str]], repeats: int = REPEATS) -> dict[str, float]:
    """Best wall-clock time [s] of each command over ``repeats`` rounds, after a warm-up round.

    Each round runs every command once, in turn, so that a change of the shared machine's
    load falls on the yardstick and on the commands alike rather than on one of them.
    """
    for argv in commands.values():
        _wall(argv)
    walls: dict[str, list[float]] = {key: [] for key in commands}
    for _ in range(repeats):
        for key, argv in commands.items():
            walls[key].append(_wall(argv))
    return {key: min(times) for key, times in walls.items()}


def search_runs(exe: str, repeats: int = SEARCH_REPEATS) -> tuple[float, float]:
    """Best wall-clock time [s] of the search command, and that run's own ``total_s`` [s]."""
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeats + 1):  # the first is the warm-up
            out = Path(tmp) / f"out_{k}"
            wall = _wall([exe, "search", str(SCENE), str(SPEC), "--out", str(out)])
            doc = json.loads((out / "search.json").read_text(encoding="utf-8"))
            if not (out / "search.png").is_file():
                raise SystemExit("`rockmech search` drew no search.png")
            runs.append((wall, float(doc["timings"]["total_s"])))
    return min(runs[1:])


def main(argv: list[str] | None = None) -> int:
    """Time the commands, print the table, write the docs section."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-docs", action="store_true", help="print only")
    args = parser.parse_args(argv)
    t_all = time.perf_counter()
    info = machine_info(("numpy", "scipy", "numba", "typer"))
    exe = _rockmech()
    times = best_walls(
        {
            "numpy": [sys.executable, "-c", "import numpy"],
            "help": [exe, "--help"],
            "version": [exe, "--version"],
            "pulse": [exe, *PULSE],
        }
    )
    numpy_s = times.pop("numpy")
    search_s, total_s = search_runs(exe)
    total = time.perf_counter() - t_all
    md = report(info, numpy_s, times, search_s, total_s, total)
    print(md)
    if not args.no_docs:
        write_section(DOC_MD, "cli_start", md)
        print(f"wrote the cli_start section of {DOC_MD}")
    return 0


def report(
    info: dict[str, str],
    numpy_s: float,
    times: dict[str, float],
    search_s: float,
    total_s: float,
    total: float,
) -> str:
    """Write the ``cli_start`` section of ``docs/benchmarks.md`` (markdown)."""
    labels = {
        "help": "`rockmech --help`",
        "version": "`rockmech --version`",
        "pulse": "`rockmech " + " ".join(PULSE) + "`",
    }
    rows = [['`python -c "import numpy"` (the yardstick)', fmt_time(numpy_s), "1.00", "-", "-"]]
    for key, label in labels.items():
        ratio, limit = times[key] / numpy_s, RATIO_LIMITS[key]
        verdict = "PASS" if ratio <= limit else "FAIL"
        rows.append([label, fmt_time(times[key]), f"{ratio:.2f}", f"{limit:g}", verdict])
    budget = SEARCH_FACTOR * total_s + times["help"]
    rows.append(
        [
            "`rockmech search` on the bundled façade, figure included",
            fmt_time(search_s),
            f"{search_s / numpy_s:.2f}",
            f"{SEARCH_FACTOR:g} x total_s + start-up = {fmt_time(budget)}",
            f"{'PASS' if search_s <= budget else 'FAIL'} ({search_s / budget:.2f})",
        ]
    )
    headers = ["command", "best wall", "/ numpy import", "limit", "result"]
    out = [
        "## Start-up of the command line (`benchmarks/cli_start.py`)",
        "",
        "Latest figures of `benchmarks/cli_start.py`. Re-run with "
        "`.venv/bin/python benchmarks/cli_start.py`; it rewrites this section only.",
        "",
        "### Machine and run",
        "",
        f"- Date: {info['date']}; rockmech commit: {info['commit']}",
        f"- CPU: {info['cpu']}; nproc = {info['nproc']}; load average (1, 5, 15 min): "
        f"{info['load']} (the machine is shared)",
        f"- Python {info['python']}, numpy {info['numpy']}, scipy {info['scipy']}, numba "
        f"{info['numba']}, typer {info['typer']}",
        f"- Command: `.venv/bin/python benchmarks/cli_start.py`; whole run {total:.0f} s",
        "",
        "### Method",
        "",
        "Each command runs as a whole process (`rockmech` of the project's environment), "
        "once to warm up (numba's kernels compiled, Python's bytecode caches written and the "
        "files in the page cache; `PYTHONDONTWRITEBYTECODE` is unset for the commands, as an "
        "installed rockmech has its caches like the yardstick's numpy), then "
        f"{REPEATS} times ({SEARCH_REPEATS} for the search), the yardstick and the light "
        "commands in turn (one run of each per round); the best wall-clock time is "
        'given, and its ratio to the best of `python -c "import numpy"` in the same run. '
        "The search command is held to "
        f"{SEARCH_FACTOR:g} times its own `total_s` (search.json: the scene read, the search, "
        "the global check, the builder, the ranking; measured inside the process) plus the "
        "start-up, taken as this run's `rockmech --help`; its `total_s` was "
        f"{fmt_time(total_s)}.",
        "",
        "### Results",
        "",
        md_table(headers, rows),
        "",
        "### Reading",
        "",
        "`--help` loads typer and the command line's own modules only; every command imports "
        "its workflow when it runs (tests/test_cli_imports.py checks that `--help`, "
        "`--version` and `pulse` load neither scipy.optimize, nor `cad_maths`, nor "
        "matplotlib). `--help` and `--version` load no numba either: "
        "`--version` reads numba's version from its package metadata and the kernels' "
        "build stamps from numba's cache folder. The one-pulse `pulse` runs the solver's "
        "pure-Python kernels (the same numbers as the compiled ones, bit for bit) instead "
        "of loading numba and its cached kernels; what it still loads beyond `--help` is "
        "numpy, pydantic (typer validates the options with it), the solver's modules, the "
        "pulse request (`shared_schema.pulse_request`, with the constants file's models it "
        "holds; not the other requests of `shared_schema.api`) and its document. The "
        "console script builds the options of the one command it runs (typer builds every "
        "registered command's otherwise). The search loads neither numba nor "
        "the code check when its spec has no records and no site (not the case of the "
        "bundled façade, which has both), and draws its figure without pyplot.",
    ]
    return "\n".join(out)


if __name__ == "__main__":
    sys.exit(main())
