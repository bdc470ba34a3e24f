"""Tests of the kinematic-constants models (shared_schema.constants)."""

import copy
import json
import math

import pytest
from pydantic import ValidationError

from shared_schema.constants import (
    ETA_SOURCES,
    SCHEMA_VERSION,
    ConstantsFile,
    G,
    Mechanism,
    SideConstants,
    parse_constants,
)
from shared_schema.errors import InputError, RockmechError

# Published-table form, as in the brief (theory §8 style wall mechanism).
W1 = {
    "id": "W1",
    "rocking": "two_sided",
    "p_eq": 2.15,
    "lam": 0.25,
    "eta": 0.90,
    "amplification": {"f_n": 6.22, "h_e": 4.66, "h": 3.11},
}


def rectangular_block(b=0.5, h=3.0, density=2000.0, length=1.0):
    """Physical constants of a rectangular block rocking about a base corner (theory §2.1)."""
    mass = density * b * h * length
    r = 0.5 * math.hypot(b, h)
    alpha = math.atan(b / h)
    return {
        "I0": 4.0 / 3.0 * mass * r**2,  # Eq. 7, I_O of a rectangle
        "K": mass * G * r,  # Eq. 8
        "Q": mass * r,  # Eq. 10
        "phi_cr": alpha,  # Eq. 9
    }, (mass, r, alpha)


def one_file(*mechanisms):
    return {"mechanisms": list(mechanisms)}


def parse_error(data):
    with pytest.raises(InputError) as info:
        parse_constants(data)
    return info.value


# --- derived constants -------------------------------------------------------------------


def test_rectangular_block_gives_housner_frequency_and_slenderness():
    phys, (mass, r, alpha) = rectangular_block()
    assert mass == pytest.approx(3000.0, rel=1e-15)
    cf = parse_constants(one_file({"id": "B", "positive": phys}))
    side = cf.mechanisms[0].positive
    assert side.p_eq == pytest.approx(math.sqrt(3.0 * G / (4.0 * r)), rel=1e-12, abs=0)
    assert side.lam == pytest.approx(alpha, rel=1e-12, abs=0)
    assert side.phi_ov == pytest.approx(alpha, rel=1e-12, abs=0)
    # Without static forces M_F defaults to 0 and is stored.
    assert side.M_F == 0.0


# K = 40000 N m/rad, phi_cr = 0.1 rad, Q = 2000 kg m, I0 = 10000 kg m^2, M_F = 1000 N m:
# K phi_cr = 4000 N m, g Q = 19613.3 N.
# positive (Eq. 5, 6): lam = (4000 - 1000)/19613.3 = 0.152957..., phi_ov = 0.1 - 0.025 = 0.075
# negative (§1.8):     lam = (4000 + 1000)/19613.3 = 0.254929..., phi_ov = 0.1 + 0.025 = 0.125
LOADED_SIDE = {"I0": 10000.0, "K": 40000.0, "Q": 2000.0, "phi_cr": 0.1, "M_F": 1000.0}


def test_static_moment_reduces_positive_and_increases_negative_multiplier():
    mech = {"id": "L1", "positive": LOADED_SIDE, "negative": LOADED_SIDE}
    m = parse_constants(one_file(mech)).mechanisms[0]
    assert m.positive.lam == pytest.approx(3000.0 / 19613.3, rel=1e-12)
    assert m.positive.lam == pytest.approx(0.15295743, rel=1e-7)
    assert m.positive.phi_ov == pytest.approx(0.075, rel=1e-12)
    assert m.negative is not None
    assert m.negative.lam == pytest.approx(5000.0 / 19613.3, rel=1e-12)
    assert m.negative.lam == pytest.approx(0.25492906, rel=1e-7)
    assert m.negative.phi_ov == pytest.approx(0.125, rel=1e-12)
    # p_eq does not depend on M_F (Eq. 4): sqrt(40000/10000) = 2.
    assert m.positive.p_eq == pytest.approx(2.0, rel=1e-15)
    assert m.negative.p_eq == pytest.approx(2.0, rel=1e-15)


def test_static_moment_zero_gives_same_constants_on_both_sides():
    side = dict(LOADED_SIDE, M_F=0.0)
    m = parse_constants(one_file({"id": "L0", "positive": side, "negative": side})).mechanisms[0]
    assert m.negative is not None
    assert m.positive.lam == pytest.approx(4000.0 / 19613.3, rel=1e-12)
    assert m.positive.lam == m.negative.lam
    assert m.positive.phi_ov == m.negative.phi_ov == pytest.approx(0.1, rel=1e-15)


