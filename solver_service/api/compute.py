"""Run a typed job on the compute pool and turn the outcome into an HTTP answer.

While the job computes, the client's connection is watched: a client that gives up
(disconnects) cancels its job, and the pool ends the worker at once instead of letting it
compute to the end of the budget for nobody.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Sequence
from contextvars import ContextVar
from typing import Optional

from fastapi import Request, Response

from shared_schema.errors import InputError

from .jobspec import Job, check_job
from .pool import RETRY_AFTER_S, BudgetExceeded, ComputePool, PoolBusy, WorkerLost, WorkerResult
from .problems import error_response

__all__ = ["CLIENT", "compute"]

#: The request being served, for code that cannot take it as an argument (Hops handlers,
#: which run on worker threads with a copy of the context).
CLIENT: ContextVar[Optional[Request]] = ContextVar("rockmech_client", default=None)


class ClientGone(Exception):
    """The client disconnected before its answer was ready."""


async def _disconnected(request: Request) -> None:
    """Return when the client disconnects (the body has been read by then)."""
    while True:
        message = await request.receive()
        if message["type"] == "http.disconnect":
            return


async def _run_watched(
    pool: ComputePool, job: Job, blobs: Sequence[bytes], request: Optional[Request]
) -> WorkerResult:
    if request is None:
        return await pool.run(job, blobs)
    work = asyncio.ensure_future(pool.run(job, blobs))
    gone = asyncio.ensure_future(_disconnected(request))
    try:
        await asyncio.wait({work, gone}, return_when=asyncio.FIRST_COMPLETED)
    finally:
        for task in (work, gone):
            if not task.done():
                task.cancel()
        with contextlib.suppress(asyncio.CancelledError, Exception):
            await gone
    if not work.done() or work.cancelled():
        with contextlib.suppress(asyncio.CancelledError, Exception):
            await work
        raise ClientGone()
    return work.result()


async def compute(
    pool: ComputePool,
    job: Job,
    blobs: Sequence[bytes] = (),
    request: Optional[Request] = None,
) -> Response:
    """Run ``job`` (with its uploads) in a compute process; answer its document or an error.

    Parameters
    ----------
    pool : ComputePool
        The compute processes.
    job : Job
        The typed job.
    blobs : sequence of bytes
        Uploaded files, in the order the job expects them.
    request : Request, optional
        The client's request: if the client disconnects, the job is cancelled (default: the
        request in ``CLIENT``).
    """
    try:
        check_job(job, pool.limits)
    except InputError as exc:
        return error_response(422, "InputError", str(exc), exc.field)
    try:
        result = await _run_watched(pool, job, blobs, request or CLIENT.get())
    except ValueError:  # the job could not be encoded: a derived number overflowed
        message = (
            "a number derived from the inputs is not finite; the inputs are too large or too "
            "small for double precision"
        )
        return error_response(422, "InputError", message)
    except (BudgetExceeded, PoolBusy) as exc:
        return error_response(503, type(exc).__name__, str(exc))
    except WorkerLost as exc:
        return error_response(
            503, "WorkerLost", str(exc), headers={"Retry-After": str(RETRY_AFTER_S)}
        )
    except ClientGone:
        # Nobody reads this answer; 499 is the customary log code for "client closed".
        return error_response(499, "ClientGone", "the client disconnected; the job was stopped")
    return Response(result.body, status_code=result.status, media_type=result.media_type)
