"""The FastAPI application of the rockmech solver service (``/api/v1``).

Thin routers: each endpoint validates its request with a model from ``shared_schema.api``,
hands the work to the compute pool (``solver_service.api.pool``) and returns the document
the worker produced, which is the one ``rockmech ... --json`` prints. rockmech's errors
become 4xx answers with the CLI's message; a computation past the time budget becomes 503
and the server carries on.

Status codes: 400 malformed body, 404 unknown path, 405 wrong method, 413 body too large,
415 wrong content type, 422 invalid input (including size limits), 501 optional feature not
installed, 503 time budget exceeded or no compute process free.
"""

from __future__ import annotations

import json
import logging
from collections.abc import AsyncIterator, Sequence
from contextlib import asynccontextmanager
from typing import Any, Optional, Union

from fastapi import APIRouter, Depends, FastAPI, Request, Response
from fastapi.exceptions import RequestValidationError
from fastapi.openapi.utils import get_openapi
from pydantic import BaseModel, ValidationError
from starlette.datastructures import FormData, UploadFile
from starlette.exceptions import HTTPException as StarletteHTTPException

from shared_schema.api import (
    ConstantsResponse,
    EnvelopeRequest,
    EnvelopeResponse,
    ErrorResponse,
    HealthResponse,
    HistoryRequest,
    HistoryResponse,
    PulseRequest,
    PulseResponse,
    ReportRequest,
    ScaleFactorRequest,
    ScaleFactorResponse,
    SpectrumRequest,
    SpectrumResponse,
)
from shared_schema.constants import parse_constants
from shared_schema.errors import InputError
from shared_schema.export import render_schema

from .errors import error_body
from .forms import FORMS, FormSpec, form_fields, multipart_schema
from .hops import RockmechHops, hops_router
from .limits import BodyLimit, too_large_message
from .pool import BudgetExceeded, ComputePool, PoolBusy, WorkerLost
from .settings import Settings

__all__ = ["API_PREFIX", "create_app", "rockmech_version"]

log = logging.getLogger("rockmech.api")

#: Version prefix of every REST endpoint.
API_PREFIX = "/api/v1"
#: Most files and fields a multipart request may carry.
MAX_FORM_FILES = 4
MAX_FORM_FIELDS = 200

_JSON = "application/json"
_MULTIPART = "multipart/form-data"


def rockmech_version() -> str:
    """Return the installed rockmech version."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("rockmech")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "unknown"


def _error(status: int, kind: str, message: str, field: Optional[str] = None) -> Response:
    return Response(error_body(kind, message, field), status_code=status, media_type=_JSON)


def _loc_path(loc: Sequence[Union[int, str]]) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


def validation_message(errors: Sequence[Any], data: Any) -> tuple[str, Optional[str]]:
    """Turn pydantic errors of a request into one message and the path of the first field.

    Errors inside ``constants`` are reported exactly as ``rockmech`` reports the same
    constants file, with ``constants`` in place of the file name.
    """
    if isinstance(data, dict) and isinstance(data.get("constants"), dict):
        if any(tuple(e["loc"][:1]) == ("constants",) for e in errors):
            try:
                parse_constants(data["constants"])
            except InputError as exc:
                field = f"constants.{exc.field}" if exc.field else "constants"
                return f"constants: {exc}", field
    lines, first = [], None
    for err in errors:
        path = _loc_path(err["loc"])
        msg = err["msg"]
        if err["type"] == "extra_forbidden":
            msg = "unknown key; " + msg
        lines.append(f"{path}: {msg}" if path else msg)
        first = first or path or None
    return "\n".join(lines), first


def _media_type(request: Request) -> str:
    return request.headers.get("content-type", "").split(";", 1)[0].strip().lower()


def _require(*allowed: str) -> Any:
    """Dependency: refuse other content types with 415."""

    async def check(request: Request) -> None:
        got = _media_type(request)
        if got not in allowed:
            raise StarletteHTTPException(
                415,
                f"content type {got or '(none)'!r} is not accepted; send {' or '.join(allowed)}",
            )

    return Depends(check)


class _Problem(Exception):
    def __init__(self, status: int, kind: str, message: str, field: Optional[str] = None) -> None:
        super().__init__(message)
        self.status, self.kind, self.field = status, kind, field


def _validate_json(model: type[BaseModel], body: bytes) -> BaseModel:
    try:
        return model.model_validate_json(body)
    except ValidationError as exc:
        try:
            data = json.loads(body)
        except (ValueError, RecursionError):
            data = None
        message, field = validation_message(exc.errors(include_url=False), data)
        raise _Problem(422, "InputError", message, field) from None


async def _read_form(request: Request) -> FormData:
    return await request.form(max_files=MAX_FORM_FILES, max_fields=MAX_FORM_FIELDS)


async def _upload(form: FormData, name: str, required: bool) -> Optional[tuple[bytes, str]]:
    """Return an uploaded part's bytes and file name (a text part is accepted as a file)."""
    items = form.getlist(name)
    if not items:
        if required:
            raise _Problem(422, "InputError", "missing; upload it as a file part", name)
        return None
    if len(items) > 1:
        raise _Problem(422, "InputError", "give one file", name)
    item = items[0]
    if isinstance(item, UploadFile):
        return await item.read(), item.filename or ""
    return item.encode("utf-8"), ""


