"""PEER NGA ``.AT2`` acceleration records (the PEER ground-motion database).

Four header lines (title; event, date, station, component; units; ``NPTS=..., DT=...``),
then the samples, several per line. The header states the units (``... IN UNITS OF G``) and
the time step; the values are checked against ``NPTS``.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from shared_schema.errors import InputError

from ._columns import check_samples, check_step, to_float
from ._text import Channel

__all__ = ["DT_SOURCE", "read", "sniff"]

#: Where the time step comes from, for the plausibility warning.
DT_SOURCE = "the AT2 header's DT"
#: Units named on line 3 of an AT2 file, upper case without spaces -> our units.
_AT2_UNITS = {
    "G": "g",
    "CM/S/S": "cm/s2",
    "CM/SEC/SEC": "cm/s2",
    "CM/S2": "cm/s2",
    "CM/SEC2": "cm/s2",
    "GAL": "cm/s2",
    "M/S/S": "m/s2",
    "M/SEC/SEC": "m/s2",
    "M/S2": "m/s2",
}
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?"
_DATE = re.compile(r"\d{1,2}/\d{1,2}/\d{2,4}")


def sniff(head: str) -> bool:
    """Tell the start of a PEER NGA file (its title line)."""
    return head.lstrip().upper().startswith("PEER NGA")


def _station(line: str) -> dict[str, str]:
    """Event, date, station and component from line 2 of an AT2 file, as far as they parse.

    NGA-West2 writes ``event, m/d/yyyy, station, component``; older NGA files
    ``EVENT m/d/yy hhmm, STATION, COMPONENT``.
    """
    parts = [s.strip() for s in line.split(",")]
    meta = {"event": "", "date": "", "station": "", "component": ""}
    if len(parts) >= 4 and _DATE.fullmatch(parts[1]):
        meta.update(event=parts[0], date=parts[1], station=", ".join(parts[2:-1]))
        meta["component"] = parts[-1]
    elif len(parts) >= 3:
        date = _DATE.search(parts[0])
        meta["event"] = parts[0][: date.start()].strip() if date else parts[0]
        meta["date"] = date.group(0) if date else ""
        meta.update(station=", ".join(parts[1:-1]), component=parts[-1])
    else:
        meta["event"] = line.strip()
    return meta


def _npts_dt(line: str, name: str) -> tuple[int, float]:
    """``NPTS`` and ``DT`` [s] from line 4 of an AT2 file (both header styles)."""
    npts = re.search(r"NPTS\s*=\s*(\d+)", line, re.IGNORECASE)
    dt = re.search(rf"DT\s*=\s*({_NUMBER})", line, re.IGNORECASE)
    if npts and dt:
        return int(npts.group(1)), float(dt.group(1))
    # Older NGA files: "  2048   .0066   NPTS, DT".
    old = re.match(rf"\s*(\d+)\s+({_NUMBER})\s+NPTS\s*,\s*DT", line, re.IGNORECASE)
    if old:
        return int(old.group(1)), float(old.group(2))
    raise InputError(f"{name} line 4: cannot find NPTS and DT in {line.strip()!r}", "record")


def _units(line: str, name: str) -> str:
    """Our units key for line 3 of an AT2 file, refusing velocity, displacement or unknown units."""
    kind = line.upper()
    if "ACCELERATION" not in kind:
        raise InputError(f"{name} line 3: not an acceleration record: {line.strip()!r}", "record")
    word = kind.rsplit("UNITS OF", 1)[-1].replace(" ", "") if "UNITS OF" in kind else ""
    if word not in _AT2_UNITS:
        raise InputError(
            f"{name} line 3: unknown units in {line.strip()!r}; known: {sorted(_AT2_UNITS)}",
            "record",
        )
    return _AT2_UNITS[word]


def read(text: str, name: str) -> list[Channel]:
    """Read the one acceleration channel of an AT2 file, in the units its header states.

    Parameters
    ----------
    text : str
        The file's text. Every value is kept, the short last line included.
    name : str
        File name, for messages and ``metadata["source"]``.

    Returns
    -------
    list of Channel
        One channel; ``metadata`` holds ``event``, ``date``, ``station``, ``component``
        (parsed from line 2 as far as possible; ``header`` keeps the raw line), ``source``,
        ``format``, ``units``, ``dt`` [s] and ``npts``.

    Raises
    ------
    InputError
        A short header, unknown units, a velocity or displacement file, unparsable values, a
        bad ``DT`` or a count of values other than ``NPTS``.
    """
    lines = text.splitlines()
    if len(lines) < 4:
        raise InputError(f"{name}: AT2 needs 4 header lines, got {len(lines)} line(s)", "record")
    units = _units(lines[2], name)
    npts, dt = _npts_dt(lines[3], name)
    check_step(dt)
    values: list[float] = []
    for lineno, raw in enumerate(lines[4:], start=5):
        where = f"{name} line {lineno}"
        values.extend(to_float(tok, where, raw) for tok in raw.split())
    if len(values) != npts:
        raise InputError(
            f"{name}: header says NPTS={npts}, but the file has {len(values)} values", "record"
        )
    a = np.array(values, dtype=float)
    check_samples(a, name)
    meta: dict[str, Any] = {
        **_station(lines[1]),
        "header": lines[1].strip(),
        "source": name,
        "format": "at2",
        "units": units,
        "dt": dt,
        "npts": npts,
    }
    return [Channel(a, dt, units, meta)]
