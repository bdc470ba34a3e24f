"""``POST /pulse``: one mechanism under a one-cycle pulse (``rockmech pulse``)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Response

from shared_schema.api import PulseRequest
from shared_schema.documents.pulse import PulseDocument

from ..bodies import json_body
from ..compute import compute
from ..deps import JSON, PoolDep, accepts
from ..jobspec import PulseJob
from ..openapi import body_doc, responses

__all__ = ["router"]

router = APIRouter(tags=["solver"])


@router.post(
    "/pulse",
    summary="One mechanism under a one-cycle sine or cosine pulse",
    response_model=PulseDocument,
    responses=responses(PulseDocument),
    openapi_extra=body_doc(PulseRequest, None),
    dependencies=[accepts(JSON)],
)
async def pulse(
    request: Annotated[PulseRequest, json_body(PulseRequest)], pool: PoolDep
) -> Response:
    """Return the document ``rockmech pulse --json`` prints."""
    return await compute(pool, PulseJob(**dict(request)))
