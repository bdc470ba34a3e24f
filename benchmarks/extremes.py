"""Extreme-case sweep: stability of every integrator on stiff, extreme and dangerous cases.

What is swept (issue 7)
-----------------------
* one-cycle pulses over a full grid: ``lam`` 1e-4 ... 1.4, ``eta`` -1 ... 1 (exactly 0 and
  1 included; negative values are one-sided rebound), ``p_eq`` 0.05 ... 100 rad/s,
  ``Omega = omega_p/p_eq`` 1e-3 ... 1e3, ``A = a_p/(g lam)`` 1 + 1e-12 ... 1e6, both shapes
  and both signs;
* records: white noise of up to 1e6 samples, ``dt`` 1e-5 ... 0.1 s, durations up to one
  hour, and El Centro 1940 N-S at scales up to 1e3;
* asymmetric two-sided mechanisms (``p`` and ``lam`` differing by 50x between sides);
* dangerous cases, built on purpose: grazing impacts (a parameter bisected until the body
  touches ``phi = 0`` with almost no velocity), Zeno sequences (free and forced), uplift
  exactly at the threshold, one-sided rebound with ``|eta| -> 1``, a pulse and a record that
  end at the instant of an impact, and an impact cap that is reached;
* Housner's nonlinear block (``simulate_nonlinear``) for ``alpha`` up to 1.4.

What every case must hold (``check``)
-------------------------------------
1. **finite**: ``peak_ratio``, ``t_peak``, ``error_estimate`` and the event times are finite;
   a body that does not collapse stays below the certain-collapse level
   ``1 + scale max|a_g|/(g lam)`` (theory §10);
2. **no hang**: the status is not -1 unless the case sets a small impact cap on purpose,
   and the work is bounded by the counters: closed-form stretches
   ``n_steps <= n_segments + n_uplifts + n_impact_events`` (every stretch starts at a
   segment boundary, an uplift or an impact), ``n_uplifts <= n_rests + 1`` and every impact
   event is either counted or ends in rest. Wall-clock time is reported, never asserted;
3. **energy**: at every impact the §1.8 energy ``E = (x'/p)**2 - (|x| - 1)**2`` (at ``x = 0``:
   ``(x'/p)**2 - 1``) does not increase, and the outgoing velocity points into the new side;
   for asymmetric mechanisms, whose sides have different normalisations, the angular speed
   ``|phi'|`` does not increase. Where the excitation is zero between two impacts, ``E`` is
   conserved (relative 1e-9);
4. **status and message**: ``collapsed`` iff status 1, status -1 iff the impact cap was
   reached, ``message`` starts with the status text, ``ratio_exceeded`` iff
   ``peak_ratio >= 1``, and the warning about an unresolved peak is there iff
   ``error_estimate >= exact.UNRESOLVED_ERROR``;
5. **honest error estimate**: where the 30-digit mpmath reference (``mpref``) is affordable
   (pulses with ``Omega >= 0.1`` and records of at most ``MP_MAX_SAMPLES`` samples), the
   true error ``|peak - peak_ref|`` must not exceed ``error_estimate``; the ratio
   ``estimate / true`` is reported for every such case.

The same case builders and checks run in the test suite on a reduced grid
(``tests/numerics/test_extremes.py``, ``cases("reduced")``).

Run ``.venv/bin/python benchmarks/extremes.py`` (or ``make numerics``): prints the summary and
rewrites the ``extremes`` section of ``docs/numerics.md``. ``--level reduced`` runs the test
grid.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from _docs import fmt_time, machine_info, md_table, write_section  # noqa: E402
from _numerics import DOC_MD, HEADER  # noqa: E402

from solver_service.core import _kernels  # noqa: E402
from solver_service.core.exact import (  # noqa: E402
    MAX_IMPACTS,
    UNRESOLVED_ERROR,
    V_REST_REL,
    cells_for,
    simulate,
)
from solver_service.core.excitation import Pulse, SampledAccel  # noqa: E402
from solver_service.core.model import G, RockingModel, RockingSide  # noqa: E402
from solver_service.core.nonlinear import HousnerBlock, simulate_nonlinear  # noqa: E402
from solver_service.core.result import STATUS_MESSAGES, RockingResult  # noqa: E402

#: Full grid (issue 7).
LAMS_FULL = (1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.0, 1.4)
ETAS_FULL = (-1.0, -0.999999, -0.5, 0.0, 0.5, 0.9, 0.999999, 1.0)
PS_FULL = (0.05, 1.0, 10.0, 100.0)
OMEGAS_FULL = (1e-3, 0.1, 1.0, 10.0, 1e3)
AMPS_FULL = (1.0 + 1e-12, 1.01, 2.0, 10.0, 1e3, 1e6)
#: Reduced grid (test suite).
LAMS_REDUCED = (1e-4, 0.2, 1.4)
ETAS_REDUCED = (-1.0, -0.5, 0.0, 0.9, 1.0)
PS_REDUCED = (0.05, 2.0, 100.0)
OMEGAS_REDUCED = (1e-3, 1.0, 5.0, 1e3)
AMPS_REDUCED = (1.0 + 1e-12, 1.3, 3.0, 1e6)
#: Records longer than this, or with more impacts, are not run through the mpmath reference
#: (it takes about 3 ms per sample and 10 ms per impact).
MP_MAX_SAMPLES = 3000
MP_MAX_IMPACTS_RECORD = 400
#: Pulses with fewer impacts than this (and Omega >= MP_MIN_OMEGA) get an mpmath reference.
MP_MAX_IMPACTS = 60
#: ``mpref`` searches turning points of a pulse response assuming ``x''`` has at most one zero
#: per cell (64 cells per quarter period, ``p h = 2 pi / (256 Omega)``). Below Omega = 1 that
#: fails for pulses hovering at the uplift threshold (A = 1 + 1e-12 at Omega = 0.1: mpref
#: gives 6.6e-12 at 30 digits and 4.5e-10 at 50, while the exact integrator and solve_ivp at
#: rtol 1e-13 agree on ~1e-21), so slower pulses are not compared with it.
MP_MIN_OMEGA = 1.0
#: Every MP_EVERY-th eligible pulse of the grid gets the mpmath reference.
MP_EVERY_FULL = 100
MP_EVERY_REDUCED = 10
#: Relative tolerance of the energy checks (rounding of one impact map).
ENERGY_RTOL = 1e-12
#: Relative tolerance of the speed (E conservation) between impacts in free motion; for the
#: nonlinear reference a floor of FREE_ABS_NL times the largest speed is added.
FREE_RTOL = 1e-9
FREE_ABS_NL = 1e-3
#: Bisection steps that tune the dangerous cases.
BISECT_STEPS = 80
#: One row per case of the full sweep (estimate / true error for every case).
CSV = REPO / "docs" / "numerics_sweep.csv"
#: Grazing record: the outward push acts from GRAZE_T to GRAZE_END [s].
GRAZE_T = 0.65
GRAZE_END = 1.0


@dataclass
class Case:
    """One sweep case: a model (or a Housner block), an excitation and run options."""

    name: str
    group: str
    model: Any  # RockingModel, or HousnerBlock for the nonlinear group
    excitation: Any
    scale: float = 1.0
    x0: float = 0.0
    t_extra: float = 0.0
    max_impacts: int = MAX_IMPACTS
    free: bool = False  # the excitation is zero: E is conserved between impacts
    expect_cap: bool = False  # the impact cap is reached on purpose
    mp_ref: bool = False  # compare with the mpmath reference
    note: str = ""

    @property
    def nonlinear(self) -> bool:
        """True for a Housner block (nonlinear reference)."""
        return isinstance(self.model, HousnerBlock)


@dataclass
class Outcome:
    """A case's result and what the checks found."""

    case: Case
    result: Optional[RockingResult]
    runtime_s: float
    n_segments: int
    violations: list[str] = field(default_factory=list)
    ref_peak: float = math.nan
    ref_collapsed: Optional[bool] = None
    true_error: float = math.nan
    ref_time_s: float = 0.0

    @property
    def ratio(self) -> float:
        """``error_estimate / true error`` (inf when the true error is 0)."""
        if self.result is None or math.isnan(self.true_error):
            return math.nan
        if self.true_error == 0.0:
            return math.inf
        return self.result.error_estimate / self.true_error


