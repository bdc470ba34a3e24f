"""The site file: schema export in step with the models, examples valid, errors by field."""

import json
from pathlib import Path

import pytest

from shared_schema.errors import InputError
from shared_schema.export import SITE_SCHEMA_PATH, render_site_schema
from shared_schema.site import parse_site

ROOT = Path(__file__).resolve().parents[2]
SITES = sorted((ROOT / "examples" / "sites").glob("*.json"))


def test_exported_site_schema_matches_the_models() -> None:
    assert SITE_SCHEMA_PATH == ROOT / "shared_schema" / "jsonschema" / "site.schema.json"
    assert SITE_SCHEMA_PATH.read_text(encoding="utf-8") == render_site_schema(), (
        "shared_schema/jsonschema/site.schema.json is out of date; "
        "run `python -m shared_schema.export`"
    )


@pytest.mark.parametrize("path", SITES, ids=[p.name for p in SITES])
def test_example_sites_are_valid(path: Path) -> None:
    site = parse_site(path.read_bytes())
    assert site.hazard.FC >= 1.0
    jsonschema = pytest.importorskip("jsonschema")
    jsonschema.validate(
        json.loads(path.read_text(encoding="utf-8")), json.loads(render_site_schema())
    )


def test_example_sites_exist() -> None:
    assert {p.name for p in SITES} >= {"ntc_site.json", "ec8_site.json"}


@pytest.mark.parametrize(
    ("hazard", "field"),
    [
        ({"code": "NTC2018", "a_g": 0.2, "F0": 2.4, "Tc_star": 0.3}, "hazard.NTC2018.FC"),
        (
            {"code": "NTC2018", "a_g": 0.2, "F0": 2.4, "Tc_star": 0.3, "FC": 0.9},
            "hazard.NTC2018.FC",
        ),
        (
            {"code": "NTC2018", "a_g": 0.2, "F0": 2.4, "Tc_star": 0.3, "FC": 1, "soil": "F"},
            "hazard.NTC2018.soil",
        ),
        ({"code": "EC8", "a_gR": 0.2, "FC": 1.2, "spectrum_type": 3}, "hazard.EC8.spectrum_type"),
        ({"code": "EC8", "a_gR": 0.2, "FC": 1.2, "ag": 0.1}, "hazard.EC8.ag"),
        ({"code": "IBC"}, "hazard"),
    ],
)
def test_invalid_site_names_the_field(hazard: dict, field: str) -> None:
    with pytest.raises(InputError) as err:
        parse_site(json.dumps({"hazard": hazard}))
    assert err.value.field == field


def test_malformed_json_is_an_input_error() -> None:
    with pytest.raises(InputError, match="invalid JSON"):
        parse_site("{")
    # a nest past Python's recursion limit was a RecursionError traceback (rockmech check)
    with pytest.raises(InputError, match="nested deeper than 1000 levels"):
        parse_site('{"a":' * 5000 + "1" + "}" * 5000)


def test_other_limit_states_and_the_checks_choices_are_read() -> None:
    site = parse_site(
        {
            "hazard": {
                "code": "NTC2018",
                "a_g": 0.26,
                "F0": 2.36,
                "Tc_star": 0.35,
                "FC": 1.35,
                "limit_states": {"SLC": {"a_g": 0.33, "F0": 2.41, "Tc_star": 0.36}},
            },
            "building": {"height": 12.0, "storeys": 4, "xi_percent": 10.0},
            "local_mechanisms": {
                "E": 1.5e9,
                "mechanisms": {"W1": {"free_standing": True, "ties": "verified"}},
            },
        }
    )
    assert site.hazard.limit_states is not None and site.hazard.limit_states["SLC"].a_g == 0.33
    assert site.building is not None and site.building.period_elongation == 1.0
    lm = site.local_mechanisms
    assert (lm.method, lm.xi_SLV_percent, lm.xi_SLC_percent) == ("circ2019", 8.0, 10.0)
    assert lm.mechanisms["W1"].ties == "verified"


@pytest.mark.parametrize(
    ("extra", "field"),
    [
        (
            {
                "hazard": {
                    "code": "EC8",
                    "a_gR": 0.2,
                    "FC": 1.2,
                    "limit_states": {"SLV": {"a_gR": 0.3}},
                }
            },
            "hazard.EC8.limit_states.SLV",
        ),
        (
            {
                "local_mechanisms": {
                    "mechanisms": {"F1": {"ties": "verified", "tie_failure_rotation": 0.01}}
                }
            },
            "local_mechanisms.mechanisms.F1.tie_failure_rotation",
        ),
        ({"local_mechanisms": {"method": "circ2008"}}, "local_mechanisms.method"),
        (
            {"building": {"height": 9.0, "storeys": 3, "period_elongation": 0.5}},
            "building.period_elongation",
        ),
    ],
)
def test_invalid_choices_name_the_field(extra: dict, field: str) -> None:
    data = {"hazard": {"code": "EC8", "a_gR": 0.2, "FC": 1.2}, **extra}
    with pytest.raises(InputError) as err:
        parse_site(json.dumps(data))
    assert err.value.field == field
