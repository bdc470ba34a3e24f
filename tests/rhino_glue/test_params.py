"""What the Grasshopper components compute (rhino_plugin.flows.params), against the CLI."""

import json
from pathlib import Path
from typing import Any, List, Tuple

import pytest

from rhino_plugin.flows.params import (
    constants_from_prepared,
    parse_constants_text,
    spec_from_parameters,
)
from shared_schema.errors import InputError

from .conftest import SPECS
from .test_prepared import prepared_from


def _records(scene: Any, names: List[str]) -> List[Tuple[str, str, Any]]:
    prepared = prepared_from(scene)
    return [(n, prepared.find(n)[0].kind, prepared.find(n)[0].geometry) for n in names]


def _without_ids(doc: Any) -> Any:
    """The document without object ids (components give their geometry ids of their own)."""
    if isinstance(doc, dict):
        return {k: _without_ids(v) for k, v in doc.items() if k not in ("objects", "object_ids")}
    if isinstance(doc, list):
        return [_without_ids(v) for v in doc]
    return doc


def test_any_spec_over_named_geometry_gives_the_cli_constants(
    scenes: Any, cli_constants: Any
) -> None:
    """facade.spec.json (a loaded wall and a cracked panel) over component geometry."""
    scene = scenes["facade"]
    names = [o.name for o in scene.objects]
    spec_text = (SPECS / "facade.spec.json").read_text()
    # The component passes the document's tolerance, as the .3dm reader does.
    cf = constants_from_prepared(_records(scene, names), spec_text, tolerance=scene.tolerance)
    want = cli_constants("facade")
    for mech in json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"]:
        ref = want[mech["id"]]
        for key in ("positive", "negative", "eta", "eta_source", "geometry"):
            assert _without_ids(mech.get(key)) == _without_ids(ref.get(key)), (mech["id"], key)


def test_build_spec_parameters_give_the_cli_constants(scenes: Any, cli_constants: Any) -> None:
    spec, names = spec_from_parameters("W1", "TwoSided", 1, [1800], True)
    assert names == ["solid_1", "axis"]
    scene = scenes["rect_wall"]
    prepared = prepared_from(scene)
    records = [
        ("solid_1", "brep", prepared.find("wall")[0].geometry),
        ("axis", "line", prepared.find("axis")[0].geometry),
    ]
    cf = constants_from_prepared(records, json.dumps(spec))
    got = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"][0]
    want = cli_constants("rect_wall")["W1"]
    for key in ("positive", "eta", "geometry"):
        assert got[key] == want[key], key


def test_equal_densities_form_one_group_and_cracks_are_named() -> None:
    spec, names = spec_from_parameters("C1", "one_sided", 3, [2600, 8500, 2600], True, 2, -0.2)
    mech = spec["mechanisms"][0]
    assert mech["groups"] == [
        {"objects": ["solid_1", "solid_3"], "density": 2600.0},
        {"objects": ["solid_2"], "density": 8500.0},
    ]
    assert mech["cracks"] == [{"object": "crack_1"}, {"object": "crack_2"}]
    assert (mech["rocking"], mech["eta"]) == ("one_sided", -0.2)
    assert names == ["solid_1", "solid_2", "solid_3", "axis", "crack_1", "crack_2"]


@pytest.mark.parametrize(
    ("args", "field"),
    [
        (("M", "two_sided", 2, [1800, 1800, 1800], True), "densities"),
        (("M", "two_sided", 1, ["heavy"], True), "densities[0]"),
        (("M", "two_sided", 2, [1800, 1e308], True), "densities[1]"),
        (("M", "two_sided", 0, [1800], True), "solids"),
        (("M", "two_sided", 1, [1800], False), "axis"),
        (("M", "sideways", 1, [1800], True), "rocking"),
    ],
)
def test_bad_component_inputs_name_the_input(args: Any, field: str) -> None:
    with pytest.raises(InputError) as info:
        spec_from_parameters(*args)
    assert info.value.field == field


def test_repeated_names_are_refused(scenes: Any) -> None:
    records = _records(scenes["rect_wall"], ["wall", "axis"])
    records[1] = ("wall", *records[1][1:])
    with pytest.raises(InputError, match="repeated"):
        constants_from_prepared(records, (SPECS / "rect_wall.spec.json").read_text())


def test_constants_text_round_trip(tmp_path: Path) -> None:
    text = (Path(__file__).resolve().parents[2] / "examples/constants/rect_walls.json").read_text()
    assert parse_constants_text(text).mechanisms[0].id == json.loads(text)["mechanisms"][0]["id"]
    with pytest.raises(InputError, match="connect a kinematic-constants JSON"):
        parse_constants_text(None)