# ------------------------------------------------------------------------------------------
# Case builders
# ------------------------------------------------------------------------------------------


def _model(p: float, lam: float, eta: float, name: str = "m") -> RockingModel:
    return RockingModel.symmetric(p, lam, eta, one_sided=eta < 0.0, name=name)


def pulse_cases(level: str) -> Iterator[Case]:
    """Yield the pulse grid: lam x eta x p x Omega x A x shape x sign."""
    full = level == "full"
    grid = itertools.product(
        LAMS_FULL if full else LAMS_REDUCED,
        ETAS_FULL if full else ETAS_REDUCED,
        PS_FULL if full else PS_REDUCED,
        OMEGAS_FULL if full else OMEGAS_REDUCED,
        AMPS_FULL if full else AMPS_REDUCED,
        ("sine", "cosine") if full else ("sine",),
        (-1.0, 1.0),
    )
    for lam, eta, p, om, amp, shape, sign in grid:
        exc = Pulse(a_p=sign * amp * G * lam, f_p=om * p / (2.0 * math.pi), shape=shape)
        yield Case(
            name=f"pulse lam={lam:g} eta={eta:g} p={p:g} Omega={om:g} A={amp:.13g} "
            f"{shape} sign={sign:+g}",
            group="pulses",
            model=_model(p, lam, eta),
            excitation=exc,
            mp_ref=om >= MP_MIN_OMEGA,
        )


def _noise(n: int, dt: float, pga_g: float, seed: int) -> SampledAccel:
    rng = np.random.default_rng(seed)
    acc = rng.normal(0.0, 1.0, n)
    return SampledAccel(acc * (pga_g * G / np.max(np.abs(acc))), dt)


def _elcentro() -> SampledAccel:
    data = np.loadtxt(REPO / "examples" / "records" / "elcentro_NS.dat")
    return SampledAccel(data[:, 1] * G, float(data[1, 0] - data[0, 0]), float(data[0, 0]))


