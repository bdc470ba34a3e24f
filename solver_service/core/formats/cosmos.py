"""COSMOS Strong-Motion Data Format V2 (corrected acceleration), e.g. CESMD ``.V2c`` files.

Each channel: a text header (its line count is on line 1, ``with 13 text lines``), an integer
header (``100 Integer-header values follow on 10 lines, Format= (10I8)``), a real header
(``Format= (5F15.6)``), comment lines, then ``42000 acceleration pts, approx 210 secs,
units=cm/sec2(04),Format=(1E15.6)`` and the samples; ``End-of-data for Chan...`` closes it.
Velocity or displacement channels in the same file are skipped.

Notes
-----
Fields used (1-based as in the COSMOS format document, v1.20): integer 1 processing stage
(2 = corrected), 2 data type (1 = acceleration); the data line's units code (2 g, 4 cm/s²,
10 gal, 11 mg, 7 in/s²); real 62 sampling interval [ms], 63 series length [s], 64 peak value
and 65 its time [s]; -999 is "unknown". Every one is checked against the data: each block's
Fortran format against its count and lines, the count against the samples, the length and
the data line's ``approx ... secs`` against count x interval, the peak against the samples.
Reference: COSMOS Strong Motion Data Format, v1.20 (2001); ``gmprocess.io.cosmos``.
"""

from __future__ import annotations

import re

from shared_schema.errors import InputError

from ._text import (
    Channel,
    check_count,
    check_duration,
    check_peak,
    fixed_width_values,
    number,
    units_from_text,
)

__all__ = ["DT_SOURCE", "read", "sniff"]

#: Where the time step comes from, for the plausibility warning.
DT_SOURCE = "real header 62 (in ms)"

#: COSMOS physical-units codes of acceleration -> ``RECORD_UNITS`` keys.
UNITS_CODES = {2: "g", 4: "cm/s2", 7: "in/s2", 10: "cm/s2", 11: "mg"}
#: COSMOS "unknown" marker of the real header.
UNKNOWN = -999.0
_FIRST = re.compile(r"\(Format v\d+\.\d+ with\s+(\d+) text lines\)", re.IGNORECASE)
_BLOCK = re.compile(
    r"^\s*(\d+)\s+(Integer|Real)-header values follow on\s+(\d+)\s+lines,\s*"
    r"Format\s*=\s*\((\d+)[IFE](\d+)(?:\.(\d+))?",
    re.IGNORECASE,
)
#: Fields of each header that the reader uses: the last one (1-based) and what they are.
_USED = {"integer": 2, "real": 65}
_USED_NAMES = {
    "integer": "processing stage and data type",
    "real": "62 sampling interval, 63 series length, 64 peak and 65 its time",
}
_APPROX = re.compile(r"approx\s+([-+0-9.Ee]+)\s*sec", re.IGNORECASE)
_COMMENTS = re.compile(r"^\s*(\d+)\s+Comment line\(s\) follow", re.IGNORECASE)
_DATA = re.compile(
    r"^\s*(\d+)\s+(\w+)\s+pts,.*units\s*=\s*([^(,]*)\((\d+)\)\s*,\s*"
    r"Format\s*=\s*\((\d+)[EFG](\d+)",
    re.IGNORECASE,
)


def sniff(head: str) -> bool:
    """Tell the start of a COSMOS file (``(Format v01.20 with 13 text lines)``)."""
    first = head.split("\n", 1)[0]
    return _FIRST.search(first) is not None


