"""The service's error bodies (``shared_schema.api.ErrorResponse``).

Light on purpose: the app process imports it without the compute modules, which only the
worker processes load.
"""

from __future__ import annotations

import json
from typing import Any, Optional

__all__ = ["error_body"]


def error_body(kind: str, message: str, field: Optional[str] = None) -> bytes:
    """Return the JSON body of an error answer (``shared_schema.api.ErrorResponse``)."""
    doc: dict[str, Any] = {"detail": message, "error": kind}
    if field:
        doc["field"] = field
    return json.dumps(doc).encode("utf-8")
