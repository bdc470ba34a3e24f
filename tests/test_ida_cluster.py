"""IDA on a Dask cluster started as docs/cluster.md starts one, driven by the real CLI.

The scheduler and the workers are the ``dask scheduler`` and ``dask worker`` commands, each
its own process talking TCP (on one machine here, as they would across machines), and
``rockmech`` runs as a user runs it, in a process of its own: a complete run gives the
numbers of a local run (checked as docs/cluster.md checks them), and Ctrl+C stops the
command and leaves no task of it on the cluster.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")
yaml = pytest.importorskip("yaml")

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
CONSTANTS = EXAMPLES / "constants" / "rect_walls.json"
BIN = Path(sys.executable).parent
#: What docs/cluster.md leaves out of the comparison: timing and where the run ran.
TIMING = {"runtime_s", "compute_s", "backend"}


def _docs_settings() -> tuple[dict[str, Any], dict[str, str]]:
    """docs/cluster.md's Dask settings: its YAML file, and its ``export`` line as variables."""
    text = (ROOT / "docs" / "cluster.md").read_text(encoding="utf-8")
    section = text.split("## Dask's settings", 1)[1].split("\n## ", 1)[0]
    [block] = re.findall(r"```yaml\n(.*?)```", section, flags=re.S)
    [line] = re.findall(r"^export (.*)$", section, flags=re.M)
    return yaml.safe_load(block), dict(word.split("=", 1) for word in line.split())


