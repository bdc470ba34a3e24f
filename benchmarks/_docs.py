"""Shared helpers of the benchmark scripts: machine info, tables, and ``docs/benchmarks.md``.

``docs/benchmarks.md`` is shared: each benchmark owns one section between the markers
``<!-- BEGIN <name> -->`` and ``<!-- END <name> -->`` and rewrites only that section
(``write_section``). The file starts with a one-paragraph header that this module owns.
"""

from __future__ import annotations

import contextlib
import datetime
import importlib.metadata
import math
import os
import platform
import re
import subprocess
import tempfile
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, Callable, List, Tuple, Union

REPO = Path(__file__).resolve().parent.parent
#: The shared results file.
DOC_MD = REPO / "docs" / "benchmarks.md"
#: Title and paragraph at the top of ``DOC_MD``.
HEADER = (
    "# Benchmarks\n"
    "\n"
    "Each section below is produced by the command it names, which rewrites that section "
    "only; the figures are the latest run of that command on the machine it describes.\n"
)
#: Packages whose versions ``machine_info`` reports unless told otherwise.
PACKAGES = ("numpy", "scipy", "numba")


def _markers(name: str) -> tuple[str, str]:
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        raise ValueError(f"section name must be a plain identifier, got {name!r}")
    return f"<!-- BEGIN {name} -->", f"<!-- END {name} -->"


def _with_header(text: str, header: str = HEADER) -> str:
    """Put ``header`` before the first section, replacing an old title-and-paragraph header.

    Text before the first section that is more than a title and one paragraph is not a
    header; it is kept below ``HEADER``.
    """
    first = text.find("<!-- BEGIN ")
    head, rest = (text, "") if first < 0 else (text[:first], text[first:])
    paragraphs = [p for p in head.strip().split("\n\n") if p.strip()]
    is_header = not paragraphs or (
        paragraphs[0].startswith("# ")
        and len(paragraphs) <= 2
        and not any(line.startswith("#") for p in paragraphs[1:] for line in p.splitlines())
    )
    if is_header:
        head = ""
    return header + "\n" + (head.strip() + "\n\n" if head.strip() else "") + rest


@contextlib.contextmanager
def _dir_lock(folder: Path) -> Iterator[None]:
    """Serialise writers of the same folder (flock on the folder; no lock where unsupported)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


def write_section(path: Union[str, Path], name: str, markdown: str, header: str = HEADER) -> Path:
    """Replace (or append) section ``name`` of the markdown file ``path``, atomically.

    Parameters
    ----------
    path : str or Path
        The shared file (created if missing).
    name : str
        Section name; the section sits between ``<!-- BEGIN name -->`` and
        ``<!-- END name -->``.
    markdown : str
        New content of the section (without the markers).
    header : str
        Title and paragraph kept at the top of the file (``HEADER`` for
        ``docs/benchmarks.md``; other result files give their own).

    Notes
    -----
    The rest of the file is kept as it is, except the header, which is set to ``header``.
    The new text goes to a temporary file in the same folder that then replaces ``path``
    (``os.replace``), so a reader never sees a half-written file.
    """
    out = Path(path)
    begin, end = _markers(name)
    block = f"{begin}\n{markdown.strip()}\n{end}"
    out.parent.mkdir(parents=True, exist_ok=True)
    with _dir_lock(out.parent):
        text = out.read_text(encoding="utf-8") if out.exists() else ""
        i = text.find(begin)
        j = text.find(end, i + len(begin)) if i >= 0 else -1
        if i >= 0 and j >= 0:
            text = text[:i] + block + text[j + len(end) :]
        else:
            text = (text.rstrip() + "\n\n" if text.strip() else "") + block + "\n"
        text = _with_header(text, header).rstrip() + "\n"
        fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".tmp", dir=out.parent)
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                fh.write(text)
            os.chmod(tmp, 0o644)  # mkstemp creates 0600
            os.replace(tmp, out)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    return out


def machine_info(packages: Sequence[str] = PACKAGES) -> dict[str, str]:
    """Date, CPU, cores, load, OS, Python and package versions, and the rockmech commit.

    The commit is read with read-only git commands; "+ uncommitted changes in
    solver_service/" is added when the solver or schema differ from it.
    """
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        nproc = str(len(os.sched_getaffinity(0)))
    except AttributeError:
        nproc = str(os.cpu_count())
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            cwd=REPO,
            capture_output=True,
            text=True,
            check=False,
        ).stdout.strip()
        # Read-only check (git diff does not write the index) for uncommitted solver changes.
        dirty = subprocess.run(
            ["git", "diff", "--quiet", "HEAD", "--", "solver_service", "shared_schema"],
            cwd=REPO,
            capture_output=True,
            check=False,
        ).returncode
        if commit and dirty == 1:
            commit += " + uncommitted changes in solver_service/"
    except OSError:
        commit = ""
    info = {
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "cpu": cpu,
        "nproc": nproc,
        "load": load_average(),
        "os": platform.platform(),
        "python": platform.python_version(),
        "commit": commit or "unknown",
    }
    for pkg in packages:
        try:
            info[pkg] = importlib.metadata.version(pkg)
        except importlib.metadata.PackageNotFoundError:
            info[pkg] = "not installed"
    return info


def load_average() -> str:
    """Return the 1, 5 and 15 minute load averages as text."""
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:  # pragma: no cover - not available on this platform
        return "unknown"


def fmt_time(t: float) -> str:
    """Format a duration [s] in us, ms or s."""
    if t != t:  # NaN
        return "-"
    if t < 1e-3:
        return f"{t * 1e6:.0f} us"
    if t < 1.0:
        return f"{t * 1e3:.2f} ms"
    return f"{t:.2f} s"


def text_table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """Format a plain-text table with left-aligned columns."""
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(headers)]
    line = "  ".join(h.ljust(w) for h, w in zip(headers, widths))
    sep = "  ".join("-" * w for w in widths)
    body = ["  ".join(c.ljust(w) for c, w in zip(r, widths)) for r in rows]
    return "\n".join([line, sep, *body])


def md_table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """Format a markdown table (``|`` in cells becomes ``/``)."""
    out = ["| " + " | ".join(headers) + " |", "|" + "|".join("---" for _ in headers) + "|"]
    out += ["| " + " | ".join(c.replace("|", "/") for c in r) + " |" for r in rows]
    return "\n".join(out)


def best_of(
    fn: Callable[[], Any], repeats: int, budget_s: float = math.inf
) -> Tuple[float, List[float], Any]:
    """Return the best wall time [s] of up to ``repeats`` calls, all times, and the last result.

    A series stops early once its calls add up to ``budget_s`` seconds.
    """
    times: List[float] = []
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
        if sum(times) > budget_s:
            break
    return min(times), times, out


def command_env() -> dict[str, str]:
    """Return the environment of a timed command: this one, with bytecode caches on.

    An installed rockmech has its modules' caches (``__pycache__``: pip byte-compiles a
    package when it installs it, and an editable install writes them on its first run), as
    the yardstick's numpy has its own. ``PYTHONDONTWRITEBYTECODE`` would have every run of
    ``rockmech`` compile its modules from source again, which no user's run does: it is
    removed, so that the warm-up run writes the caches the timed runs read.
    """
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def build_scenes() -> Any:
    """Load the example scenes' builder, ``examples/scenes/build_scenes.py`` (not a package)."""
    import importlib.util

    path = REPO / "examples" / "scenes" / "build_scenes.py"
    spec = importlib.util.spec_from_file_location("rockmech_build_scenes", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod
