"""``POST /scale-factor``: Eq. 28, EN 1998-1 or NZS 1170.5 scale factors up the structure."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Response

from shared_schema.api import ScaleFactorRequest, ScaleFactorResponse

from ..bodies import json_body
from ..compute import compute
from ..deps import JSON, PoolDep, accepts
from ..jobspec import ScaleFactorJob
from ..openapi import body_doc, responses

__all__ = ["router"]

router = APIRouter(tags=["solver"])


@router.post(
    "/scale-factor",
    summary="Scale factor up the structure: Eq. 28, EC8 or NZS 1170.5",
    response_model=None,
    responses=responses(ScaleFactorResponse),
    openapi_extra=body_doc(ScaleFactorRequest, None),
    dependencies=[accepts(JSON)],
)
async def scale_factor(
    request: Annotated[ScaleFactorRequest, json_body(ScaleFactorRequest)], pool: PoolDep
) -> Response:
    """Return the factor, its formula and its inputs (``solver_service.codes.scale_factors``)."""
    return await compute(pool, ScaleFactorJob(request=request))
