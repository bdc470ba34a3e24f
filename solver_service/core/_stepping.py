"""One run of the exact rocking integrator, event by event (pulses, records, time series).

The event path of one run over the cells (closed forms and layout in ``_closed_form``) is
``_run_cell`` -> ``_rest_step`` (uplift) / ``_flight_step`` (``_short_return``, or
``velocity_zeros`` and ``_scan_pieces``; then ``_impact`` or ``_advance``), and
``free_tail`` after the excitation. At an impact into side ``s`` the restitution of that
direction applies (``RULE_ETA`` into +1, ``RULE_ETA_NEG`` into -1; theory §1.8).

A flight that leaves an impact in a linear cell (chattering) takes a shorter route
(``_short_return``, the same with or without a trace): the return found from the Taylor
start is the first one because ``x'`` changes sign once before it, and the maximum-principle
bound shows that the flight cannot raise the peak; when the return is not in the step, the
batch path's no-event bound (``no_event``) may show that nothing happens in it. A
chattering sequence proved to end in rest within its cell, with a known number of impacts
and no new peak, is closed at once (``_chatter_count``, theory §10.5), unless a time series
or an impact log asks for every bounce.

Entries: ``simulate_cells`` and ``simulate_cells_logged`` (``exact.simulate``). The batch
path (``_batch_kernels``) and the boundary search (``_boundary_kernels``) run the same
``run_cell``, ``simulate_into`` and ``free_tail``, so they give the numbers of single runs
bit for bit.
"""

import math

import numpy as np

from shared_schema.rules import G

