"""Stiff event sequences for the nonlinear reference: which solver settings stay accurate.

What is measured (issue 7, part 3)
----------------------------------
``simulate_nonlinear`` (Housner's block) with every ``solve_ivp`` method of the study and
several tolerances, on event sequences that strain a time stepper:

* **high p, free rocking**: ``p = 50 rad/s``, many impacts in a few seconds. Reference: the
  closed-form impact times (elliptic integrals of the energy, ``numerics_wp``), independent
  of any integrator. Error: largest impact-time error over the first ``N_FREE`` impacts,
  relative to the last of them;
* **high p on a record**: El Centro 1940 N-S on a block with ``p = 20 rad/s``;
* **a long record with many impacts**: ``LONG_S`` seconds of white noise on a block with
  ``p = 5 rad/s``.

For the two records the reference is ``simulate_nonlinear`` with DOP853 at rtol
``REF_RTOL`` (atol ``ATOL_FACTOR x rtol``), cross-checked against LSODA and Radau at rtol 1e-12
(their differences are printed); the error is the relative error of the peak
``|phi|/alpha``, and a run that counts a different number of impacts is flagged.

The recommended setting (``recommend``) reaches ``TARGET`` on every case with the
reference's impact count, is within ``COST_TIE`` of the cheapest such setting, and is the
most accurate of those; the product's defaults (``simulate_nonlinear``'s ``method``,
``rtol``, ``atol``) must equal it, and the report says whether they do.

Run ``.venv/bin/python benchmarks/stiff.py`` (part of ``make numerics``); it rewrites the
``stiff`` section of ``docs/numerics.md``. ``--quick`` runs fewer settings and writes
nothing.
"""

from __future__ import annotations

import argparse
import inspect
import math
import sys
import time
from pathlib import Path
from typing import Any, Optional

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from _docs import fmt_time, machine_info, md_table, write_section  # noqa: E402
from _numerics import DOC_MD, HEADER  # noqa: E402
from mpmath import mp, mpf  # noqa: E402
from numerics_wp import nl_impact_times  # noqa: E402

from solver_service.core.excitation import SampledAccel  # noqa: E402
from solver_service.core.model import G  # noqa: E402
from solver_service.core.nonlinear import HousnerBlock, simulate_nonlinear  # noqa: E402

METHODS = ("DOP853", "RK45", "LSODA", "Radau")
RTOLS = (1e-6, 1e-8, 1e-10, 1e-12)
RTOLS_QUICK = (1e-8, 1e-10)
#: Reference tolerance for the records.
REF_RTOL = 1e-13
#: Accuracy a recommended setting must reach on every case [-].
TARGET = 1e-9
#: A method's tighter tolerances are skipped once one run took this long [s].
SKIP_AFTER_S = 120.0
N_FREE = 40
LONG_S = 120.0
#: Settings within this factor of the fastest qualifying one count as equally cheap (timing
#: noise); among them the most accurate is recommended, ties going to the tighter rtol.
COST_TIE = 1.25
#: atol = ATOL_FACTOR * rtol (the default pairing of simulate_nonlinear: 1e-10 / 1e-12).
ATOL_FACTOR = 1e-2
RECORD = REPO / "examples" / "records" / "elcentro_NS.dat"


def _cases() -> list[dict[str, Any]]:
    data = np.loadtxt(RECORD)
    ec = SampledAccel(data[:, 1] * G, float(data[1, 0] - data[0, 0]), float(data[0, 0]))
    # Band-limited noise (white noise smoothed over 0.4 s): rocking needs low frequencies.
    rng = np.random.default_rng(31)
    n = int(LONG_S / 0.01) + 1
    win = np.hanning(41)
    noise_a = np.convolve(rng.normal(0.0, 1.0, n + 40), win / win.sum(), "valid")[:n]
    noise = SampledAccel(noise_a * 0.17 * G / np.max(np.abs(noise_a)), 0.01)
    p, alpha, eta, x0 = 50.0, 0.2, 0.95, 0.9
    ref_t = nl_impact_times(p, alpha, eta, x0, N_FREE)
    dur = float(ref_t[-1]) * 1.02
    return [
        {
            "key": "free",
            "title": f"high p, free rocking: p = {p:g} rad/s, alpha = {alpha}, eta = {eta}, "
            f"x0 = {x0} ({N_FREE} impacts in {float(ref_t[-1]):.2f} s)",
            "block": HousnerBlock(p=p, alpha=alpha, eta=eta),
            "exc": SampledAccel(np.zeros(201), dur / 200),
            "x0": x0,
            "ref_times": ref_t,
        },
        {
            "key": "elcentro",
            "title": "high p on a record: El Centro 1940 N-S x 0.6, p = 20 rad/s, "
            "alpha = 0.2, eta = 0.97 (chattering: hundreds of small impacts)",
            "block": HousnerBlock(p=20.0, alpha=0.2, eta=0.97),
            "exc": ec,
            "scale": 0.6,
            "x0": 0.0,
        },
        {
            "key": "long",
            "title": f"long record: {LONG_S:g} s of band-limited noise (dt 0.01 s, PGA "
            "0.17 g), p = 5 rad/s, alpha = 0.15, eta = 0.9",
            "block": HousnerBlock(p=5.0, alpha=0.15, eta=0.9),
            "exc": noise,
            "x0": 0.0,
        },
    ]


