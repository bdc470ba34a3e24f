"""Work-precision study of every integrator in rockmech (issue 7, part 1).

What is measured
----------------
Error against run time, each error measured against a reference that is independent of
what is measured:

* **exact linear integrator and ``solve_ivp`` on the linear equation** (RK45, DOP853,
  Radau, LSODA at rtol 1e-3 ... 1e-12): the two cases of ``work_precision.py`` (a one-sine
  pulse and El Centro 1940 N-S) against the 30-digit mpmath reference ``mpref``. This run
  also rewrites the ``work_precision`` section of ``docs/benchmarks.md``;
* **nonlinear reference** (``simulate_nonlinear``, the same four methods at rtol 1e-4 ...
  1e-12): free rocking of Housner's block from rest, whose impact times are known in closed
  form (elliptic integrals of the energy, theory §2.1, evaluated with ``mpmath.quad`` at 30
  digits); error = largest error of the first ``NL_IMPACTS`` impact times over the last
  of them;
* **overturning-boundary search** (``envelope.boundary_curve``) at bisection widths rtol
  1e-2 ... 1e-9: one-sided rocking with ``eta = 0`` can only overturn without impact, so its
  boundary is the closed form of theory §6.3 (a) or (b), solved with ``mpmath.findroot`` at
  30 digits; error = largest relative error of ``A_min`` over ``N_OMEGA`` frequencies;
* **response spectrum** (``spectra.response_spectrum``, numba and numpy back ends, and,
  for comparison, the peak taken at the samples only with ``scipy.signal.lsim``): against
  an mpmath closed-form solution of the damped oscillator under the piecewise-linear record
  (peaks over continuous time, free vibration after the record included); error = largest
  relative error of the spectral displacement over the periods.

It also reports, for every result that carries one, the ratio ``error_estimate / true
error``. Output: the ``work_precision`` section of ``docs/numerics.md`` and
``docs/img/numerics_work_precision.png``.

Run ``.venv/bin/python benchmarks/numerics_wp.py`` (part of ``make numerics``); ``--quick``
runs fewer tolerances and writes nothing unless ``--write`` is given.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

import work_precision as wp  # noqa: E402
from _docs import best_of, fmt_time, machine_info, md_table, write_section  # noqa: E402
from _numerics import DOC_MD, HEADER, IMG  # noqa: E402
from mpmath import mp, mpf  # noqa: E402

from solver_service.core.envelope import boundary_curve  # noqa: E402
from solver_service.core.excitation import SampledAccel  # noqa: E402
from solver_service.core.nonlinear import HousnerBlock, simulate_nonlinear  # noqa: E402
from solver_service.core.spectra import response_spectrum  # noqa: E402

DPS = 30
#: Nonlinear free-rocking cases: (p [rad/s], alpha [rad], eta, x0).
NL_CASES = ((2.0, 0.2, 0.9, 0.9), (20.0, 0.6, 0.95, 0.9))
NL_METHODS = ("RK45", "DOP853", "Radau", "LSODA")
NL_RTOLS = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
NL_RTOLS_QUICK = (1e-6, 1e-10)
#: Impacts whose times are compared.
NL_IMPACTS = 20
#: Boundary search.
B_RTOLS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
B_RTOLS_QUICK = (1e-3, 1e-6)
N_OMEGA = 40
B_OMEGA = (0.1, 20.0)
#: Spectrum: periods [s] and record.
SPEC_PERIODS = (0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 5.0)
SPEC_N, SPEC_DT, SPEC_ZETA = 400, 0.01, 0.05
SPEC_SUBSTEPS = 16

PNG = IMG / "numerics_work_precision.png"


@dataclass
class Point:
    """One (method, setting) measurement."""

    family: str
    method: str
    setting: str
    time_s: float
    error: float
    estimate: float = math.nan
    note: str = ""


# ------------------------------------------------------------------------------------------
# Nonlinear free rocking: closed-form impact times
# ------------------------------------------------------------------------------------------


def nl_impact_times(p: float, alpha: float, eta: float, x0: float, n: int) -> list[Any]:
    """First ``n`` impact times [s] of Housner's block released from rest at ``x0 alpha``."""
    with mp.workdps(DPS):
        a, pp, e2 = mpf(alpha), mpf(p), mpf(eta) ** 2

        def quarter(phi0: Any) -> Any:
            # Energy: (phi'/p)²/2 = cos(a - phi0) - cos(a - phi); the 1/sqrt end singularity
            # is left to tanh-sinh quadrature.
            # cos(a - phi0) - cos(a - phi) = 2 sin(a - (phi0 + phi)/2) sin((phi0 - phi)/2):
            # no cancellation near the turning point.
            def f(phi: Any) -> Any:
                d = 2 * mp.sin(a - (phi0 + phi) / 2) * mp.sin((phi0 - phi) / 2)
                return 1 / mp.sqrt(2 * d)

            return mp.quad(f, [0, phi0]) / pp

        phi = mpf(x0) * a
        energy = mp.cos(a - phi)
        times = [quarter(phi)]
        for _ in range(n - 1):
            energy = mp.cos(a) + e2 * (energy - mp.cos(a))
            phi = a - mp.acos(energy)
            times.append(times[-1] + 2 * quarter(phi))
        return times


