"""shared_schema.rules: one home per rule, and the copies that mirror it do not drift."""

from __future__ import annotations

import typing

import numpy as np
import pytest

from shared_schema import api, constants, rules, spec
from shared_schema.errors import InputError
from solver_service.core import model, records
from solver_service.workflows import scaling


def _enum(model_cls: type, field: str) -> list[object]:
    extra = model_cls.model_fields[field].json_schema_extra  # type: ignore[attr-defined]
    assert isinstance(extra, dict)
    return [v for v in extra["enum"] if v is not None]


def test_rocking_kinds_match_the_schemas() -> None:
    assert typing.get_args(constants.Rocking) == rules.ROCKING_KINDS
    for typology in spec.TYPOLOGY_SPECS:
        assert typing.get_args(typology.model_fields["rocking"].annotation) == rules.ROCKING_KINDS


def test_api_enums_mirror_the_rules() -> None:
    assert tuple(_enum(api.PulseRequest, "shape")) == rules.PULSE_SHAPES
    assert set(_enum(api.PulseRequest, "criterion")) == set(rules.CRITERIA)
    assert tuple(_enum(api.RecordFileOptions, "format")) == rules.RECORD_FORMATS
    assert tuple(_enum(api.RecordFileOptions, "units")) == tuple(rules.RECORD_UNITS)
    assert tuple(_enum(api.HistoryRequest, "sf")) == rules.SF_METHODS
    assert tuple(_enum(api.RecordSamples, "units")) == tuple(rules.RECORD_UNITS)


def test_scan_length_units_match_the_reader() -> None:
    from cad_maths.scene_mesh import UNITS

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


# ---------------------------------------------------------------- physical ranges (#14)


@pytest.mark.parametrize(
    ("kind", "value", "words"),
    [
        ("density", 1e308, "at most 30000 kg/m\\^3"),
        ("density", 30000.5, "at most 30000 kg/m\\^3"),
        ("density", 0.0, "> 0"),
        ("density", float("nan"), "finite"),
        ("force", 1e300, "at most 1e\\+09 N"),
        ("force", -1.0, "> 0"),
        ("tensile_strength", 1e308, "at most 1e\\+08 Pa"),
        ("density", True, "a number"),
    ],
)
def test_a_quantity_beyond_its_range_is_refused_with_the_range_named(
    kind: str, value: float, words: str
) -> None:
    with pytest.raises(InputError, match=words) as err:
        rules.check_quantity(value, kind, "f")
    assert err.value.field == "f"


@pytest.mark.parametrize(
    ("kind", "value", "note"),
    [
        ("density", 30000.0, True),  # the limit itself is admissible, and implausible
        ("density", 9000.0, False),
        ("density", 300.0, False),
        ("density", 299.0, True),
        ("force", 1e7, False),
        ("force", 1.01e7, True),
        ("tensile_strength", 2e6, False),
        ("tensile_strength", 5e6, True),
    ],
)
def test_an_admissible_quantity_outside_its_band_gets_a_note(
    kind: str, value: float, note: bool
) -> None:
    assert rules.check_quantity(value, kind, "f") == value
    text = rules.quantity_note(value, kind, "W.f")
    assert (text is not None) == note
    if text is not None:
        assert text.startswith(f"W.f = {value:g} {rules.QUANTITY_RANGES[kind].unit} is outside")


def test_coordinates_are_refused_when_not_finite_or_beyond_the_limit() -> None:
    assert rules.coordinate_problem([1e6, -1e6, 0.0]) is None
    assert "finite" in str(rules.coordinate_problem([0.0, float("nan"), 0.0]))
    assert "beyond the largest magnitude accepted, 1e+06 m" in str(
        rules.coordinate_problem([0.0, -1.00001e6, 0.0])
    )
    assert "inf" in str(rules.coordinate_problem([float("inf"), 0.0, 0.0]))


@pytest.mark.parametrize(
    ("size_m", "scale", "units", "scan", "advice"),
    [
        (3202.0, 1.0, "meters", True, "if the file is in mm, give units mm (--units mm)"),
        (320.2, 1.0, "meters", True, "if the file is in cm, give units cm (--units cm)"),
        (
            0.0032,
            0.001,
            "millimeters",
            False,
            "if the file is in m, set its model units to m in Rhino",
        ),
        (1e5, 1.0, "meters", False, "if the file is in mm, set its model units to mm in Rhino"),
        (1e7, 1.0, "meters", False, "check the file's length unit"),
    ],
)
def test_an_implausible_body_size_names_the_unit_read_and_the_one_that_fits(
    size_m: float, scale: float, units: str, scan: bool, advice: str
) -> None:
    note = rules.body_size_note(size_m, scale, units, "W", scan)
    assert note is not None
    assert note.startswith(f"W: the body is {size_m:.4g} m across as read in {units}")
    assert note.endswith(advice), note
    assert rules.body_size_note(0.01, 1.0, "meters", "W", scan) is None
    assert rules.body_size_note(200.0, 1.0, "meters", "W", scan) is None


def _vocabularies() -> dict[str, frozenset[str]]:
    out = {}
    for name in dir(rules):
        value = getattr(rules, name)
        if name.isupper() and isinstance(value, tuple) and len(value) > 1:
            if all(isinstance(v, str) for v in value):
                out[name] = frozenset(value)
    return out


def copies_of_a_vocabulary(source: str) -> list[str]:
    """Top-level names a module binds to a literal copy of a vocabulary of ``rules``."""
    import ast

    vocabularies = _vocabularies()
    found = []
    for node in ast.parse(source).body:
        target, value = None, None
        if isinstance(node, ast.Assign) and len(node.targets) == 1:
            target, value = node.targets[0], node.value
        elif isinstance(node, ast.AnnAssign):
            target, value = node.target, node.value
        if not isinstance(target, ast.Name) or not isinstance(value, (ast.Tuple, ast.List)):
            continue
        items = [e.value for e in value.elts if isinstance(e, ast.Constant)]
        if len(items) != len(value.elts) or not all(isinstance(v, str) for v in items):
            continue
        for name, vocabulary in vocabularies.items():
            if frozenset(items) == vocabulary:
                found.append(f"{target.id} copies rules.{name}")
    return found


def test_each_vocabulary_is_defined_once() -> None:
    """One home per vocabulary: no module outside rules.py spells one out again (#38)."""
    from pathlib import Path

    root = Path(rules.__file__).resolve().parents[1]
    copies = {}
    for package in ("shared_schema", "cad_maths", "solver_service", "rhino_plugin", "rockmech"):
        for path in sorted((root / package).rglob("*.py")):
            if path.name == "rules.py" and path.parent.name == "shared_schema":
                continue
            found = copies_of_a_vocabulary(path.read_text(encoding="utf-8"))
            if found:
                copies[path.relative_to(root).as_posix()] = found
    assert copies == {}
    # the check finds the copy the solver's result module held before #38
    assert copies_of_a_vocabulary('CRITERIA = ("ratio", "exact")\n') == [
        "CRITERIA copies rules.CRITERIA"
    ]