def record_cases(level: str) -> Iterator[Case]:
    """Long records, coarse and fine steps, high scales and asymmetric mechanisms."""
    full = level == "full"
    n_big = 1_000_000
    # (samples, dt, PGA [g]): 1e6 samples over 1 h; 1e6 at dt = 1e-5; 1 h at dt = 0.1.
    recs = [
        (n_big, 3600.0 / (n_big - 1), 0.5),
        (n_big if full else 200_000, 1e-5, 0.5),
        (36_001, 0.1, 0.5),
        (2_001, 1e-3, 0.8),
    ]
    for i, (n, dt, pga) in enumerate(recs):
        exc = _noise(n, dt, pga, seed=100 + i)
        dur = (n - 1) * dt
        combos = [(0.05, 0.1, 0.9), (100.0, 0.05, 0.999999), (2.0, 1e-4, 1.0), (10.0, 1.4, 0.0)]
        combos += [(20.0, 0.2, -1.0), (2.0, 0.2, -0.5)]
        if not full:
            combos = combos[::2] if n > 10_000 else combos
        for p, lam, eta in combos:
            yield Case(
                name=f"noise n={n} dt={dt:g} ({dur:.4g} s) PGA {pga} g: p={p:g} lam={lam:g} "
                f"eta={eta:g}",
                group="records",
                model=_model(p, lam, eta),
                excitation=exc,
                mp_ref=n <= MP_MAX_SAMPLES and full,
            )
    ec = _elcentro()
    scales = (0.5, 1.0, 3.0, 1e3) if full else (1.0, 1e3)
    for scale in scales:
        for p, lam, eta in ((2.0, 0.15, 0.9), (0.5, 0.01, 1.0), (5.0, 0.3, -0.7)):
            yield Case(
                name=f"El Centro x{scale:g}: p={p:g} lam={lam:g} eta={eta:g}",
                group="records",
                model=_model(p, lam, eta),
                excitation=ec,
                scale=scale,
                mp_ref=full or (scale == 1.0 and eta == 0.9),
            )
    # Asymmetric two-sided mechanisms: sides differ by 50x in p and lam.
    asym = [
        RockingModel(RockingSide(1.0, 0.02), RockingSide(50.0, 1.0, 1.3), eta=1.0, name="asym"),
        RockingModel(RockingSide(50.0, 1.0), RockingSide(1.0, 0.02, 0.5), eta=0.7, name="asym"),
    ]
    for k, m in enumerate(asym):
        for exc, label in ((ec, "El Centro"), (_noise(20_001, 0.005, 1.0, 7), "noise 100 s")):
            yield Case(
                name=f"asymmetric #{k + 1} on {label}",
                group="asymmetric",
                model=m,
                excitation=exc,
                mp_ref=exc.n <= MP_MAX_SAMPLES,
            )
        pl = Pulse(a_p=-3.0 * G * 0.02, f_p=2.0 / (2 * math.pi))
        yield Case(f"asymmetric #{k + 1} pulse", "asymmetric", m, pl, mp_ref=True)


def _zeros(duration: float, dt: float) -> SampledAccel:
    return SampledAccel(np.zeros(round(duration / dt) + 1), dt)


def _bisect(
    lo: float, hi: float, changed: Callable[[float], bool], steps: int = BISECT_STEPS
) -> tuple[float, float]:
    """Shrink ``[lo, hi]`` around the point where ``changed`` switches (False at lo)."""
    assert not changed(lo) and changed(hi)
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if changed(mid):
            hi = mid
        else:
            lo = mid
    return lo, hi


def _grazing_record(k: float, lam: float) -> SampledAccel:
    """Open, pull back, push outward at ``k g lam`` (0.65-1.0 s), pull back, then rest.

    With ``p = 2`` the body is on its way back at ``x ~ 0.35`` when the push starts; a weak
    push lets it impact before 1 s, a strong one turns it before ``x = 0``.
    """
    dt = 0.01
    t = np.arange(0.0, 2.5 + dt / 2, dt)
    levels = np.select(
        [t < 0.3, t < GRAZE_T, t < GRAZE_END, t < GRAZE_END + 0.5], [-3.0, 3.0, -k, 3.0], 0.0
    )
    return SampledAccel(levels * G * lam, dt)


