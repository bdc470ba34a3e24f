"""Batches of runs of the exact rocking integrator (``exact.simulate_batch``: histories, IDA).

Batch path (``simulate_grid``). Scales are run in blocks as a structure of arrays
(``_simulate_block``), one stretch of ``DOZE`` cells at a time, each run through the whole
stretch before the next (its state in registers, its branches predictable). For a linear
cell of one closed-form segment, the flow over the cell width is computed once per side
and width (``_propagator``: the record's few distinct widths, not per sample or run), and
``no_event`` (``_closed_form``) decides from the two ends of the step, with the
maximum-principle bounds, that no event lies inside; only a cell where one may lie takes
the event path of one run (``_stepping.run_cell``), with the same arithmetic, so a batch
gives the numbers of single runs bit for bit.
"""

import numpy as np

from ._closed_form import (
    EPS,
    FLIGHT,
    NFL,
    NOUT,
    NRULE,
    NSIDE,
    NST,
    OUT_N_STEPS,
    OUT_PEAK,
    OUT_STATUS,
    OUT_T_PEAK,
    REST,
    RULE_ONE_SIDED,
    SIDE_KS,
    SIDE_P,
    ST_HOLD,
    ST_MODE,
    ST_PVV,
    ST_PXV,
    ST_PXX,
    ST_S,
    ST_T,
    ST_V,
    ST_VAR_PEAK,
    ST_X,
    cap_cov,
    cov_coeffs,
    flow_coeffs,
    no_event,
)
from ._compile import inline as _inline
from ._compile import jit as _jit
from ._compile import jit_parallel as _jit_parallel
from ._compile import leaf as _leaf
from ._compile import prange as _prange
from ._stepping import (
    finish,
    free_tail,
    init_state,
    n_segments,
    run_cell,
    run_constants,
)

# Propagator of one side over one sample interval: the (2, NPROP) array ``prop``.
PROP_CHM1 = 0
PROP_SHP = 1
PROP_SMP = 2
PROP_PSH = 3
PROP_P = 4
#: Then the nine covariance coefficients of ``cov_coeffs``.
PROP_COV = 5
NPROP = 14
#: Scale factors integrated together by one batch task (structure of arrays).
BLOCK = 32


@_leaf
def _propagator(prop, sides, h):
    """Fill ``prop`` with the closed-form flow over ``h`` [s] on both sides (``flow_coeffs``)."""
    for row in range(2):
        p = sides[row, SIDE_P]
        chm1, shp, smp, psh = flow_coeffs(p, h)
        prop[row, PROP_CHM1] = chm1
        prop[row, PROP_SHP] = shp
        prop[row, PROP_SMP] = smp
        prop[row, PROP_PSH] = psh
        prop[row, PROP_P] = p
        cov = cov_coeffs(p, h)
        for r in range(9):
            prop[row, PROP_COV + r] = cov[r]


@_inline
def _fast_rest(st, ksp, ksn, j, a_lo, a_hi, one_sided):
    """Return True when run ``j`` at rest stays at rest through a linear cell (no uplift).

    The drive is linear in the cell, so ``g = -s ks a`` stays at or below 1 when it does at
    both ends (``uplift_time``), that is at the lower end value ``a_lo`` for side +1 and
    the upper ``a_hi`` for side -1; a held rest needs no test.
    """
    if -ksp[j] * a_lo <= 1.0 and (one_sided or ksn[j] * a_hi <= 1.0):
        return True
    return st[ST_T, j] < st[ST_HOLD, j]


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
        fast_of[i] = cell[0] == 0 and n_segments(cell, rules) == 1
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
    cell is done). In each cell the cheap bound (``no_event``) decides from the two ends
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
        if not no_event(s, xa, va, xb, vb, q0, q1, h, p, peak):
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
        pxx, pxv, pvv = cap_cov(nxx, nxv, nvv, p)
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
    path (``run_cell``) on a copy of the run in the ``scratch`` arrays ``(st1, sides1,
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
        run_cell(st1, fl, cells[:, i], sides1, rules, trace, log)
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
    (``run_cell``) with the same arithmetic, so the results are those of ``simulate_cells``
    bit for bit.
    """
    k = scales.shape[0]
    st = np.empty((NST, k))
    sides = np.empty((k, 2, NSIDE))
    rules = np.empty(NRULE)
    for j in range(k):
        sides[j], rules = run_constants(params, scales[j], v_rest_rel, max_impacts)
        st[:, j] = init_state(cells[4, 0], 0.0)
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
            free_tail(st1, sides1, rules)
        out[j] = finish(st1, 0)
    return out


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
