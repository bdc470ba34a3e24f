"""Floor contact uses the file's absolute tolerance, and a floor touching no wall says how far.

#14: the contact tolerance was a fixed 1 µm, and "touches no wall" gave no distance. The
example scenes are written with an absolute tolerance of 0.1 mm.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from cad_scenes import BUILD

from cad_maths.mechanisms.build import constants_from_spec
from cad_maths.scene_3dm import Scene
from shared_schema.errors import GeometryError
from shared_schema.spec import parse_spec

G = 9.80665


def scene_with_floor(tmp_path: Path, dz: float) -> Scene:
    """A 0.5 x 1 x 3 m wall and a 0.2 m slab whose underside is ``dz`` above the wall top."""
    b = BUILD.Builder("test")
    assert abs(b.model.Settings.ModelAbsoluteTolerance - 1e-4) < 1e-12
    b.box("wall", "Walls", (0, 0, 0), (0.5, 1.0, 3.0), "brick")
    b.box("slab", "Floors", (-3.0, 0, 3.0 + dz), (0.5, 1.0, 3.2 + dz), "concrete")
    b.line("axis", "Axes", (0.5, 0, 0), (0.5, 1.0, 0))
    return Scene.from_3dm(b.write(tmp_path / "floor.3dm"))


def run(scene: Scene) -> dict[str, Any]:
    mech = {
        "id": "F",
        "typology": "single_block_loaded",
        "rocking": "one_sided",
        "groups": [{"objects": ["wall"], "density": 1800}],
        "axis": {"object": "axis"},
        "floors": [{"objects": ["slab"], "density": 2400, "tributary": 0.5}],
    }
    parsed = parse_spec(json.dumps({"mechanisms": [mech]}), "spec.json")
    cf = constants_from_spec(parsed, scene, scene_name="floor.3dm", spec_name="spec.json")
    out: dict[str, Any] = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"][0]
    return out


def test_a_gap_within_the_file_tolerance_is_a_bearing_contact(tmp_path: Path) -> None:
    f = run(scene_with_floor(tmp_path, 5e-5))  # 0.05 mm gap, tolerance 0.1 mm
    floor = f["geometry"]["loaded"]["elements"][0]
    assert floor["load_bearing"] is True
    # Half the 3.5 x 1 x 0.2 m slab bears on the wall (by hand).
    assert floor["mass_kg"] == pytest.approx(0.5 * 2400 * 3.5 * 1.0 * 0.2, rel=1e-12)
    assert floor["contact_area_m2"] == pytest.approx(0.5 * 1.0, rel=1e-9)


@pytest.mark.parametrize(("dz", "words"), [(1e-3, "a gap of 1 mm"), (-2e-3, "an overlap of 2 mm")])
def test_a_floor_touching_no_wall_says_how_far(tmp_path: Path, dz: float, words: str) -> None:
    with pytest.raises(GeometryError) as err:
        run(scene_with_floor(tmp_path, dz))
    text = str(err.value)
    assert "F.floors[0]: touches no wall" in text
    assert "within the tolerance 0.1 mm" in text
    assert words in text


@pytest.mark.parametrize("angle", [0.0, 37.0, -123.4])
def test_the_gap_is_measured_across_the_faces_in_a_turned_scene(
    tmp_path: Path, angle: float
) -> None:
    """A slab drawn 30 mm short of the wall's inner face, the scene turned about the
    vertical: the message gives the 30 mm gap at every angle (the bounding boxes of the
    turned solids overlap, and an axis-aligned reading called it an overlap)."""
    import math

    import numpy as np

    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))

    def turned(v: Any) -> Any:
        return np.column_stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1], v[:, 2]])

    b = BUILD.Builder(f"turned{int(angle)}")
    for name, layer, ring, z0, z1 in (
        ("wall", "Walls", [(0.0, 0.0), (0.5, 0.0), (0.5, 1.0), (0.0, 1.0)], 0.0, 3.0),
        ("slab", "Floors", [(0.53, 0.0), (3.5, 0.0), (3.5, 1.0), (0.53, 1.0)], 2.8, 3.0),
    ):
        v, f = BUILD.plan_prism(ring, [], z0, z1)
        b.mesh(name, layer, np.ascontiguousarray(turned(v)), np.ascontiguousarray(f), "brick")
    end = turned(np.array([[0.5, 0.0, 0.0], [0.5, 1.0, 0.0]]))
    b.line("axis", "Axes", tuple(end[0]), tuple(end[1]))
    with pytest.raises(GeometryError) as err:
        run(Scene.from_3dm(b.write(tmp_path / "turned.3dm")))
    assert "touches no wall" in str(err.value)
    assert "a gap of 30 mm" in str(err.value)