def run_nonlinear(quick: bool) -> list[Point]:
    pts = []
    for p, alpha, eta, x0 in NL_CASES:
        ref = nl_impact_times(p, alpha, eta, x0, NL_IMPACTS)
        dur = float(ref[-1]) * 1.02
        dt = dur / 400
        rec = SampledAccel(np.zeros(401), dt)
        blk = HousnerBlock(p=p, alpha=alpha, eta=eta)
        label = f"p={p:g}, alpha={alpha:g}"
        for method in NL_METHODS:
            for rtol in NL_RTOLS_QUICK if quick else NL_RTOLS:

                def call(
                    m: str = method,
                    r: float = rtol,
                    blk: HousnerBlock = blk,
                    rec: SampledAccel = rec,
                    x0: float = x0,
                ) -> Any:
                    return simulate_nonlinear(blk, rec, x0=x0, method=m, rtol=r, atol=1e-2 * r)

                t, _, res = best_of(call, 1 if quick else 3, budget_s=5.0)
                times = res.impacts[0] if res.impacts is not None else np.zeros(0)
                k = min(len(times), NL_IMPACTS)
                with mp.workdps(DPS):
                    err = max(
                        (float(abs(mpf(times[i]) - ref[i])) for i in range(k)), default=math.inf
                    ) / float(ref[-1])
                note = "" if k == NL_IMPACTS else f"{k} of {NL_IMPACTS} impacts"
                pts.append(
                    Point(
                        f"nonlinear free rocking ({label})",
                        method,
                        f"{rtol:.0e}",
                        t,
                        err,
                        note=note,
                    )
                )
                print(
                    f"  nonlinear {label} {method} rtol {rtol:.0e}: {fmt_time(t)}, "
                    f"error {err:.2e} {note}",
                    flush=True,
                )
    return pts


# ------------------------------------------------------------------------------------------
# Boundary search: one-sided eta = 0 against the closed forms
# ------------------------------------------------------------------------------------------


def closed_form_a(omega: float, case: str) -> float:
    """Mode-2 overturning amplitude A (theory §6.3 (a) or (b)) at 30 digits."""
    with mp.workdps(DPS):
        om = mpf(omega)
        if case == "a":

            def f(s: Any) -> Any:
                return om * mp.sin(s) - mp.cos(s) + mp.exp(-(2 * mp.pi - s) / om)
        else:

            def f(s: Any) -> Any:
                return om * mp.sin(s) - mp.cos(s) - mp.exp(-(mp.pi - s) / om)

        # f < 0 at s -> 0 and f > 0 at pi/2: a bracketed root.
        psi = mp.findroot(f, (mpf("1e-25"), mp.pi / 2), solver="anderson", tol=mp.eps)
        return float(1 / mp.sin(psi))


def run_boundary(quick: bool) -> list[Point]:
    omegas = np.geomspace(*B_OMEGA, N_OMEGA)
    pts = []
    for case, direction in (("a", -1), ("b", 1)):
        ref = np.array([closed_form_a(float(om), case) for om in omegas])
        boundary_curve(omegas[:2], 0.0, one_sided=True, direction=direction)  # warm-up
        for rtol in B_RTOLS_QUICK if quick else B_RTOLS:
            t, _, c = best_of(
                lambda r=rtol, d=direction: boundary_curve(
                    omegas, 0.0, one_sided=True, direction=d, rtol=r
                ),
                1 if quick else 3,
                budget_s=10.0,
            )
            err = float(np.max(np.abs(c.a_min / ref - 1.0)))
            pts.append(
                Point(
                    f"boundary, closed form ({case})",
                    "boundary_curve",
                    f"{rtol:.0e}",
                    t,
                    err,
                    estimate=rtol,
                )
            )
            print(
                f"  boundary ({case}) rtol {rtol:.0e}: {fmt_time(t)}, error {err:.2e}", flush=True
            )
    return pts


