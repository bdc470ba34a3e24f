"""Ground-motion records: reading, validation and metadata.

Formats read here:

* two columns, time [s] and acceleration, whitespace- or comma-separated, ``#`` comments
  allowed (``GroundMotion.from_two_column``).

Units of acceleration are named explicitly: ``"g"``, ``"m/s2"`` or ``"cm/s2"``. Inside,
everything is SI (m/s²).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

from shared_schema.errors import InputError

from .excitation import SampledAccel
from .model import G

__all__ = ["UNITS", "GroundMotion"]

#: Acceleration units and their factor to m/s².
UNITS = {"g": G, "m/s2": 1.0, "cm/s2": 0.01}
#: Relative tolerance on the spacing of time stamps read from a file.
DT_RTOL = 1e-6


def _unit_factor(units: str) -> float:
    if units not in UNITS:
        raise InputError(f"must be one of {sorted(UNITS)}, got {units!r}", "units")
    return UNITS[units]


def _read_text(path: Union[str, Path]) -> tuple[Path, str]:
    p = Path(path)
    if not p.is_file():
        raise InputError(f"record file not found: {p}", "record")
    try:
        return p, p.read_text(encoding="utf-8", errors="strict")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read record file {p}: {exc}", "record") from exc


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
        factor = _unit_factor(units)
        meta = {"units": units, **(metadata or {})}
        return cls(SampledAccel(np.asarray(acc, dtype=float) * factor, dt), name, meta)

    @classmethod
    def from_two_column(cls, path: Union[str, Path], *, units: str = "g") -> GroundMotion:
        """Read a two-column file: time [s] and acceleration in ``units``.

        Parameters
        ----------
        path : str or Path
            Text file; whitespace or commas separate the columns; lines starting with
            ``#`` are comments.
        units : {"g", "m/s2", "cm/s2"}
            Units of the acceleration column.

        Raises
        ------
        InputError
            Missing file, unparsable line, fewer than 2 samples, non-finite values, or time
            that is not strictly increasing and uniform (within ``DT_RTOL``).
        """
        factor = _unit_factor(units)
        p, text = _read_text(path)
        rows: list[tuple[float, float]] = []
        for lineno, raw in enumerate(text.splitlines(), start=1):
            line = raw.split("#", 1)[0].replace(",", " ").strip()
            if not line:
                continue
            parts = line.split()
            if len(parts) != 2:
                raise InputError(
                    f"{p.name} line {lineno}: expected 2 columns (time, acceleration), "
                    f"got {len(parts)}",
                    "record",
                )
            try:
                rows.append((float(parts[0]), float(parts[1])))
            except ValueError:
                raise InputError(
                    f"{p.name} line {lineno}: not a number: {raw.strip()!r}", "record"
                ) from None
        if len(rows) < 2:
            raise InputError(f"{p.name}: needs at least 2 samples, got {len(rows)}", "record")
        data = np.array(rows)
        t, a = data[:, 0], data[:, 1]
        bad = np.flatnonzero(~np.isfinite(data).all(axis=1))
        if bad.size:
            raise InputError(f"{p.name}: sample {int(bad[0])} is not finite", "record")
        steps = np.diff(t)
        if np.any(steps <= 0.0):
            k = int(np.flatnonzero(steps <= 0.0)[0])
            raise InputError(
                f"{p.name}: time is not strictly increasing at sample {k + 1} "
                f"(t = {t[k]} then {t[k + 1]})",
                "record",
            )
        dt = (t[-1] - t[0]) / (t.size - 1)
        worst = int(np.argmax(np.abs(steps - dt)))
        if abs(steps[worst] - dt) > DT_RTOL * dt:
            raise InputError(
                f"{p.name}: time step is not uniform (step {worst + 1} is {steps[worst]:.6g} s, "
                f"mean {dt:.6g} s); resample the record",
                "record",
            )
        if not math.isfinite(dt) or dt <= 0.0:
            raise InputError(f"{p.name}: invalid time step {dt!r}", "record")
        meta = {"source": p.name, "format": "two_column", "units": units, "npts": int(t.size)}
        return cls(SampledAccel(a * factor, dt, t0=float(t[0])), p.stem, meta)
