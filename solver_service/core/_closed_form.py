"""Closed-form pieces of the exact rocking integrator, shared by every kernel path.

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
the cell ends, plus one bracketed search for a zero of ``x''`` in the ambiguous case
(``velocity_zeros``). ``x`` is then monotone on at most three pieces, and every impact
(``x = 0``), turning point and ``|x| = 1`` crossing is bracketed and solved to machine
precision by a safeguarded Halley iteration (``root``) started from the Taylor estimate at
the left end of its piece (``taylor_start``), stopped by an a-priori bound on the next
correction (one or two closed-form evaluations). No grazing impact is missed. The same
bounds decide from the two ends of a step that no event lies inside it (``no_event``).

Layout. One run carries small arrays instead of long argument lists: ``sides`` (p, ks,
phi_ov of each side, ``SIDE_*``), ``rules`` (restitution, one-sided, rest rule, impact cap,
``RULE_*``), the closed-form flight ``fl`` (cell and anchor, ``FL_*``) and the run state
``st`` (``ST_*``; its first ``NOUT`` entries are the output vector, ``OUT_*``). This module
holds that layout, the closed-form flow (``state``, ``flow_coeffs``), its rounding-error
covariance (``propagate_cov``), the uplift time, the free rocking after the excitation
(``free_rocking_kernel``) and the cells of a pulse (``pulse_cells``). The single run is in
``_stepping``, batches in ``_batch_kernels``, boundary searches in ``_boundary_kernels``;
``_kernels`` gathers their entries.

Helpers that allocate nothing are compiled without reference counting (``_leaf``):
passing arrays to them costs nothing. The decorators are those of ``_compile``; the same
functions run uncompiled in their twins (``_compile.python_twins``).
"""

import math

import numpy as np

from ._compile import inline as _inline
from ._compile import jit as _jit
from ._compile import leaf as _leaf

#: Unit roundoff of float64.
EPS = 2.220446049250313e-16
#: Longest closed-form segment, as p*h; bounds cosh/sinh growth inside one evaluation.
MAX_PH = 1.0
#: Below this p*tau, sinh and cosh are evaluated by their Taylor series (no cancellation).
SERIES_U = 0.5
#: Iteration cap of the safeguarded Halley root finder (bisection alone needs < 1100).
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


# Side constants: the (2, NSIDE) array ``sides``, row 0 for side s = +1, row 1 for s = -1.
#: Frequency parameter p [rad/s].
SIDE_P = 0
#: ``ks = scale / (G lam)``: turns the ground acceleration [m/s²] into ``q`` [-].
SIDE_KS = 1
#: Overturning rotation phi_ov [rad].
SIDE_PHIOV = 2
NSIDE = 3

# Rules of one run: the (NRULE,) array ``rules``.
#: Restitution at an impact after which the body rocks on side +1 (the one-sided rebound).
RULE_ETA = 0
RULE_ONE_SIDED = 1
RULE_V_REST = 2
RULE_MAX_IMPACTS = 3
RULE_P_MAX = 4
#: Restitution at an impact after which the body rocks on side -1 (two-sided).
RULE_ETA_NEG = 5
NRULE = 6

# A closed-form flight: the (NFL,) array ``fl`` holds the cell and the anchor state.
FL_KIND = 0
FL_C0 = 1
FL_C1 = 2
FL_C2 = 3
FL_CS = 4
FL_KS = 5
FL_S = 6
FL_P = 7
FL_TA = 8
FL_XA = 9
FL_VA = 10
#: sin and cos of the pulse phase ``c1 ta + c2`` at the anchor (sinusoidal cells).
FL_SIN = 11
FL_COS = 12
NFL = 13

