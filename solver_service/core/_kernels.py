"""Scalar kernels of the exact rocking integrator (compiled by numba when available).

The excitation is a sequence of *cells*. In each cell the ground acceleration is either
linear in time (kind 0: ``a = c0 + c1 (t - t_start)``, a sampled record) or a quarter
period of a sinusoid (kind 1: ``a = c0 sin(c1 t + c2)``, a pulse). Both are monotone in
the cell. Between events the linearised equation (model.py)::

    x'' = p_s**2 (x - s - q(t)),     q = scale * a / (G lam_s)

is solved in closed form from an anchor state (theory §10: written about the anchor, so
no O(lam) terms cancel while the body chatters). Closed-form segments are at most
``MAX_PH / p`` long.

Events are found exactly. On a stretch where ``q'`` keeps one sign, ``w = x'`` obeys
``w'' - p**2 w = -p**2 q'``, so (maximum principle) ``w`` cannot have an interior positive
maximum when ``q' <= 0`` (or negative minimum when ``q' >= 0``). Hence ``x'`` has at most
two zeros per cell, and their presence is decided from the signs of ``x'`` and ``x''`` at
the cell ends, plus one bracketed search for a zero of ``x''`` in the ambiguous case.
``x`` is then monotone on at most three pieces, and every impact (``x = 0``), turning
point and ``|x| = 1`` crossing is bracketed and solved by safeguarded Newton iteration
to machine precision. No grazing impact is missed.

The same source runs uncompiled (``exact.kernels("python")``) as the pure-numpy path.
"""

import math
from typing import Any

import numpy as np

_NO_JIT = globals().get("_NO_JIT", False)

try:  # numba is optional: without it the same code runs as plain Python.
    if _NO_JIT:
        raise ImportError
    import numba as _numba

    def _jit(fn):
        return _numba.njit(cache=True, nogil=True)(fn)

    def _jit_parallel(fn):
        return _numba.njit(cache=True, nogil=True, parallel=True)(fn)

    _prange: Any = _numba.prange
    JIT = True
except ImportError:  # pragma: no cover - exercised through the python backend

    def _jit(fn):
        return fn

    _jit_parallel = _jit
    _prange = range
    JIT = False

#: Standard gravity [m/s²] (same value as model.G).
G = 9.80665
#: Unit roundoff of float64.
EPS = 2.220446049250313e-16
#: Longest closed-form segment, as p*h; bounds cosh/sinh growth inside one evaluation.
MAX_PH = 1.0
#: Below this p*tau, sinh(u) - u is evaluated by its Taylor series (no cancellation).
SERIES_U = 0.5
#: Iteration cap of the safeguarded Newton root finder (bisection alone needs < 1100).
ROOT_MAXITER = 200
#: Safety factor applied to the propagated rounding-error standard deviation.
ERR_SAFETY = 10.0
#: Cap on the standard deviation of the propagated error of x (and of x'/p): first-order
#: propagation overstates the error where it breaks down (near-grazing impacts, long
#: chattering), and no perturbation moves the state further than the span of the motion.
ERR_CAP = 2.0

# Layout of the output vector of one simulation.
OUT_STATUS = 0
OUT_PEAK = 1
OUT_T_PEAK = 2
OUT_T_EXCEED = 3
OUT_COLLAPSED = 4
OUT_T_COLLAPSE = 5
OUT_N_IMPACTS = 6
OUT_N_STEPS = 7
OUT_ERROR = 8
OUT_N_TRACE = 9
OUT_TRACE_FULL = 10
OUT_N_UPLIFTS = 11
OUT_N_RESTS = 12
OUT_N_LOG = 13
NOUT = 14
#: Rows of the optional impact log (``simulate_cells_logged``): time [s], side before the
#: impact, ``x'`` arriving and ``x'`` leaving (0 when the impact ends in rest) [1/s].
LOG_ROWS = ("t", "side", "v_in", "v_out")
#: Rows of the packed cell array.
CELL_ROWS = ("kind", "c0", "c1", "c2", "t_start", "t_end", "amax_after")

REST = 0
FLIGHT = 1


@_jit
def _sinh_minus(u):
    """Return ``sinh(u) - u`` without cancellation for small ``u``."""
    if abs(u) < SERIES_U:
        u2 = u * u
        # Taylor series to u**19: truncation below 1e-17 relative for |u| < 0.5.
        poly = 1.0 / 121645100408832000.0
        poly = 1.0 / 355687428096000.0 + u2 * poly
        poly = 1.0 / 1307674368000.0 + u2 * poly
        poly = 1.0 / 6227020800.0 + u2 * poly
        poly = 1.0 / 39916800.0 + u2 * poly
        poly = 1.0 / 362880.0 + u2 * poly
        poly = 1.0 / 5040.0 + u2 * poly
        poly = 1.0 / 120.0 + u2 * poly
        poly = 1.0 / 6.0 + u2 * poly
        return u * u2 * poly
    return math.sinh(u) - u


