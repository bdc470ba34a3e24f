"""The plausible ranges of a pulse request: consistent with the solver and the work bound,
stated in the published schema, and wide enough that every corner still computes; and the
record, height and restitution rules the schema states, each exactly as the service enforces it."""

from __future__ import annotations

import itertools
import json
import math
from typing import Any

import jsonschema
import numpy as np
import pytest
from pydantic import BaseModel, ValidationError
from typer.testing import CliRunner

from shared_schema import rules
from shared_schema.api import (
    MULTIPLE_MAX,
    AssessRequest,
    Ec8Request,
    EnvelopeRequest,
    Eq28Request,
    HistoryRequest,
    NzsRequest,
    PulseRequest,
    RecordSamples,
    ReportRequest,
    SpectrumRequest,
    time_domain_problem,
)
from shared_schema.constants import ConstantsFile, validation_lines
from shared_schema.errors import InputError
from shared_schema.site import SiteFile
from solver_service.api.jobs import history_options, scale_factor_doc
from solver_service.cli import app
from solver_service.codes import scale_factors as codes
from solver_service.core import exact
from solver_service.core.records import GroundMotion
from solver_service.workflows import assess
from solver_service.workflows.limits import DEFAULT_LIMITS, WORK_PER_SAMPLE
from solver_service.workflows.pages import check_history_options

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
    # phi_ov defaults to lam only where lam is an angle (at most pi/2, issue #36): beyond, the
    # largest rotation admitted
    phi_ov = min(lam, rules.ROTATION_MAX)
    body = {**PULSE, "p_eq": p_eq, "f_p": f_p, "lam": lam, "a_p_g": a_p_g, "phi_ov": phi_ov}
    PulseRequest.model_validate(body)
    args = ["pulse", "--p-eq", str(p_eq), "--f-p", str(f_p), "--lam", str(lam)]
    args += ["--phi-ov", repr(phi_ov)]
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


# --- records and heights: what the schema states is what the service enforces -----------------


def _valid(model: type[BaseModel], doc: dict[str, Any]) -> bool:
    """Whether ``doc`` is valid against ``model``'s published JSON Schema (draft 2020-12)."""
    validator = jsonschema.Draft202012Validator(model.model_json_schema())
    return not list(validator.iter_errors(doc))


def _read(accel: list[float], dt: float, units: str) -> str | None:
    """Return the field the record reader refuses, or None when it reads the samples."""
    try:
        GroundMotion.from_samples(np.asarray(accel), dt, units=units)
    except InputError as exc:
        return exc.field
    return None


@pytest.mark.parametrize("units", list(rules.RECORD_UNITS))
def test_the_largest_sample_is_stated_per_unit_as_the_reader_enforces_it(units: str) -> None:
    top = rules.accel_max(units)
    assert math.isclose(top * rules.RECORD_UNITS[units], rules.ACCEL_MAX_G * rules.G)
    for accel, ok in (
        ([top, -top], True),
        ([0.0, math.nextafter(top, math.inf)], False),
        ([math.nextafter(-top, -math.inf), 0.0], False),
    ):
        doc = {"accel": accel, "dt": 0.01, "units": units}
        assert _valid(RecordSamples, doc) is ok, (units, accel)
        assert _read(accel, 0.01, units) == (None if ok else "record"), (units, accel)
    assert (
        f"{top:.6g} {units}"
        in RecordSamples.model_json_schema()["properties"]["accel"]["description"]
    )


def edge_cases(bounds: tuple[float, float]) -> list[tuple[float, bool]]:
    """The two ends of a range (allowed), the next floats outside and the smallest float."""
    lo, hi = bounds
    return [
        (lo, True),
        (hi, True),
        (math.nextafter(lo, 0.0), False),
        (math.nextafter(hi, math.inf), False),
        (5e-324, False),
    ]


@pytest.mark.parametrize(
    ("dt", "ok"),
    edge_cases(rules.DT_RANGE_S),
)
def test_the_time_step_range_is_stated_as_the_reader_enforces_it(dt: float, ok: bool) -> None:
    doc = {"accel": [0.0, 0.1], "dt": dt, "units": "g"}
    assert _valid(RecordSamples, doc) is ok
    assert _read([0.0, 0.1], dt, "g") == (None if ok else "dt")
    assert "[1e-06, 1]" in RecordSamples.model_json_schema()["properties"]["dt"]["description"]


