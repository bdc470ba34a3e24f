"""Ground-motion records: reading, validation and metadata.

Formats read here (``GroundMotion.from_file`` picks one by name or by the file):

* ``"at2"``: PEER NGA ``.AT2``: four header lines (title; event, date, station, component;
  units; ``NPTS=..., DT=...``), then the samples in g, several per line
  (``GroundMotion.from_at2``);
* ``"two_column"``: time [s] and acceleration, whitespace- or comma-separated, ``#``
  comments allowed (``GroundMotion.from_two_column``);
* ``"one_column"``: one acceleration per line, the time step given by the caller
  (``GroundMotion.from_one_column``);
* ``"csv"``: comma-separated with a header row; a time column or a given time step
  (``GroundMotion.from_csv``).

The strong-motion databases' own formats, detected from their content and read by
``solver_service.core.formats`` (``GroundMotion.from_strong_motion``):

* ``"esm"``: ESM / ITACA ASCII (DYNA 1.2 header);
* ``"knet"``: NIED K-NET and KiK-net ASCII (scale factor applied, mean removed as NIED does);
* ``"cosmos"``: COSMOS V2 corrected acceleration;
* ``"dmg"``: CSMIP / DMG V2, several channels per file;
* ``"geonet"``: GeoNet V2A, three components per file.

Units of acceleration are a key of ``UNITS`` (``"g"``, ``"m/s2"``, ``"cm/s2"``, ``"mm/s2"``,
``"mg"``, ``"in/s2"``). Files that state their units (AT2, the strong-motion formats, a CSV
whose acceleration column names them: ``acc [g]``, ``a (m/s2)``, ``accel_cm/s2``) are read in
them; a given ``units`` must then agree. Files that do not state them need ``units``. Inside,
everything is SI (m/s²). Every sample of a file is kept, including a short last line; the
strong-motion readers also check the header's sample count and peak.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional, Union

import numpy as np
from numpy.typing import NDArray

from shared_schema.errors import InputError
from shared_schema.rules import (
    ACCEL_MAX_G,
    DT_RANGE_S,
    RECORD_FORMATS,
    RECORD_UNITS,
    G,
    accel_max,
    check_file,
)
from shared_schema.text import decimal_point, decode_text, delimiter_of

from .excitation import SampledAccel, check_finite_samples
from .formats import READERS, Channel, channel_list, select_channel
from .formats import detect as detect_strong_motion
from .formats import truncated as truncated_strong_motion
from .formats._text import units_or_none

__all__ = [
    "ACCEL_MAX_G",
    "DT_PLAUSIBLE_S",
    "DT_RANGE_S",
    "DT_RTOL",
    "FORMATS",
    "PGA_PLAUSIBLE_G",
    "UNITS",
    "GroundMotion",
    "detect_format",
    "plausibility_warnings",
]

#: Acceleration units and their factor to m/s² (``shared_schema.rules``).
UNITS = RECORD_UNITS
#: PGA [g] outside which a record gets a plausibility warning (issue #14: wrong units).
PGA_PLAUSIBLE_G = (0.001, 5.0)
#: Time step [s] outside which a record gets a plausibility warning.
DT_PLAUSIBLE_S = (1e-4, 0.1)
#: Relative tolerance on the spacing of time stamps read from a file.
DT_RTOL = 1e-6
#: What a record file must be, for the messages on empty or binary files.
RECORD_EXPECTED = (
    "a ground-motion record as text (AT2, two columns, one column, CSV, or the ASCII file of "
    "a strong-motion database: ESM, K-NET, COSMOS, DMG, GeoNet)"
)
#: What to do with a binary record.
RECORD_BINARY_HINT = (
    "rockmech reads no binary format (SAC, miniSEED, .xlsx): export the record as text, "
    "e.g. a CSV with a header 't [s],acc [g]'"
)
#: Record formats ``GroundMotion.from_file`` reads (``shared_schema.rules``).
FORMATS = RECORD_FORMATS
#: File extensions (lower case) that fix the format.
_EXTENSIONS = {".at2": "at2", ".csv": "csv"}
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
_UNITS_HINT = "give units: " + ", ".join(list(RECORD_UNITS)[:-1]) + f" or {list(RECORD_UNITS)[-1]}"
#: Units of a time column a CSV header may name; only seconds are read.
_SECONDS = {"s", "sec", "secs", "second", "seconds"}
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?"
_DATE = re.compile(r"\d{1,2}/\d{1,2}/\d{2,4}")

PathLike = Union[str, Path]
Column = Union[str, int, None]
ChannelKey = Union[int, str, None]


def _units_in_name(name: str) -> Optional[str]:
    """Units a column name states: ``acc [g]``, ``a (m/s2)``, ``accel_cm/s2`` -> key, else None."""
    bracket = re.search(r"[\[(]\s*([^\])]+?)\s*[\])]\s*$", name)
    if bracket:
        return units_or_none(bracket.group(1))
    for sep in ("_", " "):
        if sep in name.strip():
            return units_or_none(name.strip().rsplit(sep, 1)[1])
    return None


def _check_time_units(name: str, where: str) -> None:
    """Refuse a time column that names units other than seconds (``t [ms]``)."""
    bracket = re.search(r"[\[(]\s*([^\])]+?)\s*[\])]\s*$", name)
    if bracket and bracket.group(1).strip().lower() not in _SECONDS:
        raise InputError(
            f"{where}: time column {name!r} is in {bracket.group(1)!r}; give time in seconds",
            "time_column",
        )


def _unit_factor(units: str) -> float:
    if units not in UNITS:
        raise InputError(f"must be one of {sorted(UNITS)}, got {units!r}", "units")
    return UNITS[units]


def _check_dt(dt: Any) -> float:
    if isinstance(dt, bool) or not isinstance(dt, (int, float, np.floating, np.integer)):
        raise InputError(f"must be a finite number > 0 [s], got {dt!r}", "dt")
    if not (math.isfinite(float(dt)) and dt > 0):
        raise InputError(f"must be finite and > 0 [s], got {dt!r}", "dt")
    return float(dt)


def _read_text(path: PathLike) -> tuple[Path, str]:
    """Return a record file and its text (``decode_text``: empty, binary files refused)."""
    p = check_file(path, "record")
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read record file {p}: {exc.strerror or exc}", "record") from exc
    return p, decode_text(raw, p.name, "record", RECORD_EXPECTED, RECORD_BINARY_HINT)


def _data_lines(text: str) -> list[tuple[int, str, str]]:
    """``(line number, raw line, line without comment)`` of every non-blank data line."""
    out = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if line:
            out.append((lineno, raw, line))
    return out


def _to_float(token: str, where: str, raw: str) -> float:
    try:
        return float(token)
    except ValueError:
        raise InputError(f"{where}: not a number: {raw.strip()!r}", "record") from None


def _check_samples(a: NDArray[np.float64], name: str) -> None:
    if a.size < 2:
        raise InputError(f"{name}: needs at least 2 samples, got {a.size}", "record")
    check_finite_samples(a, "record", name)


def _sampled(a: NDArray[np.float64], units: str, dt: Any, name: str) -> SampledAccel:
    """Return samples ``a`` in ``units`` at step ``dt`` [s] as SI samples, checked first.

    Raises
    ------
    InputError
        A sample not finite or above ``ACCEL_MAX_G`` (field ``record``; in m/s² it might
        overflow), or ``dt`` outside ``DT_RANGE_S`` (field ``dt``).
    """
    factor = _unit_factor(units)
    a = np.asarray(a, dtype=float)
    _check_samples(a, name)
    # compared in the given units, so that a huge sample cannot overflow on the way to SI
    big = np.flatnonzero(np.abs(a) > accel_max(units))
    if big.size:
        k = int(big[0])
        raise InputError(
            f"{name}: sample {k} is {float(a[k]):.6g} {units}, above the largest acceleration "
            f"a record may hold ({ACCEL_MAX_G:g} g; plausible PGA: {PGA_PLAUSIBLE_G[0]:g} to "
            f"{PGA_PLAUSIBLE_G[1]:g} g); {big.size} such sample(s) in all: check the units",
            "record",
        )
    step = _check_dt(dt)
    lo, hi = DT_RANGE_S
    if not lo <= step <= hi:
        raise InputError(
            f"{name}: time step dt = {step:.6g} s is outside the range a record can have, "
            f"[{lo:g}, {hi:g}] s (plausible: {DT_PLAUSIBLE_S[0]:g} to {DT_PLAUSIBLE_S[1]:g} s); "
            "check the time units",
            "dt",
        )
    return SampledAccel(a * factor, step)


def _uniform_step(t: NDArray[np.float64], name: str) -> float:
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


def _at2_station(line: str) -> dict[str, str]:
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


def _at2_npts_dt(line: str, name: str) -> tuple[int, float]:
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


def _resolve_column(col: Column, header: list[str], arg: str, name: str) -> int:
    n = len(header)
    if isinstance(col, int) and not isinstance(col, bool):
        if not -n <= col < n:
            raise InputError(f"{name} has {n} columns, got column index {col}", arg)
        return col % n
    if isinstance(col, str):
        if col in header:
            return header.index(col)
        folded = [h.casefold() for h in header]
        if col.strip().casefold() in folded:
            return folded.index(col.strip().casefold())
    raise InputError(f"{name} has no column {col!r}; columns are {header}", arg)


def _check_stated_units(motion: GroundMotion, units: Optional[str], name: str) -> None:
    """Refuse ``units`` other than those the file states."""
    stated = motion.metadata["units"]
    if units is not None and units != stated:
        raise InputError(f"{name} states units {stated!r}, got {units!r}", "units")


def _check_one_channel(
    motion: GroundMotion, channel: ChannelKey, component: Optional[str], name: str
) -> None:
    """Refuse a channel or component other than the one a single-channel file holds."""
    if channel is not None and str(channel).strip() != "1":
        raise InputError(f"{name} holds one channel (1), got channel {channel!r}", "channel")
    own = str(motion.metadata.get("component", ""))
    if (
        component is not None
        and "".join(component.split()).casefold() != "".join(own.split()).casefold()
    ):
        raise InputError(
            f"{name} holds one channel (component {own or 'not stated'}), "
            f"got component {component!r}",
            "component",
        )


@dataclass(frozen=True)
class GroundMotion:
    """A uniformly sampled ground-acceleration record with its metadata.

    Attributes
    ----------
    accel : SampledAccel
        The samples [m/s²] and sampling interval [s].
    name : str
        Short name (by default the file stem).
    metadata : dict
        Event, station, component, source file, original units, ... as known.
    """

    accel: SampledAccel
    name: str = "record"
    metadata: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        notes = plausibility_warnings(self)
        if notes:
            self.metadata["warnings"] = [*self.metadata.get("warnings", []), *notes]

    @property
    def warnings(self) -> list[str]:
        """Notes on how the record was read or why its values look implausible."""
        return list(self.metadata.get("warnings", []))

    @property
    def dt(self) -> float:
        """Sampling interval [s]."""
        return self.accel.dt

    @property
    def pga(self) -> float:
        """Peak ground acceleration [m/s²]."""
        return float(np.max(np.abs(self.accel.acc)))

    @property
    def pga_g(self) -> float:
        """Peak ground acceleration [g]."""
        return self.pga / G

    @property
    def duration(self) -> float:
        """Duration [s]."""
        return self.accel.duration

    @classmethod
    def from_samples(
        cls,
        acc: NDArray[np.float64],
        dt: float,
        *,
        units: str = "m/s2",
        name: str = "record",
        metadata: dict[str, Any] | None = None,
    ) -> GroundMotion:
        """Build a record from acceleration samples in ``units`` at interval ``dt`` [s]."""
        meta = {"units": units, **(metadata or {})}
        return cls(_sampled(np.asarray(acc, dtype=float), units, dt, name), name, meta)

    @classmethod
    def from_file(
        cls,
        path: PathLike,
        *,
        format: Optional[str] = None,
        units: Optional[str] = None,
        dt: Optional[float] = None,
        channel: ChannelKey = None,
        component: Optional[str] = None,
    ) -> GroundMotion:
        """Read a record in any of ``FORMATS``, named or detected.

        Parameters
        ----------
        path : str or Path
            The record file.
        format : str, optional
            One of ``FORMATS``. By default from the extension (``.AT2``, ``.csv``), else
            from the content: a strong-motion header (ESM, K-NET, COSMOS, DMG, GeoNet), else
            the first data line: two numbers are ``two_column``, one is ``one_column``.
        units : str, optional
            Units of acceleration, a key of ``UNITS``. Required where the file does not
            state them; where it does (AT2, strong-motion formats, a CSV header naming
            them) a given value must agree.
        dt : float, optional
            Time step [s] for files without a time column (``one_column``, ``csv``);
            refused where the file has its own.
        channel : int or str, optional
            Channel number as the file gives it (1-based), for files with several.
        component : str, optional
            Component as the header names it (``S16W``, ``Up``, ``90 DEG``).

        Raises
        ------
        InputError
            Unknown or undetectable format (field ``format``), missing or contradicting
            units (``units``), missing or superfluous ``dt`` (``dt``), several channels and
            none chosen or no such channel (``channel``, ``component``), or a bad file
            (``record``).
        """
        p = Path(path)
        if format is None:
            fmt = detect_format(p)
        elif format in FORMATS:
            fmt = format
        else:
            raise InputError(
                f"unknown record format {format!r} for {p.name}; formats are {list(FORMATS)}",
                "format",
            )
        if fmt in READERS:
            if dt is not None:
                raise InputError(f"{p.name} is {fmt} and states its own time step", "dt")
            motion = cls.from_strong_motion(p, fmt, channel=channel, component=component)
            _check_stated_units(motion, units, p.name)
            return motion
        if fmt == "at2":
            if dt is not None:
                raise InputError(f"{p.name} is AT2 and states its own time step", "dt")
            motion = cls.from_at2(p)
            _check_stated_units(motion, units, p.name)
        elif fmt == "csv":
            motion = cls.from_csv(p, units, dt=dt)
        elif units is None:
            raise InputError(f"{_UNITS_HINT} ({fmt} file {p.name} does not state them)", "units")
        elif fmt == "two_column":
            if dt is not None:
                raise InputError(f"{p.name} has a time column; do not give dt", "dt")
            motion = cls.from_two_column(p, units=units)
        else:
            if dt is None:
                raise InputError(f"one_column file {p.name} needs a time step dt [s]", "dt")
            motion = cls.from_one_column(p, dt, units)
        _check_one_channel(motion, channel, component, p.name)
        return motion

    @classmethod
    def from_strong_motion(
        cls,
        path: PathLike,
        format: Optional[str] = None,
        *,
        channel: ChannelKey = None,
        component: Optional[str] = None,
    ) -> GroundMotion:
        """Read one acceleration channel of an ESM, K-NET, COSMOS, DMG or GeoNet file.

        Parameters
        ----------
        path : str or Path
            The file.
        format : {"esm", "knet", "cosmos", "dmg", "geonet"}, optional
            By default detected from the header.
        channel, component : optional
            Which channel of a file with several (see ``from_file``); required there.

        Raises
        ------
        InputError
            Not one of these formats, a bad header, a sample count or peak other than the
            header states (``record``), or no channel chosen among several (``channel``).

        Notes
        -----
        ``metadata`` holds ``station``, ``component``, ``channel``, ``event``, ``units``
        (the file's), ``dt`` [s], ``npts``, ``peak`` (the header's, in the file's units),
        ``pga_g``, ``source``, ``format`` and ``channels`` (every channel of the file,
        ``"1: 90 DEG, 2: UP, ..."``), plus the fields each format adds.
        """
        p, text = _read_text(path)
        fmt = format if format is not None else detect_strong_motion(text)
        if fmt is None or fmt not in READERS:
            raise InputError(
                f"{p.name} is not one of the strong-motion formats {list(READERS)}", "format"
            )
        channels = READERS[fmt][1](text, p.name)
        chosen: Channel = select_channel(channels, p.name, channel, component)
        meta: dict[str, Any] = {
            **chosen.metadata,
            "source": p.name,
            "format": fmt,
            "units": chosen.units,
            "channels": channel_list(channels),
        }
        name = p.stem if len(channels) == 1 else f"{p.stem}_{chosen.metadata['channel']}"
        accel = _sampled(chosen.values, chosen.units, chosen.dt, p.name)
        motion = cls(accel, name, meta)
        meta["pga_g"] = motion.pga_g
        return motion

    @classmethod
    def from_at2(cls, path: PathLike) -> GroundMotion:
        """Read a PEER NGA ``.AT2`` acceleration record.

        Parameters
        ----------
        path : str or Path
            The file: title line; ``event, date, station, component``; units
            (``... IN UNITS OF G``); ``NPTS=..., DT=... SEC``; then ``NPTS`` values,
            several per line. Every value is kept, the short last line included.

        Raises
        ------
        InputError
            Missing file, short header, unknown units, a velocity or displacement file,
            unparsable values, or a count of values other than ``NPTS``.

        Notes
        -----
        ``metadata`` holds ``event``, ``date``, ``station``, ``component`` (parsed from
        line 2 as far as possible; ``header`` keeps the raw line), ``dt`` [s], ``npts``,
        ``units``, ``source`` (file name), ``format`` and ``pga_g``.
        """
        p, text = _read_text(path)
        lines = text.splitlines()
        if len(lines) < 4:
            raise InputError(
                f"{p.name}: AT2 needs 4 header lines, got {len(lines)} line(s)", "record"
            )
        kind = lines[2].upper()
        if "ACCELERATION" not in kind:
            raise InputError(
                f"{p.name} line 3: not an acceleration record: {lines[2].strip()!r}", "record"
            )
        unit_word = kind.rsplit("UNITS OF", 1)[-1].replace(" ", "") if "UNITS OF" in kind else ""
        if unit_word not in _AT2_UNITS:
            raise InputError(
                f"{p.name} line 3: unknown units in {lines[2].strip()!r}; "
                f"known: {sorted(_AT2_UNITS)}",
                "record",
            )
        units = _AT2_UNITS[unit_word]
        npts, dt = _at2_npts_dt(lines[3], p.name)
        _check_dt(dt)
        values: list[float] = []
        for lineno, raw in enumerate(lines[4:], start=5):
            where = f"{p.name} line {lineno}"
            values.extend(_to_float(tok, where, raw) for tok in raw.split())
        if len(values) != npts:
            raise InputError(
                f"{p.name}: header says NPTS={npts}, but the file has {len(values)} values",
                "record",
            )
        a = np.array(values, dtype=float)
        _check_samples(a, p.name)
        meta: dict[str, Any] = {
            **_at2_station(lines[1]),
            "header": lines[1].strip(),
            "source": p.name,
            "format": "at2",
            "units": units,
            "dt": dt,
            "npts": npts,
        }
        motion = cls(_sampled(a, units, dt, p.name), p.stem, meta)
        meta["pga_g"] = motion.pga_g
        return motion

    @classmethod
    def from_two_column(cls, path: PathLike, *, units: str = "g") -> GroundMotion:
        """Read a two-column file: time [s] and acceleration in ``units``.

        Parameters
        ----------
        path : str or Path
            Text file; whitespace or commas separate the columns; lines starting with
            ``#`` are comments.
        units : {"g", "m/s2", "cm/s2"}
            Units of the acceleration column (default ``"g"`` kept for old callers;
            ``from_file`` requires it).

        Raises
        ------
        InputError
            Missing file, unparsable line, fewer than 2 samples, non-finite values, or time
            that is not strictly increasing and uniform (within ``DT_RTOL``).
        """
        _unit_factor(units)  # unknown units are refused before the file is read
        p, text = _read_text(path)
        rows: list[tuple[float, float]] = []
        for lineno, raw, line in _data_lines(text):
            parts = line.replace(",", " ").split()
            where = f"{p.name} line {lineno}"
            if len(parts) != 2:
                raise InputError(
                    f"{where}: expected 2 columns (time, acceleration), got {len(parts)}",
                    "record",
                )
            rows.append((_to_float(parts[0], where, raw), _to_float(parts[1], where, raw)))
        data = np.array(rows, dtype=float).reshape(-1, 2)
        t, a = data[:, 0], data[:, 1]
        _check_samples(a, p.name)
        dt = _uniform_step(t, p.name)
        meta = {"source": p.name, "format": "two_column", "units": units, "npts": int(t.size)}
        meta.update(_time_origin(float(t[0]), p.name))
        return cls(_sampled(a, units, dt, p.name), p.stem, meta)

    @classmethod
    def from_one_column(cls, path: PathLike, dt: float, units: str) -> GroundMotion:
        """Read one acceleration per line, in ``units``, sampled every ``dt`` [s].

        Parameters
        ----------
        path : str or Path
            Text file; ``#`` starts a comment; blank lines are skipped.
        dt : float
            Sampling interval [s], finite and > 0.
        units : {"g", "m/s2", "cm/s2"}
            Units of the values.

        Raises
        ------
        InputError
            Bad ``dt`` or ``units``, missing file, a line with other than one number,
            fewer than 2 samples or non-finite values.
        """
        dt = _check_dt(dt)
        _unit_factor(units)  # unknown units are refused before the file is read
        p, text = _read_text(path)
        values: list[float] = []
        for lineno, raw, line in _data_lines(text):
            parts = line.replace(",", " ").split()
            where = f"{p.name} line {lineno}"
            if len(parts) != 1:
                raise InputError(f"{where}: expected 1 column, got {len(parts)}", "record")
            values.append(_to_float(parts[0], where, raw))
        a = np.array(values, dtype=float)
        _check_samples(a, p.name)
        meta = {"source": p.name, "format": "one_column", "units": units, "npts": int(a.size)}
        return cls(_sampled(a, units, dt, p.name), p.stem, meta)

    @classmethod
    def from_csv(
        cls,
        path: PathLike,
        units: Optional[str] = None,
        time_column: Column = None,
        accel_column: Column = None,
        dt: Optional[float] = None,
    ) -> GroundMotion:
        """Read a comma-separated file with a header row.

        Parameters
        ----------
        path : str or Path
            The file; ``#`` comment lines and blank lines are skipped. If the first row is
            all numbers it is data (no header) and columns can only be given by index.
        units : str, optional
            Units of the acceleration column, a key of ``UNITS``. By default read from the
            column's name (``acc [g]``, ``a (m/s2)``, ``accel_cm/s2``); required where the
            name states none, and must agree where it does.
        time_column, accel_column : str or int, optional
            Columns by header name (exact, else case-insensitive) or 0-based index. By
            default time is column 0 and acceleration the first other column.
        dt : float, optional
            Time step [s] for a file without a time column. Then ``time_column`` must not
            be given, and ``accel_column`` defaults to the only column.

        Raises
        ------
        InputError
            Bad ``units``/``dt``/columns, missing file, unparsable cells, fewer than 2
            samples, non-finite values, or time not strictly increasing and uniform.
        """
        if units is not None:
            _unit_factor(units)
        if dt is not None:
            dt = _check_dt(dt)
            if time_column is not None:
                raise InputError("give either a time column or dt, not both", "dt")
        p, text = _read_text(path)
        lines = _data_lines(text)
        if not lines:
            raise InputError(f"{p.name}: needs at least 2 samples, got 0", "record")
        # A CSV from a European spreadsheet separates cells with ';' and may write decimal
        # commas (shared_schema.text.delimiter_of).
        delimiter = delimiter_of(lines[0][2])
        rows = [(n, raw, next(csv.reader([ln], delimiter=delimiter))) for n, raw, ln in lines]
        if delimiter == ";":
            rows = [(n, raw, [decimal_point(c) for c in cells]) for n, raw, cells in rows]
        first = [c.strip() for c in rows[0][2]]
        try:
            [float(c) for c in first]
            header = [str(i) for i in range(len(first))]
            names = False
        except ValueError:
            header, rows, names = first, rows[1:], True
        if dt is None:
            if len(header) < 2:
                raise InputError(f"{p.name} has no time column; give dt [s]", "dt")
            it: Optional[int] = _resolve_column(
                0 if time_column is None else time_column, header, "time_column", p.name
            )
            default_acc = 1 if it == 0 else 0
        else:
            it = None
            if accel_column is None and len(header) != 1:
                raise InputError(
                    f"{p.name} has {len(header)} columns {header}; name the acceleration one",
                    "accel_column",
                )
            default_acc = 0
        ia = _resolve_column(
            default_acc if accel_column is None else accel_column, header, "accel_column", p.name
        )
        if ia == it:
            raise InputError(f"{p.name}: time and acceleration are the same column", "accel_column")
        stated = _units_in_name(header[ia]) if names else None
        if stated is None and units is None:
            raise InputError(
                f"{_UNITS_HINT} (column {header[ia]!r} of {p.name} does not state them)", "units"
            )
        if stated is not None and units is not None and stated != units:
            raise InputError(
                f"{p.name}: column {header[ia]!r} states units {stated!r}, got {units!r}", "units"
            )
        units = stated or units
        assert units is not None
        if it is not None and names:
            _check_time_units(header[it], p.name)
        need = max(ia, -1 if it is None else it) + 1
        t_list: list[float] = []
        a_list: list[float] = []
        for lineno, raw, cells in rows:
            where = f"{p.name} line {lineno}"
            if len(cells) < need:
                raise InputError(
                    f"{where}: expected {len(header)} columns, got {len(cells)}", "record"
                )
            a_list.append(_to_float(cells[ia].strip(), where, raw))
            if it is not None:
                t_list.append(_to_float(cells[it].strip(), where, raw))
        a = np.array(a_list, dtype=float)
        _check_samples(a, p.name)
        t0 = 0.0
        if it is not None:
            t = np.array(t_list, dtype=float)
            dt, t0 = _uniform_step(t, p.name), float(t[0])
        assert dt is not None
        meta = {
            "source": p.name,
            "format": "csv",
            "delimiter": delimiter,
            "units": units,
            "npts": int(a.size),
            "time_column": header[it] if (it is not None and names) else it,
            "accel_column": header[ia] if names else ia,
            "units_from": "header" if stated is not None else "given",
        }
        meta.update(_time_origin(t0, p.name))
        return cls(_sampled(a, units, dt, p.name), p.stem, meta)


def _time_origin(t0: float, name: str) -> dict[str, Any]:
    """Metadata for a time column that does not start at 0: the record is shifted to 0.

    Every sample is used, from the first; the analyses take t = 0 at the first sample, so a
    time column starting at ``t0`` is shifted by ``-t0`` and the shift is reported.
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


def plausibility_warnings(motion: GroundMotion) -> list[str]:
    """Warnings for a record whose PGA or time step is implausible (often wrong units).

    A PGA below ``PGA_PLAUSIBLE_G[0]`` or above ``PGA_PLAUSIBLE_G[1]`` [g], or a time step
    outside ``DT_PLAUSIBLE_S`` [s], gets a warning naming the units the file was read in.
    """
    units = motion.metadata.get("units")
    read_in = f"read in {units}" if units else "units not stated"
    dt_from = _dt_source(motion.metadata)
    notes = []
    pga_g = motion.pga_g
    lo, hi = PGA_PLAUSIBLE_G
    if not lo <= pga_g <= hi:
        notes.append(
            f"PGA {pga_g:.3g} g is outside the plausible range [{lo:g}, {hi:g}] g "
            f"({read_in}); check the units"
        )
    dt_lo, dt_hi = DT_PLAUSIBLE_S
    if not dt_lo <= motion.dt <= dt_hi:
        notes.append(
            f"time step dt = {motion.dt:.3g} s is outside the plausible range "
            f"[{dt_lo:g}, {dt_hi:g}] s (read as seconds from {dt_from}); check the time units "
            "(ms written as s?) or the time step given"
        )
    return notes


#: Where each format's time step comes from, for the plausibility warning.
_DT_SOURCES = {
    "at2": "the AT2 header's DT",
    "two_column": "the time column",
    "one_column": "the time step given (dt, --dt)",
    "esm": "the header's SAMPLING_INTERVAL_S",
    "knet": "1 / the header's Sampling Freq(Hz)",
    "cosmos": "real header 62 (in ms)",
    "dmg": "the 'POINTS OF ACCEL DATA EQUALLY SPACED AT' line",
    "geonet": "the header's sampling interval (row 7, field 6)",
    "samples": "dt",
}


def _dt_source(meta: dict[str, Any]) -> str:
    """Where a record's time step was read from (a header field, a column, or given)."""
    fmt = meta.get("format")
    if fmt == "csv":
        return (
            "the time column" if meta.get("time_column") is not None else _DT_SOURCES["one_column"]
        )
    return _DT_SOURCES.get(str(fmt), "the time step given")


def detect_format(p: Path) -> str:
    """Return the format of a record file.

    From its extension (``.AT2``, ``.csv``), else its content: a PEER title, a strong-motion
    header (``solver_service.core.formats.detect``), else the count of numbers on the first
    data line (2: ``two_column``, 1: ``one_column``).
    """
    fmt = _EXTENSIONS.get(p.suffix.lower())
    if fmt is not None:
        return fmt
    _, text = _read_text(p)
    if text.lstrip().upper().startswith("PEER NGA"):
        return "at2"
    strong = detect_strong_motion(text)
    if strong is not None:
        return strong
    cut = truncated_strong_motion(text, p.name)
    if cut is not None:
        raise InputError(cut, "record")
    lines = _data_lines(text)
    if not lines:
        raise InputError(f"{p.name} is empty: no data lines to read", "record")
    first = lines[0][2].replace(",", " ").split()
    try:
        [float(x) for x in first]
    except ValueError:
        first = []
    if len(first) == 2:
        return "two_column"
    if len(first) == 1:
        return "one_column"
    raise InputError(
        f"cannot tell the format of {p.name} (line {lines[0][0]}: {lines[0][1].strip()!r}); "
        f"give format, one of {list(FORMATS)}",
        "format",
    )
