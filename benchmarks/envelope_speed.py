"""Speed of overturning boundaries, the overturning library and mechanism envelopes.

What is measured
----------------
1. One eta curve: ``boundary_curve(omega, 0.9)`` (two-sided, sine pulse) at 400 log-spaced
   Omega in [0.05, 50], every overturning interval bisected to relative width 1e-6; best of
   ``REPEATS_CURVE``. Target <= ``TARGET_CURVE_S``.
2. The whole library: ``build_library()`` with its defaults (51 eta, the one-sided curve in
   both pulse directions, the tabulated pulse spectrum), saved to a temporary file (never the
   shipped ``solver_service/data/overturning_library.npz``); once, wall and CPU time
   (``time.process_time``, all threads) with the load average around it. Target <=
   ``TARGET_LIBRARY_S`` on 2 cores. Every array of the full build is compared with the
   shipped library: they must be equal bit for bit. The tabulated spectrum (Python, on a
   thread beside the compiled curve search) is also timed apart, after the build.
3. Envelopes: ``envelope_doc`` for ``N_MECHANISMS`` random, plausible mechanisms (seeded) at
   ``N_FREQUENCIES`` pulse frequencies from the library (loaded beforehand, load time given
   apart): library interpolation, amplification scale factors, ground-level envelopes and
   critical bands; best of ``REPEATS_ENVELOPE``, in the fast mode (exact where the library
   cannot interpolate safely), and once exact (the default). Target: the fast mode at most
   ``TARGET_FAST_RATIO`` of the exact time.
4. The direct alternative for one curve: at a few Omega of the same grid, the first
   overturning amplitude by bisection on ``IVP_BRACKET`` with ``simulate_ivp`` (DOP853,
   rtol 1e-10, atol 1e-12) to relative width 1e-6. This finds one edge per Omega, not every
   interval. Its time per Omega is extrapolated to the 400 Omega of (1), and its edge is
   compared with ``boundary_curve``'s ``a_min`` at the same Omega.

How
---
Times are ``time.perf_counter`` around the public call. A warm-up call of each path (numba
compilation or cache load, lazy imports) comes first and is excluded; its time is printed.

Run ``.venv/bin/python benchmarks/envelope_speed.py`` for the full run, which rewrites its
section of ``docs/benchmarks.md`` (``_docs.write_section``); ``--quick`` is a smoke run
(a small library, fewer repeats and Omega) that writes no docs unless ``--write-docs``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from _docs import (  # noqa: E402  (benchmarks/ is not a package)
    DOC_MD,
    best_of,
    fmt_time,
    load_average,
    machine_info,
    md_table,
    text_table,
    write_section,
)

from shared_schema.constants import ConstantsFile, parse_constants  # noqa: E402
from solver_service.core.amplification import pulse_response_spectrum  # noqa: E402
from solver_service.core.envelope import (  # noqa: E402
    LIBRARY_PATH,
    MAX_EDGES,
    SPECTRUM_ZETA,
    BoundaryCurve,
    OverturningLibrary,
    boundary_curve,
    build_library,
)
from solver_service.core.exact import simulate  # noqa: E402
from solver_service.core.excitation import Pulse  # noqa: E402
from solver_service.core.model import G, RockingModel  # noqa: E402
from solver_service.core.reference import simulate_ivp  # noqa: E402
from solver_service.workflows.documents import envelope_doc, frequency_grid  # noqa: E402

#: The eta curve of (1): Omega grid (log-spaced) and restitution.
CURVE_OMEGA = (0.05, 50.0, 400)
CURVE_ETA = 0.9
#: Repeats (best of) of the curve and of the envelopes.
REPEATS_CURVE = 3
REPEATS_ENVELOPE = 5
#: Mechanisms and pulse frequencies [Hz] of (3).
N_MECHANISMS = 100
N_FREQUENCIES = 200
F_RANGE_HZ = (0.1, 10.0)
#: Seed of the random mechanisms.
SEED = 20261121
#: Direct alternative (4): bracket in A, bisection width, solve_ivp tolerances, Omega count.
IVP_BRACKET = (1.0, 50.0)
IVP_BISECT_RTOL = 1e-6
IVP_RTOL = 1e-10
IVP_ATOL = 1e-12
IVP_N_OMEGA = 8
IVP_N_OMEGA_QUICK = 3
#: An edge of the bisection matches one of ``boundary_curve`` within this relative distance
#: (ten times the bisection width of either).
MATCH_RTOL = 10 * IVP_BISECT_RTOL
#: Relative offset from the bisection's edge at which the exact integrator is consulted.
EXACT_PROBE = 5 * IVP_BISECT_RTOL
#: The direct alternative stops taking new Omega once it has used this much time [s].
IVP_BUDGET_S = 180.0
#: Quick run: a small library instead of the default one.
QUICK_LIBRARY_OMEGA = 40
QUICK_LIBRARY_ETA = (0.0, 0.5, 0.9, 1.0)
#: The arrays of a library compared with the shipped one.
LIBRARY_ARRAYS = (
    "omega",
    "eta",
    "a_min_two_sided",
    "a_min_one_sided",
    "direction_one_sided",
    "edges_flat",
    "edges_offsets",
    "spectrum_ratio",
    "spectrum",
)
#: Targets [s].
TARGET_CURVE_S = 1.0
TARGET_LIBRARY_S = 10.0
#: The fast mode (the library, exact where it cannot interpolate safely; #27) takes at most
#: this share of the time of the exact envelopes (the default) of the same mechanisms [-].
TARGET_FAST_RATIO = 0.25

COMMAND = ".venv/bin/python benchmarks/envelope_speed.py"


@dataclass
class IvpRow:
    """Bisection with ``simulate_ivp`` at one Omega."""

    omega: float
    time_s: float
    n_runs: int
    edge: Optional[float]  # None: same outcome at both ends of the bracket
    a_min_bc: float
    intervals_bc: list[tuple[float, Optional[float]]] = field(default_factory=list)
    #: Exact-integrator outcomes (collapsed) just below and above ``edge``.
    exact_around: Optional[tuple[bool, bool]] = None

    @property
    def rel_diff(self) -> float:
        """``|A_ivp - a_min| / a_min`` (NaN when either is missing)."""
        if self.edge is None or not math.isfinite(self.a_min_bc):
            return math.nan
        return abs(self.edge - self.a_min_bc) / self.a_min_bc

    def nearest_edge(self) -> tuple[int, int, float]:
        """Index of ``boundary_curve``'s edge nearest to ``edge``, edge count, rel. distance."""
        edges = [e for iv in self.intervals_bc for e in iv if e is not None]
        if self.edge is None or not edges:
            return -1, len(edges), math.nan
        d = [abs(self.edge - e) / e for e in edges]
        k = int(np.argmin(d))
        return k, len(edges), d[k]

    @property
    def kind(self) -> str:
        """``none``, ``none?``, ``a_min``, ``later``, ``missed`` or ``unconfirmed``."""
        if self.edge is None:
            return "none" if not self.a_min_bc <= IVP_BRACKET[1] else "none?"
        k, _, d = self.nearest_edge()
        if k >= 0 and d <= MATCH_RTOL:
            return "a_min" if k == 0 else "later"
        ex = self.exact_around
        return "missed" if ex is not None and ex[0] != ex[1] else "unconfirmed"

    def verdict(self) -> str:
        """How the bisection's edge relates to ``boundary_curve``'s edges at this Omega."""
        k, n, d = self.nearest_edge()
        lo, hi = IVP_BRACKET
        return {
            "none": f"agrees: no edge in [{lo:g}, {hi:g}]",
            "none?": "DISAGREES: boundary_curve has an edge in the bracket",
            "a_min": f"a_min (rel. diff {d:.1e})",
            "later": f"edge {k + 1} of {n}, not a_min (rel. diff to it {d:.1e})",
            "missed": "not reported by boundary_curve; the exact integrator changes outcome "
            "there too: an island narrower than the scan step",
            "unconfirmed": "DISAGREES: no such edge in boundary_curve or the exact integrator",
        }[self.kind]