def dangerous_cases(level: str) -> Iterator[Case]:
    """Cases built to hit the integrator's weak spots (see the module docstring)."""
    p, lam = 2.0, 0.2
    # Grazing: the outward push of the last phase is bisected between "impact" (weak push) and
    # "turns back before phi = 0" (strong push); at the boundary the body touches phi = 0 with
    # (almost) no velocity.
    for eta in (0.9, -0.5):
        m = _model(p, lam, eta)

        def no_impact(k: float, m: RockingModel = m) -> bool:
            log = simulate(m, _grazing_record(k, lam), impact_log=True).impacts
            assert log is not None
            return not np.any(log[0] < GRAZE_END)

        lo, hi = _bisect(1.0, 40.0, no_impact)
        for tag, k in (("impact side", lo), ("miss side", hi)):
            for rel in (0.0, 1e-12, 1e-8):
                kk = k * (1.0 - rel) if tag == "impact side" else k * (1.0 + rel)
                yield Case(
                    f"grazing eta={eta:g} ({tag}, push {kk:.17g} g lam)",
                    "grazing",
                    m,
                    _grazing_record(kk, lam),
                    mp_ref=True,
                )
    # Zeno: free rocking from x0 = 0.9, and forced Zeno under a steady inward pull below the
    # uplift threshold.
    etas_zeno = (0.5, 0.9, 0.99, 0.999, 0.999999) if level == "full" else (0.5, 0.999)
    for eta in etas_zeno:
        yield Case(
            f"Zeno free rocking eta={eta:g}, 1 h",
            "zeno",
            _model(p, lam, eta),
            _zeros(3600.0, 0.1),
            x0=0.9,
            free=True,
            mp_ref=eta <= 0.9,
        )
        # One-sided (rebound -eta): a two-sided body would be thrown over on the other side.
        # 0.5 g lam towards phi = 0; long enough for the cascade (about 2/(p (1 - eta)) s).
        n_pull, dt_pull = (2001, 0.01) if eta <= 0.9 else (36_001, 0.1)  # 20 s or 1 h
        pull = SampledAccel(np.full(n_pull, 0.5 * G * lam), dt_pull)
        yield Case(
            f"Zeno under a steady pull, one-sided eta={-eta:g}",
            "zeno",
            _model(p, lam, -eta),
            pull,
            x0=0.9,
            mp_ref=eta <= 0.9,
        )
    yield Case(
        "impact cap reached (max_impacts = 10)",
        "zeno",
        _model(p, lam, 0.9),
        _zeros(60.0, 0.05),
        x0=0.9,
        max_impacts=10,
        expect_cap=True,
    )
    # Elastic free rocking for an hour: eta = 1 two-sided and eta = -1 one-sided.
    for eta, pp in ((1.0, 20.0), (-1.0, 100.0), (-0.999999, 100.0)):
        yield Case(
            f"elastic free rocking eta={eta:g} p={pp:g}, 1 h",
            "rebound |eta| -> 1",
            _model(pp, lam, eta),
            _zeros(3600.0, 0.1),
            x0=0.5,
            free=True,
        )
    # Uplift exactly at the threshold: pulses with A = 1 (and one ulp either side), records
    # holding the threshold on a plateau or touching it at one sample.
    thr = G * lam
    for a_p in (-thr, -np.nextafter(thr, 0.0), -np.nextafter(thr, 1.0)):
        yield Case(
            f"pulse at the threshold a_p = {a_p!r}",
            "threshold",
            _model(p, lam, 0.9),
            Pulse(a_p=float(a_p), f_p=0.5),
            mp_ref=True,
        )
    for level_a in (-thr, -np.nextafter(thr, 1.0)):
        acc = np.zeros(401)
        acc[100:300] = level_a
        acc[99] = acc[300] = 0.5 * level_a
        yield Case(
            f"record with a plateau at {level_a!r}",
            "threshold",
            _model(p, lam, 0.9),
            SampledAccel(acc, 0.01),
            mp_ref=True,
        )
        spike = np.zeros(201)
        spike[100] = level_a
        yield Case(
            f"record touching {level_a!r} at one sample",
            "threshold",
            _model(p, lam, 0.9),
            SampledAccel(spike, 0.01),
            mp_ref=True,
        )
    # A pulse that ends at the instant of an impact: bisect the amplitude where the first
    # impact moves from inside the pulse to after its end.
    for eta in (0.9, -0.5):
        m = _model(p, lam, eta)
        f_p = 6.0 * p / (2.0 * math.pi)  # Omega = 6: the impact leaves the pulse near A = 3

        def pulse_of(amp: float, f_p: float = f_p) -> Pulse:
            return Pulse(a_p=-amp * thr, f_p=f_p)

        def impacts_inside(amp: float, m: RockingModel = m) -> bool:
            return simulate(m, pulse_of(amp)).n_impacts > 0

        grid = np.linspace(2.0, 3.6, 17)
        flags = [impacts_inside(a) for a in grid]
        for j in range(len(grid) - 1):
            if flags[j] != flags[j + 1]:
                lo, hi = _bisect_any(grid[j], grid[j + 1], impacts_inside)
                for amp in (lo, hi):
                    yield Case(
                        f"pulse ending at an impact eta={eta:g} A={amp:.17g}",
                        "ends mid-impact",
                        m,
                        pulse_of(amp),
                        mp_ref=True,
                    )
                break
    # A record that ends at the instant of an impact: bisect the scale factor.
    ec = _elcentro()
    short = SampledAccel(ec.acc[:400], ec.dt, ec.t0)
    m = _model(p, 0.15, 0.9)
    base = simulate(m, short).n_impacts

    def more_impacts(sc: float) -> bool:
        return simulate(m, short, scale=sc).n_impacts != base

    sc_hi = 1.0
    while not more_impacts(sc_hi * 1.01) and sc_hi < 1.5:
        sc_hi *= 1.01
    if more_impacts(sc_hi * 1.01):
        lo, hi = _bisect(sc_hi, sc_hi * 1.01, more_impacts)
        for sc in (lo, hi):
            yield Case(
                f"record ending at an impact (scale {sc:.17g})",
                "ends mid-impact",
                m,
                short,
                scale=sc,
                mp_ref=True,
            )


def _bisect_any(lo: float, hi: float, fn: Callable[[float], bool]) -> tuple[float, float]:
    """Bisect a change of ``fn`` between ``lo`` and ``hi`` whatever its sign at ``lo``."""
    f_lo = fn(lo)
    return _bisect(lo, hi, lambda z: fn(z) != f_lo)


