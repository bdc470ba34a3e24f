"""Ground excitations the solvers accept: one-cycle pulses and sampled records.

Sign convention (Housner, theory §0): a positive ground acceleration opposes positive
rotation. A pulse with ``a_p > 0`` therefore first drives a body towards *negative*
rotation; ``a_p < 0`` first drives it open (positive rotation).

Pulse convention A (Zhang & Makris 2001, theory §10): the pulse starts at ``t = 0``
and ends at ``t = 1/f_p``; the body uplifts when the acceleration first exceeds the
uplift threshold, and the pulse ends at phase 2π regardless of when uplift happened.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from shared_schema.errors import InputError, wrong_type
from shared_schema.rules import G

__all__ = ["PULSE_SHAPES", "Pulse", "SampledAccel", "accel_hint", "require_accel"]

#: Pulse shapes and their phase offset: ``a_g(t) = a_p * sin(omega_p * t + offset)``.
PULSE_SHAPES = {"sine": 0.0, "cosine": 0.5 * math.pi}


@dataclass(frozen=True)
class Pulse:
    """One full cycle of a sine or cosine acceleration pulse.

    Parameters
    ----------
    a_p : float
        Signed amplitude [m/s²]. Positive first pushes towards negative rotation. The command
        line and the service take the amplitude in g (``a_p_g``): build such a pulse with
        ``Pulse.from_g``.
    f_p : float
        Pulse frequency [Hz]; the pulse lasts ``1/f_p`` seconds.
    shape : {"sine", "cosine"}
        ``a_g = a_p sin(2π f_p t)`` or ``a_g = a_p cos(2π f_p t)`` for ``0 <= t <= 1/f_p``.
    """

    a_p: float
    f_p: float
    shape: str = "sine"

    def __post_init__(self) -> None:
        if isinstance(self.a_p, bool) or not math.isfinite(float(self.a_p)):
            raise InputError(f"must be a finite number, got {self.a_p!r}", "a_p")
        if isinstance(self.f_p, bool) or not (math.isfinite(float(self.f_p)) and self.f_p > 0):
            raise InputError(f"must be finite and > 0, got {self.f_p!r}", "f_p")
        if self.shape not in PULSE_SHAPES:
            raise InputError(f"must be one of {sorted(PULSE_SHAPES)}, got {self.shape!r}", "shape")

    @classmethod
    def from_g(cls, a_p_g: float, f_p: float, shape: str = "sine") -> "Pulse":
        """Build the pulse of signed amplitude ``a_p_g`` in g, as the CLI and REST take it.

        Parameters
        ----------
        a_p_g : float
            Signed amplitude [g].
        f_p : float
            Pulse frequency [Hz].
        shape : {"sine", "cosine"}
            Pulse shape.

        Examples
        --------
        >>> round(Pulse.from_g(-0.5, 1.0).a_p, 6)
        -4.903325
        """
        if isinstance(a_p_g, bool) or not math.isfinite(float(a_p_g)):
            raise InputError(f"must be a finite number, got {a_p_g!r}", "a_p_g")
        return cls(float(a_p_g) * G, f_p, shape)

    @property
    def omega_p(self) -> float:
        """Circular pulse frequency [rad/s]."""
        return 2.0 * math.pi * self.f_p

    @property
    def duration(self) -> float:
        """Pulse duration [s]."""
        return 1.0 / self.f_p

    @property
    def phase(self) -> float:
        """Phase offset [rad] in ``a_g = a_p sin(omega_p t + phase)``."""
        return PULSE_SHAPES[self.shape]

    def accel(self, t: ArrayLike) -> NDArray[np.float64]:
        """Ground acceleration [m/s²] at times ``t`` [s]; zero outside the pulse."""
        tt = np.asarray(t, dtype=float)
        inside = (tt >= 0.0) & (tt <= self.duration)
        return np.where(inside, self.a_p * np.sin(self.omega_p * tt + self.phase), 0.0)


def check_finite_samples(a: NDArray[np.float64], field: str, where: str = "") -> None:
    """Refuse an acceleration history with a non-finite sample.

    Parameters
    ----------
    a : (n,) float
        The samples [m/s² or the record's units].
    field : str
        The input field the error names (``record``, ``acc``).
    where : str
        What to name before the message (a file), or nothing.

    Raises
    ------
    InputError
        Naming the first non-finite sample, its value and how many there are.
    """
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        prefix = f"{where}: " if where else ""
        raise InputError(
            f"{prefix}sample {int(bad[0])} is not finite ({float(a[bad[0]])}); "
            f"{bad.size} non-finite sample(s) in all",
            field,
        )


@dataclass(frozen=True)
class SampledAccel:
    """A uniformly sampled ground acceleration, linear between samples.

    This is the solver's view of a record (``records.GroundMotion`` adds metadata).

    Parameters
    ----------
    acc : (n,) float
        Acceleration samples [m/s²], ``n >= 2``, all finite.
    dt : float
        Sampling interval [s], > 0.
    t0 : float
        Time of the first sample [s], >= 0 (the body is at rest before it). Record files
        whose time column starts elsewhere are shifted to 0 when read (with a note).
    """

    acc: NDArray[np.float64]
    dt: float
    t0: float = 0.0

    def __post_init__(self) -> None:
        a = np.ascontiguousarray(self.acc, dtype=float)
        if a.ndim != 1 or a.size < 2:
            raise InputError(f"needs at least 2 samples, got {a.size}", "record")
        check_finite_samples(a, "record")
        if isinstance(self.dt, bool) or not (math.isfinite(float(self.dt)) and self.dt > 0):
            raise InputError(f"must be finite and > 0, got {self.dt!r}", "dt")
        t0 = float(self.t0)
        if not (math.isfinite(t0) and t0 >= 0.0):
            raise InputError(
                f"must be finite and >= 0, got {self.t0!r} (the body is at rest before the first "
                "sample; shift the time axis so that it starts at 0)",
                "t0",
            )
        a.setflags(write=False)
        object.__setattr__(self, "acc", a)
        object.__setattr__(self, "dt", float(self.dt))
        object.__setattr__(self, "t0", float(self.t0))

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.acc.size)

    @property
    def duration(self) -> float:
        """Time from first to last sample [s]."""
        return (self.n - 1) * self.dt

    @property
    def time(self) -> NDArray[np.float64]:
        """Sample times [s], shape (n,)."""
        return np.asarray(self.t0 + self.dt * np.arange(self.n), dtype=np.float64)

    def accel(self, t: ArrayLike) -> NDArray[np.float64]:
        """Piecewise-linear acceleration [m/s²] at ``t`` [s]; zero outside the record."""
        tt = np.asarray(t, dtype=float)
        inside = (tt >= self.t0) & (tt <= self.t0 + self.duration)
        return np.where(inside, np.interp(tt, self.time, self.acc), 0.0)


def accel_hint(value: object) -> str:
    """How to get a ``SampledAccel`` from ``value`` (a record, a path), for the messages."""
    if isinstance(getattr(value, "accel", None), SampledAccel):  # a GroundMotion
        return "a record's samples are its .accel (motion.accel)"
    if isinstance(value, (str, os.PathLike)):
        return "read the record first: rockmech.read_record(path).accel"
    return ""


def require_accel(value: object, field: str = "accel") -> SampledAccel:
    """Return ``value`` if it is a ``SampledAccel``; else an ``InputError`` saying what to pass."""
    if isinstance(value, SampledAccel):
        return value
    raise wrong_type(value, field, "a SampledAccel", accel_hint(value))
