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

The process ends when its stdin closes. Anything a library prints goes to stderr: file
descriptor 1 is pointed at stderr and the protocol uses a private copy of it.
"""

from __future__ import annotations

import json
import os
import sys
import traceback
from typing import Any, BinaryIO

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


def serve_forever(inp: BinaryIO, out: BinaryIO) -> None:
    """Answer requests from ``inp`` on ``out`` until ``inp`` closes."""
    _write(
        out,
        {"ready": True, "warmup": _answer({"job": {"kind": "warmup"}, "limits": {}}, []).status},
    )
    while True:
        line = inp.readline()
        if not line:
            return
        request = json.loads(line)
        blobs = [inp.read(int(n)) for n in request.get("blobs", [])]
        result = _answer(request, blobs)
        header = {
            "status": result.status,
            "media_type": result.media_type,
            "size": len(result.body),
        }
        _write(out, header, result.body)


def main() -> None:
    """Entry point: protocol on a private copy of stdout; fd 1 then goes to stderr."""
    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    serve_forever(sys.stdin.buffer, out)


if __name__ == "__main__":
    main()