@_jit
def _accel(kind, c0, c1, c2, cs, t):
    """Ground acceleration of a cell and its rate at absolute time ``t``."""
    if kind == 0:
        return c0 + c1 * (t - cs), c1
    return c0 * math.sin(c1 * t + c2), c0 * c1 * math.cos(c1 * t + c2)


@_jit
def _state(kind, c0, c1, c2, cs, ks, s, p, ta, xa, va, tau):
    """State ``(x, x', x'', x''')`` at ``ta + tau`` from the anchor ``(ta, xa, va)`` on side ``s``.

    ``ks = scale / (G lam_s)`` turns the ground acceleration into ``q``.
    """
    u = p * tau
    sh = math.sinh(u)
    h = math.sinh(0.5 * u)
    chm1 = 2.0 * h * h  # cosh(u) - 1 without cancellation
    if kind == 0:
        q0 = ks * (c0 + c1 * (ta - cs))
        q1 = ks * c1
        a = xa - s - q0
        x = xa + a * chm1 + va * sh / p - q1 * _sinh_minus(u) / p
        v = va + (va - q1) * chm1 + a * p * sh
        q = q0 + q1 * tau
        qd = q1
    else:
        kk = ks * c0
        w = c1
        th = w * ta + c2
        kap = p * p * kk / (p * p + w * w)
        y = xa - s - kap * math.sin(th)
        yp = va - kap * w * math.cos(th)
        half = th + 0.5 * w * tau
        sw = math.sin(0.5 * w * tau)
        x = xa + 2.0 * kap * math.cos(half) * sw + y * chm1 + yp * sh / p
        v = va - 2.0 * kap * w * math.sin(half) * sw + y * p * sh + yp * chm1
        q = kk * math.sin(th + w * tau)
        qd = kk * w * math.cos(th + w * tau)
    acc = p * p * (x - s - q)
    jerk = p * p * (v - qd)
    return x, v, acc, jerk


@_jit
def _sgn(z):
    if z > 0.0:
        return 1.0
    if z < 0.0:
        return -1.0
    return 0.0


@_jit
def _root(which, target, kind, c0, c1, c2, cs, ks, s, p, ta, xa, va, lo, hi, sig_lo, f_lo, f_hi):
    """Zero of component ``which`` (0: x - target, 1: x', 2: x'') in ``[lo, hi]``.

    ``sig_lo`` is the sign of the function just right of ``lo``; the function is assumed to
    change sign once in the bracket. ``f_lo``, ``f_hi`` are its values at the ends when known
    (NaN otherwise) and give a regula-falsi start. Safeguarded Halley iteration (Newton for
    ``x''``): a step is taken when it stays inside the bracket and shrinks fast enough,
    otherwise bisection.
    Returns the root (time offset from ``ta``).
    """
    t = 0.5 * (lo + hi)
    if f_lo - f_hi != 0.0 and math.isfinite(f_lo - f_hi):
        t = lo + (hi - lo) * min(max(f_lo / (f_lo - f_hi), 0.01), 0.99)
    width = hi - lo
    # Absolute time cannot be resolved finer than a few ulps of ta + t.
    tol = 4.0 * EPS * (abs(ta) + abs(hi))
    for _ in range(ROOT_MAXITER):
        x, v, acc, jerk = _state(kind, c0, c1, c2, cs, ks, s, p, ta, xa, va, t)
        fpp = 0.0
        if which == 0:
            f = x - target
            fp = v
            fpp = acc
        elif which == 1:
            f = v
            fp = acc
            fpp = jerk
        else:
            f = acc
            fp = jerk
        if f == 0.0:
            return t
        if _sgn(f) == sig_lo:
            lo = t
        else:
            hi = t
        if hi - lo <= tol:
            return t
        # Halley's step where the second derivative is at hand, else Newton's.
        den = 2.0 * fp * fp - f * fpp
        tn = t - 2.0 * f * fp / den if den != 0.0 else lo - 1.0
        if lo < tn < hi and abs(tn - t) < 0.5 * width:
            width = abs(tn - t)
            if width <= tol:
                return tn
            t = tn
        else:
            width = hi - lo
            t = 0.5 * (lo + hi)
    return t