HEIGHT_CASES = [
    (Eq28Request, {"method": "eq28", "sa_g": 0.2, "pga_g": 0.1, "h": 4.6, "h_e": 4.5}, "h"),
    (Eq28Request, {"method": "eq28", "sa_g": 0.2, "pga_g": 0.1, "h": 4.6, "h_e": 4.5}, "h_e"),
    (Ec8Request, {"method": "ec8", "z": 4.0, "H": 12.0, "T_a": 0.0, "T_1": 0.5}, "H"),
    (NzsRequest, {"method": "nzs", "h_i": 4.6, "h_n": 9.0}, "h_n"),
]


@pytest.mark.parametrize(("model", "doc", "key"), HEIGHT_CASES)
def test_the_tallest_height_is_stated_as_the_codes_enforce_it(
    model: type[BaseModel], doc: dict[str, Any], key: str
) -> None:
    top = rules.BUILDING_HEIGHT_MAX_M
    assert codes.BUILDING_HEIGHT_MAX_M == top
    for value, ok in ((top, True), (math.nextafter(top, math.inf), False)):
        body = {**doc, key: value}
        assert _valid(model, body) is ok, body
        try:
            doc_out = scale_factor_doc(model.model_validate(body), DEFAULT_LIMITS)
        except InputError as exc:
            assert not ok and exc.field == key, exc
        else:
            assert ok and doc_out["value"] >= 1.0
    assert "at most 1000 m" in model.model_json_schema()["properties"][key]["description"]


@pytest.mark.parametrize(
    ("given", "missing"),
    [
        ({"eta_to_negative": 0.5, "eta": 0.6}, "eta_to_positive"),
        ({"eta_to_positive": 0.7, "eta": 0.6}, "eta_to_negative"),
        ({"eta_to_negative": 0.5, "eta_to_positive": 0.7}, "eta"),
        ({"eta_source": "user"}, "eta"),
    ],
)
def test_the_restitutions_that_go_together_are_stated_as_the_file_enforces_them(
    given: dict[str, Any], missing: str
) -> None:
    mech = {"id": "W1", "p_eq": 2.0, "lam": 0.2, **given}
    assert not _valid(ConstantsFile, {"mechanisms": [mech]})
    with pytest.raises(ValidationError, match=missing):
        ConstantsFile.model_validate({"mechanisms": [mech]})
    full = {"id": "W1", "p_eq": 2.0, "lam": 0.2, "eta": 0.6, "eta_to_negative": 0.5}
    full["eta_to_positive"] = 0.7
    assert _valid(ConstantsFile, {"mechanisms": [full]})
    ConstantsFile.model_validate({"mechanisms": [full]})


@pytest.mark.parametrize(
    ("f_n", "ok"),
    edge_cases(rules.F_N_RANGE),
)
def test_the_natural_frequency_range_is_stated_as_the_service_enforces_it(
    f_n: float, ok: bool
) -> None:
    body = {**_eq28([0.0, 0.3, -0.2, 0.1]), "f_n": f_n}
    assert _valid(Eq28Request, body) is ok
    try:
        doc = scale_factor_doc(Eq28Request.model_validate(body), DEFAULT_LIMITS)
    except InputError as exc:
        assert not ok and exc.field == "f_n", exc
    else:
        assert ok and doc["value"] >= 1.0 and math.isclose(doc["inputs"]["T_n"], 1 / f_n)


# --- the constants file's rules across fields, stated null-aware (null means "not given") ---

MECHANISM_RULE_CASES = [
    ({"eta_to_negative": None}, True),
    ({"eta": 0.6, "eta_to_negative": 0.5, "eta_to_positive": None}, False),
    ({"eta": None, "eta_to_negative": 0.5, "eta_to_positive": 0.7}, False),
    ({"eta": 0.6, "eta_to_negative": 0.5, "eta_to_positive": 0.7}, True),
    ({"rocking": "one_sided", "eta": -0.5, "eta_to_negative": 0.5, "eta_to_positive": 0.7}, False),
    ({"eta_source": None}, True),
    ({"eta_source": "user", "eta": None}, False),
    ({"rocking": "one_sided", "eta": 0.5}, False),
    ({"rocking": "one_sided", "eta": -0.5}, True),
    ({"rocking": "two_sided", "eta": -0.5}, False),
    ({"eta": -0.5}, False),
    ({"rocking": "one_sided", "eta": None}, True),
]


def _schema_and_file_agree(doc: dict[str, Any], ok: bool) -> None:
    """Assert that the file's JSON Schema and its model accept ``doc`` exactly when ``ok``."""
    assert _valid(ConstantsFile, doc) is ok
    try:
        ConstantsFile.model_validate(doc)
    except ValidationError:
        assert not ok
    else:
        assert ok


