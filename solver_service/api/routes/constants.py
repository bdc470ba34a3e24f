"""``POST /constants``: kinematic constants from an uploaded .3dm scene and a mechanism spec."""

from __future__ import annotations

from fastapi import APIRouter, Request, Response

from shared_schema.api import ConstantsResponse

from ..compute import compute
from ..deps import MULTIPART, PoolDep, accepts
from ..forms import FORMS, check_scene_upload, parse_form, read_form, read_upload
from ..jobspec import SceneJob
from ..openapi import body_doc, responses

__all__ = ["router"]

router = APIRouter(tags=["geometry"])


@router.post(
    "/constants",
    summary="Kinematic constants from an uploaded .3dm scene and a mechanism spec",
    response_model=None,
    responses=responses(ConstantsResponse, extra=(501,)),
    openapi_extra=body_doc(None, "constants"),
    dependencies=[accepts(MULTIPART)],
)
async def constants(request: Request, pool: PoolDep) -> Response:
    """Return the kinematic-constants file ``rockmech constants`` writes."""
    form = await read_form(request)
    try:
        fields = parse_form(form, FORMS["constants"])
        scene = await read_upload(form, "scene", True)
        spec = await read_upload(form, "spec", True)
    finally:
        await form.close()
    assert scene is not None and spec is not None
    job = SceneJob(scene_name=scene[1], spec_name=spec[1], units=fields.get("units"))
    check_scene_upload(scene[0], scene[1])
    return await compute(pool, job, [scene[0], spec[0]])
