"""Run a typed job on the compute pool and turn the outcome into an HTTP answer."""

from __future__ import annotations

from collections.abc import Sequence

from fastapi import Response

from .jobspec import Job
from .pool import BudgetExceeded, ComputePool, PoolBusy, WorkerLost
from .problems import error_response

__all__ = ["compute"]


async def compute(pool: ComputePool, job: Job, blobs: Sequence[bytes] = ()) -> Response:
    """Run ``job`` (with its uploads) in a compute process; answer its document or an error."""
    try:
        result = await pool.run(job, blobs)
    except (BudgetExceeded, PoolBusy) as exc:
        return error_response(503, type(exc).__name__, str(exc))
    except WorkerLost as exc:
        return error_response(422, "WorkerLost", str(exc))
    return Response(result.body, status_code=result.status, media_type=result.media_type)