# Run state: the (NST,) array ``st``; its first NOUT entries are the output vector.
ST_MODE = NOUT
ST_S = NOUT + 1
ST_X = NOUT + 2
ST_V = NOUT + 3
ST_T = NOUT + 4
ST_PXX = NOUT + 5
ST_PXV = NOUT + 6
ST_PVV = NOUT + 7
#: Variance of x at the anchor of the flight that holds the peak.
ST_VAR_PEAK = NOUT + 8
#: When |x| reached 1 on the current excursion (NaN: not yet).
ST_T_CROSS = NOUT + 9
#: Rest is held until this time (sub-resolution uplift).
ST_HOLD = NOUT + 10
#: Time of the last uplift (NaN after an impact).
ST_UPLIFT_T = NOUT + 11
NST = NOUT + 12


@_inline
def accel(cell, t):
    """Ground acceleration of a cell (rows ``CELL_ROWS``) and its rate at absolute time ``t``."""
    if cell[0] == 0:
        return cell[1] + cell[2] * (t - cell[4]), cell[2]
    arg = cell[2] * t + cell[3]
    return cell[1] * math.sin(arg), cell[1] * cell[2] * math.cos(arg)


@_inline
def side(s):
    """Row of the ``sides`` array for side ``s`` (+1: 0, -1: 1)."""
    return 0 if s > 0.0 else 1


@_leaf
def anchor(fl, cell, sides, s, ta, xa, va):
    """Fill the flight array ``fl``: cell, side constants of side ``s`` and anchor state."""
    for r in range(5):
        fl[r] = cell[r]
    row = side(s)
    fl[FL_KS] = sides[row, SIDE_KS]
    fl[FL_S] = s
    fl[FL_P] = sides[row, SIDE_P]
    fl[FL_TA] = ta
    fl[FL_XA] = xa
    fl[FL_VA] = va
    if cell[0] != 0:
        th = cell[2] * ta + cell[3]
        fl[FL_SIN] = math.sin(th)
        fl[FL_COS] = math.cos(th)


#: Below this ``u**2`` four terms of each series reach full double precision.
SHORT_U2 = 2.5e-3


@_inline
def _series(u2):
    """Return ``(ps, pc)``: ``sinh(u) - u = u**3 ps`` and ``cosh(u) - 1 = u**2 pc``.

    Taylor series in ``u2 = u**2`` for ``|u| < SERIES_U``: to ``u**19`` and ``u**16``
    (truncation below 1e-17 relative), or four terms each when ``u2 < SHORT_U2`` (the
    common case of one record sample, truncation below 3e-17 relative). No cancellation.
    """
    if u2 < SHORT_U2:
        ps = 1.0 / 6.0 + u2 * (1.0 / 120.0 + u2 * (1.0 / 5040.0 + u2 * (1.0 / 362880.0)))
        pc = 0.5 + u2 * (1.0 / 24.0 + u2 * (1.0 / 720.0 + u2 * (1.0 / 40320.0)))
        return ps, pc
    ps = 1.0 / 121645100408832000.0
    ps = 1.0 / 355687428096000.0 + u2 * ps
    ps = 1.0 / 1307674368000.0 + u2 * ps
    ps = 1.0 / 6227020800.0 + u2 * ps
    ps = 1.0 / 39916800.0 + u2 * ps
    ps = 1.0 / 362880.0 + u2 * ps
    ps = 1.0 / 5040.0 + u2 * ps
    ps = 1.0 / 120.0 + u2 * ps
    ps = 1.0 / 6.0 + u2 * ps
    pc = 1.0 / 20922789888000.0
    pc = 1.0 / 87178291200.0 + u2 * pc
    pc = 1.0 / 479001600.0 + u2 * pc
    pc = 1.0 / 3628800.0 + u2 * pc
    pc = 1.0 / 40320.0 + u2 * pc
    pc = 1.0 / 720.0 + u2 * pc
    pc = 1.0 / 24.0 + u2 * pc
    pc = 0.5 + u2 * pc
    return ps, pc


