"""``POST /check`` and ``POST /assess``: code checks beside rocking dynamics (theory §11).

``/check`` answers the document ``rockmech check --json`` prints; ``/assess`` the document
``rockmech assess --json`` prints or, with ``format: "html"``, the page ``rockmech assess``
writes, or with ``format: "pdf"`` that page printed by a headless Chromium (501 naming it
where the deployment has none).
"""

from __future__ import annotations

from typing import Annotated, Any, Union

from fastapi import APIRouter, Response

from shared_schema.api import AssessRequest, CheckRequest
from shared_schema.documents.assess import AssessDocument
from shared_schema.documents.check import CheckDocument

from ..bodies import json_body
from ..compute import compute
from ..deps import JSON, PoolDep, accepts
from ..jobspec import AssessHtmlJob, AssessJob, AssessPdfJob, CheckJob
from ..openapi import body_doc, responses

__all__ = ["router"]

router = APIRouter(tags=["assessment"], dependencies=[accepts(JSON)])


def _json_or_html(model: Any) -> dict[Any, Any]:
    """Documented answers: the document as JSON, or the page as text/html."""
    out = responses(model)
    out[200] = {
        "model": model,
        "description": "The assessment document (format json) or its HTML page (format html).",
        "content": {
            "text/html": {"schema": {"type": "string"}},
            "application/pdf": {"schema": {"type": "string", "format": "binary"}},
        },
    }
    return out


@router.post(
    "/check",
    summary="Code checks (Circolare 2019 §C8.7.1, NTC 2018) of every mechanism on a site",
    response_model=CheckDocument,
    responses=responses(CheckDocument),
    openapi_extra=body_doc(CheckRequest, None),
)
async def check(
    request: Annotated[CheckRequest, json_body(CheckRequest)], pool: PoolDep
) -> Response:
    """Return the document ``rockmech check --json`` prints."""
    return await compute(pool, CheckJob(**dict(request)))


@router.post(
    "/assess",
    summary="Assessment: code checks beside rocking dynamics on records scaled to the site",
    response_model=AssessDocument,
    responses=_json_or_html(AssessDocument),
    openapi_extra=body_doc(AssessRequest, None),
)
async def assess(
    request: Annotated[AssessRequest, json_body(AssessRequest)], pool: PoolDep
) -> Response:
    """Return the document ``rockmech assess --json`` prints, or the page it writes."""
    kinds = {"html": AssessHtmlJob, "pdf": AssessPdfJob}
    job: Union[AssessJob, AssessHtmlJob, AssessPdfJob] = kinds.get(request.format, AssessJob)(
        **dict(request)
    )
    return await compute(pool, job)