@pytest.mark.parametrize(("given", "ok"), MECHANISM_RULE_CASES)
def test_the_restitution_rules_are_stated_as_the_file_enforces_them_with_nulls(
    given: dict[str, Any], ok: bool
) -> None:
    _schema_and_file_agree({"mechanisms": [{"id": "W1", "p_eq": 2.0, "lam": 0.2, **given}]}, ok)


PHYSICAL = {"I0": 2.0, "K": 8.0, "Q": 1.0, "phi_cr": 0.2}
SIDE_FORM_CASES = [
    (PHYSICAL, True),
    ({**PHYSICAL, "M_F": 0.5}, True),
    ({**PHYSICAL, "Q": None}, False),
    ({"I0": 2.0, "p_eq": 2.0, "lam": 0.2}, False),
    ({"I0": None, "K": None, "Q": None, "phi_cr": None, "p_eq": 2.0, "lam": 0.2}, True),
    ({"I0": None, "K": None, "Q": None, "phi_cr": None}, False),
    ({"p_eq": 2.0, "lam": 0.2, "M_F": 1.0}, False),
    ({"p_eq": 2.0, "lam": 0.2, "M_F": None}, True),
    ({"p_eq": 2.0, "lam": None}, False),
]


@pytest.mark.parametrize(("side", "ok"), SIDE_FORM_CASES)
def test_the_two_forms_of_a_side_are_stated_as_the_file_enforces_them(
    side: dict[str, Any], ok: bool
) -> None:
    _schema_and_file_agree({"mechanisms": [{"id": "W1", "positive": side}]}, ok)


@pytest.mark.parametrize(
    ("value", "ok"), [(100, True), (100.0, True), (2.5, False), (True, False), ("3", False)]
)
def test_an_integer_written_with_a_point_is_an_integer_as_json_schema_says(
    value: object, ok: bool
) -> None:
    site = {"hazard": {"code": "NTC2018", "a_g": 0.2, "F0": 2.5, "Tc_star": 0.3, "FC": 1.35}}
    doc = {**site, "building": {"height": 12.0, "storeys": value}}
    assert _valid(SiteFile, doc) is ok
    assert _valid(SpectrumRequest, {**SPECTRUM, "n": value}) is ok
    for model, body in ((SiteFile, doc), (SpectrumRequest, {**SPECTRUM, "n": value})):
        try:
            model.model_validate_json(json.dumps(body))
        except ValidationError:
            assert not ok
        else:
            assert ok


SPECTRUM = {"record": {"accel": [0.0, 0.1, -0.1], "dt": 0.01, "units": "g"}}
TIME_DOMAIN = {"mechanisms": [{"id": "W1", "p_eq": 2.0, "lam": 0.2, "eta": 0.9}]}


@pytest.mark.parametrize(
    ("key", "value", "ok"),
    [
        ("p_eq", rules.P_EQ_RANGE[0], True),
        ("p_eq", rules.P_EQ_RANGE[1], True),
        ("p_eq", 5e-324, False),
        ("p_eq", math.nextafter(rules.P_EQ_RANGE[1], math.inf), False),
        ("lam", rules.LAM_RANGE[1], True),
        ("lam", math.nextafter(rules.LAM_RANGE[0], 0.0), False),
    ],
)
def test_time_domain_constants_are_plausible_as_stated(key: str, value: float, ok: bool) -> None:
    # phi_ov given: it defaults to lam, which must then be an angle (at most pi/2)
    flat = {"mechanisms": [{**TIME_DOMAIN["mechanisms"][0], "phi_ov": 0.2, key: value}]}
    side = {
        "id": "W1",
        "eta": 0.9,
        "positive": {"p_eq": 2.0, "lam": 0.2, "phi_ov": 0.2, key: value},
    }
    for constants in (flat, {"mechanisms": [side]}):
        body = {"constants": constants}
        assert _valid(EnvelopeRequest, body) is ok
        try:
            EnvelopeRequest.model_validate(body)
        except ValidationError as exc:
            assert not ok
            (path, message), *_ = validation_lines(exc)
            assert path == f"constants.mechanisms[0].positive.{key}", path
            assert f"got {value!r}" in message and "plausible" in message
        else:
            assert ok


