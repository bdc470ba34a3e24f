"""NIED K-NET and KiK-net ASCII records (Japan).

Seventeen ``Label   value`` header lines (``Origin Time`` ... ``Memo.``), then integer counts,
eight per line. The header states ``Sampling Freq(Hz)`` (``100Hz``), ``Duration Time(s)``,
``Dir.`` (K-NET ``N-S``/``E-W``/``U-D``; KiK-net ``1``-``3`` borehole, ``4``-``6`` surface),
``Scale Factor`` as ``7845(gal)/8223790`` (gal per count: the recorder's full scale over its
counts at full scale) and ``Max. Acc. (gal)``.

Notes
-----
The Scale Factor is checked where it enters: both numbers > 0, the full scale within
``FULL_SCALE_GAL`` and its counts within ``FULL_SCALE_COUNTS``, and no count beyond the full
scale; an empty ``Max. Acc.`` (so that the peak cannot check the scale) is a warning.

acceleration [gal] = counts x scale factor, minus the mean of the whole record: NIED
distributes raw counts with the logger's offset and states ``Max. Acc.`` after removing the
mean, so the reader removes it too and the peak matches the header (the mean is kept in
``metadata["mean_removed"]``). The record start in the header (``Record Time``, JST) includes
the logger's 15 s pre-trigger. References: NIED K-NET/KiK-net ASCII format note;
``obspy.io.nied.knet`` and ``gmprocess.io.knet``.
"""

from __future__ import annotations

import re

import numpy as np

from shared_schema.errors import InputError
from shared_schema.rules import DT_RANGE_S

from ._text import Channel, check_count, check_peak, first_number, number

__all__ = ["DT_SOURCE", "read", "sniff"]

#: Where the time step comes from, for the plausibility warning.
DT_SOURCE = "1 / the header's Sampling Freq(Hz)"

#: Header lines before the counts.
HEADER_LINES = 17
#: ``Dir.`` codes -> component name (KiK-net 1-3 are the borehole sensor, 4-6 the surface).
_DIRECTIONS = {
    "N-S": "N-S",
    "E-W": "E-W",
    "U-D": "U-D",
    "1": "N-S (borehole)",
    "2": "E-W (borehole)",
    "3": "U-D (borehole)",
    "4": "N-S (surface)",
    "5": "E-W (surface)",
    "6": "U-D (surface)",
}
#: Longest record a K-NET header may state [s] (a day; NIED's records last minutes).
DURATION_MAX_S = 86400.0
#: Valid full scale [gal] of a recorder, the Scale Factor's numerator: NIED's recorders have
#: 2000 gal (K-NET95) to 7845 gal (8 g, K-NET02/KiK-net); the range is 1 to 10 g.
FULL_SCALE_GAL = (980.665, 9806.65)
#: Valid counts at full scale, the Scale Factor's denominator: NIED's 24-bit converters give
#: 6.1e6 to 8.4e6 (6170801, 8223790, 8388608); the range is 2**21 to 2**24.
FULL_SCALE_COUNTS = (2.0**21, 2.0**24)
_SCALE = re.compile(r"^\s*([-+0-9.Ee]+)\s*\(gal\)\s*/\s*([-+0-9.Ee]+)\s*$", re.IGNORECASE)


def sniff(head: str) -> bool:
    """Tell the start of a K-NET / KiK-net ASCII file."""
    lines = head.splitlines()
    return (
        len(lines) >= 14
        and lines[0].startswith("Origin Time")
        and lines[5].startswith("Station Code")
        and lines[13].startswith("Scale Factor")
    )


def _need(header: dict[str, str], label: str, name: str) -> str:
    """Return a header value, refusing an empty or missing one."""
    if not header.get(label):
        raise InputError(f"{name}: K-NET header has no {label!r}", "record")
    return header[label]


def _rate_and_duration(header: dict[str, str], name: str) -> tuple[float, float]:
    """Return the sampling frequency [Hz] and the duration [s], each in its range."""
    rate = first_number(_need(header, "Sampling Freq(Hz)", name), f"{name} Sampling Freq(Hz)")
    lo, hi = 1.0 / DT_RANGE_S[1], 1.0 / DT_RANGE_S[0]
    if not lo <= rate <= hi:
        raise InputError(
            f"{name}: Sampling Freq(Hz) is {rate:g} Hz, outside [{lo:g}, {hi:g}] Hz "
            "(K-NET records are sampled at 100 or 200 Hz)",
            "record",
        )
    duration = first_number(_need(header, "Duration Time(s)", name), f"{name} Duration Time(s)")
    if not 0.0 < duration <= DURATION_MAX_S:
        raise InputError(
            f"{name}: Duration Time(s) is {duration:g} s, outside (0, {DURATION_MAX_S:g}] s",
            "record",
        )
    return rate, duration