def _parse_form(form: FormData, spec: FormSpec) -> dict[str, Any]:
    try:
        values = form_fields(form, spec)
        return spec.model.model_validate(values).model_dump()
    except ValidationError as exc:
        message, field = validation_message(exc.errors(include_url=False), None)
        raise _Problem(422, "InputError", message, field) from None
    except ValueError as exc:
        raise _Problem(422, "InputError", str(exc)) from None


_ERRORS = {
    code: {"model": ErrorResponse, "description": text}
    for code, text in (
        (400, "Malformed request body."),
        (413, "Request body larger than ROCKMECH_MAX_BODY_BYTES."),
        (415, "Wrong content type."),
        (422, "Invalid input (the message is the one rockmech prints), or a size limit."),
        (503, "Compute time budget exceeded, or no compute process free."),
    )
}


def _responses(model: Any, media: str = _JSON, extra: Sequence[int] = ()) -> dict[Any, Any]:
    out: dict[Any, Any] = (
        {200: {"model": model}}
        if media == _JSON
        else {
            200: {"content": {media: {"schema": {"type": "string"}}}, "description": "The report."}
        }
    )
    out.update(_ERRORS)
    for code in extra:
        out[code] = {"model": ErrorResponse, "description": "Not available in this deployment."}
    return out