def _dotted(tree: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in tree.items():
        if isinstance(value, dict):
            out.update(_dotted(value, f"{prefix}{key}."))
        else:
            out[prefix + key] = value
    return out


def test_the_settings_docs_give_are_the_ones_rockmech_checks() -> None:
    from dask.config import collect_env

    from solver_service.workflows.ida.dask import DASK_SETTINGS, _same_setting

    tree, env = _docs_settings()
    for given in (_dotted(tree), _dotted(collect_env(env))):  # read as Dask reads them
        assert set(given) == set(DASK_SETTINGS)
        assert all(_same_setting(given[k], v) for k, v in DASK_SETTINGS.items()), given
    # And the batch script of docs/cluster.md exports the same line.
    text = (ROOT / "docs" / "cluster.md").read_text(encoding="utf-8")
    assert text.count("export " + " ".join(f"{k}={v}" for k, v in env.items())) == 2


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _stop(proc: subprocess.Popen[Any]) -> None:
    """End a process this test started (SIGTERM, then SIGKILL)."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=20)


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """A scheduler and two one-thread workers, started with docs/cluster.md's commands.

    With its Dask settings, given as its ``export`` line gives them.
    """
    logs = tmp_path_factory.mktemp("dask")
    address = f"tcp://127.0.0.1:{_free_port()}"
    port = address.rsplit(":", 1)[1]
    commands = {
        "scheduler": ["scheduler", "--host", "127.0.0.1", "--port", port, "--no-dashboard"],
        "workers": ["worker", address, "--nworkers", "2", "--nthreads", "1", "--no-dashboard"],
    }
    env = _docs_settings()[1]
    with contextlib.ExitStack() as stack:
        for name, args in commands.items():
            log = stack.enter_context(open(logs / f"{name}.log", "w"))
            proc = subprocess.Popen(
                [str(BIN / "dask"), *args], stdout=log, stderr=log, env={**os.environ, **env}
            )
            stack.callback(_stop, proc)
        client = distributed.Client(address, timeout=60, set_as_default=False)
        try:
            client.wait_for_workers(2, timeout=120)
        finally:
            client.close()
        yield address


def _tasks_on(address: str) -> int:
    """Tasks the scheduler holds (queued, running or kept results), of every client."""
    with distributed.Client(address, timeout=30, set_as_default=False) as client:
        return int(client.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks)))


def _rockmech(*args: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(BIN / "rockmech"), *args], capture_output=True, text=True, timeout=timeout
    )


def test_a_malformed_address_is_one_line_and_no_traceback() -> None:
    # It printed the clear error, then a Client.__del__ traceback after 20 s (#25).
    res = _rockmech(
        "ida", str(CONSTANTS), str(EXAMPLES / "records" / "elcentro_NS.dat"), "--scales", "1",
        "--scheduler", "not-a-url", timeout=60,
    )  # fmt: skip
    assert res.returncode == 2
    assert res.stderr.splitlines() == [
        "error: scheduler: expected a Dask scheduler address like tcp://host:8786, got "
        "'not-a-url': it needs a host and a port number 1-65535"
    ]


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_the_cluster_gives_the_local_numbers_as_docs_check_them(
    scheduler: str, tmp_path: Path, elcentro_path: Path
) -> None:
    ns = np.loadtxt(elcentro_path)
    reversed_record = tmp_path / "reversed.dat"
    np.savetxt(reversed_record, np.column_stack([ns[:, 0], ns[::-1, 1]]))
    church = EXAMPLES / "constants" / "church.json"
    args = [str(church), str(elcentro_path), str(reversed_record), "--units", "g"]
    args += ["--scales", "0.1:4:12", "--sf", "eq28", "--no-progress"]
    local = _rockmech("ida", *args, "--out", str(tmp_path / "local"))
    assert local.returncode == 0, local.stderr
    cluster = _rockmech("ida", *args, "--out", str(tmp_path / "cluster"), "--scheduler", scheduler)
    assert cluster.returncode == 0, cluster.stderr
    assert f"on Dask at {scheduler} (2 worker threads)" in cluster.stdout
    # docs/cluster.md: the two ida.json agree on everything but the timing and the backend.
    a, b = (json.loads((tmp_path / d / "ida.json").read_text()) for d in ("local", "cluster"))
    assert {k: v for k, v in a.items() if k not in TIMING} == {
        k: v for k, v in b.items() if k not in TIMING
    }
    assert b["backend"]["kind"] == "dask" and b["backend"]["n_workers"] == 2
    # Started with the settings of docs/cluster.md: no note about them.
    assert "settings_differ" not in b["backend"] and "rockmech's settings" not in cluster.stderr
    assert (tmp_path / "local" / "ida.csv").read_bytes() == (
        tmp_path / "cluster" / "ida.csv"
    ).read_bytes()


@pytest.mark.slow
def test_ctrl_c_stops_the_command_and_cancels_its_tasks_on_the_cluster(
    scheduler: str, tmp_path: Path, elcentro_path: Path
) -> None:
    ns = np.loadtxt(elcentro_path)
    long_record = tmp_path / "long.dat"  # El Centro fifty times over: 134,400 samples
    np.savetxt(long_record, np.tile(ns[:, 1], 50), fmt="%.6g")
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    argv = [str(BIN / "rockmech"), "ida", str(CONSTANTS), *[str(long_record)] * 40]
    argv += ["--dt", str(ns[1, 0] - ns[0, 0]), "--units", "g", "--scales", "0.05:5:100"]
    argv += ["--scheduler", scheduler, "--out", str(out), "--no-progress"]
    assert _tasks_on(scheduler) == 0
    proc = subprocess.Popen(
        argv,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # SIGINT as a terminal delivers it, even where this test runs with it ignored (the
        # background of a non-interactive shell), which the command would inherit.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        deadline = time.monotonic() + 240
        while _tasks_on(scheduler) == 0 and proc.poll() is None:
            assert time.monotonic() < deadline, "the run never reached the cluster"
            time.sleep(0.1)
        assert proc.poll() is None, proc.communicate()
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        _stop(proc)
    assert proc.returncode == 130, err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("interrupted: stopped after "), err
    assert lines[0].endswith("runs; its tasks on the cluster were cancelled; nothing written")
    deadline = time.monotonic() + 60
    while (left := _tasks_on(scheduler)) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert left == 0
    assert sorted(p.name for p in out.iterdir() if p.name != ".rockmech") == ["notes.txt"]
