"""Reading users' text files: the one place that turns a file's bytes into text, or says why not.

Every reader of a text input (records, constants files and tables, site files, specs) takes
its text from :func:`decode_text`, so that an empty file, a binary file (a workbook, an
archive, a SAC or miniSEED record) and a file in another encoding each get one message that
says what was expected, what was found and what to do, instead of a codec's error text.

Encodings read: UTF-8 (with or without a byte-order mark) and UTF-16/UTF-32 with a byte-order
mark (what Excel's "Unicode Text" and a PowerShell ``>`` redirect write). Nothing else is
guessed: a file in a legacy code page (Windows-1252, Latin-1) is refused with the byte and
line where it stops being UTF-8.

Python 3.9-clean, no third-party imports (every floor may import it).
"""

import codecs
import re
from typing import Optional, Tuple

from shared_schema.errors import InputError

__all__ = ["BINARY_SIGNATURES", "decimal_point", "decode_text", "delimiter_of", "empty_problem"]

#: Start of a file -> what it most likely is, for the message on a binary file.
BINARY_SIGNATURES: Tuple[Tuple[bytes, str], ...] = (
    (b"PK\x03\x04", "a ZIP archive or an Office file (an Excel .xlsx workbook is one)"),
    (b"\xd0\xcf\x11\xe0", "an old Office file (an Excel .xls workbook)"),
    (b"%PDF", "a PDF document"),
    (b"\x1f\x8b", "a gzip archive"),
    (b"\x89HDF", "an HDF5 file"),
    (b"\x89PNG", "a PNG image"),
    (b"\xff\xd8\xff", "a JPEG image"),
    (b"3D Geometry File Format", "a Rhino .3dm model"),
)
_DECIMAL_COMMA = re.compile(r"[-+]?\d*,\d+(?:[EeDd][-+]?\d+)?")
#: Byte-order marks read, longest first (a UTF-32 LE mark starts with the UTF-16 LE one).
_BOMS = (
    (codecs.BOM_UTF32_LE, "utf-32-le"),
    (codecs.BOM_UTF32_BE, "utf-32-be"),
    (codecs.BOM_UTF8, "utf-8"),
    (codecs.BOM_UTF16_LE, "utf-16-le"),
    (codecs.BOM_UTF16_BE, "utf-16-be"),
)


def empty_problem(text: str, name: str, what: str) -> Optional[str]:
    r"""Return the message for a file holding no text but blank space, or None.

    Examples
    --------
    >>> print(empty_problem("  \n", "walls.json", "JSON").split(";")[0])
    walls.json holds only blank space: expected JSON
    >>> empty_problem("{}", "walls.json", "JSON") is None
    True
    """
    if text.strip():
        return None
    found = "is empty (0 bytes)" if not text else "holds only blank space"
    return f"{name} {found}: expected {what}; check that it was saved or copied completely"


def decode_text(raw: bytes, name: str, field: str, what: str, hint: str = "") -> str:
    r"""Return a file's bytes as text, or raise an ``InputError`` that says what is wrong.

    Parameters
    ----------
    raw : bytes
        The file's content.
    name : str
        The file's name, for the message.
    field : str
        The field the error names (``record``, ``constants``, ``site``, ``spec``, ``table``).
    what : str
        What the file should be, for the message (``"a ground-motion record as text"``).
    hint : str, optional
        What to do with a binary file of this kind (``"export the record as text"``).

    Raises
    ------
    InputError
        An empty file, a binary file (naming what its first bytes suggest), or text that is
        neither UTF-8 nor UTF-16/32 with a byte-order mark (naming the byte and its line).

    Examples
    --------
    >>> decode_text("t,a\n".encode("utf-16"), "r.csv", "record", "a record")
    't,a\n'
    >>> decode_text(b"PK\x03\x04....", "r.dat", "record", "text")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    shared_schema.errors.InputError: record: r.dat is not a text file (it starts like a ZIP...
    """
    for signature, kind in BINARY_SIGNATURES:
        if raw.startswith(signature):
            tail = f"; {hint}" if hint else ""
            raise InputError(
                f"{name} is not a text file (it starts like {kind}): expected {what}{tail}", field
            )
    for bom, encoding in _BOMS:
        if raw.startswith(bom):
            try:
                text = raw[len(bom) :].decode(encoding)
            except UnicodeDecodeError as exc:
                raise InputError(
                    f"{name} starts with a {encoding.upper()} byte-order mark but is not "
                    f"{encoding.upper()} text after it (byte {exc.start + len(bom)}): expected "
                    f"{what}; save it again as UTF-8 text",
                    field,
                ) from None
            break
    else:
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise InputError(_not_text(raw, exc.start, name, what, hint), field) from None
    if "\x00" in text:
        raise InputError(_not_text(raw, max(raw.find(b"\x00"), 0), name, what, hint), field)
    empty = empty_problem(text, name, what)
    if empty is not None:
        raise InputError(empty, field)
    return text


def _not_text(raw: bytes, at: int, name: str, what: str, hint: str) -> str:
    """Return the message for bytes that are not UTF-8 text from offset ``at`` on."""
    tail = f"; {hint}" if hint else ""
    head = raw[:4096]
    # Text in a legacy code page has no NUL and few control bytes; a binary file has many.
    control = sum(1 for b in head if b < 32 and b not in (9, 10, 13))
    if b"\x00" in head or control > len(head) // 20:
        return (
            f"{name} is not a text file (binary data from byte {at}, 0x{raw[at]:02x}): "
            f"expected {what}{tail}"
        )
    line = raw[:at].count(b"\n") + 1
    return (
        f"{name} is not UTF-8 text: byte {at} (line {line}) is 0x{raw[at]:02x}, which UTF-8 "
        f"does not allow (the file is in another encoding, such as Windows-1252): expected "
        f"{what}; save it again as UTF-8 text"
    )


def delimiter_of(first_row: str) -> str:
    r"""Return the cell separator of a delimited text file from its first (header) row.

    A comma, unless the row has a semicolon (a European spreadsheet's CSV, which writes
    decimal commas) or a tab (Excel's "Unicode Text") and no comma: neither is ever part of
    a number or of a comma-separated header.

    Examples
    --------
    >>> delimiter_of("t [s];acc [g]"), delimiter_of("id\tp_eq"), delimiter_of("t,a")
    (';', '\t', ',')
    """
    if "," not in first_row:
        for sep in (";", "\t"):
            if sep in first_row:
                return sep
    return ";" if ";" in first_row else ","


def decimal_point(cell: str) -> str:
    """Return a cell with a decimal comma (``"0,01"``) written with a point; others as is.

    Only for files whose cells a semicolon separates (see :func:`delimiter_of`).

    Examples
    --------
    >>> decimal_point("-2,5e-01"), decimal_point("W1"), decimal_point("1.5")
    ('-2.5e-01', 'W1', '1.5')
    """
    return cell.replace(",", ".") if _DECIMAL_COMMA.fullmatch(cell.strip()) else cell
