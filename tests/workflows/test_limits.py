"""The size limits shared by the command line and the service, and their work estimates."""

from __future__ import annotations

import numpy as np
import pytest

from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError
from solver_service.core import amplification, exact
from solver_service.core import envelope as core_envelope
from solver_service.workflows import limits


def _walls(*p_eqs: float) -> ConstantsFile:
    mechs = [
        {
            "id": f"W{i}",
            "name": "wall",
            "eta": 0.9,
            "positive": {"p_eq": p, "lam": 0.2, "phi_ov": 0.2},
        }
        for i, p in enumerate(p_eqs)
    ]
    return ConstantsFile.model_validate({"mechanisms": mechs})


def test_copied_numbers_match_the_solver() -> None:
    assert limits.N_SCAN == core_envelope.N_SCAN
    assert limits.P_EQ_PLAUSIBLE == exact.P_EQ_PLAUSIBLE
    assert limits.SPECTRUM_GRID_PER_PERIOD == amplification.GRID_PER_PERIOD
    assert limits.LIBRARY_OMEGA == core_envelope.LIBRARY_OMEGA


def test_scale_factor_points_equal_the_direct_sum() -> None:
    amp = {"f_n": 5.0, "h": 3.0, "h_e": 6.0}
    cf = ConstantsFile.model_validate(
        {
            "mechanisms": [
                {"id": "A", "p_eq": 2.0, "lam": 0.2, "amplification": amp},
                {"id": "G", "p_eq": 2.0, "lam": 0.2},
            ]
        }
    )
    f = np.geomspace(0.1, 10.0, 50)
    direct = (limits.SPECTRUM_GRID_PER_PERIOD * np.maximum(1.0, 5.0 / f)).sum()
    assert limits.scale_factor_points(cf, 0.1, 10.0, 50) == pytest.approx(direct, rel=1e-9)


def test_envelope_steps_equal_the_direct_sum() -> None:
    cf = _walls(2.0, 7.0)
    f = np.geomspace(0.1, 10.0, 50)
    direct = sum(limits.N_SCAN * np.maximum(1.0, p / f).sum() for p in (2.0, 7.0))
    # Walls given by their positive side only: one side each, one direction.
    assert limits.envelope_steps(cf, 0.1, 10.0, 50) == pytest.approx(direct, rel=1e-9)
    assert limits.envelope_steps(cf, 0.1, 10.0, 50, p_max=5.0) == pytest.approx(
        limits.N_SCAN * np.maximum(1.0, 2.0 / f).sum(), rel=1e-9
    )


@pytest.mark.parametrize(
    ("p_eqs", "f_min", "f_max", "n"),
    [((2.0, 7.0), 0.1, 10.0, 50), ((292.9,), 0.001, 307.3, 5079), ((0.05, 50.0), 0.01, 100.0, 999)],
)
def test_fast_mode_steps_count_the_frequencies_outside_the_library(
    p_eqs: tuple[float, ...], f_min: float, f_max: float, n: int
) -> None:
    # The fast mode computes exactly where Omega = 2 pi f / p_eq leaves the library's grid
    # (schemathesis found a stiff one-sided mechanism at 5079 frequencies past the budget).
    cf = _walls(*p_eqs)
    f = np.geomspace(f_min, f_max, n)
    lo, hi, _ = core_envelope.LIBRARY_OMEGA
    direct = 0.0
    for p in p_eqs:
        om = 2.0 * np.pi * f / p
        outside = (om < lo) | (om > hi)
        direct += limits.N_SCAN * np.maximum(1.0, p / f)[outside].sum()
    got = limits.envelope_steps(cf, f_min, f_max, n, exact=False)
    assert got == pytest.approx(direct, rel=1e-9, abs=1e-9)
    # The library's exact points: the same count as core.envelope's library_curve makes.
    lib = core_envelope.OverturningLibrary.load()
    computed = 0
    for p in p_eqs:
        om = 2.0 * np.pi * f / p
        computed += int(np.count_nonzero(lib.a_min_flagged(om, 0.9)[1] & ((om < lo) | (om > hi))))
    assert computed == sum(
        int(np.count_nonzero((2 * np.pi * f / p < lo) | (2 * np.pi * f / p > hi))) for p in p_eqs
    )


def test_messages_name_the_option_the_limit_and_the_lift() -> None:
    with pytest.raises(InputError) as info:
        limits.check_run(envelope=(0.1, 10.0, 10_000_000, False))
    assert str(info.value) == (
        "n: 10000000 frequencies exceed the limit of 500000; give --no-limits to lift it"
    )
    with pytest.raises(InputError, match=r"^scales: 101 scale factors exceed the limit of 100"):
        limits.check_run(scales=101)
    limits.check_run(scales=100, periods=500_000)  # at the limits: fine
    # 500000 samples at dt 1 s of a p_eq = 100 rad/s wall: 100 steps a sample, over 20.
    with pytest.raises(InputError, match=r"^record: one time history .* --no-limits"):
        limits.check_run(_walls(100.0), scales=1, record=(500_000, 1.0))
    # A side too stiff for the solver is left to the solver's own message (naming p_eq).
    limits.check_run(_walls(1e200), scales=1, record=(1000, 0.01))
    # Total work: 4e10 steps cannot finish in 1 s at twice the measured rate (it would
    # take 270 cores).
    with pytest.raises(InputError, match=r"^record: the run would take 4e\+10 .* 1 s"):
        limits.check_run(
            _walls(10.0), scales=100, record=(400_000, 0.1), records=1000, budget_s=1.0
        )
