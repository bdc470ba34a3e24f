"""A compute process of the service: runs jobs one at a time, speaking framed JSON on stdio.

Started by :class:`solver_service.api.pool.ComputePool` as ``python -m
solver_service.api.worker``. No pickle crosses the pipe: each message is one line of JSON
followed by raw byte blobs whose sizes the line states.

Protocol
--------
start-up : the process warms its kernels up, then writes ``{"ready": true}``.
request : ``{"job": {"kind": str, ...}, "limits": {...}, "blobs": [n1, n2, ...]}`` + blobs; the
    job is one of ``solver_service.api.jobspec``'s models.
answer : ``{"status": int, "media_type": str, "size": n}`` + ``n`` bytes of body.

The process ends when its stdin closes, at once, even in the middle of a job: stdin is a pipe
only the server holds, so its end means the server closed it (shutting down) or is gone
(killed with SIGKILL, it closed nothing). A thread reads the requests, so the end is seen
while the main thread computes (the kernels release the GIL); the process then removes its
temporary folder (``solver_service.api.scratch.leave``) and exits. Anything a library prints
goes to stderr: file descriptor 1 is pointed at stderr and the protocol uses a private copy
of it.
"""

from __future__ import annotations

import json
import os
import queue
import sys
import threading
import traceback
from collections.abc import Callable
from typing import Any, BinaryIO, Optional

from . import scratch
from .errors import error_body
from .jobs import JobOutput, run_job
from .jobspec import JOB

__all__ = ["main", "serve_forever"]


def _write(out: BinaryIO, header: dict[str, Any], body: bytes = b"") -> None:
    out.write(json.dumps(header).encode("utf-8") + b"\n")
    if body:
        out.write(body)
    out.flush()


def _answer(request: dict[str, Any], blobs: list[bytes]) -> JobOutput:
    try:
        return run_job(JOB.validate_python(request["job"]), blobs, request["limits"])
    except Exception as exc:  # a bug: report it as such, keep serving
        traceback.print_exc(file=sys.stderr)
        message = f"internal error ({type(exc).__name__}); see the service log"
        return JobOutput(500, "application/json", error_body("InternalError", message))


#: A request read from the server: its header and its blobs.
_Request = tuple[dict[str, Any], list[bytes]]


def _read_requests(inp: BinaryIO, requests: queue.Queue[Optional[_Request]]) -> None:
    """Put each request of ``inp`` on ``requests``; None once ``inp`` has ended."""
    try:
        while True:
            line = inp.readline()
            if not line:
                return
            request = json.loads(line)
            blobs = [inp.read(int(n)) for n in request.get("blobs", [])]
            requests.put((request, blobs))
    finally:
        requests.put(None)


def serve_forever(
    inp: BinaryIO, out: BinaryIO, on_end: Optional[Callable[[], None]] = None
) -> None:
    """Answer requests from ``inp`` on ``out`` until ``inp`` closes.

    ``on_end``: called in the reading thread the moment ``inp`` ends, while a job may still
    be computing (the process's exit, ``main``); without it the job in hand is answered
    first.
    """
    requests: queue.Queue[Optional[_Request]] = queue.Queue()

    def read() -> None:
        _read_requests(inp, requests)
        if on_end is not None:
            on_end()

    # Reading from the start: a server gone while the kernels warm up is seen too.
    threading.Thread(target=read, name="requests", daemon=True).start()
    _write(
        out,
        {"ready": True, "warmup": _answer({"job": {"kind": "warmup"}, "limits": {}}, []).status},
    )
    while True:
        item = requests.get()
        if item is None:
            return
        result = _answer(*item)
        header = {
            "status": result.status,
            "media_type": result.media_type,
            "size": len(result.body),
        }
        _write(out, header, result.body)


def _exit_now() -> None:
    """Remove this process's temporary folder and exit, whatever the main thread does."""
    scratch.leave(os.environ.get("TMPDIR", ""))
    sys.stderr.flush()
    os._exit(0)


def main() -> None:
    """Entry point: protocol on a private copy of stdout; fd 1 then goes to stderr."""
    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    serve_forever(sys.stdin.buffer, out, on_end=_exit_now)
    _exit_now()


if __name__ == "__main__":
    main()
