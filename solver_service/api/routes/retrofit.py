"""``POST /retrofit``: tie-bars for the mechanisms that fail the 2019 checks (theory §11.12).

The answer is the document ``rockmech retrofit --json`` prints, byte for byte the
``retrofit.json`` it writes. Its work (the planned code checks) is bounded up front against
the compute budget, as the command bounds it against ``--time-limit``.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Response

from shared_schema.api import RetrofitRequest, RetrofitResponse

from ..bodies import json_body
from ..compute import compute
from ..deps import JSON, PoolDep, accepts
from ..jobspec import RetrofitJob
from ..openapi import body_doc, responses

__all__ = ["router"]

router = APIRouter(tags=["assessment"], dependencies=[accepts(JSON)])


@router.post(
    "/retrofit",
    summary="Tie-bars: the least tie force that makes each failing mechanism pass",
    response_model=RetrofitResponse,
    responses=responses(RetrofitResponse),
    openapi_extra=body_doc(RetrofitRequest, None),
)
async def retrofit(
    request: Annotated[RetrofitRequest, json_body(RetrofitRequest)], pool: PoolDep
) -> Response:
    """Return the document ``rockmech retrofit --json`` prints (its ``retrofit.json``)."""
    return await compute(pool, RetrofitJob(**dict(request)))