def _body_doc(json_model: Optional[type[BaseModel]], form: Optional[str]) -> dict[str, Any]:
    content: dict[str, Any] = {}
    if json_model is not None:
        content[_JSON] = {"schema": {"$ref": f"#/components/schemas/{json_model.__name__}"}}
    if form is not None:
        content[_MULTIPART] = {"schema": multipart_schema(FORMS[form])}
    return {"requestBody": {"required": True, "content": content}}


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
        description=(
            "Rocking collapse mechanisms of masonry: kinematic constants from Rhino scenes, "
            "pulse responses, overturning envelopes, time histories, spectra, scale factors "
            "and HTML reports. SI units unless a name says otherwise (_g: in g)."
        ),
        lifespan=lifespan,
        openapi_url=f"{API_PREFIX}/openapi.json",
        docs_url=f"{API_PREFIX}/docs",
        redoc_url=None,
        separate_input_output_schemas=False,
    )
    app.add_middleware(BodyLimit, limit=cfg.max_body_bytes)
    app.state.settings = cfg
    app.state.pool = pool

    async def compute(kind: str, params: dict[str, Any], blobs: Sequence[bytes] = ()) -> Response:
        try:
            result = await pool.run(kind, params, blobs)
        except (BudgetExceeded, PoolBusy) as exc:
            return _error(503, type(exc).__name__, str(exc))
        except WorkerLost as exc:
            return _error(422, "WorkerLost", str(exc))
        return Response(result.body, status_code=result.status, media_type=result.media_type)

    @app.exception_handler(RequestValidationError)
    async def on_validation(request: Request, exc: RequestValidationError) -> Response:
        errors = [
            {**e, "loc": tuple(e["loc"])[1:] if e["loc"][:1] == ("body",) else e["loc"]}
            for e in exc.errors()
        ]
        message, field = validation_message(errors, exc.body)
        return _error(422, "InputError", message, field)

    @app.exception_handler(StarletteHTTPException)
    async def on_http(request: Request, exc: StarletteHTTPException) -> Response:
        message = str(exc.detail)
        if exc.status_code == 413:
            message = too_large_message(cfg.max_body_bytes)
        response = _error(exc.status_code, "HTTPError", message)
        response.headers.update(exc.headers or {})
        return response

    @app.exception_handler(_Problem)
    async def on_problem(request: Request, exc: _Problem) -> Response:
        return _error(exc.status, exc.kind, str(exc), exc.field)

    @app.exception_handler(RecursionError)
    async def on_recursion(request: Request, exc: RecursionError) -> Response:
        return _error(400, "HTTPError", "request body nested too deeply")

    router = APIRouter(prefix=API_PREFIX)

    @router.get("/health", response_model=HealthResponse, summary="Service status")
    async def health() -> HealthResponse:
        return HealthResponse(
            status="ok",
            version=rockmech_version(),
            compute_workers=pool.alive,
            compute_timeout_s=cfg.compute_timeout_s,
        )

    @router.get(
        "/schema/kinematic-constants.json",
        summary="JSON Schema of the kinematic-constants file",
        response_class=Response,
        responses={200: {"content": {"application/schema+json": {"schema": {"type": "object"}}}}},
    )
    async def constants_schema() -> Response:

        return Response(render_schema(), media_type="application/schema+json")

    @router.post(
        "/pulse",
        summary="One mechanism under a one-cycle sine or cosine pulse",
        response_model=None,
        responses=_responses(PulseResponse),
        dependencies=[_require(_JSON)],
    )
    async def pulse(request: PulseRequest) -> Response:
        return await compute("pulse", request.model_dump())

    @router.post(
        "/envelope",
        summary="Overturning envelopes and the critical mechanism per frequency",
        response_model=None,
        responses=_responses(EnvelopeResponse),
        dependencies=[_require(_JSON)],
    )
    async def envelope(request: EnvelopeRequest) -> Response:
        params = request.model_dump(exclude={"constants"})
        params["constants"] = request.constants.model_dump(exclude_none=True)
        return await compute("envelope", params)

    @router.post(
        "/scale-factor",
        summary="Scale factor up the structure: Eq. 28, EC8 or NZS 1170.5",
        response_model=None,
        responses=_responses(ScaleFactorResponse),
        dependencies=[_require(_JSON)],
    )
    async def scale_factor(
        request: ScaleFactorRequest,
    ) -> Response:
        return await compute("scale_factor", request.model_dump())

    async def record_job(
        request: Request, kind: str, json_model: type[BaseModel], form_name: str
    ) -> Response:
        media = _media_type(request)
        if media == _JSON:
            body = await request.body()
            model = _validate_json(json_model, body)
            params = model.model_dump(exclude={"constants"})
            if "constants" in type(model).model_fields:
                dumped = model.model_dump(include={"constants"}, exclude_none=True)
                params["constants"] = dumped["constants"]
                params["constants_label"] = "constants"
            return await compute(kind, params)
        if media == _MULTIPART:
            form = await _read_form(request)
            try:
                spec = FORMS[form_name]
                params = _parse_form(form, spec)
                blobs: list[bytes] = []
                if spec.constants:
                    data, name = await _upload(form, "constants", True) or (b"", "")
                    params["constants"] = None
                    params["constants_label"] = name.rsplit("/", 1)[-1] or "constants"
                    blobs.append(data)
                record = await _upload(form, "record", spec.record_required)
                params["record"] = None
                if record is not None:
                    params["upload"] = {
                        "filename": record[1],
                        "format": params.pop("format", None),
                        "units": params.pop("units", None),
                        "dt": params.pop("dt", None),
                    }
                    blobs.append(record[0])
            finally:
                await form.close()
            return await compute(kind, params, blobs)
        return _error(
            415,
            "HTTPError",
            f"content type {media or '(none)'!r} is not accepted; send {_JSON} or {_MULTIPART}",
        )

    @router.post(
        "/history",
        summary="Time histories of every mechanism at every scale factor",
        response_model=None,
        responses=_responses(HistoryResponse),
        openapi_extra=_body_doc(HistoryRequest, "history"),
    )
    async def history(request: Request) -> Response:
        return await record_job(request, "history", HistoryRequest, "history")

    @router.post(
        "/spectrum",
        summary="Exact elastic response spectrum of a record",
        response_model=None,
        responses=_responses(SpectrumResponse),
        openapi_extra=_body_doc(SpectrumRequest, "spectrum"),
    )
    async def spectrum(request: Request) -> Response:
        return await record_job(request, "spectrum", SpectrumRequest, "spectrum")

    @router.post(
        "/report",
        summary="Self-contained HTML report",
        response_model=None,
        response_class=Response,
        responses=_responses(None, media="text/html"),
        openapi_extra=_body_doc(ReportRequest, "report"),
    )
    async def report(request: Request) -> Response:
        return await record_job(request, "report", ReportRequest, "report")

    @router.post(
        "/constants",
        summary="Kinematic constants from an uploaded .3dm scene and a mechanism spec",
        response_model=None,
        responses=_responses(ConstantsResponse, extra=(501,)),
        openapi_extra=_body_doc(None, "constants"),
    )
    async def constants(request: Request) -> Response:
        if _media_type(request) != _MULTIPART:
            got = _media_type(request) or "(none)"
            return _error(
                415, "HTTPError", f"content type {got!r} is not accepted; send {_MULTIPART}"
            )
        form = await _read_form(request)
        try:
            _parse_form(form, FORMS["constants"])
            scene = await _upload(form, "scene", True)
            spec = await _upload(form, "spec", True)
        finally:
            await form.close()
        assert scene is not None and spec is not None
        params = {"scene_name": scene[1], "spec_name": spec[1]}
        return await compute("constants", params, [scene[0], spec[0]])

    app.include_router(router)

    def run_job_from_thread(kind: str, params: dict[str, Any]) -> tuple[int, str, bytes]:
        import anyio.from_thread

        async def go() -> Response:
            return await compute(kind, params)

        response = anyio.from_thread.run(go)
        return response.status_code, response.media_type or _JSON, bytes(response.body)

    components = RockmechHops(run_job_from_thread)
    app.state.hops = components
    app.include_router(hops_router(lambda: components))

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            schema = get_openapi(
                title=app.title,
                version=app.version,
                description=app.description,
                routes=app.routes,
                separate_input_output_schemas=False,
            )
            components_ = schema.setdefault("components", {}).setdefault("schemas", {})
            for model in (HistoryRequest, SpectrumRequest, ReportRequest):
                doc = model.model_json_schema(ref_template="#/components/schemas/{model}")
                for name, sub in doc.pop("$defs", {}).items():
                    components_.setdefault(name, sub)
                components_.setdefault(model.__name__, doc)
            app.openapi_schema = schema
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
    return app
