"""Overturning boundaries of pulses by the exact integrator (``envelope``, the library).

``boundary_grid`` scans the amplitude ``A`` of a one-sine or one-cosine pulse for each
frequency ratio ``Omega`` and bisects each change of outcome (``search``, one ``Omega``
after the other; ``pulse_work`` and ``pulse_collapses`` run one pulse through
``_stepping.simulate_into``).

Many curves at once (the library build): ``boundary_grids`` runs the scan-and-bisect of
``boundary_grid`` for several curves (each its own restitution, one-sided flag and pulse
direction) in one parallel loop over
every (curve, Omega) pair, so that all threads share the work of all curves (no thread idle
at the end of each curve). Each pair is searched by the same ``search`` as
``boundary_grid``, so the edges are those of ``boundary_grid`` bit for bit.

Restitution-free outcomes. The restitution enters a run only at an impact (and in the
analytic free tail only after one). A two-sided run with ``eta = 0`` that overturns without
any impact (no impact counted, no rest: with ``eta = 0`` every impact is one or the other)
therefore follows the same arithmetic for every ``eta`` up to its collapse: in a cell, or at
the end of the pulse by the free tail's first test, which looks only at the state. Such a
run overturns for every ``eta``. ``probe_grid`` scans ``eta = 0`` and marks these scan points
(70 % of the library's), and ``boundary_grids`` takes them as overturned without running
them again; the outcome, and so every edge, is the same bit for bit.

Without numba the same functions run as plain Python, like every kernel (``_compile``).
"""

import math

import numpy as np

from shared_schema.rules import G

from ._closed_form import (
    CELL_ROWS,
    NFL,
    NST,
    OUT_COLLAPSED,
    OUT_N_IMPACTS,
    OUT_N_RESTS,
)
from ._compile import jit as _jit
from ._compile import jit_parallel as _jit_parallel
from ._compile import leaf as _leaf
from ._compile import prange as _prange
from ._stepping import (
    run_constants,
    simulate_into,
)


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
    simulate_into(st, fl, cells, sides, rules, 0.0, trace, log)
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
    sides, rules = run_constants(params, 1.0, v_rest_rel, 1_000_000)
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


@_jit_parallel
def probe_grid(omegas, sign, phase, a_scan, rtol, max_edges, v_rest_rel):
    """Search the two-sided ``eta = 0`` curve; mark where its scan overturns whatever eta.

    Returns ``(edges, n_edges, first, known)``: the first three as one curve of
    ``boundary_grids``, and ``known`` (n, n_scan) bool, True at the scan points that
    overturn for every ``eta`` (module docstring).
    """
    n_om = omegas.shape[0]
    edges = np.full((n_om, max_edges), np.nan)
    n_edges = np.zeros(n_om, dtype=np.int64)
    first = np.zeros(n_om, dtype=np.bool_)
    known = np.zeros((n_om, a_scan.shape[0]), dtype=np.bool_)
    order = np.argsort((np.arange(n_om) * GOLDEN) % 1.0)
    for c in _prange(n_om):
        i = order[c]
        ne, f = search(
            0.0,
            False,
            sign,
            omegas[i],
            phase,
            a_scan,
            rtol,
            v_rest_rel,
            edges[i],
            known[i],
            KNOWN_FILL,
            math.nan,
        )
        n_edges[i] = ne
        first[i] = f
    return edges, n_edges, first, known


@_jit_parallel
def boundary_grids(
    omegas, etas, one_sided, signs, phase, a_scan, rtol, max_edges, v_rest_rel, known, use_known
):
    """Overturning edges in A for every curve and Omega.

    Parameters
    ----------
    omegas : (n,) float
        Frequency ratios, shared by every curve [-].
    etas, one_sided, signs : (c,) float, (c,) bool, (c,) float
        Per curve: restitution, one-sided rocking, pulse direction (+1 / -1).
    phase, a_scan, rtol, max_edges, v_rest_rel
        As in ``_kernels.boundary_grid``.
    known : (n, n_scan) bool
        Restitution-free overturning scan points (``probe_grid``, same ``omegas``, ``phase``,
        ``a_scan`` and direction).
    use_known : (c,) bool
        Per curve: take ``known`` as overturned (two-sided curves of the probe's direction).

    Returns
    -------
    edges : (c, n, max_edges) float
        NaN-padded edges per curve and Omega.
    n_edges : (c, n) int
        Number of edges found (may exceed ``max_edges``).
    first : (c, n) bool
        Outcome at ``a_scan[0]``.
    """
    n_c = etas.shape[0]
    n_om = omegas.shape[0]
    total = n_c * n_om
    edges = np.full((n_c, n_om, max_edges), np.nan)
    n_edges = np.zeros((n_c, n_om), dtype=np.int64)
    first = np.zeros((n_c, n_om), dtype=np.bool_)
    # The parallel loop is cut into static chunks, and the cost varies with Omega and eta:
    # visiting the pairs in golden-ratio order gives every chunk a sample of the whole set.
    order = np.argsort((np.arange(total) * GOLDEN) % 1.0)
    for t in _prange(total):
        k = order[t]
        c = k // n_om
        i = k % n_om
        ne, f = search(
            etas[c],
            one_sided[c],
            signs[c],
            omegas[i],
            phase,
            a_scan,
            rtol,
            v_rest_rel,
            edges[c, i],
            known[i],
            KNOWN_USE if use_known[c] else KNOWN_IGNORE,
            math.nan,
        )
        n_edges[c, i] = ne
        first[c, i] = f
    return edges, n_edges, first
