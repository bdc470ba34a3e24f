"""The exported JSON Schema matches the models, and validates the example files."""

import json
from pathlib import Path

import pytest

from shared_schema.constants import parse_constants
from shared_schema.export import SCHEMA_PATH, build_schema, main, render_schema

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples" / "constants"


def test_schema_file_matches_the_models():
    assert SCHEMA_PATH == ROOT / "shared_schema" / "jsonschema" / "kinematic_constants.schema.json"
    on_disk = SCHEMA_PATH.read_bytes().decode("utf-8")
    assert on_disk == render_schema(), (
        "shared_schema/jsonschema/kinematic_constants.schema.json is out of date; "
        "run `python -m shared_schema.export`"
    )


def test_rendered_schema_is_sorted_indented_and_newline_terminated():
    text = render_schema()
    assert text.endswith("}\n") and not text.endswith("\n\n")
    assert text == json.dumps(json.loads(text), sort_keys=True, indent=2, ensure_ascii=False) + "\n"
    schema = json.loads(text)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert schema["required"] == ["mechanisms"]


def test_check_mode_reports_drift_and_writing_fixes_it(tmp_path, capsys):
    out = tmp_path / "schema.json"
    assert main(["--check", "--output", str(out)]) == 1  # missing
    out.write_text(render_schema().replace("rad/s", "deg/s"), encoding="utf-8")
    assert main(["--check", "--output", str(out)]) == 1  # different
    assert "out of date" in capsys.readouterr().err
    assert main(["--output", str(out)]) == 0
    assert main(["--check", "--output", str(out)]) == 0
    assert out.read_text(encoding="utf-8") == render_schema()


def test_schema_documents_units_and_ranges():
    defs = build_schema()["$defs"]
    side = defs["SideConstants"]["properties"]
    assert "[kg m^2]" in side["I0"]["description"]
    assert "[rad/s]" in side["p_eq"]["description"]
    p_eq = next(a for a in side["p_eq"]["anyOf"] if a.get("type") == "number")
    assert p_eq["exclusiveMinimum"] == 0
    eta = next(a for a in defs["Mechanism"]["properties"]["eta"]["anyOf"] if "type" in a)
    assert (eta["minimum"], eta["maximum"]) == (-1, 1)
    assert defs["Mechanism"]["additionalProperties"] is False


# --- validation with the jsonschema package (skipped when it is not installed) ------------


def example_files():
    return sorted(EXAMPLES.glob("*.json")) if EXAMPLES.is_dir() else []


@pytest.fixture(scope="module")
def validator():
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


@pytest.mark.parametrize("path", example_files(), ids=lambda p: p.name)
def test_example_files_are_valid_against_schema_and_models(path, validator):
    data = json.loads(path.read_text(encoding="utf-8"))
    validator.validate(data)
    parse_constants(data)


def test_saved_canonical_form_is_valid_against_schema(validator):
    cf = parse_constants(
        [
            {"id": "W1", "p_eq": 2.15, "lam": 0.25, "eta": 0.9},
            {"id": "L1", "positive": {"I0": 1e4, "K": 4e4, "Q": 2e3, "phi_cr": 0.1}},
        ]
    )
    validator.validate(json.loads(cf.model_dump_json(exclude_none=True)))


@pytest.mark.parametrize(
    "mechanism",
    [
        {"id": "W1", "p_eq": -2.15, "lam": 0.25},
        {"id": "W1", "p_eq": 2.15},
        {"id": "W1", "p_eq": 2.15, "lam": 0.25, "positive": {"p_eq": 2.15, "lam": 0.25}},
        {"id": "W1", "p_eq": 2.15, "lam": 0.25, "damping": 0.05},
        {"id": "W1", "p_eq": 2.15, "lam": 0.25, "eta": 1.3},
        {"id": "W1", "positive": {"I0": 1.0, "K": 1.0}},
    ],
)
def test_schema_rejects_what_the_models_reject(mechanism, validator):
    import jsonschema

    with pytest.raises(jsonschema.ValidationError):
        validator.validate({"mechanisms": [mechanism]})
