"""``GET /health`` and the published JSON Schema of the kinematic-constants file."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from fastapi import APIRouter, Response

from shared_schema.api import HealthResponse
from shared_schema.export import render_schema
from shared_schema.version import __version__

from ..deps import PoolDep, SettingsDep

__all__ = ["rockmech_version", "router"]

router = APIRouter(tags=["service"])


def rockmech_version() -> str:
    """Return the installed rockmech version."""
    try:
        return version("rockmech")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "unknown"


@router.get(
    "/health",
    response_model=HealthResponse,
    summary="Service status",
    responses={
        503: {"model": HealthResponse, "description": "The compute processes are starting."}
    },
)
async def health(pool: PoolDep, settings: SettingsDep) -> Response:
    """Return the version, the compute processes alive and the compute time budget.

    503 with ``status: starting`` until every compute process has warmed up.
    """
    doc = HealthResponse(
        status="ok" if pool.ready else "starting",
        version=rockmech_version(),
        rockmech_version=__version__,
        units={"compute_timeout_s": "s"},
        compute_workers=pool.alive,
        compute_timeout_s=settings.compute_timeout_s,
    )
    return Response(
        doc.model_dump_json(),
        status_code=200 if pool.ready else 503,
        media_type="application/json",
        headers=None if pool.ready else {"Retry-After": "1"},
    )


@router.get(
    "/schema/kinematic-constants.json",
    summary="JSON Schema of the kinematic-constants file",
    response_class=Response,
    responses={200: {"content": {"application/schema+json": {"schema": {"type": "object"}}}}},
)
async def kinematic_constants_schema() -> Response:
    """Return the text of ``shared_schema/jsonschema/kinematic_constants.schema.json``."""
    return Response(render_schema(), media_type="application/schema+json")