def _scale_factor(header: dict[str, str], name: str) -> tuple[float, float]:
    """Return the Scale Factor's full scale [gal] and its counts, checked (``_check_scale``)."""
    scale = _SCALE.match(_need(header, "Scale Factor", name))
    if scale is None:
        raise InputError(
            f"{name}: Scale Factor {header['Scale Factor']!r} is not of the form 7845(gal)/8223790",
            "record",
        )
    full_gal, full_counts = (number(scale.group(k), f"{name} Scale Factor") for k in (1, 2))
    _check_scale(full_gal, full_counts, header["Scale Factor"], name)
    return full_gal, full_counts


def read(text: str, name: str) -> list[Channel]:
    """Read the one channel of a K-NET / KiK-net ASCII file, in gal, mean removed.

    Raises
    ------
    InputError
        A short or unparsable header, a sampling frequency or duration out of range, a
        Scale Factor no recorder has (see ``_check_scale``), an unknown direction, a sample
        count other than sampling frequency x duration, a count beyond the full scale, or a
        peak other than ``Max. Acc.``.
    """
    lines = text.splitlines()
    if len(lines) < HEADER_LINES:
        raise InputError(f"{name}: K-NET header needs {HEADER_LINES} lines", "record")
    header = {ln[:18].strip(): ln[18:].strip() for ln in lines[:HEADER_LINES]}
    rate, duration = _rate_and_duration(header, name)
    full_gal, full_counts = _scale_factor(header, name)
    gal_per_count = full_gal / full_counts
    direction = _need(header, "Dir.", name)
    if direction not in _DIRECTIONS:
        raise InputError(f"{name}: unknown Dir. {direction!r}", "record")
    counts = [
        number(tok, f"{name} line {k}")
        for k, ln in enumerate(lines[HEADER_LINES:], HEADER_LINES + 1)
        for tok in ln.split()
    ]
    raw = np.array(counts, dtype=float)
    npts = round(rate * duration)
    check_count(raw, npts, name)
    beyond = np.flatnonzero(np.abs(raw) > full_counts)
    if beyond.size:
        k = int(beyond[0])
        raise InputError(
            f"{name}: count {k} is {raw[k]:.0f}, beyond the recorder's full scale of "
            f"{full_counts:.0f} counts that the Scale Factor {header['Scale Factor']!r} states "
            f"({beyond.size} such count(s)): the Scale Factor or the data were edited; "
            "download the record again from NIED",
            "record",
        )
    values = raw * gal_per_count
    mean = float(np.mean(values))
    values = values - mean
    stated = header.get("Max. Acc. (gal)") or None
    peak = check_peak(values, stated, "cm/s2", name)
    notes = []
    if stated is None:
        notes.append(
            f"{name}: 'Max. Acc. (gal)' is empty, so the Scale Factor "
            f"{header['Scale Factor']!r} could not be checked against the header's peak "
            f"(the samples give {float(np.max(np.abs(values))):.6g} gal)"
        )
    meta = {
        "event": f"M{header.get('Mag.', '?')} {header.get('Origin Time', '')}",
        "date": header.get("Origin Time", ""),
        "station": header.get("Station Code", ""),
        "component": _DIRECTIONS[direction],
        "channel": 1,
        "npts": npts,
        "dt": 1.0 / rate,
        "peak": peak,
        "scale_factor": header["Scale Factor"],
        "mean_removed": mean,
        "record_time_jst": header.get("Record Time", ""),
    }
    if notes:
        meta["warnings"] = notes
    return [Channel(values, 1.0 / rate, "cm/s2", meta)]


def _check_scale(full_gal: float, full_counts: float, text: str, name: str) -> None:
    """Refuse a Scale Factor no NIED recorder has (zero, negative, or outside the ranges).

    Raises
    ------
    InputError
        Naming the Scale Factor, what it states and the valid range (field ``record``).
    """
    where = f"{name}: Scale Factor {text!r}"
    todo = "correct it as NIED wrote it (e.g. 7845(gal)/8223790) or download the record again"
    if full_counts == 0.0:
        raise InputError(f"{where} divides by 0 counts; {todo}", "record")
    if full_gal <= 0.0 or full_counts < 0.0:
        raise InputError(
            f"{where} is negative or zero, which would flip or erase the record: both the full "
            f"scale [gal] and its counts are > 0; {todo}",
            "record",
        )
    lo, hi = FULL_SCALE_GAL
    if not lo <= full_gal <= hi:
        raise InputError(
            f"{where} states a full scale of {full_gal:g} gal ({full_gal / 980.665:.3g} g), "
            f"outside [{lo:g}, {hi:g}] gal (1 to 10 g; NIED's recorders have 2000 to 7845 gal); "
            f"{todo}",
            "record",
        )
    lo, hi = FULL_SCALE_COUNTS
    if not lo <= full_counts <= hi:
        raise InputError(
            f"{where} states {full_counts:g} counts at full scale, outside [{lo:.0f}, {hi:.0f}] "
            f"(a 24-bit converter; NIED's files have 6170801 to 8388608); {todo}",
            "record",
        )
