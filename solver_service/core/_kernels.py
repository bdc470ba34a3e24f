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
point and ``|x| = 1`` crossing is bracketed and solved to machine precision by a
safeguarded Halley iteration started from the Taylor estimate at the left end of its
piece, stopped by an a-priori bound on the next correction (one or two closed-form
evaluations). No grazing impact is missed. A flight that leaves an impact in a linear cell
(chattering) takes a shorter route (``_short_return``, the same with or without a trace):
the return found from the Taylor start is the first one because ``x'`` changes sign once
before it, and the maximum-principle bound shows that the flight cannot raise the peak; when
the return is not in the step, the batch path's no-event bound (below) may show that nothing
happens in it. A chattering sequence proved to end in rest within its cell, with a known
number of impacts and no new peak, is closed at once (``_chatter_count``, theory §10.5),
unless a time series or an impact log asks for every bounce.

Layout. One run carries small arrays instead of long argument lists: ``sides`` (p, ks,
phi_ov of each side, ``SIDE_*``), ``rules`` (restitution, one-sided, rest rule, impact cap,
``RULE_*``), the closed-form flight ``fl`` (cell and anchor, ``FL_*``) and the run state
``st`` (``ST_*``; its first ``NOUT`` entries are the output vector). The event path is
``_run_cell`` -> ``_rest_step`` (uplift) / ``_flight_step`` (``_short_return``, or
``_velocity_zeros`` and ``_scan_pieces``; then ``_impact`` or ``_advance``), and
``_free_tail`` after the excitation. At an impact into side ``s`` the restitution of that
direction applies (``RULE_ETA`` into +1, ``RULE_ETA_NEG`` into -1; theory §1.8).
Helpers that allocate nothing are compiled without reference counting (``_leaf``):
passing arrays to them costs nothing. The decorators are those of ``_compile``.