def nonlinear_cases(level: str) -> Iterator[Case]:
    """Housner's block for alpha up to 1.4: pulses, a record and free rocking."""
    alphas = (0.01, 0.2, 0.8, 1.4) if level == "full" else (0.01, 1.4)
    ec = _elcentro()
    for alpha in alphas:
        eta = max(0.0, 1.0 - 1.5 * math.sin(alpha) ** 2)
        blk = HousnerBlock(p=2.0, alpha=alpha, eta=eta)
        thr = G * math.tan(alpha)
        for amp, om in ((1.0 + 1e-9, 1.0), (1.5, 3.0), (50.0, 50.0)):
            yield Case(
                f"nonlinear alpha={alpha:g} pulse A={amp:g} Omega={om:g}",
                "nonlinear",
                blk,
                Pulse(a_p=-amp * thr, f_p=om * 2.0 / (2 * math.pi)),
            )
        yield Case(
            f"nonlinear alpha={alpha:g} free rocking x0=0.9 (eta={eta:.3g})",
            "nonlinear",
            blk,
            _zeros(30.0, 0.05),
            x0=0.9,
            free=True,
        )
        sc = 1.5 * math.tan(alpha) / 0.349
        if level == "full" or alpha < 0.1:
            yield Case(
                f"nonlinear alpha={alpha:g} El Centro x{sc:.3g} (PGA 1.5 g tan alpha)",
                "nonlinear",
                blk,
                ec,
                scale=sc,
            )


def cases(level: str = "full") -> list[Case]:
    """Every case of the sweep at ``level`` ("full" or "reduced")."""
    if level not in ("full", "reduced"):
        raise ValueError(f"level must be 'full' or 'reduced', got {level!r}")
    out = [
        *pulse_cases(level),
        *record_cases(level),
        *dangerous_cases(level),
        *nonlinear_cases(level),
    ]
    return out


# ------------------------------------------------------------------------------------------
# Running and checking
# ------------------------------------------------------------------------------------------


def n_segments(case: Case) -> int:
    """Closed-form segments the exact integrator needs without events (work bound)."""
    if case.nonlinear:
        return 0
    cells = cells_for(case.excitation, t_extra=case.t_extra)
    p_max = max(case.model.positive.p_eq, case.model.neg.p_eq)
    widths = cells.widths
    return int(np.maximum(1.0, np.ceil(p_max * widths / _kernels.MAX_PH)).sum())


def run(case: Case) -> Outcome:
    """Run one case and check it (no reference)."""
    t0 = time.perf_counter()
    if case.nonlinear:
        res = simulate_nonlinear(
            case.model,
            case.excitation,
            scale=case.scale,
            x0=case.x0,
            max_impacts=min(case.max_impacts, 100_000),
        )
    else:
        res = simulate(
            case.model,
            case.excitation,
            scale=case.scale,
            x0=case.x0,
            t_extra=case.t_extra,
            max_impacts=case.max_impacts,
            impact_log=True,
        )
    runtime = time.perf_counter() - t0
    out = Outcome(case, res, runtime, n_segments(case))
    out.violations = check(case, res, out.n_segments)
    return out


def _amax(case: Case) -> float:
    exc = case.excitation
    amax = abs(exc.a_p) if isinstance(exc, Pulse) else float(np.max(np.abs(exc.acc)))
    return case.scale * amax


def check(case: Case, res: RockingResult, n_seg: int) -> list[str]:
    """Return the violated properties of one result (empty when all hold)."""
    bad: list[str] = []
    # 1. finite
    for name in ("peak_ratio", "t_peak", "error_estimate"):
        if not math.isfinite(getattr(res, name)):
            bad.append(f"{name} is not finite ({getattr(res, name)!r})")
    for name in ("t_ratio_exceeded", "t_collapse"):
        val = getattr(res, name)
        if val is not None and not math.isfinite(val):
            bad.append(f"{name} is not finite ({val!r})")
    if not res.error_estimate > 0.0:
        bad.append(f"error_estimate is not positive ({res.error_estimate!r})")
    if case.nonlinear:
        level = min(case.model.alpha + math.atan(_amax(case) / G), 0.5 * math.pi)
        level /= case.model.alpha
    else:
        lam_min = min(case.model.positive.lam, case.model.neg.lam)
        ratio_ov = max(
            case.model.positive.phi_ov / case.model.neg.phi_ov,
            case.model.neg.phi_ov / case.model.positive.phi_ov,
        )
        level = (1.0 + _amax(case) / (G * lam_min)) * ratio_ov
    if not res.collapsed and not res.peak_ratio <= level * (1.0 + 1e-9):
        bad.append(f"peak {res.peak_ratio:.6g} beyond the certain-collapse level {level:.6g}")
    # 2. no hang
    if res.status == -1 and not case.expect_cap:
        bad.append(f"impact cap reached ({res.n_impacts} impacts)")
    if case.expect_cap and res.status != -1:
        bad.append(f"expected the impact cap to stop the run, got status {res.status}")
    if res.status == -2:
        bad.append("non-finite state (status -2)")
    log = res.impacts
    n_events = 0 if log is None else log.shape[1]
    if not case.nonlinear:
        if res.n_steps > n_seg + res.n_uplifts + n_events:
            bad.append(
                f"work bound: n_steps {res.n_steps} > segments {n_seg} + uplifts "
                f"{res.n_uplifts} + impact events {n_events}"
            )
        if res.n_uplifts > res.n_rests + 1:
            bad.append(f"uplifts {res.n_uplifts} > rests {res.n_rests} + 1")
        if n_events > res.n_impacts + res.n_rests:
            bad.append(f"impact events {n_events} > counted {res.n_impacts} + rests {res.n_rests}")
    # 3. energy at impacts
    if log is not None and n_events:
        bad += _energy_violations(case, log)
    # 4. status and message
    if res.collapsed != (res.status == 1):
        bad.append(f"collapsed={res.collapsed} but status {res.status}")
    if not res.message.startswith(STATUS_MESSAGES[res.status]):
        bad.append(f"message {res.message!r} does not state status {res.status}")
    if res.success != (res.status >= 0):
        bad.append("success disagrees with status")
    if res.ratio_exceeded != (res.peak_ratio >= 1.0):
        bad.append(f"ratio_exceeded={res.ratio_exceeded} but peak_ratio {res.peak_ratio!r}")
    if not case.nonlinear:
        unresolved = any("not resolved" in w for w in res.warnings)
        if unresolved != (res.error_estimate >= UNRESOLVED_ERROR):
            bad.append(f"unresolved-peak warning {unresolved}, estimate {res.error_estimate:.3g}")
    return bad


