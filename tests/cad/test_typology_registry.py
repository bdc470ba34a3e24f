"""A typology is one spec model and one registry line; every list of typologies follows (#29).

The spec models (``shared_schema.spec.TYPOLOGY_SPECS``) are the one list: the spec file's
union, ``TYPOLOGIES``, the constants file's ``typology`` vocabulary, both JSON Schemas, the
builders (``MECHANISMS``) and the Rhino commands (``MECHANISM_COMMANDS``, their scripts and
``rockmech.rhproj``) are checked against it. The recipe of CONTRIBUTING.md ("A mechanism
typology") is then followed for a made-up typology, ``demo_block``: its model and its builder
line are enough for the spec to read it, the schema to list it, the other typologies' errors
to name it and the builder to compute it, with the numbers of the single block it copies.
"""

from __future__ import annotations

import json
import typing
from pathlib import Path
from typing import Any, List, Literal

import pytest
from pydantic import Field

pytest.importorskip("rhino3dm")

from cad_maths.mechanisms import build, single
from cad_maths.scenes import read_scene
from rhino_plugin.flows import mechanisms as flows
from shared_schema import constants, spec
from shared_schema.errors import InputError
from shared_schema.export import SCHEMA_PATH, SPEC_SCHEMA_PATH, build_spec_schema

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def _branch_typologies(schema: dict[str, Any]) -> list[str]:
    """The ``typology`` const of each ``oneOf`` branch of a spec schema's mechanisms."""
    branches = schema["properties"]["mechanisms"]["items"]["oneOf"]
    defs = schema["$defs"]
    return [defs[b["$ref"].split("/")[-1]]["properties"]["typology"]["const"] for b in branches]


def test_every_list_of_typologies_is_the_spec_models() -> None:
    names = tuple(spec.typology_of(m) for m in spec.TYPOLOGY_SPECS)
    assert (
        names
        == spec.TYPOLOGIES
        == ("single_block", "single_block_loaded", "two_block", "multi_block")
    )
    assert typing.get_args(constants.Typology) == (*spec.TYPOLOGIES, "user_defined")
    assert tuple(build.MECHANISMS) == spec.TYPOLOGIES
    assert tuple(e.spec for e in build.MECHANISMS.values()) == spec.TYPOLOGY_SPECS
    assert tuple(c.spec for c in flows.MECHANISM_COMMANDS) == spec.TYPOLOGY_SPECS
    assert tuple(flows.FLOWS) == spec.TYPOLOGIES
    assert [t for t, _ in flows.COMMANDS.values()] == list(spec.TYPOLOGIES)
    # only the default typology may be left out of a mechanism
    assert spec.TYPOLOGY_SPECS[0].model_fields["typology"].default == spec.DEFAULT_TYPOLOGY
    assert all(m.model_fields["typology"].is_required() for m in spec.TYPOLOGY_SPECS[1:])


def test_the_schemas_on_disk_list_the_typologies() -> None:
    spec_schema = json.loads(SPEC_SCHEMA_PATH.read_text(encoding="utf-8"))
    assert _branch_typologies(spec_schema) == list(spec.TYPOLOGIES)
    constants_schema = json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))
    enum = constants_schema["$defs"]["Mechanism"]["properties"]["typology"]["enum"]
    assert enum == [*spec.TYPOLOGIES, "user_defined"]


def test_every_mechanism_command_has_its_script_and_its_rhproj_line() -> None:
    proj = json.loads((ROOT / "rhino_plugin" / "rockmech.rhproj").read_text(encoding="utf-8"))
    listed = {c["title"]: c["uri"] for c in proj["codes"]}
    for cmd in flows.MECHANISM_COMMANDS:
        assert listed.get(cmd.command) == f"rhino/{cmd.command}.py"
        script = ROOT / "rhino_plugin" / "rhino" / f"{cmd.command}.py"
        assert f'run_mechanism("{cmd.command}")' in script.read_text(encoding="utf-8")
    prefixes = [c.prefix for c in flows.MECHANISM_COMMANDS]
    assert len(set(prefixes)) == len(prefixes)


def test_every_example_spec_is_valid_against_the_exported_schema() -> None:
    jsonschema = pytest.importorskip("jsonschema")
    validator = jsonschema.Draft202012Validator(
        json.loads(SPEC_SCHEMA_PATH.read_text(encoding="utf-8"))
    )
    paths = sorted((EXAMPLES / "specs").glob("*.spec.json"))
    assert len(paths) >= 10
    typologies = set()
    for path in paths:
        doc = json.loads(path.read_text(encoding="utf-8"))
        assert not list(validator.iter_errors(doc)), path.name
        typologies |= {m.typology for m in spec.parse_spec(path.read_text()).mechanisms}
    assert typologies == set(spec.TYPOLOGIES)  # the examples show every typology
    # what the reader refuses, the schema refuses too: a key of another typology
    bad = {
        "mechanisms": [
            {
                "id": "W1",
                "groups": [{"objects": ["w"], "density": 1800}],
                "axis": {"object": "a"},
                "f_mt": 1.0e5,
            }
        ]
    }
    assert list(validator.iter_errors(bad))


class DemoBlockSpec(spec.SingleBlockSpec):
    """The made-up typology of the recipe: a single block under another name."""

    typology: Literal["demo_block"]  # type: ignore[assignment]


def test_a_new_typology_is_its_model_and_one_builder_line(monkeypatch: pytest.MonkeyPatch) -> None:
    models = (*spec.TYPOLOGY_SPECS, DemoBlockSpec)
    monkeypatch.setattr(spec, "TYPOLOGY_SPECS", models)

    class DemoSpecFile(spec.SpecFile):
        mechanisms: List[spec.mechanism_union(models)] = Field(min_length=1)  # type: ignore[valid-type]

    text = (EXAMPLES / "specs" / "rect_wall.spec.json").read_text(encoding="utf-8")
    doc = json.loads(text)
    doc["mechanisms"][0]["typology"] = "demo_block"
    demo = DemoSpecFile.model_validate_json(json.dumps(doc)).mechanisms[0]
    assert isinstance(demo, DemoBlockSpec) and demo.typology == "demo_block"
    # the old typologies still read as before, a missing typology still is single_block
    del doc["mechanisms"][0]["typology"]
    plain = DemoSpecFile.model_validate_json(json.dumps(doc)).mechanisms[0]
    assert type(plain) is spec.SingleBlockSpec

    # the schema lists it
    assert _branch_typologies(build_spec_schema(DemoSpecFile))[-1] == "demo_block"

    # a key of its model given to another typology names it among those that take it
    multi = json.loads((EXAMPLES / "specs" / "portal_frame.spec.json").read_text())
    multi["mechanisms"][0]["axis_negative"] = {"object": "axis"}
    with pytest.raises(
        InputError,
        match=r"'axis_negative' needs typology 'single_block', "
        r"'single_block_loaded' or 'demo_block'",
    ):
        spec.parse_spec(json.dumps(multi), "portal_frame.spec.json")

    # its builder: one line of the registry; the numbers are the single block's
    monkeypatch.setitem(
        build.MECHANISMS,
        "demo_block",
        build.TypologyEntry(DemoBlockSpec, single.build_single_block),
    )
    scene = read_scene(EXAMPLES / "scenes" / "rect_wall.3dm")
    entry = build.mechanism_entry(demo, scene, None)
    reference = build.mechanism_entry(plain, scene, None)
    assert entry["typology"] == "demo_block" and reference["typology"] == "single_block"
    assert entry["positive"] == reference["positive"]
    assert entry["positive"]["I0"] > 0 and entry["eta"] == reference["eta"]
