"""The service's routers, one module per resource, all under ``/api/v1`` (Hops under ``/hops``)."""

from __future__ import annotations

from fastapi import APIRouter

from . import (
    assess,
    constants,
    envelope,
    meta,
    pulse,
    records,
    report,
    retrofit,
    scale_factor,
    search,
)

__all__ = ["API_PREFIX", "api_router"]

#: Version prefix of every REST endpoint.
API_PREFIX = "/api/v1"


def api_router() -> APIRouter:
    """Return every REST route under ``API_PREFIX``."""
    router = APIRouter(prefix=API_PREFIX)
    modules = (meta, constants, search, pulse, envelope, scale_factor, records, report, assess)
    for module in (*modules, retrofit):
        router.include_router(module.router)
    return router
