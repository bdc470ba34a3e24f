"""ESM / ITACA ASCII records (the European and Italian strong-motion databases).

A ``KEY: value`` header in the DYNA 1.2 layout (64 lines, ending with ``USER5:``), then one
sample per line. The header states ``SAMPLING_INTERVAL_S``, ``NDATA``, ``UNITS``
(``cm/s^2``), ``DATA_TYPE`` (must be ``ACCELERATION``) and ``PGA_CM/S^2``, all checked against
the samples. Reference: the ESM/ITACA "DYNA 1.2" format note and ``gmprocess.io.esm``.
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from shared_schema.errors import InputError
from shared_schema.rules import RECORD_UNITS

from ._text import Channel, check_count, check_duration, check_peak, number, units_from_text

__all__ = ["DT_SOURCE", "read", "sniff", "truncated_header"]

#: Where the time step comes from, for the plausibility warning.
DT_SOURCE = "the header's SAMPLING_INTERVAL_S"

#: Keys that identify the format (all present in a DYNA 1.2 header).
_KEYS = ("EVENT_ID:", "NDATA:", "SAMPLING_INTERVAL_S:", "UNITS:")
#: The header's last key; the samples start on the next line.
_LAST_KEY = "USER5"


def sniff(head: str) -> bool:
    """Tell the start of an ESM / ITACA file (DYNA 1.x ``KEY: value`` header)."""
    return head.startswith("EVENT_NAME:") and all(k in head for k in _KEYS)


#: Lines of a DYNA 1.2 header (``EVENT_NAME:`` to ``USER5:``), for the messages.
HEADER_LINES = 64


def _header_lines(lines: list[str]) -> list[str]:
    """Return the keys of the leading ``KEY: value`` lines of a file, up to ``USER5:``."""
    out = []
    for line in lines:
        key, sep, _ = line.partition(":")
        if not sep:
            break
        out.append(key.strip())
        if key.strip() == _LAST_KEY:
            break
    return out


def _cut_short(keys: list[str], name: str) -> str:
    """Say where a DYNA 1.2 header that never reaches ``USER5:`` stops."""
    last = f" ({keys[-1]}:)" if keys else ""
    return (
        f"{name}: the ESM / ITACA header stops after line {len(keys)}{last}, before its last "
        f"key {_LAST_KEY}: (a DYNA 1.2 header has {HEADER_LINES} 'KEY: value' lines from "
        "EVENT_NAME: to USER5:, then one sample a line): the file is truncated; download or "
        "copy it again"
    )


def truncated_header(head: str, name: str) -> Optional[str]:
    """Return the message for a file that starts like ESM but whose header is cut short, or None.

    ``sniff`` needs ``EVENT_ID``, ``NDATA``, ``SAMPLING_INTERVAL_S`` and ``UNITS``; a file cut
    within its first 33 lines has ``EVENT_NAME:`` but not all of them (issue #36: it was
    answered "cannot tell the format").
    """
    if not head.startswith("EVENT_NAME:") or sniff(head):
        return None
    keys = _header_lines(head.splitlines())
    if keys and keys[-1] == _LAST_KEY:
        return None
    missing = [k.rstrip(":") for k in _KEYS if k.rstrip(":") not in keys]
    return _cut_short(keys, name) + f" (it lacks {', '.join(missing)})"


def read(text: str, name: str) -> list[Channel]:
    """Read the one acceleration channel of an ESM / ITACA ASCII file.

    Raises
    ------
    InputError
        A header key missing or unparsable, not an acceleration record, unknown units, a
        sample count other than ``NDATA``, a ``DURATION_S`` other than ``NDATA`` x
        ``SAMPLING_INTERVAL_S``, or a peak other than ``PGA_CM/S^2``.
    """
    lines = text.splitlines()
    header: dict[str, str] = {}
    start = 0
    for line in lines:
        key, sep, value = line.partition(":")
        if not sep:
            break
        header[key.strip()] = value.strip()
        start += 1
        if key.strip() == _LAST_KEY:
            break

    if _LAST_KEY not in header and not any(ln.strip() for ln in lines[start:]):
        # the file ends inside its header (no sample follows): cut short
        raise InputError(_cut_short(list(header), name), "record")

    def need(key: str) -> str:
        if not header.get(key):
            if _LAST_KEY not in header:
                raise InputError(_cut_short(list(header), name) + f" (no {key})", "record")
            raise InputError(f"{name}: ESM header has no {key}", "record")
        return header[key]

    kind = need("DATA_TYPE").upper()
    if kind != "ACCELERATION":
        raise InputError(f"{name}: DATA_TYPE is {kind}, not ACCELERATION", "record")
    dt = number(need("SAMPLING_INTERVAL_S"), f"{name} SAMPLING_INTERVAL_S")
    if dt <= 0:
        raise InputError(f"{name}: SAMPLING_INTERVAL_S must be > 0, got {dt}", "record")
    ndata = number(need("NDATA"), f"{name} NDATA")
    if ndata != int(ndata) or ndata < 2:
        raise InputError(f"{name}: NDATA must be a whole number >= 2, got {ndata:g}", "record")
    npts = int(ndata)
    if header.get("DURATION_S"):
        check_duration(header["DURATION_S"], npts, dt, name, "DURATION_S")
    units = units_from_text(need("UNITS"), f"{name} UNITS")
    samples = [
        number(tok, f"{name} line {k}")
        for k, ln in enumerate(lines[start:], start + 1)
        for tok in ln.split()
    ]
    values = np.array(samples, dtype=float)
    check_count(values, npts, name)
    # The PGA key names its own units (PGA_CM/S^2 in DYNA 1.2); compare in the file's units.
    peak = None
    pga_key = next((k for k in header if k.startswith("PGA_")), None)
    if pga_key is not None and header[pga_key]:
        pga_units = units_from_text(pga_key.split("_", 1)[1], f"{name} {pga_key}")
        factor = RECORD_UNITS[pga_units] / RECORD_UNITS[units]
        peak = check_peak(values, header[pga_key], units, name, factor)
    component = header.get("STREAM", "")
    meta = {
        "event": header.get("EVENT_NAME", ""),
        "event_id": header.get("EVENT_ID", ""),
        "date": header.get("EVENT_DATE_YYYYMMDD", ""),
        "network": header.get("NETWORK", ""),
        "station": header.get("STATION_CODE", ""),
        "station_name": header.get("STATION_NAME", ""),
        "component": component,
        "channel": 1,
        "npts": npts,
        "dt": dt,
        "peak": peak,
        "processing": header.get("PROCESSING", ""),
        "header_format": header.get("HEADER_FORMAT", ""),
    }
    return [Channel(values, dt, units, meta)]
