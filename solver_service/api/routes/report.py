"""``POST /report``: a self-contained HTML report (``rockmech report``)."""

from __future__ import annotations

from fastapi import APIRouter, Request, Response

from shared_schema.api import ReportRequest

from ..deps import JSON, MULTIPART, PoolDep, accepts
from ..jobspec import ReportJob
from ..openapi import body_doc, responses
from ._record_jobs import run_record_job

__all__ = ["router"]

router = APIRouter(tags=["reports"])


@router.post(
    "/report",
    summary="Self-contained HTML report",
    response_model=None,
    response_class=Response,
    responses=responses(None, media="text/html"),
    openapi_extra=body_doc(ReportRequest, "report"),
    dependencies=[accepts(JSON, MULTIPART)],
)
async def report(request: Request, pool: PoolDep) -> Response:
    """Return the page ``rockmech report`` writes."""
    return await run_record_job(request, pool, ReportJob, ReportRequest)
