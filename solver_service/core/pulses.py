"""The largest single sine pulse contained in a ground-motion record (MISSION B8).

Method (zero-crossing lobes)
----------------------------
1. The record is read as piecewise linear, as the solver reads it. Its zero crossings are
   found between samples by linear interpolation. A stretch where the record is exactly
   zero (e.g. padding) is a gap; a single zero sample that the record only passes through
   or touches is not.
2. A *lobe* is the stretch between two consecutive crossings: one sign, a duration ``d`` [s]
   and a peak ``|a|`` (the largest sample in it). The partial lobes before the first and
   after the last crossing are not complete half-cycles and are left out.
3. Every two adjacent lobes of opposite sign form a candidate one-cycle
   sine pulse: ``f_p = 1/(d_1 + d_2)`` and ``a_p = min(peak_1, peak_2)``, signed by the first
   lobe (positive: the ground first accelerates positively, the solver's ``Pulse``
   convention). Taking the smaller peak makes the pulse *contained* in the record: both of
   its half-cycles reach at least ``a_p``.
4. The largest pulse is the candidate with the greatest ``|a_p|`` within the frequency
   range asked for (ties: the lower frequency, the more damaging one for rocking).

A one-cycle sine pulse embedded in a record is recovered up to sampling: ``f_p`` and the
start time to the accuracy of the interpolated crossings (exact where they fall on samples;
within one ``dt`` at the edge of zero padding), and ``a_p`` to within
``|a_p| (1 - cos(π f_p dt))``, the largest gap between a crest and its nearest sample.

Drawn on an envelope plot at a series of scale factors ``s``, the points ``(f_p, s |a_p|)``
show from which scale the record's strongest pulse crosses each mechanism's envelope.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np
from numpy.typing import NDArray

from shared_schema.errors import InputError

from .excitation import SampledAccel, require_accel
from .model import G

__all__ = ["ExtractedPulse", "extract_pulses", "largest_pulse"]


@dataclass(frozen=True)
class ExtractedPulse:
    """One sine pulse found in a record.

    Attributes
    ----------
    a_p : float
        Signed amplitude [m/s²]; positive when the ground first accelerates positively.
    f_p : float
        Frequency [Hz]: the inverse of the two lobes' total duration.
    t_start : float
        Time of the zero crossing that starts the pulse [s].
    half_durations : tuple of float
        Durations of the first and second lobes [s]; equal for a perfect sine.
    peaks : tuple of float
        Peak ``|a|`` of the first and second lobes [m/s²].
    """

    a_p: float
    f_p: float
    t_start: float
    half_durations: tuple[float, float]
    peaks: tuple[float, float]

    @property
    def a_p_g(self) -> float:
        """Signed amplitude [g]."""
        return self.a_p / G

    @property
    def duration(self) -> float:
        """Pulse duration ``1/f_p`` [s]."""
        return 1.0 / self.f_p

    def to_dict(self) -> dict[str, Any]:
        """Return a JSON-ready dict (SI units and g)."""
        return {
            "a_p_g": self.a_p_g,
            "a_p_m_s2": self.a_p,
            "f_p_hz": self.f_p,
            "t_start_s": self.t_start,
            "half_durations_s": list(self.half_durations),
            "peaks_g": [p / G for p in self.peaks],
        }


def _lobes(
    acc: NDArray[np.float64], dt: float, t0: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Complete lobes of a record: start and end times [s], sign and peak |a| of each.

    Stretches where the record is exactly zero for a while are gaps (sign 0); a zero that
    only touches (a single sample) does not split a lobe.
    """
    sign = np.sign(acc)
    b = np.flatnonzero(sign[:-1] != sign[1:])  # sign changes between samples b and b + 1
    if b.size < 2:
        empty = np.empty(0)
        return empty, empty, empty, empty
    a0, a1 = acc[b], acc[b + 1]
    t_cross = t0 + dt * (b + a0 / (a0 - a1))  # exact at a zero sample (a0 or a1 = 0)
    start, end = t_cross[:-1], t_cross[1:]
    sgn = sign[b[:-1] + 1]
    peak = np.maximum.reduceat(np.abs(acc), b[:-1] + 1)
    peak[-1] = np.max(np.abs(acc[b[-2] + 1 : b[-1] + 1]))  # reduceat's last runs to the end
    keep = (sgn != 0) | (end > start)
    if not keep.any():
        # One crossing through a single zero sample ([0.1, 0, -0.1]): no lobe at all.
        empty = np.empty(0)
        return empty, empty, empty, empty
    start, end, sgn, peak = start[keep], end[keep], sgn[keep], peak[keep]
    runs = np.flatnonzero(np.concatenate(([True], sgn[1:] != sgn[:-1])))
    run_end = np.concatenate((runs[1:], [sgn.size])) - 1
    return start[runs], end[run_end], sgn[runs], np.maximum.reduceat(peak, runs)


