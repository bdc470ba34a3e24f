"""Amplification of ground motion up the structure (docs/theory.md §7).

The exact pulse response spectrum of a damped linear oscillator (§7.1) and the
square-root-sum-of-squares scale factor of Eqs. 27–28 (§7.2–7.3).

Notation
--------
f_n, omega_n : natural frequency of the oscillator [Hz], [rad/s]
zeta : damping ratio [-], ``0 <= zeta < 1``
omega_d : damped natural frequency divided by ``omega_n``, ``sqrt(1 - zeta**2)`` [-]
f_p, omega_p, a_p : pulse frequency [Hz], [rad/s] and amplitude [m/s²] (theory §6.1)
r : frequency ratio ``f_p / f_n`` [-] (also the ratio of circular frequencies)
u : displacement of the oscillator relative to the ground [m]
R : pulse response spectrum, the peak response divided by ``a_p`` [-]
S_a, a_g : spectral (pseudo-)acceleration and peak ground acceleration (same units)
h, h_e : height of the mechanism and effective (modal) height of the structure [m]

The oscillator is ``ü + 2 zeta omega_n u̇ + omega_n**2 u = -a_g(t)`` (§7.1), at rest at
``t = 0`` and driven by one full cycle ``a_g = a_p sin(omega_p t + phase)`` for
``0 <= t <= 1/f_p`` (``phase`` 0 for "sine", π/2 for "cosine", as in ``excitation.Pulse``),
then vibrating freely. In the time ``tau = omega_n t`` and the displacement
``w = omega_n**2 u / a_p`` it reads ``w'' + 2 zeta w' + w = -sin(r tau + phase)``, so the
spectrum depends only on ``r``, ``zeta`` and the shape:

* ``"pseudo"``: ``R = omega_n**2 max|u| / a_p = max|w|`` (the pseudo-acceleration, which is
  the ``S_a`` of Eq. 28);
* ``"relative"``: ``R = max|ü| / a_p = max|w''|`` (the acceleration relative to the
  ground, the "relative acc" row of the §7.1 table; see the ambiguity note there).
"""

from __future__ import annotations

import cmath
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from shared_schema.errors import InputError

from .excitation import PULSE_SHAPES
from .model import check_non_negative, check_number, check_positive

__all__ = [
    "QUANTITIES",
    "RATIO_MIN",
    "effective_height",
    "pulse_response_spectrum",
    "pulse_scale_factor",
    "scale_factor",
    "sdof_pulse_peak",
]

#: Peak quantities of ``pulse_response_spectrum``.
QUANTITIES = ("pseudo", "relative")

#: Grid points per shortest period (pulse or natural) when bracketing extrema in the pulse.
GRID_PER_PERIOD = 64
#: A bracket is refined only if its grid values reach this fraction of the best grid value;
#: a sinusoid sampled 64 times a period peaks at most 0.12 % above its samples.
REFINE_FRACTION = 0.9
#: Absolute root tolerance of brentq on the extremum times, in ``tau = omega_n t`` [-].
XTOL = 1e-14
#: Below this ``|z|`` the exponential ``(e**z - 1)/z`` uses its Taylor series.
EXPREL_SERIES = 1e-4
#: Above this real part of ``(a - mu1) tau`` the divided difference ``f[a, mu1]`` is formed
#: as ``(e^{a tau} - e^{mu1 tau})/(a - mu1)``: ``e**x`` overflows past x = 709.78, and at
#: such ``x`` there is no cancellation to avoid (a pulse of over 700/zeta natural radians).
EXP_DIRECT = 700.0
#: Smallest frequency ratio ``f_p/f_n`` [-] of the closed form: the extrema in the pulse
#: are bracketed on ``GRID_PER_PERIOD / r`` grid points (640,000 here, 0.15 s), so a
#: smaller ratio is refused rather than allowed to take minutes and gigabytes.
RATIO_MIN = 1e-4


def _exprel(z: complex) -> complex:
    """``(e**z - 1)/z``, accurate for small ``|z|`` (1 at ``z = 0``)."""
    if abs(z) < EXPREL_SERIES:
        return 1.0 + z / 2.0 + z * z / 6.0 + z * z * z / 24.0
    # Complex expm1 without cancellation: e^x cos y - 1 = expm1(x) cos y - 2 sin²(y/2).
    x, y = z.real, z.imag
    s = math.sin(0.5 * y)
    em1 = complex(math.expm1(x) * math.cos(y) - 2.0 * s * s, math.exp(x) * math.sin(y))
    return em1 / z