def verdict(ok: Optional[bool]) -> str:
    return "SKIP" if ok is None else ("PASS" if ok else "FAIL")


def fmt_times(times: list[float]) -> str:
    return ", ".join(fmt_time(t) for t in times)


def numba_threads() -> tuple[int, str]:
    """Numba's thread count and threading layer (the layer is known after a parallel run)."""
    import numba

    try:
        layer = str(numba.threading_layer())
    except ValueError:
        layer = "not initialised"
    return int(numba.get_num_threads()), layer


# ------------------------------------------------------------------------------------------
# Measurements
# ------------------------------------------------------------------------------------------


def curve_omega() -> np.ndarray:
    return np.geomspace(*CURVE_OMEGA[:2], CURVE_OMEGA[2])


def run_curve(quick: bool) -> dict[str, Any]:
    om = curve_omega()
    t0 = time.perf_counter()
    boundary_curve(om[:2], CURVE_ETA)
    warm = time.perf_counter() - t0
    threads, layer = numba_threads()
    reps = 1 if quick else REPEATS_CURVE
    t, times, curve = best_of(lambda: boundary_curve(om, CURVE_ETA), reps)
    import numba

    numba.set_num_threads(1)
    try:
        t1, _, _ = best_of(lambda: boundary_curve(om, CURVE_ETA), 1)
    finally:
        numba.set_num_threads(threads)
    n_edges = np.minimum(curve.n_edges, MAX_EDGES)
    out = {
        "warm_s": warm,
        "time_s": t,
        "times": times,
        "time_1thread_s": t1,
        "threads": threads,
        "layer": layer,
        "curve": curve,
        "n_edges_total": int(curve.n_edges.sum()),
        "n_edges_max": int(curve.n_edges.max()),
        "n_multi": int((n_edges > 1).sum()),
        "n_none": int((~np.isfinite(curve.a_min)).sum()),
        "n_at_start": int(curve.collapsed_at_start.sum()),
    }
    print(
        f"  boundary_curve, {om.size} Omega: best {fmt_time(t)} of [{fmt_times(times)}] with "
        f"{threads} numba threads ({layer}); {fmt_time(t1)} with 1 thread; warm-up "
        f"{fmt_time(warm)} excluded; {out['n_edges_total']} edges, scan ratio "
        f"{curve.scan_ratio:.6f}",
        flush=True,
    )
    return out


