"""The retrofit document as a file: ``retrofit.json`` written and read back.

``retrofit_json`` is the document's one text (the file, ``rockmech retrofit --json`` and
the Python API's ``RetrofitDoc.model_dump_json(indent=2)`` give the same bytes);
``write_retrofit`` writes it atomically; ``read_retrofit_doc`` reads a file back (for the
report's retrofit table) and refuses anything but a retrofit document, naming the field.
``read_retrofit_input`` reads what ``rockmech assess --retrofit`` takes: a retrofit spec or a
``retrofit.json``, told apart by the document's stamp.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Union

from shared_schema.atomic import write_atomic
from shared_schema.constants import json_document, validate_document
from shared_schema.errors import InputError
from shared_schema.paths import readable_file
from shared_schema.retrofit import RetrofitDoc, RetrofitSpec, parse_retrofit_spec
from shared_schema.text import decode_text

__all__ = [
    "RETROFIT_FILE",
    "parse_retrofit_doc",
    "read_retrofit_doc",
    "read_retrofit_input",
    "retrofit_json",
    "write_retrofit",
]

#: The file ``rockmech retrofit`` writes into its output folder.
RETROFIT_FILE = "retrofit.json"


def retrofit_json(doc: RetrofitDoc) -> str:
    """Return the document's text: ``doc.model_dump_json(indent=2)`` and a newline."""
    return doc.model_dump_json(indent=2) + "\n"


def write_retrofit(out_dir: Union[str, Path], doc: RetrofitDoc) -> Path:
    """Write ``retrofit.json`` into ``out_dir`` atomically; return its path."""
    path = Path(out_dir) / RETROFIT_FILE
    write_atomic(path, retrofit_json(doc))
    return path


def parse_retrofit_doc(source: Union[str, bytes, dict[str, Any]]) -> RetrofitDoc:
    """Validate a retrofit document given as JSON text, a file's bytes or plain data.

    Raises
    ------
    InputError
        Not text, malformed JSON or not a retrofit document; the message names the field.
    """
    return validate_document(
        RetrofitDoc,
        source,
        "the retrofit document",
        "retrofit",
        "a retrofit document (retrofit.json, as rockmech retrofit writes it)",
    )


def read_retrofit_doc(path: Union[str, Path]) -> RetrofitDoc:
    """Read ``retrofit.json`` (``str`` or ``os.PathLike``); errors name ``retrofit``."""
    p = readable_file(path, "retrofit")
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read {p.name}: {exc.strerror}", "retrofit") from None
    return parse_retrofit_doc(raw)


#: What ``rockmech assess --retrofit`` takes, in words (its messages).
RETROFIT_INPUT = "a retrofit spec or a retrofit.json (JSON)"


def read_retrofit_input(path: Union[str, Path]) -> Union[RetrofitSpec, RetrofitDoc]:
    """Read ``rockmech assess --retrofit FILE``: a retrofit spec, or a ``retrofit.json``.

    A JSON object that carries the document's stamp (``rockmech_version``) or its
    ``standard`` is read as a retrofit document (``rockmech retrofit`` wrote it); any other
    as a retrofit spec (``shared_schema.retrofit``).

    Raises
    ------
    InputError
        A missing file, one that is not JSON, or an invalid spec or document; the field is
        named under ``retrofit`` (``retrofit.steel.grade``, ``retrofit.anchorage.source``).
    """
    p = readable_file(path, "retrofit")
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read {p.name}: {exc.strerror}", "retrofit") from None
    text = decode_text(raw, p.name, "retrofit", RETROFIT_INPUT)
    try:
        data = json_document(text)
    except InputError as exc:
        raise InputError(f"{p.name}: {exc.reason}", "retrofit") from None
    is_doc = isinstance(data, dict) and ("rockmech_version" in data or "standard" in data)
    try:
        return parse_retrofit_doc(data) if is_doc else parse_retrofit_spec(data)
    except InputError as exc:
        if exc.field is None or exc.field == "retrofit" or exc.field.startswith("retrofit."):
            raise
        raise InputError(exc.reason, f"retrofit.{exc.field}") from None
