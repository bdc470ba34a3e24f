"""Comma-separated records with a header row (a spreadsheet's export).

A time column (in seconds) or a time step given by the caller; the acceleration column's
name may state its units (``acc [g]``, ``a (m/s2)``, ``accel_cm/s2``). A file whose first row
is all numbers has no header, and its columns can only be given by index. A European
spreadsheet's export (``;`` between cells, decimal commas) reads the same.
"""

from __future__ import annotations

import csv
from typing import Any, Optional, Union

import numpy as np

from shared_schema.errors import InputError
from shared_schema.rules import RECORD_UNITS
from shared_schema.text import decimal_point, delimiter_of

from ._columns import (
    check_samples,
    check_time_units,
    data_lines,
    time_origin,
    to_float,
    uniform_step,
    units_in_name,
)
from ._text import Channel

__all__ = ["Column", "read"]

#: A column by header name or 0-based index; None for the default.
Column = Union[str, int, None]
UNITS_HINT = "give units: " + ", ".join(list(RECORD_UNITS)[:-1]) + f" or {list(RECORD_UNITS)[-1]}"
Rows = list[tuple[int, str, list[str]]]


def _resolve_column(col: Column, header: list[str], arg: str, name: str) -> int:
    n = len(header)
    if isinstance(col, int) and not isinstance(col, bool):
        if not -n <= col < n:
            raise InputError(f"{name} has {n} columns, got column index {col}", arg)
        return col % n
    if isinstance(col, str):
        if col in header:
            return header.index(col)
        folded = [h.casefold() for h in header]
        if col.strip().casefold() in folded:
            return folded.index(col.strip().casefold())
    raise InputError(f"{name} has no column {col!r}; columns are {header}", arg)


def _rows(text: str, name: str) -> tuple[str, list[str], Rows, bool]:
    """Return the delimiter, the header (or column numbers), the rows and if names head them."""
    lines = data_lines(text)
    if not lines:
        raise InputError(f"{name}: needs at least 2 samples, got 0", "record")
    # A CSV from a European spreadsheet separates cells with ';' and may write decimal
    # commas (shared_schema.text.delimiter_of).
    delimiter = delimiter_of(lines[0][2])
    rows = [(n, raw, next(csv.reader([ln], delimiter=delimiter))) for n, raw, ln in lines]
    if delimiter == ";":
        rows = [(n, raw, [decimal_point(c) for c in cells]) for n, raw, cells in rows]
    first = [c.strip() for c in rows[0][2]]
    try:
        [float(c) for c in first]
    except ValueError:
        return delimiter, first, rows[1:], True
    return delimiter, [str(i) for i in range(len(first))], rows, False


def _columns(
    header: list[str], time_column: Column, accel_column: Column, dt: Optional[float], name: str
) -> tuple[Optional[int], int]:
    """Return the indices of the time column (None with ``dt``) and the acceleration column."""
    if dt is None:
        if len(header) < 2:
            raise InputError(f"{name} has no time column; give dt [s]", "dt")
        it: Optional[int] = _resolve_column(
            0 if time_column is None else time_column, header, "time_column", name
        )
        default_acc = 1 if it == 0 else 0
    else:
        it = None
        if accel_column is None and len(header) != 1:
            raise InputError(
                f"{name} has {len(header)} columns {header}; name the acceleration one",
                "accel_column",
            )
        default_acc = 0
    ia = _resolve_column(
        default_acc if accel_column is None else accel_column, header, "accel_column", name
    )
    if ia == it:
        raise InputError(f"{name}: time and acceleration are the same column", "accel_column")
    return it, ia


def _units(column: str, stated: Optional[str], units: Optional[str], name: str) -> str:
    """Return the acceleration's units: the column name's, which a given ``units`` must match."""
    if stated is None and units is None:
        raise InputError(f"{UNITS_HINT} (column {column!r} of {name} does not state them)", "units")
    if stated is not None and units is not None and stated != units:
        raise InputError(
            f"{name}: column {column!r} states units {stated!r}, got {units!r}", "units"
        )
    chosen = stated or units
    assert chosen is not None
    return chosen


def read(
    text: str,
    name: str,
    units: Optional[str] = None,
    time_column: Column = None,
    accel_column: Column = None,
    dt: Optional[float] = None,
) -> Channel:
    """Read the acceleration column of a CSV file.

    Parameters
    ----------
    text : str
        The file's text; ``#`` comment lines and blank lines are skipped.
    name : str
        File name, for messages and ``metadata["source"]``.
    units : str, optional
        Units of the acceleration column (checked by the caller), required where its name
        states none and matching where it does.
    time_column, accel_column : str or int, optional
        Columns by header name (exact, else case-insensitive) or 0-based index. By default
        time is column 0 and acceleration the first other column.
    dt : float, optional
        Time step [s] (checked by the caller) for a file without a time column; then
        ``accel_column`` defaults to the only column.

    Returns
    -------
    Channel
        The samples in their units at their step [s]; ``metadata``: ``source``, ``format``,
        ``delimiter``, ``units``, ``npts``, ``time_column``, ``accel_column``, ``units_from``
        (``header`` or ``given``) and, for a time column that does not start at 0, the shift.

    Raises
    ------
    InputError
        Bad columns or units (naming the field), unparsable cells, fewer than 2 samples,
        non-finite values, or time not strictly increasing and uniform.
    """
    delimiter, header, rows, names = _rows(text, name)
    it, ia = _columns(header, time_column, accel_column, dt, name)
    stated = units_in_name(header[ia]) if names else None
    units = _units(header[ia], stated, units, name)
    if it is not None and names:
        check_time_units(header[it], name)
    need = max(ia, -1 if it is None else it) + 1
    t_list: list[float] = []
    a_list: list[float] = []
    for lineno, raw, cells in rows:
        where = f"{name} line {lineno}"
        if len(cells) < need:
            raise InputError(f"{where}: expected {len(header)} columns, got {len(cells)}", "record")
        a_list.append(to_float(cells[ia].strip(), where, raw))
        if it is not None:
            t_list.append(to_float(cells[it].strip(), where, raw))
    a = np.array(a_list, dtype=float)
    check_samples(a, name)
    t0 = 0.0
    if it is not None:
        t = np.array(t_list, dtype=float)
        dt, t0 = uniform_step(t, name), float(t[0])
    assert dt is not None
    meta: dict[str, Any] = {
        "source": name,
        "format": "csv",
        "delimiter": delimiter,
        "units": units,
        "npts": int(a.size),
        "time_column": header[it] if (it is not None and names) else it,
        "accel_column": header[ia] if names else ia,
        "units_from": "header" if stated is not None else "given",
    }
    meta.update(time_origin(t0, name))
    return Channel(a, dt, units, meta)