def run_library(quick: bool, folder: Path) -> dict[str, Any]:
    kwargs: dict[str, Any] = {}
    if quick:
        kwargs = {
            "omega": np.geomspace(*CURVE_OMEGA[:2], QUICK_LIBRARY_OMEGA),
            "eta": np.array(QUICK_LIBRARY_ETA),
        }
    path = folder / "overturning_library.npz"
    assert path.resolve() != LIBRARY_PATH.resolve()
    threads, _ = numba_threads()
    # Warm-up (excluded): numba compilation or cache load of the library's own kernels.
    t0 = time.perf_counter()
    build_library(omega=np.geomspace(0.5, 5.0, 3), eta=[0.0, 0.5])
    warm = time.perf_counter() - t0
    # Breakdown from the progress callback: called once after the eta = 0 probe curve, then
    # after each parallel group of curves; the spectrum runs beside them on a thread.
    stamps: dict[int, float] = {}
    load_before = load_average()
    t0 = time.perf_counter()
    c0 = time.process_time()
    lib = build_library(
        progress=lambda done, total: stamps.__setitem__(done, time.perf_counter()), **kwargs
    )
    t_build = time.perf_counter() - t0
    cpu_build = time.process_time() - c0
    load_after = load_average()
    lib.save(path)
    t_all = time.perf_counter() - t0
    first = min(stamps) if stamps else 0
    t_probe = stamps.get(first, math.nan) - t0
    t_curves = max(stamps.values(), default=math.nan) - t0
    ratio = lib.spectrum_ratio
    c1 = time.process_time()
    t1 = time.perf_counter()
    pulse_response_spectrum(ratio, zeta=SPECTRUM_ZETA)
    t_spec = time.perf_counter() - t1
    cpu_spec = time.process_time() - c1
    same: Optional[bool] = None
    if not quick:
        shipped = OverturningLibrary.load()
        same = all(np.array_equal(getattr(lib, k), getattr(shipped, k)) for k in LIBRARY_ARRAYS)
    _, layer = numba_threads()
    out = {
        "time_s": t_all,
        "build_s": t_build,
        "cpu_s": cpu_build,
        "warm_s": warm,
        "load": f"{load_before} / {load_after}",
        "probe_s": t_probe,
        "curves_s": t_curves,
        "spectrum_s": t_spec,
        "spectrum_cpu_s": cpu_spec,
        "same_as_shipped": same,
        "save_s": t_all - t_build,
        "n_eta": int(lib.eta.size),
        "n_omega": int(lib.omega.size),
        "n_spectrum": int(lib.spectrum.size),
        "n_edges": int(lib.edges_flat.size),
        "size_kb": path.stat().st_size / 1024,
        "threads": threads,
        "layer": layer,
        "nproc": len(os.sched_getaffinity(0))
        if hasattr(os, "sched_getaffinity")
        else os.cpu_count(),
        "path": path,
    }
    print(
        f"  build_library: {fmt_time(t_build)} (CPU {fmt_time(cpu_build)}; load "
        f"{out['load']}; same as shipped: {same}) + save {fmt_time(out['save_s'])} "
        f"({out['n_eta']} eta + one-sided x 2 directions, {out['n_omega']} Omega; "
        f"{out['size_kb']:.0f} kB) with {threads} numba threads",
        flush=True,
    )
    return out


def random_mechanisms(n: int, seed: int = SEED) -> ConstantsFile:
    """``n`` plausible symmetric mechanisms, half of them one-sided, about half amplified."""
    rng = np.random.default_rng(seed)
    mechs: list[dict[str, Any]] = []
    for i in range(n):
        m: dict[str, Any] = {
            "id": f"M{i:03d}",
            "p_eq": float(rng.uniform(1.0, 5.0)),
            "lam": float(rng.uniform(0.05, 0.4)),
        }
        if rng.random() < 0.5:
            m["rocking"] = "one_sided"
        else:
            m["rocking"] = "two_sided"
            m["eta"] = float(rng.uniform(0.7, 0.98))
        if rng.random() < 0.5:
            h_e = float(rng.uniform(2.0, 15.0))
            m["amplification"] = {
                "f_n": float(rng.uniform(2.0, 10.0)),
                "h_e": h_e,
                "h": float(rng.uniform(0.5, 1.3) * h_e),
            }
        mechs.append(m)
    return parse_constants({"mechanisms": mechs})


