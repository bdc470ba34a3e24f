"""Work-precision benchmark of the exact rocking integrator against time-stepping references.

What is measured
----------------
For two cases (a one-sine pulse and El Centro 1940 N-S), the error of the peak ratio
``max |phi|/phi_ov`` and the wall-clock time of:

* the exact integrator (``solver_service.core.exact.simulate``), numba and python back ends;
* the time-stepping reference ``simulate_ivp`` (RK45, DOP853, Radau, LSODA) at
  ``rtol = 1e-3 ... 1e-12`` with ``atol = ATOL_FACTOR * rtol``;
* the nonlinear Housner block (``simulate_nonlinear``, DOP853) with ``p = p_eq``,
  ``alpha = lam``: its "error" is the difference between the nonlinear and the linearised
  model (the linearisation difference), not an integration error, and is tabled apart.

The yardstick is an independent 30-digit mpmath implementation of the same linearised model
and rules (``benchmarks/mpref.py``). Errors are relative: ``|peak - peak_ref| / peak_ref``.

Also measured: 1000 scale factors of El Centro (``np.linspace(0.1, 3.0, 1000)``) in one
``simulate_batch`` call.

How
---
* Times are ``time.perf_counter`` around the public call, best of several repeats (see
  ``REPEATS_*``; a repeat series stops early once it has used ``REPEAT_BUDGET_S``).
* The first call of each exact back end (numba compilation or cache load, the python module
  copy) and of ``simulate_batch`` is a warm-up and is excluded; its time is printed.
* A ``simulate_ivp`` combination is skipped when the previous (looser) ``rtol`` of the same
  method took more than ``SKIP_AFTER_S`` or its time trend predicts more than that.
* Targets (PASS/FAIL): exact error <= 1e-10 (both cases); exact >= 1000x faster than DOP853
  at rtol 1e-12 measured in the same run (both cases); 1000 scale factors <= 0.3 s.

Run ``.venv/bin/python benchmarks/work_precision.py`` (or ``make bench``) for the full run,
which rewrites its section of ``docs/benchmarks.md`` (``_docs.write_section``) and
``docs/img/work_precision.png``; ``--quick`` is a smoke run (fewer tolerances and repeats) that
writes no docs unless ``--write-docs`` is given.
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

try:
    import mpmath  # noqa: F401
except ImportError:  # pragma: no cover - depends on the environment
    sys.exit("benchmarks/work_precision.py needs mpmath for its reference: pip install mpmath")

import mpref  # noqa: E402  (benchmarks/ is not a package)
from _docs import (  # noqa: E402
    best_of,
    fmt_time,
    machine_info,
    md_table,
    text_table,
    write_section,
)
from mpmath import mp, mpf  # noqa: E402

from solver_service.core.exact import simulate, simulate_batch  # noqa: E402
from solver_service.core.excitation import Pulse  # noqa: E402
from solver_service.core.model import G, RockingModel  # noqa: E402
from solver_service.core.nonlinear import HousnerBlock, simulate_nonlinear  # noqa: E402
from solver_service.core.records import GroundMotion  # noqa: E402
from solver_service.core.reference import simulate_ivp  # noqa: E402

#: solve_ivp methods compared.
IVP_METHODS = ("RK45", "DOP853", "Radau", "LSODA")
#: Relative tolerances of the full run.
RTOLS_FULL = tuple(10.0**-k for k in range(3, 13))
#: Relative tolerances of the quick run.
RTOLS_QUICK = (1e-3, 1e-8, 1e-12)
#: atol = ATOL_FACTOR * rtol (x is O(1); v is O(p)).
ATOL_FACTOR = 1e-2
#: Tolerances of the nonlinear reference.
NL_RTOLS_FULL = (1e-6, 1e-9, 1e-12)
NL_RTOLS_QUICK = (1e-9,)
#: A method's tighter tolerances are skipped once a run takes (or is predicted to take) this [s].
SKIP_AFTER_S = 60.0
#: Repeats (best of) for the exact numba back end, the python back end, references, batch.
REPEATS_NUMBA = 50
REPEATS_PYTHON = 3
REPEATS_REF = 3
REPEATS_BATCH = 3
#: A repeat series stops once its runs add up to this [s] (slow runs are timed fewer times).
REPEAT_BUDGET_S = 5.0
#: Errors of exactly 0 are drawn at this level in the diagram.
ERR_FLOOR = 1e-17
#: Targets.
TARGET_ERR = 1e-10
TARGET_SPEEDUP = 1000.0
TARGET_BATCH_S = 0.3
N_SCALES = 1000

RECORD = REPO / "examples" / "records" / "elcentro_NS.dat"
DOC_MD = REPO / "docs" / "benchmarks.md"
DOC_PNG = REPO / "docs" / "img" / "work_precision.png"

#: Pulse case: requested amplitude (the brief) and the one used (see ``pulse_case``).
PULSE_A_REQUESTED = 2.5
PULSE_A_USED = 1.3
PULSE_OMEGA_RATIO = 3.0


@dataclass
class Case:
    """One benchmark case."""

    key: str
    title: str
    label: str
    model: RockingModel
    excitation: Any
    block: HousnerBlock
    notes: list[str] = field(default_factory=list)
    ref: Any = None  # mpref.MPResult
    ref_time: float = 0.0


@dataclass
class Row:
    """One measured solver configuration."""

    method: str
    rtol: Optional[float]
    time_s: float
    peak: float
    rel_err: float
    n_impacts: int
    collapsed: bool
    repeats: int
    note: str = ""
    err_est: float = math.nan


# ------------------------------------------------------------------------------------------
# Helpers
# ------------------------------------------------------------------------------------------


def rel_err(peak: float, ref: Any) -> float:
    """``|peak - ref| / ref`` evaluated in mpmath (the float peak is exact in mpf)."""
    with mp.workdps(mpref.DPS):
        if ref == 0:
            return abs(float(peak))
        return float(abs(mpf(peak) - ref) / ref)


def fmt_err(e: float) -> str:
    if math.isnan(e):
        return "-"
    return "0" if e == 0.0 else f"{e:.1e}"


# ------------------------------------------------------------------------------------------
# Cases
# ------------------------------------------------------------------------------------------


def pulse_of(amp: float, lam: float, p_eq: float) -> Pulse:
    """One-sine pulse with ``A = |a_p|/(g lam)``, ``a_p < 0`` (first drives positive rotation)."""
    return Pulse(a_p=-amp * G * lam, f_p=PULSE_OMEGA_RATIO * p_eq / (2.0 * math.pi))


def pulse_case() -> Case:
    p_eq, lam, eta = 2.0, 0.2, 0.9
    model = RockingModel.symmetric(p_eq, lam, eta, name="pulse block")
    notes = []
    asked = mpref.simulate_mp(model, pulse_of(PULSE_A_REQUESTED, lam, p_eq))
    notes.append(
        f"The requested A = {PULSE_A_REQUESTED} collapses (mpmath reference: collapsed="
        f"{asked.collapsed}, {asked.n_impacts} impact(s)); at Omega = 3, eta = 0.9 the "
        "linearised model overturns from A = 1.404 (theory §6.5), so A = "
        f"{PULSE_A_USED} is used: a case with an impact and no collapse."
    )
    return Case(
        key="pulse",
        label=f"(a) one-sine pulse, Omega = {PULSE_OMEGA_RATIO:g}, A = {PULSE_A_USED}",
        title=(
            f"(a) one-sine pulse: p_eq = {p_eq}, lam = {lam}, eta = {eta}, "
            f"Omega = {PULSE_OMEGA_RATIO:g}, A = {PULSE_A_USED} (a_p = -{PULSE_A_USED} g lam "
            "< 0: first drives positive rotation)"
        ),
        model=model,
        excitation=pulse_of(PULSE_A_USED, lam, p_eq),
        block=HousnerBlock(p=p_eq, alpha=lam, eta=eta, name="pulse block"),
        notes=notes,
    )


def elcentro_case() -> Case:
    p_eq, lam, eta = 2.0, 0.15, 0.9
    rec = GroundMotion.from_two_column(RECORD, units="g")
    return Case(
        key="elcentro",
        label="(b) El Centro 1940 N-S, scale 1.0",
        title=(
            f"(b) El Centro 1940 N-S ({rec.accel.n} samples, dt = {rec.dt:g} s, "
            f"PGA {rec.pga_g:.3f} g), scale 1.0: p_eq = {p_eq}, lam = {lam}, eta = {eta}"
        ),
        model=RockingModel.symmetric(p_eq, lam, eta, name="El Centro block"),
        excitation=rec.accel,
        block=HousnerBlock(p=p_eq, alpha=lam, eta=eta, name="El Centro block"),
    )


# ------------------------------------------------------------------------------------------
# Measurements
# ------------------------------------------------------------------------------------------


def run_reference(case: Case) -> None:
    t0 = time.perf_counter()
    case.ref = mpref.simulate_mp(case.model, case.excitation)
    case.ref_time = time.perf_counter() - t0
    r = case.ref
    print(
        f"  mpmath reference ({r.dps} digits): peak = {mpref.mpf_str(r.peak, 25)}, "
        f"collapsed = {r.collapsed}, impacts = {r.n_impacts}, {case.ref_time:.1f} s",
        flush=True,
    )
    ok = (not r.collapsed) and r.n_impacts >= 1 and r.peak < 1
    if not ok:
        print("  WARNING: the case should have at least one impact and no collapse", flush=True)


def run_exact(case: Case, quick: bool) -> list[Row]:
    rows = []
    for backend, reps in (
        ("numba", 10 if quick else REPEATS_NUMBA),
        ("python", 1 if quick else REPEATS_PYTHON),
    ):
        t0 = time.perf_counter()
        simulate(case.model, case.excitation, backend=backend)
        warm = time.perf_counter() - t0
        t, times, res = best_of(
            lambda b=backend: simulate(case.model, case.excitation, backend=b),
            reps,
            budget_s=REPEAT_BUDGET_S,
        )
        n = len(times)
        rows.append(
            Row(
                method=f"exact ({backend})",
                rtol=None,
                time_s=t,
                peak=res.peak_ratio,
                rel_err=rel_err(res.peak_ratio, case.ref.peak),
                n_impacts=res.n_impacts,
                collapsed=res.collapsed,
                repeats=n,
                note=f"warm-up {fmt_time(warm)} excluded",
                err_est=res.error_estimate / max(res.peak_ratio, 1e-300),
            )
        )
        print(f"  {rows[-1].method}: {fmt_time(t)}, rel. error {fmt_err(rows[-1].rel_err)}")
    return rows


def run_ivp(case: Case, rtols: tuple[float, ...], quick: bool) -> list[Row]:
    rows: list[Row] = []
    for method in IVP_METHODS:
        times: list[float] = []
        skip_reason = ""
        for rtol in rtols:
            if skip_reason:
                rows.append(
                    Row(method, rtol, math.nan, math.nan, math.nan, -1, False, 0, skip_reason)
                )
                continue
            atol = ATOL_FACTOR * rtol

            def call(m: str = method, r: float = rtol, a: float = atol) -> Any:
                return simulate_ivp(case.model, case.excitation, method=m, rtol=r, atol=a)

            try:
                t, times, res = best_of(call, 1 if quick else REPEATS_REF, budget_s=REPEAT_BUDGET_S)
                n = len(times)
            except Exception as exc:  # report, do not stop the benchmark
                rows.append(
                    Row(method, rtol, math.nan, math.nan, math.nan, -1, False, 1, f"failed: {exc}")
                )
                print(f"  {method} rtol={rtol:.0e}: FAILED {exc}", flush=True)
                continue
            note = "" if res.success else f"status {res.status}"
            rows.append(
                Row(
                    method=method,
                    rtol=rtol,
                    time_s=t,
                    peak=res.peak_ratio,
                    rel_err=rel_err(res.peak_ratio, case.ref.peak),
                    n_impacts=res.n_impacts,
                    collapsed=res.collapsed,
                    repeats=n,
                    note=note,
                    err_est=res.error_estimate / max(res.peak_ratio, 1e-300),
                )
            )
            print(
                f"  {method} rtol={rtol:.0e}: {fmt_time(t)} (x{n}), "
                f"rel. error {fmt_err(rows[-1].rel_err)}, impacts {res.n_impacts}",
                flush=True,
            )
            times.append(t)
            growth = times[-1] / times[-2] if len(times) >= 2 else 1.0
            if t > SKIP_AFTER_S or t * max(growth, 1.0) > SKIP_AFTER_S:
                skip_reason = (
                    f"skipped: rtol {rtol:.0e} took {t:.1f} s, the next is predicted "
                    f"> {SKIP_AFTER_S:.0f} s"
                )
    return rows


def run_nonlinear(case: Case, rtols: tuple[float, ...]) -> list[Row]:
    rows = []
    for rtol in rtols:
        try:
            t, times, res = best_of(
                lambda r=rtol: simulate_nonlinear(
                    case.block, case.excitation, method="DOP853", rtol=r, atol=ATOL_FACTOR * r
                ),
                1,
                budget_s=REPEAT_BUDGET_S,
            )
            n = len(times)
        except Exception as exc:
            rows.append(Row("DOP853", rtol, math.nan, math.nan, math.nan, -1, False, 1, str(exc)))
            continue
        rows.append(
            Row(
                method="nonlinear DOP853",
                rtol=rtol,
                time_s=t,
                peak=res.peak_ratio,
                rel_err=rel_err(res.peak_ratio, case.ref.peak),
                n_impacts=res.n_impacts,
                collapsed=res.collapsed,
                repeats=n,
            )
        )
        print(
            f"  nonlinear rtol={rtol:.0e}: peak {res.peak_ratio:.12f}, {fmt_time(t)}, "
            f"linearisation difference {fmt_err(rows[-1].rel_err)}",
            flush=True,
        )
    if rows and not math.isnan(rows[-1].peak):
        tight = rows[-1].peak
        for r in rows:
            if not math.isnan(r.peak):
                r.err_est = abs(r.peak - tight) / tight  # self-convergence
    return rows


def run_batch(case: Case, quick: bool) -> dict[str, Any]:
    import numba

    scales = np.linspace(0.1, 3.0, N_SCALES)
    t0 = time.perf_counter()
    simulate_batch([case.model], case.excitation, scales)
    warm = time.perf_counter() - t0
    reps = 1 if quick else REPEATS_BATCH
    threads = numba.get_num_threads()
    t, times, res = best_of(
        lambda: simulate_batch([case.model], case.excitation, scales),
        reps,
        budget_s=REPEAT_BUDGET_S,
    )
    n = len(times)
    # Single-thread figure, to separate the per-core speed from the parallel speed-up (which
    # other load on the machine eats first).
    numba.set_num_threads(1)
    try:
        t1, _, _ = best_of(
            lambda: simulate_batch([case.model], case.excitation, scales),
            reps,
            budget_s=REPEAT_BUDGET_S,
        )
    finally:
        numba.set_num_threads(threads)
    out = {
        "time_s": t,
        "time_1thread_s": t1,
        "threads": threads,
        "warm_s": warm,
        "repeats": n,
        "n_collapsed": int(res.collapsed.sum()),
        "n_impacts_total": int(res.n_impacts.sum()),
        "all_success": bool((res.status >= 0).all()),
        "nproc": len(os.sched_getaffinity(0))
        if hasattr(os, "sched_getaffinity")
        else os.cpu_count(),
    }
    print(
        f"  {N_SCALES} scale factors: {fmt_time(t)} with {threads} numba threads (best of {n}; "
        f"warm-up {fmt_time(warm)} excluded), {fmt_time(t1)} with 1 thread; collapsed "
        f"{out['n_collapsed']}, total impacts {out['n_impacts_total']}",
        flush=True,
    )
    return out


# ------------------------------------------------------------------------------------------
# Reporting
# ------------------------------------------------------------------------------------------

HEAD_MAIN = ["method", "rtol", "time", "rel. error of peak", "peak", "impacts", "repeats", "note"]
HEAD_NL = [
    "method",
    "rtol",
    "time",
    "nonlinear peak",
    "linearisation difference",
    "self-convergence",
    "impacts",
    "collapsed",
]


def main_rows(rows: list[Row]) -> list[list[str]]:
    out = []
    for r in rows:
        note = r.note
        if r.method.startswith("exact"):
            note = f"{note}; own error estimate {r.err_est:.1e}".lstrip("; ")
        if r.collapsed:
            note = f"{note}; collapsed".lstrip("; ")
        out.append(
            [
                r.method,
                "-" if r.rtol is None else f"{r.rtol:.0e}",
                fmt_time(r.time_s),
                fmt_err(r.rel_err),
                "-" if math.isnan(r.peak) else f"{r.peak:.15f}",
                "-" if r.n_impacts < 0 else str(r.n_impacts),
                str(r.repeats),
                note,
            ]
        )
    return out


def nl_rows(rows: list[Row]) -> list[list[str]]:
    return [
        [
            r.method,
            f"{r.rtol:.0e}",
            fmt_time(r.time_s),
            "-" if math.isnan(r.peak) else f"{r.peak:.12f}",
            fmt_err(r.rel_err),
            fmt_err(r.err_est),
            "-" if r.n_impacts < 0 else str(r.n_impacts),
            str(r.collapsed),
        ]
        for r in rows
    ]


def plot(cases: list[Case], results: dict[str, list[Row]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(cases), figsize=(6.2 * len(cases), 5.0), squeeze=False)
    colors = {"RK45": "C0", "DOP853": "C1", "Radau": "C2", "LSODA": "C3"}
    for ax, case in zip(axes[0], cases):
        rows = results[case.key]
        for method in IVP_METHODS:
            pts = [r for r in rows if r.method == method and not math.isnan(r.time_s)]
            if not pts:
                continue
            xs = [math.log10(r.time_s) for r in pts]
            ys = [math.log10(max(r.rel_err, ERR_FLOOR)) for r in pts]
            ax.plot(xs, ys, "o-", color=colors[method], ms=4, label=f"solve_ivp {method}")
            ax.annotate(
                f"{pts[0].rtol:.0e}",
                (xs[0], ys[0]),
                fontsize=7,
                color=colors[method],
                textcoords="offset points",
                xytext=(4, 2),
            )
            ax.annotate(
                f"{pts[-1].rtol:.0e}",
                (xs[-1], ys[-1]),
                fontsize=7,
                color=colors[method],
                textcoords="offset points",
                xytext=(4, -8),
            )
        for r, mk, col in (
            (rows[0], "*", "k"),
            (rows[1], "D", "0.45"),
        ):
            ax.plot(
                math.log10(r.time_s),
                math.log10(max(r.rel_err, ERR_FLOOR)),
                mk,
                color=col,
                ms=13 if mk == "*" else 8,
                label=r.method.replace("exact", "exact integrator"),
                zorder=5,
            )
        ax.axhline(math.log10(TARGET_ERR), color="0.6", ls="--", lw=0.8)
        ax.text(
            ax.get_xlim()[0],
            math.log10(TARGET_ERR),
            " target 1e-10",
            va="bottom",
            fontsize=7,
            color="0.4",
        )
        ax.set_xlabel("log10 run time [s]")
        ax.set_ylabel("log10 relative error of peak |phi|/phi_ov")
        ax.set_title(case.label, fontsize=10)
        ax.grid(alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=6, fontsize=8, frameon=False)
    fig.suptitle(
        "Work-precision against the 30-digit mpmath reference "
        "(solve_ivp: rtol 1e-3 ... 1e-12 along each line; errors of 0 drawn at 1e-17)",
        fontsize=10,
    )
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".work_precision.", suffix=".png", dir=path.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=110)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    finally:
        plt.close(fig)
        if os.path.exists(tmp):
            os.unlink(tmp)


def pulse_batch_time(case: Case, quick: bool) -> float:
    """Per-simulation time [s] of the pulse case run 1000 times (amplitudes +-10 %) in one call."""
    scales = np.linspace(0.9, 1.1, N_SCALES)
    simulate_batch([case.model], case.excitation, scales)
    t, _, _ = best_of(
        lambda: simulate_batch([case.model], case.excitation, scales),
        1 if quick else 5,
        budget_s=REPEAT_BUDGET_S,
    )
    return t / N_SCALES


def targets(
    cases: list[Case], results: dict[str, list[Row]], batch: dict[str, Any], quick: bool = False
) -> list:
    out = []
    for case in cases:
        rows = results[case.key]
        for r in rows[:2]:
            out.append(
                (
                    f"{case.key}: {r.method} relative error <= {TARGET_ERR:.0e}",
                    r.rel_err <= TARGET_ERR,
                    fmt_err(r.rel_err),
                )
            )
        dop = [r for r in rows if r.method == "DOP853" and r.rtol == 1e-12]
        exact_t = rows[0].time_s
        if dop and not math.isnan(dop[0].time_s):
            ratio = dop[0].time_s / exact_t
            out.append(
                (
                    f"{case.key}: exact (numba) >= {TARGET_SPEEDUP:.0f}x faster than DOP853 "
                    "at rtol 1e-12",
                    ratio >= TARGET_SPEEDUP,
                    f"{ratio:.0f}x ({fmt_time(dop[0].time_s)} / {fmt_time(exact_t)})",
                )
            )
        else:
            out.append((f"{case.key}: speed-up vs DOP853 at rtol 1e-12", False, "not measured"))
        if case.key == "pulse" and dop and not math.isnan(dop[0].time_s):
            per_sim = pulse_batch_time(case, quick)
            ratio = dop[0].time_s / per_sim
            out.append(
                (
                    f"{case.key} (throughput, informative): exact in a 1000-pulse batch, per "
                    f"simulation, >= {TARGET_SPEEDUP:.0f}x faster than one DOP853 call",
                    ratio >= TARGET_SPEEDUP,
                    f"{ratio:.0f}x ({fmt_time(dop[0].time_s)} / {fmt_time(per_sim)})",
                )
            )
    out.append(
        (
            f"El Centro: {N_SCALES} scale factors in one simulate_batch call <= {TARGET_BATCH_S} s",
            batch["time_s"] <= TARGET_BATCH_S,
            fmt_time(batch["time_s"]),
        )
    )
    return out


def reading(cases: list[Case], results: dict[str, list[Row]], batch: dict[str, Any]) -> str:
    """Return a short, data-driven reading of the diagram for users."""
    parts = [
        "How to read the diagram: each line is one `solve_ivp` method, its points going from "
        "rtol 1e-3 to 1e-12; lower is more accurate, further left is faster. The star is the "
        "exact integrator (numba), the diamond the same code run as plain Python."
    ]
    for case in cases:
        rows = results[case.key]
        ex = rows[0]
        ivp = [r for r in rows[2:] if not math.isnan(r.time_s)]
        fastest = min(ivp, key=lambda r: r.time_s)
        good = [r for r in ivp if r.rel_err <= TARGET_ERR]
        wrong_imp = [r for r in ivp if r.n_impacts != case.ref.n_impacts]
        wrong_col = [r for r in ivp if r.collapsed != case.ref.collapsed]
        name = "the pulse" if case.key == "pulse" else "El Centro"
        txt = (
            f"On {name}, the exact integrator gives the peak to a relative error of "
            f"{fmt_err(ex.rel_err)} in {fmt_time(ex.time_s)}. The fastest time-stepping run "
            f"({fastest.method}, rtol {fastest.rtol:.0e}) takes {fmt_time(fastest.time_s)} and "
            f"is off by {fmt_err(fastest.rel_err)}."
        )
        if good:
            g = min(good, key=lambda r: r.time_s)
            txt += (
                f" The fastest time-stepping run within {TARGET_ERR:.0e} is {g.method} at rtol "
                f"{g.rtol:.0e}: {fmt_time(g.time_s)}, {g.time_s / ex.time_s:.0f} times the exact "
                "integrator's time."
            )
        else:
            txt += f" No time-stepping run reached {TARGET_ERR:.0e}."
        if wrong_imp:
            txt += (
                f" {len(wrong_imp)} of {len(ivp)} time-stepping runs count a different number "
                f"of impacts from the reference ({case.ref.n_impacts}), e.g. "
                + ", ".join(f"{r.method} rtol {r.rtol:.0e}: {r.n_impacts}" for r in wrong_imp[:3])
                + "."
            )
        if wrong_col:
            txt += f" {len(wrong_col)} of them get the collapse verdict wrong."
        parts.append(txt)
    loose = [r for c in cases for r in results[c.key][2:] if r.rtol == 1e-3]
    loose_max = max((r.rel_err for r in loose if not math.isnan(r.rel_err)), default=math.nan)
    bounded = all(results[c.key][0].rel_err <= results[c.key][0].err_est for c in cases)
    parts.append(
        "For a record, `simulate_ivp` restarts the integrator at every sample (0.02 s here), "
        "so its steps are short whatever the tolerance: its run time is dominated by a "
        "per-segment overhead and hardly changes with rtol, which is why the El Centro lines "
        "are nearly vertical. A loose tolerance is still not safe in general: at rtol 1e-3 "
        f"the worst error over both cases is {fmt_err(loose_max)}. The exact integrator has "
        "no tolerance to choose; its remaining error is rounding. "
        + (
            "Its own error estimate (in the tables) bounds the measured error in both cases."
            if bounded
            else "NOTE: its own error estimate did NOT bound the measured error in this run "
            "(see the tables)."
        )
    )
    parts.append(
        f"A whole incremental analysis of {N_SCALES} scale factors of El Centro takes "
        f"{fmt_time(batch['time_s'])} in one `simulate_batch` call on this {batch['nproc']}-core "
        "machine. Times depend on the machine's load (the load averages are given above); "
        "repeat the run before drawing conclusions from a ratio close to a target."
    )
    return "\n\n".join(parts)


def write_docs(
    info: dict[str, str],
    cases: list[Case],
    results: dict[str, list[Row]],
    nl: dict[str, list[Row]],
    batch: dict[str, Any],
    tgt: list,
    total_s: float,
    quick: bool,
) -> None:
    cmd = ".venv/bin/python benchmarks/work_precision.py" + (
        " --quick --write-docs" if quick else ""
    )
    lines = [
        "## Work precision (`benchmarks/work_precision.py`)",
        "",
        "Latest figures of `benchmarks/work_precision.py`. Re-run with `make bench` "
        f"(equivalently `{cmd}`); it rewrites this section and `docs/img/work_precision.png`.",
        "",
        "### Machine and run",
        "",
        f"- Date: {info['date']}; rockmech commit: {info['commit']}",
        f"- CPU: {info['cpu']}; nproc = {info['nproc']}; load average (1, 5, 15 min) at "
        f"start: {info['load']}, at the end: {info.get('load_end', '?')} (other work may share "
        "the machine; it slows the parallel batch first)",
        f"- {info['os']}",
        f"- Python {info['python']}, numpy {info['numpy']}, scipy {info['scipy']}, "
        f"numba {info['numba']}, mpmath {info['mpmath']}, matplotlib {info['matplotlib']}",
        f"- Command: `{cmd}`{' (quick smoke run)' if quick else ''}; whole run "
        f"{total_s / 60:.1f} min",
        "",
        "### Method",
        "",
        "- Yardstick: `benchmarks/mpref.py`, an independent implementation of the linearised "
        "model and of the exact integrator's rules in mpmath at 30 significant digits "
        "(closed form between events; turning points exact for records, impacts solved by "
        "`mpmath.findroot` to full precision). It takes the same float64 inputs as the "
        "solvers, so the difference is the float64 solver's error. "
        "`tests/benchmarks_ref/test_mpref.py` checks it against closed forms. It needs "
        "`mpmath` (`pip install mpmath`).",
        "- Error: `|peak - peak_ref| / peak_ref` of the peak `|phi|/phi_ov` over the motion "
        "(including the exact free-rocking tail after the excitation).",
        f"- `simulate_ivp`: atol = {ATOL_FACTOR:g} x rtol; records are restarted at every "
        "sample (the default `restart_at_samples=True`).",
        f"- Time: `time.perf_counter` around the public call; best of up to "
        f"{REPEATS_NUMBA} (exact numba), {REPEATS_PYTHON} (exact python), {REPEATS_REF} "
        f"(references) repeats, a series stopping once it has used {REPEAT_BUDGET_S:g} s. "
        "The first call of each exact back end and of `simulate_batch` (numba compilation "
        "or cache load) is excluded; its time is in the notes. One `simulate_ivp` call per "
        "method (the lazy scipy import) is also made before timing.",
        f"- Combinations are skipped when the looser tolerance of the same method took, or "
        f"is predicted to take, more than {SKIP_AFTER_S:.0f} s.",
        "",
        "### Results",
        "",
    ]
    for case in cases:
        r = case.ref
        lines += [
            f"#### {case.title}",
            "",
            f"Reference: peak = {mpref.mpf_str(r.peak, 25)}, collapsed = {r.collapsed}, "
            f"{r.n_impacts} impacts ({case.ref_time:.1f} s in mpmath).",
            "",
        ]
        lines += [f"{n}" for n in case.notes] + ([""] if case.notes else [])
        lines += [md_table(HEAD_MAIN, main_rows(results[case.key])), ""]
    lines += [
        "#### Nonlinear Housner block (linearisation difference, not an integration error)",
        "",
        "`simulate_nonlinear` with DOP853 for the block with p = p_eq and alpha = lam. "
        "'linearisation difference' is `|peak_nonlinear - peak_linear_ref| / "
        "peak_linear_ref`: how far the linearised model is from Housner's equation for this "
        "case (the nonlinear uplift threshold is g tan(alpha), not g alpha). "
        "'self-convergence' compares each tolerance with the tightest.",
        "",
    ]
    for case in cases:
        lines += [f"{case.label}:", "", md_table(HEAD_NL, nl_rows(nl[case.key])), ""]
    lines += [
        "#### Incremental analysis",
        "",
        f"{N_SCALES} scale factors `np.linspace(0.1, 3.0, {N_SCALES})` of El Centro on the "
        f"case (b) block in one `simulate_batch` call: **{fmt_time(batch['time_s'])}** with "
        f"{batch['threads']} numba threads (best of {batch['repeats']}; warm-up "
        f"{fmt_time(batch['warm_s'])} excluded), {fmt_time(batch['time_1thread_s'])} with one "
        "thread; "
        f"{batch['n_collapsed']} collapse, {batch['n_impacts_total']} impacts in all.",
        "",
        "### Targets",
        "",
        md_table(
            ["target", "result", "measured"],
            [[name, "PASS" if ok else "FAIL", val] for name, ok, val in tgt],
        ),
        "",
        "### Work-precision diagram",
        "",
        "![work-precision diagram](img/work_precision.png)",
        "",
        reading(cases, results, batch),
        "",
    ]
    # docs/benchmarks.md is shared: this benchmark rewrites only its own section.
    write_section(DOC_MD, "work_precision", "\n".join(lines))


# ------------------------------------------------------------------------------------------
# Main
# ------------------------------------------------------------------------------------------


def measure(quick: bool) -> tuple[list[Case], dict[str, list[Row]], dict[str, Any]]:
    """Run every measurement; return the cases, their rows and the extras (nonlinear, batch)."""
    wall0 = time.perf_counter()
    info = machine_info(("numpy", "scipy", "numba", "mpmath", "matplotlib"))
    print(f"rockmech work-precision benchmark ({'quick' if quick else 'full'} run)")
    print(
        f"{info['date']} | {info['cpu']} | nproc {info['nproc']} | load {info['load']} | "
        f"Python {info['python']} numpy {info['numpy']} scipy {info['scipy']} "
        f"numba {info['numba']} mpmath {info['mpmath']}",
        flush=True,
    )
    rtols = RTOLS_QUICK if quick else RTOLS_FULL
    nl_rtols = NL_RTOLS_QUICK if quick else NL_RTOLS_FULL
    cases = [pulse_case(), elcentro_case()]
    # Warm-up: the references import scipy.integrate lazily on their first call.
    t0 = time.perf_counter()
    for method in IVP_METHODS:
        simulate_ivp(cases[0].model, cases[0].excitation, method=method, rtol=1e-3, atol=1e-5)
    print(f"solve_ivp warm-up (scipy import) {fmt_time(time.perf_counter() - t0)} excluded")
    results: dict[str, list[Row]] = {}
    nl: dict[str, list[Row]] = {}
    for case in cases:
        print(f"\n{case.title}", flush=True)
        for n in case.notes:
            print(f"  note: {n}")
        run_reference(case)
        results[case.key] = run_exact(case, quick)
        results[case.key] += run_ivp(case, rtols, quick)
        nl[case.key] = run_nonlinear(case, nl_rtols)
    print("\nIncremental analysis", flush=True)
    batch = run_batch(cases[1], quick)
    extra = {"info": info, "nl": nl, "batch": batch, "wall0": wall0}
    return cases, results, extra


def report(
    cases: list[Case],
    results: dict[str, list[Row]],
    extra: dict[str, Any],
    *,
    quick: bool,
    write: bool,
) -> None:
    """Print the tables and targets; write docs/benchmarks.md and the diagram if ``write``."""
    info, nl, batch = extra["info"], extra["nl"], extra["batch"]
    print("\n" + "=" * 100)
    for case in cases:
        r = case.ref
        print(f"\n{case.title}")
        print(
            f"reference (mpmath, {r.dps} digits): peak = {mpref.mpf_str(r.peak, 25)}, "
            f"collapsed = {r.collapsed}, impacts = {r.n_impacts}"
        )
        print(text_table(HEAD_MAIN, main_rows(results[case.key])))
    print("\nNonlinear Housner block (p = p_eq, alpha = lam), DOP853: linearisation difference")
    print("(relative to the linear mpmath reference; NOT an integration error)")
    for case in cases:
        print(f"\n{case.label}")
        print(text_table(HEAD_NL, nl_rows(nl[case.key])))
    print(
        f"\n{N_SCALES} scale factors of El Centro, one simulate_batch call: "
        f"{fmt_time(batch['time_s'])} with {batch['threads']} numba threads (best of "
        f"{batch['repeats']}, warm-up {fmt_time(batch['warm_s'])} excluded); "
        f"{fmt_time(batch['time_1thread_s'])} with 1 thread"
    )
    tgt = targets(cases, results, batch, quick)
    print("\nTargets")
    for name, ok, val in tgt:
        print(f"  {'PASS' if ok else 'FAIL'}  {name}: {val}")
    total = time.perf_counter() - extra["wall0"]
    info["load_end"] = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"\nWhole run: {total:.0f} s; load average at the end: {info['load_end']}")
    if write:
        plot(cases, results, DOC_PNG)
        write_docs(info, cases, results, nl, batch, tgt, total, quick)
        print(f"wrote {DOC_MD.relative_to(REPO)} and {DOC_PNG.relative_to(REPO)}")


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke run: fewer rtols and repeats")
    ap.add_argument(
        "--write-docs",
        action="store_true",
        help="write docs/benchmarks.md and the diagram also in --quick mode",
    )
    args = ap.parse_args(argv)
    quick = bool(args.quick)
    cases, results, extra = measure(quick)
    report(cases, results, extra, quick=quick, write=(not quick) or args.write_docs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