def test_a_physical_form_outside_the_time_domain_range_is_refused_naming_the_side() -> None:
    # p_eq = sqrt(K/I0) = 2e3 rad/s: derived, so the schema cannot state it.
    side = {"I0": 1.0, "K": 4e6, "Q": 1e6, "phi_cr": 0.1}
    cf = ConstantsFile.model_validate(
        {"mechanisms": [{"id": "W", "negative": side, **TIME_DOMAIN["mechanisms"][0]}]}
    )
    assert time_domain_problem(cf) == (
        "mechanisms[0].negative.p_eq",
        "must be in [0.01, 1000] for a time-domain analysis (a plausible range, as for a "
        "pulse), got 2000.0 (mechanism 'W1')",
    )
    with pytest.raises(ValidationError) as info:
        HistoryRequest.model_validate({"constants": cf.model_dump(exclude_none=True), **SPECTRUM})
    assert validation_lines(info.value)[0][0] == "constants.mechanisms[0].negative.p_eq"


@pytest.mark.parametrize(
    ("value", "ok"),
    [(rules.F_P_RANGE[0], True), (rules.F_P_RANGE[1], True), (5e-324, False), (1e300, False)],
)
def test_envelope_frequencies_are_in_the_pulse_range_as_stated(value: float, ok: bool) -> None:
    for model in (EnvelopeRequest, ReportRequest):
        for key in ("f_min", "f_max"):
            body = {"constants": TIME_DOMAIN, key: value}
            assert _valid(model, body) is ok
            try:
                model.model_validate(body)
            except ValidationError as exc:
                assert not ok and validation_lines(exc)[0][0] == key
            else:
                assert ok


REPORT_OPTIONS = [
    ({}, True),
    ({"scales": [1.0]}, True),
    ({"scales": [2.0]}, False),
    ({"sf": "eq28"}, False),
    ({"criterion": "exact"}, False),
    ({"criterion": None, "at_height": None, "building_height": None}, True),
    ({"at_height": 1.0}, False),
    ({"building_height": 10.0}, False),
    ({"soil_factor": 1.2}, False),
    ({"element_period": 0.0, "soil_factor": 1}, True),
    ({"element_period": 0.1}, False),
]


@pytest.mark.parametrize(("options", "ok"), REPORT_OPTIONS)
def test_a_report_without_a_record_keeps_the_history_options_as_stated(
    options: dict[str, Any], ok: bool
) -> None:
    body = {"constants": TIME_DOMAIN, **options}
    assert _valid(ReportRequest, body) is ok
    assert _valid(ReportRequest, {**body, "record": SPECTRUM["record"]})
    request = ReportRequest.model_validate(body)
    try:
        check_history_options(request.scales, history_options(request), None)
    except InputError as exc:
        assert not ok and exc.field in {*options, "building"}, exc
    else:
        assert ok


def test_the_largest_multiple_is_stated_as_the_assessment_enforces_it() -> None:
    items = AssessRequest.model_json_schema()["properties"]["multiples"]["items"]
    assert items["maximum"] == MULTIPLE_MAX == assess.MULTIPLE_MAX
    assert assess.check_multiples([MULTIPLE_MAX]) == [MULTIPLE_MAX]
    with pytest.raises(InputError, match="must be in"):
        assess.check_multiples([math.nextafter(MULTIPLE_MAX, math.inf)])


@pytest.mark.parametrize(
    ("key", "value", "ok"),
    [
        ("f_n", rules.F_N_RANGE[0], True),
        ("f_n", math.nextafter(rules.F_N_RANGE[0], 0.0), False),
        ("f_n", math.nextafter(rules.F_N_RANGE[1], math.inf), False),
        ("h", rules.BUILDING_HEIGHT_MAX_M, True),
        ("h", math.nextafter(rules.BUILDING_HEIGHT_MAX_M, math.inf), False),
        ("h_e", math.nextafter(rules.BUILDING_HEIGHT_MAX_M, math.inf), False),
    ],
)
def test_time_domain_amplification_data_are_plausible_as_stated(
    key: str, value: float, ok: bool
) -> None:
    amp = {"f_n": 2.0, "h": 5.0, "h_e": 10.0, key: value}
    constants = {"mechanisms": [{**TIME_DOMAIN["mechanisms"][0], "amplification": amp}]}
    site = {"hazard": {"code": "NTC2018", "a_g": 0.2, "F0": 2.5, "Tc_star": 0.3, "FC": 1.35}}
    assess_body = {"constants": constants, "site": site, "records": [SPECTRUM["record"]]}
    for model, body in ((EnvelopeRequest, {"constants": constants}), (AssessRequest, assess_body)):
        assert _valid(model, body) is ok
        try:
            model.model_validate(body)
        except ValidationError as exc:
            assert not ok
            assert validation_lines(exc)[0][0] == f"constants.mechanisms[0].amplification.{key}"
        else:
            assert ok