def run_envelopes(quick: bool, lib_path: Path) -> dict[str, Any]:
    cf = random_mechanisms(N_MECHANISMS)
    f_p = frequency_grid(*F_RANGE_HZ, N_FREQUENCIES)
    t0 = time.perf_counter()
    lib = OverturningLibrary.load(lib_path)
    t_load = time.perf_counter() - t0
    t0 = time.perf_counter()
    envelope_doc(cf, f_p, library=lib)
    warm = time.perf_counter() - t0
    reps = 2 if quick else REPEATS_ENVELOPE
    t, times, (doc, envs) = best_of(lambda: envelope_doc(cf, f_p, library=lib), reps)
    t_exact, _, _ = best_of(lambda: envelope_doc(cf, f_p, method="exact"), 1)
    a = np.stack([e.a_p_min_g for e in envs])
    out = {
        "time_s": t,
        "exact_s": t_exact,
        "exact_points": doc.method.exact_points,
        "times": times,
        "warm_s": warm,
        "load_s": t_load,
        "lib_path": lib_path,
        "n_two": sum(m.rocking == "two_sided" for m in cf.mechanisms),
        "n_one": sum(m.rocking == "one_sided" for m in cf.mechanisms),
        "n_amp": sum(m.amplification is not None for m in cf.mechanisms),
        "n_bands": len(doc.critical),
        "n_governing": len({g for g in doc.governing if g is not None}),
        "n_finite": int(np.isfinite(a).sum()),
        "n_values": int(a.size),
        "a_range": (float(np.nanmin(a)), float(np.nanmax(a[np.isfinite(a)]))),
    }
    print(
        f"  envelope_doc, {N_MECHANISMS} mechanisms x {N_FREQUENCIES} f_p: best {fmt_time(t)} "
        f"of [{fmt_times(times)}]; library load {fmt_time(t_load)}, warm-up {fmt_time(warm)} "
        f"excluded; {out['n_bands']} critical bands",
        flush=True,
    )
    return out


def ivp_edge(omega: float) -> tuple[Optional[float], int]:
    """First change of outcome in ``IVP_BRACKET`` by bisection with ``simulate_ivp``.

    Dimensionless: ``p_eq = 1``, ``g lam = 1`` so that ``a_p = -A`` [m/s²] (first opens the
    mechanism, like ``boundary_curve``'s default direction) and ``f_p = Omega / (2 pi)``.
    Returns (edge or None, number of ``simulate_ivp`` runs).
    """
    model = RockingModel.symmetric(1.0, 1.0 / G, CURVE_ETA)
    f_p = omega / (2.0 * math.pi)
    n = 0

    def collapses(amp: float) -> bool:
        nonlocal n
        n += 1
        res = simulate_ivp(model, Pulse(a_p=-amp, f_p=f_p), rtol=IVP_RTOL, atol=IVP_ATOL)
        return bool(res.collapsed)

    lo, hi = IVP_BRACKET
    c_lo = collapses(lo)
    if collapses(hi) == c_lo:
        return None, n
    # The same stopping rule as the library's bisection (_kernels.boundary_grid).
    while hi - lo > IVP_BISECT_RTOL * hi:
        mid = 0.5 * (lo + hi)
        if collapses(mid) == c_lo:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi), n


def run_ivp(quick: bool, curve: BoundaryCurve) -> dict[str, Any]:
    n_om = IVP_N_OMEGA_QUICK if quick else IVP_N_OMEGA
    idx = np.unique(np.round(np.linspace(0, curve.omega.size - 1, n_om)).astype(int))
    # Warm-up: scipy.integrate is imported lazily on the first call.
    t0 = time.perf_counter()
    simulate_ivp(
        RockingModel.symmetric(1.0, 1.0 / G, CURVE_ETA),
        Pulse(a_p=-2.0, f_p=1.0 / (2.0 * math.pi)),
        rtol=IVP_RTOL,
        atol=IVP_ATOL,
    )
    warm = time.perf_counter() - t0
    rows: list[IvpRow] = []
    skipped = 0
    start = time.perf_counter()
    for i in idx:
        if time.perf_counter() - start > IVP_BUDGET_S:
            skipped += 1
            continue
        om = float(curve.omega[i])
        t0 = time.perf_counter()
        edge, n = ivp_edge(om)
        t = time.perf_counter() - t0
        row = IvpRow(om, t, n, edge, float(curve.a_min[i]), curve.intervals(int(i)))
        if edge is not None:
            # Outside the timing: does the exact integrator change outcome at this edge too?
            model = RockingModel.symmetric(1.0, 1.0 / G, CURVE_ETA)
            below, above = (
                bool(simulate(model, Pulse(a_p=-edge * f, f_p=om / (2.0 * math.pi))).collapsed)
                for f in (1.0 - EXACT_PROBE, 1.0 + EXACT_PROBE)
            )
            row.exact_around = (below, above)
        rows.append(row)
        print(
            f"  Omega {om:8.4f}: {n:3d} simulate_ivp runs, {fmt_time(t)}; A_ivp = "
            f"{'-' if edge is None else f'{edge:.7g}'}, boundary_curve a_min = "
            f"{row.a_min_bc:.7g}; {row.verdict()}",
            flush=True,
        )
    per_omega = float(np.mean([r.time_s for r in rows]))
    return {
        "rows": rows,
        "warm_s": warm,
        "skipped": skipped,
        "per_omega_s": per_omega,
        "extrapolated_s": per_omega * curve.omega.size,
        "total_s": sum(r.time_s for r in rows),
        "n_runs": sum(r.n_runs for r in rows),
    }


