"""Two-column records: time [s] and acceleration on each line.

Whitespace or commas separate the columns, ``#`` starts a comment. The file states no
units, so the caller gives them; the time column must be strictly increasing and uniform.
"""

from __future__ import annotations

import numpy as np

from shared_schema.errors import InputError

from ._columns import check_samples, data_lines, time_origin, to_float, uniform_step
from ._text import Channel

__all__ = ["DT_SOURCE", "read"]

#: Where the time step comes from, for the plausibility warning.
DT_SOURCE = "the time column"


def read(text: str, name: str, units: str) -> Channel:
    """Read a two-column file's samples, in the ``units`` the caller states.

    Parameters
    ----------
    text : str
        The file's text.
    name : str
        File name, for messages and ``metadata["source"]``.
    units : str
        Units of the acceleration column, a key of ``shared_schema.rules.RECORD_UNITS``
        (checked by the caller before the file is read).

    Returns
    -------
    Channel
        The samples in ``units``, the time step [s] of the time column, and ``metadata``:
        ``source``, ``format``, ``units``, ``npts`` and, for a time column that does not
        start at 0, the shift ``time_shift_s`` [s] with a warning.

    Raises
    ------
    InputError
        A line with other than 2 columns, an unparsable value, fewer than 2 samples,
        non-finite values, or time that is not strictly increasing and uniform.
    """
    rows: list[tuple[float, float]] = []
    for lineno, raw, line in data_lines(text):
        parts = line.replace(",", " ").split()
        where = f"{name} line {lineno}"
        if len(parts) != 2:
            raise InputError(
                f"{where}: expected 2 columns (time, acceleration), got {len(parts)}", "record"
            )
        rows.append((to_float(parts[0], where, raw), to_float(parts[1], where, raw)))
    data = np.array(rows, dtype=float).reshape(-1, 2)
    t, a = data[:, 0], data[:, 1]
    check_samples(a, name)
    dt = uniform_step(t, name)
    meta = {"source": name, "format": "two_column", "units": units, "npts": int(t.size)}
    meta.update(time_origin(float(t[0]), name))
    return Channel(a, dt, units, meta)
