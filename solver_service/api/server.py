"""Run the service with uvicorn (``rockmech serve``), in this process or in a child process."""

from __future__ import annotations

import contextlib
import math
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any, Optional

from pydantic import ValidationError

from shared_schema.constants import validation_lines
from shared_schema.errors import InputError

from .app import create_app
from .settings import Settings

__all__ = [
    "background_server",
    "free_port",
    "process_rss_bytes",
    "run",
    "serve",
    "settings_env",
    "settings_with",
]


def settings_with(**overrides: Any) -> Settings:
    """Return the settings from the environment, with the given non-None values on top.

    Raises
    ------
    InputError
        A value is out of range (the message names the setting).
    """
    given = {k: v for k, v in overrides.items() if v is not None}
    try:
        return Settings(**given)
    except ValidationError as exc:
        err = exc.errors(include_url=False)[0]
        field, msg = validation_lines([err])[0]
        raise InputError(f"{msg}, got {err.get('input')!r}", field) from None


def run(settings: Settings) -> None:
    """Serve until interrupted, in a fresh process that imports only what routing needs.

    ``rockmech serve`` runs in the command line's process, which has imported the numerics
    (numpy, scipy, numba: 240 MB) for the other commands. This process is replaced
    (``os.execve``, same process id) by ``python -m solver_service.api.server`` with the
    settings in its environment; only the compute processes load the numerics.
    """
    env = {**os.environ, **settings_env(settings)}
    sys.stdout.flush()
    sys.stderr.flush()
    os.execve(sys.executable, [sys.executable, "-m", __name__], env)


def serve(settings: Settings) -> None:
    """Serve until interrupted, in this process (uvicorn, one event loop)."""
    import uvicorn

    uvicorn.run(
        create_app(settings),
        host=settings.host,
        port=settings.port,
        log_level=settings.log_level,
        access_log=False,
        timeout_graceful_shutdown=math.ceil(settings.shutdown_timeout_s),
    )


def settings_env(settings: Settings) -> dict[str, str]:
    """Return ``settings`` as ``ROCKMECH_*`` environment variables."""
    return {
        f"ROCKMECH_{name.upper()}": _env_value(value)
        for name, value in settings.model_dump().items()
    }


def free_port() -> int:
    """Return a TCP port that is free on the loopback interface now."""
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


@contextlib.contextmanager
def background_server(
    settings: dict[str, Any],
    log: Path,
    *,
    start_timeout_s: float = 120.0,
    env: Optional[dict[str, str]] = None,
    ready: bool = True,
) -> Iterator[tuple[str, subprocess.Popen[bytes]]]:
    """Run ``rockmech serve`` in a child process on a free loopback port (tests, benchmarks).

    Parameters
    ----------
    settings : dict
        Settings, passed as ``ROCKMECH_<NAME>`` environment variables (others are cleared).
    log : Path
        File for the server's output.
    start_timeout_s : float
        Longest wait for ``/api/v1/health`` to answer [s].
    env : dict, optional
        More environment variables for the server (e.g. ``TMPDIR``).
    ready : bool
        Wait until ``/api/v1/health`` says ``ok`` (every compute process has warmed up);
        False: only until it answers (``starting`` too).

    Yields
    ------
    (url, process)
        Base URL ``http://127.0.0.1:<port>`` and the server process; it is stopped (SIGTERM,
        then SIGKILL after 30 s) on exit.
    """
    import signal
    import time
    import urllib.error
    import urllib.request

    port = free_port()
    child_env = {k: v for k, v in os.environ.items() if not k.startswith("ROCKMECH_")}
    child_env.update(env or {})
    child_env.update({f"ROCKMECH_{k.upper()}": _env_value(v) for k, v in settings.items()})
    code = "from solver_service.cli import main; main()"
    cmd = [sys.executable, "-c", code, "serve", "--port", str(port)]
    with log.open("wb") as out:
        proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, env=child_env)
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + start_timeout_s
        while True:
            if proc.poll() is not None:
                raise RuntimeError(f"server exited with {proc.returncode}: {log.read_text()}")
            try:
                with urllib.request.urlopen(f"{url}/api/v1/health", timeout=2) as res:
                    if res.status == 200:
                        break
            except urllib.error.HTTPError:  # 503: the compute processes are starting
                if not ready:
                    break
            except (urllib.error.URLError, ConnectionError, TimeoutError):
                pass
            if time.monotonic() > deadline:
                raise RuntimeError(f"server did not start in {start_timeout_s:g} s")
            time.sleep(0.2)
        yield url, proc
    finally:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def _env_value(value: Any) -> str:
    """Return a setting as an environment variable: lists as JSON, the rest as text."""
    import json

    return json.dumps(value) if isinstance(value, (list, tuple)) else str(value)


def process_rss_bytes(pid: int) -> int:
    """Resident memory of process ``pid`` and its children (Linux ``/proc``) [bytes]."""
    total = 0
    try:
        kids = Path(f"/proc/{pid}/task/{pid}/children").read_text().split()
    except OSError:
        kids = []
    for p in [pid, *map(int, kids)]:
        try:
            for line in Path(f"/proc/{p}/status").read_text().splitlines():
                if line.startswith("VmRSS:"):
                    total += int(line.split()[1]) * 1024
        except OSError:
            continue
    return total


if __name__ == "__main__":  # ``run`` starts the service this way, settings in the environment
    serve(Settings())
