"""The event search of the exact kernel: short route for chattering, few evaluations, symmetry.

A flight that leaves an impact takes ``_short_return``; switched off (python kernels,
``_short_return`` patched to decline), every flight takes the general scan. Both must give
the same motion, and a time series must not change it.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from solver_service.core.exact import kernels, simulate
from solver_service.core.excitation import SampledAccel
from solver_service.core.model import RockingModel
from solver_service.core.records import GroundMotion


@pytest.fixture()
def elcentro(elcentro_path: Any) -> SampledAccel:
    return GroundMotion.from_two_column(elcentro_path).accel


@pytest.fixture()
def general_scan_only() -> Iterator[None]:
    """The python kernels with the short route declined (every flight takes the scan)."""
    step = kernels("python")._stepping
    short = step._short_return
    step._short_return = lambda *args: -1.0
    try:
        yield
    finally:
        step._short_return = short


def test_short_route_agrees_with_the_general_scan(
    elcentro: SampledAccel, general_scan_only: None
) -> None:
    model = RockingModel.symmetric(2.0, 0.15, 0.9)
    fast = simulate(model, elcentro, impact_log=True, backend="numba")
    full = simulate(model, elcentro, impact_log=True, backend="python")
    assert fast.n_impacts == full.n_impacts > 100
    assert fast.impacts is not None and full.impacts is not None
    assert fast.impacts.shape == full.impacts.shape
    np.testing.assert_allclose(fast.impacts[0], full.impacts[0], rtol=0, atol=1e-12)
    assert fast.peak_ratio == pytest.approx(full.peak_ratio, rel=1e-12)
    assert abs(fast.peak_ratio - full.peak_ratio) <= fast.error_estimate


def test_a_time_series_does_not_change_the_motion(elcentro: SampledAccel) -> None:
    model = RockingModel.symmetric(2.0, 0.15, 0.9)
    plain = simulate(model, elcentro, impact_log=True)
    dense = simulate(model, elcentro, impact_log=True, dense=True)
    assert plain.impacts is not None and dense.impacts is not None
    np.testing.assert_array_equal(plain.impacts, dense.impacts)
    assert (plain.peak_ratio, plain.t_peak) == (dense.peak_ratio, dense.t_peak)
    assert dense.ratio is not None
    # Every impact is in the series (x = 0), with the turning points between them.
    assert np.count_nonzero(dense.ratio == 0.0) >= plain.impacts.shape[1]


def test_mirrored_record_gives_the_mirrored_impacts_bit_for_bit(elcentro: SampledAccel) -> None:
    model = RockingModel.symmetric(2.0, 0.15, 0.9)
    a = simulate(model, elcentro, impact_log=True)
    b = simulate(model, SampledAccel(-elcentro.acc, elcentro.dt), impact_log=True)
    assert a.impacts is not None and b.impacts is not None
    np.testing.assert_array_equal(a.impacts[0], b.impacts[0])
    np.testing.assert_array_equal(a.impacts[1:], -b.impacts[1:])
    assert a.peak_ratio == b.peak_ratio


@pytest.fixture()
def counted() -> Iterator[tuple[Any, dict[str, int]]]:
    """The python kernels with a counter on the closed-form evaluations (``state``)."""
    kern = kernels("python")
    # Both the one-run path and the closed forms it calls evaluate the state.
    callers = (kern._closed_form, kern._stepping)
    state = kern._closed_form.state
    count = {"state": 0}

    def counting(fl: Any, tau: float) -> Any:
        count["state"] += 1
        return state(fl, tau)

    for mod in callers:
        mod.state = counting
    try:
        yield kern, count
    finally:
        for mod in callers:
            mod.state = state


@pytest.mark.parametrize("speed", [1e-2, 1e-4, 1e-7])
def test_a_chattering_impact_costs_two_or_three_evaluations(
    counted: tuple[Any, dict[str, int]], speed: float
) -> None:
    # One flight from an impact at speed `speed * p` back to the base under a steady drive:
    # the Taylor start and the a-priori stop find the return in one or two evaluations, and
    # the impact evaluates the state once (it took 11 to 26 before). The impact log asks for
    # every bounce (no closed chattering sequence, test_chatter_closure.py).
    kern, count = counted
    step, cf = kern._stepping, kern._closed_form
    params = np.array([2.0, 2.0, 0.15, 0.15, 0.15, 0.15, 0.9, 0.0])
    sides, rules = step.run_constants(params, 1.0, 1e-9, 1e6)
    cell = np.array([0.0, 0.3, 5.0, 0.0, 10.0, 10.02, 3.0])
    st = step.init_state(10.0, 0.0)
    st[cf.ST_MODE] = cf.FLIGHT
    st[cf.ST_S] = 1.0
    st[cf.ST_V] = 2.0 * speed
    st[cf.OUT_PEAK] = 0.5
    done = step._flight_step(
        st, np.empty(cf.NFL), cell, sides, rules, 10.02, 10.0, np.empty((2, 0)), np.empty((4, 1))
    )
    assert not done and st[cf.OUT_N_IMPACTS] == 1
    assert count["state"] <= 3
    # The return time of x'' = p**2 (x - 1 - q), q = ks (0.3 + 5 t), from x = 0 at speed v:
    # to leading order 2 v / (p**2 (1 + q)).
    q = 0.3 / (9.80665 * 0.15)
    assert st[cf.ST_T] - 10.0 == pytest.approx(2 * 2.0 * speed / (4.0 * (1 + q)), rel=2e-2)
