"""The base of every analysis document: the version and units stamp, and its one serialiser.

A document is a pydantic model that refuses unknown keys (``extra="forbid"``). Its JSON form
(``to_dict``) is what ``rockmech ... --json`` prints, the files beside a run hold and the
REST service and Hops answer: fields in the order they are declared, optional sections that
do not apply absent (never ``null``), and a number ``null`` only where its value is not
finite (an overflow on extreme inputs, or "none up to the search limit").

Python 3.9-clean: no ``X | Y`` annotations.
"""

import math
from typing import Any, Dict, Sequence, TypeVar

from pydantic import BaseModel, ConfigDict, Field

from shared_schema.errors import InputError

__all__ = ["DOCUMENT_CONFIG", "Document", "Part", "find_entry", "finite"]

#: Documents state what rockmech computed: unknown keys are refused; a value that is not
#: finite is kept in the model and written as ``null`` (``to_dict``).
DOCUMENT_CONFIG = ConfigDict(extra="forbid")


def finite(value: Any) -> Any:
    """Return ``value`` with every non-finite float replaced by None, recursively."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [finite(v) for v in value]
    return value


class Part(BaseModel):
    """A section of a document (no stamp of its own)."""

    model_config = DOCUMENT_CONFIG

    def to_dict(self) -> Dict[str, Any]:
        """Return the JSON-ready form: declared order, unset sections absent, NaN as null."""
        out: Dict[str, Any] = finite(self.model_dump(mode="json", exclude_unset=True))
        return out


class Document(Part):
    """An analysis document: the version that wrote it and the units of its quantities first."""

    rockmech_version: str = Field(description="The rockmech version that wrote the document.")
    units: Dict[str, str] = Field(
        description="Unit of each quantity whose name does not state it (``-``: dimensionless)."
    )


_E = TypeVar("_E")


def find_entry(entries: Sequence[_E], mechanism_id: str) -> _E:
    """Return the entry whose ``id`` is ``mechanism_id``: every document's ``find``.

    Raises
    ------
    InputError
        No such entry (field ``mechanism``; the message lists the ids the document has).
    """
    for entry in entries:
        if getattr(entry, "id", None) == mechanism_id:
            return entry
    known = [getattr(e, "id", None) for e in entries]
    raise InputError(f"no mechanism {mechanism_id!r}; the document has {known}", "mechanism")