def _energy_violations(case: Case, log: np.ndarray) -> list[str]:
    bad: list[str] = []
    t, side, v_in, v_out = log
    if case.nonlinear:
        one_sided = case.model.one_sided
        p_in = p_out = np.full(t.size, case.model.p)
        ov_in = ov_out = np.ones(t.size)
    else:
        m = case.model
        one_sided = m.one_sided
        new_side = side if one_sided else -side
        p_in = np.where(side > 0, m.positive.p_eq, m.neg.p_eq)
        p_out = np.where(new_side > 0, m.positive.p_eq, m.neg.p_eq)
        ov_in = np.where(side > 0, m.positive.phi_ov, m.neg.phi_ov)
        ov_out = np.where(new_side > 0, m.positive.phi_ov, m.neg.phi_ov)
    symmetric = case.nonlinear or case.model.is_symmetric
    if symmetric:
        # theory §1.8 at x = 0: E = (x'/p)^2 - 1 on both sides of the impact.
        e_in = (v_in / p_in) ** 2 - 1.0
        e_out = (v_out / p_out) ** 2 - 1.0
        gain = e_out - e_in
        tol = ENERGY_RTOL * (e_in + 1.0)
        k = np.flatnonzero(gain > tol)
        if k.size:
            bad.append(
                f"E increased at {k.size} impact(s), first at t = {t[k[0]]:.9g} s by "
                f"{gain[k[0]]:.3g}"
            )
    else:
        w_in = np.abs(v_in * ov_in)
        w_out = np.abs(v_out * ov_out)
        k = np.flatnonzero(w_out > w_in * (1.0 + ENERGY_RTOL))
        if k.size:
            bad.append(f"|phi'| increased at {k.size} impact(s), first at t = {t[k[0]]:.9g} s")
    new_side = side if one_sided else -side
    k = np.flatnonzero(new_side * v_out < 0.0)
    if k.size:
        bad.append(f"outgoing velocity points out of the new side at {k.size} impact(s)")
    # Below the rest speed an "impact" is rounding noise that ends in rest: its sign is not
    # meaningful (uplift with no excess over the threshold, sub-resolution excursions).
    counted = np.abs(v_in) >= V_REST_REL * p_in
    k = np.flatnonzero(counted & (side * v_in > 0.0))
    if k.size:
        bad.append(f"arriving velocity points away from phi = 0 at {k.size} impact(s)")
    if case.free and t.size > 1:
        # Between impacts of free motion E is conserved: the speed leaving impact k equals
        # the speed arriving at impact k+1 (the same side, the same p).
        # The nonlinear reference integrates with an absolute tolerance, so the tiny speeds at
        # the end of a Zeno cascade carry an absolute error of the order of the tolerance
        # times the initial speed; the exact integrator is held to the relative test alone.
        keep = v_out[:-1] != 0.0
        a, b = np.abs(v_out[:-1][keep]), np.abs(v_in[1:][keep])
        if a.size:
            v_abs = FREE_ABS_NL * float(np.max(a)) if case.nonlinear else 0.0
            dev = np.max(np.abs(a - b) / np.maximum(a + v_abs, 1e-300))
            if dev > FREE_RTOL:
                bad.append(f"E not conserved in free motion (relative change {dev:.3g})")
    return bad


def reference(out: Outcome) -> None:
    """Add the mpmath reference and the true error to ``out`` (the case must allow it)."""
    import mpref

    case = out.case
    t0 = time.perf_counter()
    ref = mpref.simulate_mp(case.model, case.excitation, scale=case.scale, x0=case.x0)
    out.ref_time_s = time.perf_counter() - t0
    out.ref_peak = float(ref.peak)
    out.ref_collapsed = ref.collapsed
    assert out.result is not None
    from mpmath import mp, mpf

    with mp.workdps(mpref.DPS):
        out.true_error = float(abs(mpf(out.result.peak_ratio) - ref.peak))
    if out.true_error > out.result.error_estimate:
        out.violations.append(
            f"error estimate {out.result.error_estimate:.3g} below the true error "
            f"{out.true_error:.3g} (mpmath peak {mpref.mpf_str(ref.peak, 20)})"
        )


def wants_reference(out: Outcome, every: int, counter: list[int]) -> bool:
    """Whether this outcome gets an mpmath reference (eligible, affordable, sampled)."""
    case, res = out.case, out.result
    if not case.mp_ref or case.nonlinear or res is None:
        return False
    if isinstance(case.excitation, SampledAccel):
        return case.excitation.n <= MP_MAX_SAMPLES and res.n_impacts <= MP_MAX_IMPACTS_RECORD
    if res.n_impacts > MP_MAX_IMPACTS:
        return False
    if case.group != "pulses":
        return True
    counter[0] += 1
    return counter[0] % every == 0


