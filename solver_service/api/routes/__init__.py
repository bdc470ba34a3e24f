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

__all__ = ["API_PREFIX", "ROUTE_MODULES", "api_router"]

#: Version prefix of every REST endpoint.
API_PREFIX = "/api/v1"
#: The modules of the routers, in the order the service includes them.
ROUTE_MODULES = (
    meta,
    constants,
    search,
    pulse,
    envelope,
    scale_factor,
    records,
    report,
    assess,
    retrofit,
)


def api_router() -> APIRouter:
    """Return every REST route under ``API_PREFIX``."""
    router = APIRouter(prefix=API_PREFIX)
    for module in ROUTE_MODULES:
        router.include_router(module.router)
    return router
