"""``POST /search``: a façade's collapse mechanisms found and ranked (``rockmech search``)."""

from __future__ import annotations

from fastapi import APIRouter, Request, Response

from shared_schema.documents.search import SearchDocument

from ..compute import compute
from ..deps import MULTIPART, PoolDep, accepts
from ..forms import FORMS, check_scene_upload, parse_form, read_form, read_upload
from ..jobspec import RecordUpload, SearchJob
from ..openapi import body_doc, responses

__all__ = ["router"]

router = APIRouter(tags=["geometry"])


@router.post(
    "/search",
    summary="Find a façade's collapse mechanisms in a scene and rank them by how they rock",
    response_model=SearchDocument,
    responses=responses(SearchDocument, extra=(501,)),
    openapi_extra=body_doc(None, "search"),
    dependencies=[accepts(MULTIPART)],
)
async def search(request: Request, pool: PoolDep) -> Response:
    """Return the document ``rockmech search --json`` prints (``search.json``).

    A search whose refinements would need more evaluations of the static multiplier than the
    work limit (``max_evaluations``, at most the service's) is refused with 422 before it
    runs them; the compute timeout bounds the rest.
    """
    form = await read_form(request)
    try:
        fields = parse_form(form, FORMS["search"])
        scene = await read_upload(form, "scene", True)
        spec = await read_upload(form, "spec", True)
        site = await read_upload(form, "site", False)
        record = await read_upload(form, "record", False)
    finally:
        await form.close()
    assert scene is not None and spec is not None
    upload = None
    if record is not None:
        upload = RecordUpload(
            filename=record[1] or "record.dat",
            format=fields.get("record_format"),
            units=fields.get("record_units"),
            dt=fields.get("record_dt"),
        )
    job = SearchJob(
        scene_name=scene[1],
        spec_name=spec[1],
        units=fields.get("units"),
        max_evaluations=fields.get("max_evaluations"),
        exact=bool(fields.get("exact", False)),
        has_site=site is not None,
        site_name=site[1] if site is not None else "",
        record=upload,
    )
    check_scene_upload(scene[0], scene[1])
    blobs = [scene[0], spec[0]]
    if site is not None:
        blobs.append(site[0])
    if record is not None:
        blobs.append(record[0])
    return await compute(pool, job, blobs)
