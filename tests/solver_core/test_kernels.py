"""The exact kernel's batch path, its cheap no-event bound and its series (issue #18).

The batch path (``_batch_kernels.simulate_grid``: blocks of scales, a propagator per cell width,
the no-event bound before any root finding) must give the event-by-event path's numbers bit
for bit; the bound must never wave through a cell that holds an event; the series of the
closed form must be accurate to a few ulps.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver_service.core import _closed_form as CF
from solver_service.core import _kernels as K
from solver_service.core.exact import (
    _params,
    cells_for,
    kernels,
    simulate,
    simulate_batch,
    single_threaded,
)
from solver_service.core.excitation import Pulse
from solver_service.core.model import RockingModel, RockingSide
from solver_service.core.records import GroundMotion

MODELS = [
    RockingModel.symmetric(2.0, 0.15, 0.9, name="sym"),
    RockingModel(RockingSide(2.2, 0.15, 0.15), RockingSide(1.8, 0.18, 0.2), eta=0.85, name="asym"),
    RockingModel.symmetric(2.2, 0.08, 0.99, name="elastic"),
    RockingModel.symmetric(1.5, 0.25, -0.5, one_sided=True, name="one-sided"),
]
FIELDS = ("peak_ratio", "t_peak", "error_estimate", "n_impacts", "n_steps", "status")


def test_batch_path_equals_event_path_bit_for_bit(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    rec = GroundMotion.from_two_column(elcentro_path).accel
    scales = np.geomspace(0.2, 4.0, 37)  # more than one block of scales
    batch = simulate_batch(MODELS, rec, scales)
    with single_threaded():
        serial = simulate_batch(MODELS, rec, scales)
    for i, model in enumerate(MODELS):
        for j in range(0, scales.size, 4):
            one = simulate(model, rec, scale=float(scales[j]))
            for field in FIELDS:
                assert getattr(batch, field)[i, j] == getattr(one, field), (model.name, j, field)
    for field in FIELDS:
        np.testing.assert_array_equal(getattr(serial, field), getattr(batch, field))
    assert batch.n_impacts.sum() > 1000  # the comparison covers many events


def test_batch_path_with_cells_of_several_segments(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    # p dt > MAX_PH: every record cell takes several closed-form segments, so no cell is
    # fast and each goes through the event path, stretch after stretch (the body rocks,
    # then overturns at the largest scale).
    rec = GroundMotion.from_two_column(elcentro_path).accel
    stiff = RockingModel.symmetric(60.0, 0.25, 0.9, name="stiff")
    scales = np.array([0.5, 0.8, 1.0, 1.2])
    batch = simulate_batch([stiff, MODELS[0]], rec, scales)
    for i, model in enumerate([stiff, MODELS[0]]):
        for j, sc in enumerate(scales):
            one = simulate(model, rec, scale=float(sc))
            for field in FIELDS:
                assert getattr(batch, field)[i, j] == getattr(one, field), (model.name, j, field)
    assert batch.n_impacts[0].sum() > 0


def test_dense_and_plain_runs_agree(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    # Dense runs locate every turning point; plain runs may skip those the bound clears.
    rec = GroundMotion.from_two_column(elcentro_path).accel
    for model in MODELS:
        plain = simulate(model, rec, scale=1.2)
        dense = simulate(model, rec, scale=1.2, dense=True)
        assert plain.peak_ratio == dense.peak_ratio and plain.n_impacts == dense.n_impacts


def _dense_extremes(s: float, xa: float, va: float, q0: float, q1: float, p: float, h: float):  # type: ignore[no-untyped-def]
    """min and max of ``s x`` over a flight of ``h``, sampled densely from the closed form."""
    fl = np.array([0.0, q0, q1, 0.0, 0.0, 1.0, s, p, 0.0, xa, va])  # ks = 1: q = a
    taus = np.linspace(0.0, h, 2001)
    xs = np.array([CF.state(fl, t)[0] for t in taus])
    return float(np.min(s * xs)), float(np.max(s * xs)), CF.state(fl, h)


def test_no_event_bound_never_clears_an_event() -> None:
    # Random flights across a sample, many of them with a turning point inside: whenever
    # the bound says "no event", dense sampling finds no impact, no crossing of 1 and no
    # value above the peak; it must also clear a good share of them (else it is useless).
    rng = np.random.default_rng(7)
    cleared = with_turn = 0
    for _ in range(600):
        s = float(rng.choice([-1.0, 1.0]))
        p = float(rng.uniform(0.5, 8.0))
        h = float(rng.uniform(0.002, 0.1))
        xa = s * float(rng.uniform(0.0, 0.9))
        va = float(rng.normal(0.0, 0.5 * p))
        q0 = float(rng.normal(0.0, 1.5))
        q1 = float(rng.normal(0.0, 20.0))
        peak = float(rng.uniform(abs(xa), 1.0))
        lo, hi, (xb, vb, _a, _j) = _dense_extremes(s, xa, va, q0, q1, p, h)
        if va * vb < 0.0:
            with_turn += 1
        if CF.no_event(s, xa, va, xb, vb, q0, q1, h, p, peak):
            cleared += 1
            assert lo >= 0.0 and hi < 1.0
            assert hi <= max(peak, s * xb) + 1e-12
    assert with_turn > 50 and cleared > 200


@pytest.mark.parametrize("u", [1e-9, 1e-4, 0.01, 0.049, 0.05, 0.2, 0.49, 0.51, 1.0, 3.0])
def test_closed_form_coefficients_are_accurate_to_a_few_ulps(u: float) -> None:
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 40
    p = 1.7
    tau = u / p
    chm1, shp, smp, psh = CF.flow_coeffs(p, tau)
    uu, pp = mpmath.mpf(p) * mpmath.mpf(tau), mpmath.mpf(p)
    exact = (
        mpmath.cosh(uu) - 1,
        mpmath.sinh(uu) / pp,
        (mpmath.sinh(uu) - uu) / pp,
        pp * mpmath.sinh(uu),
    )
    # (sinh(u) - u)/p multiplies q1 where sinh(u)/p multiplies x': its error counts on the
    # scale of sinh(u)/p (above SERIES_U it is sinh(u) - u in floating point, as before).
    scales = (exact[0], exact[1], exact[1], exact[3])
    for got, ref, scale in zip((chm1, shp, smp, psh), exact, scales):
        assert abs(got - float(ref)) <= 4 * CF.EPS * abs(float(scale)), (u, got, ref)


def test_pulse_cells_match_the_quarter_period_layout() -> None:
    pulse = Pulse(a_p=-0.3 * 9.80665, f_p=1.3, shape="cosine")
    for per_quarter, t_extra in ((1, 0.0), (50, 0.0), (1, 2.0)):
        data = cells_for(pulse, dense=per_quarter > 1, t_extra=t_extra).data
        n = 4 * per_quarter
        edges = pulse.duration * np.arange(n + 1) / n
        assert data.shape == (7, n + (1 if t_extra else 0))
        np.testing.assert_array_equal(data[4, :n], edges[:-1])
        np.testing.assert_array_equal(data[5, :n], edges[1:])
        assert np.all(data[0, :n] == 1.0) and np.all(data[6, :n] == abs(pulse.a_p))
        assert np.all(data[1, :n] == pulse.a_p) and np.all(data[3, :n] == math.pi / 2)
        if t_extra:
            assert data[4, n] == edges[-1] and data[5, n] == edges[-1] + t_extra
            assert np.all(data[[0, 1, 2, 3, 6], n] == 0.0)


def test_python_backend_runs_the_batch_path(elcentro_path) -> None:  # type: ignore[no-untyped-def]
    rec = GroundMotion.from_two_column(elcentro_path).accel
    cells = cells_for(rec).data
    params = np.stack([_params(MODELS[1])])
    scales = np.array([0.7, 1.3])
    slow = kernels("python").simulate_grid(cells, params, scales, 1e-9, 1_000_000)
    fast = K.simulate_grid(cells, params, scales, 1e-9, 1_000_000)
    np.testing.assert_allclose(slow[..., K.OUT_PEAK], fast[..., K.OUT_PEAK], rtol=1e-12)
    np.testing.assert_array_equal(slow[..., K.OUT_N_IMPACTS], fast[..., K.OUT_N_IMPACTS])
