"""The retrofit spec's JSON Schema: exported in step with the models, and agreeing with them.

An editor or another program validates a retrofit spec with
``shared_schema/jsonschema/retrofit.schema.json``; what the schema refuses the reader refuses
too (naming the field), and the bundled spec passes both.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from shared_schema.errors import InputError
from shared_schema.export import RETROFIT_SCHEMA_PATH, main, render_retrofit_schema
from shared_schema.retrofit import parse_retrofit_spec

ROOT = Path(__file__).resolve().parents[2]
SPECS = sorted((ROOT / "examples" / "specs").glob("*.retrofit.json"))
GOOD: dict[str, Any] = {
    "steel": {"grade": "S275", "diameters_mm": [16, 20]},
    "anchorage": {"capacity_N": 60000.0, "source": "plate punching, calc. 12"},
    "mechanisms": {"F1": {"heights_m": [7.2], "bars": 2, "length_m": 6.2}},
}


def test_exported_retrofit_schema_matches_the_models() -> None:
    assert RETROFIT_SCHEMA_PATH == ROOT / "shared_schema" / "jsonschema" / "retrofit.schema.json"
    assert RETROFIT_SCHEMA_PATH.read_text(encoding="utf-8") == render_retrofit_schema(), (
        "shared_schema/jsonschema/retrofit.schema.json is out of date; "
        "run `python -m shared_schema.export`"
    )


def test_the_check_mode_sees_a_stale_retrofit_schema(tmp_path: Path) -> None:
    out = tmp_path / "retrofit.schema.json"
    assert main(["--check", "--retrofit-output", str(out)]) == 1  # missing
    out.write_text(render_retrofit_schema().replace("S355", "S460"), encoding="utf-8")
    assert main(["--check", "--retrofit-output", str(out)]) == 1  # different
    assert main(["--retrofit-output", str(out)]) == 0
    assert main(["--check", "--retrofit-output", str(out)]) == 0


def test_the_schema_states_the_grades_units_and_required_source() -> None:
    schema = json.loads(render_retrofit_schema())
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert schema["title"] == "rockmech retrofit spec"
    assert set(schema["required"]) == {"steel", "anchorage"}
    defs = schema["$defs"]
    assert defs["Steel"]["properties"]["grade"]["enum"] == ["S235", "S275", "S355"]
    assert set(defs["Anchorage"]["required"]) == {"capacity_N", "source"}
    capacity = defs["Anchorage"]["properties"]["capacity_N"]
    assert capacity["exclusiveMinimum"] == 0 and capacity["maximum"] == 5.0e6
    assert "[N]" in capacity["description"]
    assert all(d["additionalProperties"] is False for d in defs.values())


@pytest.fixture(scope="module")
def validator() -> Any:
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(RETROFIT_SCHEMA_PATH.read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def test_the_bundled_specs_are_valid(validator: Any) -> None:
    assert [p.name for p in SPECS] == ["church.retrofit.json"]
    for path in SPECS:
        validator.validate(json.loads(path.read_text(encoding="utf-8")))
        parse_retrofit_spec(path.read_bytes())
    validator.validate(GOOD)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda s: s["steel"].update(grade="S460"), "steel.grade"),
        (lambda s: s["steel"].update(diameters_mm=[]), "steel.diameters_mm"),
        (lambda s: s["anchorage"].update(capacity_N=-1.0), "anchorage.capacity_N"),
        (lambda s: s["anchorage"].update(capacity_N=1e9), "anchorage.capacity_N"),
        (lambda s: s["anchorage"].pop("source"), "anchorage.source"),
        (lambda s: s["mechanisms"]["F1"].update(bars=0), "mechanisms.F1.bars"),
        (lambda s: s["mechanisms"]["F1"].update(length_m=0.0), "mechanisms.F1.length_m"),
        (lambda s: s.update(colour="red"), "colour"),
    ],
    ids=[
        "grade",
        "no_sizes",
        "negative",
        "absurd",
        "no_source",
        "no_bars",
        "zero_length",
        "unknown_field",
    ],
)
def test_what_the_schema_refuses_the_reader_refuses_naming_the_field(
    validator: Any, change: Any, field: str
) -> None:
    spec = json.loads(json.dumps(GOOD))
    change(spec)
    assert list(validator.iter_errors(spec)), spec
    with pytest.raises(InputError) as info:
        parse_retrofit_spec(spec)
    assert info.value.field == field or str(info.value).startswith(field), str(info.value)