@_inline
def flow_coeffs(p, tau):
    """Coefficients of the closed-form flow over ``tau`` [s] on a side of frequency ``p``.

    Returns ``(cosh(u) - 1, sinh(u)/p, (sinh(u) - u)/p, p sinh(u))`` with ``u = p tau``:
    from the anchor, ``x = xa + a chm1 + va shp - q1 smp`` and ``x' = va + (va - q1) chm1 +
    a psh`` for a linear drive (``a = xa - s - q0``). Below ``SERIES_U`` only polynomials
    in ``u**2`` are evaluated (no division, no cancellation). The batch path computes them
    once per side and sample interval, the event path per call: the same numbers either
    way.
    """
    u = p * tau
    if abs(u) < SERIES_U:
        u2 = u * u
        ps, pc = _series(u2)
        smp = tau * u2 * ps
        return u2 * pc, tau + smp, smp, p * (u + u * u2 * ps)
    h = math.sinh(0.5 * u)
    sh = math.sinh(u)
    return 2.0 * h * h, sh / p, (sh - u) / p, p * sh


@_leaf
def cov_coeffs(p, tau):
    """Coefficients of the covariance map of the homogeneous flow over ``tau`` [s].

    With the flow matrix ``[[a, b], [c, d]] = [[cosh u, sinh(u)/p], [p sinh u, cosh u]]``:
    ``(a a, 2 a b, b b, a c, a d + b c, b d, c c, 2 c d, d d)``.
    """
    chm1, b, _smp, c = flow_coeffs(p, tau)
    a = 1.0 + chm1
    d = a
    return a * a, 2.0 * a * b, b * b, a * c, a * d + b * c, b * d, c * c, 2.0 * c * d, d * d


@_inline
def state(fl, tau):
    """State ``(x, x', x'', x''')`` at ``ta + tau`` from the anchor of the flight ``fl``."""
    ks = fl[FL_KS]
    s = fl[FL_S]
    p = fl[FL_P]
    ta = fl[FL_TA]
    xa = fl[FL_XA]
    va = fl[FL_VA]
    if fl[FL_KIND] == 0:
        chm1, shp, smp, psh = flow_coeffs(p, tau)
        q0 = ks * (fl[FL_C0] + fl[FL_C1] * (ta - fl[FL_CS]))
        q1 = ks * fl[FL_C1]
        a = xa - s - q0
        x = xa + a * chm1 + va * shp - q1 * smp
        v = va + (va - q1) * chm1 + a * psh
        q = q0 + q1 * tau
        qd = q1
    else:
        chm1, shp, _smp, psh = flow_coeffs(p, tau)
        kk = ks * fl[FL_C0]
        w = fl[FL_C1]
        sn = fl[FL_SIN]
        cn = fl[FL_COS]
        kap = p * p * kk / (p * p + w * w)
        y = xa - s - kap * sn
        yp = va - kap * w * cn
        # Phases th + w tau / 2 and th + w tau by angle addition from the anchor's (FL_SIN,
        # FL_COS): two sines per evaluation instead of six.
        sw = math.sin(0.5 * w * tau)
        cw = math.cos(0.5 * w * tau)
        sin_h = sn * cw + cn * sw
        cos_h = cn * cw - sn * sw
        x = xa + 2.0 * kap * cos_h * sw + y * chm1 + yp * shp
        v = va - 2.0 * kap * w * sin_h * sw + y * psh + yp * chm1
        q = kk * (sin_h * cw + cos_h * sw)
        qd = kk * w * (cos_h * cw - sin_h * sw)
    acc = p * p * (x - s - q)
    jerk = p * p * (v - qd)
    return x, v, acc, jerk


@_inline
def sign_of(z):
    if z > 0.0:
        return 1.0
    if z < 0.0:
        return -1.0
    return 0.0


@_inline
def component(which, target, fl, t):
    """Return function ``which`` (0: x - target, 1: x', 2: x''), 2 derivatives, |3rd| bound.

    The second derivative is returned as 0 for ``which == 2`` (Newton's step, not Halley's),
    and the bound as infinite there (no a-priori stop). For ``which == 1`` the third
    derivative is ``x'''' = p**2 (x'' - q'')``, bounded with ``|q''| <= w**2 max|q|`` in a
    sinusoidal cell (``q'' = 0`` in a linear one).
    """
    x, v, acc, jerk = state(fl, t)
    if which == 0:
        return x - target, v, acc, abs(jerk)
    if which == 1:
        p2 = fl[FL_P] * fl[FL_P]
        qdd = 0.0 if fl[FL_KIND] == 0 else fl[FL_C1] * fl[FL_C1] * abs(fl[FL_KS] * fl[FL_C0])
        return v, acc, jerk, p2 * (abs(acc) + qdd)
    return acc, jerk, 0.0, math.inf


