"""NIED K-NET and KiK-net ASCII records (Japan).

Seventeen ``Label   value`` header lines (``Origin Time`` ... ``Memo.``), then integer counts,
eight per line. The header states ``Sampling Freq(Hz)`` (``100Hz``), ``Duration Time(s)``,
``Dir.`` (K-NET ``N-S``/``E-W``/``U-D``; KiK-net ``1``-``3`` borehole, ``4``-``6`` surface),
``Scale Factor`` as ``7845(gal)/8223790`` (gal per count) and ``Max. Acc. (gal)``.

Notes
-----
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

from ._text import Channel, check_count, check_peak, first_number, number

__all__ = ["read", "sniff"]

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


def read(text: str, name: str) -> list[Channel]:
    """Read the one channel of a K-NET / KiK-net ASCII file, in gal, mean removed.

    Raises
    ------
    InputError
        A short or unparsable header, an unknown direction, a sample count other than
        sampling frequency x duration, or a peak other than ``Max. Acc.``.
    """
    lines = text.splitlines()
    if len(lines) < HEADER_LINES:
        raise InputError(f"{name}: K-NET header needs {HEADER_LINES} lines", "record")
    header = {ln[:18].strip(): ln[18:].strip() for ln in lines[:HEADER_LINES]}

    def need(label: str) -> str:
        if not header.get(label):
            raise InputError(f"{name}: K-NET header has no {label!r}", "record")
        return header[label]

    rate = first_number(need("Sampling Freq(Hz)"), f"{name} Sampling Freq(Hz)")
    if rate <= 0:
        raise InputError(f"{name}: Sampling Freq(Hz) must be > 0, got {rate}", "record")
    duration = first_number(need("Duration Time(s)"), f"{name} Duration Time(s)")
    scale = _SCALE.match(need("Scale Factor"))
    if scale is None:
        raise InputError(
            f"{name}: Scale Factor {header['Scale Factor']!r} is not of the form 7845(gal)/8223790",
            "record",
        )
    gal_per_count = number(scale.group(1), name) / number(scale.group(2), name)
    direction = need("Dir.")
    if direction not in _DIRECTIONS:
        raise InputError(f"{name}: unknown Dir. {direction!r}", "record")
    counts = [
        number(tok, f"{name} line {k}")
        for k, ln in enumerate(lines[HEADER_LINES:], HEADER_LINES + 1)
        for tok in ln.split()
    ]
    values = np.array(counts, dtype=float) * gal_per_count
    npts = round(rate * duration)
    check_count(values, npts, name)
    mean = float(np.mean(values))
    values = values - mean
    peak = check_peak(values, header.get("Max. Acc. (gal)") or None, "cm/s2", name)
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
    return [Channel(values, 1.0 / rate, "cm/s2", meta)]
