"""shared_schema.rules: one home per rule, and the copies that mirror it do not drift."""

from __future__ import annotations

import typing

import numpy as np
import pytest

from rhino_plugin.mechanisms.build import MECHANISMS
from shared_schema import api, constants, rules, spec
from shared_schema.errors import InputError
from solver_service.core import model, records
from solver_service.workflows import scaling


def _enum(model_cls: type, field: str) -> list[object]:
    extra = model_cls.model_fields[field].json_schema_extra  # type: ignore[attr-defined]
    assert isinstance(extra, dict)
    return [v for v in extra["enum"] if v is not None]


def test_typologies_match_the_registry_and_both_schemas() -> None:
    assert tuple(MECHANISMS) == rules.TYPOLOGIES
    spec_typologies = typing.get_args(spec.MechanismSpec.model_fields["typology"].annotation)
    assert spec_typologies == rules.TYPOLOGIES
    assert typing.get_args(constants.Typology) == (*rules.TYPOLOGIES, "user_defined")


def test_rocking_kinds_match_the_schemas() -> None:
    assert typing.get_args(constants.Rocking) == rules.ROCKING_KINDS
    assert typing.get_args(spec.MechanismSpec.model_fields["rocking"].annotation) == (
        rules.ROCKING_KINDS
    )


def test_api_enums_mirror_the_rules() -> None:
    assert tuple(_enum(api.PulseRequest, "shape")) == rules.PULSE_SHAPES
    assert set(_enum(api.PulseRequest, "criterion")) == set(rules.CRITERIA)
    assert tuple(_enum(api.RecordFileOptions, "format")) == rules.RECORD_FORMATS
    assert tuple(_enum(api.RecordFileOptions, "units")) == tuple(rules.RECORD_UNITS)
    assert tuple(_enum(api.HistoryRequest, "sf")) == rules.SF_METHODS
    assert tuple(_enum(api.RecordSamples, "units")) == tuple(rules.RECORD_UNITS)


def test_scan_length_units_match_the_reader() -> None:
    from rhino_plugin.scene_mesh import UNITS

    assert tuple(UNITS) == rules.LENGTH_UNITS
    assert tuple(_enum(api.ConstantsForm, "units")) == rules.LENGTH_UNITS


def test_core_and_workflows_use_the_rules_themselves() -> None:
    assert model.G is constants.G is rules.G
    assert records.FORMATS is rules.RECORD_FORMATS
    assert records.UNITS is rules.RECORD_UNITS
    assert scaling.SF_METHODS is rules.SF_METHODS
    assert model.check_eta is rules.check_eta


@pytest.mark.parametrize(
    ("value", "kwargs", "message"),
    [
        (True, {}, "must be a number"),
        ("1.0", {}, "must be a number"),
        (float("nan"), {}, "must be finite"),
        (np.inf, {}, "must be finite"),
        (0.0, {"above": 0.0}, "must be finite and > 0"),
        (-1e-300, {"at_least": 0.0}, "must be >= 0"),
        (2.0, {"at_most": 1.0}, "must be <= 1"),
    ],
)
def test_number_check_names_the_field_and_the_problem(
    value: object, kwargs: dict[str, float], message: str
) -> None:
    with pytest.raises(InputError, match=message) as info:
        rules.check_number(value, "mechanisms[2].p_eq", **kwargs)
    assert info.value.field == "mechanisms[2].p_eq"


def test_number_check_takes_python_and_numpy_numbers() -> None:
    assert rules.check_number(np.float32(0.5), "x") == 0.5
    assert rules.check_number(np.int64(3), "x", at_least=3) == 3.0
    assert rules.check_positive(1e-300, "x") == 1e-300


@pytest.mark.parametrize(
    ("eta", "one_sided", "ok"),
    [
        (0.0, False, True),
        (1.0, False, True),
        (-0.1, False, False),
        (0.0, True, True),
        (-1.0, True, True),
        (0.1, True, False),
        (1.5, False, False),
        (-1.5, True, False),
    ],
)
def test_eta_sign_rule_is_the_same_everywhere(eta: float, one_sided: bool, ok: bool) -> None:
    lo, hi = rules.eta_range(one_sided)
    assert (lo <= eta <= hi) is ok
    assert (rules.eta_problem(eta, one_sided) is None) is ok
    rocking = "one_sided" if one_sided else "two_sided"
    entry = {"id": "M", "rocking": rocking, "p_eq": 2.0, "lam": 0.2, "eta": eta}
    if ok:
        rules.check_eta(eta, one_sided)
        constants.ConstantsFile.model_validate({"mechanisms": [entry]})
    else:
        with pytest.raises(InputError, match="eta"):
            rules.check_eta(eta, one_sided)
        with pytest.raises(InputError, match="eta"):
            constants.parse_constants({"mechanisms": [entry]})