def _run(case: dict[str, Any], method: str, rtol: float) -> tuple[float, Any]:
    t0 = time.perf_counter()
    res = simulate_nonlinear(
        case["block"],
        case["exc"],
        scale=case.get("scale", 1.0),
        x0=case["x0"],
        method=method,
        rtol=rtol,
        atol=ATOL_FACTOR * rtol,
    )
    return time.perf_counter() - t0, res


def _free_error(case: dict[str, Any], res: Any) -> float:
    times = res.impacts[0]
    ref = case["ref_times"]
    k = min(len(times), len(ref))
    if k < len(ref):
        return math.inf
    with mp.workdps(30):
        return max(float(abs(mpf(times[i]) - ref[i])) for i in range(k)) / float(ref[-1])


def measure(quick: bool) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    cases = _cases()
    rows: list[dict[str, Any]] = []
    for case in cases:
        print(case["title"], flush=True)
        _run(case, "DOP853", 1e-6)  # warm-up (lazy imports, caches)
        if case["key"] != "free":
            t, ref = _run(case, "DOP853", REF_RTOL)
            case["ref"] = ref
            case["ref_time"] = t
            checks = []
            for m in ("LSODA", "Radau"):
                _, other = _run(case, m, 1e-12)
                checks.append(
                    f"{m} rtol 1e-12: peak differs by "
                    f"{abs(other.peak_ratio / ref.peak_ratio - 1):.1e}, impacts "
                    f"{other.n_impacts} vs {ref.n_impacts}"
                )
            case["checks"] = checks
            print(f"  reference {ref.peak_ratio!r}, {ref.n_impacts} impacts; " + "; ".join(checks))
        for method in METHODS:
            skip = False
            for rtol in RTOLS_QUICK if quick else RTOLS:
                if skip:
                    rows.append(
                        {
                            "case": case["key"],
                            "method": method,
                            "rtol": rtol,
                            "time": math.nan,
                            "error": math.nan,
                            "impacts_ok": False,
                            "estimate": math.nan,
                            "note": "skipped (too slow)",
                        }
                    )
                    continue
                t, res = _run(case, method, rtol)
                if case["key"] == "free":
                    err = _free_error(case, res)
                    ok = math.isfinite(err)
                    est = math.nan
                else:
                    ref = case["ref"]
                    err = abs(res.peak_ratio / ref.peak_ratio - 1.0)
                    ok = res.n_impacts == ref.n_impacts and res.collapsed == ref.collapsed
                    est = res.error_estimate / max(abs(res.peak_ratio - ref.peak_ratio), 1e-300)
                rows.append(
                    {
                        "case": case["key"],
                        "method": method,
                        "rtol": rtol,
                        "time": t,
                        "error": err,
                        "impacts_ok": ok,
                        "estimate": est,
                        "impacts": res.n_impacts,
                        "nfev": res.n_steps,
                        "note": "",
                    }
                )
                print(
                    f"  {method} rtol {rtol:.0e}: {fmt_time(t)}, error {err:.2e}, "
                    f"impacts {res.n_impacts} ({'same' if ok else 'DIFFERENT'})",
                    flush=True,
                )
                if t > SKIP_AFTER_S:
                    skip = True
    return cases, rows


def recommend(rows: list[dict[str, Any]], keys: list[str]) -> Optional[tuple[str, float, float]]:
    """Recommend (method, rtol, total time) among settings within ``TARGET`` on every case.

    The settings within ``COST_TIE`` of the fastest qualifying one are equally cheap; of
    those the most accurate (worst error over the cases) wins, errors within a factor 2
    counting as a tie won by the tighter rtol.
    """
    ok = []
    for m, rt in sorted({(r["method"], r["rtol"]) for r in rows}):
        sel = [r for r in rows if r["method"] == m and r["rtol"] == rt]
        if len(sel) != len(keys) or any(math.isnan(r["time"]) for r in sel):
            continue
        if all(r["error"] <= TARGET and r["impacts_ok"] for r in sel):
            total = sum(r["time"] for r in sel)
            worst = max(r["error"] for r in sel)
            ok.append((m, rt, total, worst))
    if not ok:
        return None
    fastest = min(t for _, _, t, _ in ok)
    cheap = [o for o in ok if o[2] <= COST_TIE * fastest]
    # Most accurate; errors within a factor 2 are a tie, won by the tighter tolerance.
    best_err = min(o[3] for o in cheap)
    tied = [o for o in cheap if o[3] <= 2.0 * max(best_err, 1e-300)]
    m, rt, total, _ = min(tied, key=lambda o: o[1])
    return m, rt, total


