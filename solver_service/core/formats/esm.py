"""ESM / ITACA ASCII records (the European and Italian strong-motion databases).

A ``KEY: value`` header in the DYNA 1.2 layout (64 lines, ending with ``USER5:``), then one
sample per line. The header states ``SAMPLING_INTERVAL_S``, ``NDATA``, ``UNITS``
(``cm/s^2``), ``DATA_TYPE`` (must be ``ACCELERATION``) and ``PGA_CM/S^2``, all checked against
the samples. Reference: the ESM/ITACA "DYNA 1.2" format note and ``gmprocess.io.esm``.
"""

from __future__ import annotations

import numpy as np

from shared_schema.errors import InputError
from shared_schema.rules import RECORD_UNITS

from ._text import Channel, check_count, check_duration, check_peak, number, units_from_text

__all__ = ["read", "sniff"]

#: Keys that identify the format (all present in a DYNA 1.2 header).
_KEYS = ("EVENT_ID:", "NDATA:", "SAMPLING_INTERVAL_S:", "UNITS:")
#: The header's last key; the samples start on the next line.
_LAST_KEY = "USER5"


def sniff(head: str) -> bool:
    """Tell the start of an ESM / ITACA file (DYNA 1.x ``KEY: value`` header)."""
    return head.startswith("EVENT_NAME:") and all(k in head for k in _KEYS)


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

    def need(key: str) -> str:
        if not header.get(key):
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
