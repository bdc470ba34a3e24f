"""Constants tables: one mechanism per row, as papers print them, into a constants file.

A table is a ``.csv`` file (UTF-8 or UTF-16; cells separated by commas, or by semicolons with
decimal commas as European spreadsheets write them, or by tabs) or the first sheet of an
``.xlsx`` workbook (read with openpyxl, the ``tables`` extra; a table on another sheet is named
in the error). The first non-blank row names the columns; each further row is one
mechanism. Column names are matched without case, spaces or a trailing unit in brackets
(``p_eq [rad/s]``, ``f_n (Hz)``); a unit in brackets must be the column's SI unit, or ``deg``
for the angles ``phi_ov``/``phi_cr`` (converted to rad).

Columns (``COLUMNS``): ``id`` (required), ``name``, ``typology``, ``rocking``, ``eta``,
``eta_source``, ``source`` (into ``provenance.source``); the positive side in the short form
``p_eq``, ``lam``, ``phi_ov`` or the physical form ``I0``, ``K``, ``Q``, ``phi_cr``, ``M_F``;
the negative side as ``p_eq_neg``, ``lam_neg``, ``phi_ov_neg``; the amplification data
``f_n``, ``h_e``, ``h`` (all three or none). Empty cells mean "not given". Every row is
validated as the constants file validates a mechanism (``shared_schema.constants``), and
errors name the row (as the spreadsheet numbers it) and the column.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
from pathlib import Path
from typing import Any, Optional

from shared_schema.api import time_domain_problem
from shared_schema.constants import ConstantsFile, parse_constants
from shared_schema.errors import InputError
from shared_schema.paths import PathLike
from shared_schema.rules import check_file
from shared_schema.text import decimal_point, decode_text, delimiter_of

__all__ = [
    "COLUMNS",
    "TABLE_SUFFIXES",
    "XLSX_HINT",
    "checked_table",
    "constants_from_table",
    "is_table",
]

#: Column -> (where it goes in a mechanism, SI unit or None for text, dimensionless "-").
COLUMNS: dict[str, tuple[tuple[str, ...], Optional[str]]] = {
    "id": (("id",), None),
    "name": (("name",), None),
    "typology": (("typology",), None),
    "rocking": (("rocking",), None),
    "eta": (("eta",), "-"),
    "eta_source": (("eta_source",), None),
    "source": (("provenance", "source"), None),
    "p_eq": (("positive", "p_eq"), "rad/s"),
    "lam": (("positive", "lam"), "-"),
    "phi_ov": (("positive", "phi_ov"), "rad"),
    "I0": (("positive", "I0"), "kg m^2"),
    "K": (("positive", "K"), "N m/rad"),
    "Q": (("positive", "Q"), "kg m"),
    "phi_cr": (("positive", "phi_cr"), "rad"),
    "M_F": (("positive", "M_F"), "N m"),
    "p_eq_neg": (("negative", "p_eq"), "rad/s"),
    "lam_neg": (("negative", "lam"), "-"),
    "phi_ov_neg": (("negative", "phi_ov"), "rad"),
    "f_n": (("amplification", "f_n"), "Hz"),
    "h_e": (("amplification", "h_e"), "m"),
    "h": (("amplification", "h"), "m"),
}
#: Other spellings papers use for a column (folded: lower case, no spaces).
ALIASES = {"lambda": "lam", "λ": "lam", "η": "eta", "p": "p_eq", "i0": "I0", "k": "K"}
#: Table file suffixes (lower case) that commands take where a constants JSON is expected.
TABLE_SUFFIXES = (".csv", ".xlsx")
#: What a CSV table must be, for the messages on empty or binary files.
CSV_EXPECTED = (
    "a constants table as CSV text (a header row naming the columns, then a mechanism a row)"
)
#: What to do with a binary ``.csv``.
CSV_BINARY_HINT = "if it is an Excel workbook, name it .xlsx; else save the sheet as CSV UTF-8"
#: What to run when openpyxl is missing.
XLSX_HINT = "pip install 'rockmech[tables]'  (or: pip install openpyxl)"
#: Unit spellings accepted in brackets, folded, per SI unit.
_UNIT_SPELLINGS = {
    "-": {"-", "", "g"},
    "rad/s": {"rad/s", "1/s", "s^-1", "s-1"},
    "rad": {"rad"},
    "Hz": {"hz"},
    "m": {"m"},
    "kg m^2": {"kgm^2", "kgm2", "kg·m^2", "kg·m²", "kgm²"},
    "N m/rad": {"nm/rad", "n·m/rad"},
    "kg m": {"kgm", "kg·m"},
    "N m": {"nm", "n·m"},
}
_UNIT = re.compile(r"^(.*?)\s*[\[(]\s*([^\])]*)\s*[\])]\s*$")
_FOLDED = {k.casefold(): k for k in COLUMNS}


def is_table(path: PathLike) -> bool:
    """Tell a constants table (``.csv``, ``.xlsx``) from a constants JSON by its suffix."""
    return Path(path).suffix.lower() in TABLE_SUFFIXES


def _column(title: str, col: int) -> tuple[str, float]:
    """Return the canonical column of a header cell and the factor to SI of its unit."""
    text = title.strip()
    match = _UNIT.match(text)
    base, unit = (match.group(1), match.group(2).strip()) if match else (text, None)
    key = "".join(base.split()).casefold()
    key = ALIASES.get(key, key)
    name = _FOLDED.get(key.casefold())
    if name is None:
        raise InputError(f"column {col} {title!r}: unknown; columns are {list(COLUMNS)}", "table")
    si = COLUMNS[name][1]
    if unit is None:
        return name, 1.0
    folded = "".join(unit.split()).casefold()
    if si is None:
        raise InputError(f"column {title!r}: {name} is text and takes no unit", "table")
    if si == "rad" and folded in ("deg", "°", "degrees"):
        return name, math.pi / 180.0
    if folded not in _UNIT_SPELLINGS[si]:
        raise InputError(f"column {title!r}: unit {unit!r}, expected {si!r}", "table")
    return name, 1.0


def _read_csv(path: Path) -> tuple[list[tuple[int, list[Any]]], bool]:
    """Rows of a CSV table (UTF-8 or UTF-16; cells separated by ',', ';' or a tab).

    Returns the numbered rows and whether numbers may have decimal commas: a ';'-separated
    table is a European spreadsheet's CSV, which writes them.
    """
    text = decode_text(path.read_bytes(), path.name, "table", CSV_EXPECTED, CSV_BINARY_HINT)
    first = next((ln for ln in text.splitlines() if ln.strip()), "")
    delimiter = delimiter_of(first)
    rows = list(csv.reader(io.StringIO(text), delimiter=delimiter))
    return [(n, cells) for n, cells in enumerate(rows, start=1)], delimiter == ";"


def _has_table(rows: Any) -> bool:
    """Tell a sheet whose first non-blank row names an ``id`` column (a table's header)."""
    for row in rows:
        if not all(_blank(c) for c in row):
            return any(_column_name(str(c)) == "id" for c in row if not _blank(c))
    return False


def _column_name(title: str) -> Optional[str]:
    """Return the canonical column of a header cell, or None where it names none."""
    try:
        return _column(title, 0)[0]
    except InputError:
        return None


def _read_xlsx(path: Path) -> list[tuple[int, list[Any]]]:
    try:
        # openpyxl is optional (the "tables" extra): only .xlsx tables need it.
        import openpyxl  # type: ignore[import-untyped]
    except ImportError:
        raise InputError(f"reading {path.name} needs openpyxl: {XLSX_HINT}", "table") from None
    try:
        book = openpyxl.load_workbook(path, read_only=True, data_only=True)
    except Exception as exc:  # openpyxl raises many kinds for a damaged workbook
        raise InputError(f"cannot read {path.name} as .xlsx: {exc}", "table") from None
    try:
        sheets = [(ws.title, list(ws.iter_rows(values_only=True))) for ws in book.worksheets]
    finally:
        book.close()
    title, first = sheets[0]
    if not _has_table(first):
        others = [(k, t) for k, (t, rows) in enumerate(sheets[1:], start=2) if _has_table(rows)]
        if others:
            k, other = others[0]
            raise InputError(
                f"{path.name}: the table is read from the first sheet, but sheet 1 {title!r} has "
                f"no header row naming an 'id' column, and sheet {k} {other!r} has one: move "
                f"{other!r} to the front of the workbook (or save it as CSV)",
                "table",
            )
    return [(n, list(r)) for n, r in enumerate(first, start=1)]


def _blank(cell: Any) -> bool:
    return cell is None or (isinstance(cell, str) and not cell.strip())


def _number(cell: Any, where: str, decimal_comma: bool = False) -> float:
    """Return a numeric cell's value; ``decimal_comma`` reads ``0,25`` as 0.25 (a ';' table)."""
    if isinstance(cell, bool):
        raise InputError(f"{where}: must be a number, got {cell!r}", "table")
    if isinstance(cell, (int, float)):
        value = float(cell)
    else:
        text = decimal_point(str(cell)) if decimal_comma else str(cell)
        try:
            value = float(text.strip())
        except ValueError:
            raise InputError(f"{where}: not a number: {str(cell).strip()!r}", "table") from None
    if not math.isfinite(value):
        raise InputError(f"{where}: must be finite, got {cell!r}", "table")
    return value


#: Mechanism field path (as constants-file errors give it) -> column.
_PATHS = {".".join(where): name for name, (where, _) in COLUMNS.items()}


#: Errors on a whole part of a mechanism -> the columns that make it.
_WHOLE = {
    "": "id",
    "positive": "p_eq, lam",
    "negative": "p_eq_neg, lam_neg",
    "amplification": "f_n, h_e, h",
}


def _row_error(exc: InputError, row: int, titles: dict[str, str], name: str) -> InputError:
    """Re-word a constants-file error on one mechanism as row ``row`` and its column."""
    path = re.sub(r"^mechanisms\[\d+\](?: \(id [^)]*\))?\.?", "", exc.field or "")
    column = _PATHS.get(path) or _WHOLE.get(path.split(".", 1)[0])
    label = f"row {row}" + (f", column {titles.get(column, column)!r}" if column else "")
    return InputError(f"{name} {label}: {exc.reason}", "table")


def constants_from_table(path: PathLike, *, time_domain: bool = False) -> ConstantsFile:
    """Read a constants table (``.csv`` or ``.xlsx``) into a validated constants file.

    Parameters
    ----------
    path : str or os.PathLike
        The table; see the module docstring for its columns.
    time_domain : bool
        Also hold each row to the ranges of a time-domain analysis (``p_eq``, ``lam``, the
        amplification data: ``shared_schema.api.time_domain_problem``), as a constants JSON
        file and the REST service are for envelopes, histories, IDA, reports and assessments.

    Returns
    -------
    ConstantsFile
        The same model ``shared_schema.io.read_constants`` gives for the equivalent JSON
        file (short-form mechanisms written flat, ``phi_ov`` defaulting to ``lam``).

    Raises
    ------
    InputError
        Missing file, a folder, unknown suffix, openpyxl missing for ``.xlsx`` (with the ``pip
        install`` line), an unknown column or unit, or a bad cell; every message names the
        row (as the spreadsheet numbers it) and the column. Field ``table``.
    """
    cf, range_error = checked_table(path)
    if time_domain and range_error is not None:
        raise range_error
    return cf


def checked_table(path: PathLike) -> tuple[ConstantsFile, Optional[InputError]]:
    """Read a constants table; also return the error a time-domain analysis would give it.

    Returns
    -------
    constants : ConstantsFile
        As ``constants_from_table``.
    range_error : InputError or None
        The first value outside the ranges of a time-domain analysis, naming its row and
        column (``shared_schema.api.time_domain_problem``), or None.
    """
    path = check_file(path, "table")
    suffix = path.suffix.lower()
    if suffix not in TABLE_SUFFIXES:
        raise InputError(f"{path.name}: a table is .csv or .xlsx, got {suffix!r}", "table")
    rows, decimal_comma = _read_csv(path) if suffix == ".csv" else (_read_xlsx(path), False)
    rows = [(n, cells) for n, cells in rows if not all(_blank(c) for c in cells)]
    if not rows:
        raise InputError(f"{path.name} is empty", "table")
    head_row, head = rows[0]
    columns: list[Optional[tuple[str, float]]] = []
    titles: dict[str, str] = {}
    for col, title in enumerate(head, start=1):
        if _blank(title):
            columns.append(None)
            continue
        try:
            name, factor = _column(str(title), col)
        except InputError as exc:
            raise InputError(f"{path.name} row {head_row}, {exc.reason}", "table") from None
        if name in titles:
            raise InputError(
                f"{path.name} row {head_row}: columns {titles[name]!r} and {title!r} are "
                f"both {name}",
                "table",
            )
        titles[name] = str(title).strip()
        columns.append((name, factor))
    if "id" not in titles:
        raise InputError(f"{path.name} row {head_row}: no 'id' column", "table")
    mechanisms: list[dict[str, Any]] = []
    row_numbers: list[int] = []
    for n, cells in rows[1:]:
        mech: dict[str, Any] = {}
        for col, cell in enumerate(cells):
            if _blank(cell):
                continue
            spec = columns[col] if col < len(columns) else None
            if spec is None:
                raise InputError(
                    f"{path.name} row {n}, column {col + 1}: a value under no column name",
                    "table",
                )
            name, factor = spec
            where, unit = COLUMNS[name]
            cell_where = f"{path.name} row {n}, column {titles[name]!r}"
            if unit is None:
                value: Any = str(cell).strip()
            else:
                value = _number(cell, cell_where, decimal_comma) * factor
            target = mech
            for key in where[:-1]:
                target = target.setdefault(key, {})
            target[where[-1]] = value
        if "id" not in mech:
            raise InputError(f"{path.name} row {n}, column {titles['id']!r}: missing", "table")
        # The short form of the positive side is written flat, as in the JSON files.
        positive = mech.get("positive", {})
        if positive and not {"I0", "K", "Q", "phi_cr", "M_F"} & set(positive):
            mech.update(mech.pop("positive"))
        try:
            parse_constants(json.dumps({"mechanisms": [mech]}))
        except InputError as exc:
            raise _row_error(exc, n, titles, path.name) from None
        mechanisms.append(mech)
        row_numbers.append(n)
    if not mechanisms:
        raise InputError(f"{path.name}: the table has a header but no mechanism rows", "table")
    try:
        cf = parse_constants(json.dumps({"mechanisms": mechanisms}))
    except InputError as exc:
        index = re.match(r"mechanisms\[(\d+)\]", exc.field or "")
        row = row_numbers[int(index.group(1))] if index else head_row
        raise _row_error(exc, row, titles, path.name) from None
    problem = time_domain_problem(cf)
    if problem is None:
        return cf, None
    field, message = problem
    index = re.match(r"mechanisms\[(\d+)\]", field)
    row = row_numbers[int(index.group(1))] if index else head_row
    return cf, _row_error(InputError(message, field), row, titles, path.name)
