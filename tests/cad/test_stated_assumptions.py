"""What the CAD path assumes is said in the output, and what it would ignore is refused.

#14: ``axis_negative`` on a two-block wall was accepted and ignored; ``hinges_negative`` was
documented as required but derived without a word; N defaulted to half the slab's weight
(``tributary`` 0.5) without saying so.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Callable

import pytest
from cad_scenes import BUILD

from cad_maths.mechanisms.build import constants_from_spec
from cad_maths.scene_3dm import Scene
from shared_schema.errors import InputError
from shared_schema.spec import parse_spec

G = 9.80665


def scene_of(tmp_path: Path, fill: Callable[[Any], None]) -> Scene:
    b = BUILD.Builder("test")
    fill(b)
    return Scene.from_3dm(b.write(tmp_path / "scene.3dm"))


def run(scene: Scene, mech: dict[str, Any]) -> dict[str, Any]:
    parsed = parse_spec(json.dumps({"mechanisms": [mech]}), "spec.json")
    cf = constants_from_spec(parsed, scene, scene_name="scene.3dm", spec_name="spec.json")
    out: dict[str, Any] = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"][0]
    return out


def wall(b: Any) -> None:
    b.box("wall", "Walls", (0, 0, 0), (0.3, 2.0, 4.0), "brick")
    b.box("slab", "Floors", (0.0, 0, 4.0), (4.0, 2.0, 4.2), "concrete")
    b.line("axis", "Axes", (0.3, 0, 0), (0.3, 2.0, 0))
    b.line("inner", "Axes", (0.0, 0, 0), (0.0, 2.0, 0))


def two_block(**extra: Any) -> dict[str, Any]:
    mech: dict[str, Any] = {
        "id": "T",
        "typology": "two_block",
        "groups": [{"objects": ["wall"], "density": 1800}],
        "axis": {"object": "axis"},
        "f_mt": 1.0e5,
        "overburden": {"objects": ["slab"], "density": 2400},
    }
    mech.update(extra)
    return mech


def test_axis_negative_on_a_two_block_wall_is_refused_not_ignored() -> None:
    text = json.dumps({"mechanisms": [two_block(axis_negative={"object": "inner"})]})
    with pytest.raises(InputError, match="axis_negative does not apply to a two_block wall"):
        parse_spec(text, "spec.json")


def test_default_tributary_share_of_the_overburden_is_stated(tmp_path: Path) -> None:
    scene = scene_of(tmp_path, wall)
    t = run(scene, two_block())
    n = 0.5 * 2400 * 4.0 * 2.0 * 0.2 * G  # half the slab's weight, by hand
    notes = [w for w in t["provenance"]["warnings"] if "tributary not given" in w]
    assert len(notes) == 1 and "default 0.5" in notes[0] and f"{n:.6g} N" in notes[0]
    assert t["geometry"]["two_block"]["overburden_tributary"] == 0.5
    given = two_block(overburden={"objects": ["slab"], "density": 2400, "tributary": 0.5})
    t = run(scene, given)
    assert not [w for w in t["provenance"]["warnings"] if "tributary" in w]
    assert t["geometry"]["two_block"]["overburden_N"] == pytest.approx(n, rel=1e-12)


def frame(b: Any) -> None:
    b.box("col_left", "Frame", (0, 0, 0), (0.5, 1, 4), "stone")
    b.box("col_right", "Frame", (3.5, 0, 0), (4.0, 1, 4), "stone")
    b.box("beam", "Frame", (0, 0, 4), (4.0, 1, 4.5), "stone")


def test_derived_negative_hinges_are_stated_with_their_points(tmp_path: Path) -> None:
    mech = {
        "id": "P",
        "typology": "multi_block",
        "blocks": [
            [{"objects": ["col_left"], "density": 2000}],
            [{"objects": ["beam"], "density": 2000}],
            [{"objects": ["col_right"], "density": 2000}],
        ],
        "hinges": {"A": [0.5, 0.5, 0], "B": [0, 0.5, 4], "C": [3.5, 0.5, 4], "D": [4, 0.5, 0]},
    }
    p = run(scene_of(tmp_path, frame), mech)
    notes = [w for w in p["provenance"]["warnings"] if "hinges_negative not given" in w]
    assert len(notes) == 1
    # Each column's other base and top corners, by hand.
    for text in (
        "A' = [0.0, 0.5, 0.0]",
        "B' = [0.5, 0.5, 4.0]",
        "C' = [4.0, 0.5, 4.0]",
        "D' = [3.5, 0.5, 0.0]",
    ):
        assert text in notes[0], notes[0]


def loaded_wall(b: Any) -> None:
    b.box("wall", "Walls", (0, 0, 0), (0.3, 2.0, 4.0), "brick")
    # a slab abutting the wall's inner face, and a roof block on the wall's top
    b.box("slab", "Floors", (0.3, 0, 2.0), (4.0, 2.0, 2.2), "concrete")
    b.box("roof", "Roof", (0.0, 0, 4.0), (4.0, 2.0, 4.4), "brick")
    b.line("axis", "Axes", (0.3, 0, 0), (0.3, 2.0, 0))


def loaded(**extra: Any) -> dict[str, Any]:
    mech: dict[str, Any] = {
        "id": "L",
        "typology": "single_block_loaded",
        "rocking": "one_sided",
        "groups": [{"objects": ["wall"], "density": 1800}],
        "axis": {"object": "axis"},
        "floors": [{"objects": ["slab"], "density": 2400}],
        "roof": {"objects": ["roof"], "density": 500, "tied": True},
    }
    mech.update(extra)
    return mech


def test_default_tributary_share_of_floors_and_roof_is_stated(tmp_path: Path) -> None:
    scene = scene_of(tmp_path, loaded_wall)
    out = run(scene, loaded())
    notes = [w for w in out["provenance"]["warnings"] if "tributary not given" in w]
    slab = 0.5 * 2400 * 3.7 * 2.0 * 0.2  # half the slab's mass [kg], by hand
    roof = 0.5 * 500 * 4.0 * 2.0 * 0.4
    assert len(notes) == 2, notes
    assert notes[0].startswith("L.floors[0]:") and f"({slab:.6g} kg" in notes[0]
    assert notes[1].startswith("L.roof:") and f"({roof:.6g} kg" in notes[1]
    floor = next(e for e in out["geometry"]["loaded"]["elements"] if e["kind"] == "floor")
    assert floor["mass_kg"] == pytest.approx(slab, rel=1e-12)
    given = loaded(
        floors=[{"objects": ["slab"], "density": 2400, "tributary": 0.5}],
        roof={"objects": ["roof"], "density": 500, "tied": True, "tributary": 0.5},
    )
    again = run(scene, given)
    assert not [w for w in again["provenance"]["warnings"] if "tributary" in w]
    assert again["positive"] == out["positive"]  # the same numbers, now said