@_jit
def _side_sign_right(v, acc, jerk):
    """Sign of x' just after a point, from x', x'' and x''' there."""
    if v != 0.0:
        return _sgn(v)
    if acc != 0.0:
        return _sgn(acc)
    return _sgn(jerk)


@_jit
def _side_sign_left(v, acc, jerk):
    """Sign of x' just before a point, from x', x'' and x''' there."""
    if v != 0.0:
        return _sgn(v)
    if acc != 0.0:
        return -_sgn(acc)
    return _sgn(jerk)


@_jit
def _velocity_zeros(kind, c0, c1, c2, cs, ks, s, p, ta, xa, va, aa, ja, big_h, sig_a, qd_sign):
    """Interior zeros of x' on ``(0, big_h)``: returns ``(n, z1, z2, x(big_h), x'(big_h))``.

    ``sig_a`` is the sign of x' just after 0; ``qd_sign`` the constant sign of q' on the
    stretch (0 when q is constant). See the module docstring for the argument.
    """
    xb, vb, ab, jb = _state(kind, c0, c1, c2, cs, ks, s, p, ta, xa, va, big_h)
    sig_b = _side_sign_left(vb, ab, jb)
    n = 0
    z1 = 0.0
    z2 = 0.0
    # Same sign at both ends: zero or two zeros. Two need a hump of the sign the maximum
    # principle allows: negative when q' <= 0, positive when q' >= 0.
    hump = -1.0 if qd_sign <= 0.0 else 1.0
    if sig_a == 0.0 or sig_b == 0.0:
        n = 0
    elif sig_a != sig_b:
        n = 1
        z1 = _root(1, 0.0, kind, c0, c1, c2, cs, ks, s, p, ta, xa, va, 0.0, big_h, sig_a, va, vb)
    elif sig_a != hump and _sgn(aa) == hump and _sgn(ab) == -hump:
        # x' has sign -hump at both ends and x'' turns from hump to -hump: it may dip.
        m = _root(2, 0.0, kind, c0, c1, c2, cs, ks, s, p, ta, xa, va, 0.0, big_h, hump, aa, ab)
        vm = _state(kind, c0, c1, c2, cs, ks, s, p, ta, xa, va, m)[1]
        if _sgn(vm) == hump:
            n = 2
            z1 = _root(1, 0.0, kind, c0, c1, c2, cs, ks, s, p, ta, xa, va, 0.0, m, sig_a, va, vm)
            z2 = _root(1, 0.0, kind, c0, c1, c2, cs, ks, s, p, ta, xa, va, m, big_h, hump, vm, vb)
    return n, z1, z2, xb, vb


@_jit
def _free_time_to_zero(y, w, p):
    """Time for free motion ``y'' = p**2 y`` to go from ``(y, w)`` to ``y = -1``."""
    wp = w / p
    e = wp * wp - y * y
    if e < 0.0:
        yt = -math.sqrt(-e)
        since_turn = math.acosh(min(max(y / yt, 1.0), 1e300)) / p
        if w > 0.0:
            since_turn = -since_turn
        return math.acosh(max(-1.0 / yt, 1.0)) / p - since_turn
    c = math.sqrt(e)
    if c == 0.0:
        return math.inf
    return max(math.asinh(1.0 / c) - math.asinh(-y / c), 0.0) / p


@_jit
def _free_rocking(s, x, v, p_s, p_o, r_so, eta, one_sided, v_rest):
    """Free-rocking outcome; documented in ``freemotion.free_rocking``, which wraps it."""
    y = s * x - 1.0
    w = s * v
    if y + w / p_s > 0.0:
        if y >= 0.0:
            return True, 0.0, 1.0, 0.0
        return True, math.atanh(min(-y * p_s / w, 1.0)) / p_s, 1.0, 0.0
    peak = s * x
    dt_peak = 0.0
    e = (w / p_s) ** 2 - y * y
    if w > 0.0:
        peak = 1.0 - math.sqrt(max(-e, 0.0))
        dt_peak = math.atanh(min(-w / (p_s * y), 1.0)) / p_s
    t_ret = _free_time_to_zero(y, w, p_s)
    w0 = p_s * math.sqrt(max(e + 1.0, 0.0))
    if one_sided:
        w1 = -eta * w0
        p1 = p_s
    else:
        w1 = eta * r_so * w0
        p1 = p_o
    if w1 < v_rest or w1 <= 0.0 or not math.isfinite(t_ret):
        return False, math.nan, peak, dt_peak
    qq = w1 / p1
    if qq > 1.0:
        return True, t_ret + math.atanh(1.0 / qq) / p1, 1.0, 0.0
    peak2 = 1.0 - math.sqrt(max(1.0 - qq * qq, 0.0))
    if peak2 > peak:
        return False, math.nan, peak2, t_ret + math.atanh(qq) / p1
    return False, math.nan, peak, dt_peak


