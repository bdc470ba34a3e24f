"""Error answers of the service: one exception for a refused request, and the app's handlers.

Every error is JSON ``{"detail", "field", "error"}`` (``shared_schema.api.ErrorResponse``)
with rockmech's message; no traceback reaches a client.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Optional

from fastapi import FastAPI, Request, Response
from fastapi.exceptions import RequestValidationError
from starlette.exceptions import HTTPException as StarletteHTTPException

from shared_schema.constants import parse_constants, validation_lines
from shared_schema.errors import InputError
from shared_schema.site import parse_site

from .errors import error_body
from .limits import TooManyValues, too_large_message

__all__ = ["Problem", "error_response", "install_handlers", "validation_message"]

_JSON = "application/json"


class Problem(Exception):
    """A request refused with ``status``; ``kind`` and ``field`` go into the error body."""

    def __init__(
        self,
        status: int,
        kind: str,
        message: str,
        field: Optional[str] = None,
        headers: Optional[dict[str, str]] = None,
    ) -> None:
        super().__init__(message)
        self.status, self.kind, self.field = status, kind, field
        self.headers = headers or {}


def error_response(
    status: int,
    kind: str,
    message: str,
    field: Optional[str] = None,
    headers: Optional[dict[str, str]] = None,
) -> Response:
    """Return an error answer in the service's format."""
    return Response(
        error_body(kind, message, field), status_code=status, media_type=_JSON, headers=headers
    )


def validation_message(errors: Sequence[Any], data: Any) -> tuple[str, Optional[str]]:
    """Turn pydantic errors of a request into one message and the path of the first field.

    Errors inside ``constants`` (or ``site``) are reported exactly as ``rockmech`` reports
    the same constants (or site) file, with ``constants`` (``site``) in place of the file name.
    """
    for key, parse in (("constants", parse_constants), ("site", parse_site)):
        if not (isinstance(data, dict) and isinstance(data.get(key), dict)):
            continue
        if any(tuple(e["loc"][:1]) == (key,) for e in errors):
            try:
                parse(data[key])
            except InputError as exc:
                field = f"{key}.{exc.field}" if exc.field else key
                return f"{key}: {exc}", field
            except RecursionError:
                return f"{key}: nested too deeply", key
    found = validation_lines(errors)
    lines = [f"{path}: {msg}" if path else msg for path, msg in found]
    first = next((path for path, _ in found if path), None)
    return "\n".join(lines), first


def install_handlers(app: FastAPI, max_body_bytes: int) -> None:
    """Answer validation errors, HTTP errors and refused requests in the service's format."""

    @app.exception_handler(RequestValidationError)
    async def on_validation(request: Request, exc: RequestValidationError) -> Response:
        errors = [
            {**e, "loc": tuple(e["loc"])[1:] if e["loc"][:1] == ("body",) else e["loc"]}
            for e in exc.errors()
        ]
        message, field = validation_message(errors, exc.body)
        return error_response(422, "InputError", message, field)

    @app.exception_handler(StarletteHTTPException)
    async def on_http(request: Request, exc: StarletteHTTPException) -> Response:
        message = str(exc.detail)
        if exc.status_code == 413:
            message = too_large_message(max_body_bytes)
        if isinstance(exc, TooManyValues):
            return error_response(422, "InputError", message, "record")
        headers = dict(exc.headers) if exc.headers else None
        return error_response(exc.status_code, "HTTPError", message, headers=headers)

    @app.exception_handler(Problem)
    async def on_problem(request: Request, exc: Problem) -> Response:
        return error_response(exc.status, exc.kind, str(exc), exc.field, exc.headers)

    @app.exception_handler(RecursionError)
    async def on_recursion(request: Request, exc: RecursionError) -> Response:
        return error_response(400, "HTTPError", "request body nested too deeply")
