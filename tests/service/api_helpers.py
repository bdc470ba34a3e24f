"""Helpers of the service tests: the ``rockmech`` command line run in-process, the independent
path results are compared with, and readings of a server's processes. The real server and its
fixtures are in ``tests/servers.py``.
"""

from __future__ import annotations

import contextlib
import json
import time
from pathlib import Path
from typing import Any

from typer.testing import CliRunner

from shared_schema.documents.base import Part
from solver_service.cli import app

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
runner = CliRunner()
"""In-process runner of the ``rockmech`` command line."""


def cli_json(*args: str) -> Any:
    """Run ``rockmech ARGS --json`` in-process and return its document."""
    res = runner.invoke(app, [*args, "--json"])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout)


def cli_error(*args: str, cwd: Path | None = None) -> str:
    """Run ``rockmech ARGS`` (optionally in ``cwd``), expect failure, return its message."""
    with contextlib.chdir(cwd) if cwd is not None else contextlib.nullcontext():
        res = runner.invoke(app, list(args))
    assert res.exit_code == 2, res.output
    line = res.stderr.strip()
    assert line.startswith("error: "), line
    return line[len("error: ") :]


def without_runtime(doc: Any) -> Any:
    """Drop wall-clock fields (``runtime_s``), which differ between two runs.

    A typed document (``shared_schema.documents``) is compared in its JSON form.
    """
    if isinstance(doc, Part):
        doc = doc.to_dict()
    if isinstance(doc, dict):
        return {k: without_runtime(v) for k, v in doc.items() if k != "runtime_s"}
    if isinstance(doc, list):
        return [without_runtime(v) for v in doc]
    return doc


def cpu_ticks(pid: int) -> int:
    """CPU time process ``pid`` has used, user and system [clock ticks] (``/proc``)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return int(fields[11]) + int(fields[12])


def peak_rss(pid: int) -> int:
    """Peak resident memory of process ``pid`` so far (``VmHWM``) [bytes]."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) * 1024
    raise AssertionError(f"no VmHWM for {pid}")


def wait_busy(pid: int, wait_s: float = 30.0) -> None:
    """Wait until process ``pid`` has used 0.2 s of CPU (it has taken a job)."""
    start = cpu_ticks(pid)
    deadline = time.monotonic() + wait_s
    while cpu_ticks(pid) - start < 20:  # 0.2 s of CPU at 100 ticks per second
        assert time.monotonic() < deadline, f"process {pid} never started the job"
        time.sleep(0.05)