@_jit
def _uplift_time(kind, c0, c1, c2, cs, ks, s, t, tb):
    """First time in ``[t, tb]`` at which the drive ``g = -s ks a`` exceeds 1, or ``-1``.

    The returned time is the bracket end at which ``g >= 1`` holds in floating point, so the
    closed form started there moves outward (theory §10, sub-resolution uplift).
    """
    a_t, _ad_t = _accel(kind, c0, c1, c2, cs, t)
    g_t = -s * ks * a_t
    if g_t > 1.0:
        return t
    a_b, _ad_b = _accel(kind, c0, c1, c2, cs, tb)
    g_b = -s * ks * a_b
    if g_b <= 1.0:
        return -1.0
    # g is monotone in the cell: safeguarded Newton from the regula-falsi point, then the
    # first representable time at which g >= 1 holds.
    lo = t
    hi = tb
    x = lo + (hi - lo) * min(max((1.0 - g_t) / (g_b - g_t), 0.0), 1.0)
    tol = 4.0 * EPS * (abs(t) + abs(tb))
    for _ in range(ROOT_MAXITER):
        a_x, ad_x = _accel(kind, c0, c1, c2, cs, x)
        g = -s * ks * a_x
        if g >= 1.0:
            hi = x
        else:
            lo = x
        if hi - lo <= tol:
            break
        gd = -s * ks * ad_x
        xn = x - (g - 1.0) / gd if gd != 0.0 else lo - 1.0
        if not lo < xn < hi:
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= tol:
            x = xn
            break
        x = xn
    # Step up from the converged point to the first time where g >= 1 (bounded by hi).
    for _ in range(8):
        if x >= hi or -s * ks * _accel(kind, c0, c1, c2, cs, x)[0] >= 1.0:
            break
        x = min(x + tol, hi)
    return min(x, hi)


@_jit
def _propagate_cov(pxx, pxv, pvv, p, tau, ex, ev):
    """Covariance of the rounding error carried through a homogeneous flight of ``tau``."""
    u = p * tau
    ch = math.cosh(u)
    sh = math.sinh(u)
    a = ch
    b = sh / p
    c = p * sh
    d = ch
    nxx = a * a * pxx + 2.0 * a * b * pxv + b * b * pvv + ex * ex
    nxv = a * c * pxx + (a * d + b * c) * pxv + b * d * pvv
    nvv = c * c * pxx + 2.0 * c * d * pxv + d * d * pvv + ev * ev
    return nxx, nxv, nvv


@_jit
def _record(trace_t, trace_x, ntr, t, x):
    """Append ``(t, x)`` to the time-series buffers if there is room; return the new length."""
    if ntr < trace_t.shape[0]:
        trace_t[ntr] = t
        trace_x[ntr] = x
        return ntr + 1
    return ntr


@_jit
def _cap_cov(pxx, pxv, pvv, p):
    """Clip the error covariance to the physical span of the motion (``ERR_CAP``)."""
    xcap = ERR_CAP * ERR_CAP
    vcap = xcap * p * p
    if not pxx <= xcap:  # also catches NaN
        pxx = xcap
    if not pvv <= vcap:
        pvv = vcap
    lim = math.sqrt(pxx * pvv)
    if not abs(pxv) <= lim:
        pxv = lim if pxv > 0.0 else -lim
    return pxx, pxv, pvv