# ------------------------------------------------------------------------------------------
# Reporting
# ------------------------------------------------------------------------------------------

HEAD_KV = ["quantity", "value"]
HEAD_IVP = [
    "Omega",
    "simulate_ivp runs",
    "time",
    "A (solve_ivp bisection)",
    "a_min (boundary_curve)",
    "rel. diff",
    "boundary_curve intervals",
    "edge found",
]


def fmt_intervals(iv: list[tuple[float, Optional[float]]]) -> str:
    if not iv:
        return "none up to a_max"
    return " ".join(f"[{lo:.6g}, {'a_max' if hi is None else f'{hi:.6g}'}]" for lo, hi in iv)


def curve_rows(c: dict[str, Any]) -> list[list[str]]:
    cv: BoundaryCurve = c["curve"]
    return [
        ["call", f"boundary_curve(omega, {CURVE_ETA}) (two-sided, sine, direction -1)"],
        ["Omega", f"{cv.omega.size} log-spaced in [{cv.omega[0]:g}, {cv.omega[-1]:g}]"],
        ["search", f"A in (1, {cv.a_max:g}], scan ratio {cv.scan_ratio:.6f}, rtol {cv.rtol:g}"],
        ["time (best)", f"**{fmt_time(c['time_s'])}**"],
        ["all repeats", fmt_times(c["times"])],
        ["numba threads", f"{c['threads']} ({c['layer']})"],
        ["time with 1 thread (informative)", fmt_time(c["time_1thread_s"])],
        ["warm-up (excluded)", fmt_time(c["warm_s"])],
        ["edges found", f"{c['n_edges_total']} (most at one Omega: {c['n_edges_max']})"],
        ["Omega with more than one interval", str(c["n_multi"])],
        ["Omega with no overturning up to a_max", str(c["n_none"])],
        ["Omega collapsing already just above A = 1", str(c["n_at_start"])],
    ]


def library_rows(lb: dict[str, Any], quick: bool) -> list[list[str]]:
    call = (
        "build_library() (defaults)"
        if not quick
        else f"build_library(omega={lb['n_omega']} points, eta={list(QUICK_LIBRARY_ETA)}) (quick)"
    )
    return [
        ["call", f"{call} + save() to a temporary file"],
        [
            "curves",
            f"{lb['n_eta']} two-sided eta + one-sided in 2 directions = {lb['n_eta'] + 2} "
            f"curves x {lb['n_omega']} Omega; spectrum {lb['n_spectrum']} ratios",
        ],
        ["time (build + save, once)", f"**{fmt_time(lb['time_s'])}**"],
        [
            "breakdown",
            f"eta = 0 probe curve {fmt_time(lb['probe_s'])}; all {lb['n_eta'] + 2} curves done "
            f"at {fmt_time(lb['curves_s'])}; save {fmt_time(lb['save_s'])}",
        ],
        [
            "CPU time of the build (all threads)",
            f"{fmt_time(lb['cpu_s'])}; CPU / 2 = {fmt_time(lb['cpu_s'] / 2)}, the wall time "
            f"two free cores would give with perfect balance (load average before / after: "
            f"{lb['load']})",
        ],
        [
            "pulse spectrum alone (timed apart, after the build)",
            f"{fmt_time(lb['spectrum_s'])} wall, {fmt_time(lb['spectrum_cpu_s'])} CPU "
            f"({lb['n_spectrum']} ratios; in the build it runs on a thread beside the curves)",
        ],
        ["warm-up (excluded)", f"{fmt_time(lb['warm_s'])} (a 3 Omega x 2 eta library)"],
        [
            "same arrays as the shipped library",
            "not compared (quick run)"
            if lb["same_as_shipped"] is None
            else ("yes, bit for bit" if lb["same_as_shipped"] else "**NO**"),
        ],
        ["numba threads", f"{lb['threads']} ({lb['layer']})"],
        ["edges stored", str(lb["n_edges"])],
        ["file size", f"{lb['size_kb']:.0f} kB"],
    ]


