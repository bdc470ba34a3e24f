"""Dependencies of the routers, declared once: the settings, the compute pool, content types.

The app keeps its settings and pool on ``app.state``; routers receive them as typed
parameters (``SettingsDep``, ``PoolDep``). ``accepts`` is the service's one content-type
check: a route lists the media types it takes and anything else gets 415.
"""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import Depends, Request
from starlette.exceptions import HTTPException

from .compute import CLIENT
from .pool import ComputePool
from .settings import Settings

__all__ = ["JSON", "MULTIPART", "PoolDep", "SettingsDep", "accepts", "bind_client", "media_type"]

JSON = "application/json"
MULTIPART = "multipart/form-data"


def _settings(request: Request) -> Settings:
    settings: Settings = request.app.state.settings
    return settings


def _pool(request: Request) -> ComputePool:
    pool: ComputePool = request.app.state.pool
    return pool


#: The service's settings.
SettingsDep = Annotated[Settings, Depends(_settings)]
#: The compute pool.
PoolDep = Annotated[ComputePool, Depends(_pool)]


def media_type(request: Request) -> str:
    """Return the request's media type, lower case, without parameters."""
    return request.headers.get("content-type", "").split(";", 1)[0].strip().lower()


def accepts(*allowed: str) -> Any:
    """Dependency of a route: refuse a body of another media type with 415."""

    async def check(request: Request) -> None:
        got = media_type(request)
        if got not in allowed:
            raise HTTPException(
                415,
                f"content type {got or '(none)'!r} is not accepted; send {' or '.join(allowed)}",
            )

    return Depends(check)


async def bind_client(request: Request) -> None:
    """App-wide dependency: remember the request, so a job can notice its client leave."""
    CLIENT.set(request)
