"""A chattering sequence closed in one step gives the results of following every bounce.

The kernel closes a chattering sequence at an impact when bounds on the bounces that
follow prove that it ends in rest within the cell, how many impacts it still counts, and
that none raises the peak (``_stepping._chatter_count``, theory §10.5). An impact log or a
time series asks for every bounce, so a run with either follows them one by one: those runs
are the reference here. Every output but the number of closed-form steps must be the same, bit for
bit, on many scale factors of El Centro and on mechanisms of every kind (symmetric,
asymmetric, directional restitution, one-sided).
"""

from __future__ import annotations

import numpy as np
import pytest

from solver_service.core.exact import simulate, simulate_batch
from solver_service.core.excitation import SampledAccel
from solver_service.core.model import RockingModel, RockingSide

FIELDS = (
    "peak_ratio",
    "t_peak",
    "collapsed",
    "status",
    "n_impacts",
    "n_uplifts",
    "n_rests",
    "error_estimate",
)

MODELS = {
    "symmetric": RockingModel.symmetric(2.0, 0.15, 0.9),
    "asymmetric": RockingModel(RockingSide(2.2, 0.18, 0.2), RockingSide(1.6, 0.12, 0.15), eta=0.85),
    "directional": RockingModel(
        RockingSide(2.0, 0.15), None, eta=0.9, eta_to_negative=0.9, eta_to_positive=0.75
    ),
    "one-sided": RockingModel(RockingSide(2.0, 0.15), None, eta=-0.7, one_sided=True),
}


@pytest.fixture(scope="module")
def record(elcentro_path) -> SampledAccel:  # type: ignore[no-untyped-def]
    data = np.loadtxt(elcentro_path)
    return SampledAccel(data[:, 1] * 9.80665, float(data[1, 0] - data[0, 0]), float(data[0, 0]))


@pytest.mark.parametrize("name", list(MODELS))
def test_closed_sequences_give_the_bounce_by_bounce_results(
    name: str, record: SampledAccel
) -> None:
    model = MODELS[name]
    closed_runs = 0
    rests = 0
    for scale in np.geomspace(0.3, 2.0, 12):
        every = simulate(model, record, scale=float(scale), impact_log=True)
        dense = simulate(model, record, scale=float(scale), dense=True)
        closed = simulate(model, record, scale=float(scale))
        for field in FIELDS:
            assert getattr(closed, field) == getattr(every, field), (name, scale, field)
        assert dense.n_steps == every.n_steps
        assert closed.n_steps <= every.n_steps
        closed_runs += closed.n_steps < every.n_steps
        rests += every.n_rests
    # The comparison covers many closed sequences (else it would prove nothing).
    assert rests >= 5
    assert closed_runs >= 3


def test_the_batch_closes_sequences_as_single_runs_do(record: SampledAccel) -> None:
    model = MODELS["symmetric"]
    scales = np.geomspace(0.3, 2.0, 12)
    batch = simulate_batch([model], record, scales)
    for j, scale in enumerate(scales):
        one = simulate(model, record, scale=float(scale))
        assert batch.peak_ratio[0, j] == one.peak_ratio
        assert batch.n_impacts[0, j] == one.n_impacts
        assert batch.n_steps[0, j] == one.n_steps


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("x0", [0.05, 0.3, 0.9])
def test_free_rocking_sequences_close_with_the_same_results(name: str, x0: float) -> None:
    # No drive: the bounds are exact but for rounding (zero drive rate), so sequences close
    # at their first bounces; the count must still be the bounce-by-bounce one.
    model = MODELS[name]
    calm = SampledAccel(np.zeros(2001), 0.01)
    every = simulate(model, calm, x0=x0, impact_log=True)
    closed = simulate(model, calm, x0=x0)
    for field in FIELDS:
        assert getattr(closed, field) == getattr(every, field), (name, x0, field)
    if every.collapsed:  # the asymmetric body, released far out, overturns on its other side
        assert name == "asymmetric" and x0 > 0.1
        return
    assert every.n_rests == 1 and every.n_impacts > 5
    assert closed.n_steps < every.n_steps