def defaults() -> tuple[str, float, float]:
    sig = inspect.signature(simulate_nonlinear)
    return (
        str(sig.parameters["method"].default),
        float(sig.parameters["rtol"].default),
        float(sig.parameters["atol"].default),
    )


def markdown(
    cases: list[dict[str, Any]], rows: list[dict[str, Any]], info: dict[str, str], total_s: float
) -> str:
    rec = recommend(rows, [c["key"] for c in cases])
    dm, dr, da = defaults()
    lines = [
        "## Stiff event sequences: the nonlinear reference (`benchmarks/stiff.py`)",
        "",
        f"Command: `.venv/bin/python benchmarks/stiff.py` (part of `make numerics`); "
        f"{total_s / 60:.1f} min on {info['cpu']}, nproc {info['nproc']}, load {info['load']} "
        f"at the start; {info['date']}, commit {info['commit']}. Times are provisional "
        "(shared machine).",
        "",
        f"`simulate_nonlinear` (atol = {ATOL_FACTOR:g} x rtol) on event sequences that "
        "strain a time stepper. References: closed-form impact times for free rocking; "
        f"for the records DOP853 at rtol {REF_RTOL:g}, cross-checked against other "
        "methods at rtol 1e-12 (below). Error: impact-time error (free rocking) or "
        "relative peak error (records); "
        "'impacts' says whether the run found the reference's impact count.",
        "",
    ]
    for case in cases:
        lines += [f"**{case['title']}**", ""]
        if "ref" in case:
            r = case["ref"]
            lines += [
                f"Reference peak {r.peak_ratio:.15g}, {r.n_impacts} impacts "
                f"({fmt_time(case['ref_time'])}); " + "; ".join(case["checks"]) + ".",
                "",
            ]
        sel = [r for r in rows if r["case"] == case["key"]]
        lines += [
            md_table(
                ["method", "rtol", "time", "error", "impacts", "estimate / true", "note"],
                [
                    [
                        r["method"],
                        f"{r['rtol']:.0e}",
                        fmt_time(r["time"]),
                        "-" if math.isnan(r["error"]) else f"{r['error']:.1e}",
                        "-"
                        if math.isnan(r["time"])
                        else ("same" if r["impacts_ok"] else f"DIFFERENT ({r.get('impacts')})"),
                        "-" if math.isnan(r["estimate"]) else f"{r['estimate']:.2g}",
                        r["note"],
                    ]
                    for r in sel
                ],
            ),
            "",
        ]
    if rec is None:
        verdict = f"No setting reached {TARGET:g} on every case."
    else:
        m, rt, tot = rec
        same = (m, rt) == (dm, dr) and math.isclose(da, ATOL_FACTOR * rt)
        verdict = (
            f"**Recommended:** {m} at rtol {rt:.0e} (atol = {ATOL_FACTOR:g} x rtol): within "
            f"{TARGET:g} on every case with the right impact count, within {COST_TIE:g}x of "
            f"the cheapest such setting ({fmt_time(tot)} over the three cases), and the most "
            f"accurate of those. The product's defaults are {dm}, rtol {dr:g}, atol "
            f"{da:g}: " + ("they are this recommendation." if same else "they DIFFER from it.")
        )
    lines += [
        verdict,
        "",
        "**Reading.** The rocking equation is not stiff in the ODE sense (its eigenvalues "
        "are +-p, real): what strains a time stepper is the sequence of events, each a "
        "restart of the integrator, and the exponential growth of errors between them. "
        "On records the restarts at every sample dominate the cost, so tightening rtol is "
        "almost free for the explicit methods; DOP853 reaches the smallest error for its "
        "cost, RK45's error follows rtol, implicit Radau costs 2 to 5 times more, and "
        "LSODA, though cheapest, miscounts impacts on both records at every tolerance "
        "(its interpolant locates events worst): do not use it for the reference. Loose "
        "tolerances change the impact count, so the verdict can change: never use scipy's "
        "default tolerances for the nonlinear reference (theory §10).",
    ]
    return "\n".join(lines)


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer settings; writes nothing")
    args = ap.parse_args(argv)
    wall0 = time.perf_counter()
    info = machine_info(("numpy", "scipy"))
    cases, rows = measure(args.quick)
    total = time.perf_counter() - wall0
    rec = recommend(rows, [c["key"] for c in cases])
    print(f"recommended: {rec}; defaults: {defaults()}; {total:.0f} s")
    if not args.quick:
        write_section(DOC_MD, "stiff", markdown(cases, rows, info, total), header=HEADER)
        print(f"wrote {DOC_MD.relative_to(REPO)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