def envelope_rows(ev: dict[str, Any]) -> list[list[str]]:
    lib_name = (
        "the shipped library"
        if Path(ev["lib_path"]).resolve() == LIBRARY_PATH.resolve()
        else "the library built above"
    )
    return [
        [
            "call",
            f"envelope_doc(cf, frequency_grid({F_RANGE_HZ[0]:g}, {F_RANGE_HZ[1]:g}, "
            f"{N_FREQUENCIES}), library=lib)",
        ],
        [
            "mechanisms",
            f"{N_MECHANISMS} (seed {SEED}): {ev['n_two']} two-sided, {ev['n_one']} one-sided; "
            f"{ev['n_amp']} amplified",
        ],
        ["time (best)", f"**{fmt_time(ev['time_s'])}**"],
        [
            "exact envelopes (the default), once",
            f"{fmt_time(ev['exact_s'])}; the fast mode computed {ev['exact_points']} of "
            f"{ev['n_values']} points exactly",
        ],
        ["all repeats", fmt_times(ev["times"])],
        ["per mechanism", fmt_time(ev["time_s"] / N_MECHANISMS)],
        ["library load (apart)", f"{fmt_time(ev['load_s'])} ({lib_name})"],
        ["warm-up (excluded)", fmt_time(ev["warm_s"])],
        [
            "result",
            f"{ev['n_finite']} of {ev['n_values']} a_p,min finite "
            f"({ev['a_range'][0]:.3g} to {ev['a_range'][1]:.3g} g); {ev['n_bands']} critical "
            f"bands, {ev['n_governing']} mechanisms govern somewhere",
        ],
    ]


def ivp_rows(iv: dict[str, Any]) -> list[list[str]]:
    out = []
    for r in iv["rows"]:
        out.append(
            [
                f"{r.omega:.4g}",
                str(r.n_runs),
                fmt_time(r.time_s),
                "-" if r.edge is None else f"{r.edge:.7g}",
                f"{r.a_min_bc:.7g}" if math.isfinite(r.a_min_bc) else "inf",
                "-" if math.isnan(r.rel_diff) else f"{r.rel_diff:.1e}",
                fmt_intervals(r.intervals_bc),
                r.verdict(),
            ]
        )
    return out


def ivp_summary(iv: dict[str, Any], c: dict[str, Any]) -> list[list[str]]:
    ratio = iv["extrapolated_s"] / c["time_s"]
    rows = [
        [
            "method",
            f"simulate_ivp DOP853, rtol {IVP_RTOL:g}, atol {IVP_ATOL:g}; bisection on "
            f"[{IVP_BRACKET[0]:g}, {IVP_BRACKET[1]:g}] to relative width {IVP_BISECT_RTOL:g} "
            "(one edge per Omega)",
        ],
        ["Omega measured", f"{len(iv['rows'])} of the {c['curve'].omega.size} (evenly spread)"],
        ["time for them", fmt_time(iv["total_s"]) + f" ({iv['n_runs']} simulate_ivp runs)"],
        ["mean time per Omega", fmt_time(iv["per_omega_s"])],
        [
            f"extrapolated to {c['curve'].omega.size} Omega",
            f"**{fmt_time(iv['extrapolated_s'])}**",
        ],
        [
            "boundary_curve, same 400 Omega, every interval in (1, 200]",
            fmt_time(c["time_s"]),
        ],
        ["speed ratio (extrapolated solve_ivp / boundary_curve)", f"**{ratio:.0f}x**"],
        ["warm-up (excluded)", fmt_time(iv["warm_s"])],
    ]
    if iv["skipped"]:
        rows.append(["skipped (time budget)", f"{iv['skipped']} Omega"])
    return rows


def targets(c: dict[str, Any], lb: dict[str, Any], ev: dict[str, Any], quick: bool) -> list:
    lib_ok = lb["time_s"] <= TARGET_LIBRARY_S and bool(lb["same_as_shipped"])
    lib_val = (
        f"{fmt_time(lb['time_s'])} (CPU {fmt_time(lb['cpu_s'])}, {lb['threads']} numba "
        f"threads, load {lb['load']}; same as shipped: {lb['same_as_shipped']})"
    )
    if quick:
        lib_ok, lib_val = None, f"not measured (quick run built a small library: {lib_val})"
    return [
        (
            f"one eta curve, {CURVE_OMEGA[2]} Omega, every interval to 1e-6 <= "
            f"{TARGET_CURVE_S:g} s",
            c["time_s"] <= TARGET_CURVE_S,
            fmt_time(c["time_s"]),
        ),
        (
            f"whole library build <= {TARGET_LIBRARY_S:g} s on 2 cores, the shipped arrays "
            f"bit for bit (this machine: "
            f"{lb['nproc']} cores)",
            lib_ok,
            lib_val,
        ),
        (
            f"{N_MECHANISMS} scaled, amplified envelopes + critical bands at {N_FREQUENCIES} "
            f"frequencies, fast mode <= {TARGET_FAST_RATIO:g} x the exact envelopes",
            ev["time_s"] <= TARGET_FAST_RATIO * ev["exact_s"],
            f"{fmt_time(ev['time_s'])} = {ev['time_s'] / ev['exact_s']:.3f} x "
            f"{fmt_time(ev['exact_s'])}",
        ),
    ]