def extract_pulses(
    accel: SampledAccel,
    *,
    f_min: Optional[float] = None,
    f_max: Optional[float] = None,
    n: int = 5,
) -> list[ExtractedPulse]:
    """Return the ``n`` largest one-cycle sine pulses in a record, largest first.

    Parameters
    ----------
    accel : SampledAccel
        The record [m/s²] (``GroundMotion.accel``).
    f_min, f_max : float, optional
        Keep only pulses with ``f_min <= f_p <= f_max`` [Hz].
    n : int
        How many pulses to return (fewer if the record has fewer), >= 1.

    Returns
    -------
    list of ExtractedPulse
        Sorted by ``|a_p|`` descending, then by ``f_p`` ascending. Empty when the record
        has fewer than two complete half-cycles in the range.

    Raises
    ------
    InputError
        ``f_min``/``f_max`` not finite and > 0, or ``f_min > f_max`` (fields ``f_min``,
        ``f_max``); ``n < 1`` (``n``); an ``accel`` that is not a ``SampledAccel``
        (``accel``, saying how to get one).
    """
    accel = require_accel(accel)
    for name, value in (("f_min", f_min), ("f_max", f_max)):
        if value is not None and (
            isinstance(value, bool) or not (math.isfinite(float(value)) and value > 0)
        ):
            raise InputError(f"must be finite and > 0, got {value!r}", name)
    if f_min is not None and f_max is not None and f_min > f_max:
        raise InputError(f"must not exceed f_max ({f_max!r}), got {f_min!r}", "f_min")
    if isinstance(n, bool) or int(n) < 1:
        raise InputError(f"must be >= 1, got {n!r}", "n")
    start, end, sign, peaks = _lobes(accel.acc, accel.dt, accel.t0)
    if peaks.size < 2:
        return []
    d = end - start
    amp = np.minimum(peaks[:-1], peaks[1:])
    f_p = 1.0 / (d[:-1] + d[1:])
    # Two adjacent lobes of opposite sign (a zero gap between them breaks the cycle).
    keep = (sign[:-1] * sign[1:] < 0) & (end[:-1] == start[1:])
    if f_min is not None:
        keep &= f_p >= f_min
    if f_max is not None:
        keep &= f_p <= f_max
    cand = np.flatnonzero(keep)
    order = cand[np.lexsort((f_p[cand], -amp[cand]))][: int(n)]
    return [
        ExtractedPulse(
            a_p=float(sign[k] * amp[k]),
            f_p=float(f_p[k]),
            t_start=float(start[k]),
            half_durations=(float(d[k]), float(d[k + 1])),
            peaks=(float(peaks[k]), float(peaks[k + 1])),
        )
        for k in order
    ]


def largest_pulse(
    accel: SampledAccel, *, f_min: Optional[float] = None, f_max: Optional[float] = None
) -> ExtractedPulse:
    """Return the largest one-cycle sine pulse contained in a record.

    Parameters
    ----------
    accel : SampledAccel
        The record [m/s²].
    f_min, f_max : float, optional
        Frequency range to search [Hz].

    Raises
    ------
    InputError
        The record (in the range) holds no complete cycle (field ``record``), or a bad range.

    Examples
    --------
    >>> t = np.arange(0.0, 3.0, 0.001)
    >>> acc = np.where((t > 1) & (t < 1.5), 2.0 * np.sin(2 * np.pi * 2.0 * (t - 1)), 0.0)
    >>> p = largest_pulse(SampledAccel(acc, 0.001))
    >>> round(p.a_p, 4), round(p.f_p, 4), round(p.t_start, 4)
    (2.0, 2.0, 1.0)
    """
    found = extract_pulses(accel, f_min=f_min, f_max=f_max, n=1)
    if not found:
        where = "" if f_min is None and f_max is None else f" with f_p in [{f_min}, {f_max}] Hz"
        raise InputError(f"holds no complete acceleration cycle{where}", "record")
    return found[0]
