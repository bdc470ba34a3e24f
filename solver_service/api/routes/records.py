"""``POST /history`` and ``POST /spectrum``: time histories and spectra of a record."""

from __future__ import annotations

from fastapi import APIRouter, Request, Response

from shared_schema.api import HistoryRequest, SpectrumRequest
from shared_schema.documents.history import HistoryDocument
from shared_schema.documents.record import RecordDocument

from ..deps import JSON, MULTIPART, PoolDep, accepts
from ..jobspec import HistoryJob, SpectrumJob
from ..openapi import body_doc, responses
from ._record_jobs import run_record_job

__all__ = ["router"]

router = APIRouter(tags=["records"], dependencies=[accepts(JSON, MULTIPART)])


@router.post(
    "/history",
    summary="Time histories of every mechanism at every scale factor",
    response_model=HistoryDocument,
    responses=responses(HistoryDocument),
    openapi_extra=body_doc(HistoryRequest, "history"),
)
async def history(request: Request, pool: PoolDep) -> Response:
    """Return the document ``rockmech history --json`` prints."""
    return await run_record_job(request, pool, HistoryJob, HistoryRequest)


@router.post(
    "/spectrum",
    summary="Exact elastic response spectrum of a record",
    response_model=RecordDocument,
    responses=responses(RecordDocument),
    openapi_extra=body_doc(SpectrumRequest, "spectrum"),
)
async def spectrum(request: Request, pool: PoolDep) -> Response:
    """Return the document ``rockmech record --json`` prints."""
    return await run_record_job(request, pool, SpectrumJob, SpectrumRequest)
