"""The real service for tests: ``rockmech serve`` (uvicorn) on a free loopback port.

A pytest plugin (``tests/conftest.py`` loads it), so that every test folder shares its
fixtures:

- ``server`` and ``client``: the one shared server with ``TEST_SETTINGS``, started once per
  session; every test that can live with those settings uses it.
- ``server_with(**settings)``: a server with special settings (limits, budget, compute
  processes), started on first use and shared, for the rest of the session, by every test
  that asks for the same settings.
- ``start_server``: a server of one's own, for a test that stops it (a shutdown).

The summary line ``rockmech servers started: N`` counts the servers a run started (outside
pytest-xdist's workers, which print no summary).
"""

from __future__ import annotations

import contextlib
import json
import subprocess
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import httpx
import pytest

from solver_service.api.server import background_server

#: Seconds a server may take to start (two compute processes warm their kernels up).
START_TIMEOUT_S = 120.0
#: Settings of the shared test server (small limits, so limit tests stay cheap).
TEST_SETTINGS = {
    "compute_workers": 2,
    "compute_timeout_s": 120,
    "max_body_bytes": 4 * 1024 * 1024,
    "max_samples": 100_000,
    "max_mechanisms": 20,
    "max_scales": 20,
}
#: A server with one compute process (a test knows which one is busy), the default limits and
#: budget (30 s), a 2 s shutdown grace and a private ``TMPDIR`` (a test lists it): for
#: ``server_with(**ONE_PROCESS)``.
ONE_PROCESS: dict[str, Any] = {"private_tmp": True, "compute_workers": 1, "shutdown_timeout_s": 2}
#: Read timeout of the shared client [s]: generous, a hang check and not a speed limit.
CLIENT_TIMEOUT_S = 180.0

#: Servers started by this process (the run's summary line).
_started = 0


@dataclass
class Server:
    """A running service: its base URL, process and log file."""

    url: str
    proc: subprocess.Popen[bytes]
    log: Path

    def children(self) -> list[int]:
        """Process ids of the server's compute processes."""
        path = Path(f"/proc/{self.proc.pid}/task/{self.proc.pid}/children")
        return [int(p) for p in path.read_text().split()]

    def worker(self, wait_s: float = 60.0) -> int:
        """Pid of a one-process server's compute process, once it is up and warmed.

        Waits while a process that a test ended is being replaced (health says so).
        """
        deadline = time.monotonic() + wait_s
        while time.monotonic() < deadline:
            kids = self.children()
            health = httpx.get(f"{self.url}/api/v1/health").json()
            if len(kids) == 1 and health["compute_workers"] == 1:
                return kids[0]
            time.sleep(0.1)
        raise AssertionError("no compute process came up")


@contextlib.contextmanager
def start_server(
    tmp: Path, env: dict[str, str] | None = None, ready: bool = True, **settings: Any
) -> Iterator[Server]:
    """Start ``rockmech serve`` with ``ROCKMECH_*`` settings on a free port; stop it after.

    ``ready``: wait until its compute processes have warmed up (else until it answers).
    """
    global _started
    _started += 1
    log = tmp / "server.log"
    with background_server(
        settings, log, start_timeout_s=START_TIMEOUT_S, env=env, ready=ready
    ) as (url, proc):
        yield Server(url, proc, log)


@pytest.fixture(scope="session")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    """The shared test server (``TEST_SETTINGS``)."""
    with start_server(tmp_path_factory.mktemp("service"), **TEST_SETTINGS) as srv:
        yield srv


@pytest.fixture(scope="session")
def client(server: Server) -> Iterator[httpx.Client]:
    """An HTTP client on the shared server, with a generous read timeout."""
    with httpx.Client(base_url=server.url, timeout=httpx.Timeout(CLIENT_TIMEOUT_S)) as c:
        yield c


#: Starts (or returns the running) server with these settings.
ServerWith = Callable[..., Server]


@pytest.fixture(scope="session")
def server_with(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServerWith]:
    """A server with special settings: ``server_with(private_tmp=False, **settings)``.

    Each set of settings starts one server, on first use, shared by every test that asks
    for the same settings until the session ends. ``private_tmp``: the compute processes'
    ``TMPDIR`` is the folder ``tmp`` beside the server's log (a test can list it).
    """
    running: dict[str, Server] = {}
    with contextlib.ExitStack() as stack:

        def get(private_tmp: bool = False, **settings: Any) -> Server:
            key = json.dumps([private_tmp, settings], sort_keys=True)
            if key not in running:
                folder = tmp_path_factory.mktemp("server")
                env = None
                if private_tmp:
                    (folder / "tmp").mkdir()
                    env = {"TMPDIR": str(folder / "tmp")}
                running[key] = stack.enter_context(start_server(folder, env=env, **settings))
            return running[key]

        yield get


def pytest_terminal_summary(terminalreporter: Any) -> None:
    """Say how many servers the run started."""
    if _started:
        terminalreporter.write_line(f"rockmech servers started: {_started}")