@_jit
def _simulate(
    kind,
    c0,
    c1,
    c2,
    tstart,
    tend,
    amax_after,
    scale,
    p_pos,
    p_neg,
    lam_pos,
    lam_neg,
    phiov_pos,
    phiov_neg,
    eta,
    one_sided,
    x0,
    v_rest_rel,
    max_impacts,
    trace_t,
    trace_x,
    log,
):
    """Integrate one mechanism through a cell sequence (unpacked arguments; see ``simulate_cells``).

    Parameters
    ----------
    kind, c0, c1, c2, tstart, tend, amax_after : (n,) arrays
        Cells (see module docstring); ``amax_after[i]`` bounds ``|a|`` from ``tstart[i]`` on
        [m/s²].
    scale : float
        Factor on the ground acceleration [-].
    p_pos, p_neg, lam_pos, lam_neg, phiov_pos, phiov_neg : float
        Side constants [rad/s], [-], [rad].
    eta : float
        Coefficient of restitution [-].
    one_sided : bool
        One-sided rocking.
    x0 : float
        Initial normalised rotation, released from rest [-].
    v_rest_rel : float
        Rest rule: an impact whose outgoing speed is below ``v_rest_rel * p`` ends in rest.
    max_impacts : int
        Impact cap.
    trace_t, trace_x : (m,) arrays
        Output buffers for the time series (size 0: no trace).
    log : (4, k) array
        Output buffer for the impact log (rows ``LOG_ROWS``; ``k = 0``: no log). Every
        impact is logged, also those below the rest speed that end in rest.

    Returns
    -------
    (NOUT,) float array, indexed by the ``OUT_*`` constants.
    """
    out = np.zeros(NOUT)
    ntr_cap = trace_t.shape[0]
    ntr = 0
    nlog_cap = log.shape[1]
    nlog = 0
    n_up = 0
    n_rest = 0
    n = kind.shape[0]
    p_max = max(p_pos, p_neg)
    ks_pos = scale / (G * lam_pos)
    ks_neg = scale / (G * lam_neg)

    mode = REST
    s = 0.0
    x = 0.0
    v = 0.0
    t = tstart[0]
    if x0 != 0.0:
        mode = FLIGHT
        s = _sgn(x0)
        x = x0
    peak = abs(x0)
    t_peak = t
    var_peak = 0.0
    t_exceed = math.nan
    t_cross = math.nan  # when |x| reached 1 on the current excursion
    if abs(x0) >= 1.0:
        t_exceed = t
        t_cross = t
    collapsed = False
    t_collapse = math.nan
    n_imp = 0
    n_steps = 0
    status = 0
    pxx = 0.0
    pxv = 0.0
    pvv = 0.0
    hold_until = -math.inf
    uplift_t = math.nan
    done = False
    ntr = _record(trace_t, trace_x, ntr, t, x)

    for i in range(n):
        if done:
            break
        k = kind[i]
        a0 = c0[i]
        a1 = c1[i]
        a2 = c2[i]
        cs = tstart[i]
        ce = tend[i]
        nsub = max(1, math.ceil(p_max * (ce - cs) / MAX_PH))
        hsub = (ce - cs) / nsub
        for j in range(nsub):
            if done:
                break
            tb = ce if j == nsub - 1 else cs + (j + 1) * hsub
            t_sub0 = t
            while not done:
                if mode == REST:
                    if t < hold_until:
                        t = tb
                        ntr = _record(trace_t, trace_x, ntr, t, 0.0)
                        break
                    tu = -1.0
                    su = 0.0
                    t1 = _uplift_time(k, a0, a1, a2, cs, ks_pos, 1.0, t, tb)
                    if t1 >= 0.0:
                        tu = t1
                        su = 1.0
                    if not one_sided:
                        t2 = _uplift_time(k, a0, a1, a2, cs, ks_neg, -1.0, t, tb)
                        if t2 >= 0.0 and (tu < 0.0 or t2 < tu):
                            tu = t2
                            su = -1.0
                    if tu < 0.0 or tu >= tb:
                        t = tb
                        ntr = _record(trace_t, trace_x, ntr, t, 0.0)
                        break
                    mode = FLIGHT
                    s = su
                    x = 0.0
                    v = 0.0
                    t = tu
                    uplift_t = tu
                    n_up += 1
                    ntr = _record(trace_t, trace_x, ntr, t, 0.0)
                    continue

                # Flight on side s from the anchor (t, x, v) to tb or to the first impact.
                if s > 0.0:
                    p = p_pos
                    ks = ks_pos
                else:
                    p = p_neg
                    ks = ks_neg
                big_h = tb - t
                if big_h <= 0.0:
                    break
                n_steps += 1
                ta = t
                xa = x
                va = v
                ad_a = _accel(k, a0, a1, a2, cs, ta)[1]
                # Sign of q' on the stretch: constant for linear cells; for sinusoidal quarter
                # cells taken at the midpoint, clear of the zeros on the cell boundaries.
                qd_sign = (
                    _sgn(ad_a) if k == 0 else _sgn(_accel(k, a0, a1, a2, cs, 0.5 * (ta + tb))[1])
                )
                acc_a = p * p * (xa - s - ks * _accel(k, a0, a1, a2, cs, ta)[0])
                jerk_a = p * p * (va - ks * ad_a)
                sig_a = _side_sign_right(va, acc_a, jerk_a)
                if xa == 0.0 and va == 0.0:
                    sig_a = s  # uplift: the drive exceeds the threshold, motion is outward
                nz, z1, z2, xb, vb = _velocity_zeros(
                    k, a0, a1, a2, cs, ks, s, p, ta, xa, va, acc_a, jerk_a, big_h, sig_a, qd_sign
                )
                # Monotone pieces of x: [0, z1], [z1, z2], [z2, H].
                tau_l = 0.0
                sx_l = s * xa
                tau_imp = -1.0
                for piece in range(nz + 1):
                    if piece < nz:
                        tau_r = z1 if piece == 0 else z2
                        xr = _state(k, a0, a1, a2, cs, ks, s, p, ta, xa, va, tau_r)[0]
                        if s * xr >= 0.0:  # turning point
                            ntr = _record(trace_t, trace_x, ntr, ta + tau_r, xr)
                    else:
                        tau_r = big_h
                        xr = xb
                    sx_r = s * xr
                    if sx_r < 0.0:
                        # Impact in (tau_l, tau_r]: s*x falls through 0 on a monotone piece.
                        if sx_l <= 0.0:
                            tau_imp = tau_l
                        else:
                            tau_imp = _root(
                                0,
                                0.0,
                                k,
                                a0,
                                a1,
                                a2,
                                cs,
                                ks,
                                s,
                                p,
                                ta,
                                xa,
                                va,
                                tau_l,
                                tau_r,
                                s,
                                s * sx_l,
                                xr,
                            )
                        break
                    if sx_r >= 1.0 and sx_l < 1.0 and math.isnan(t_cross):
                        tc = _root(
                            0,
                            s,
                            k,
                            a0,
                            a1,
                            a2,
                            cs,
                            ks,
                            s,
                            p,
                            ta,
                            xa,
                            va,
                            tau_l,
                            tau_r,
                            -s,
                            s * sx_l - s,
                            xr - s,
                        )
                        t_cross = ta + tc
                        if math.isnan(t_exceed):
                            t_exceed = t_cross
                    if sx_r > peak:
                        peak = sx_r
                        t_peak = ta + tau_r
                        var_peak = pxx
                    tau_l = tau_r
                    sx_l = sx_r

                if tau_imp >= 0.0:
                    _xi, vi, ai, _ji = _state(k, a0, a1, a2, cs, ks, s, p, ta, xa, va, tau_imp)
                    ex = EPS * (abs(xa) + 1.0 + abs(ks * a0))
                    pxx, pxv, pvv = _propagate_cov(pxx, pxv, pvv, p, tau_imp, ex, ex * p)
                    pxx, pxv, pvv = _cap_cov(pxx, pxv, pvv, p)
                    t = ta + tau_imp
                    if one_sided:
                        s_new = s
                        c_imp = eta
                        p_new = p
                        ks_new = ks
                    else:
                        s_new = -s
                        c_imp = eta * (phiov_pos / phiov_neg if s > 0.0 else phiov_neg / phiov_pos)
                        p_new = p_neg if s > 0.0 else p_pos
                        ks_new = ks_neg if s > 0.0 else ks_pos
                    v_new = c_imp * vi
                    a_now = _accel(k, a0, a1, a2, cs, t)[0]
                    acc_new = p_new * p_new * (-s_new - ks_new * a_now)
                    ntr = _record(trace_t, trace_x, ntr, t, 0.0)
                    ends_in_rest = abs(v_new) < v_rest_rel * p_new or vi == 0.0
                    if nlog < nlog_cap:
                        log[0, nlog] = t
                        log[1, nlog] = s
                        log[2, nlog] = vi
                        log[3, nlog] = 0.0 if ends_in_rest else v_new
                        nlog += 1
                    if abs(vi) >= v_rest_rel * p:
                        n_imp += 1
                        if n_imp >= max_impacts:
                            status = -1
                            done = True
                    if ends_in_rest:
                        n_rest += 1
                        # Rest rule (ends Zeno sequences, theory §10). A null excursion right
                        # after uplift in this segment holds the body until the segment ends.
                        if uplift_t >= t_sub0 and abs(vi) < v_rest_rel * p:
                            hold_until = tb
                        mode = REST
                        s = 0.0
                        x = 0.0
                        v = 0.0
                        pxx = 0.0
                        pxv = 0.0
                        pvv = 0.0
                        t_cross = math.nan
                        continue
                    m_s = (acc_new - c_imp * ai) / vi
                    nxx = c_imp * c_imp * pxx
                    nxv = c_imp * (m_s * pxx + c_imp * pxv)
                    nvv = m_s * m_s * pxx + 2.0 * m_s * c_imp * pxv + c_imp * c_imp * pvv
                    dtau = 4.0 * EPS * max(abs(t), 1.0)
                    pxx = nxx
                    pxv = nxv
                    pvv = nvv + (c_imp * ai * dtau) ** 2
                    pxx, pxv, pvv = _cap_cov(pxx, pxv, pvv, p_new)
                    s = s_new
                    x = 0.0
                    v = v_new
                    t_cross = math.nan
                    uplift_t = math.nan
                    continue

                # No impact: advance to the segment end.
                ex = EPS * (abs(xa) + abs(xb) + 1.0 + abs(ks * a0))
                pxx, pxv, pvv = _propagate_cov(pxx, pxv, pvv, p, big_h, ex, ex * p)
                pxx, pxv, pvv = _cap_cov(pxx, pxv, pvv, p)
                x = xb
                v = vb
                t = tb
                if not (math.isfinite(x) and math.isfinite(v)):
                    status = -2
                    done = True
                    break
                ntr = _record(trace_t, trace_x, ntr, t, x)
                # Certain collapse: moving outward beyond 1 + max future drive.
                if s * v > 0.0 and s * x > 1.0 + ks * amax_after[i]:
                    collapsed = True
                    t_collapse = t_cross if not math.isnan(t_cross) else t
                    status = 1
                    done = True
                break

    err_var = var_peak
    if status == 0 and mode == FLIGHT:
        # Free rocking after the excitation: exact outcome (theory §1.8).
        if s > 0.0:
            p_s = p_pos
            p_o = p_neg
            r_so = phiov_pos / phiov_neg
        else:
            p_s = p_neg
            p_o = p_pos
            r_so = phiov_neg / phiov_pos
        col, dt_cross, pk, dt_pk = _free_rocking(
            s, x, v, p_s, p_o, r_so, eta, one_sided, v_rest_rel * (p_s if one_sided else p_o)
        )
        if col:
            collapsed = True
            t_collapse = t + dt_cross if math.isnan(t_cross) else t_cross
            if math.isnan(t_exceed):
                t_exceed = t_collapse
            status = 1
        elif pk > peak:
            # Sensitivity of the analytic tail to the propagated state error.
            dx = math.sqrt(pxx) + EPS
            dv = math.sqrt(pvv) + EPS * p_s
            pk_x = _free_rocking(s, x + s * dx, v, p_s, p_o, r_so, eta, one_sided, 0.0)[2]
            pk_v = _free_rocking(s, x, v + s * dv, p_s, p_o, r_so, eta, one_sided, 0.0)[2]
            err_var = (pk_x - pk) ** 2 + (pk_v - pk) ** 2
            peak = pk
            t_peak = t + dt_pk
            if peak >= 1.0 and math.isnan(t_exceed):
                t_exceed = t_peak
    if collapsed:
        peak = 1.0
        t_peak = t_collapse

    out[OUT_STATUS] = status
    out[OUT_PEAK] = peak
    out[OUT_T_PEAK] = t_peak
    out[OUT_T_EXCEED] = t_exceed
    out[OUT_COLLAPSED] = 1.0 if collapsed else 0.0
    out[OUT_T_COLLAPSE] = t_collapse
    out[OUT_N_IMPACTS] = n_imp
    out[OUT_N_STEPS] = n_steps
    out[OUT_ERROR] = ERR_SAFETY * (math.sqrt(err_var) + EPS * max(peak, 1.0))
    out[OUT_N_TRACE] = ntr
    out[OUT_TRACE_FULL] = 1.0 if ntr_cap > 0 and ntr == ntr_cap else 0.0
    out[OUT_N_UPLIFTS] = n_up
    out[OUT_N_RESTS] = n_rest
    out[OUT_N_LOG] = nlog
    return out


