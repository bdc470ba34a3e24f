"""The plausible ranges of a pulse request: consistent with the solver and the work bound,
stated in the published schema, and wide enough that every corner still computes."""

from __future__ import annotations

import itertools
import json
import math
from typing import Any

import pytest
from pydantic import ValidationError
from typer.testing import CliRunner

from shared_schema import rules
from shared_schema.api import Eq28Request, PulseRequest
from solver_service.cli import app
from solver_service.core import exact
from solver_service.workflows.limits import DEFAULT_LIMITS, WORK_PER_SAMPLE

runner = CliRunner()


def test_the_ranges_fit_the_solver_and_the_default_work_bound() -> None:
    assert rules.P_EQ_RANGE[1] == exact.P_EQ_PLAUSIBLE
    assert rules.A_P_G_MAX / rules.LAM_RANGE[0] <= exact.MAX_AMPLITUDE_RATIO
    longest = rules.P_EQ_RANGE[1] / rules.F_P_RANGE[0]  # closed-form steps of one pulse
    assert longest <= WORK_PER_SAMPLE * DEFAULT_LIMITS["max_samples"]
    # p_eq = sqrt(3 g / (4 R)) of a rectangular block of half-diagonal R (theory Eq. 5)
    assert math.isclose(3 * rules.G / (4 * rules.P_EQ_RANGE[0] ** 2), 73_550, rel_tol=1e-3)
    assert math.isclose(3 * rules.G / (4 * rules.P_EQ_RANGE[1] ** 2), 7.355e-6, rel_tol=1e-3)


def test_the_schema_states_each_range_with_its_unit() -> None:
    props = PulseRequest.model_json_schema()["properties"]
    for key, (lo, hi), unit in (
        ("p_eq", rules.P_EQ_RANGE, "[rad/s]"),
        ("lam", rules.LAM_RANGE, "[-]"),
        ("f_p", rules.F_P_RANGE, "[Hz]"),
        ("a_p_g", (-rules.A_P_G_MAX, rules.A_P_G_MAX), "[g]"),
    ):
        assert (props[key]["minimum"], props[key]["maximum"]) == (lo, hi), key
        assert (
            unit in props[key]["description"] and f"[{lo:g}, {hi:g}]" in props[key]["description"]
        )


PULSE = {"p_eq": 2.0, "lam": 0.2, "a_p_g": 0.3, "f_p": 1.0, "eta": 0.9}


@pytest.mark.parametrize(
    ("key", "value"),
    [("p_eq", 5e-324), ("p_eq", 1001.0), ("f_p", 5e-324), ("lam", 5e-324), ("a_p_g", -101.0)],
)
def test_a_pulse_outside_the_ranges_is_refused_naming_the_field(key: str, value: float) -> None:
    with pytest.raises(ValidationError) as exc:
        PulseRequest.model_validate({**PULSE, key: value})
    assert exc.value.errors()[0]["loc"] == (key,)


CORNERS = list(
    itertools.product(
        rules.P_EQ_RANGE, rules.F_P_RANGE, rules.LAM_RANGE, (rules.A_P_G_MAX, -rules.A_P_G_MAX)
    )
)


@pytest.mark.parametrize(("p_eq", "f_p", "lam", "a_p_g"), CORNERS)
def test_every_corner_of_the_ranges_computes(
    p_eq: float, f_p: float, lam: float, a_p_g: float
) -> None:
    PulseRequest.model_validate({**PULSE, "p_eq": p_eq, "f_p": f_p, "lam": lam, "a_p_g": a_p_g})
    args = ["pulse", "--p-eq", str(p_eq), "--f-p", str(f_p), "--lam", str(lam)]
    res = runner.invoke(app, [*args, "--a-p-g", str(a_p_g), "--eta", "0.9", "--json"])
    assert res.exit_code == 0, res.output
    doc: dict[str, Any] = json.loads(res.stdout)
    assert isinstance(doc, dict) and doc


def _eq28(accel: list[float], units: str = "g") -> dict[str, Any]:
    record = {"accel": accel, "dt": 0.01, "units": units}
    return {"method": "eq28", "h": 4.6, "h_e": 4.54, "f_n": 2.0, "record": record}


def test_an_eq28_record_needs_a_peak_ground_acceleration() -> None:
    with pytest.raises(ValidationError, match=r"record\.accel: needs a sample of magnitude 1e-300"):
        Eq28Request.model_validate(_eq28([0.0, 0.0, 0.0]))
    with pytest.raises(ValidationError, match=r"record\.accel"):
        Eq28Request.model_validate(_eq28([0.0, 1e-310]))
    Eq28Request.model_validate(_eq28([0.0, -1e-300], "mm/s2"))
    branch = Eq28Request.model_json_schema()["oneOf"][1]["properties"]["record"]
    assert branch["properties"]["accel"]["contains"] == {
        "anyOf": [{"minimum": 1e-300}, {"maximum": -1e-300}]
    }