def test_restraining_static_moment_increases_positive_multiplier():
    # A tie force: M_F = -1000 N m resists positive rotation.
    m = parse_constants(one_file({"id": "T", "positive": dict(LOADED_SIDE, M_F=-1000.0)}))
    assert m.mechanisms[0].positive.lam == pytest.approx(5000.0 / 19613.3, rel=1e-12)
    assert m.mechanisms[0].positive.phi_ov == pytest.approx(0.125, rel=1e-12)


def test_static_forces_that_alone_overturn_are_rejected_naming_side_and_lam():
    side = dict(LOADED_SIDE, M_F=4000.0)  # M_F = K phi_cr: lam = 0
    err = parse_error(one_file({"id": "Thrust", "positive": side}))
    assert err.field == "mechanisms[0] (id 'Thrust').positive.lam"
    assert "static forces alone overturn" in str(err)
    assert "positive side" in str(err)
    err = parse_error(
        one_file({"id": "Tie", "positive": LOADED_SIDE, "negative": dict(LOADED_SIDE, M_F=-4500.0)})
    )
    assert err.field == "mechanisms[0] (id 'Tie').negative.lam"
    assert "static forces alone overturn" in str(err)


def test_consistent_given_short_constants_are_accepted_with_physical_ones():
    phys, (_, r, alpha) = rectangular_block()
    side = dict(phys, p_eq=math.sqrt(3.0 * G / (4.0 * r)) * (1 + 1e-12), lam=alpha)
    m = parse_constants(one_file({"id": "B", "positive": side})).mechanisms[0]
    assert m.positive.lam == pytest.approx(alpha, rel=1e-12)


@pytest.mark.parametrize("key", ["p_eq", "lam", "phi_ov"])
def test_inconsistent_given_short_constant_is_rejected_naming_it(key):
    phys, (_, r, alpha) = rectangular_block()
    derived = {"p_eq": math.sqrt(3.0 * G / (4.0 * r)), "lam": alpha, "phi_ov": alpha}
    side = dict(phys, **{key: derived[key] * (1 + 1e-7)})
    err = parse_error(one_file({"id": "B", "positive": side}))
    assert err.field == f"mechanisms[0] (id 'B').positive.{key}"
    assert "disagrees" in str(err)


def test_incomplete_physical_form_names_the_missing_constant():
    phys, _ = rectangular_block()
    del phys["Q"]
    err = parse_error(one_file({"id": "B", "positive": phys}))
    assert err.field == "mechanisms[0] (id 'B').positive.Q"


def test_static_moment_without_physical_constants_is_rejected():
    err = parse_error(one_file({"id": "S", "positive": {"p_eq": 2.0, "lam": 0.2, "M_F": 5.0}}))
    assert err.field == "mechanisms[0] (id 'S').positive.M_F"


def test_short_form_without_lam_is_rejected_naming_lam():
    err = parse_error(one_file({"id": "S", "positive": {"p_eq": 2.0}}))
    assert err.field == "mechanisms[0] (id 'S').positive.lam"


def test_side_constants_alone_leave_derivation_to_the_mechanism():
    side = SideConstants.model_validate({"p_eq": 2.0, "lam": 0.2})
    assert side.phi_ov is None
    assert not side.is_physical


# --- short published-table form ----------------------------------------------------------


def test_published_table_form_is_moved_into_positive_side():
    m = Mechanism.model_validate(W1)
    assert (m.positive.p_eq, m.positive.lam, m.positive.phi_ov) == (2.15, 0.25, 0.25)
    assert m.negative is None
    assert m.name == "W1"
    assert m.typology == "user_defined"
    assert m.eta == 0.9
    assert m.eta_source == "user"
    assert m.amplification is not None
    assert (m.amplification.f_n, m.amplification.h_e, m.amplification.h) == (6.22, 4.66, 3.11)
    assert m.geometry is None and m.provenance is None


def test_flat_phi_ov_overrides_the_default():
    m = Mechanism.model_validate(dict(W1, phi_ov=0.2))
    assert m.positive.phi_ov == 0.2
    assert m.positive.lam == 0.25


def test_flat_form_does_not_modify_the_callers_dict():
    data = copy.deepcopy(W1)
    Mechanism.model_validate(data)
    assert data == W1


