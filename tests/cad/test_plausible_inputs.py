"""Implausible CAD inputs are said or refused, never silently used (issue #14).

An object reached by two selectors is refused (it would be counted twice); a body of
kilometres or millimetres gets a warning naming the unit the file was read in and the one
that fits; densities, forces and strengths outside their plausible band get a warning, and
beyond their admissible range are refused, in the spec itself (``shared_schema.rules``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from cad_scenes import BUILD

from cad_maths.mechanisms.build import constants_from_spec
from cad_maths.scene_3dm import Scene
from shared_schema.errors import InputError
from shared_schema.spec import parse_spec

pytest.importorskip("rhino3dm")

G = 9.80665


def wall_scene(tmp_path: Path, units: str = "Meters", scale: float = 1.0) -> Scene:
    """A 0.5 x 1 x 3 wall (times ``scale`` in the file's numbers) and its base edge."""
    b = BUILD.Builder("plausible")
    b.model.Settings.ModelUnitSystem = getattr(b.r3.UnitSystem, units)
    b.box("wall", "Walls", (0, 0, 0), (0.5 * scale, 1.0 * scale, 3.0 * scale), "stone")
    b.line("axis", "Axes", (0.5 * scale, 0, 0), (0.5 * scale, 1.0 * scale, 0))
    return Scene.from_3dm(b.write(tmp_path / "scene.3dm"))


def mech(**extra: Any) -> dict[str, Any]:
    m: dict[str, Any] = {
        "id": "W",
        "groups": [{"objects": ["wall"], "density": 2000}],
        "axis": {"object": "axis"},
    }
    m.update(extra)
    return m


def run(scene: Scene, m: dict[str, Any]) -> dict[str, Any]:
    parsed = parse_spec(json.dumps({"mechanisms": [m]}), "spec.json")
    cf = constants_from_spec(parsed, scene, scene_name="scene.3dm", spec_name="spec.json")
    out: dict[str, Any] = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"][0]
    return out


def test_an_object_selected_by_name_and_by_id_is_refused(tmp_path: Path) -> None:
    scene = wall_scene(tmp_path)
    wall_id = scene.find("wall")[0].id
    one_group = mech(groups=[{"objects": ["wall", {"id": wall_id}], "density": 2000}])
    with pytest.raises(InputError, match=r"wall .* is selected twice .*counted twice") as err:
        run(scene, one_group)
    assert err.value.field == "W.groups[0]"
    two_groups = mech(
        groups=[
            {"objects": ["wall"], "density": 2000},
            {"objects": [{"layer": "Walls"}], "density": 2000},
        ]
    )
    with pytest.raises(InputError, match=r"selected twice \(W.groups\[0\] and W.groups\[1\]\)"):
        run(scene, two_groups)


def test_a_name_written_in_two_groups_is_refused_in_the_spec() -> None:
    text = json.dumps(
        {
            "mechanisms": [
                mech(
                    groups=[
                        {"objects": ["wall"], "density": 2000},
                        {"objects": ["wall"], "density": 1000},
                    ]
                )
            ]
        }
    )
    with pytest.raises(InputError, match=r"'wall' is listed in two density groups"):
        parse_spec(text, "spec.json")


def _size_notes(out: dict[str, Any]) -> list[str]:
    return [w for w in out["provenance"]["warnings"] if "m across as read in" in w]


def test_a_millimetre_wall_read_in_metres_is_said_and_the_numbers_are_housners(
    tmp_path: Path,
) -> None:
    """The numbers of a 500 x 1000 x 3000 mm wall in a file that says metres: a 3 km wall."""
    big = run(wall_scene(tmp_path, "Meters", 1000.0), mech())
    notes = _size_notes(big)
    diag = 1000.0 * math.sqrt(0.5**2 + 1.0**2 + 3.0**2)
    assert notes == [
        f"W: the body is {diag:.4g} m across as read in meters, but a rocking body is between "
        "0.01 and 200 m: if the file is in mm, set its model units to mm in Rhino"
    ]
    # Housner's block of R = 1000 sqrt(0.25^2 + 1.5^2) m: the answer is right for that wall
    r = 1000.0 * math.hypot(0.25, 1.5)
    assert big["positive"]["p_eq"] == pytest.approx(math.sqrt(3 * G / (4 * r)), rel=1e-9)


def test_the_same_wall_in_millimetres_is_silent(tmp_path: Path) -> None:
    ok = run(wall_scene(tmp_path, "Millimeters", 1000.0), mech())
    assert _size_notes(ok) == []
    r = math.hypot(0.25, 1.5)
    assert ok["positive"]["p_eq"] == pytest.approx(math.sqrt(3 * G / (4 * r)), rel=1e-9)


def test_a_metre_wall_read_in_millimetres_is_said(tmp_path: Path) -> None:
    tiny = run(wall_scene(tmp_path, "Millimeters", 1.0), mech())
    assert _size_notes(tiny)[0].endswith("if the file is in m, set its model units to m in Rhino")


@pytest.mark.parametrize(
    ("extra", "field", "words"),
    [
        ({"groups": [{"objects": ["wall"], "density": 1.8}]}, "W.groups[0].density = 1.8", "t/m^3"),
        (
            {"groups": [{"objects": ["wall"], "density": 17650}]},
            "W.groups[0].density = 17650",
            "unit weight in N/m^3",
        ),
    ],
)
def test_an_implausible_density_is_said_and_used(
    tmp_path: Path, extra: dict[str, Any], field: str, words: str
) -> None:
    out = run(wall_scene(tmp_path), mech(**extra))
    notes = [w for w in out["provenance"]["warnings"] if w.startswith(field)]
    assert len(notes) == 1 and words in notes[0], out["provenance"]["warnings"]
    # a single block's p_eq does not depend on its density
    r = math.hypot(0.25, 1.5)
    assert out["positive"]["p_eq"] == pytest.approx(math.sqrt(3 * G / (4 * r)), rel=1e-9)


def test_a_plausible_density_is_silent(tmp_path: Path) -> None:
    out = run(wall_scene(tmp_path), mech())
    assert out["provenance"]["warnings"] == []


@pytest.mark.parametrize(
    ("point", "words"),
    [([0.0, 2e6, 0.0], "coordinate 2e\\+06 is beyond the largest magnitude accepted, 1e\\+06")],
)
def test_hinge_points_beyond_the_coordinate_limit_are_refused(
    point: list[float], words: str
) -> None:
    m = {
        "id": "P",
        "typology": "multi_block",
        "blocks": [[{"objects": [n], "density": 2000}] for n in ("a", "b", "c")],
        "hinges": {"A": point, "B": [0, 0, 4], "C": [3, 0, 4], "D": [3, 0, 0]},
    }
    with pytest.raises(InputError, match=words) as err:
        parse_spec(json.dumps({"mechanisms": [m]}), "spec.json")
    assert "hinges.A" in str(err.value)