@_leaf
def taylor_start(f, fp, fpp, t, lo, hi):
    """Start for a root in ``(lo, hi)`` from the value and two derivatives at ``t``.

    The root of ``f + fp d + fpp d**2 / 2`` nearest to ``t`` that lies inside the bracket,
    computed without cancellation; NaN when there is none.
    """
    best = math.nan
    if fpp == 0.0:
        if fp != 0.0:
            best = t - f / fp
    else:
        disc = fp * fp - 2.0 * fpp * f
        if disc < 0.0:
            return math.nan
        # The sign of fp (of -f when fp is 0) keeps the result odd under (f, fp, fpp) -> -(...).
        q = -0.5 * (fp + math.copysign(math.sqrt(disc), fp if fp != 0.0 else -f))
        d1 = 2.0 * q / fpp
        d2 = f / q if q != 0.0 else math.nan
        if lo < t + d1 < hi:
            best = t + d1
        if lo < t + d2 < hi and not abs(d2) >= abs(best - t):
            best = t + d2
    if lo < best < hi:
        return best
    return math.nan


#: An iterate is final when the a-priori bound on the next Halley correction, times this
#: factor, is below the time tolerance (Halley converges cubically).
APRIORI_SAFETY = 16.0


@_leaf
def root(which, target, fl, lo, hi, sig_lo, f_lo, f_hi, t0):
    """Zero of component ``which`` (0: x - target, 1: x', 2: x'') of flight ``fl`` in ``[lo, hi]``.

    ``sig_lo`` is the sign of the function just right of ``lo``; the function is assumed to
    change sign once in the bracket. ``t0`` is a start inside the bracket (a Taylor estimate,
    ``taylor_start``) or NaN; without one, ``f_lo``, ``f_hi`` (values at the ends when known,
    NaN otherwise) give a regula-falsi start. Safeguarded Halley iteration (Newton for
    ``x''``): a step is taken when it stays inside the bracket and shrinks fast enough,
    otherwise bisection. It stops when the bracket or the step is below the time resolution,
    or when the a-priori bound ``C d**3`` on the next correction is
    (``C = f''**2/(4 f'**2) + |f'''|/(6 |f'|)``, ``d`` the step just taken).
    Returns the root (time offset from the anchor).
    """
    t = 0.5 * (lo + hi)
    if lo < t0 < hi:
        t = t0
    elif f_lo - f_hi != 0.0 and math.isfinite(f_lo - f_hi):
        t = lo + (hi - lo) * min(max(f_lo / (f_lo - f_hi), 0.01), 0.99)
    width = hi - lo
    # Absolute time cannot be resolved finer than a few ulps of ta + t.
    tol = 4.0 * EPS * (abs(fl[FL_TA]) + abs(hi))
    for _ in range(ROOT_MAXITER):
        f, fp, fpp, c3 = component(which, target, fl, t)
        if f == 0.0:
            return t
        if sign_of(f) == sig_lo:
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
            if fp != 0.0:
                r = fpp / (2.0 * fp)
                if APRIORI_SAFETY * (r * r + c3 / (6.0 * abs(fp))) * width**3 <= tol:
                    return tn
            t = tn
        else:
            width = hi - lo
            t = 0.5 * (lo + hi)
    return t


@_leaf
def side_sign_right(v, acc, jerk):
    """Sign of x' just after a point, from x', x'' and x''' there."""
    if v != 0.0:
        return sign_of(v)
    if acc != 0.0:
        return sign_of(acc)
    return sign_of(jerk)


@_leaf
def _side_sign_left(v, acc, jerk):
    """Sign of x' just before a point, from x', x'' and x''' there."""
    if v != 0.0:
        return sign_of(v)
    if acc != 0.0:
        return -sign_of(acc)
    return sign_of(jerk)