def reading(c: dict[str, Any], lb: dict[str, Any], ev: dict[str, Any], iv: dict[str, Any]) -> str:
    """Return a short, data-driven reading for users."""
    ratio = iv["extrapolated_s"] / c["time_s"]
    rows = iv["rows"]
    at_min = [r for r in rows if r.kind == "a_min"]
    above = [r for r in rows if r.kind in ("later", "missed")]
    bad = [r for r in rows if r.kind in ("none?", "unconfirmed")]
    txt = (
        f"A full overturning curve (every interval at {CURVE_OMEGA[2]} frequencies) takes "
        f"{fmt_time(c['time_s'])} with the exact integrator, and the whole library "
        f"({lb['n_eta']} restitution coefficients plus one-sided rocking) "
        f"{fmt_time(lb['time_s'])}; it is built once and shipped, so users normally pay only "
        f"for loading it ({fmt_time(ev['load_s'])}). With the library loaded, the fast mode's "
        f"envelopes and critical bands of {N_MECHANISMS} mechanisms at {N_FREQUENCIES} "
        f"frequencies take {fmt_time(ev['time_s'])}, about "
        f"{fmt_time(ev['time_s'] / N_MECHANISMS)} per mechanism ({ev['exact_points']} points "
        f"computed exactly where the library cannot interpolate safely); the exact envelopes, "
        f"the default, take {fmt_time(ev['exact_s'])}. "
        f"Finding just one edge per frequency by bisection with `solve_ivp` would take about "
        f"{fmt_time(iv['extrapolated_s'])} for the same {CURVE_OMEGA[2]} frequencies, "
        f"{ratio:.0f} times longer than `boundary_curve`, which finds every interval."
    )
    if at_min:
        txt += (
            f" Where the bisection landed on `boundary_curve`'s a_min ({len(at_min)} of "
            f"{len(rows)} frequencies) the two agree to "
            f"{max(r.rel_diff for r in at_min):.1e}"
        )
        txt += ";" if above else "."
    if above:
        worst = max(r.rel_diff for r in above)
        txt += (
            f" {'at' if at_min else 'At'} {len(above)} frequencies it converged to a higher "
            f"edge, overstating the first overturning amplitude by up to {100 * worst:.1f} %"
        )
        missed = [r for r in above if r.kind == "missed"]
        if missed:
            txt += (
                f" ({len(missed)} of these edges `boundary_curve` does not report, but the "
                "exact integrator confirms them: safe islands narrower than the scan step "
                f"{c['curve'].scan_ratio:.4f}; near the uplift threshold the outcome alternates "
                "on such fine scales that a_min is resolved only to the scan, see "
                "`n_scan_near`)"
            )
        txt += "."
    if bad:
        txt += f" At {len(bad)} frequencies the two disagree (see the table)."
    txt += (
        f" The library build searches all {lb['n_eta'] + 2} curves in one parallel loop over "
        "(curve, Omega); the scan points where the eta = 0 curve overturns without any impact "
        "overturn for every eta (restitution acts only at impacts) and are not run again, and "
        "the pulse spectrum is computed on a thread beside the compiled search"
    )
    if lb["same_as_shipped"] is not None:
        txt += (
            "; the result equals the shipped library bit for bit"
            if lb["same_as_shipped"]
            else "; the result DIFFERS from the shipped library"
        )
    txt += (
        ". Times depend on the machine's load (given above); parallel parts (numba threads) "
        "suffer first, and the CPU time (all threads) shows the work apart from the load."
    )
    return txt