def test_flat_and_nested_positive_together_are_rejected():
    data = dict(W1, positive={"p_eq": 2.0, "lam": 0.2})
    err = parse_error([data])
    assert err.field == "mechanisms[0] (id 'W1').p_eq"
    assert "not both" in str(err)


def test_file_of_only_mechanisms_gets_default_version_and_units():
    cf = parse_constants({"mechanisms": [W1]})
    assert cf.schema_version == SCHEMA_VERSION == "1.0"
    assert cf.units.p_eq == "rad/s"
    assert cf.units.I0 == "kg m^2"


@pytest.mark.parametrize("source", [[W1], json.dumps([W1]), json.dumps([W1]).encode()])
def test_bare_list_of_mechanisms_is_a_file(source):
    cf = parse_constants(source)
    assert [m.id for m in cf.mechanisms] == ["W1"]


def test_json_text_and_python_data_give_the_same_model():
    assert parse_constants(json.dumps(one_file(W1))) == parse_constants(one_file(W1))


def test_integers_are_accepted_for_floats():
    m = parse_constants(json.dumps([{"id": "I", "p_eq": 2, "lam": 1, "eta": 1}])).mechanisms[0]
    assert isinstance(m.positive.p_eq, float) and m.positive.p_eq == 2.0
    assert isinstance(m.eta, float)


def test_explicit_eta_source_is_kept():
    assert Mechanism.model_validate(dict(W1, eta_source="published")).eta_source == "published"
    assert set(ETA_SOURCES) >= {"housner_general", "one_sided_eq26", "user", "published"}


def test_one_sided_mechanism_accepts_negative_and_absent_eta():
    base = {"id": "F", "rocking": "one_sided", "p_eq": 1.9, "lam": 0.09}
    assert Mechanism.model_validate(base).eta is None
    assert Mechanism.model_validate(dict(base, eta=-0.6)).eta == -0.6


def test_get_mechanism_finds_by_id_and_names_missing_ones():
    cf = parse_constants([W1, dict(W1, id="W2")])
    assert cf.get_mechanism("W2").id == "W2"
    with pytest.raises(InputError, match=r"'W3'.*'W1', 'W2'"):
        cf.get_mechanism("W3")


# --- rejections name the mechanism and the field -----------------------------------------


def with_bad(**changes):
    """A two-mechanism file whose second mechanism, id 'W2', carries ``changes``."""
    bad = dict(W1, id="W2", **changes)
    return one_file(W1, bad)


REJECTIONS = [
    # (changes to mechanism W2, expected field path after the id, expected message part)
    ({"p_eq": True}, "positive.p_eq", "valid number"),
    ({"p_eq": -2.15}, "positive.p_eq", "greater than 0"),
    ({"lam": 0}, "positive.lam", "greater than 0"),
    ({"phi_ov": 0.0}, "positive.phi_ov", "greater than 0"),
    ({"eta": 1.3}, "eta", "less than or equal to 1"),
    ({"eta": True}, "eta", "valid number"),
    ({"eta": -0.5}, "eta", ">= 0 for two-sided"),
    ({"eta": 0.5, "rocking": "one_sided"}, "eta", "<= 0 for one-sided"),
    ({"damping": 0.05}, "damping", "Extra inputs are not permitted"),
    ({"typology": "arch"}, "typology", "two_block"),
    ({"rocking": "both"}, "rocking", "one_sided"),
    ({"eta_source": "guess"}, "eta_source", "published"),
    ({"amplification": {"f_n": 0, "h_e": 4.66, "h": 3.11}}, "amplification.f_n", "greater than 0"),
    ({"amplification": {"f_n": 6.2, "h_e": 4.66, "h": -1}}, "amplification.h", "greater than or"),
    ({"amplification": {"f_n": 6.2, "h_e": 4.66}}, "amplification.h", "Field required"),
    ({"negative": {"p_eq": 2.0, "lam": -0.1}}, "negative.lam", "greater than 0"),
    ({"name": 7}, "name", "valid string"),
]


@pytest.mark.parametrize(("changes", "field", "message"), REJECTIONS)
def test_invalid_value_is_rejected_naming_mechanism_and_field(changes, field, message):
    err = parse_error(with_bad(**changes))
    assert isinstance(err, RockmechError) and isinstance(err, ValueError)
    assert err.field == f"mechanisms[1] (id 'W2').{field}"
    first_line = str(err).splitlines()[0]
    assert first_line.startswith(f"mechanisms[1] (id 'W2').{field}: ")
    assert message in first_line