@_jit
def simulate_cells(cells, params, scale, x0, v_rest_rel, max_impacts, trace):
    """Integrate one mechanism through a cell sequence; return the output vector.

    Parameters
    ----------
    cells : (7, n) float
        Rows ``kind, c0, c1, c2, t_start, t_end, amax_after`` (see ``CELL_ROWS``).
    params : (8,) float
        ``p_pos, p_neg, lam_pos, lam_neg, phiov_pos, phiov_neg, eta, one_sided``.
    scale, x0, v_rest_rel, max_impacts
        Scale factor, initial ratio, rest rule, impact cap (see ``_simulate``).
    trace : (2, m) float
        Time-series buffer (times, ratios); ``m = 0`` for none.

    Returns
    -------
    (NOUT,) float array, indexed by the ``OUT_*`` constants.
    """
    return simulate_cells_logged(
        cells, params, scale, x0, v_rest_rel, max_impacts, trace, np.empty((4, 0))
    )


@_jit
def simulate_cells_logged(cells, params, scale, x0, v_rest_rel, max_impacts, trace, log):
    """``simulate_cells`` that also fills the impact log ``log`` (4, k); see ``LOG_ROWS``.

    The log holds the first ``k`` impacts; ``out[OUT_N_LOG]`` says how many were written.
    """
    return _simulate(
        cells[0],
        cells[1],
        cells[2],
        cells[3],
        cells[4],
        cells[5],
        cells[6],
        scale,
        params[0],
        params[1],
        params[2],
        params[3],
        params[4],
        params[5],
        params[6],
        params[7] != 0.0,
        x0,
        v_rest_rel,
        max_impacts,
        trace[0],
        trace[1],
        log,
    )


