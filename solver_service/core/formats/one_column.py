"""One-column records: one acceleration per line, the time step given by the caller.

``#`` starts a comment and blank lines are skipped. The file states neither units nor a
time step, so the caller gives both.
"""

from __future__ import annotations

import numpy as np

from shared_schema.errors import InputError

from ._columns import check_samples, data_lines, to_float
from ._text import Channel

__all__ = ["DT_SOURCE", "read"]

#: Where the time step comes from, for the plausibility warning.
DT_SOURCE = "the time step given (dt, --dt)"


def read(text: str, name: str, dt: float, units: str) -> Channel:
    """Read a one-column file's samples, sampled every ``dt`` [s] in ``units``.

    Parameters
    ----------
    text : str
        The file's text.
    name : str
        File name, for messages and ``metadata["source"]``.
    dt : float
        Sampling interval [s] (checked by the caller: finite and > 0).
    units : str
        Units of the values, a key of ``shared_schema.rules.RECORD_UNITS``.

    Returns
    -------
    Channel
        The samples in ``units`` at ``dt``; ``metadata``: ``source``, ``format``, ``units``
        and ``npts``.

    Raises
    ------
    InputError
        A line with other than one number, fewer than 2 samples or non-finite values.
    """
    values: list[float] = []
    for lineno, raw, line in data_lines(text):
        parts = line.replace(",", " ").split()
        where = f"{name} line {lineno}"
        if len(parts) != 1:
            raise InputError(f"{where}: expected 1 column, got {len(parts)}", "record")
        values.append(to_float(parts[0], where, raw))
    a = np.array(values, dtype=float)
    check_samples(a, name)
    meta = {"source": name, "format": "one_column", "units": units, "npts": int(a.size)}
    return Channel(a, dt, units, meta)
