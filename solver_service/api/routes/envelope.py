"""``POST /envelope``: overturning envelopes and critical bands (``rockmech envelope``)."""

from __future__ import annotations

from fastapi import APIRouter, Response

from shared_schema.api import EnvelopeRequest, EnvelopeResponse

from ..compute import compute
from ..deps import JSON, PoolDep, accepts
from ..jobspec import EnvelopeJob
from ..openapi import responses

__all__ = ["router"]

router = APIRouter(tags=["solver"])


@router.post(
    "/envelope",
    summary="Overturning envelopes and the critical mechanism per frequency",
    response_model=None,
    responses=responses(EnvelopeResponse),
    dependencies=[accepts(JSON)],
)
async def envelope(request: EnvelopeRequest, pool: PoolDep) -> Response:
    """Return the document ``rockmech envelope --json`` prints."""
    return await compute(pool, EnvelopeJob(**dict(request)))
