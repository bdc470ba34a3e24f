"""Compiled search of many overturning boundary curves at once (the library build).

``boundary_grids`` runs the scan-and-bisect of ``_kernels.boundary_grid`` for several curves
(each its own restitution, one-sided flag and pulse direction) in one parallel loop over
every (curve, Omega) pair, so that all threads share the work of all curves (no thread idle
at the end of each curve). Each pair is searched by the same ``_kernels.search`` as
``boundary_grid``, so the edges are those of ``boundary_grid`` bit for bit.

Restitution-free outcomes. The restitution enters a run only at an impact (and in the
analytic free tail only after one). A two-sided run with ``eta = 0`` that overturns without
any impact (no impact counted, no rest: with ``eta = 0`` every impact is one or the other)
therefore follows the same arithmetic for every ``eta`` up to its collapse: in a cell, or at
the end of the pulse by the free tail's first test, which looks only at the state. Such a
run overturns for every ``eta``. ``probe_grid`` scans ``eta = 0`` and marks these scan points
(70 % of the library's), and ``boundary_grids`` takes them as overturned without running
them again; the outcome, and so every edge, is the same bit for bit.

Without numba the same source runs as plain Python, like ``_kernels``.
"""

import math

import numpy as np

from ._compile import jit_parallel as _jit_parallel
from ._compile import prange as _prange
from ._kernels import (
    GOLDEN,
    KNOWN_FILL,
    KNOWN_IGNORE,
    KNOWN_USE,
    search,
)


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