# ------------------------------------------------------------------------------------------
# Response spectrum against an mpmath closed form
# ------------------------------------------------------------------------------------------


def sd_reference(acc: np.ndarray, dt: float, period: float, zeta: float) -> float:
    """Peak |u| [m] of ``u'' + 2 zeta w u' + w² u = -a_g`` (linear between samples), mpmath."""
    with mp.workdps(DPS):
        w = 2 * mp.pi / mpf(period)
        z = mpf(zeta)
        wd = w * mp.sqrt(1 - z * z)
        h = mpf(dt)
        u, v = mpf(0), mpf(0)
        peak = mpf(0)

        def seg(u0: Any, v0: Any, a0: Any, a1: Any) -> tuple[Any, Any]:
            # Particular solution of the linear forcing; homogeneous part from (u0, v0).
            up0 = -a0 / w**2 + 2 * z * a1 / w**3
            vp = -a1 / w**2
            c1 = u0 - up0
            c2 = (v0 - vp + z * w * c1) / wd

            def state(t: Any) -> tuple[Any, Any]:
                ex = mp.exp(-z * w * t)
                cs, sn = mp.cos(wd * t), mp.sin(wd * t)
                uh = ex * (c1 * cs + c2 * sn)
                vh = ex * (-z * w * (c1 * cs + c2 * sn) + wd * (-c1 * sn + c2 * cs))
                return up0 + vp * t + uh, vp + vh

            return state  # type: ignore[return-value]

        def scan(state: Any, length: Any, n_sub: int) -> Any:
            best = mpf(0)
            lo = mpf(0)
            v_lo = state(lo)[1]
            for k in range(1, n_sub + 1):
                hi = length * k / n_sub
                u_hi, v_hi = state(hi)
                best = max(best, abs(u_hi))
                if v_lo * v_hi < 0:
                    tz = mp.findroot(lambda t: state(t)[1], (lo, hi), solver="anderson")
                    best = max(best, abs(state(tz)[0]))
                lo, v_lo = hi, v_hi
            return best

        a = [mpf(float(x)) for x in acc]
        for k in range(len(a) - 1):
            st = seg(u, v, a[k], (a[k + 1] - a[k]) / h)
            peak = max(peak, scan(st, h, SPEC_SUBSTEPS))
            u, v = st(h)
        free = seg(u, v, mpf(0), mpf(0))  # free vibration after the record: first periods
        peak = max(peak, scan(free, 2 * mpf(period), 64))
        return float(peak)


def run_spectrum(quick: bool) -> list[Point]:
    rng = np.random.default_rng(2026)
    acc = rng.normal(0.0, 2.0, SPEC_N)
    periods = np.array(SPEC_PERIODS)
    t0 = time.perf_counter()
    ref = np.array([sd_reference(acc, SPEC_DT, float(T), SPEC_ZETA) for T in periods])
    print(f"  spectrum reference: {time.perf_counter() - t0:.1f} s", flush=True)
    pts = []
    for backend in ("numba", "numpy"):
        response_spectrum(acc, SPEC_DT, periods, SPEC_ZETA, backend=backend)  # warm-up
        t, _, s = best_of(
            lambda b=backend: response_spectrum(acc, SPEC_DT, periods, SPEC_ZETA, backend=b),
            5 if not quick else 1,
        )
        err = float(np.max(np.abs(s.sd / ref - 1.0)))
        pts.append(Point("response spectrum", f"exact ({backend})", "-", t, err))
        print(f"  spectrum {backend}: {fmt_time(t)}, error {err:.2e}", flush=True)
    # The common shortcut: the oscillator's response at the samples only (scipy.signal.lsim,
    # linear interpolation of the input), missing the peaks between samples.
    from scipy import signal

    def at_samples() -> np.ndarray:
        out = np.empty(periods.size)
        tt = SPEC_DT * np.arange(acc.size + int(2 * periods.max() / SPEC_DT))
        aa = np.concatenate([acc, np.zeros(tt.size - acc.size)])
        for i, T in enumerate(periods):
            wn = 2 * math.pi / T
            sys_ = signal.lti([-1.0], [1.0, 2 * SPEC_ZETA * wn, wn * wn])
            _, y, _ = signal.lsim(sys_, aa, tt, interp=True)
            out[i] = np.max(np.abs(y))
        return out

    t, _, sd = best_of(at_samples, 3 if not quick else 1)
    err = float(np.max(np.abs(sd / ref - 1.0)))
    pts.append(Point("response spectrum", "scipy.signal.lsim, peak at samples", "-", t, err))
    print(f"  spectrum lsim: {fmt_time(t)}, error {err:.2e}", flush=True)
    return pts