def sweep(level: str, verbose: bool = False) -> list[Outcome]:
    """Run (and check) every case of ``level``, with mpmath references where eligible."""
    outs = []
    every = MP_EVERY_FULL if level == "full" else MP_EVERY_REDUCED
    counter = [0]
    group = ""
    t_group = time.perf_counter()
    for case in cases(level):
        if verbose and case.group != group:
            print(f"{case.group} ({time.perf_counter() - t_group:.0f} s so far)", flush=True)
            group = case.group
        try:
            out = run(case)
        except Exception as exc:  # report, never stop the sweep
            out = Outcome(case, None, math.nan, 0, [f"raised {type(exc).__name__}: {exc}"])
        if wants_reference(out, every, counter):
            reference(out)
        if verbose and (out.violations or out.runtime_s > 1.0):
            print(f"  {case.name}: {fmt_time(out.runtime_s)} {out.violations}", flush=True)
        outs.append(out)
    return outs


# ------------------------------------------------------------------------------------------
# Report
# ------------------------------------------------------------------------------------------


def _fmt(x: float) -> str:
    if isinstance(x, float) and math.isnan(x):
        return "-"
    if x == math.inf:
        return "inf"
    return f"{x:.2g}"


def summary_rows(outs: list[Outcome]) -> list[list[str]]:
    groups: dict[str, list[Outcome]] = {}
    for o in outs:
        groups.setdefault(o.case.group, []).append(o)
    rows = []
    for g, os_ in groups.items():
        ok = [o for o in os_ if o.result is not None]
        refs = [o for o in ok if not math.isnan(o.true_error)]
        ratios = [o.ratio for o in refs]
        rows.append(
            [
                g,
                str(len(os_)),
                str(sum(1 for o in os_ if o.violations)),
                str(sum(1 for o in ok if o.result.collapsed)),  # type: ignore[union-attr]
                str(max((o.result.n_impacts for o in ok), default=0)),  # type: ignore[union-attr]
                str(max((o.result.n_steps for o in ok), default=0)),  # type: ignore[union-attr]
                fmt_time(max((o.runtime_s for o in ok), default=math.nan)),
                _fmt(max((o.result.error_estimate for o in ok), default=math.nan)),  # type: ignore[union-attr]
                str(len(refs)),
                _fmt(max((o.true_error for o in refs), default=math.nan)),
                _fmt(min(ratios, default=math.nan)),
            ]
        )
    return rows


SUMMARY_HEAD = [
    "group",
    "cases",
    "violations",
    "collapsed",
    "max impacts",
    "max steps",
    "max time",
    "max estimate",
    "mpmath refs",
    "max true error",
    "min estimate/true",
]


def worst_rows(outs: list[Outcome], n: int = 5) -> list[tuple[str, list[list[str]]]]:
    ok = [o for o in outs if o.result is not None]

    def row(o: Outcome, what: str) -> list[str]:
        r = o.result
        assert r is not None
        return [
            o.case.name,
            what,
            str(r.status),
            str(r.n_impacts),
            str(r.n_steps),
            fmt_time(o.runtime_s),
            f"{r.error_estimate:.2g}",
            _fmt(o.true_error),
        ]

    by_time = sorted(ok, key=lambda o: -o.runtime_s)[:n]
    by_imp = sorted(ok, key=lambda o: -o.result.n_impacts)[:n]  # type: ignore[union-attr]
    by_est = sorted(ok, key=lambda o: -o.result.error_estimate)[:n]  # type: ignore[union-attr]
    refs = [o for o in ok if not math.isnan(o.true_error) and o.true_error > 0.0]
    by_ratio = sorted(refs, key=lambda o: o.ratio)[:n]
    by_true = sorted(refs, key=lambda o: -o.true_error)[:n]
    return [
        ("longest run time", [row(o, "time") for o in by_time]),
        ("most impacts", [row(o, "impacts") for o in by_imp]),
        ("largest error estimate", [row(o, "estimate") for o in by_est]),
        ("largest true error (mpmath)", [row(o, "true error") for o in by_true]),
        (
            "tightest estimate (smallest estimate/true)",
            [row(o, f"ratio {_fmt(o.ratio)}") for o in by_ratio],
        ),
    ]


WORST_HEAD = ["case", "why listed", "status", "impacts", "steps", "time", "estimate", "true"]


def ratio_histogram(outs: list[Outcome]) -> list[list[str]]:
    """Count estimate/true in decades (inf: the result equals the reference)."""
    refs = [o for o in outs if not math.isnan(o.true_error)]
    bins = [(0.0, 1.0), (1.0, 1e1), (1e1, 1e2), (1e2, 1e3), (1e3, 1e4), (1e4, math.inf)]
    rows = []
    for lo, hi in bins:
        k = sum(1 for o in refs if lo <= o.ratio < hi)
        rows.append([f"[{_fmt(lo)}, {_fmt(hi)})", str(k)])
    rows.append(["exact match (true error 0)", str(sum(1 for o in refs if o.ratio == math.inf))])
    return rows