def test_nan_literal_in_json_is_rejected():
    text = json.dumps(with_bad(p_eq=float("nan")))
    assert "NaN" in text
    err = parse_error(text)
    assert str(err) == "mechanisms[1] (id 'W2').positive.p_eq: Input should be a finite number"


def test_infinity_literal_in_json_is_rejected():
    err = parse_error(json.dumps(with_bad(eta=float("inf"))))
    assert err.field == "mechanisms[1] (id 'W2').eta"


def test_nan_in_free_form_geometry_is_rejected():
    err = parse_error(json.dumps(with_bad(geometry={"widths": [0.5, float("nan")]})))
    assert err.field == "mechanisms[1] (id 'W2').geometry.widths[1]"


def test_each_error_gets_its_own_line_and_the_first_is_the_field():
    err = parse_error(one_file(dict(W1, p_eq=-1.0), dict(W1, id="W2", eta=2.0)))
    lines = str(err).splitlines()
    assert lines == [
        "mechanisms[0] (id 'W1').positive.p_eq: Input should be greater than 0",
        "mechanisms[1] (id 'W2').eta: Input should be less than or equal to 1",
    ]
    assert err.field == "mechanisms[0] (id 'W1').positive.p_eq"


def test_duplicate_ids_are_rejected_naming_the_id():
    err = parse_error(one_file(W1, dict(W1, name="copy"), dict(W1, id="W3")))
    assert "duplicate mechanism id 'W1'" in str(err)
    assert err.field == "mechanisms[1] (id 'W1')"


def test_empty_mechanism_list_is_rejected():
    err = parse_error({"mechanisms": []})
    assert err.field == "mechanisms"
    assert "at least 1" in str(err)
    assert "at least 1" in str(parse_error([]))


def test_missing_mechanisms_key_is_rejected():
    assert parse_error({"schema_version": "1.0"}).field == "mechanisms"


def test_empty_id_is_rejected():
    assert parse_error([dict(W1, id="")]).field == "mechanisms[0].id"


def test_unknown_top_level_key_is_rejected():
    err = parse_error(dict(one_file(W1), comment="x"))
    assert err.field == "comment"
    assert "unknown key" in str(err)


def test_other_major_schema_version_is_rejected():
    assert parse_error(dict(one_file(W1), schema_version="2.0")).field == "schema_version"
    assert parse_constants(dict(one_file(W1), schema_version="1.3")).schema_version == "1.3"


def test_non_si_units_are_rejected():
    err = parse_error(dict(one_file(W1), units={"length": "mm"}))
    assert err.field == "units.length"


def test_eta_source_without_eta_is_rejected():
    err = parse_error([dict({k: v for k, v in W1.items() if k != "eta"}, eta_source="user")])
    assert err.field == "mechanisms[0] (id 'W1').eta_source"


def test_malformed_json_names_the_position():
    err = parse_error('{"mechanisms": [')
    assert "invalid JSON" in str(err)
    assert "line 1" in str(err)


def test_non_object_file_is_rejected():
    assert "object" in str(parse_error("3"))


def test_model_itself_is_strict_without_parse_constants():
    with pytest.raises(ValidationError, match="valid number"):
        ConstantsFile.model_validate(one_file(dict(W1, lam=False)))


@pytest.mark.parametrize(
    ("positive", "field", "inputs"),
    [
        (
            {"I0": 1e-300, "K": 1e300, "Q": 1.0, "phi_cr": 0.2},
            "positive.p_eq",
            "K = 1e+300, I0 = 1e-300",
        ),
        (
            {"I0": 1.0, "K": 1e300, "Q": 1e-300, "phi_cr": 0.2},
            "positive.lam",
            "K = 1e+300, phi_cr = 0.2, M_F = 0, Q = 1e-300",
        ),
        (
            {"I0": 1.0, "K": 1e-300, "Q": 1.0, "phi_cr": 0.2, "M_F": 1e300},
            "positive.phi_ov",
            "phi_cr = 0.2, M_F = 1e+300, K = 1e-300",
        ),
    ],
)
def test_a_non_finite_derived_constant_is_refused_naming_its_inputs(
    positive: dict[str, float], field: str, inputs: str
) -> None:
    with pytest.raises(InputError, match="is not finite") as err:
        parse_constants([{"id": "a", "positive": positive, "eta": 0.9}])
    assert err.value.field == f"mechanisms[0] (id 'a').{field}"
    assert f"the inputs {inputs} are out of any physical range" in str(err.value)