from ._closed_form import (
    APRIORI_SAFETY,
    BOUND_MARGIN,
    EPS,
    ERR_SAFETY,
    FL_C0,
    FL_KS,
    FL_P,
    FL_S,
    FL_TA,
    FL_VA,
    FL_XA,
    FLIGHT,
    MAX_PH,
    NFL,
    NOUT,
    NRULE,
    NSIDE,
    NST,
    OUT_COLLAPSED,
    OUT_ERROR,
    OUT_N_IMPACTS,
    OUT_N_LOG,
    OUT_N_RESTS,
    OUT_N_STEPS,
    OUT_N_TRACE,
    OUT_N_UPLIFTS,
    OUT_PEAK,
    OUT_STATUS,
    OUT_T_COLLAPSE,
    OUT_T_EXCEED,
    OUT_T_PEAK,
    OUT_TRACE_FULL,
    REST,
    RULE_ETA,
    RULE_ETA_NEG,
    RULE_MAX_IMPACTS,
    RULE_ONE_SIDED,
    RULE_P_MAX,
    RULE_V_REST,
    SIDE_KS,
    SIDE_P,
    SIDE_PHIOV,
    ST_HOLD,
    ST_MODE,
    ST_PVV,
    ST_PXV,
    ST_PXX,
    ST_S,
    ST_T,
    ST_T_CROSS,
    ST_UPLIFT_T,
    ST_V,
    ST_VAR_PEAK,
    ST_X,
    accel,
    anchor,
    component,
    free_rocking_kernel,
    no_event,
    propagate_cov,
    root,
    set_cov,
    side,
    side_sign_right,
    sign_of,
    state,
    taylor_start,
    uplift_time,
    velocity_zeros,
)
from ._compile import inline as _inline
from ._compile import jit as _jit
from ._compile import leaf as _leaf


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
        st[ST_S] = sign_of(x0)
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
def init_state(t0, x0):
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
    t1 = uplift_time(cell, sides[0, SIDE_KS], 1.0, t, tb)
    if t1 >= 0.0:
        tu = t1
        su = 1.0
    if rules[RULE_ONE_SIDED] == 0.0:
        t2 = uplift_time(cell, sides[1, SIDE_KS], -1.0, t, tb)
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
            xr, vr, ar, _jr = state(fl, tau_r)
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
            t0 = taylor_start(x_l, v_l, a_l, tau_l, tau_l, tau_r)
            return root(0, 0.0, fl, tau_l, tau_r, s, x_l, xr, t0)
        if sx_r >= 1.0 and sx_l < 1.0:
            # Every outward crossing: a body pulled back inside |x| = 1 that collapses on a
            # later excursion collapses at its last crossing, not its first.
            t0 = taylor_start(x_l - s, v_l, a_l, tau_l, tau_l, tau_r)
            tc = root(0, s, fl, tau_l, tau_r, -s, x_l - s, xr - s, t0)
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
    row = side(s)
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
    _xi, vi, ai, _ji = state(fl, tau_imp)
    ex = EPS * (abs(fl[FL_XA]) + 1.0 + abs(fl[FL_KS] * fl[FL_C0]))
    propagate_cov(st, p, tau_imp, ex)
    t = fl[FL_TA] + tau_imp
    st[ST_T] = t
    row = side(s)
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
    acc_new = p_new * p_new * (-s_new - sides[row_new, SIDE_KS] * accel(cell, t)[0])
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
    set_cov(st, nxx, nxv, nvv + (c_imp * ai * dtau) ** 2, p_new)
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
    propagate_cov(st, fl[FL_P], tb - fl[FL_TA], ex)
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
    the Taylor start ``-2 x'/x''`` Halley's iteration (a-priori stop as in ``root``) finds
    a zero ``tau`` of x in ``(0, big_h)`` at which x' points inward. In a linear cell x' has
    at most two zeros (module docstring), and it changes sign an odd number of times on
    ``(0, tau)``: once. So x is unimodal there and ``tau`` is the first return; its top is
    bounded by the maximum-principle bound of ``no_event``. Returns -1 (the caller takes
    the general path, nothing is changed) when the iteration leaves the step or does not
    settle, or when the top could raise the peak or reach 1.
    """
    s = fl[FL_S]
    t = taylor_start(0.0, va, acc_a, 0.0, 0.0, big_h)
    if not t > 0.0:
        return -1.0
    tol = 4.0 * EPS * (abs(fl[FL_TA]) + abs(big_h))
    for _ in range(SHORT_MAXITER):
        f, fp, fpp, c3 = component(0, 0.0, fl, t)
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
    t0 = taylor_start(va, acc_a, jerk_a, 0.0, 0.0, tau_imp)
    z = root(1, 0.0, fl, 0.0, tau_imp, sign_of(va), va, math.nan, t0)
    _record(st, trace, fl[FL_TA] + z, state(fl, z)[0])


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
    anchor(fl, cell, sides, s, ta, xa, va)
    p = fl[FL_P]
    ks = fl[FL_KS]
    a_a, ad_a = accel(cell, ta)
    # Sign of q' on the stretch: constant for linear cells; for sinusoidal quarter cells
    # taken at the midpoint, clear of the zeros on the cell boundaries.
    qd_sign = sign_of(ad_a) if cell[0] == 0 else sign_of(accel(cell, 0.5 * (ta + tb))[1])
    acc_a = p * p * (xa - s - ks * a_a)
    jerk_a = p * p * (va - ks * ad_a)
    sig_a = side_sign_right(va, acc_a, jerk_a)
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
    xb, vb, ab, jb = state(fl, big_h)
    if leaving and trace.shape[1] == 0:
        # No return in this step: when the bounds of the batch path show that no event lies
        # in it either, the general search would only find the turning point, which a run
        # without a time series does not record.
        if no_event(s, xa, va, xb, vb, ks * a_a, ks * ad_a, big_h, p, st[OUT_PEAK]):
            _advance(st, fl, xb, vb, tb, cell[6], trace)
            return True
    nz, z1, z2 = velocity_zeros(fl, acc_a, jerk_a, big_h, sig_a, qd_sign, vb, ab, jb)
    tau_imp = _scan_pieces(st, fl, nz, z1, z2, xb, big_h, acc_a, trace)
    if tau_imp >= 0.0:
        _impact(st, fl, cell, tau_imp, sides, rules, tb, t_sub0, trace, log)
        return False
    _advance(st, fl, xb, vb, tb, cell[6], trace)
    return True


@_leaf
def free_tail(st, sides, rules):
    """After the excitation: the exact free-rocking outcome (theory §1.8) and its error."""
    s = st[ST_S]
    x = st[ST_X]
    v = st[ST_V]
    t = st[ST_T]
    row = side(s)
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
def finish(st, ntr_cap):
    """Return the output vector (``OUT_*``) of the final run state."""
    _finalise(st, ntr_cap)
    return st[:NOUT].copy()


@_leaf
def n_segments(cell, rules):
    """Closed-form segments of a cell: each at most ``MAX_PH / p`` long."""
    return max(1, math.ceil(rules[RULE_P_MAX] * (cell[5] - cell[4]) / MAX_PH))


@_leaf
def run_cell(st, fl, cell, sides, rules, trace, log):
    """Integrate one cell, event by event, from its start (where the run state is)."""
    cs = cell[4]
    ce = cell[5]
    nsub = n_segments(cell, rules)
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
    simulate_into(st, np.empty(NFL), cells, sides, rules, x0, trace, log)
    return st[:NOUT].copy()


@_leaf
def simulate_into(st, fl, cells, sides, rules, x0, trace, log):
    """``_simulate`` into the caller's run state ``st`` and flight scratch ``fl``."""
    _reset_state(st, cells[4, 0], x0)
    _record(st, trace, st[ST_T], st[ST_X])
    for i in range(cells.shape[1]):
        if st[OUT_STATUS] != 0.0:
            break
        run_cell(st, fl, cells[:, i], sides, rules, trace, log)
    if st[OUT_STATUS] == 0.0 and st[ST_MODE] == FLIGHT:
        free_tail(st, sides, rules)
    _finalise(st, trace.shape[1])


@_jit
def run_constants(params, scale, v_rest_rel, max_impacts):
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
    sides, rules = run_constants(params, scale, v_rest_rel, max_impacts)
    return _simulate(cells, sides, rules, x0, trace, log)