def markdown(outs: list[Outcome], info: dict[str, str], level: str, total_s: float) -> str:
    n_bad = sum(1 for o in outs if o.violations)
    cmd = ".venv/bin/python benchmarks/extremes.py" + (
        " --level reduced" if level != "full" else ""
    )
    lines = [
        "## Extreme-case sweep (`benchmarks/extremes.py`)",
        "",
        f"Command: `{cmd}` (part of `make numerics`); whole run {total_s / 60:.1f} min on "
        f"{info['cpu']}, nproc {info['nproc']}, load {info['load']} at the start; "
        f"{info['date']}, commit {info['commit']}. Times were measured with other work "
        "sharing the machine and are provisional.",
        "",
        f"**{len(outs)} cases, {n_bad} with a violated property.** Each case is checked for: "
        "finite outputs and a peak below the certain-collapse level; no hang (status -1 only "
        "where a small impact cap is set on purpose, and the work counters within "
        "`n_steps <= n_segments + n_uplifts + n_impact_events`); E of theory §1.8 never "
        "increased by an impact (angular speed for asymmetric mechanisms) and conserved "
        "between impacts of free motion; status, message and warnings consistent with the "
        "outcome; and, where the 30-digit mpmath reference is affordable, "
        "`error_estimate >= |peak - peak_mpmath|`. The test suite runs the same checks on a "
        "reduced grid (`tests/numerics/test_extremes.py`).",
        "",
        "Grid: pulses over lam {"
        + ", ".join(f"{x:g}" for x in LAMS_FULL)
        + "} x eta {"
        + ", ".join(f"{x:g}" for x in ETAS_FULL)
        + "} x p_eq {"
        + ", ".join(f"{x:g}" for x in PS_FULL)
        + "} rad/s x Omega {"
        + ", ".join(f"{x:g}" for x in OMEGAS_FULL)
        + "} x A {"
        + ", ".join(f"{x:.13g}" for x in AMPS_FULL)
        + "} x {sine, cosine} x both signs "
        "(negative eta: one-sided rebound); white-noise records of 1e6 samples over one hour "
        "and at dt = 1e-5 s, one hour at dt = 0.1 s, El Centro at scales up to 1e3; "
        "asymmetric mechanisms; the dangerous cases; Housner's nonlinear block for alpha up "
        "to 1.4.",
        "",
        md_table(SUMMARY_HEAD, summary_rows(outs)),
        "",
        "'max estimate' is the largest `error_estimate`; an estimate of 0.1 or more means the "
        "peak is not resolved and the result says so in its `warnings` and `message`.",
        "",
        "### Error estimate against the true error",
        "",
        "Ratio `error_estimate / |peak - peak_mpmath|` over every case with a reference "
        "(below 1 would be an estimate that undershoots); the ratio of every such case is "
        "in [numerics_sweep.csv](numerics_sweep.csv), with every case outside the pulse "
        "grid:",
        "",
        md_table(["estimate / true", "cases"], ratio_histogram(outs)),
        "",
        "### Worst cases",
        "",
    ]
    for title, rows in worst_rows(outs):
        lines += [f"**{title}**", "", md_table(WORST_HEAD, rows), ""]
    if n_bad:
        lines += ["### Violations", ""]
        for o in outs:
            if o.violations:
                lines.append(f"- {o.case.name}: " + "; ".join(o.violations))
        lines.append("")
    return "\n".join(lines)


def write_csv(outs: list[Outcome], path: Path) -> None:
    """Write one row per case with a reference, per special case and per violation.

    Columns: outcome, work, estimate, true error and their ratio. The bulk of the pulse grid
    (no reference, no violation) is summarised in the markdown only.
    """
    import csv

    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(
            [
                "group",
                "case",
                "status",
                "collapsed",
                "peak_ratio",
                "n_impacts",
                "n_steps",
                "runtime_s",
                "error_estimate",
                "true_error_vs_mpmath",
                "estimate_over_true",
                "violations",
            ]
        )
        for o in outs:
            if o.case.group == "pulses" and math.isnan(o.true_error) and not o.violations:
                continue
            r = o.result
            w.writerow(
                [
                    o.case.group,
                    o.case.name,
                    "" if r is None else r.status,
                    "" if r is None else r.collapsed,
                    "" if r is None else repr(r.peak_ratio),
                    "" if r is None else r.n_impacts,
                    "" if r is None else r.n_steps,
                    f"{o.runtime_s:.3g}",
                    "" if r is None else f"{r.error_estimate:.3g}",
                    "" if math.isnan(o.true_error) else f"{o.true_error:.3g}",
                    "" if math.isnan(o.ratio) else f"{o.ratio:.3g}",
                    "; ".join(o.violations),
                ]
            )


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--level", choices=("full", "reduced"), default="full")
    ap.add_argument("--no-docs", action="store_true", help="print only; do not write docs")
    args = ap.parse_args(argv)
    wall0 = time.perf_counter()
    info = machine_info(("numpy", "scipy", "numba", "mpmath"))
    simulate(_model(2.0, 0.2, 0.9), Pulse(-3.0, 1.0), impact_log=True)  # compile / cache load
    outs = sweep(args.level, verbose=True)
    total = time.perf_counter() - wall0
    print(md_table(SUMMARY_HEAD, summary_rows(outs)))
    for title, rows in worst_rows(outs):
        print(f"\n{title}")
        print(md_table(WORST_HEAD, rows))
    n_bad = sum(1 for o in outs if o.violations)
    print(f"\n{len(outs)} cases, {n_bad} with violations; {total:.0f} s")
    if not args.no_docs:
        write_section(DOC_MD, "extremes", markdown(outs, info, args.level, total), header=HEADER)
        write_csv(outs, CSV)
        print(f"wrote {DOC_MD.relative_to(REPO)} and {CSV.relative_to(REPO)}")
    return 1 if n_bad else 0


if __name__ == "__main__":
    sys.exit(main())
