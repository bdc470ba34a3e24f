"""Pydantic's validation errors in rockmech's words: ``(path, message)`` per error.

The one formatting of validation errors: the constants file, spec files, search specs, API
requests, Hops inputs and settings all read the same (``shared_schema.constants`` and
``shared_schema.spec`` use it).

Python 3.9-clean: imported by Rhino 8.
"""

import re
from typing import Any, List, Mapping, Optional, Sequence, Tuple, Union

from pydantic import ValidationError

__all__ = ["validation_lines"]


def _mechanism_label(data: Any, index: int) -> str:
    mechanisms = data.get("mechanisms") if isinstance(data, Mapping) else None
    if isinstance(mechanisms, Sequence) and not isinstance(mechanisms, (str, bytes)):
        if 0 <= index < len(mechanisms):
            item = mechanisms[index]
            mech_id = item.get("id") if isinstance(item, Mapping) else None
            if isinstance(mech_id, str) and mech_id:
                return f" (id {mech_id!r})"
    return ""


def _format_loc(loc: Sequence[Union[int, str]], data: Any, extra: Optional[str]) -> str:
    parts: List[Union[int, str]] = list(loc)
    if extra:
        index = re.fullmatch(r"\[(\d+)\]", extra)
        parts.append(int(index.group(1)) if index else extra)
    out = ""
    for i, part in enumerate(parts):
        if isinstance(part, int):
            out += f"[{part}]"
            if i == 1 and parts[0] == "mechanisms":
                out += _mechanism_label(data, part)
        else:
            out += f".{part}" if out else str(part)
    return out


def validation_lines(
    errors: Union[ValidationError, Sequence[Mapping[str, Any]]], data: Any = None
) -> List[Tuple[str, str]]:
    """``(path, message)`` of every error of a pydantic ``ValidationError``, in our words.

    The one formatting of validation errors in rockmech: the constants file, spec files, API
    requests, Hops inputs and settings all read the same. ``errors`` is the exception or its
    ``errors()`` list (FastAPI's request errors). Paths look like
    ``mechanisms[1] (id 'W2').positive.p_eq`` (the mechanism named by its id when ``data``,
    the input as plain Python data, has one); pydantic's "Value error, " prefix is dropped
    and an unknown key says so.
    """
    items = errors.errors(include_url=False) if isinstance(errors, ValidationError) else errors
    out: List[Tuple[str, str]] = []
    for err in items:
        ctx = err.get("ctx") or {}
        extra = ctx.get("field") if isinstance(ctx.get("field"), str) else None
        msg = str(err["msg"]).replace("Value error, ", "")
        if err["type"] == "extra_forbidden":
            msg = "unknown key; " + msg
        out.append((_format_loc(err["loc"], data, extra), msg))
    return out