@_leaf
def velocity_zeros(fl, aa, ja, big_h, sig_a, qd_sign, vb, ab, jb):
    """Interior zeros of x' on ``(0, big_h)``: returns ``(n, z1, z2)``.

    ``aa``, ``ja`` are x'' and x''' at the anchor (Taylor starts of the searches) and
    ``sig_a`` the sign of x' just after it; ``qd_sign`` the constant sign of q' on the
    stretch (0 when q is constant); ``vb``, ``ab``, ``jb`` are x', x'' and x''' at
    ``big_h``. See the module docstring.
    """
    va = fl[FL_VA]
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
        t1 = taylor_start(va, aa, ja, 0.0, 0.0, big_h)
        z1 = root(1, 0.0, fl, 0.0, big_h, sig_a, va, vb, t1)
    elif sig_a != hump and sign_of(aa) == hump and sign_of(ab) == -hump:
        # x' has sign -hump at both ends and x'' turns from hump to -hump: it may dip.
        tm = taylor_start(aa, ja, 0.0, 0.0, 0.0, big_h)
        m = root(2, 0.0, fl, 0.0, big_h, hump, aa, ab, tm)
        _xm, vm, am, jm = state(fl, m)
        if sign_of(vm) == hump:
            n = 2
            t1 = taylor_start(va, aa, ja, 0.0, 0.0, m)
            z1 = root(1, 0.0, fl, 0.0, m, sig_a, va, vm, t1)
            t2 = taylor_start(vm, am, jm, m, m, big_h)
            z2 = root(1, 0.0, fl, m, big_h, hump, vm, vb, t2)
    return n, z1, z2


@_leaf
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


@_leaf
def free_rocking_kernel(s, x, v, p_s, p_o, r_so, eta, one_sided, v_rest):
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


@_leaf
def uplift_time(cell, ks, s, t, tb):
    """First time in ``[t, tb]`` at which the drive ``g = -s ks a`` exceeds 1, or ``-1``.

    The returned time is the bracket end at which ``g >= 1`` holds in floating point, so the
    closed form started there moves outward (theory §10, sub-resolution uplift).
    """
    g_t = -s * ks * accel(cell, t)[0]
    if g_t > 1.0:
        return t
    g_b = -s * ks * accel(cell, tb)[0]
    if g_b <= 1.0:
        return -1.0
    # g is monotone in the cell: safeguarded Newton from the regula-falsi point, then the
    # first representable time at which g >= 1 holds.
    lo = t
    hi = tb
    x = lo + (hi - lo) * min(max((1.0 - g_t) / (g_b - g_t), 0.0), 1.0)
    tol = 4.0 * EPS * (abs(t) + abs(tb))
    for _ in range(ROOT_MAXITER):
        a_x, ad_x = accel(cell, x)
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
        if x >= hi or -s * ks * accel(cell, x)[0] >= 1.0:
            break
        x = min(x + tol, hi)
    return min(x, hi)


@_inline
def cap_cov(pxx, pxv, pvv, p):
    """Clip the error covariance to the physical span of the motion (``ERR_CAP``)."""
    xcap = ERR_CAP * ERR_CAP
    vcap = xcap * p * p
    if not pxx <= xcap:  # also catches NaN
        pxx = xcap
    if not pvv <= vcap:
        pvv = vcap
    if not pxv * pxv <= pxx * pvv:  # Cauchy-Schwarz, checked without the square root
        lim = math.sqrt(pxx * pvv)
        pxv = lim if pxv > 0.0 else -lim
    return pxx, pxv, pvv


@_inline
def set_cov(st, pxx, pxv, pvv, p):
    """Store the error covariance, clipped (``cap_cov``)."""
    pxx, pxv, pvv = cap_cov(pxx, pxv, pvv, p)
    st[ST_PXX] = pxx
    st[ST_PXV] = pxv
    st[ST_PVV] = pvv


