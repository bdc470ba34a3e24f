"""The ASGI routes of the Hops components (kept out of the OpenAPI document).

``GET /hops/`` lists the components, ``GET /hops/<name>`` describes one, ``POST
/hops/<name>`` (or the legacy ``POST /hops/solve`` with a ``pointer``) solves it. The
components block on the compute pool, so they run on a worker thread.
"""

from __future__ import annotations

from typing import Annotated

import anyio.from_thread
from fastapi import APIRouter, Depends, Request, Response
from starlette.concurrency import run_in_threadpool

from ..compute import CLIENT, compute
from ..hops import HOPS_PREFIX, JobRunner, RockmechHops
from ..jobspec import Job
from ..pool import ComputePool

__all__ = ["hops_router", "thread_job_runner"]


def thread_job_runner(pool: ComputePool) -> JobRunner:
    """Return a job runner for the Hops handlers, which run on worker threads."""

    def run(job: Job) -> tuple[int, str, bytes]:
        client = CLIENT.get()  # the thread runs in a copy of the request's context

        async def go() -> Response:
            return await compute(pool, job, request=client)

        response = anyio.from_thread.run(go)
        media = response.media_type or "application/json"
        return response.status_code, media, bytes(response.body)

    return run


def _hops(request: Request) -> RockmechHops:
    hops: RockmechHops = request.app.state.hops
    return hops


HopsDep = Annotated[RockmechHops, Depends(_hops)]


def hops_router() -> APIRouter:
    """Return the Hops routes under ``HOPS_PREFIX``."""
    router = APIRouter(prefix=HOPS_PREFIX, include_in_schema=False)

    @router.get("/")
    @router.get("/{name}")
    async def query(hops: HopsDep, name: str = "") -> Response:
        status, body = hops.query("/" + name if name else "/")
        return Response(body, status_code=status, media_type="application/json")

    @router.post("/{name}")
    async def solve(name: str, request: Request, hops: HopsDep) -> Response:
        payload = await request.body()
        status, body = await run_in_threadpool(hops.solve, "/" + name, payload)
        return Response(body, status_code=status, media_type="application/json")

    return router
