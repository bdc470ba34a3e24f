"""The FastAPI application of the rockmech solver service (``/api/v1``).

Thin routers (``solver_service.api.routes``, one module per resource): each endpoint
validates its request with a model from ``shared_schema.api``, builds a typed job
(``solver_service.api.jobspec``), hands it to the compute pool (``solver_service.api.pool``)
and returns the document the worker produced, which is the one ``rockmech ... --json``
prints. rockmech's errors become 4xx answers with the CLI's message; a computation past the
time budget becomes 503 and the server carries on.

Status codes: 400 malformed body, 404 unknown path, 405 wrong method, 413 body too large,
415 wrong content type, 422 invalid input (including size limits), 501 optional feature not
installed, 503 time budget exceeded, no compute process free (or still starting), or the
service shutting down.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from typing import Optional

from fastapi import Depends, FastAPI

from .deps import bind_client
from .guard import HostGuard
from .hops import RockmechHops
from .limits import VALUES_PER_MECHANISM, VALUES_SLACK, BodyLimit
from .openapi import install_openapi, operation_id
from .pool import ComputePool
from .problems import install_handlers
from .routes import API_PREFIX, api_router
from .routes.hops import hops_router, thread_job_runner
from .routes.meta import rockmech_version
from .settings import Settings
from .shutdown import ShutdownAnswer

__all__ = ["API_PREFIX", "create_app", "rockmech_version"]

_DESCRIPTION = (
    "Rocking collapse mechanisms of masonry: kinematic constants from Rhino scenes, "
    "pulse responses, overturning envelopes, time histories, spectra, scale factors "
    "and HTML reports. SI units unless a name says otherwise (_g: in g)."
)


def create_app(settings: Optional[Settings] = None) -> FastAPI:
    """Build the service.

    Parameters
    ----------
    settings : Settings, optional
        Default: read from the environment (``ROCKMECH_*``).

    Returns
    -------
    FastAPI
        The app; its lifespan starts and stops the compute pool.
    """
    cfg = settings or Settings()
    pool = ComputePool(
        cfg.compute_workers,
        cfg.compute_timeout_s,
        cfg.queue_timeout_s,
        cfg.startup_timeout_s,
        cfg.limits(),
    )

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        await pool.start()
        try:
            yield
        finally:
            await pool.close()

    app = FastAPI(
        title="rockmech solver service",
        version=rockmech_version(),
        description=_DESCRIPTION,
        lifespan=lifespan,
        openapi_url=f"{API_PREFIX}/openapi.json",
        docs_url=f"{API_PREFIX}/docs",
        redoc_url=None,
        separate_input_output_schemas=False,
        generate_unique_id_function=operation_id,
        dependencies=[Depends(bind_client)],
    )
    max_values = cfg.max_samples + VALUES_PER_MECHANISM * cfg.max_mechanisms + VALUES_SLACK
    app.add_middleware(BodyLimit, limit=cfg.max_body_bytes, max_values=max_values)
    # Added last, so it runs first: foreign hosts and origins are refused before any body.
    app.add_middleware(HostGuard, hosts=cfg.allowed_hosts, origins=cfg.allowed_origins)
    # Outermost: a request the shutdown cancels still gets the service's JSON error (503).
    app.add_middleware(ShutdownAnswer, grace_s=cfg.shutdown_timeout_s)
    app.state.settings = cfg
    app.state.pool = pool
    install_handlers(app, cfg.max_body_bytes)
    app.include_router(api_router())
    app.state.hops = RockmechHops(thread_job_runner(pool))
    app.include_router(hops_router())
    install_openapi(app)
    return app
