"""GeoNet (GNS Science, New Zealand) V2A corrected records: three components in one file.

Each component: 16 text lines (``Corrected accelerogram ... GNS Science``; ``Number of points
5800``; ``Component S16W  Longitudinal Accelerometer Axis``; ``Acceleration:  peak -41.6
mm/s/s at 43.68 sec``), 10 header lines of 10 numbers in 8 characters (4 integer, 6 real),
then the acceleration, velocity and displacement samples, 10 per line in 8 characters
(10F8.1), each series with its own count.

Notes
-----
Header fields used (0-based row, column of the 10 x 10 block): (3, 3), (3, 4), (3, 5) the
acceleration, velocity and displacement counts; (6, 5) the sampling interval [s]. Samples
are in mm/s². The text header's ``Number of points`` and ``data at ... sec intervals`` are
checked against the numeric header. Reference: GeoNet strong-motion file formats
(https://www.geonet.org.nz/data/supplementary/strong_motion_file_formats) and
``gmprocess.io.geonet``.
"""

from __future__ import annotations

import re

from shared_schema.errors import InputError

from ._text import (
    PEAK_RTOL,
    Channel,
    check_count,
    check_peak,
    decimals,
    fixed_width_values,
    number,
    units_from_text,
)

__all__ = ["DT_SOURCE", "read", "sniff"]

#: Where the time step comes from, for the plausibility warning.
DT_SOURCE = "the header's sampling interval (row 7, field 6)"

#: Text lines of each component's header.
TEXT_LINES = 16
#: Lines of the numeric header (4 integer + 6 real), 10 fields each.
HEADER_ROWS = 10
#: Numbers per line and characters per number (Fortran 10F8.x).
PER_LINE, FIELD_WIDTH = 10, 8
_PEAK = re.compile(r"^Acceleration:\s*peak\s+([-+0-9.Ee]+)\s+(\S+)", re.IGNORECASE)
_POINTS = re.compile(r"^Number of points\s+(\d+)", re.IGNORECASE)
_INTERVAL = re.compile(r"data at\s+([-+0-9.Ee]+)\s+sec intervals", re.IGNORECASE)
_COMPONENT = re.compile(r"^Component\s+(\S+)\s*(.*)$", re.IGNORECASE)


def sniff(head: str) -> bool:
    """Tell the start of a GeoNet corrected (V2A) file."""
    first = head.split("\n", 1)[0]
    return first.startswith("Corrected accelerogram") and "GNS Science" in first


def read(text: str, name: str) -> list[Channel]:
    """Read the acceleration of every component of a GeoNet V2A file.

    Raises
    ------
    InputError
        A short block, unknown units, a sample count other than the header's or a peak
        other than the ``Acceleration: peak`` line.
    """
    lines = text.splitlines()
    channels: list[Channel] = []
    i = 0
    while i < len(lines):
        if not lines[i].strip():
            i += 1
            continue
        where = f"{name} component {len(channels) + 1}"
        if not sniff(lines[i]) or i + TEXT_LINES + HEADER_ROWS > len(lines):
            raise InputError(f"{name} line {i + 1}: expected a GeoNet V2A header", "record")
        text_header = lines[i : i + TEXT_LINES]
        rows = [(k + 1, lines[k]) for k in range(i + TEXT_LINES, i + TEXT_LINES + HEADER_ROWS)]
        head = fixed_width_values(rows, FIELD_WIDTH, HEADER_ROWS * PER_LINE, f"{where} header")
        counts = [float(head[3 * PER_LINE + c]) for c in (3, 4, 5)]
        bad = next((c for c in counts if c != int(c) or c < 0), None)
        if bad is not None:
            raise InputError(
                f"{where}: the header's sample counts (row 4, fields 4-6) must be whole numbers "
                f">= 0, got {bad:g}; the header was edited or the file is damaged",
                "record",
            )
        n_acc, n_vel, n_disp = (int(c) for c in counts)
        dt = float(head[6 * PER_LINE + 5])
        if dt <= 0:
            raise InputError(f"{where}: header sampling interval must be > 0, got {dt}", "record")
        _check_text_header(text_header, n_acc, dt, where)
        peak_line = _PEAK.match(text_header[13])
        if peak_line is None:
            raise InputError(f"{where}: no 'Acceleration: peak' line", "record")
        units = units_from_text(peak_line.group(2), where)
        start = i + TEXT_LINES + HEADER_ROWS
        nrows = -(-n_acc // PER_LINE)
        data = [(k + 1, lines[k]) for k in range(start, min(start + nrows, len(lines)))]
        values = fixed_width_values(data, FIELD_WIDTH, n_acc, where)
        check_count(values, n_acc, where)
        peak = check_peak(values, peak_line.group(1), units, where)
        comp = _COMPONENT.match(text_header[12])
        meta = {
            "event": text_header[6].strip() + ", " + text_header[7].strip(),
            "station": text_header[1].split()[1] if len(text_header[1].split()) > 1 else "",
            "station_name": text_header[2].strip(),
            "component": comp.group(1) if comp else "",
            "axis": comp.group(2).strip() if comp else "",
            "channel": len(channels) + 1,
            "npts": n_acc,
            "dt": dt,
            "peak": peak,
        }
        channels.append(Channel(values, dt, units, meta))
        i = start + sum(-(-n // PER_LINE) for n in (n_acc, n_vel, n_disp))
    if not channels:
        raise InputError(f"{name}: no GeoNet component", "record")
    return channels


def _check_text_header(text_header: list[str], n_acc: int, dt: float, where: str) -> None:
    """Check the text header's ``Number of points`` and ``data at 0.020 sec intervals``.

    They state the count and the time step that the numeric header gives the reader; a
    disagreement means an edited or damaged header (lines a file lacks are not checked).
    """
    for line in text_header:
        points = _POINTS.match(line)
        if points is not None and int(points.group(1)) != n_acc:
            raise InputError(
                f"{where}: the text header says 'Number of points {points.group(1)}', but the "
                f"numeric header (row 4, field 4) says {n_acc}; the header was edited or the "
                "file is damaged",
                "record",
            )
        interval = _INTERVAL.search(line)
        if interval is not None:
            stated = interval.group(1)
            tol = 0.5 * 10.0 ** (-decimals(stated)) + PEAK_RTOL * dt
            if abs(number(stated, f"{where} interval") - dt) > tol:
                raise InputError(
                    f"{where}: the text header says data at {stated} sec intervals, but the "
                    f"numeric header (row 7, field 6) says {dt:g} s; the header was edited or "
                    "the file is damaged",
                    "record",
                )