def _exprel_array(z: NDArray[np.complexfloating[Any, Any]]) -> NDArray[np.complex128]:
    """Vectorised ``_exprel``."""
    x, y = z.real, z.imag
    s = np.sin(0.5 * y)
    em1 = (np.expm1(x) * np.cos(y) - 2.0 * s * s) + 1j * (np.exp(x) * np.sin(y))
    small = np.abs(z) < EXPREL_SERIES
    safe = np.where(small, 1.0, z)
    series = 1.0 + z / 2.0 + z * z / 6.0 + z * z * z / 24.0
    return np.asarray(np.where(small, series, em1 / safe), dtype=np.complex128)


class _Oscillator:
    """Closed-form response ``w(tau)`` of ``w'' + 2 zeta w' + w = -sin(r tau + phase)``.

    Starting at rest, the response to the complex forcing ``e^{i r tau}`` is the second
    divided difference of ``x -> e^{x tau}`` at the forcing root ``a = i r`` and the two
    free roots ``mu1,2 = -zeta ± i omega_d``: the particular solution
    ``e^{a tau}/((a-mu1)(a-mu2))`` plus the homogeneous part that cancels its initial state.
    Grouped as ``(f[a, mu1] - f[mu1, mu2]) / (a - mu2)``, with
    ``f[a, mu1] = e^{mu1 tau} tau exprel((a - mu1) tau)``, it stays exact when ``a -> mu1``
    (``zeta = 0`` at resonance, where it becomes the secular solution
    ``tau cos(tau)/2 - sin(tau)/2`` for the sine pulse); ``a - mu2`` and ``mu1 - mu2`` never
    vanish for ``r > 0`` and ``zeta < 1``. The real response is ``w = -Im(e^{i phase} g)``.
    """

    def __init__(self, r: float, zeta: float, phase: float) -> None:
        self.r = r
        self.zeta = zeta
        self.wd = math.sqrt(1.0 - zeta * zeta)
        self.phase = phase
        self.a = 1j * r
        self.mu1 = complex(-zeta, self.wd)
        self.mu2 = complex(-zeta, -self.wd)
        self.rot = cmath.exp(1j * phase)
        self.inv_am2 = 1.0 / (self.a - self.mu2)
        self.T = 2.0 * math.pi / r

    # --- during the pulse ---------------------------------------------------------------

    def state(self, tau: float) -> tuple[float, float]:
        """``(w, w')`` at ``0 <= tau <= T``."""
        e1 = cmath.exp(self.mu1 * tau)
        e2 = cmath.exp(self.mu2 * tau)
        z = (self.a - self.mu1) * tau
        if z.real > EXP_DIRECT:
            fab = (cmath.exp(self.a * tau) - e1) / (self.a - self.mu1)
        else:
            fab = e1 * tau * _exprel(z)
        fbc = (e1 - e2) / (self.mu1 - self.mu2)
        g = (fab - fbc) * self.inv_am2
        # d/dtau of the divided difference is the divided difference of x e^{x tau}.
        dg = ((self.a * fab + e1) - (self.mu1 * fbc + e2)) * self.inv_am2
        return -(self.rot * g).imag, -(self.rot * dg).imag

    def state_array(self, tau: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        """``(w, w')`` on an array of times in ``[0, T]``."""
        e1 = np.exp(self.mu1 * tau)
        e2 = np.exp(self.mu2 * tau)
        z = (self.a - self.mu1) * tau
        direct = z.real > EXP_DIRECT
        fab = e1 * tau * _exprel_array(np.where(direct, 0.0, z))
        if direct.any():
            fab[direct] = (np.exp(self.a * tau[direct]) - e1[direct]) / (self.a - self.mu1)
        fbc = (e1 - e2) / (self.mu1 - self.mu2)
        g = (fab - fbc) * self.inv_am2
        dg = ((self.a * fab + e1) - (self.mu1 * fbc + e2)) * self.inv_am2
        return -(self.rot * g).imag, -(self.rot * dg).imag

    def quantity(self, tau: float, kind: str) -> tuple[float, float]:
        """Return the peak quantity (``w`` or ``w''``) and its time derivative at ``tau``."""
        w, v = self.state(tau)
        if kind == "pseudo":
            return w, v
        arg = self.r * tau + self.phase
        acc = -math.sin(arg) - 2.0 * self.zeta * v - w
        jerk = -self.r * math.cos(arg) - 2.0 * self.zeta * acc - v
        return acc, jerk

    def quantity_array(
        self, tau: NDArray[np.float64], kind: str
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Vectorised ``quantity``."""
        w, v = self.state_array(tau)
        if kind == "pseudo":
            return w, v
        arg = self.r * tau + self.phase
        acc = -np.sin(arg) - 2.0 * self.zeta * v - w
        jerk = -self.r * np.cos(arg) - 2.0 * self.zeta * acc - v
        return acc, jerk

    # --- peaks ---------------------------------------------------------------------------

    def peak_in_pulse(self, kind: str) -> float:
        """``max |q|`` over ``0 <= tau <= T`` (one-sided limits at the ends)."""
        period = min(self.T, 2.0 * math.pi)
        n = max(math.ceil(GRID_PER_PERIOD * self.T / period), 2) + 1
        tau = np.linspace(0.0, self.T, n)
        q, dq = self.quantity_array(tau, kind)
        aq = np.abs(q)
        best = float(aq.max())
        # Extrema in the interior are sign changes of dq; refine only those that can matter.
        idx = np.flatnonzero(np.signbit(dq[:-1]) != np.signbit(dq[1:]))
        if idx.size:
            reach = np.maximum(aq[idx], aq[idx + 1])
            idx = idx[reach >= REFINE_FRACTION * best]

        def dq_scalar(t: float) -> float:
            return self.quantity(t, kind)[1]

        for i in idx:
            lo, hi = float(tau[i]), float(tau[i + 1])
            if dq[i] == 0.0:
                t_star = lo
            elif dq[i + 1] == 0.0:
                t_star = hi
            else:
                # scipy.optimize is loaded where a peak needs it, not with the module (#38)
                from scipy.optimize import brentq

                t_star = float(brentq(dq_scalar, lo, hi, xtol=XTOL, rtol=4 * np.finfo(float).eps))
            best = max(best, abs(self.quantity(t_star, kind)[0]))
        return best

    def peak_after_pulse(self, kind: str) -> float:
        """``max |q|`` over ``tau >= T``: the free damped vibration from the end state."""
        w, v = self.state(self.T)
        if kind == "pseudo":
            x0, dx0 = w, v
        else:
            # a_g = 0 after the pulse: w'' = -2 zeta w' - w, w''' = -2 zeta w'' - w'.
            x0 = -2.0 * self.zeta * v - w
            dx0 = -2.0 * self.zeta * x0 - v
        return _free_peak(x0, dx0, self.zeta, self.wd)


def _free_peak(x0: float, dx0: float, zeta: float, wd: float) -> float:
    """Largest ``|x(s)|``, ``s >= 0``, of ``x = e^{-zeta s}(C cos wd s + D sin wd s)``.

    Notes
    -----
    ``x' = 0`` where ``tan(wd s) = P/Q`` with ``P = wd D - zeta C`` and ``Q = wd C + zeta D``,
    i.e. every ``pi/wd`` from the first root ``s1``; successive extrema shrink by
    ``e^{-zeta pi/wd}``, so the candidates are ``s = 0`` and the first two roots.
    """
    c = x0
    d = (dx0 + zeta * x0) / wd
    p = wd * d - zeta * c
    q = wd * c + zeta * d
    best = abs(x0)
    if p == 0.0 and q == 0.0:
        return best
    s1 = (math.atan2(p, q) % math.pi) / wd
    for s in (s1, s1 + math.pi / wd):
        x = math.exp(-zeta * s) * (c * math.cos(wd * s) + d * math.sin(wd * s))
        best = max(best, abs(x))
    return best


# --- validation ---------------------------------------------------------------------------


def _check_options(zeta: object, quantity: object, shape: object) -> float:
    z = check_number(zeta, "zeta")
    if not 0.0 <= z < 1.0:
        raise InputError(f"must be in [0, 1), got {zeta!r}", "zeta")
    if quantity not in QUANTITIES:
        raise InputError(f"must be one of {list(QUANTITIES)}, got {quantity!r}", "quantity")
    if shape not in PULSE_SHAPES:
        raise InputError(f"must be one of {sorted(PULSE_SHAPES)}, got {shape!r}", "shape")
    return z


def _positive_array(value: ArrayLike, name: str) -> NDArray[np.float64]:
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"must be numbers, got {value!r}", name) from exc
    bad = ~(np.isfinite(arr) & (arr > 0.0))
    if bad.any():
        first = arr.ravel()[int(np.flatnonzero(bad.ravel())[0])]
        raise InputError(f"must be finite and > 0, got {first!r}", name)
    return arr


# --- public API ---------------------------------------------------------------------------


def pulse_response_spectrum(
    ratio: ArrayLike,
    *,
    zeta: float = 0.05,
    quantity: str = "pseudo",
    shape: str = "sine",
) -> NDArray[np.float64]:
    """Exact pulse response spectrum ``R(f_p/f_n)`` of a damped linear oscillator.

    Parameters
    ----------
    ratio : array_like of float
        Frequency ratios ``r = f_p / f_n`` [-], each finite and > 0.
    zeta : float, optional
        Damping ratio [-], in ``[0, 1)``. Default 0.05.
    quantity : {"pseudo", "relative"}, optional
        ``"pseudo"``: ``omega_n**2 max|u| / a_p``; ``"relative"``: ``max|ü| / a_p`` with ``ü``
        the acceleration relative to the ground.
    shape : {"sine", "cosine"}, optional
        Pulse shape, as in ``excitation.Pulse``.

    Returns
    -------
    R : ndarray of float, shape of ``ratio``
        Peak response over all ``t >= 0`` divided by ``a_p`` [-].

    Raises
    ------
    InputError
        If a ratio is not finite and > 0, or below ``RATIO_MIN`` (field ``ratio``), or
        ``zeta``, ``quantity`` or ``shape`` is invalid.

    Notes
    -----
    theory §7.1. The response is evaluated in closed form: during the pulse the forced
    damped harmonic response (particular solution plus the homogeneous part matching rest
    at ``t = 0``), grouped so that the undamped resonant case ``zeta = 0, r = 1`` is the exact
    secular limit; after the pulse the free damped vibration from the end state. Interior
    extrema are bracketed on a grid of ``GRID_PER_PERIOD`` points per shortest period and
    refined with ``brentq``; the free-vibration extrema are at analytic times.

    Examples
    --------
    >>> r = pulse_response_spectrum([0.5, 1.0, 2.0])
    >>> [round(float(x), 2) for x in r]
    [1.62, 2.7, 1.15]
    """
    z = _check_options(zeta, quantity, shape)
    r = _positive_array(ratio, "ratio")
    phase = PULSE_SHAPES[shape]
    out = np.empty(r.shape, dtype=np.float64)
    flat = out.reshape(-1)
    if r.size and float(r.min()) < RATIO_MIN:
        raise InputError(
            f"must be >= {RATIO_MIN:g} (a pulse at most {1 / RATIO_MIN:g} times longer than "
            f"the natural period), got {float(r.min())!r}",
            "ratio",
        )
    for k, rk in enumerate(r.reshape(-1)):
        osc = _Oscillator(float(rk), z, phase)
        flat[k] = max(osc.peak_in_pulse(quantity), osc.peak_after_pulse(quantity))
    return out


def sdof_pulse_peak(
    f_n: float,
    f_p: float,
    a_p: float,
    *,
    zeta: float = 0.05,
    quantity: str = "pseudo",
    shape: str = "sine",
) -> float:
    """Peak response [m/s²] of an oscillator of frequency ``f_n`` to one pulse.

    Parameters
    ----------
    f_n : float
        Natural frequency [Hz], > 0.
    f_p : float
        Pulse frequency [Hz], > 0.
    a_p : float
        Pulse amplitude [m/s²]; its sign does not matter.
    zeta, quantity, shape
        As in ``pulse_response_spectrum``.

    Returns
    -------
    float
        ``omega_n**2 max|u|`` (``"pseudo"``) or ``max|ü|`` (``"relative"``) [m/s²].

    Examples
    --------
    >>> round(sdof_pulse_peak(2.0, 2.0, 1.5), 3)
    4.05
    """
    fn = check_positive(f_n, "f_n")
    fp = check_positive(f_p, "f_p")
    ap = check_number(a_p, "a_p")
    r = pulse_response_spectrum(fp / fn, zeta=zeta, quantity=quantity, shape=shape)
    return float(r) * abs(ap)


def pulse_scale_factor(
    f_p: ArrayLike,
    *,
    f_n: float,
    h: float,
    h_e: float,
    zeta: float = 0.05,
    quantity: str = "pseudo",
    shape: str = "sine",
) -> NDArray[np.float64]:
    """Scale factor ``SF(f_p)`` of a pulse at height ``h`` (Eq. 28 with the §7.1 spectrum).

    Parameters
    ----------
    f_p : array_like of float
        Pulse frequencies [Hz], each finite and > 0.
    f_n : float
        Natural frequency of the structure [Hz], > 0.
    h : float
        Height of the mechanism above the base [m], >= 0.
    h_e : float
        Effective (modal) height of the structure [m], > 0.
    zeta, quantity, shape
        As in ``pulse_response_spectrum``.

    Returns
    -------
    SF : ndarray of float, shape of ``f_p``
        Ratio of the local pulse amplitude to the ground amplitude [-], >= 1.

    Notes
    -----
    theory §7.3: ``SF(f_p) = sqrt(1 + (R(f_p/f_n) h/h_e)**2)``; the local pulse amplitude is
    ``SF(f_p) a_p``.

    Examples
    --------
    >>> float(pulse_scale_factor(1.0, f_n=2.0, h=0.0, h_e=3.0))
    1.0
    """
    fn = check_positive(f_n, "f_n")
    hh = check_non_negative(h, "h")
    he = check_positive(h_e, "h_e")
    fp = _positive_array(f_p, "f_p")
    if fp.size and float(fp.min()) / fn < RATIO_MIN:
        raise InputError(
            f"f_p/f_n = {float(fp.min()) / fn:g} is below {RATIO_MIN:g}: the exact scale factor "
            f"of a pulse over {1 / RATIO_MIN:g} times longer than the structure's period "
            f"(f_n = {fn:g} Hz) is not computed; raise f_min, or use the library (whose table "
            "takes its end value there)",
            "f_p",
        )
    spec = pulse_response_spectrum(fp / fn, zeta=zeta, quantity=quantity, shape=shape)
    return np.asarray(np.hypot(1.0, spec * (hh / he)), dtype=np.float64)


def scale_factor(sa_g: float, pga_g: float, h: float, h_e: float) -> float:
    """Scale factor of a time history at height ``h`` (Eq. 28).

    Parameters
    ----------
    sa_g : float
        Spectral acceleration ``S_a(T_n)`` [g], >= 0 (any unit shared with ``pga_g``).
    pga_g : float
        Peak ground acceleration ``a_g`` [g], > 0.
    h : float
        Height of the mechanism above the base [m], >= 0.
    h_e : float
        Effective (modal) height of the structure [m], > 0.

    Returns
    -------
    float
        ``SF = sqrt(1 + (S_a/a_g · h/h_e)**2)`` [-].

    Notes
    -----
    theory Eq. 28 (§7.3): square-root-sum-of-squares of the ground acceleration and the
    response acceleration scaled linearly from ``h_e`` to ``h``.

    Examples
    --------
    >>> round(scale_factor(0.19, 0.155, 4.60, 4.54), 3)
    1.595
    """
    sa = check_non_negative(sa_g, "sa_g")
    ag = check_positive(pga_g, "pga_g")
    hh = check_non_negative(h, "h")
    he = check_positive(h_e, "h_e")
    return math.hypot(1.0, sa / ag * hh / he)


def effective_height(masses: ArrayLike, heights: ArrayLike) -> float:
    """Effective (modal) height of a linear mode shape, ``sum(m h²) / sum(m h)``.

    Parameters
    ----------
    masses : (n,) array_like of float
        Lumped masses [kg], each finite and >= 0.
    heights : (n,) array_like of float
        Their heights above the base [m], each finite and >= 0.

    Returns
    -------
    float
        ``h_e`` [m].

    Notes
    -----
    theory §7.2. A uniform cantilever gives ``2H/3``; a dominant tip mass gives ``H``.

    Examples
    --------
    >>> effective_height([1.0, 1.0], [1.0, 2.0])
    1.6666666666666667
    """
    m = _array_1d(masses, "masses")
    z = _array_1d(heights, "heights")
    if m.shape != z.shape:
        raise InputError(f"must have the same length as masses ({m.size}), got {z.size}", "heights")
    moment = float(np.sum(m * z))
    if moment <= 0.0:
        raise InputError("need at least one positive mass above the base", "masses")
    return float(np.sum(m * z * z)) / moment


def _array_1d(value: ArrayLike, name: str) -> NDArray[np.float64]:
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"must be numbers, got {value!r}", name) from exc
    if arr.ndim != 1 or arr.size == 0:
        raise InputError(f"must be a non-empty 1-D sequence, got shape {arr.shape}", name)
    bad = ~(np.isfinite(arr) & (arr >= 0.0))
    if bad.any():
        raise InputError(f"must be finite and >= 0, got {arr[np.flatnonzero(bad)[0]]!r}", name)
    return arr