def _layout(text: str, count: int, per_line: int, width: int, nlines: int, where: str) -> None:
    """Refuse a Fortran format ``(nFw.d)`` that cannot lay ``count`` values on ``nlines`` lines.

    Raises
    ------
    InputError
        ``n`` or ``w`` is 0, or ``nlines`` is not the lines that ``count`` values take at
        ``n`` a line (field ``record``, quoting the line).
    """
    if per_line < 1 or width < 1:
        raise InputError(
            f"{where}: {text.strip()!r} gives {per_line} values a line of {width} characters; "
            "a COSMOS format has at least 1 value a line, at least 1 character wide (e.g. "
            "(5F15.6)); the header was edited or the file is damaged",
            "record",
        )
    need = -(-count // per_line)
    if nlines != need:
        raise InputError(
            f"{where}: {text.strip()!r}: {count} values at {per_line} a line take {need} lines, "
            f"not {nlines}; the header was edited or the file is damaged",
            "record",
        )


def _block(lines: list[str], i: int, name: str, kind: str) -> tuple[list[float], int, int]:
    """Read an integer or real header block at line index ``i``: values, next index, decimals."""
    match = _BLOCK.match(lines[i]) if i < len(lines) else None
    if match is None or match.group(2).lower() != kind:
        raise InputError(f"{name} line {i + 1}: expected the COSMOS {kind}-header line", "record")
    count, nlines = int(match.group(1)), int(match.group(3))
    per_line, width = int(match.group(4)), int(match.group(5))
    where = f"{name} line {i + 1}"
    _layout(lines[i], count, per_line, width, nlines, where)
    used = _USED[kind]
    if count < used:
        raise InputError(
            f"{where}: the {kind} header has {count} values, but the COSMOS V2 format has "
            f"100 and rockmech reads fields 1 to {used} ({_USED_NAMES[kind]}); the header "
            "is cut short or the file is damaged",
            "record",
        )
    if i + 1 + nlines > len(lines):
        raise InputError(
            f"{where}: the {kind} header takes {nlines} lines, but the file ends after "
            f"{len(lines) - i - 1}; the file is truncated",
            "record",
        )
    rows = [(k + 1, lines[k]) for k in range(i + 1, i + 1 + nlines)]
    values = fixed_width_values(rows, width, count, f"{name} {kind} header")
    return [float(v) for v in values], i + 1 + nlines, int(match.group(6) or 0)


def _check_text_count(lines: list[str], i: int, count: int, name: str) -> None:
    """Refuse a channel whose first line's text-line count does not reach its integer header.

    A COSMOS channel is its text header (as many lines as its first line says, ``with 13
    text lines``), then the integer-header line. A wrong count was answered "line 201:
    expected the integer-header line" (issue #36); this says what the count should be.
    """
    at = i + count
    if at < len(lines) and _is_block(lines[at], "integer"):
        return
    said = f"{name} line {i + 1} says the channel's text header has {count} lines"
    found = next((k for k in range(i + 1, len(lines)) if _is_block(lines[k], "integer")), None)
    layout = (
        "a COSMOS V2 channel is its text header (the count on its first line), then the line "
        "'100 Integer-header values follow on 10 lines, ...'"
    )
    if found is not None:
        raise InputError(
            f"{said}, but its integer-header line is line {found + 1}, after {found - i} text "
            f"lines ({layout}): the count on line {i + 1} was edited or the file is damaged "
            f"(it should read 'with {found - i} text lines')",
            "record",
        )
    ends = (
        f"the file ends after {len(lines) - i} lines"
        if at >= len(lines)
        else f"no integer-header line follows in the file's {len(lines)} lines"
    )
    raise InputError(
        f"{said}, but {ends} ({layout}): the file is truncated or its header is too long",
        "record",
    )


def _is_block(line: str, kind: str) -> bool:
    match = _BLOCK.match(line)
    return match is not None and match.group(2).lower() == kind


def _units(data: re.Match[str], where: str) -> str:
    """Return the units of a channel's data line, its code and its text agreeing."""
    code = int(data.group(4))
    if code not in UNITS_CODES:
        raise InputError(f"{where}: unknown COSMOS units code {code}", "record")
    units = UNITS_CODES[code]
    if data.group(3).strip() and units_from_text(data.group(3), where) != units:
        raise InputError(
            f"{where}: units {data.group(3).strip()!r} disagree with code {code}", "record"
        )
    return units


def _step(reals: list[float], npts: int, digits: int, where: str) -> float:
    """Return the time step [s] of real header 62 [ms], checked against the length (63)."""
    if reals[61] == UNKNOWN:
        raise InputError(f"{where}: real header 62 (sampling interval) is unknown", "record")
    if reals[61] <= 0:
        raise InputError(
            f"{where}: real header 62 (sampling interval) must be > 0 ms, got "
            f"{reals[61]:g}; the header was edited or the file is damaged",
            "record",
        )
    dt = reals[61] / 1000.0
    if reals[62] != UNKNOWN:
        check_duration(f"{reals[62]:.{digits}f}", npts, dt, where, "real header 63 (length)")
    return dt


def _station(text_header: list[str], notes: list[str]) -> dict[str, str]:
    """Return the event, station, component and SCNL a channel's text header and notes give."""
    scnl = next((c.split(">", 1)[1].split()[0] for c in notes if "<SCNL>" in c), "")
    found = re.search(r"Code:\s*(\S+)\s+(.*)$", text_header[4]) if len(text_header) > 4 else None
    return {
        "event": text_header[1].strip() if len(text_header) > 1 else "",
        "station": f"{found.group(1)} {found.group(2).strip()}" if found else "",
        "component": scnl.split(".")[1] if scnl.count(".") >= 1 else scnl,
        "scnl": scnl,
    }


def read(text: str, name: str) -> list[Channel]:
    """Read every acceleration channel of a COSMOS V2 file (usually one).

    Raises
    ------
    InputError
        A malformed header, a file that is not corrected (V2) acceleration, unknown units,
        a sample count other than the data line's or a peak other than real header 64.
    """
    lines = text.splitlines()
    channels: list[Channel] = []
    i, number_in_file = 0, 0
    while i < len(lines):
        if not lines[i].strip():
            i += 1
            continue
        first = _FIRST.search(lines[i])
        if first is None:
            raise InputError(f"{name} line {i + 1}: expected a COSMOS channel header", "record")
        _check_text_count(lines, i, int(first.group(1)), name)
        text_header = lines[i : i + int(first.group(1))]
        i += int(first.group(1))
        ints, i, _ = _block(lines, i, name, "integer")
        reals, i, digits = _block(lines, i, name, "real")
        comments = _COMMENTS.match(lines[i]) if i < len(lines) else None
        if comments is None:
            raise InputError(f"{name} line {i + 1}: expected the comment-count line", "record")
        notes = lines[i + 1 : i + 1 + int(comments.group(1))]
        i += 1 + int(comments.group(1))
        data = _DATA.match(lines[i]) if i < len(lines) else None
        if data is None:
            raise InputError(f"{name} line {i + 1}: expected the data line", "record")
        npts, width = int(data.group(1)), int(data.group(6))
        per_line = int(data.group(5))
        where_line = f"{name} line {i + 1}"
        _layout(lines[i], npts, per_line, width, -(-npts // max(per_line, 1)), where_line)
        approx = _APPROX.search(lines[i])
        nrows = -(-npts // per_line)
        rows = [(k + 1, lines[k]) for k in range(i + 1, min(i + 1 + nrows, len(lines)))]
        i += 1 + nrows
        if i < len(lines) and lines[i].lstrip().lower().startswith("end-of-data"):
            i += 1
        number_in_file += 1
        if int(ints[1]) != 1 or data.group(2).lower() != "acceleration":
            continue  # velocity or displacement channel
        where = f"{name} channel {number_in_file}"
        if int(ints[0]) != 2:
            raise InputError(
                f"{where}: processing stage {int(ints[0])}, not corrected acceleration (V2)",
                "record",
            )
        units = _units(data, where)
        dt = _step(reals, npts, digits, where)
        if approx is not None:
            _check_approx(approx.group(1), npts, dt, where)
        values = fixed_width_values(rows, width, npts, where)
        check_count(values, npts, where)
        stated = None if reals[63] == UNKNOWN else f"{reals[63]:.{digits}f}"
        peak = check_peak(values, stated, units, where)
        meta = {
            **_station(text_header, notes),
            "channel": number_in_file,
            "npts": npts,
            "dt": dt,
            "peak": peak,
            "peak_time_s": None if reals[64] == UNKNOWN else reals[64],
        }
        channels.append(Channel(values, dt, units, meta))
    if not channels:
        raise InputError(f"{name}: no acceleration channel in this COSMOS file", "record")
    return channels


def _check_approx(stated: str, npts: int, dt: float, where: str) -> None:
    """Check the data line's ``approx 210 secs`` against ``npts`` x ``dt`` (to 1 s or 1 %)."""
    value = number(stated, f"{where} approx secs")
    length = npts * dt
    if abs(value - length) > max(1.0, 0.01 * length):
        raise InputError(
            f"{where}: the data line says approx {stated} secs, but {npts} points at real "
            f"header 62's {dt * 1000.0:g} ms last {length:.6g} s: the point count, the sampling "
            "interval or the file was edited; download it again",
            "record",
        )
