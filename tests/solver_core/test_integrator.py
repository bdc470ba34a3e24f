"""The integrators' contract (``integrator.py``, #29): one call, one result, the same rules.

``exact.simulate``, ``reference.simulate_ivp`` and ``nonlinear.simulate_nonlinear`` take the
same call (mypy checks each against ``integrator.Integrator``; this checks it at run time) and
answer the same question with the same rules: the exact and the time-stepping integrators
agree to within the reference's own error estimate, and Housner's equation of a slender block
agrees with its linearisation to within the order of the linearisation error (theory §2.1).
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable

import numpy as np
import pytest

from solver_service.core.exact import simulate
from solver_service.core.excitation import Pulse
from solver_service.core.integrator import V_REST_REL, motion_events
from solver_service.core.model import G
from solver_service.core.nonlinear import HousnerBlock, simulate_nonlinear
from solver_service.core.reference import ZENO_VREL, simulate_ivp
from solver_service.core.result import RockingResult

#: Slenderness of the block compared with its linearisation [rad]: the terms dropped by the
#: linearisation are of relative order alpha² (sin, cos), and the uplift threshold moves by
#: alpha²/3 of itself (tan), 2 alpha²/3 of the excess of a pulse at 1.5 times the threshold.
ALPHA = 0.02
BLOCK = HousnerBlock(p=2.0, alpha=ALPHA, eta=0.9)
#: A one-sine pulse at 1.5 times the uplift threshold: one impact, no overturning.
PULSE = Pulse(a_p=-1.5 * G * math.tan(ALPHA), f_p=2.0)
ENTRIES: list[tuple[str, Callable[..., RockingResult], object]] = [
    ("exact", simulate, BLOCK.linearised()),
    ("reference", simulate_ivp, BLOCK.linearised()),
    ("nonlinear", simulate_nonlinear, BLOCK),
]
CONTRACT = ("scale", "criterion", "dense", "x0", "max_impacts")


@pytest.mark.parametrize(("name", "entry", "model"), ENTRIES)
def test_each_integrator_takes_the_contract_call_and_returns_its_result(
    name: str, entry: Callable[..., RockingResult], model: object
) -> None:
    params = list(inspect.signature(entry).parameters.values())
    assert [p.kind for p in params[:2]] == [inspect.Parameter.POSITIONAL_OR_KEYWORD] * 2
    by_name = {p.name: p for p in params}
    for field in CONTRACT:
        assert by_name[field].kind is inspect.Parameter.KEYWORD_ONLY, field
        assert by_name[field].default is not inspect.Parameter.empty, field
    r = entry(model, PULSE, scale=1.0, criterion="ratio", dense=True, x0=0.0, max_impacts=1000)
    assert isinstance(r, RockingResult)
    assert r.success and r.status == 0 and r.message
    assert r.method.startswith(name.replace("reference", "solve_ivp"))
    assert r.n_impacts >= 1 and r.n_uplifts >= 1 and r.n_steps > 0
    assert 0.0 <= r.error_estimate < 1e-6 and r.runtime_s >= 0.0
    assert r.t is not None and r.ratio is not None and r.t.shape == r.ratio.shape
    assert 0.1 < r.peak_ratio < 1.0 and not r.overturned


def test_the_exact_and_the_time_stepping_integrators_agree_within_the_reference_estimate() -> None:
    model = BLOCK.linearised()
    ex = simulate(model, PULSE)
    ref = simulate_ivp(model, PULSE)
    assert ex.n_impacts == ref.n_impacts
    assert abs(ex.peak_ratio - ref.peak_ratio) <= ref.error_estimate + ex.error_estimate
    assert abs(ex.t_peak - ref.t_peak) < 1e-6


def test_housner_block_agrees_with_its_linearisation_to_the_order_of_alpha_squared() -> None:
    lin = simulate(BLOCK.linearised(), PULSE)
    nl = simulate_nonlinear(BLOCK, PULSE)
    assert lin.n_impacts == nl.n_impacts
    assert abs(lin.peak_ratio - nl.peak_ratio) < 3.0 * ALPHA**2 * nl.peak_ratio


def test_every_integrator_applies_one_rest_rule() -> None:
    assert ZENO_VREL == V_REST_REL == 1e-9


def test_motion_events_start_outward_where_the_state_is_at_a_threshold() -> None:
    # An uplift at the exact threshold: x = v = x'' = 0, and the motion starts towards s.
    for s in (1, -1):
        impact, collapse, cross, turn = motion_events(s, 5.0, 0.0, np.zeros(2), 0.0)
        assert impact(0.0, np.zeros(2)) == s and turn(0.0, np.zeros(2)) == s
        assert collapse(0.0, np.zeros(2)) == -5.0 and cross(0.0, np.zeros(2)) == -1.0
        assert impact.terminal and collapse.terminal and not cross.terminal
        assert impact.direction == -s and collapse.direction == 1.0
        assert impact(0.5, np.array([0.25 * s, 0.0])) == 0.25 * s
