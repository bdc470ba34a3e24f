"""A plain wheel install against the development install: `envelope --exact` on the church.

What is measured
----------------
The wheel (built from this tree with ``python -m build --wheel``, or given with ``--wheel``)
is installed with no extras into a fresh virtual environment, as a user would
(``pip install rockmech-*.whl``). From an empty folder, that install runs the README's wheel
path: ``rockmech --version`` and ``jit.kernel_status`` (the compiled kernels must be active),
``rockmech examples``, then ``rockmech envelope examples/constants/church.json --out out --exact``:

1. once on a cold kernel cache: the first run of the boundary path compiles it (numba),
   announced by one line on stderr; timed apart ("first run");
2. then ``REPEATS`` times, alternating with the development install (``.venv``, kernels
   built beforehand by ``rockmech kernels``) running the same command on the repository's
   ``examples/constants/church.json``, so that both see the same machine load.

The ratio is the wheel install's best time over the development install's best time
[-]; the target is ``TARGET_RATIO`` (issue #28: a plain install within 2x of the dev
install). The first run's ratio is reported too (it includes compiling the path once).

Times are wall-clock seconds of the whole command (``time.perf_counter`` around
``subprocess.run``): interpreter start, imports, reading the constants, the exact boundaries
and writing the three output files.

Run ``.venv/bin/python benchmarks/install_speed.py`` (about 5 minutes on 2 cores); it
rewrites its section of ``docs/benchmarks.md``. ``--no-docs`` prints only.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
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

#: Timed runs of each install after the first (cold) run of the wheel install.
REPEATS = 2
#: Largest accepted ratio of the wheel install's time to the development install's [-].
TARGET_RATIO = 2.0
#: The command, relative to the folder holding ``examples/``.
#: Loads numba and says whether the kernels are active (--version no longer loads it, #38).
KERNEL_STATUS = (
    "from solver_service.core.jit import kernel_status; print(kernel_status().describe())"
)
ENVELOPE = ("envelope", "examples/constants/church.json", "--out", "out/church", "--exact")


#: CPU time [s] of each timed run (user + system, all its threads), by its wall time.
CPU: dict[float, float] = {}


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _run(argv: list[str], cwd: Path, env: dict[str, str] | None = None) -> tuple[float, str]:
    """Run ``argv`` in ``cwd``; return its wall time [s] and its stderr (fails loudly).

    Its CPU time is kept in ``CPU`` (the work apart from the machine's load).
    """
    cpu0 = _children_cpu()
    t0 = time.perf_counter()
    res = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, env=env, timeout=3600)
    took = time.perf_counter() - t0
    CPU[took] = _children_cpu() - cpu0
    if res.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({res.returncode}):\n{res.stderr[-3000:]}")
    return took, res.stderr


def _wheel(work: Path, given: str | None) -> Path:
    if given:
        return Path(given).resolve()
    out = work / "dist"
    subprocess.run(
        [sys.executable, "-m", "build", "--wheel", "--outdir", str(out), str(REPO)],
        check=True,
        capture_output=True,
        timeout=1800,
    )
    (wheel,) = out.glob("rockmech-*.whl")
    return wheel


def measure(wheel_arg: str | None, venv_arg: str | None) -> dict[str, object]:
    """Install the wheel (unless ``venv_arg`` holds one) and time both installs."""
    work = Path(tempfile.mkdtemp(prefix="rockmech-install-speed-"))
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "PYTHONPATH")}
    if venv_arg:
        venv = Path(venv_arg).resolve()
        wheel = None
    else:
        wheel = _wheel(work, wheel_arg)
        venv = work / "venv"
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=600)
        subprocess.run(
            [str(venv / "bin" / "python"), "-m", "pip", "install", "--quiet", str(wheel)],
            check=True,
            timeout=1800,
        )
    user = work / "user"  # the empty folder a user starts from
    user.mkdir()
    rockmech = str(venv / "bin" / "rockmech")
    version = subprocess.run(
        [rockmech, "--version"], cwd=user, capture_output=True, text=True, check=True, env=env
    ).stdout.splitlines()
    # --version does not load numba (#38): kernel_status does, without building anything.
    status = subprocess.run(
        [str(venv / "bin" / "python"), "-c", KERNEL_STATUS],
        cwd=user,
        capture_output=True,
        text=True,
        check=True,
        env=env,
    ).stdout.strip()
    if not status.startswith("compiled kernels: active"):
        raise SystemExit(f"the wheel install runs without compiled kernels: {status}")
    _run([rockmech, "examples"], user, env)
    dev = str(REPO / ".venv" / "bin" / "rockmech")
    _run([dev, "kernels"], REPO, env)
    dev_out = work / "dev"
    load_before = load_average()
    first, first_err = _run([rockmech, *ENVELOPE], user, env)
    wheel_times, dev_times = [], []
    for _ in range(REPEATS):
        dev_times.append(_run([dev, *ENVELOPE[:2], "--out", str(dev_out), "--exact"], REPO, env)[0])
        wheel_times.append(_run([rockmech, *ENVELOPE], user, env)[0])
    return {
        "wheel": wheel.name if wheel else f"(installed in {venv})",
        "version": version,
        "first": first,
        "first_notes": [line for line in first_err.splitlines() if line.startswith("note:")],
        "wheel_times": wheel_times,
        "dev_times": dev_times,
        "load_before": load_before,
        "load_after": load_average(),
    }


def report(m: dict[str, object], argv: list[str]) -> tuple[str, str, bool]:
    """Plain-text table, markdown section, and whether the target is met."""
    wheel_best = min(m["wheel_times"])
    dev_best = min(m["dev_times"])
    ratio = wheel_best / dev_best
    first_ratio = m["first"] / dev_best
    ok = ratio <= TARGET_RATIO
    headers = ["install", "envelope church.json --exact", "CPU time", "ratio to dev", "target"]
    rows = [
        [
            "development (.venv, kernels built)",
            fmt_time(dev_best),
            fmt_time(CPU[dev_best]),
            "1",
            "-",
        ],
        [
            "wheel, no extras, fresh venv (best of later runs)",
            fmt_time(wheel_best),
            fmt_time(CPU[wheel_best]),
            f"{ratio:.2f}",
            f"<= {TARGET_RATIO:g}: {'PASS' if ok else 'FAIL'}",
        ],
        [
            "wheel, first run (compiles the boundary path once)",
            fmt_time(m["first"]),
            fmt_time(CPU[m["first"]]),
            f"{first_ratio:.2f}",
            "informative",
        ],
    ]
    info = machine_info()
    notes = m["first_notes"] or ["(none: the path was already built)"]
    md = "\n".join(
        [
            "## Plain wheel install against the development install "
            "(`benchmarks/install_speed.py`)",
            "",
            "Latest figures of `benchmarks/install_speed.py` (issue #28): the wheel installed with "
            "no extras into a fresh virtual environment (`pip install rockmech-*.whl`), run from "
            "an empty folder after `rockmech examples`, against the development install, the "
            "same command alternating between them. Re-run with "
            "`.venv/bin/python benchmarks/install_speed.py`; it rewrites this section only.",
            "",
            f"- Date: {info['date']}; rockmech commit: {info['commit']}; wheel: {m['wheel']}",
            f"- CPU: {info['cpu']}; nproc = {info['nproc']}; load average (1, 5, 15 min) "
            f"before: {m['load_before']}, after: {m['load_after']}",
            f"- Python {info['python']}, numpy {info['numpy']}, numba {info['numba']}",
            f"- Command: `{' '.join(['.venv/bin/python', 'benchmarks/install_speed.py', *argv])}`",
            f"- The wheel install's `rockmech --version`: `{m['version'][1]}` "
            "(read before the first run)",
            f"- Its first run said: `{notes[0]}`",
            f"- Wall time of the whole command, best of {REPEATS} each after the first run "
            f"(wheel: {', '.join(fmt_time(t) for t in m['wheel_times'])}; "
            f"dev: {', '.join(fmt_time(t) for t in m['dev_times'])})",
            "",
            md_table(headers, rows),
            "",
            f"Reading: with numba in the base install the wheel runs the same compiled kernels as "
            f"the development install ({ratio:.2f}x its time; before #28 a plain install ran the "
            f"pure-Python kernels, 325 s against 27 s). The first run of the path compiles it "
            f"once, with the line above on stderr, and keeps it in numba's cache: "
            f"{fmt_time(m['first'])} ({first_ratio:.2f}x); `rockmech kernels` does it ahead. "
            "Times depend on the machine's load (given above); the CPU time (all threads of the "
            "command) shows the work apart from it.",
        ]
    )
    return text_table(headers, rows), md, ok


def main() -> int:
    """Measure, print, and rewrite the section of ``docs/benchmarks.md``."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--wheel", help="a built rockmech wheel (default: build one)")
    parser.add_argument("--venv", help="a virtual environment holding it already (cold cache)")
    parser.add_argument("--no-docs", action="store_true", help="print only")
    args = parser.parse_args()
    m = measure(args.wheel, args.venv)
    table, md, ok = report(m, sys.argv[1:])
    print(table)
    if not args.no_docs:
        print(f"wrote {write_section(DOC_MD, 'install_speed', md)}")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