@_jit_parallel
def simulate_grid(cells, params, scales, v_rest_rel, max_impacts):
    """Run every mechanism (rows of ``params``) at every scale; return (m, k, NOUT).

    ``params[i] = (p_pos, p_neg, lam_pos, lam_neg, phiov_pos, phiov_neg, eta, one_sided)``.
    """
    m = params.shape[0]
    nk = scales.shape[0]
    out = np.empty((m, nk, NOUT))
    for ij in _prange(m * nk):
        i = ij // nk
        j = ij % nk
        out[i, j, :] = simulate_cells(
            cells, params[i], scales[j], 0.0, v_rest_rel, max_impacts, np.empty((2, 0))
        )
    return out


@_jit
def pulse_collapses(amp, omega, phase, eta, one_sided, v_rest_rel, quarter_cells, cells):
    """Exact outcome of a dimensionless one-cycle pulse (p = 1, g lam = 1).

    ``cells`` is a scratch (7, 4 * quarter_cells) array; ``amp`` is the signed amplitude
    ``a_p / (g lam)`` and ``omega`` the ratio ``omega_p / p``.
    """
    n = 4 * quarter_cells
    period = 2.0 * math.pi / omega
    for i in range(n):
        cells[0, i] = 1.0
        cells[1, i] = amp
        cells[2, i] = omega
        cells[3, i] = phase
        cells[4, i] = period * i / n
        cells[5, i] = period * (i + 1) / n
        cells[6, i] = abs(amp)
    params = np.array([1.0, 1.0, 1.0 / G, 1.0 / G, 1.0, 1.0, eta, 1.0 if one_sided else 0.0])
    out = simulate_cells(cells, params, 1.0, 0.0, v_rest_rel, 1_000_000, np.empty((2, 0)))
    return out[OUT_COLLAPSED] != 0.0


