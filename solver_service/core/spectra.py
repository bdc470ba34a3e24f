"""Elastic response spectra of ground-motion records (the ``S_a(T_n)`` of Eq. 28, theory §7.3).

The oscillator is ``ü + 2 zeta omega_n u̇ + omega_n**2 u = -a_g(t)`` (§7.1), at rest at the
first sample, with ``a_g`` linear between samples. It is integrated exactly with the
Nigam–Jennings recurrence, so the only approximation is roundoff.

Notation
--------
T_n, omega_n : natural period [s] and circular frequency ``2 pi / T_n`` [rad/s]
zeta : damping ratio [-], ``0 <= zeta < 1``
a_g : ground acceleration [m/s²], sampled at interval ``dt`` [s]
u : displacement of the oscillator relative to the ground [m]
SD, PSA, PSV : ``max|u|`` [m], ``omega_n**2 SD`` [m/s²], ``omega_n SD`` [m/s]
tau, x : dimensionless time ``omega_n t`` and scaled displacement ``omega_n**2 u`` [m/s²];
    then ``x'' + 2 zeta x' + x = -a_g`` and ``PSA = max|x|``
h, eta : sub-step [s] and ``omega_n h`` [-]
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from shared_schema.errors import InputError

from .excitation import check_finite_samples
from .model import G

__all__ = ["BACKENDS", "Spectrum", "response_spectrum"]

#: Back ends of ``response_spectrum``: numba-compiled if available, or numpy/scipy.
BACKENDS = ("auto", "numba", "numpy")

#: Each sample interval is cut into sub-steps of at most ``T_n / STEPS_PER_PERIOD``
#: (the excitation stays exactly linear on them): ``eta <= 2 pi / 20`` keeps the series
#: below short and gives Newton a start within a twentieth of a period of each peak.
STEPS_PER_PERIOD = 20
#: Taylor terms for the recurrence matrices; ``||eta M||**n / n!`` < 1e-20 at ``eta <= 0.32``.
N_MATRIX_TERMS = 20
#: Taylor terms for the response inside a sub-step when a peak is refined.
N_PEAK_TERMS = 18
#: Newton iterations on ``x'(sigma) = 0`` inside a sub-step (quadratic convergence from a
#: start within ``O(eta**2)``; three reach roundoff).
NEWTON_ITERATIONS = 3


# --- validation ---------------------------------------------------------------------------


def _check_inputs(
    acc: ArrayLike, dt: float, periods: ArrayLike, zeta: float
) -> tuple[NDArray[np.float64], float, NDArray[np.float64], float]:
    try:
        a = np.asarray(acc, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"must be numbers, got {acc!r}", "acc") from exc
    if a.ndim != 1 or a.size < 2:
        raise InputError(f"must be a 1-D array of at least 2 samples, got shape {a.shape}", "acc")
    check_finite_samples(a, "acc")
    if isinstance(dt, bool) or not isinstance(dt, (int, float, np.integer, np.floating)):
        raise InputError(f"must be a number, got {dt!r}", "dt")
    if not (math.isfinite(float(dt)) and dt > 0.0):
        raise InputError(f"must be finite and > 0, got {dt!r}", "dt")
    if isinstance(zeta, bool) or not isinstance(zeta, (int, float, np.integer, np.floating)):
        raise InputError(f"must be a number, got {zeta!r}", "zeta")
    if not 0.0 <= float(zeta) < 1.0:
        raise InputError(f"must be in [0, 1), got {zeta!r}", "zeta")
    try:
        t = np.asarray(periods, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"must be numbers, got {periods!r}", "periods") from exc
    if t.ndim > 1 or t.size == 0:
        raise InputError(f"must be a non-empty 1-D sequence, got shape {t.shape}", "periods")
    t = np.atleast_1d(t)
    bad = np.flatnonzero(~(np.isfinite(t) & (t > 0.0)))
    if bad.size:
        raise InputError(f"T_n must be > 0 and finite, got {t[bad[0]]!r}", "periods")
    return np.ascontiguousarray(a), float(dt), t, float(zeta)


# --- Nigam–Jennings recurrence ------------------------------------------------------------


def _recurrence(eta: NDArray[np.float64], zeta: float) -> NDArray[np.float64]:
    """Nigam–Jennings matrices for sub-steps ``eta = omega_n h``, shape ``(len(eta), 8)``.

    Columns ``A11 A12 A21 A22 Bs1 Bs2 Be1 Be2``: with ``y = (x, x')``,
    ``y(tau + eta) = A y(tau) + Bs a_g(tau) + Be a_g(tau + eta)`` exactly for ``a_g`` linear
    on the step. With ``M = [[0, 1], [-1, -2 zeta]]`` and ``g = (0, -1)``:
    ``A = exp(eta M)``, ``Be = eta phi2(eta M) g``, ``Bs = eta (phi1 - phi2)(eta M) g``,
    ``phi_k(z) = sum z**j / (j + k)!``. The sums are those of Nigam & Jennings (1969) in
    closed form, summed here as Taylor series because ``eta <= 2 pi / STEPS_PER_PERIOD``:
    they converge to roundoff, whereas the closed form loses ``~eps / eta**3`` to
    cancellation at long periods.
    """
    m = np.array([[0.0, 1.0], [-1.0, -2.0 * zeta]])
    g = np.array([0.0, -1.0])
    n = eta.size
    a = np.zeros((n, 2, 2))
    phi1 = np.zeros((n, 2, 2))
    phi2 = np.zeros((n, 2, 2))
    mj = np.eye(2)  # M**j
    pw = np.ones(n)  # eta**j
    fact = [math.factorial(k) for k in range(N_MATRIX_TERMS + 3)]
    for j in range(N_MATRIX_TERMS):
        term = pw[:, None, None] * mj
        a += term / fact[j]
        phi1 += term / fact[j + 1]
        phi2 += term / fact[j + 2]
        mj = mj @ m
        pw = pw * eta
    be = eta[:, None] * (phi2 @ g)
    bs = eta[:, None] * ((phi1 - phi2) @ g)
    return np.ascontiguousarray(np.column_stack([a.reshape(n, 4), bs, be]))


def _series(x0: Any, v0: Any, a0: Any, c: Any, zeta: float, sig: Any) -> tuple[Any, Any, Any]:
    """``(x, x', x'')`` at ``sigma`` into a sub-step, from ``(x0, x'0)`` at its start.

    ``a_g = a0 + c sigma`` on the sub-step (``c`` per unit ``tau``). The Taylor coefficients
    follow from the equation: ``d2 = -a0 - 2 zeta d1 - d0``, ``d3 = -c - 2 zeta d2 - d1``,
    ``d_n = -2 zeta d_{n-1} - d_{n-2}`` for ``n >= 4``. Works on scalars (compiled) and on
    arrays.
    """
    dn = x0
    dn1 = v0
    dn2 = -a0 - 2.0 * zeta * v0 - x0
    dn3 = -c - 2.0 * zeta * dn2 - dn1
    x = 0.0 * x0
    xp = 0.0 * x0
    xpp = 0.0 * x0
    w = 1.0 + 0.0 * sig
    for k in range(N_PEAK_TERMS):
        x = x + dn * w
        xp = xp + dn1 * w
        xpp = xpp + dn2 * w
        dn4 = -2.0 * zeta * dn3 - dn2
        dn, dn1, dn2, dn3 = dn1, dn2, dn3, dn4
        w = w * sig / (k + 1)
    return x, xp, xpp


def _free_peak(x0: Any, v0: Any, zeta: float) -> Any:
    """``max |x(s)|, s >= 0`` of the free vibration ``x'' + 2 zeta x' + x = 0`` from ``(x0, v0)``.

    ``x = e^{-zeta s}(C cos wd s + D sin wd s)`` has ``x' = 0`` every ``pi / wd`` from
    ``s1``; extrema shrink by ``e^{-zeta pi / wd}``, so ``s = 0``, ``s1`` and ``s1 + pi/wd``
    are the only candidates (as in ``amplification._free_peak``). Scalars or arrays.
    """
    wd = np.sqrt(1.0 - zeta * zeta)
    c = x0
    d = (v0 + zeta * x0) / wd
    p = wd * d - zeta * c
    q = wd * c + zeta * d
    s1 = np.mod(np.arctan2(p, q), np.pi) / wd
    s2 = s1 + np.pi / wd
    x1 = np.exp(-zeta * s1) * (c * np.cos(wd * s1) + d * np.sin(wd * s1))
    x2 = np.exp(-zeta * s2) * (c * np.cos(wd * s2) + d * np.sin(wd * s2))
    return np.maximum(np.abs(x0), np.maximum(np.abs(x1), np.abs(x2)))


def _may_exceed(
    x: float,
    xn: float,
    v: float,
    vn: float,
    a0: float,
    a1: float,
    e: float,
    zeta: float,
    best: float,
) -> bool:
    """Whether an extremum inside the sub-step can beat ``best`` (cheap bound, 2x safety).

    At the extremum ``x' = 0``, so the nearer end (at most ``eta/2`` away) is below it by
    ``|x''| (eta/2)**2 / 2`` at most, with ``|x''| <= |a_g| + |x| + 2 zeta |x'|``.
    """
    xm = max(abs(x), abs(xn))
    bound = max(abs(a0), abs(a1)) + xm + 2.0 * zeta * max(abs(v), abs(vn))
    return xm + 2.0 * bound * e * e / 8.0 >= best


def _peaks_scalar(
    acc: NDArray[np.float64],
    coef: NDArray[np.float64],
    n_sub: NDArray[np.int64],
    eta: NDArray[np.float64],
    zeta: float,
    out: NDArray[np.float64],
) -> None:  # pragma: no cover - runs compiled by numba
    """Per period: recurrence over sub-steps, exact peaks inside sub-steps, free vibration."""
    n = acc.size
    for p in range(coef.shape[0]):
        a11, a12, a21, a22 = coef[p, 0], coef[p, 1], coef[p, 2], coef[p, 3]
        bs1, bs2, be1, be2 = coef[p, 4], coef[p, 5], coef[p, 6], coef[p, 7]
        m = n_sub[p]
        e = eta[p]
        x = 0.0
        v = 0.0
        best = 0.0
        for i in range(n - 1):
            lo = acc[i]
            da = (acc[i + 1] - lo) / m
            for k in range(m):
                a0 = lo + k * da
                a1 = lo + (k + 1) * da
                xn = a11 * x + a12 * v + bs1 * a0 + be1 * a1
                vn = a21 * x + a22 * v + bs2 * a0 + be2 * a1
                if abs(xn) > best:
                    best = abs(xn)
                if v * vn < 0.0 and _may_exceed(x, xn, v, vn, a0, a1, e, zeta, best):
                    # An extremum of x inside the sub-step: Newton on x'(sigma) = 0.
                    c = (a1 - a0) / e
                    sig = e * v / (v - vn)
                    for _ in range(NEWTON_ITERATIONS):
                        _, xp, xpp = _series(x, v, a0, c, zeta, sig)
                        if xpp == 0.0:
                            break
                        sig = min(max(sig - xp / xpp, 0.0), e)
                    xm = _series(x, v, a0, c, zeta, sig)[0]
                    if abs(xm) > best:
                        best = abs(xm)
                x = xn
                v = vn
        fp = _free_peak(x, v, zeta)
        out[p] = max(best, fp)


@functools.lru_cache(maxsize=None)
def _compiled() -> Callable[..., None]:
    """Compile ``_peaks_scalar`` with numba (imported lazily; raises ImportError without it)."""
    import numba
    from numba.extending import register_jitable

    register_jitable(_series)
    register_jitable(_free_peak)
    register_jitable(_may_exceed)
    return numba.njit(cache=True, nogil=True)(_peaks_scalar)


def _numba_available() -> bool:
    try:
        _compiled()
    except ImportError:
        return False
    return True


def _powers(eta: float, zeta: float, k: NDArray[np.float64]) -> NDArray[np.float64]:
    """``A**k`` for ``A = exp(eta M)``, shape ``(len(k), 2, 2)``, in closed form."""
    wd = math.sqrt(1.0 - zeta * zeta)
    tau = k * eta
    e = np.exp(-zeta * tau)
    cs = e * np.cos(wd * tau)
    sn = e * np.sin(wd * tau) / wd
    # exp(tau M) = e^{-zeta tau} [cos(wd tau) I + sin(wd tau)/wd (M + zeta I)].
    out = np.empty((k.size, 2, 2))
    out[:, 0, 0] = cs + zeta * sn
    out[:, 0, 1] = sn
    out[:, 1, 0] = -sn
    out[:, 1, 1] = cs - zeta * sn
    return out


def _peaks_numpy(
    acc: NDArray[np.float64], dt: float, omega: NDArray[np.float64], zeta: float
) -> NDArray[np.float64]:
    """Loop over periods, vectorised over time: the recurrence run as a linear filter.

    With ``w_k = y_k - Be a_k`` the recurrence is the state-space filter
    ``w_{k+1} = A w_k + (A Be + Bs) a_k``, ``y_k = w_k + Be a_k``, run by
    ``scipy.signal.lfilter`` from ``w = 0``; the oscillator at rest (``w_0 = -Be a_0``) differs
    by the free response ``-A**k Be a_0``. The direct-form filter loses about
    ``eps / eta**2`` relative accuracy, far below 1e-9 for ``eta > 1e-3``.
    """
    from scipy.signal import lfilter, ss2tf

    n_sub = np.maximum(1, np.ceil(dt * omega * STEPS_PER_PERIOD / (2.0 * np.pi))).astype(int)
    eta = omega * dt / n_sub
    coef = _recurrence(eta, zeta)
    out = np.empty_like(omega)
    grid = np.arange(acc.size) * dt
    for p in range(omega.size):
        m = int(n_sub[p])
        # The record is linear between samples, so the finer samples lie on it exactly.
        fine = acc if m == 1 else np.interp(np.arange((acc.size - 1) * m + 1) * (dt / m), grid, acc)
        if m > 1:
            fine[::m] = acc
        a_mat = coef[p, :4].reshape(2, 2)
        bs, be = coef[p, 4:6], coef[p, 6:8]
        num, den = ss2tf(a_mat, (a_mat @ be + bs)[:, None], np.eye(2), be[:, None])
        x = lfilter(num[0], den, fine)
        v = lfilter(num[1], den, fine)
        free = _powers(float(eta[p]), zeta, np.arange(fine.size, dtype=float)) @ (be * fine[0])
        x -= free[:, 0]
        v -= free[:, 1]
        best = float(np.max(np.abs(x)))
        turn = np.flatnonzero(v[:-1] * v[1:] < 0.0)
        if turn.size:
            e = float(eta[p])
            xs, vs, a0 = x[turn], v[turn], fine[turn]
            c = (fine[turn + 1] - a0) / e
            sig = e * vs / (vs - v[turn + 1])
            for _ in range(NEWTON_ITERATIONS):
                _, xp, xpp = _series(xs, vs, a0, c, zeta, sig)
                step = np.divide(xp, xpp, out=np.zeros_like(xp), where=xpp != 0.0)
                sig = np.clip(sig - step, 0.0, e)
            best = max(best, float(np.max(np.abs(_series(xs, vs, a0, c, zeta, sig)[0]))))
        out[p] = max(best, float(_free_peak(x[-1], v[-1], zeta)))
    return out


def _psa(
    acc: NDArray[np.float64], dt: float, periods: NDArray[np.float64], zeta: float, backend: str
) -> NDArray[np.float64]:
    omega = 2.0 * np.pi / periods
    if backend == "auto":
        backend = "numba" if _numba_available() else "numpy"
    if backend == "numpy":
        return _peaks_numpy(acc, dt, omega, zeta)
    # the note of the kernel's first use (jit loads numba), with the compiled kernel (#38)
    from .jit import first_use

    kernel = _compiled()
    n_sub = np.maximum(1, np.ceil(dt * omega * STEPS_PER_PERIOD / (2.0 * np.pi))).astype(np.int64)
    eta = omega * dt / n_sub
    out = np.empty_like(omega)
    compiled = first_use("spectrum", "numba")
    kernel(acc, _recurrence(eta, zeta), n_sub, eta, zeta, out)
    if compiled is not None:
        compiled()
    return out


# --- public API ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Spectrum:
    """Elastic response spectrum of one record.

    Attributes
    ----------
    periods : (m,) float
        Natural periods ``T_n`` [s].
    zeta : float
        Damping ratio [-].
    sd : (m,) float
        Spectral displacement ``max|u|`` [m].
    psa : (m,) float
        Pseudo-spectral acceleration ``omega_n**2 SD`` [m/s²].
    runtime_s : float
        Wall time of the computation [s].
    """

    periods: NDArray[np.float64]
    zeta: float
    sd: NDArray[np.float64]
    psa: NDArray[np.float64]
    runtime_s: float = 0.0
    _acc: NDArray[np.float64] = field(default_factory=lambda: np.zeros(2), repr=False)
    _dt: float = field(default=1.0, repr=False)
    _backend: str = field(default="auto", repr=False)

    @property
    def psa_g(self) -> NDArray[np.float64]:
        """Pseudo-spectral acceleration [g]."""
        return self.psa / G

    @property
    def psv(self) -> NDArray[np.float64]:
        """Pseudo-spectral velocity ``omega_n SD`` [m/s]."""
        return np.asarray(self.sd * (2.0 * np.pi / self.periods), dtype=np.float64)

    def sa_at(self, T_n: float) -> float:
        """Pseudo-spectral acceleration at ``T_n`` [s], computed exactly (not interpolated).

        Parameters
        ----------
        T_n : float
            Natural period [s], > 0.

        Returns
        -------
        float
            ``PSA(T_n)`` [m/s²] for the same record and damping.
        """
        _, _, t, _ = _check_inputs(self._acc, self._dt, [T_n], self.zeta)
        return float(_psa(self._acc, self._dt, t, self.zeta, self._backend)[0])


def response_spectrum(
    acc: ArrayLike,
    dt: float,
    periods: ArrayLike,
    zeta: float = 0.05,
    *,
    backend: str = "auto",
) -> Spectrum:
    """Exact elastic response spectrum of a record, linear between samples.

    Parameters
    ----------
    acc : (n,) array_like of float
        Ground acceleration [m/s²], ``n >= 2``, all finite.
    dt : float
        Sampling interval [s], > 0.
    periods : (m,) array_like of float
        Natural periods ``T_n`` [s], each > 0.
    zeta : float, optional
        Damping ratio [-], in ``[0, 1)``. Default 0.05.
    backend : {"auto", "numba", "numpy"}, optional
        ``"numba"`` compiles one loop per period (an ImportError without numba);
        ``"numpy"`` loops over periods and runs the recurrence as a linear filter over
        time; ``"auto"`` prefers numba.

    Returns
    -------
    Spectrum
        ``sd`` [m] and ``psa`` [m/s²] at ``periods``.

    Raises
    ------
    InputError
        Bad ``acc``, ``dt``, ``periods`` (``T_n`` must be > 0) or ``zeta``.

    Notes
    -----
    ``x = omega_n**2 u`` obeys ``x'' + 2 zeta x' + x = -a_g`` in ``tau = omega_n t``. Over a
    step where ``a_g`` is linear the Nigam–Jennings recurrence
    ``y_{k+1} = A y_k + Bs a_k + Be a_{k+1}``, ``y = (x, x')``, is exact (Nigam & Jennings
    1969). Each sample interval is split into ``ceil(STEPS_PER_PERIOD dt / T_n)`` equal
    sub-steps (the excitation is still exactly linear on each). Where ``x'`` changes sign in
    a sub-step the extremum is found by Newton on the exact Taylor series of the response,
    so ``SD`` is the true maximum over continuous time, not over the samples.

    After the last sample the ground is at rest (``a_g = 0``) and the oscillator vibrates
    freely for ever; the peak of that free vibration is taken in closed form (its first two
    extrema), so no free-vibration duration has to be chosen and no late peak is missed.

    Examples
    --------
    >>> t = np.arange(0.0, 2.0, 0.01)
    >>> s = response_spectrum(np.sin(2 * np.pi * t), 0.01, [0.5, 1.0, 2.0])
    >>> [round(float(v), 2) for v in s.psa]
    [1.62, 4.67, 0.81]
    """
    if backend not in BACKENDS:
        raise InputError(f"must be one of {list(BACKENDS)}, got {backend!r}", "backend")
    a, step, t, z = _check_inputs(acc, dt, periods, zeta)
    start = time.perf_counter()
    psa = _psa(a, step, t, z, backend)
    runtime = time.perf_counter() - start
    sd = psa * (t / (2.0 * np.pi)) ** 2
    return Spectrum(t, z, sd, psa, runtime, a, step, backend)
