"""Shared parsing helpers of the strong-motion format readers.

Every reader works on the file's text and returns ``Channel`` objects with the samples in the
units the file states; ``solver_service.core.records`` turns them into SI ``GroundMotion``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np
from numpy.typing import NDArray

from shared_schema.errors import InputError

__all__ = [
    "Channel",
    "check_count",
    "check_duration",
    "check_peak",
    "decimals",
    "first_number",
    "fixed_width_values",
    "number",
    "units_from_text",
    "units_or_none",
]

#: Relative slack on a stated peak beyond its printed rounding (catches a wrong scale or units).
PEAK_RTOL = 1e-6
#: Spellings of acceleration units in strong-motion headers (upper case, no spaces, ``^`` and
#: ``*`` removed, ``SEC`` read as ``S``) -> ``shared_schema.rules.RECORD_UNITS`` keys.
_UNIT_SPELLINGS = {
    "G": "g",
    "MG": "mg",
    "GAL": "cm/s2",
    "CM/S/S": "cm/s2",
    "CM/S2": "cm/s2",
    "CMS-2": "cm/s2",
    "MM/S/S": "mm/s2",
    "MM/S2": "mm/s2",
    "M/S/S": "m/s2",
    "M/S2": "m/s2",
    "MS-2": "m/s2",
    "IN/S/S": "in/s2",
    "IN/S2": "in/s2",
}
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?")


@dataclass(frozen=True)
class Channel:
    """One acceleration channel of a strong-motion file, in the units the file states.

    Attributes
    ----------
    values : (n,) float
        Acceleration samples in ``units``.
    dt : float
        Sampling interval [s].
    units : str
        A key of ``shared_schema.rules.RECORD_UNITS``.
    metadata : dict
        ``station``, ``component``, ``channel`` (1-based number in the file), ``event``,
        ``npts``, ``dt``, the stated ``peak`` in ``units``, and format-specific fields.
    """

    values: NDArray[np.float64]
    dt: float
    units: str
    metadata: dict[str, Any] = field(default_factory=dict)


def number(token: str, where: str) -> float:
    """Parse one number of a header; a Fortran ``D`` exponent is accepted."""
    try:
        value = float(token.strip().replace("D", "E").replace("d", "e"))
    except ValueError:
        raise InputError(f"{where}: not a number: {token.strip()!r}", "record") from None
    if not math.isfinite(value):
        raise InputError(f"{where}: not finite: {token.strip()!r}", "record")
    return value


def first_number(text: str, where: str) -> float:
    """Return the first number in ``text``."""
    match = _NUMBER.search(text)
    if match is None:
        raise InputError(f"{where}: no number in {text.strip()!r}", "record")
    return number(match.group(0), where)


def units_or_none(text: str) -> Optional[str]:
    """Return the units key a header spells (``cm/s^2``, ``CM/SEC/SEC``, ``m/s²``), or None."""
    key = re.sub(r"[\s^*]", "", text.replace("²", "2")).upper().replace("SEC", "S")
    return _UNIT_SPELLINGS.get(key)


def units_from_text(text: str, where: str) -> str:
    """Acceleration units named in a header (``cm/s^2``, ``CM/SEC/SEC``, ``mm/s/s``, ``gal``...)."""
    units = units_or_none(text)
    if units is None:
        raise InputError(
            f"{where}: unknown acceleration units {text.strip()!r}; known: "
            f"{sorted(set(_UNIT_SPELLINGS.values()))}",
            "record",
        )
    return units


def fixed_width_values(
    lines: Sequence[tuple[int, str]], width: int, count: int, name: str
) -> NDArray[np.float64]:
    """Read ``count`` numbers in fields of ``width`` characters (Fortran ``nFw.d``).

    Parameters
    ----------
    lines : sequence of (line number, text)
        The data lines, in order; every number on them is read, so a surplus is an error
        too (never a silently dropped sample).
    width : int
        Field width [characters]; fixed fields also read numbers that touch (``-1.5-2.5``).
    count : int
        Numbers expected; fewer in ``lines`` is an error naming the file.
    name : str
        File name for messages.
    """
    out: list[float] = []
    for lineno, raw in lines:
        line = raw.rstrip("\r\n")
        for start in range(0, len(line), width):
            cell = line[start : start + width]
            if cell.strip():
                out.append(number(cell, f"{name} line {lineno}"))
    if len(out) != count:
        raise InputError(
            f"{name}: header says {count} samples, but the file has {len(out)}", "record"
        )
    return np.array(out, dtype=float)


def check_count(values: NDArray[np.float64], npts: int, name: str) -> None:
    """Refuse a sample count other than the header's, and non-finite or too few samples."""
    if values.size != npts:
        raise InputError(
            f"{name}: header says {npts} samples, but the file has {values.size}", "record"
        )
    if values.size < 2:
        raise InputError(f"{name}: needs at least 2 samples, got {values.size}", "record")
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise InputError(f"{name}: sample {int(bad[0])} is not finite", "record")


def check_duration(stated: str, npts: int, dt: float, name: str, label: str) -> float:
    """Check a header's record length [s] against its sample count and time step.

    Headers write the length as ``npts x dt`` or ``(npts - 1) x dt``; either is accepted
    within half a unit of the printed value's last digit (and ``PEAK_RTOL``).

    Raises
    ------
    InputError
        The stated length is neither (field ``record``, naming ``label`` and both values).
    """
    value = number(stated, f"{name} {label}")
    tol = 0.5 * 10.0 ** (-decimals(stated)) + PEAK_RTOL * abs(value)
    if min(abs(value - npts * dt), abs(value - (npts - 1) * dt)) > tol:
        raise InputError(
            f"{name}: {label} is {stated.strip()} s, but {npts} samples at {dt:g} s last "
            f"{npts * dt:.10g} s: the header's sample count, time step or length was edited "
            "or the file is damaged; download it again",
            "record",
        )
    return value


def decimals(token: str) -> int:
    """Digits after the decimal point of a printed number (``"-267.957"`` -> 3)."""
    mantissa = re.split(r"[EeDd]", token.strip())[0]
    return len(mantissa.split(".", 1)[1]) if "." in mantissa else 0


def check_peak(
    values: NDArray[np.float64],
    stated: Optional[str],
    units: str,
    name: str,
    factor: float = 1.0,
) -> Optional[float]:
    """Check the samples' peak |a| against the header's printed peak; return it as a float.

    The printed value is rounded to its last digit, so the tolerance is half a unit of that
    digit (plus ``PEAK_RTOL``); ``factor`` turns the printed value into ``units`` where the
    header prints it in other units. A mismatch means a wrong scale factor, wrong units or
    samples read out of place, so it is an error rather than a warning.
    """
    if stated is None:
        return None
    peak = abs(number(stated, f"{name} header peak")) * factor
    tol = 0.5 * 10.0 ** (-decimals(stated)) * factor + PEAK_RTOL * peak
    got = float(np.max(np.abs(values)))
    if abs(got - peak) > tol:
        raise InputError(
            f"{name}: header states peak {peak:.10g} {units}, but the samples give {got:.6g} "
            f"{units}; the file is damaged or not what its header says",
            "record",
        )
    return peak
