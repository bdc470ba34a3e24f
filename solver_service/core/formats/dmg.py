"""CSMIP / DMG V2 records (California Strong Motion Instrumentation Program, CDMG/CGS).

One file holds several channels. Each: 25 text lines (line 1 ``CORRECTED ACCELEROGRAM ...
CHAN  1:  90 DEG``; ``PEAK ACCELERATION =  -267.957    CM/SEC/SEC  AT   10.940   SEC.``),
integer and real headers, then ``3251 POINTS OF ACCEL DATA EQUALLY SPACED AT  .020 SEC.
(UNITS: CM/SEC/SEC)`` and the samples in fields of 10 characters (8F10.3), then the velocity
and displacement blocks, closed by ``/&  ----  END OF DATA FOR CHANNEL  1  ----``.

Only the acceleration block of each channel is read; a channel is chosen by its number
(``CHAN 1``) or its component (``90 DEG``, ``UP``). Reference: CSMIP V2 format (CDMG
Report OSMS 83-?), ``gmprocess.io.dmg``.
"""

from __future__ import annotations

import re

from shared_schema.errors import InputError

from ._text import Channel, check_count, check_peak, fixed_width_values, number, units_from_text

__all__ = ["DT_SOURCE", "read", "sniff"]

#: Where the time step comes from, for the plausibility warning.
DT_SOURCE = "the 'POINTS OF ACCEL DATA EQUALLY SPACED AT' line"

#: Characters per sample in the data blocks (Fortran 8F10.3).
FIELD_WIDTH = 10
_CHAN = re.compile(r"CHAN\s+(\d+)\s*:\s*(.*?)\s*(?:FROM)?\s*$")
_ACCEL = re.compile(
    r"^\s*(\d+)\s+POINTS OF ACCEL DATA EQUALLY SPACED AT\s+([-+0-9.Ee]+)\s+SEC.*"
    r"\(UNITS:\s*([^)]+)\)",
    re.IGNORECASE,
)
_PEAK = re.compile(r"PEAK ACCELERATION\s*=\s*([-+0-9.Ee]+)\s+(\S+)", re.IGNORECASE)
_END = "/&"


def sniff(head: str) -> bool:
    """Tell the start of a CSMIP/DMG V2 file."""
    first = head.split("\n", 1)[0].upper()
    return first.startswith("CORRECTED ACCELEROGRAM") and "CHAN" in first


def read(text: str, name: str) -> list[Channel]:
    """Read the acceleration of every channel of a DMG V2 file.

    Raises
    ------
    InputError
        A channel without its acceleration block, unknown units, a sample count other than
        the block's ``POINTS`` or a peak other than ``PEAK ACCELERATION``.
    """
    lines = text.splitlines()
    starts = [k for k, ln in enumerate(lines) if ln.upper().startswith("CORRECTED ACCELEROGRAM")]
    channels: list[Channel] = []
    for n, start in enumerate(starts):
        stop = starts[n + 1] if n + 1 < len(starts) else len(lines)
        section = lines[start:stop]
        chan = _CHAN.search(section[0].upper())
        where = f"{name} channel {n + 1}"
        number_in_file = int(chan.group(1)) if chan else n + 1
        component = chan.group(2).strip() if chan else ""
        head = next((k for k, ln in enumerate(section) if _ACCEL.match(ln)), None)
        if head is None:
            raise InputError(f"{where}: no 'POINTS OF ACCEL DATA' line", "record")
        block = _ACCEL.match(section[head])
        assert block is not None
        npts = int(block.group(1))
        dt = number(block.group(2), f"{where} time step")
        if dt <= 0:
            raise InputError(f"{where}: time step must be > 0, got {dt}", "record")
        units = units_from_text(block.group(3), where)
        rows = [(start + k + 1, section[k]) for k in range(head + 1, len(section))]
        rows = rows[: next((j for j, (_, ln) in enumerate(rows) if not _is_data(ln)), len(rows))]
        values = fixed_width_values(rows, FIELD_WIDTH, npts, where)
        check_count(values, npts, where)
        peak_line = next((m for m in map(_PEAK.search, section[:head]) if m), None)
        peak = None
        if peak_line is not None:
            stated_units = units_from_text(peak_line.group(2), f"{where} PEAK ACCELERATION")
            if stated_units != units:
                raise InputError(
                    f"{where}: peak in {stated_units} but samples in {units}", "record"
                )
            peak = check_peak(values, peak_line.group(1), units, where)
        meta = {
            "event": section[2].strip() if len(section) > 2 else "",
            "date": section[3].split("(")[0].strip() if len(section) > 3 else "",
            "station": _station(section),
            "component": component,
            "channel": number_in_file,
            "npts": npts,
            "dt": dt,
            "peak": peak,
        }
        channels.append(Channel(values, dt, units, meta))
    if not channels:
        raise InputError(f"{name}: no 'CORRECTED ACCELEROGRAM' channel", "record")
    return channels


def _station(section: list[str]) -> str:
    """``36456 PARKFIELD FAULT ZONE 14`` from text lines 6 (number) and 7 (name)."""
    code = re.search(r"STATION NO\.\s*(\S+)", section[5]) if len(section) > 6 else None
    return f"{code.group(1)} {section[6].strip()}" if code else ""


def _is_data(line: str) -> bool:
    """Tell a data line: numbers only (the next block starts ``n POINTS OF ...``)."""
    return (
        bool(line.strip())
        and not any(c.isalpha() and c not in "Ee" for c in line)
        and (_END not in line)
    )