@_jit_parallel
def boundary_grid(omegas, eta, one_sided, sign, phase, a_scan, rtol, max_edges, v_rest_rel):
    """Overturning edges in A for every Omega: scan ``a_scan`` and bisect each change.

    Returns ``(edges, n_edges, collapsed_at_first)``: ``edges[i, :n_edges[i]]`` are the
    amplitudes ``a_p/(g lam)`` where the outcome changes at ``omegas[i]`` (relative width
    ``rtol``), and ``collapsed_at_first[i]`` is the outcome at ``a_scan[0]``.
    """
    n_om = omegas.shape[0]
    edges = np.full((n_om, max_edges), np.nan)
    n_edges = np.zeros(n_om, dtype=np.int64)
    first = np.zeros(n_om, dtype=np.bool_)
    for i in _prange(n_om):
        cells = np.empty((7, 4))
        om = omegas[i]
        prev = pulse_collapses(sign * a_scan[0], om, phase, eta, one_sided, v_rest_rel, 1, cells)
        first[i] = prev
        ne = 0
        for j in range(1, a_scan.shape[0]):
            cur = pulse_collapses(sign * a_scan[j], om, phase, eta, one_sided, v_rest_rel, 1, cells)
            if cur != prev:
                lo = a_scan[j - 1]
                hi = a_scan[j]
                while hi - lo > rtol * hi:
                    mid = 0.5 * (lo + hi)
                    c_mid = pulse_collapses(
                        sign * mid, om, phase, eta, one_sided, v_rest_rel, 1, cells
                    )
                    if c_mid == prev:
                        lo = mid
                    else:
                        hi = mid
                if ne < max_edges:
                    edges[i, ne] = 0.5 * (lo + hi)
                ne += 1
                prev = cur
        n_edges[i] = ne
    return edges, n_edges, first
