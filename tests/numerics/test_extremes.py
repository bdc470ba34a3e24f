"""The reduced extreme-case sweep (issue 7): every case must hold every property.

The cases and the checks live in ``benchmarks/extremes.py`` (the full sweep there writes
``docs/numerics.md``); this runs the reduced grid of the same builders and fails on any
violated property: non-finite output, a hang (impact cap or work beyond the counters' bound),
an energy gain at an impact, a status or message that does not say what happened, or an
error estimate below the true error measured against the 30-digit mpmath reference.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("mpmath", reason="mpmath is needed for the reference of the sweep")

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import extremes

from solver_service.core.excitation import Pulse, SampledAccel
from solver_service.core.result import RockingResult

GROUPS = (
    "pulses",
    "records",
    "asymmetric",
    "grazing",
    "zeno",
    "rebound |eta| -> 1",
    "threshold",
    "ends mid-impact",
    "nonlinear",
)


@pytest.fixture(scope="module")
def sweep() -> list[extremes.Outcome]:
    return extremes.sweep("reduced")


def _group(outs: list[extremes.Outcome], group: str) -> list[extremes.Outcome]:
    return [o for o in outs if o.case.group == group]


@pytest.mark.parametrize("group", GROUPS)
def test_every_case_of_the_reduced_sweep_holds_every_property(
    sweep: list[extremes.Outcome], group: str
) -> None:
    outs = _group(sweep, group)
    assert outs, f"no case in group {group!r}"
    bad = [f"{o.case.name}: {'; '.join(o.violations)}" for o in outs if o.violations]
    assert not bad, "\n".join(bad)


def test_error_estimates_are_checked_against_mpmath_on_every_group(
    sweep: list[extremes.Outcome],
) -> None:
    refs = [o for o in sweep if not math.isnan(o.true_error)]
    assert len(refs) >= 100
    for group in ("pulses", "grazing", "threshold", "ends mid-impact", "zeno", "records"):
        assert any(o.case.group == group for o in refs), group
    # The estimate bounds the true error everywhere (also part of each case's violations).
    assert all(o.result is not None and o.true_error <= o.result.error_estimate for o in refs)


def test_sweep_reaches_the_extremes_it_claims(sweep: list[extremes.Outcome]) -> None:
    res = {o.case.name: o.result for o in sweep}
    assert all(r is not None for r in res.values())
    # A record of 1e6 samples over one hour, and one at dt = 1e-5 s.
    assert any(
        isinstance(o.case.excitation, SampledAccel) and o.case.excitation.n == 1_000_000
        for o in sweep
    )
    assert any(
        isinstance(o.case.excitation, SampledAccel) and o.case.excitation.dt == 1e-5 for o in sweep
    )
    pulses = [o.case.excitation for o in _group(sweep, "pulses")]
    lams = {o.case.model.positive.lam for o in _group(sweep, "pulses")}
    assert min(lams) == 1e-4 and max(lams) == 1.4
    etas = {o.case.model.eta for o in _group(sweep, "pulses")}
    assert {-1.0, 0.0, 1.0} <= etas
    assert max(abs(p.a_p) for p in pulses if isinstance(p, Pulse)) > 1e6 * 9.8 * 1.4 * 0.99


def test_grazing_cases_touch_zero_with_almost_no_velocity(sweep: list[extremes.Outcome]) -> None:
    speeds = []
    for o in _group(sweep, "grazing"):
        assert o.result is not None and o.result.impacts is not None
        log = o.result.impacts
        early = log[:, log[0] < extremes.GRAZE_END]
        if early.shape[1]:
            speeds.append(float(np.min(np.abs(early[2]))))
    # The bisection puts the impact-side cases within a few ulps of grazing.
    assert speeds and min(speeds) < 1e-6


def test_zeno_sequences_end_in_rest_after_finitely_many_impacts(
    sweep: list[extremes.Outcome],
) -> None:
    for o in _group(sweep, "zeno"):
        r = o.result
        assert r is not None
        if o.case.expect_cap:
            assert r.status == -1 and "impact limit" in r.message and not r.success
            continue
        eta = abs(o.case.model.eta)
        # The cascade lasts about 2/(p (1 - eta)) seconds: it ends within the record.
        assert r.success and (r.n_rests >= 1 or eta > 0.999)
        if eta > 0.0:
            # Each impact scales the speed by eta; the rest rule stops at 1e-9 p.
            bound = 2 + math.log(1e9 * 10) / -math.log(eta)
            assert r.n_impacts <= bound * (r.n_uplifts + 1)


def test_threshold_pulses_move_only_above_the_threshold(sweep: list[extremes.Outcome]) -> None:
    for o in _group(sweep, "threshold"):
        r, exc = o.result, o.case.excitation
        assert r is not None
        if isinstance(exc, Pulse) and abs(exc.a_p) <= 9.80665 * o.case.model.positive.lam:
            assert r.peak_ratio == 0.0 and r.n_uplifts == 0


def _doctored(res: RockingResult, **changes: object) -> RockingResult:
    return dataclasses.replace(res, **changes)  # type: ignore[arg-type]


def test_checks_catch_each_kind_of_violation() -> None:
    case = next(c for c in extremes.dangerous_cases("reduced") if c.group == "zeno")
    out = extremes.run(case)
    assert out.violations == []
    res = out.result
    assert res is not None and res.impacts is not None and res.impacts.shape[1] > 2
    log = res.impacts.copy()
    log[3, 1] = -1.5 * log[2, 1]  # an impact that leaves faster than it arrived
    assert any("E increased" in v for v in extremes.check(case, _doctored(res, impacts=log), 10**6))
    bad = _doctored(res, peak_ratio=math.nan)
    assert any("not finite" in v for v in extremes.check(case, bad, 10**6))
    assert any("status" in v for v in extremes.check(case, _doctored(res, status=1), 10**6))
    assert any("work bound" in v for v in extremes.check(case, res, 0))
    assert any("cap" in v for v in extremes.check(case, _doctored(res, status=-1), 10**6))
    log = res.impacts.copy()
    log[2, 2] *= 1.001  # E not conserved between impacts of free motion
    assert any("conserved" in v for v in extremes.check(case, _doctored(res, impacts=log), 10**6))
