"""The service's error bodies (``shared_schema.api.ErrorResponse``).

Light on purpose: the app process imports it without the compute modules, which only the
worker processes load.
"""

from __future__ import annotations

import json
import re
from typing import Any, Optional

__all__ = ["ECHO_LIMIT", "LINE_LIMIT", "clip_echoes", "error_body"]

#: Longest piece of a request's input an error message quotes back [characters].
ECHO_LIMIT = 200
#: Longest line of an error message [characters] (a message names a field and what is
#: wrong in well under this; only quoted input can make a line longer).
LINE_LIMIT = 2000
#: Runs a message may quote from its input: a quoted string, or a word without spaces (a
#: number, a name, a path).
_ECHO = re.compile(r"'[^'\n]{%d,}'|\"[^\"\n]{%d,}\"|[^\s'\"]{%d,}" % ((ECHO_LIMIT + 1,) * 3))


def _clip(text: str) -> str:
    quote = text[0] if len(text) > 1 and text[0] in "'\"" and text[-1] == text[0] else ""
    inner = text[1:-1] if quote else text
    return f"{quote}{inner[:ECHO_LIMIT]}\u2026({len(inner)} characters){quote}"


def clip_echoes(message: str) -> str:
    """Shorten what an error message quotes from the request to ``ECHO_LIMIT`` characters.

    A 31 MB value must not come back as a 31 MB error: every quoted string and every word
    longer than ``ECHO_LIMIT`` keeps its first ``ECHO_LIMIT`` characters and says how long
    it was; a line still longer than ``LINE_LIMIT`` is cut the same way.

    Examples
    --------
    >>> clip_echoes("units: unknown unit '" + "x" * 300 + "'")[:30]
    "units: unknown unit 'xxxxxxxxx"
    >>> clip_echoes("p_eq: " + "1" * 5000).endswith("\u2026(5000 characters)")
    True
    >>> clip_echoes("lam: Input should be greater than 0")
    'lam: Input should be greater than 0'
    """
    if len(message) <= ECHO_LIMIT:
        return message
    lines = []
    for line in message.split("\n"):
        line = _ECHO.sub(lambda m: _clip(m.group(0)), line)
        lines.append(_clip(line) if len(line) > LINE_LIMIT else line)
    return "\n".join(lines)


def error_body(kind: str, message: str, field: Optional[str] = None) -> bytes:
    """Return the JSON body of an error answer (``shared_schema.api.ErrorResponse``).

    What the message and the field quote from the request is shortened (``clip_echoes``).
    """
    doc: dict[str, Any] = {"detail": clip_echoes(message), "error": kind}
    if field:
        doc["field"] = clip_echoes(field)
    return json.dumps(doc).encode("utf-8")
