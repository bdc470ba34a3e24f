"""``POST /retrofit``: tie-bars for the mechanisms that fail the 2019 checks (theory §11.12).

The answer is the document ``rockmech retrofit --json`` prints, byte for byte the
``retrofit.json`` it writes. Two bodies, as ``/history`` takes its record:

* JSON (``RetrofitRequest``): constants, site and retrofit spec, as ``rockmech retrofit
  CONSTANTS``. Its work (the planned code checks) is bounded up front against the compute
  budget, as the command bounds it against ``--time-limit``.
* a multipart form (``FORMS["retrofit"]``): a scene, its search spec, the site, the retrofit
  spec and optionally a record, as ``rockmech retrofit --scene SCENE --search-spec SPEC``:
  the scene is searched, the designed ties go into it and it is searched again
  (``search_after``), and again per connection upgrade. The searches together stay within
  the work limit (``max_evaluations``): the search's work estimate counts once per search and
  a retrofit past it is refused with 422 before any search runs (in the compute process,
  which reads the scene).
"""

from __future__ import annotations

from fastapi import APIRouter, Request, Response

from shared_schema.api import RetrofitRequest, RetrofitResponse
from shared_schema.errors import InputError

from ..bodies import validate_json
from ..compute import compute
from ..deps import JSON, MULTIPART, PoolDep, accepts, media_type
from ..forms import FORMS, check_scene_upload, parse_form, read_form, read_upload
from ..jobspec import RecordUpload, RetrofitJob, RetrofitSceneJob
from ..openapi import body_doc, responses
from ..pool import ComputePool
from ..problems import Problem
from ..uploads import check_record_lines

__all__ = ["router"]

router = APIRouter(tags=["assessment"], dependencies=[accepts(JSON, MULTIPART)])

#: The file parts of the scene form, in the order the compute process takes them as blobs.
SCENE_PARTS = ("scene", "search_spec", "site", "spec")


@router.post(
    "/retrofit",
    summary="Tie-bars: the least tie force that makes each failing mechanism pass",
    response_model=RetrofitResponse,
    responses=responses(RetrofitResponse, extra=(501,)),
    openapi_extra=body_doc(RetrofitRequest, "retrofit"),
)
async def retrofit(request: Request, pool: PoolDep) -> Response:
    """Return the document ``rockmech retrofit --json`` prints (its ``retrofit.json``).

    A JSON body retrofits the constants it holds; a multipart form retrofits a scene
    (``rockmech retrofit --scene``), its two searches within ``max_evaluations`` together.
    """
    if media_type(request) == JSON:
        body = validate_json(RetrofitRequest, await request.body())
        return await compute(pool, RetrofitJob(**dict(body)))
    return await _scene_retrofit(request, pool)


async def _scene_retrofit(request: Request, pool: ComputePool) -> Response:
    """Read the scene form (``FORMS["retrofit"]``) and run its job."""
    form = await read_form(request)
    try:
        fields = parse_form(form, FORMS["retrofit"])
        parts = [await read_upload(form, name, True) for name in SCENE_PARTS]
        record = await read_upload(form, "record", False)
    finally:
        await form.close()
    scene, search_spec, site, spec = (p for p in parts if p is not None)
    upload = None
    if record is not None:
        try:  # before a compute process parses it (and holds it in memory)
            check_record_lines(record[0], pool.limits["max_samples"])
        except InputError as exc:
            raise Problem(422, "InputError", str(exc), exc.field) from None
        upload = RecordUpload(
            filename=record[1] or "record.dat",
            format=fields.get("record_format"),
            units=fields.get("record_units"),
            dt=fields.get("record_dt"),
        )
    job = RetrofitSceneJob(
        scene_name=scene[1],
        search_spec_name=search_spec[1],
        site_name=site[1],
        spec_name=spec[1],
        units=fields.get("units"),
        max_evaluations=fields.get("max_evaluations"),
        record=upload,
    )
    check_scene_upload(scene[0], scene[1])
    blobs = [scene[0], search_spec[0], site[0], spec[0]]
    if record is not None:
        blobs.append(record[0])
    return await compute(pool, job, blobs)
