"""``POST /envelope``: overturning envelopes and critical bands (``rockmech envelope``)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Response

from shared_schema.api import EnvelopeRequest
from shared_schema.documents.envelope import EnvelopeDocument

from ..bodies import json_body
from ..compute import compute
from ..deps import JSON, PoolDep, accepts
from ..jobspec import EnvelopeJob
from ..openapi import body_doc, responses

__all__ = ["router"]

router = APIRouter(tags=["solver"])


@router.post(
    "/envelope",
    summary="Overturning envelopes and the critical mechanism per frequency",
    response_model=EnvelopeDocument,
    responses=responses(EnvelopeDocument),
    openapi_extra=body_doc(EnvelopeRequest, None),
    dependencies=[accepts(JSON)],
)
async def envelope(
    request: Annotated[EnvelopeRequest, json_body(EnvelopeRequest)], pool: PoolDep
) -> Response:
    """Return the document ``rockmech envelope --json`` prints."""
    return await compute(pool, EnvelopeJob(**dict(request)))
