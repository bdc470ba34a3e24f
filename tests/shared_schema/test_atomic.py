"""Atomic writes: temporary files say whose they are, and a killed run's are cleaned later."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from shared_schema.atomic import (
    TEMP_SUFFIX,
    remove_stale_temps,
    stale_temps,
    temp_name,
    write_atomic,
)

pytestmark = pytest.mark.skipif(os.name != "posix", reason="process probes are POSIX-only")

#: A writer that stops inside ``write_atomic`` (at fsync) until it is killed.
_STUCK_WRITER = """
import os, sys, time
from shared_schema import atomic
atomic.os.fsync = lambda fd: (print("writing", flush=True), time.sleep(60))
atomic.write_atomic(sys.argv[1], "new")
"""


def _dead_pid() -> int:
    done = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        capture_output=True,
        text=True,
        check=True,
    )
    return int(done.stdout)


def test_a_write_leaves_only_the_target(tmp_path: Path) -> None:
    write_atomic(tmp_path / "a.json", "1")
    write_atomic(tmp_path / "a.json", b"2")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]
    assert (tmp_path / "a.json").read_text() == "2"


def test_a_killed_writer_leaves_a_recognised_temp_that_is_then_removed(tmp_path: Path) -> None:
    target = tmp_path / "result.json"
    target.write_text("old")
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    proc = subprocess.Popen(
        [sys.executable, "-c", _STUCK_WRITER, str(target)],
        stdout=subprocess.PIPE,
        text=True,
        env=env,
    )
    assert proc.stdout is not None and proc.stdout.readline().strip() == "writing"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    left = [p for p in tmp_path.iterdir() if p != target]
    assert [p.name for p in left] == [f".result.json.{proc.pid}-{left[0].name.split('-')[1]}"]
    assert left[0].name.endswith(TEMP_SUFFIX) and left[0].read_text() == "new"
    assert target.read_text() == "old"
    assert stale_temps(tmp_path) == left
    assert remove_stale_temps(tmp_path) == left
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.json"]


def test_a_live_writers_temp_is_left_alone(tmp_path: Path) -> None:
    live = tmp_path / temp_name("a.json", os.getpid(), "ab12")
    dead = tmp_path / temp_name("a.json", _dead_pid(), "cd34")
    other = tmp_path / ".a.json.123.tmp"  # not ours: another program's temporary file
    for path in (live, dead, other):
        path.write_text("half")
    assert remove_stale_temps(tmp_path) == [dead]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([live.name, other.name])
    assert remove_stale_temps(tmp_path / "missing") == []


def test_the_temp_name_holds_the_pid() -> None:
    name = temp_name("x.csv", 77, "0a")
    assert name == ".x.csv.77-0a.rockmech.tmp"
