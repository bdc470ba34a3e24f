"""Shared parsing helpers of the plain-text column formats (two columns, one column, CSV).

These files state neither a header sample count nor a peak: each line is a sample, ``#``
starts a comment, and a time column must be strictly increasing and uniform.
"""

from __future__ import annotations

import math
import re
from typing import Any, Optional

import numpy as np
from numpy.typing import NDArray

from shared_schema.errors import InputError

from ..excitation import check_finite_samples
from ._text import units_or_none

__all__ = [
    "DT_RTOL",
    "check_samples",
    "check_step",
    "check_time_units",
    "data_lines",
    "time_origin",
    "to_float",
    "uniform_step",
    "units_in_name",
]

#: Relative tolerance on the spacing of time stamps read from a file.
DT_RTOL = 1e-6
#: Units of a time column a CSV header may name; only seconds are read.
_SECONDS = {"s", "sec", "secs", "second", "seconds"}
_BRACKET = re.compile(r"[\[(]\s*([^\])]+?)\s*[\])]\s*$")


def data_lines(text: str) -> list[tuple[int, str, str]]:
    """``(line number, raw line, line without comment)`` of every non-blank data line."""
    out = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if line:
            out.append((lineno, raw, line))
    return out


def to_float(token: str, where: str, raw: str) -> float:
    """Parse one number of a data line; ``where`` and the ``raw`` line name a bad one."""
    try:
        return float(token)
    except ValueError:
        raise InputError(f"{where}: not a number: {raw.strip()!r}", "record") from None


def check_step(dt: Any) -> float:
    """Return a time step [s] that is a finite number > 0, or refuse it (field ``dt``)."""
    if isinstance(dt, bool) or not isinstance(dt, (int, float, np.floating, np.integer)):
        raise InputError(f"must be a finite number > 0 [s], got {dt!r}", "dt")
    if not (math.isfinite(float(dt)) and dt > 0):
        raise InputError(f"must be finite and > 0 [s], got {dt!r}", "dt")
    return float(dt)


def check_samples(a: NDArray[np.float64], name: str) -> None:
    """Refuse fewer than 2 samples or a non-finite one (field ``record``)."""
    if a.size < 2:
        raise InputError(f"{name}: needs at least 2 samples, got {a.size}", "record")
    check_finite_samples(a, "record", name)


def uniform_step(t: NDArray[np.float64], name: str) -> float:
    """Time step [s] of strictly increasing, uniform (within ``DT_RTOL``) time stamps."""
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise InputError(f"{name}: time of sample {int(bad[0])} is not finite", "record")
    steps = np.diff(t)
    if np.any(steps <= 0.0):
        k = int(np.flatnonzero(steps <= 0.0)[0])
        raise InputError(
            f"{name}: time is not strictly increasing at sample {k + 1} "
            f"(t = {t[k]} then {t[k + 1]})",
            "record",
        )
    dt = float((t[-1] - t[0]) / (t.size - 1))
    worst = int(np.argmax(np.abs(steps - dt)))
    if abs(steps[worst] - dt) > DT_RTOL * dt:
        raise InputError(
            f"{name}: time step is not uniform (step {worst + 1} is {steps[worst]:.6g} s, "
            f"mean {dt:.6g} s); resample the record",
            "record",
        )
    if not math.isfinite(dt) or dt <= 0.0:
        raise InputError(f"{name}: invalid time step {dt!r}", "record")
    return dt


def units_in_name(name: str) -> Optional[str]:
    """Units a column name states: ``acc [g]``, ``a (m/s2)``, ``accel_cm/s2`` -> key, else None."""
    bracket = _BRACKET.search(name)
    if bracket:
        return units_or_none(bracket.group(1))
    for sep in ("_", " "):
        if sep in name.strip():
            return units_or_none(name.strip().rsplit(sep, 1)[1])
    return None


def check_time_units(name: str, where: str) -> None:
    """Refuse a time column that names units other than seconds (``t [ms]``)."""
    bracket = _BRACKET.search(name)
    if bracket and bracket.group(1).strip().lower() not in _SECONDS:
        raise InputError(
            f"{where}: time column {name!r} is in {bracket.group(1)!r}; give time in seconds",
            "time_column",
        )


def time_origin(t0: float, name: str) -> dict[str, Any]:
    """Metadata for a time column that does not start at 0: the record is shifted to 0.

    Every sample is used, from the first; the analyses take t = 0 at the first sample, so a
    time column starting at ``t0`` [s] is shifted by ``-t0`` and the shift is reported.
    """
    if t0 == 0.0:
        return {}
    return {
        "time_shift_s": -t0,
        "warnings": [
            f"{name}: the time column starts at t = {t0:g} s; every sample is used and the "
            f"time axis is shifted by {-t0:g} s so that the record starts at t = 0"
        ],
    }
