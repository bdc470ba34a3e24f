"""JSON request bodies: the one place every endpoint's JSON body is parsed and validated.

A route that takes JSON declares its body with ``json_body(Model)`` (or, when it also takes a
multipart form, calls ``validate_json``), so that every endpoint answers a bad body alike:
an empty body names the fields to send, a body nested too deeply names the depth limit, and
a body that does not fit the model gets rockmech's own message naming the field (422).
"""

from __future__ import annotations

import json
import math
from typing import Any, Optional, TypeVar, Union

from fastapi import Depends, Request
from pydantic import TypeAdapter, ValidationError

from .problems import Problem, validation_message

__all__ = ["MAX_BODY_DEPTH", "json_body", "out_of_range", "parse_json", "validate_json"]

#: Deepest nesting of a JSON body that is parsed [levels]: the recursion limit of pydantic's
#: JSON parser (a test pins it), well above the few levels a request needs.
MAX_BODY_DEPTH = 200

M = TypeVar("M")


def _fields_to_send(adapter: TypeAdapter[Any]) -> str:
    """Name the required fields of a body in words.

    For example ``a_p_g and f_p; and p_eq, lam and eta, or mechanism`` (``oneOf`` forms).
    """
    schema = adapter.json_schema()
    chooser = schema.get("discriminator")
    if chooser:
        choices = ", ".join(chooser.get("mapping", {}))
        return f"{chooser['propertyName']} (one of {choices}) and that method's fields"
    text = _and(list(schema.get("required", []))) or "its fields"
    # Fields required by one of several forms (a pulse: p_eq, lam and eta, or mechanism).
    needs = [list(b.get("required", [])) for b in schema.get("oneOf", [])]
    forms = [need for need in needs if need and not any(set(other) < set(need) for other in needs)]
    if forms:
        text += "; and " + ", or ".join(_and(form) for form in forms)
    return text


def _and(names: list[str]) -> str:
    """Join names as ``a, b and c``."""
    if len(names) > 1:
        return ", ".join(names[:-1]) + f" and {names[-1]}"
    return names[0] if names else ""


def _too_deep(exc: ValidationError) -> bool:
    return any(
        e["type"] == "json_invalid" and "recursion limit" in str(e.get("msg", ""))
        for e in exc.errors(include_url=False)
    )


#: Any JSON value, read by pydantic's parser (whose recursion limit is ``MAX_BODY_DEPTH``).
_ANY_JSON: TypeAdapter[Any] = TypeAdapter(Any)


def parse_json(body: bytes) -> Any:
    """Return the JSON value of ``body``, read with the depth limit of every request body.

    For the routes that take JSON outside a model (Hops), so that they refuse a deep body
    as the others do.

    Raises
    ------
    ValueError
        The body is not JSON, or it is nested deeper than ``MAX_BODY_DEPTH`` levels (the
        message says which).
    """
    try:
        return _ANY_JSON.validate_json(body)
    except ValidationError as exc:
        if _too_deep(exc):
            raise ValueError(
                f"the request body is nested deeper than {MAX_BODY_DEPTH} levels"
            ) from None
        first = exc.errors(include_url=False)[0]
        raise ValueError(str(first.get("msg", "invalid JSON"))) from None


class _OutOfRange:
    """A JSON number beyond double precision (its text kept for the message)."""

    def __init__(self, text: str) -> None:
        self.text = text


def _number(text: str) -> Any:
    """Read a JSON number; one that no double can hold becomes ``_OutOfRange``.

    Python's own reading would refuse an integer of more than 4300 digits with its own
    words ("Exceeds the limit (4300 digits) for integer string conversion").
    """
    digits = len(text.lstrip("-"))
    if digits > 400:  # past 1.8e308 whatever the digits, and past Python's digit limit
        return _OutOfRange(text)
    value = float(text)
    return value if math.isfinite(value) else _OutOfRange(text)


def _path(value: Any, prefix: str = "") -> Optional[tuple[str, str]]:
    """(field path, number text) of the first ``_OutOfRange`` in ``value``."""
    if isinstance(value, _OutOfRange):
        return prefix, value.text
    items = (
        value.items()
        if isinstance(value, dict)
        else enumerate(value)
        if isinstance(value, list)
        else ()
    )
    for key, item in items:
        name = (
            f"{prefix}[{key}]"
            if isinstance(key, int)
            else f"{prefix}.{key}"
            if prefix
            else str(key)
        )
        found = _path(item, name)
        if found is not None:
            return found
    return None


def out_of_range(body: bytes) -> Optional[Problem]:
    """Return the 422 for a JSON body holding a number beyond double precision.

    The message names the number's field; None if the body holds none, or is not JSON.
    """
    try:
        data = json.loads(body, parse_int=_number, parse_float=_number)
    except (ValueError, RecursionError):
        return None
    found = _path(data)
    if found is None:
        return None
    field, text = found
    return Problem(
        422,
        "InputError",
        f"{field}: the number {text} is out of the range of double "
        "precision (magnitudes up to 1.8e308)",
        field or None,
    )


def validate_json(model: Union[type[M], TypeAdapter[M]], body: bytes) -> M:
    """Validate a JSON body with ``model``; 422 with rockmech's message if it does not fit.

    Parameters
    ----------
    model : type or TypeAdapter
        The request model (a pydantic model, or an adapter of a union of them).
    body : bytes
        The request body.

    Raises
    ------
    Problem
        422: the body is empty (the message names the fields to send), nested deeper than
        ``MAX_BODY_DEPTH`` levels, not JSON, or does not fit the model (the message names the
        field, as ``rockmech`` does for the same input).
    """
    adapter: TypeAdapter[M] = model if isinstance(model, TypeAdapter) else TypeAdapter(model)
    if not body.strip():
        raise Problem(
            422,
            "InputError",
            f"the request body is empty; send a JSON object with {_fields_to_send(adapter)}",
        )
    try:
        return adapter.validate_json(body)
    except ValidationError as exc:
        if _too_deep(exc):
            raise Problem(
                422,
                "InputError",
                f"the request body is nested deeper than {MAX_BODY_DEPTH} levels",
            ) from None
        if any(e["type"] == "json_invalid" for e in exc.errors(include_url=False)):
            problem = out_of_range(body)  # "number out of range at line 1 column 4311"
            if problem is not None:
                raise problem from None
        try:
            data = json.loads(body)
        except (ValueError, RecursionError):
            data = None
        message, field = validation_message(exc.errors(include_url=False), data)
        raise Problem(422, "InputError", message, field) from None


def json_body(model: Any) -> Any:
    """Dependency of a route: its JSON body, validated with ``model`` by ``validate_json``.

    Declare the body as ``Annotated[Model, json_body(Model)]`` and document it with
    ``openapi.body_doc(Model, None)``: FastAPI's own body parsing answers an empty or deeply
    nested body in its own words (400 "There was an error parsing the body").
    """
    adapter: TypeAdapter[Any] = TypeAdapter(model)

    async def parse(request: Request) -> Any:
        return validate_json(adapter, await request.body())

    return Depends(parse)
