"""Ground-motion records: reading a file, validation and metadata.

Every format's reader lives in ``solver_service.core.formats`` (one module per format); this
module reads the file's text, hands it to the reader and turns the ``Channel`` it returns
into an SI ``GroundMotion``, checked. ``GroundMotion.from_file`` picks the format by name or
by the file:

* ``"at2"``: PEER NGA ``.AT2``: four header lines (title; event, date, station, component;
  units; ``NPTS=..., DT=...``), then the samples in g, several per line
  (``GroundMotion.from_at2``);
* ``"two_column"``: time [s] and acceleration, whitespace- or comma-separated, ``#``
  comments allowed (``GroundMotion.from_two_column``);
* ``"one_column"``: one acceleration per line, the time step given by the caller
  (``GroundMotion.from_one_column``);
* ``"csv"``: comma-separated with a header row; a time column or a given time step
  (``GroundMotion.from_csv``).

The strong-motion databases' own formats, detected from their content
(``GroundMotion.from_strong_motion``):

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
from shared_schema.text import decode_text

from . import formats
from .excitation import SampledAccel
from .formats import READERS, Channel, channel_list, check_samples, check_step, select_channel
from .formats.csv import UNITS_HINT, Column

__all__ = [
    "ACCEL_MAX_G",
    "DT_PLAUSIBLE_S",
    "DT_RANGE_S",
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
PathLike = Union[str, Path]
ChannelKey = Union[int, str, None]


def _unit_factor(units: str) -> float:
    if units not in UNITS:
        raise InputError(f"must be one of {sorted(UNITS)}, got {units!r}", "units")
    return UNITS[units]


def _read_text(path: PathLike) -> tuple[Path, str]:
    """Return a record file and its text (``decode_text``: empty, binary files refused)."""
    p = check_file(path, "record")
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read record file {p}: {exc.strerror or exc}", "record") from exc
    return p, decode_text(raw, p.name, "record", RECORD_EXPECTED, RECORD_BINARY_HINT)


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
    check_samples(a, name)
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
    step = check_step(dt)
    lo, hi = DT_RANGE_S
    if not lo <= step <= hi:
        raise InputError(
            f"{name}: time step dt = {step:.6g} s is outside the range a record can have, "
            f"[{lo:g}, {hi:g}] s (plausible: {DT_PLAUSIBLE_S[0]:g} to {DT_PLAUSIBLE_S[1]:g} s); "
            "check the time units",
            "dt",
        )
    return SampledAccel(a * factor, step)


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
            raise InputError(f"{UNITS_HINT} ({fmt} file {p.name} does not state them)", "units")
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
        fmt = format if format is not None else formats.detect(text)
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
        return cls.from_channel(Channel(chosen.values, chosen.dt, chosen.units, meta), name)

    @classmethod
    def from_channel(cls, channel: Channel, name: str) -> GroundMotion:
        """Build a record from one channel a format's reader returned (checked, then SI).

        Parameters
        ----------
        channel : Channel
            The samples in the units the file states or the caller gave, the time step
            [s] and the metadata (``source`` names the file in messages).
        name : str
            The record's name (the file's stem).
        """
        meta = channel.metadata
        source = str(meta.get("source", name))
        motion = cls(_sampled(channel.values, channel.units, channel.dt, source), name, meta)
        if meta.get("format") in ("at2", *READERS):
            meta["pga_g"] = motion.pga_g
        return motion

    @classmethod
    def from_at2(cls, path: PathLike) -> GroundMotion:
        """Read a PEER NGA ``.AT2`` acceleration record (``formats.at2.read``).

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
        return cls.from_channel(formats.at2.read(text, p.name)[0], p.stem)

    @classmethod
    def from_two_column(cls, path: PathLike, *, units: str = "g") -> GroundMotion:
        """Read a two-column file: time [s] and acceleration in ``units`` (``formats.two_column``).

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
            that is not strictly increasing and uniform (within ``formats.DT_RTOL``).
        """
        _unit_factor(units)  # unknown units are refused before the file is read
        p, text = _read_text(path)
        return cls.from_channel(formats.two_column.read(text, p.name, units), p.stem)

    @classmethod
    def from_one_column(cls, path: PathLike, dt: float, units: str) -> GroundMotion:
        """Read one acceleration per line, in ``units``, every ``dt`` [s] (``formats.one_column``).

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
        dt = check_step(dt)
        _unit_factor(units)  # unknown units are refused before the file is read
        p, text = _read_text(path)
        return cls.from_channel(formats.one_column.read(text, p.name, dt, units), p.stem)

    @classmethod
    def from_csv(
        cls,
        path: PathLike,
        units: Optional[str] = None,
        time_column: Column = None,
        accel_column: Column = None,
        dt: Optional[float] = None,
    ) -> GroundMotion:
        """Read a comma-separated file with a header row (``formats.csv``).

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
            dt = check_step(dt)
            if time_column is not None:
                raise InputError("give either a time column or dt, not both", "dt")
        p, text = _read_text(path)
        channel = formats.csv.read(text, p.name, units, time_column, accel_column, dt)
        return cls.from_channel(channel, p.stem)


def plausibility_warnings(motion: GroundMotion) -> list[str]:
    """Warnings for a record whose PGA or time step is implausible (often wrong units).

    A PGA below ``PGA_PLAUSIBLE_G[0]`` or above ``PGA_PLAUSIBLE_G[1]`` [g], or a time step
    outside ``DT_PLAUSIBLE_S`` [s], gets a warning naming the units the file was read in.
    """
    units = motion.metadata.get("units")
    read_in = f"read in {units}" if units else "units not stated"
    dt_from = formats.dt_source(motion.metadata)
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


def detect_format(p: Path) -> str:
    """Return the format of a record file (``formats.format_of``).

    From its extension (``.AT2``, ``.csv``), else its content: a PEER title, a strong-motion
    header (``solver_service.core.formats.detect``), else the count of numbers on the first
    data line (2: ``two_column``, 1: ``one_column``).
    """
    if p.suffix.lower() in formats.EXTENSIONS:
        return formats.EXTENSIONS[p.suffix.lower()]
    _, text = _read_text(p)
    return formats.format_of(text, p.name)