# ------------------------------------------------------------------------------------------
# Linear integrators (from work_precision.py)
# ------------------------------------------------------------------------------------------


def run_linear(quick: bool) -> tuple[list[Any], dict[str, Any], dict[str, Any]]:
    """Measure the cases of ``work_precision.py`` (see ``work_precision.measure``)."""
    return wp.measure(quick)


def linear_points(cases: list[Any], results: dict[str, list[Any]]) -> list[Point]:
    pts = []
    for case in cases:
        fam = "linear, one-sine pulse" if case.key == "pulse" else "linear, El Centro"
        for r in results[case.key]:
            if math.isnan(r.time_s):
                continue
            pts.append(
                Point(
                    fam,
                    r.method,
                    "-" if r.rtol is None else f"{r.rtol:.0e}",
                    r.time_s,
                    r.rel_err,
                    estimate=r.err_est,
                )
            )
    return pts


# ------------------------------------------------------------------------------------------
# Report
# ------------------------------------------------------------------------------------------

FLOOR = 1e-17


def plot(pts: list[Point], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fams: dict[str, list[Point]] = {}
    for p in pts:
        fams.setdefault(p.family, []).append(p)
    n = len(fams)
    cols = 3
    rows_n = math.ceil(n / cols)
    fig, axes = plt.subplots(rows_n, cols, figsize=(5.2 * cols, 4.2 * rows_n), squeeze=False)
    for ax, (fam, fp) in zip(axes.flat, fams.items()):
        methods: dict[str, list[Point]] = {}
        for p in fp:
            methods.setdefault(p.method, []).append(p)
        for m, mp_ in methods.items():
            x = [q.time_s for q in mp_]
            y = [max(q.error, FLOOR) for q in mp_]
            marker = "*" if m.startswith("exact") else "o"
            size = 14 if marker == "*" else 5
            ax.loglog(x, y, marker=marker, ms=size, ls="-" if len(mp_) > 1 else "", label=m)
        ax.set_title(fam, fontsize=10)
        times = [q.time_s for q in fp]
        if max(times) < 10.0 * min(times):
            # A narrow time range: label the decades' minor ticks would overlap.
            from matplotlib.ticker import NullFormatter

            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("run time [s]")
        ax.set_ylabel("error")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.suptitle("Work-precision: error against run time (lower left is better)")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def fmt(x: float) -> str:
    if math.isnan(x):
        return "-"
    return "0" if x == 0.0 else f"{x:.1e}"


def ratio_str(p: Point) -> str:
    if math.isnan(p.estimate):
        return "-"
    if p.error == 0.0:
        return "inf"
    return f"{p.estimate / p.error:.2g}"


def markdown(pts: list[Point], info: dict[str, str], total_s: float, quick: bool) -> str:
    head = ["family", "method", "rtol", "time", "error", "estimate / true", "note"]
    rows = [
        [p.family, p.method, p.setting, fmt_time(p.time_s), fmt(p.error), ratio_str(p), p.note]
        for p in pts
    ]
    est = [p for p in pts if not math.isnan(p.estimate) and p.family.startswith("linear")]
    under = [p for p in est if p.error > p.estimate]
    fastest: dict[str, Point] = {}
    for p in pts:
        if p.error <= 1e-10 and (p.family not in fastest or p.time_s < fastest[p.family].time_s):
            fastest[p.family] = p
    cmd = ".venv/bin/python benchmarks/numerics_wp.py" + (" --quick --write" if quick else "")
    reading = [
        "**Reading.** Each panel is one problem; every point is one integrator at one "
        "setting, placed by its run time (x) and its error against the independent reference "
        "(y), so lower left is better. The exact linear integrator (stars) sits at rounding "
        "level (1e-15) in microseconds to a millisecond; time-stepping `solve_ivp` needs "
        "100 to 1000 times longer to come within 1e-10, and at loose tolerances it can be "
        "off by percents and miss impacts (LSODA). On a record every method restarts at "
        "each sample, so its cost hardly depends on rtol. The nonlinear reference: DOP853 "
        "is at rounding level at every tolerance for about the cost of RK45 (whose error "
        "follows rtol), LSODA is the least accurate and Radau, an implicit method, the most "
        "expensive, as the rocking equation is not stiff in the ODE sense (its cost here is "
        "dominated by the restarts at the record's samples and impacts). The boundary "
        "search is limited by its bisection width, as designed (its error is a few times "
        "below the requested rtol at about the same cost, since the amplitude scan "
        "dominates), and the response spectrum is exact to rounding, while taking the peak "
        "at the samples only misses it by percents at short periods."
    ]
    if fastest:
        reading.append(
            "Fastest setting within 1e-10 per problem: "
            + "; ".join(
                f"{f}: {p.method} {p.setting} ({fmt_time(p.time_s)})" for f, p in fastest.items()
            )
            + "."
        )
    reading.append(
        f"Error estimates: of {len(est)} linear results with an estimate, "
        + (
            f"{len(under)} undershoot their true error ("
            + ", ".join(f"{p.family} {p.method} {p.setting}" for p in under[:5])
            + ")."
            if under
            else "none undershoots its true error (column 'estimate / true' >= 1)."
        )
    )
    return "\n".join(
        [
            "## Work precision of every integrator (`benchmarks/numerics_wp.py`)",
            "",
            f"Command: `{cmd}` (part of `make numerics`); whole run {total_s / 60:.1f} min on "
            f"{info['cpu']}, nproc {info['nproc']}, load {info['load']} at the start; "
            f"{info['date']}, commit {info['commit']}. Python {info['python']}, numpy "
            f"{info['numpy']}, scipy {info['scipy']}, numba {info['numba']}, mpmath "
            f"{info['mpmath']}. Times were measured with other work sharing the machine and "
            "are provisional.",
            "",
            "References, each independent of what it measures: the linear cases against "
            "`benchmarks/mpref.py` (30-digit mpmath implementation of the linearised model, "
            "checked against closed forms in `tests/benchmarks_ref`); the nonlinear block "
            "against the closed-form impact times of free rocking (elliptic integrals of the "
            f"energy, `mpmath.quad` at {DPS} digits; error = largest impact-time error over "
            f"the first {NL_IMPACTS} impacts, relative to the last impact time); the boundary "
            "search against the mode-2 closed forms of theory §6.3 (one-sided rocking with "
            f"eta = 0, {N_OMEGA} Omega in [{B_OMEGA[0]:g}, {B_OMEGA[1]:g}], `mpmath.findroot`; "
            "error = largest relative error of A_min); the response spectrum against the "
            "closed-form damped-oscillator response to the piecewise-linear record in mpmath "
            f"({SPEC_N} random samples at dt = {SPEC_DT:g} s, zeta = {SPEC_ZETA:g}, "
            f"{len(SPEC_PERIODS)} periods from {SPEC_PERIODS[0]:g} to {SPEC_PERIODS[-1]:g} s; "
            "error = largest relative error of SD). Linear-case errors are relative errors of "
            "the peak |phi|/phi_ov (the tables of `docs/benchmarks.md` give them in full).",
            "",
            "![work-precision diagrams](img/numerics_work_precision.png)",
            "",
            "\n\n".join(reading),
            "",
            "'estimate / true' is the result's own `error_estimate` (relative to the peak for "
            "the linear cases; for the boundary search the requested rtol) over the measured "
            "error.",
            "",
            md_table(head, rows),
        ]
    )


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer tolerances; writes nothing")
    ap.add_argument("--write", action="store_true", help="write the outputs also with --quick")
    args = ap.parse_args(argv)
    quick = bool(args.quick)
    write = (not quick) or args.write
    wall0 = time.perf_counter()
    info = machine_info(("numpy", "scipy", "numba", "mpmath", "matplotlib"))
    print("linear integrators (work_precision.py cases)", flush=True)
    cases, results, extra = run_linear(quick)
    if write:
        wp.report(cases, results, extra, quick=quick, write=True)
    pts = linear_points(cases, results)
    print("nonlinear reference", flush=True)
    pts += run_nonlinear(quick)
    print("boundary search", flush=True)
    pts += run_boundary(quick)
    print("response spectrum", flush=True)
    pts += run_spectrum(quick)
    total = time.perf_counter() - wall0
    print(
        md_table(
            ["family", "method", "rtol", "time", "error", "est/true"],
            [
                [p.family, p.method, p.setting, fmt_time(p.time_s), fmt(p.error), ratio_str(p)]
                for p in pts
            ],
        )
    )
    if write:
        plot(pts, PNG)
        write_section(DOC_MD, "work_precision", markdown(pts, info, total, quick), header=HEADER)
        print(f"wrote {DOC_MD.relative_to(REPO)} and {PNG.relative_to(REPO)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