Batch path (``simulate_grid``). Scales are run in blocks as a structure of arrays
(``_simulate_block``), one stretch of ``DOZE`` cells at a time, each run through the whole
stretch before the next (its state in registers, its branches predictable). For a linear
cell of one closed-form segment, the flow over the cell width is computed once per side
and width (``_propagator``: the record's few distinct widths, not per sample or run), and
``_no_event`` decides from the two ends of the step, with the maximum-principle bounds
above, that no event lies inside; only a cell where one may lie takes the event path, with
the same arithmetic, so a batch gives the numbers of single runs bit for bit.

The same functions run uncompiled (``exact.kernels("python")``, ``_compile.python_twins``)
as the pure-numpy path.
"""

import math

import numpy as np

from shared_schema.rules import G

# JIT and JIT_REASON say whether a kernel module is compiled (False in its python twin).
from ._compile import JIT, JIT_REASON  # noqa: F401
from ._compile import inline as _inline
from ._compile import jit as _jit
from ._compile import jit_parallel as _jit_parallel
from ._compile import leaf as _leaf
from ._compile import prange as _prange

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
def _accel(cell, t):
    """Ground acceleration of a cell (rows ``CELL_ROWS``) and its rate at absolute time ``t``."""
    if cell[0] == 0:
        return cell[1] + cell[2] * (t - cell[4]), cell[2]
    arg = cell[2] * t + cell[3]
    return cell[1] * math.sin(arg), cell[1] * cell[2] * math.cos(arg)


@_inline
def _side(s):
    """Row of the ``sides`` array for side ``s`` (+1: 0, -1: 1)."""
    return 0 if s > 0.0 else 1


@_leaf
def _anchor(fl, cell, sides, s, ta, xa, va):
    """Fill the flight array ``fl``: cell, side constants of side ``s`` and anchor state."""
    for r in range(5):
        fl[r] = cell[r]
    row = _side(s)
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
def _flow_coeffs(p, tau):
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
def _cov_coeffs(p, tau):
    """Coefficients of the covariance map of the homogeneous flow over ``tau`` [s].

    With the flow matrix ``[[a, b], [c, d]] = [[cosh u, sinh(u)/p], [p sinh u, cosh u]]``:
    ``(a a, 2 a b, b b, a c, a d + b c, b d, c c, 2 c d, d d)``.
    """
    chm1, b, _smp, c = _flow_coeffs(p, tau)
    a = 1.0 + chm1
    d = a
    return a * a, 2.0 * a * b, b * b, a * c, a * d + b * c, b * d, c * c, 2.0 * c * d, d * d


@_inline
def _state(fl, tau):
    """State ``(x, x', x'', x''')`` at ``ta + tau`` from the anchor of the flight ``fl``."""
    ks = fl[FL_KS]
    s = fl[FL_S]
    p = fl[FL_P]
    ta = fl[FL_TA]
    xa = fl[FL_XA]
    va = fl[FL_VA]
    if fl[FL_KIND] == 0:
        chm1, shp, smp, psh = _flow_coeffs(p, tau)
        q0 = ks * (fl[FL_C0] + fl[FL_C1] * (ta - fl[FL_CS]))
        q1 = ks * fl[FL_C1]
        a = xa - s - q0
        x = xa + a * chm1 + va * shp - q1 * smp
        v = va + (va - q1) * chm1 + a * psh
        q = q0 + q1 * tau
        qd = q1
    else:
        chm1, shp, _smp, psh = _flow_coeffs(p, tau)
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
def _sgn(z):
    if z > 0.0:
        return 1.0
    if z < 0.0:
        return -1.0
    return 0.0


@_inline
def _component(which, target, fl, t):
    """Return function ``which`` (0: x - target, 1: x', 2: x''), 2 derivatives, |3rd| bound.

    The second derivative is returned as 0 for ``which == 2`` (Newton's step, not Halley's),
    and the bound as infinite there (no a-priori stop). For ``which == 1`` the third
    derivative is ``x'''' = p**2 (x'' - q'')``, bounded with ``|q''| <= w**2 max|q|`` in a
    sinusoidal cell (``q'' = 0`` in a linear one).
    """
    x, v, acc, jerk = _state(fl, t)
    if which == 0:
        return x - target, v, acc, abs(jerk)
    if which == 1:
        p2 = fl[FL_P] * fl[FL_P]
        qdd = 0.0 if fl[FL_KIND] == 0 else fl[FL_C1] * fl[FL_C1] * abs(fl[FL_KS] * fl[FL_C0])
        return v, acc, jerk, p2 * (abs(acc) + qdd)
    return acc, jerk, 0.0, math.inf


@_leaf
def _taylor_start(f, fp, fpp, t, lo, hi):
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
def _root(which, target, fl, lo, hi, sig_lo, f_lo, f_hi, t0):
    """Zero of component ``which`` (0: x - target, 1: x', 2: x'') of flight ``fl`` in ``[lo, hi]``.

    ``sig_lo`` is the sign of the function just right of ``lo``; the function is assumed to
    change sign once in the bracket. ``t0`` is a start inside the bracket (a Taylor estimate,
    ``_taylor_start``) or NaN; without one, ``f_lo``, ``f_hi`` (values at the ends when known,
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
        f, fp, fpp, c3 = _component(which, target, fl, t)
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
def _side_sign_right(v, acc, jerk):
    """Sign of x' just after a point, from x', x'' and x''' there."""
    if v != 0.0:
        return _sgn(v)
    if acc != 0.0:
        return _sgn(acc)
    return _sgn(jerk)


@_leaf
def _side_sign_left(v, acc, jerk):
    """Sign of x' just before a point, from x', x'' and x''' there."""
    if v != 0.0:
        return _sgn(v)
    if acc != 0.0:
        return -_sgn(acc)
    return _sgn(jerk)


@_leaf
def _velocity_zeros(fl, aa, ja, big_h, sig_a, qd_sign, vb, ab, jb):
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
        t1 = _taylor_start(va, aa, ja, 0.0, 0.0, big_h)
        z1 = _root(1, 0.0, fl, 0.0, big_h, sig_a, va, vb, t1)
    elif sig_a != hump and _sgn(aa) == hump and _sgn(ab) == -hump:
        # x' has sign -hump at both ends and x'' turns from hump to -hump: it may dip.
        tm = _taylor_start(aa, ja, 0.0, 0.0, 0.0, big_h)
        m = _root(2, 0.0, fl, 0.0, big_h, hump, aa, ab, tm)
        _xm, vm, am, jm = _state(fl, m)
        if _sgn(vm) == hump:
            n = 2
            t1 = _taylor_start(va, aa, ja, 0.0, 0.0, m)
            z1 = _root(1, 0.0, fl, 0.0, m, sig_a, va, vm, t1)
            t2 = _taylor_start(vm, am, jm, m, m, big_h)
            z2 = _root(1, 0.0, fl, m, big_h, hump, vm, vb, t2)
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
def _uplift_time(cell, ks, s, t, tb):
    """First time in ``[t, tb]`` at which the drive ``g = -s ks a`` exceeds 1, or ``-1``.

    The returned time is the bracket end at which ``g >= 1`` holds in floating point, so the
    closed form started there moves outward (theory §10, sub-resolution uplift).
    """
    g_t = -s * ks * _accel(cell, t)[0]
    if g_t > 1.0:
        return t
    g_b = -s * ks * _accel(cell, tb)[0]
    if g_b <= 1.0:
        return -1.0
    # g is monotone in the cell: safeguarded Newton from the regula-falsi point, then the
    # first representable time at which g >= 1 holds.
    lo = t
    hi = tb
    x = lo + (hi - lo) * min(max((1.0 - g_t) / (g_b - g_t), 0.0), 1.0)
    tol = 4.0 * EPS * (abs(t) + abs(tb))
    for _ in range(ROOT_MAXITER):
        a_x, ad_x = _accel(cell, x)
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
        if x >= hi or -s * ks * _accel(cell, x)[0] >= 1.0:
            break
        x = min(x + tol, hi)
    return min(x, hi)


@_inline
def _cap_cov(pxx, pxv, pvv, p):
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
def _set_cov(st, pxx, pxv, pvv, p):
    """Store the error covariance, clipped (``_cap_cov``)."""
    pxx, pxv, pvv = _cap_cov(pxx, pxv, pvv, p)
    st[ST_PXX] = pxx
    st[ST_PXV] = pxv
    st[ST_PVV] = pvv


@_leaf
def _propagate_cov(st, p, tau, ex):
    """Carry the error covariance through a homogeneous flight of ``tau`` [s].

    ``ex`` is the rounding error added to x on the way (``ex * p`` to x'); the result is
    capped (``_set_cov``).
    """
    aa, ab2, bb, ac, adbc, bd, cc, cd2, dd = _cov_coeffs(p, tau)
    pxx = st[ST_PXX]
    pxv = st[ST_PXV]
    pvv = st[ST_PVV]
    ev = ex * p
    nxx = aa * pxx + ab2 * pxv + bb * pvv + ex * ex
    nxv = ac * pxx + adbc * pxv + bd * pvv
    nvv = cc * pxx + cd2 * pxv + dd * pvv + ev * ev
    _set_cov(st, nxx, nxv, nvv, p)


@_leaf
def _record(st, trace, t, x):
    """Append ``(t, x)`` to the time-series buffer ``trace`` (2, m) if there is room."""
    ntr = int(st[OUT_N_TRACE])
    if ntr < trace.shape[1]:
        trace[0, ntr] = t
        trace[1, ntr] = x
        st[OUT_N_TRACE] = ntr + 1


@_leaf
def _log_impact(st, log, t, s, vi, v_out):
    """Append an impact to the impact log ``log`` (4, k) if there is room."""
    nlog = int(st[OUT_N_LOG])
    if nlog < log.shape[1]:
        log[0, nlog] = t
        log[1, nlog] = s
        log[2, nlog] = vi
        log[3, nlog] = v_out
        st[OUT_N_LOG] = nlog + 1


@_leaf
def _reset_state(st, t0, x0):
    """Set ``st`` to the run state at ``t0``: at rest, or released from rest at ``x0``."""
    st[:] = 0.0
    st[ST_MODE] = REST
    st[ST_T] = t0
    if x0 != 0.0:
        st[ST_MODE] = FLIGHT
        st[ST_S] = _sgn(x0)
        st[ST_X] = x0
    st[OUT_PEAK] = abs(x0)
    st[OUT_T_PEAK] = t0
    st[OUT_T_EXCEED] = math.nan
    st[ST_T_CROSS] = math.nan
    if abs(x0) >= 1.0:
        st[OUT_T_EXCEED] = t0
        st[ST_T_CROSS] = t0
    st[OUT_T_COLLAPSE] = math.nan
    st[ST_HOLD] = -math.inf
    st[ST_UPLIFT_T] = math.nan


@_jit
def _init_state(t0, x0):
    """Return a new run state at ``t0`` (``_reset_state``)."""
    st = np.empty(NST)
    _reset_state(st, t0, x0)
    return st


@_leaf
def _set_rest(st):
    """Come to rest on the base (no error is carried at rest)."""
    st[ST_MODE] = REST
    st[ST_S] = 0.0
    st[ST_X] = 0.0
    st[ST_V] = 0.0
    st[ST_PXX] = 0.0
    st[ST_PXV] = 0.0
    st[ST_PVV] = 0.0
    st[ST_T_CROSS] = math.nan


@_leaf
def _rest_step(st, cell, sides, rules, tb, trace):
    """At rest until ``tb`` or until uplift; returns True when the segment is done."""
    t = st[ST_T]
    if t < st[ST_HOLD]:
        st[ST_T] = tb
        _record(st, trace, tb, 0.0)
        return True
    tu = -1.0
    su = 0.0
    t1 = _uplift_time(cell, sides[0, SIDE_KS], 1.0, t, tb)
    if t1 >= 0.0:
        tu = t1
        su = 1.0
    if rules[RULE_ONE_SIDED] == 0.0:
        t2 = _uplift_time(cell, sides[1, SIDE_KS], -1.0, t, tb)
        if t2 >= 0.0 and (tu < 0.0 or t2 < tu):
            tu = t2
            su = -1.0
    if tu < 0.0 or tu >= tb:
        st[ST_T] = tb
        _record(st, trace, tb, 0.0)
        return True
    st[ST_MODE] = FLIGHT
    st[ST_S] = su
    st[ST_X] = 0.0
    st[ST_V] = 0.0
    st[ST_T] = tu
    st[ST_UPLIFT_T] = tu
    st[OUT_N_UPLIFTS] += 1
    _record(st, trace, tu, 0.0)
    return False


@_leaf
def _scan_pieces(st, fl, nz, z1, z2, xb, big_h, acc_a, trace):
    """Walk the monotone pieces ``[0, z1], [z1, z2], [z2, H]`` of x in the flight ``fl``.

    Records turning points, the first ``|x| = 1`` crossing and the peak. Returns the time
    offset of the impact (``x = 0``) from the anchor, or -1 when there is none. ``acc_a``
    is x'' at the anchor: with x, x' and x'' at the left end of a piece, a Taylor estimate
    starts each search in it.
    """
    s = fl[FL_S]
    ta = fl[FL_TA]
    tau_l = 0.0
    x_l = fl[FL_XA]
    v_l = fl[FL_VA]
    a_l = acc_a
    for piece in range(nz + 1):
        vr = 0.0
        ar = 0.0
        if piece < nz:
            tau_r = z1 if piece == 0 else z2
            xr, vr, ar, _jr = _state(fl, tau_r)
            if s * xr >= 0.0:  # turning point
                _record(st, trace, ta + tau_r, xr)
        else:
            tau_r = big_h
            xr = xb
        sx_l = s * x_l
        sx_r = s * xr
        if sx_r < 0.0:
            # Impact in (tau_l, tau_r]: s*x falls through 0 on a monotone piece.
            if sx_l <= 0.0:
                return tau_l
            t0 = _taylor_start(x_l, v_l, a_l, tau_l, tau_l, tau_r)
            return _root(0, 0.0, fl, tau_l, tau_r, s, x_l, xr, t0)
        if sx_r >= 1.0 and sx_l < 1.0:
            # Every outward crossing: a body pulled back inside |x| = 1 that collapses on a
            # later excursion collapses at its last crossing, not its first.
            t0 = _taylor_start(x_l - s, v_l, a_l, tau_l, tau_l, tau_r)
            tc = _root(0, s, fl, tau_l, tau_r, -s, x_l - s, xr - s, t0)
            st[ST_T_CROSS] = ta + tc
            if math.isnan(st[OUT_T_EXCEED]):
                st[OUT_T_EXCEED] = ta + tc
        if sx_r > st[OUT_PEAK]:
            st[OUT_PEAK] = sx_r
            st[OUT_T_PEAK] = ta + tau_r
            st[ST_VAR_PEAK] = st[ST_PXX]
        tau_l = tau_r
        x_l = xr
        v_l = vr
        a_l = ar
    return -1.0


@_inline
def _eta_into(rules, s_new):
    """Restitution of a two-sided impact after which the body rocks on side ``s_new``."""
    return rules[RULE_ETA] if s_new > 0.0 else rules[RULE_ETA_NEG]


#: Relative widening of the speed bounds of a closed chattering sequence at each bounce:
#: far above the rounding of the speeds the event path computes, far below the width of
#: the bounds themselves.
CLOSE_MARGIN = 1e-9
#: Most bounces a chattering sequence is followed through by its bounds (else not closed).
CLOSE_MAXITER = 10_000


@_leaf
def _chatter_rate(rules, sides, row):
    """Ratio of the speeds leaving and reaching an impact that ends a flight on side ``row``.

    One-sided, the body rebounds onto the same side; two-sided, it rocks on into the other.
    """
    if rules[RULE_ONE_SIDED] != 0.0:
        return abs(rules[RULE_ETA])
    s_new = -1.0 if row == 0 else 1.0
    return _eta_into(rules, s_new) * (sides[row, SIDE_PHIOV] / sides[1 - row, SIDE_PHIOV])


@_leaf
def _chatter_precheck(sides, rules, row, u0, a_max, j_max, t_left):
    """Return False when the sequence from ``u0`` is unlikely to close (``_chatter_count``).

    Cheap tests, so that the bounds are followed only when they can succeed: the drive below
    uplift on both sides and the first bounce within ``t_left`` (necessary), then estimates
    with the mean rate per bounce: the speeds contracting, the geometric duration within
    ``t_left`` and the count not near a rounding edge (the estimated width of the bounds
    against the distance to the rest speed, in bounces).
    """
    p = sides[row, SIDE_P]
    p2 = p * p
    delta = 1.0 - sides[row, SIDE_KS] * a_max
    if not (delta > 0.0 and 1.0 - sides[1 - row, SIDE_KS] * a_max > 0.0):
        return False
    if 2.0 * u0 > t_left * p2 * delta or not u0 * u0 < 0.5 * p2 * delta * delta:
        return False
    mu = delta - u0 * u0 / (p2 * delta)
    dq = sides[row, SIDE_KS] * j_max
    g = (4.0 / 3.0) * dq / (p2 * mu * mu)
    # The mean rate per bounce (two-sided: the two directions in turn).
    c = math.sqrt(_chatter_rate(rules, sides, row) * _chatter_rate(rules, sides, 1 - row))
    rate = c * (1.0 + 0.5 * g * u0)
    if not (0.0 < c and rate < 1.0):
        return False
    duration = 2.0 * u0 / (p2 * mu * (1.0 - rate))
    if duration > t_left:
        return False
    # The restoring drive varies by this fraction over the sequence; the bounds on the
    # energy the drive's rate feeds in differ by about twice that.
    spread = (dq * duration + u0 * u0 / (p2 * mu)) / mu
    per_bounce = -math.log(c)
    width = (2.0 * g * u0 * spread / (1.0 - rate) + 4.0 * CLOSE_MARGIN / (1.0 - c)) / per_bounce
    pos = math.log(u0 / (rules[RULE_V_REST] * p)) / per_bounce
    frac = pos - math.floor(pos)
    return width < 0.25 and 2.0 * width < frac < 1.0 - 2.0 * width


@_inline
def _bounded_impact(st, sides, rules, row, u_lo, u_hi, z_lo, z_hi, rate, n):
    """Bound the impact that ends a bounce on side ``row`` of a sequence being closed.

    The bounce left at a speed within ``[u_lo, u_hi]`` and returns at ``u sqrt(1 + z)``,
    ``z`` within ``[z_lo, z_hi]`` (``|z| <= 1/2``); ``rate`` is the ratio of the speeds
    leaving and reaching the impact, ``n`` the impacts counted so far. Returns ``(done,
    u_lo, u_hi, n, row)``: the bounds on the speed leaving it, the count with it and the
    side it leaves on; ``done`` is 1 when the sequence ends in rest here, 0 when it goes
    on, and -1 when a comparison of the event path (counted, ends in rest) differs at the
    two bounds or the impact cap would be reached.
    """
    # 1 + z/2 - z**2/2 <= sqrt(1 + z) <= 1 + z/2 for |z| <= 1/2.
    hi = u_hi * (1.0 + 0.5 * z_hi) * (1.0 + CLOSE_MARGIN)
    lo = u_lo * (1.0 + 0.5 * z_lo - 0.5 * z_lo * z_lo) * (1.0 - CLOSE_MARGIN)
    row_new = row if rules[RULE_ONE_SIDED] != 0.0 else 1 - row
    thr_in = rules[RULE_V_REST] * sides[row, SIDE_P]
    thr_out = rules[RULE_V_REST] * sides[row_new, SIDE_P]
    counted = hi >= thr_in
    u_hi = rate * hi * (1.0 + CLOSE_MARGIN)
    u_lo = rate * lo * (1.0 - CLOSE_MARGIN)
    rests = u_hi < thr_out
    if counted != (lo >= thr_in) or rests != (u_lo < thr_out):
        return -1, u_lo, u_hi, n, row_new
    if counted:
        n += 1
    if not rests:
        return 0, u_lo, u_hi, n, row_new
    if st[OUT_N_IMPACTS] + n >= rules[RULE_MAX_IMPACTS]:
        return -1, u_lo, u_hi, n, row_new
    return 1, u_lo, u_hi, n, row_new


#: The cell-wide bounds take over a closed chattering sequence once they widen its speed
#: bounds by at most this fraction over all the bounces left (``_chatter_tail``).
CLOSE_TAIL = 1e-4


@_leaf
def _tail_gain(sides, row, a_max, slope):
    """Bound ``g`` on the speed change of a bounce on side ``row``: ``|z| <= g u`` [s/rad].

    From the cell-wide bounds of ``_chatter_count``: ``R >= p**2 delta/2`` and
    ``|k| = 4 p**2 ks |a'|/3``, so ``|z| = |k| u/R**2 <= 16 ks |a'| u/(3 p**2 delta**2)``.
    """
    p2 = sides[row, SIDE_P] * sides[row, SIDE_P]
    delta = 1.0 - sides[row, SIDE_KS] * a_max
    return (16.0 / 3.0) * sides[row, SIDE_KS] * abs(slope) / (p2 * delta * delta)


@_leaf
def _chatter_tail(st, sides, rules, a_max, slope, row, u_lo, u_hi, t_left):
    """``_chatter_count`` on from a bounce leaving on side ``row``, with cell-wide bounds.

    Each bounce lasts at most ``4 u/(p**2 delta)``, rises at most ``u**2/(p**2 delta)`` and
    returns at ``u sqrt(1 + z)``, ``|z| <= g u`` (``_tail_gain``): no division per bounce.
    ``t_left`` is the time left in the cell [s]. Returns the impacts still counted, or -1.
    """
    top = min(st[OUT_PEAK], 1.0) - BOUND_MARGIN
    d_0 = 1.0 - sides[0, SIDE_KS] * a_max
    d_1 = 1.0 - sides[1, SIDE_KS] * a_max
    inv_0 = 1.0 / (sides[0, SIDE_P] * sides[0, SIDE_P] * d_0)
    inv_1 = 1.0 / (sides[1, SIDE_P] * sides[1, SIDE_P] * d_1)
    g_0 = _tail_gain(sides, 0, a_max, slope)
    g_1 = _tail_gain(sides, 1, a_max, slope)
    rate_0 = _chatter_rate(rules, sides, 0)
    rate_1 = _chatter_rate(rules, sides, 1)
    n = 0
    elapsed = 0.0
    for _ in range(CLOSE_MAXITER):
        inv = inv_0 if row == 0 else inv_1
        x = u_hi * u_hi * inv
        elapsed += 4.0 * u_hi * inv
        z = (g_0 if row == 0 else g_1) * u_hi
        if not (x < top and x < 0.5 * (d_0 if row == 0 else d_1)):
            return -1
        if not (elapsed <= t_left and z <= 0.5):
            return -1
        rate = rate_0 if row == 0 else rate_1
        done, u_lo, u_hi, n, row = _bounded_impact(
            st, sides, rules, row, u_lo, u_hi, -z, z, rate, n
        )
        if done != 0:
            return n if done > 0 else -1
    return -1


@_leaf
def _chatter_count(st, cell, sides, rules, t, s, u0):
    """Impacts still to count before a chattering sequence comes to rest, or -1 (theory §10.5).

    The body leaves ``x = 0`` at time ``t`` on side ``s`` at speed ``u0`` inside the linear
    cell ``cell``, where ``q = ks a`` is linear with rate ``dq = ks a'``. On side ``s``,
    ``y = s x >= 0`` obeys ``y'' = -R`` with ``R = p**2 (1 + s q - y)``, and the energy
    ``E = y'**2/2 + p**2 (1 + s q) y - p**2 y**2/2`` changes at the rate ``p**2 s dq y``.
    Each bounce is followed with bounds: its start time within ``[t + e_lo, t + e_hi]``,
    its launch speed within ``[u_lo, u_hi]``; from them ``R`` within ``[R_min, R_max]``
    (``q`` over the times the bounce can span, ``y`` below its excursion bound
    ``u**2/(2 R_min)``), its duration within ``[2 u/R_max, 2 u/R_min]`` and, as ``y`` lies
    between the parabolas ``u t - R t**2/2``, its integral within ``2 u**3/(3 R**2)`` at the
    two ``R``: the speed at its return is ``u sqrt(1 + k u)``, ``k = 4 p**2 s dq/(3 R**2)``.
    The restitution of each impact carries the bounds to the next bounce. Returns the number
    of impacts that arrive at or above the rest speed before one leaves below it (the event
    path's count), when every such comparison comes out the same at both bounds, the bounces
    end within the cell (where the drive cannot lift the body: the rest that follows holds to
    the cell's end), their excursions stay below the peak so far and the impact cap is not
    reached. Otherwise -1: the event path follows the bounces.
    """
    if cell[0] != 0:
        return -1
    a_t = cell[1] + cell[2] * (t - cell[4])
    a_e = cell[1] + cell[2] * (cell[5] - cell[4])
    a_max = max(abs(a_t), abs(a_e))
    t_left = cell[5] - t
    row = _side(s)
    if not _chatter_precheck(sides, rules, row, u0, a_max, abs(cell[2]), t_left):
        return -1
    top = min(st[OUT_PEAK], 1.0) - BOUND_MARGIN
    u_hi = u0 * (1.0 + CLOSE_MARGIN)
    u_lo = u0 * (1.0 - CLOSE_MARGIN)
    e_lo = 0.0
    e_hi = 0.0
    n = 0
    # Below this speed the cell-wide bounds alone decide the rest (``_chatter_tail``): the
    # speed bounds then widen by at most CLOSE_TAIL over all the bounces left.
    rate_0 = _chatter_rate(rules, sides, 0)
    rate_1 = _chatter_rate(rules, sides, 1)
    rate_max = max(rate_0, rate_1)
    gain = max(_tail_gain(sides, 0, a_max, cell[2]), _tail_gain(sides, 1, a_max, cell[2]))
    u_tail = CLOSE_TAIL * (1.0 - rate_max) / gain if gain > 0.0 else math.inf
    for _ in range(CLOSE_MAXITER):
        if u_hi < u_tail:
            tail = _chatter_tail(st, sides, rules, a_max, cell[2], row, u_lo, u_hi, t_left - e_hi)
            return -1 if tail < 0 else n + tail
        sgn = 1.0 if row == 0 else -1.0
        p = sides[row, SIDE_P]
        p2 = p * p
        sks = sgn * sides[row, SIDE_KS]
        # Crude bounds first (drive over the rest of the cell: y <= x_crude <= delta/2, so
        # R >= p**2 delta/2 and the bounce lasts at most 4 u/(p**2 delta)), then over the
        # times this bounce can span.
        p2d = p2 * (1.0 - sgn * sks * a_max)
        x_crude = u_hi * u_hi / p2d
        if not x_crude < 0.5 * (1.0 - sgn * sks * a_max):
            return -1
        sq_a = sks * (a_t + cell[2] * e_lo)
        sq_b = sks * (a_t + cell[2] * min(e_hi + 4.0 * u_hi / p2d, t_left))
        r_max = p2 * (1.0 + max(sq_a, sq_b))
        r_min = p2 * (1.0 + min(sq_a, sq_b) - x_crude)
        inv_min = 1.0 / r_min
        inv_max = 1.0 / r_max
        e_lo += 2.0 * u_lo * inv_max
        e_hi += 2.0 * u_hi * inv_min
        if not (0.5 * u_hi * u_hi * inv_min < top and e_hi <= t_left):
            return -1
        k = (4.0 / 3.0) * p2 * sks * cell[2]
        z_hi = k * u_hi * (inv_min * inv_min if k > 0.0 else inv_max * inv_max)
        z_lo = k * u_lo * (inv_max * inv_max if k > 0.0 else inv_min * inv_min)
        if not (abs(z_hi) <= 0.5 and abs(z_lo) <= 0.5):
            return -1
        rate = rate_0 if row == 0 else rate_1
        done, u_lo, u_hi, n, row = _bounded_impact(
            st, sides, rules, row, u_lo, u_hi, z_lo, z_hi, rate, n
        )
        if done != 0:
            return n if done > 0 else -1
    return -1


@_leaf
def _impact(st, fl, cell, tau_imp, sides, rules, tb, t_sub0, trace, log):
    """Impact at ``ta + tau_imp``: restitution, side change, rest rule, error saltation."""
    s = fl[FL_S]
    p = fl[FL_P]
    v_rest_rel = rules[RULE_V_REST]
    _xi, vi, ai, _ji = _state(fl, tau_imp)
    ex = EPS * (abs(fl[FL_XA]) + 1.0 + abs(fl[FL_KS] * fl[FL_C0]))
    _propagate_cov(st, p, tau_imp, ex)
    t = fl[FL_TA] + tau_imp
    st[ST_T] = t
    row = _side(s)
    if rules[RULE_ONE_SIDED] != 0.0:
        s_new = s
        row_new = row
        c_imp = rules[RULE_ETA]
    else:
        s_new = -s
        row_new = 1 - row
        c_imp = _eta_into(rules, s_new) * (sides[row, SIDE_PHIOV] / sides[row_new, SIDE_PHIOV])
    p_new = sides[row_new, SIDE_P]
    v_new = c_imp * vi
    acc_new = p_new * p_new * (-s_new - sides[row_new, SIDE_KS] * _accel(cell, t)[0])
    _record(st, trace, t, 0.0)
    ends_in_rest = abs(v_new) < v_rest_rel * p_new or vi == 0.0
    _log_impact(st, log, t, s, vi, 0.0 if ends_in_rest else v_new)
    if abs(vi) >= v_rest_rel * p:
        st[OUT_N_IMPACTS] += 1
        if st[OUT_N_IMPACTS] >= rules[RULE_MAX_IMPACTS]:
            st[OUT_STATUS] = -1
    if (
        not ends_in_rest
        and st[OUT_STATUS] == 0.0
        and log.shape[1] + trace.shape[1] == 0
        and 2.0 * abs(v_new) <= (cell[5] - t) * p_new * p_new
    ):
        # A chattering sequence that surely ends in rest within the cell is closed at once
        # (``_chatter_count``); an impact log or a time series, when asked for, shows every
        # bounce instead. Its first bounce lasts at least 2 u/p**2: when that does not fit in
        # the cell, the sequence is not bounded.
        n_more = _chatter_count(st, cell, sides, rules, t, s_new, abs(v_new))
        if n_more >= 0:
            st[OUT_N_IMPACTS] += n_more
            st[OUT_N_RESTS] += 1
            st[ST_UPLIFT_T] = math.nan
            _set_rest(st)
            return
    if ends_in_rest:
        st[OUT_N_RESTS] += 1
        # Rest rule (ends Zeno sequences, theory §10). A null excursion right after uplift
        # in this segment holds the body until the segment ends.
        if st[ST_UPLIFT_T] >= t_sub0 and abs(vi) < v_rest_rel * p:
            st[ST_HOLD] = tb
        _set_rest(st)
        return
    # Saltation of the error covariance: the impact time moves with the state.
    pxx = st[ST_PXX]
    pxv = st[ST_PXV]
    pvv = st[ST_PVV]
    m_s = (acc_new - c_imp * ai) / vi
    nxx = c_imp * c_imp * pxx
    nxv = c_imp * (m_s * pxx + c_imp * pxv)
    nvv = m_s * m_s * pxx + 2.0 * m_s * c_imp * pxv + c_imp * c_imp * pvv
    dtau = 4.0 * EPS * max(abs(t), 1.0)
    _set_cov(st, nxx, nxv, nvv + (c_imp * ai * dtau) ** 2, p_new)
    st[ST_S] = s_new
    st[ST_X] = 0.0
    st[ST_V] = v_new
    st[ST_T_CROSS] = math.nan
    st[ST_UPLIFT_T] = math.nan


@_leaf
def _advance(st, fl, xb, vb, tb, amax_after, trace):
    """No impact in the flight: move to its end ``tb``; check for certain collapse."""
    s = fl[FL_S]
    ks = fl[FL_KS]
    ex = EPS * (abs(fl[FL_XA]) + abs(xb) + 1.0 + abs(ks * fl[FL_C0]))
    _propagate_cov(st, fl[FL_P], tb - fl[FL_TA], ex)
    st[ST_X] = xb
    st[ST_V] = vb
    st[ST_T] = tb
    if not (math.isfinite(xb) and math.isfinite(vb)):
        st[OUT_STATUS] = -2
        return
    _record(st, trace, tb, xb)
    # Certain collapse: moving outward beyond 1 + max future drive.
    if s * vb > 0.0 and s * xb > 1.0 + ks * amax_after:
        st[OUT_COLLAPSED] = 1.0
        t_cross = st[ST_T_CROSS]
        st[OUT_T_COLLAPSE] = t_cross if not math.isnan(t_cross) else tb
        st[OUT_STATUS] = 1


#: Most Halley iterations of the short-flight search before it leaves the flight to the
#: general scan (it converges in one or two from its Taylor start).
SHORT_MAXITER = 6


@_leaf
def _short_return(st, fl, va, acc_a, big_h):
    """Time of the return to ``x = 0`` of a flight leaving ``x = 0`` outward, or -1.

    For the flights of a chattering sequence, without the general scan of the step (a
    time series gets the turning point from ``_record_turn``). From
    the Taylor start ``-2 x'/x''`` Halley's iteration (a-priori stop as in ``_root``) finds
    a zero ``tau`` of x in ``(0, big_h)`` at which x' points inward. In a linear cell x' has
    at most two zeros (module docstring), and it changes sign an odd number of times on
    ``(0, tau)``: once. So x is unimodal there and ``tau`` is the first return; its top is
    bounded by the maximum-principle bound of ``_no_event``. Returns -1 (the caller takes
    the general path, nothing is changed) when the iteration leaves the step or does not
    settle, or when the top could raise the peak or reach 1.
    """
    s = fl[FL_S]
    t = _taylor_start(0.0, va, acc_a, 0.0, 0.0, big_h)
    if not t > 0.0:
        return -1.0
    tol = 4.0 * EPS * (abs(fl[FL_TA]) + abs(big_h))
    for _ in range(SHORT_MAXITER):
        f, fp, fpp, c3 = _component(0, 0.0, fl, t)
        den = 2.0 * fp * fp - f * fpp
        if not (s * fp < 0.0 and den != 0.0):
            return -1.0
        tn = t - 2.0 * f * fp / den
        if not 0.0 < tn < big_h:
            return -1.0
        width = abs(tn - t)
        r = fpp / (2.0 * fp)
        if width <= tol or APRIORI_SAFETY * (r * r + c3 / (6.0 * abs(fp))) * width**3 <= tol:
            top = max(s * va * t, s * f - s * fp * t)
            if top + BOUND_MARGIN < min(st[OUT_PEAK], 1.0):
                return tn
            return -1.0
        t = tn
    return -1.0


@_leaf
def _record_turn(st, fl, acc_a, jerk_a, tau_imp, trace):
    """Record the one turning point of a short flight (``_short_return``) in the trace."""
    va = fl[FL_VA]
    t0 = _taylor_start(va, acc_a, jerk_a, 0.0, 0.0, tau_imp)
    z = _root(1, 0.0, fl, 0.0, tau_imp, _sgn(va), va, math.nan, t0)
    _record(st, trace, fl[FL_TA] + z, _state(fl, z)[0])


@_leaf
def _flight_step(st, fl, cell, sides, rules, tb, t_sub0, trace, log):
    """Closed-form flight from the current state to ``tb`` or to the first impact.

    Returns True when the segment is done (``tb`` reached, or the run ended there).
    """
    s = st[ST_S]
    ta = st[ST_T]
    big_h = tb - ta
    if big_h <= 0.0:
        return True
    st[OUT_N_STEPS] += 1
    xa = st[ST_X]
    va = st[ST_V]
    _anchor(fl, cell, sides, s, ta, xa, va)
    p = fl[FL_P]
    ks = fl[FL_KS]
    a_a, ad_a = _accel(cell, ta)
    # Sign of q' on the stretch: constant for linear cells; for sinusoidal quarter cells
    # taken at the midpoint, clear of the zeros on the cell boundaries.
    qd_sign = _sgn(ad_a) if cell[0] == 0 else _sgn(_accel(cell, 0.5 * (ta + tb))[1])
    acc_a = p * p * (xa - s - ks * a_a)
    jerk_a = p * p * (va - ks * ad_a)
    sig_a = _side_sign_right(va, acc_a, jerk_a)
    leaving = False
    if xa == 0.0 and va == 0.0:
        sig_a = s  # uplift: the drive exceeds the threshold, motion is outward
    elif xa == 0.0 and s * va > 0.0 and cell[0] == 0:
        # Leaving an impact (chattering): the turning point cannot raise the peak, so it is
        # searched only for the time series, and the motion is the same with or without one.
        tau_imp = _short_return(st, fl, va, acc_a, big_h)
        if tau_imp > 0.0:
            if trace.shape[1] > 0:
                _record_turn(st, fl, acc_a, jerk_a, tau_imp, trace)
            _impact(st, fl, cell, tau_imp, sides, rules, tb, t_sub0, trace, log)
            return False
        leaving = True
    xb, vb, ab, jb = _state(fl, big_h)
    if leaving and trace.shape[1] == 0:
        # No return in this step: when the bounds of the batch path show that no event lies
        # in it either, the general search would only find the turning point, which a run
        # without a time series does not record.
        if _no_event(s, xa, va, xb, vb, ks * a_a, ks * ad_a, big_h, p, st[OUT_PEAK]):
            _advance(st, fl, xb, vb, tb, cell[6], trace)
            return True
    nz, z1, z2 = _velocity_zeros(fl, acc_a, jerk_a, big_h, sig_a, qd_sign, vb, ab, jb)
    tau_imp = _scan_pieces(st, fl, nz, z1, z2, xb, big_h, acc_a, trace)
    if tau_imp >= 0.0:
        _impact(st, fl, cell, tau_imp, sides, rules, tb, t_sub0, trace, log)
        return False
    _advance(st, fl, xb, vb, tb, cell[6], trace)
    return True


@_leaf
def _free_tail(st, sides, rules):
    """After the excitation: the exact free-rocking outcome (theory §1.8) and its error."""
    s = st[ST_S]
    x = st[ST_X]
    v = st[ST_V]
    t = st[ST_T]
    row = _side(s)
    p_s = sides[row, SIDE_P]
    p_o = sides[1 - row, SIDE_P]
    r_so = sides[row, SIDE_PHIOV] / sides[1 - row, SIDE_PHIOV]
    one_sided = rules[RULE_ONE_SIDED] != 0.0
    # The next impact, the only one that can matter (theory §1.8), leads into side -s.
    eta = rules[RULE_ETA] if one_sided else _eta_into(rules, -s)
    v_rest = rules[RULE_V_REST] * (p_s if one_sided else p_o)
    col, dt_cross, pk, dt_pk = free_rocking_kernel(s, x, v, p_s, p_o, r_so, eta, one_sided, v_rest)
    if col:
        st[OUT_COLLAPSED] = 1.0
        t_cross = st[ST_T_CROSS]
        # Already past |x| = 1 on this excursion: it collapses at that crossing; otherwise
        # at the crossing the free motion reaches (a later swing, after the excitation).
        st[OUT_T_COLLAPSE] = (
            t_cross if dt_cross == 0.0 and not math.isnan(t_cross) else t + dt_cross
        )
        if math.isnan(st[OUT_T_EXCEED]):
            st[OUT_T_EXCEED] = st[OUT_T_COLLAPSE]
        st[OUT_STATUS] = 1
    elif pk > st[OUT_PEAK]:
        # Sensitivity of the analytic tail to the propagated state error.
        dx = math.sqrt(st[ST_PXX]) + EPS
        dv = math.sqrt(st[ST_PVV]) + EPS * p_s
        pk_x = free_rocking_kernel(s, x + s * dx, v, p_s, p_o, r_so, eta, one_sided, 0.0)[2]
        pk_v = free_rocking_kernel(s, x, v + s * dv, p_s, p_o, r_so, eta, one_sided, 0.0)[2]
        st[ST_VAR_PEAK] = (pk_x - pk) ** 2 + (pk_v - pk) ** 2
        st[OUT_PEAK] = pk
        st[OUT_T_PEAK] = t + dt_pk
        if pk >= 1.0 and math.isnan(st[OUT_T_EXCEED]):
            st[OUT_T_EXCEED] = t + dt_pk


@_leaf
def _finalise(st, ntr_cap):
    """Complete the output entries (``OUT_*``) of the final run state in place."""
    if st[OUT_COLLAPSED] != 0.0:
        st[OUT_PEAK] = 1.0
        st[OUT_T_PEAK] = st[OUT_T_COLLAPSE]
    peak = st[OUT_PEAK]
    st[OUT_ERROR] = ERR_SAFETY * (math.sqrt(st[ST_VAR_PEAK]) + EPS * max(peak, 1.0))
    st[OUT_TRACE_FULL] = 1.0 if ntr_cap > 0 and st[OUT_N_TRACE] == ntr_cap else 0.0


@_jit
def _finish(st, ntr_cap):
    """Return the output vector (``OUT_*``) of the final run state."""
    _finalise(st, ntr_cap)
    return st[:NOUT].copy()


@_leaf
def _n_segments(cell, rules):
    """Closed-form segments of a cell: each at most ``MAX_PH / p`` long."""
    return max(1, math.ceil(rules[RULE_P_MAX] * (cell[5] - cell[4]) / MAX_PH))


@_leaf
def _run_cell(st, fl, cell, sides, rules, trace, log):
    """Integrate one cell, event by event, from its start (where the run state is)."""
    cs = cell[4]
    ce = cell[5]
    nsub = _n_segments(cell, rules)
    hsub = (ce - cs) / nsub
    for j in range(nsub):
        if st[OUT_STATUS] != 0.0:
            break
        tb = ce if j == nsub - 1 else cs + (j + 1) * hsub
        t_sub0 = st[ST_T]
        while st[OUT_STATUS] == 0.0:
            if st[ST_MODE] == REST:
                if _rest_step(st, cell, sides, rules, tb, trace):
                    break
            elif _flight_step(st, fl, cell, sides, rules, tb, t_sub0, trace, log):
                break


@_jit
def _simulate(cells, sides, rules, x0, trace, log):
    """Integrate one mechanism through a cell sequence (see ``simulate_cells``).

    Parameters
    ----------
    cells : (7, n) float
        Rows ``CELL_ROWS``; ``amax_after[i]`` bounds ``|a|`` from ``t_start[i]`` on [m/s²].
    sides : (2, NSIDE) float
        ``SIDE_*`` constants of side +1 (row 0) and side -1 (row 1): p [rad/s],
        ks [s²/m], phi_ov [rad].
    rules : (NRULE,) float
        ``RULE_*``: restitution [-], one-sided (1 or 0), rest rule [-] (an impact whose
        outgoing speed is below ``v_rest_rel * p`` ends in rest), impact cap, largest p
        [rad/s].
    x0 : float
        Initial normalised rotation, released from rest [-].
    trace : (2, m) float
        Output buffer for the time series (``m = 0``: no trace).
    log : (4, k) float
        Output buffer for the impact log (rows ``LOG_ROWS``; ``k = 0``: no log). Every
        impact is logged, also those below the rest speed that end in rest.

    Returns
    -------
    (NOUT,) float array, indexed by the ``OUT_*`` constants.
    """
    st = np.empty(NST)
    _simulate_into(st, np.empty(NFL), cells, sides, rules, x0, trace, log)
    return st[:NOUT].copy()


@_leaf
def _simulate_into(st, fl, cells, sides, rules, x0, trace, log):
    """``_simulate`` into the caller's run state ``st`` and flight scratch ``fl``."""
    _reset_state(st, cells[4, 0], x0)
    _record(st, trace, st[ST_T], st[ST_X])
    for i in range(cells.shape[1]):
        if st[OUT_STATUS] != 0.0:
            break
        _run_cell(st, fl, cells[:, i], sides, rules, trace, log)
    if st[OUT_STATUS] == 0.0 and st[ST_MODE] == FLIGHT:
        _free_tail(st, sides, rules)
    _finalise(st, trace.shape[1])


@_jit
def _run_constants(params, scale, v_rest_rel, max_impacts):
    """Return ``sides`` and ``rules`` of one run (``params`` as in ``simulate_cells``).

    ``params`` has 8 entries (one restitution for both impact directions) or 10 (then
    entries 8 and 9 are the restitution into side -1 and into side +1).
    """
    sides = np.empty((2, NSIDE))
    sides[0, SIDE_P] = params[0]
    sides[1, SIDE_P] = params[1]
    sides[0, SIDE_KS] = scale / (G * params[2])
    sides[1, SIDE_KS] = scale / (G * params[3])
    sides[0, SIDE_PHIOV] = params[4]
    sides[1, SIDE_PHIOV] = params[5]
    rules = np.empty(NRULE)
    rules[RULE_ETA] = params[9] if params.shape[0] >= 10 else params[6]
    rules[RULE_ETA_NEG] = params[8] if params.shape[0] >= 10 else params[6]
    rules[RULE_ONE_SIDED] = 1.0 if params[7] != 0.0 else 0.0
    rules[RULE_V_REST] = v_rest_rel
    rules[RULE_MAX_IMPACTS] = max_impacts
    rules[RULE_P_MAX] = max(params[0], params[1])
    return sides, rules


# Propagator of one side over one sample interval: the (2, NPROP) array ``prop``.
PROP_CHM1 = 0
PROP_SHP = 1
PROP_SMP = 2
PROP_PSH = 3
PROP_P = 4
#: Then the nine covariance coefficients of ``_cov_coeffs``.
PROP_COV = 5
NPROP = 14
#: Scale factors integrated together by one batch task (structure of arrays).
BLOCK = 32


@_leaf
def _propagator(prop, sides, h):
    """Fill ``prop`` with the closed-form flow over ``h`` [s] on both sides (``_flow_coeffs``)."""
    for row in range(2):
        p = sides[row, SIDE_P]
        chm1, shp, smp, psh = _flow_coeffs(p, h)
        prop[row, PROP_CHM1] = chm1
        prop[row, PROP_SHP] = shp
        prop[row, PROP_SMP] = smp
        prop[row, PROP_PSH] = psh
        prop[row, PROP_P] = p
        cov = _cov_coeffs(p, h)
        for r in range(9):
            prop[row, PROP_COV + r] = cov[r]


@_inline
def _fast_rest(st, ksp, ksn, j, a_lo, a_hi, one_sided):
    """Return True when run ``j`` at rest stays at rest through a linear cell (no uplift).

    The drive is linear in the cell, so ``g = -s ks a`` stays at or below 1 when it does at
    both ends (``_uplift_time``), that is at the lower end value ``a_lo`` for side +1 and
    the upper ``a_hi`` for side -1; a held rest needs no test.
    """
    if -ksp[j] * a_lo <= 1.0 and (one_sided or ksn[j] * a_hi <= 1.0):
        return True
    return st[ST_T, j] < st[ST_HOLD, j]


#: Margin [-] by which a bound on a turning point must clear the peak (and 1) for the batch
#: path to skip locating it: far above the rounding of the bound and of the located value.
BOUND_MARGIN = 1e-12


@_inline
def _no_event(s, xa, va, xb, vb, q0, q1, h, p, peak):
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
        if _sgn(va) != hump and _sgn(p * p * (xa - s - q0)) == hump:
            # x' may dip to zero inside: the event path decides.
            return _sgn(p * p * (xb - s - (q0 + q1 * h))) != -hump
        return True
    if wa > 0.0:
        top = s * xa + wa * h if sq <= 0.0 else sx - wb * h
        return top + BOUND_MARGIN < min(peak, 1.0)
    low = s * xa + wa * h if sq >= 0.0 else sx - wb * h
    return low > BOUND_MARGIN


#: Cells per stretch of the batch path: each run awake goes through a stretch before the
#: next run; a run at rest that cannot lift off anywhere in it is left asleep (``_doze``),
#: its uplift test skipped for the whole stretch.
DOZE = 64


@_jit
def _doze_table(cells, rules):
    """Which cells take the batch fast path, and per stretch of ``DOZE`` cells the drive.

    Returns ``(fast_of, neg, pos, fast)``: per cell, whether it is linear and of one
    closed-form segment (``fast_of``); per stretch, the largest ``-a`` and ``a`` at the
    cell ends [m/s²] and whether every cell of it is fast.
    """
    n = cells.shape[1]
    nb = (n + DOZE - 1) // DOZE
    fast_of = np.empty(n, dtype=np.bool_)
    neg = np.full(nb, -np.inf)
    pos = np.full(nb, -np.inf)
    fast = np.ones(nb, dtype=np.bool_)
    for i in range(n):
        b = i // DOZE
        cell = cells[:, i]
        a_t = cell[1] + cell[2] * (cell[4] - cell[4])
        a_b = cell[1] + cell[2] * (cell[5] - cell[4])
        neg[b] = max(neg[b], -min(a_t, a_b))
        pos[b] = max(pos[b], max(a_t, a_b))
        fast_of[i] = cell[0] == 0 and _n_segments(cell, rules) == 1
        if not fast_of[i]:
            fast[b] = False
    return fast_of, neg, pos, fast


@_leaf
def _doze(st, ksp, ksn, asleep, neg, pos, fast, one_sided, t_start, awake):
    """Wake the runs asleep (time ``t_start`` [s]); put to sleep those no cell can lift.

    At rest, a run sleeps through a stretch when no cell of it can lift it. The test is
    ``_fast_rest``'s on the stretch's extremes ``neg``, ``pos`` [m/s²]; the product with
    ``ks > 0`` keeps the order, so it decides as the per-cell tests would. Returns the
    number of runs left awake and still running, listed first in ``awake``.
    """
    n_awake = 0
    for j in range(st.shape[1]):
        if asleep[j]:
            st[ST_T, j] = t_start
        running = st[OUT_STATUS, j] == 0.0
        asleep[j] = (
            fast
            and running
            and st[ST_MODE, j] == REST
            and ksp[j] * neg <= 1.0
            and (one_sided or ksn[j] * pos <= 1.0)
        )
        if running and not asleep[j]:
            awake[n_awake] = j
            n_awake += 1
    return n_awake


@_leaf
def _load_run(st1, sides1, st, sides, j):
    """Copy run ``j`` of a block into the contiguous scratch arrays of the event path."""
    for r in range(NST):
        st1[r] = st[r, j]
    for row in range(2):
        for c in range(NSIDE):
            sides1[row, c] = sides[j, row, c]


@_leaf
def _store_run(st, st1, j):
    """Copy the scratch run state back into column ``j`` of the block."""
    for r in range(NST):
        st[r, j] = st1[r]


@_inline
def _fly(st, ksp, ksn, j, cells, i, i1, fast_of, width_of, props):
    """Fly run ``j`` through the fast cells from ``i`` on; return the first cell not done.

    The run goes on while no event can lie in the cell, up to ``i1`` (returned when every
    cell is done). In each cell the cheap bound (``_no_event``) decides from the two ends
    of the step, computed with the propagator of the cell's width, bit for bit the
    arithmetic of ``_flight_step``. The run state is held in locals meanwhile.
    """
    s = st[ST_S, j]
    row = 0 if s > 0.0 else 1
    ks = ksp[j] if s > 0.0 else ksn[j]
    xa = st[ST_X, j]
    va = st[ST_V, j]
    pxx = st[ST_PXX, j]
    pxv = st[ST_PXV, j]
    pvv = st[ST_PVV, j]
    peak = st[OUT_PEAK, j]
    t_peak = st[OUT_T_PEAK, j]
    var_peak = st[ST_VAR_PEAK, j]
    i0 = i
    while i < i1 and fast_of[i]:
        c0 = cells[1, i]
        c1 = cells[2, i]
        h = cells[5, i] - cells[4, i]
        q0 = ks * (c0 + c1 * (cells[4, i] - cells[4, i]))
        q1 = ks * c1
        a = xa - s - q0
        pr = props[width_of[i], row]
        xb = xa + a * pr[PROP_CHM1] + va * pr[PROP_SHP] - q1 * pr[PROP_SMP]
        vb = va + (va - q1) * pr[PROP_CHM1] + a * pr[PROP_PSH]
        p = pr[PROP_P]
        if not _no_event(s, xa, va, xb, vb, q0, q1, h, p, peak):
            break
        sx = s * xb
        if sx > peak:
            peak = sx
            t_peak = cells[4, i] + h
            var_peak = pxx
        ex = EPS * (abs(xa) + abs(xb) + 1.0 + abs(ks * c0))
        ev = ex * p
        k = PROP_COV
        nxx = pr[k] * pxx + pr[k + 1] * pxv + pr[k + 2] * pvv + ex * ex
        nxv = pr[k + 3] * pxx + pr[k + 4] * pxv + pr[k + 5] * pvv
        nvv = pr[k + 6] * pxx + pr[k + 7] * pxv + pr[k + 8] * pvv + ev * ev
        pxx, pxv, pvv = _cap_cov(nxx, nxv, nvv, p)
        xa = xb
        va = vb
        i += 1
    if i > i0:
        st[OUT_N_STEPS, j] += i - i0
        st[ST_X, j] = xa
        st[ST_V, j] = va
        st[ST_PXX, j] = pxx
        st[ST_PXV, j] = pxv
        st[ST_PVV, j] = pvv
        st[OUT_PEAK, j] = peak
        st[OUT_T_PEAK, j] = t_peak
        st[ST_VAR_PEAK, j] = var_peak
        st[ST_T, j] = cells[5, i - 1]
    return i


@_leaf
def _run_stretch(
    st, j, ksp, ksn, cells, i0, i1, fast_of, width_of, props, sides, rules, scratch, trace, log
):
    """Integrate run ``j`` of a block through the cells ``i0`` to ``i1 - 1``.

    Fast cells (``fast_of``) in flight go through ``_fly`` and at rest through
    ``_fast_rest``; a cell in which an event may lie, and every other cell, takes the event
    path (``_run_cell``) on a copy of the run in the ``scratch`` arrays ``(st1, sides1,
    fl)``.
    """
    one_sided = rules[RULE_ONE_SIDED] != 0.0
    st1, sides1, fl = scratch
    i = i0
    while i < i1 and st[OUT_STATUS, j] == 0.0:
        if st[ST_MODE, j] == FLIGHT:
            i = _fly(st, ksp, ksn, j, cells, i, i1, fast_of, width_of, props)
            if i == i1:
                break
        elif fast_of[i]:
            a_t = cells[1, i]
            a_b = cells[1, i] + cells[2, i] * (cells[5, i] - cells[4, i])
            if _fast_rest(st, ksp, ksn, j, min(a_t, a_b), max(a_t, a_b), one_sided):
                st[ST_T, j] = cells[5, i]
                i += 1
                continue
        _load_run(st1, sides1, st, sides, j)
        _run_cell(st1, fl, cells[:, i], sides1, rules, trace, log)
        _store_run(st, st1, j)
        i += 1


@_jit
def _simulate_block(cells, width_of, widths, params, scales, v_rest_rel, max_impacts):
    """Run one mechanism at every scale of ``scales`` together; return (k, NOUT).

    Structure of arrays: ``st[:, j]`` is the run state of scale ``j``. ``widths`` are the
    distinct cell widths [s] and ``width_of[i]`` the one of cell ``i``. The cells are taken
    in stretches of ``DOZE``; in each, every run awake (``_doze``) goes through the whole
    stretch before the next (``_run_stretch``), its state held in registers while no event
    lies in its cells. Each linear cell short enough for one closed-form segment uses the
    propagator of its width (computed once per side and width, not per sample or run); the
    runs in which an event may lie, and every other cell, take the event path
    (``_run_cell``) with the same arithmetic, so the results are those of ``simulate_cells``
    bit for bit.
    """
    k = scales.shape[0]
    st = np.empty((NST, k))
    sides = np.empty((k, 2, NSIDE))
    rules = np.empty(NRULE)
    for j in range(k):
        sides[j], rules = _run_constants(params, scales[j], v_rest_rel, max_impacts)
        st[:, j] = _init_state(cells[4, 0], 0.0)
    ksp = sides[:, 0, SIDE_KS].copy()
    ksn = sides[:, 1, SIDE_KS].copy()
    one_sided = rules[RULE_ONE_SIDED] != 0.0
    fast_of, neg, pos, fast = _doze_table(cells, rules)
    props = np.empty((widths.shape[0], 2, NPROP))
    have = np.zeros(widths.shape[0], dtype=np.bool_)
    for i in range(cells.shape[1]):
        w = width_of[i]
        if fast_of[i] and not have[w]:
            _propagator(props[w], sides[0], widths[w])
            have[w] = True
    scratch = (np.empty(NST), np.empty((2, NSIDE)), np.empty(NFL))
    trace = np.empty((2, 0))
    log = np.empty((4, 0))
    asleep = np.zeros(k, dtype=np.bool_)
    awake = np.empty(k, dtype=np.int64)
    for b in range(neg.shape[0]):
        i0 = b * DOZE
        i1 = min(i0 + DOZE, cells.shape[1])
        n_awake = _doze(
            st, ksp, ksn, asleep, neg[b], pos[b], fast[b], one_sided, cells[4, i0], awake
        )
        for ia in range(n_awake):
            _run_stretch(
                st,
                awake[ia],
                ksp,
                ksn,
                cells,
                i0,
                i1,
                fast_of,
                width_of,
                props,
                sides,
                rules,
                scratch,
                trace,
                log,
            )
    _doze(st, ksp, ksn, asleep, 0.0, 0.0, False, one_sided, cells[5, -1], awake)
    out = np.empty((k, NOUT))
    st1, sides1, _fl = scratch
    for j in range(k):
        _load_run(st1, sides1, st, sides, j)
        if st1[OUT_STATUS] == 0.0 and st1[ST_MODE] == FLIGHT:
            _free_tail(st1, sides1, rules)
        out[j] = _finish(st1, 0)
    return out


@_jit
def simulate_cells(cells, params, scale, x0, v_rest_rel, max_impacts, trace):
    """Integrate one mechanism through a cell sequence; return the output vector.

    Parameters
    ----------
    cells : (7, n) float
        Rows ``kind, c0, c1, c2, t_start, t_end, amax_after`` (see ``CELL_ROWS``).
    params : (8,) or (10,) float
        ``p_pos, p_neg, lam_pos, lam_neg, phiov_pos, phiov_neg, eta, one_sided`` and
        optionally ``eta_to_negative, eta_to_positive``, the restitution at an impact into
        side -1 and +1 (two-sided; without them ``eta`` serves both).
    scale, x0, v_rest_rel, max_impacts
        Scale factor [-], initial ratio [-], rest rule [-], impact cap (see ``_simulate``).
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
    sides, rules = _run_constants(params, scale, v_rest_rel, max_impacts)
    return _simulate(cells, sides, rules, x0, trace, log)


#: Most distinct cell widths looked up one by one (``_width_table``); more are sorted.
LINEAR_WIDTHS = 64


@_jit
def _width_table(cells):
    """Distinct cell widths [s] and the index of each cell's width among them.

    A record has a few distinct widths (its sampling interval, rounded): each cell's is
    looked up among those found so far, starting with the previous cell's; past
    ``LINEAR_WIDTHS`` of them, they are sorted instead.
    """
    n = cells.shape[1]
    found = np.empty(LINEAR_WIDTHS)
    width_of = np.empty(n, dtype=np.int64)
    nw = 0
    last = 0
    for i in range(n):
        h = cells[5, i] - cells[4, i]
        if nw > 0 and found[last] == h:
            width_of[i] = last
            continue
        last = -1
        for w in range(nw):
            if found[w] == h:
                last = w
                break
        if last < 0:
            if nw == LINEAR_WIDTHS:
                all_widths = cells[5] - cells[4]
                widths = np.unique(all_widths)
                return widths, np.searchsorted(widths, all_widths)
            found[nw] = h
            last = nw
            nw += 1
        width_of[i] = last
    return found[:nw].copy(), width_of


@_jit
def _grid_task(out, task, cells, width_of, widths, params, scales, v_rest_rel, max_impacts):
    """Task ``task`` of ``simulate_grid``: one mechanism at one block of ``BLOCK`` scales."""
    nb = (scales.shape[0] + BLOCK - 1) // BLOCK
    i = task // nb
    lo = (task % nb) * BLOCK
    hi = min(lo + BLOCK, scales.shape[0])
    out[i, lo:hi, :] = _simulate_block(
        cells, width_of, widths, params[i], scales[lo:hi], v_rest_rel, max_impacts
    )


@_jit_parallel
def simulate_grid(cells, params, scales, v_rest_rel, max_impacts):
    """Run every mechanism (rows of ``params``) at every scale; return (m, k, NOUT).

    ``params[i] = (p_pos, p_neg, lam_pos, lam_neg, phiov_pos, phiov_neg, eta, one_sided)``,
    optionally followed by ``eta_to_negative, eta_to_positive`` (``simulate_cells``).
    The work is split in tasks of one mechanism × up to ``BLOCK`` scales
    (``_grid_task``), run in parallel; the distinct cell widths are found once.
    """
    widths, width_of = _width_table(cells)
    out = np.empty((params.shape[0], scales.shape[0], NOUT))
    n_tasks = params.shape[0] * ((scales.shape[0] + BLOCK - 1) // BLOCK)
    for task in _prange(n_tasks):
        _grid_task(out, task, cells, width_of, widths, params, scales, v_rest_rel, max_impacts)
    return out


@_jit
def simulate_grid_serial(cells, params, scales, v_rest_rel, max_impacts):
    """``simulate_grid`` on the calling thread only (for callers that run many in threads)."""
    widths, width_of = _width_table(cells)
    out = np.empty((params.shape[0], scales.shape[0], NOUT))
    n_tasks = params.shape[0] * ((scales.shape[0] + BLOCK - 1) // BLOCK)
    for task in range(n_tasks):
        _grid_task(out, task, cells, width_of, widths, params, scales, v_rest_rel, max_impacts)
    return out


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


@_leaf
def pulse_collapses(amp, omega, phase, quarter_cells, work):
    """Exact outcome of a dimensionless one-cycle pulse (p = 1, g lam = 1).

    ``amp`` is the signed amplitude ``a_p / (g lam)`` and ``omega`` the ratio
    ``omega_p / p``. ``work`` is the scratch of ``pulse_work`` (its cells are overwritten);
    nothing is allocated, so the scan and bisection of ``boundary_grid`` cost only the
    integration.
    """
    cells, sides, rules, st, fl, trace, log = work
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
    _simulate_into(st, fl, cells, sides, rules, 0.0, trace, log)
    return st[OUT_COLLAPSED] != 0.0


@_jit
def pulse_work(eta, one_sided, v_rest_rel, quarter_cells, eta_neg=math.nan):
    """Scratch of ``pulse_collapses`` for a restitution and rest rule (any amplitude, Omega).

    ``eta`` is the restitution of impacts into side +1 and ``eta_neg`` of those into side -1
    (NaN: ``eta`` for both).
    """
    e_neg = eta if math.isnan(eta_neg) else eta_neg
    params = np.array(
        [1.0, 1.0, 1.0 / G, 1.0 / G, 1.0, 1.0, eta, 1.0 if one_sided else 0.0, e_neg, eta]
    )
    sides, rules = _run_constants(params, 1.0, v_rest_rel, 1_000_000)
    cells = np.empty((len(CELL_ROWS), 4 * quarter_cells))
    return cells, sides, rules, np.empty(NST), np.empty(NFL), np.empty((2, 0)), np.empty((4, 0))


#: What ``search`` does with its ``known`` row: nothing, take its True entries as overturned
#: without a run, or fill it with the restitution-free outcomes (the ``eta = 0`` probe).
KNOWN_IGNORE = 0
KNOWN_USE = 1
KNOWN_FILL = 2


#: Golden-ratio conjugate: the visiting order of the Omega of a boundary search.
GOLDEN = 0.6180339887498949


@_jit
def _scan_point(amp, om, phase, work, known, j, mode):
    """Outcome at scan point ``j``, using or filling ``known[j]`` as ``mode`` says."""
    if mode == KNOWN_USE and known[j]:
        return True
    out = pulse_collapses(amp, om, phase, 1, work)
    if mode == KNOWN_FILL:
        st = work[3]
        known[j] = out and st[OUT_N_IMPACTS] == 0.0 and st[OUT_N_RESTS] == 0.0
    return out


@_jit
def search(
    eta, one_sided, sign, om, phase, a_scan, rtol, v_rest_rel, edges_row, known, mode, eta_neg
):
    """Scan and bisect the outcome in A at one Omega; return (n_edges, collapsed at first).

    ``edges_row`` (max_edges,) receives the first edges; the count may exceed its size.
    ``known`` (n_scan,) and ``mode``: see ``KNOWN_*``; ``eta_neg`` as in ``pulse_work``.
    """
    max_edges = edges_row.shape[0]
    work = pulse_work(eta, one_sided, v_rest_rel, 1, eta_neg)
    prev = _scan_point(sign * a_scan[0], om, phase, work, known, 0, mode)
    first = prev
    ne = 0
    for j in range(1, a_scan.shape[0]):
        cur = _scan_point(sign * a_scan[j], om, phase, work, known, j, mode)
        if cur != prev:
            lo = a_scan[j - 1]
            hi = a_scan[j]
            while hi - lo > rtol * hi:
                mid = 0.5 * (lo + hi)
                if pulse_collapses(sign * mid, om, phase, 1, work) == prev:
                    lo = mid
                else:
                    hi = mid
            if ne < max_edges:
                edges_row[ne] = 0.5 * (lo + hi)
            ne += 1
            prev = cur
    return ne, first


@_jit_parallel
def boundary_grid(
    omegas, eta, one_sided, sign, phase, a_scan, rtol, max_edges, v_rest_rel, eta_neg=math.nan
):
    """Overturning edges in A for every Omega: scan ``a_scan`` and bisect each change.

    ``eta_neg`` is the restitution of impacts into side -1 when it differs from ``eta``
    (which then serves the impacts into side +1); NaN: ``eta`` for both.

    Returns ``(edges, n_edges, collapsed_at_first)``: ``edges[i, :n_edges[i]]`` are the
    amplitudes ``a_p/(g lam)`` where the outcome changes at ``omegas[i]`` (relative width
    ``rtol``), and ``collapsed_at_first[i]`` is the outcome at ``a_scan[0]``.
    """
    n_om = omegas.shape[0]
    edges = np.full((n_om, max_edges), np.nan)
    n_edges = np.zeros(n_om, dtype=np.int64)
    first = np.zeros(n_om, dtype=np.bool_)
    # Static chunks of the parallel loop would give one thread the slow, low Omega: visit the
    # Omega in golden-ratio order, so that every contiguous chunk samples the whole range.
    order = np.argsort((np.arange(n_om) * GOLDEN) % 1.0)
    no_known = np.zeros(0, dtype=np.bool_)
    for c in _prange(n_om):
        i = order[c]
        n_edges[i], first[i] = search(
            eta,
            one_sided,
            sign,
            omegas[i],
            phase,
            a_scan,
            rtol,
            v_rest_rel,
            edges[i],
            no_known,
            KNOWN_IGNORE,
            eta_neg,
        )
    return edges, n_edges, first