def write_docs(
    info: dict[str, str],
    c: dict[str, Any],
    lb: dict[str, Any],
    ev: dict[str, Any],
    iv: dict[str, Any],
    tgt: list,
    total_s: float,
    quick: bool,
) -> None:
    cmd = COMMAND + (" --quick --write-docs" if quick else "")
    lines = [
        "## Envelope speed (`benchmarks/envelope_speed.py`)",
        "",
        f"Latest figures of `benchmarks/envelope_speed.py`. Re-run with `{cmd}`; it rewrites "
        "this section only (the library it builds goes to a temporary file, never to the "
        "shipped `solver_service/data/overturning_library.npz`).",
        "",
        "### Machine and run",
        "",
        f"- Date: {info['date']}; rockmech commit: {info['commit']}",
        f"- CPU: {info['cpu']}; nproc = {info['nproc']}; numba threads = {c['threads']} "
        f"({c['layer']}); load average (1, 5, 15 min) at start: {info['load']}, at the end: "
        f"{info.get('load_end', '?')}",
        f"- {info['os']}",
        f"- Python {info['python']}, numpy {info['numpy']}, scipy {info['scipy']}, "
        f"numba {info['numba']}, pydantic {info['pydantic']}",
        f"- Command: `{cmd}`{' (quick smoke run)' if quick else ''}; whole run "
        f"{total_s / 60:.1f} min",
        "",
        "### Method",
        "",
        "- Time: `time.perf_counter` around the public call. The first call of each path "
        "(numba compilation or cache load, lazy imports) is a warm-up and is excluded; its "
        "time is in the tables.",
        f"- Curve: best of {REPEATS_CURVE}. Library: once (default grids) into a temporary "
        f"file. Envelopes: best of {REPEATS_ENVELOPE}, with the library loaded beforehand.",
        f"- Mechanisms: {N_MECHANISMS} symmetric mechanisms drawn with "
        f"`numpy.random.default_rng({SEED})`: p_eq uniform in [1, 5] rad/s, lam in "
        "[0.05, 0.4]; two-sided (eta uniform in [0.7, 0.98]) or one-sided (no eta) with equal "
        "probability; with probability 1/2 amplified, f_n in [2, 10] Hz, h_e in [2, 15] m, "
        "h in [0.5, 1.3] h_e. Parsed with `shared_schema.constants.parse_constants`.",
        "- Direct alternative: the dimensionless model `RockingModel.symmetric(1.0, 1/G, "
        "0.9)` under `Pulse(a_p=-A, f_p=Omega/(2 pi))`, outcome `simulate_ivp(...).collapsed`, "
        f"bisection on A in [{IVP_BRACKET[0]:g}, {IVP_BRACKET[1]:g}] to relative width "
        f"{IVP_BISECT_RTOL:g} (the library's stopping rule); Omega taken evenly from the "
        "curve's grid, and its edge compared with the curve's `a_min` at the same Omega. The "
        "extrapolation is the mean time per Omega times 400. Where the bisection's edge is "
        f"not within {MATCH_RTOL:g} of one of `boundary_curve`'s edges, the exact integrator "
        f"(`simulate`) is run at A (1 -/+ {EXACT_PROBE:g}), outside the timing, to see "
        "whether the outcome really changes there.",
        "",
        "### Results",
        "",
        "#### One eta curve",
        "",
        md_table(HEAD_KV, curve_rows(c)),
        "",
        "#### Library build",
        "",
        md_table(HEAD_KV, library_rows(lb, quick)),
        "",
        "#### Envelopes and critical bands",
        "",
        md_table(HEAD_KV, envelope_rows(ev)),
        "",
        "#### Direct alternative: first edge by bisection with `solve_ivp`",
        "",
        md_table(HEAD_IVP, ivp_rows(iv)),
        "",
        md_table(HEAD_KV, ivp_summary(iv, c)),
        "",
        "### Targets",
        "",
        md_table(
            ["target", "result", "measured"],
            [[name, verdict(ok), val] for name, ok, val in tgt],
        ),
        "",
        "### Reading",
        "",
        reading(c, lb, ev, iv),
    ]
    write_section(DOC_MD, "envelope_speed", "\n".join(lines))


# ------------------------------------------------------------------------------------------
# Main
# ------------------------------------------------------------------------------------------


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--quick", action="store_true", help="smoke run: small library, fewer repeats and Omega"
    )
    ap.add_argument(
        "--write-docs", action="store_true", help="write docs/benchmarks.md also in --quick mode"
    )
    args = ap.parse_args(argv)
    quick = bool(args.quick)
    write = (not quick) or args.write_docs
    wall0 = time.perf_counter()
    info = machine_info(("numpy", "scipy", "numba", "pydantic"))
    print(f"rockmech envelope speed benchmark ({'quick' if quick else 'full'} run)")
    print(
        f"{info['date']} | {info['cpu']} | nproc {info['nproc']} | load {info['load']} | "
        f"Python {info['python']} numpy {info['numpy']} scipy {info['scipy']} "
        f"numba {info['numba']}",
        flush=True,
    )
    with tempfile.TemporaryDirectory(prefix="rockmech-bench-") as tmp:
        print("\n1. One eta curve", flush=True)
        c = run_curve(quick)
        print("\n2. Library build", flush=True)
        lb = run_library(quick, Path(tmp))
        print("\n3. Envelopes and critical bands", flush=True)
        ev = run_envelopes(quick, LIBRARY_PATH if quick else lb["path"])
    print("\n4. Direct alternative: bisection with simulate_ivp", flush=True)
    iv = run_ivp(quick, c["curve"])

    print("\n" + "=" * 100)
    print("\nOne eta curve")
    print(text_table(HEAD_KV, [[k, v.replace("**", "")] for k, v in curve_rows(c)]))
    print("\nLibrary build")
    print(text_table(HEAD_KV, [[k, v.replace("**", "")] for k, v in library_rows(lb, quick)]))
    print("\nEnvelopes and critical bands")
    print(text_table(HEAD_KV, [[k, v.replace("**", "")] for k, v in envelope_rows(ev)]))
    print("\nDirect alternative: first edge by bisection with solve_ivp")
    print(text_table(HEAD_IVP, ivp_rows(iv)))
    print(text_table(HEAD_KV, [[k, v.replace("**", "")] for k, v in ivp_summary(iv, c)]))
    tgt = targets(c, lb, ev, quick)
    print("\nTargets")
    for name, ok, val in tgt:
        print(f"  {verdict(ok)}  {name}: {val}")
    total = time.perf_counter() - wall0
    info["load_end"] = load_average()
    print(f"\nWhole run: {total:.0f} s; load average at the end: {info['load_end']}")
    if write:
        write_docs(info, c, lb, ev, iv, tgt, total, quick)
        print(f"wrote the envelope_speed section of {DOC_MD.relative_to(REPO)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