@_leaf
def propagate_cov(st, p, tau, ex):
    """Carry the error covariance through a homogeneous flight of ``tau`` [s].

    ``ex`` is the rounding error added to x on the way (``ex * p`` to x'); the result is
    capped (``set_cov``).
    """
    aa, ab2, bb, ac, adbc, bd, cc, cd2, dd = cov_coeffs(p, tau)
    pxx = st[ST_PXX]
    pxv = st[ST_PXV]
    pvv = st[ST_PVV]
    ev = ex * p
    nxx = aa * pxx + ab2 * pxv + bb * pvv + ex * ex
    nxv = ac * pxx + adbc * pxv + bd * pvv
    nvv = cc * pxx + cd2 * pxv + dd * pvv + ev * ev
    set_cov(st, nxx, nxv, nvv, p)


#: Margin [-] by which a bound on a turning point must clear the peak (and 1) for the batch
#: path to skip locating it: far above the rounding of the bound and of the located value.
BOUND_MARGIN = 1e-12


@_inline
def no_event(s, xa, va, xb, vb, q0, q1, h, p, peak):
    """Return True when a flight of ``h`` [s] from ``(xa, va)`` to ``(xb, vb)`` has no event.

    No impact, no ``|x| = 1`` crossing, no new peak inside, and no zero of ``x'`` whose
    value the event path would use. With ``x~ = s x`` and ``w~ = s x'``, and ``q~' = s q1``
    of one sign on the cell (maximum principle, module docstring):

    * ``x'`` of one sign at both ends and no hump allowed: ``x`` is monotone;
    * one zero of ``x'``, a maximum of ``x~``: ``x~ <= x~a + w~a h`` when ``q~' <= 0``, else
      ``x~ <= x~b - w~b h``; the bound must stay below the peak and 1 (then the event path
      would find the same state at the end and change nothing on the way);
    * one zero of ``x'``, a minimum of ``x~``: ``x~ >= x~a + w~a h`` when ``q~' >= 0``, else
      ``x~ >= x~b - w~b h``; the bound must stay above 0 (no impact).
    """
    sx = s * xb
    if not (va != 0.0 and vb != 0.0 and 0.0 <= sx < 1.0 and abs(vb) <= 1.7976931348623157e308):
        return False
    wa = s * va
    wb = s * vb
    sq = s * q1
    if (wa > 0.0) == (wb > 0.0):
        hump = -1.0 if q1 <= 0.0 else 1.0
        if sign_of(va) != hump and sign_of(p * p * (xa - s - q0)) == hump:
            # x' may dip to zero inside: the event path decides.
            return sign_of(p * p * (xb - s - (q0 + q1 * h))) != -hump
        return True
    if wa > 0.0:
        top = s * xa + wa * h if sq <= 0.0 else sx - wb * h
        return top + BOUND_MARGIN < min(peak, 1.0)
    low = s * xa + wa * h if sq >= 0.0 else sx - wb * h
    return low > BOUND_MARGIN


@_jit
def pulse_cells(a_p, omega, phase, duration, per_quarter, t_extra):
    """Cells (``CELL_ROWS``) of a one-cycle pulse ``a = a_p sin(omega t + phase)``.

    ``4 per_quarter`` sinusoidal cells over ``duration`` [s] (quarter periods hold every
    extremum on a boundary, so the acceleration is monotone in each cell), then, when
    ``t_extra > 0``, one cell of zero acceleration ``t_extra`` [s] long.
    """
    n = 4 * per_quarter
    n_all = n + 1 if t_extra > 0.0 else n
    cells = np.zeros((len(CELL_ROWS), n_all))
    for i in range(n):
        cells[0, i] = 1.0
        cells[1, i] = a_p
        cells[2, i] = omega
        cells[3, i] = phase
        cells[4, i] = duration * i / n
        cells[5, i] = duration * (i + 1) / n
        cells[6, i] = abs(a_p)
    if t_extra > 0.0:
        cells[4, n] = cells[5, n - 1]
        cells[5, n] = cells[5, n - 1] + t_extra
    return cells
