"""The service's OpenAPI document: error answers, multipart bodies and readable operation ids."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Optional

from fastapi import FastAPI
from fastapi.openapi.utils import get_openapi
from fastapi.routing import APIRoute
from pydantic import BaseModel, TypeAdapter

from shared_schema.api import ErrorResponse

from .deps import JSON, MULTIPART
from .forms import FORMS, multipart_schema

__all__ = ["TAGS", "body_doc", "install_openapi", "operation_id", "responses"]

#: OpenAPI tags, in the order the document lists them.
TAGS = [
    {"name": "service", "description": "Status and published schemas."},
    {"name": "solver", "description": "Pulses, envelopes and scale factors."},
    {"name": "records", "description": "Time histories and spectra of ground motions."},
    {"name": "geometry", "description": "Kinematic constants from Rhino scenes."},
    {"name": "reports", "description": "Self-contained HTML reports."},
    {
        "name": "assessment",
        "description": "Code checks (NTC 2018 / EC8 sites) beside rocking dynamics.",
    },
]

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


#: Where the document keeps a schema.
_REF = "#/components/schemas/{model}"
#: Schemas of the JSON bodies that routes parse themselves (``body_doc``), by name.
_BODY_SCHEMAS: dict[str, dict[str, Any]] = {}


def operation_id(route: APIRoute) -> str:
    """Operation id of a route: its function's name (``pulse``, ``scale_factor``, ...)."""
    return route.name


def responses(model: Any, media: str = JSON, extra: Sequence[int] = ()) -> dict[Any, Any]:
    """Documented answers of a compute endpoint: 200 with ``model`` (or text), and the errors."""
    out: dict[Any, Any] = (
        {200: {"model": model}}
        if media == JSON
        else {
            200: {"content": {media: {"schema": {"type": "string"}}}, "description": "The report."}
        }
    )
    out.update(_ERRORS)
    for code in extra:
        out[code] = {"model": ErrorResponse, "description": "Not available in this deployment."}
    return out


def _json_schema(model: Any) -> dict[str, Any]:
    """Return the schema of a JSON body (a reference, or a union inline); keep its parts."""
    doc = TypeAdapter(model).json_schema(ref_template=_REF)
    for name, sub in doc.pop("$defs", {}).items():
        _BODY_SCHEMAS.setdefault(name, sub)
    if isinstance(model, type) and issubclass(model, BaseModel):
        _BODY_SCHEMAS.setdefault(model.__name__, doc)
        return {"$ref": _REF.format(model=model.__name__)}
    return doc


def body_doc(json_model: Any, form: Optional[str]) -> dict[str, Any]:
    """``openapi_extra`` of a route that reads its body itself: JSON and/or multipart.

    ``json_model`` is a pydantic model or a union of them (``ScaleFactorRequest``); its
    schemas go into the document's components (``install_openapi``).
    """
    content: dict[str, Any] = {}
    if json_model is not None:
        content[JSON] = {"schema": _json_schema(json_model)}
    if form is not None:
        content[MULTIPART] = {"schema": multipart_schema(FORMS[form])}
    return {"requestBody": {"required": True, "content": content}}


def install_openapi(app: FastAPI) -> None:
    """Build the document once, adding the JSON models of routes that parse their own body."""

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            schema = get_openapi(
                title=app.title,
                version=app.version,
                description=app.description,
                routes=app.routes,
                tags=TAGS,
                separate_input_output_schemas=False,
            )
            components = schema.setdefault("components", {}).setdefault("schemas", {})
            for name, sub in _BODY_SCHEMAS.items():
                components.setdefault(name, sub)
            app.openapi_schema = schema
        return app.openapi_schema

    setattr(app, "openapi", openapi)  # noqa: B010 - FastAPI's documented override
