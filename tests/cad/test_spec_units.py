"""Points written in a spec can be in the file's units (or an explicit unit), not only metres.

#14: axis and crack points were always metres, even in a millimetre file, and an axis far
from the body said nothing about units. Reference: Housner's block (theory §2.1), lam =
alpha = atan(b/h) and p_eq = sqrt(3 g / (4 R)) for a 0.5 m x 3 m wall.
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
from shared_schema.errors import GeometryError
from shared_schema.spec import parse_spec

G = 9.80665


def mm_wall(tmp_path: Path) -> Scene:
    b = BUILD.Builder("test")
    b.model.Settings.ModelUnitSystem = b.r3.UnitSystem.Millimeters
    b.box("wall", "Walls", (0, 0, 0), (500, 1000, 3000), "brick")
    return Scene.from_3dm(b.write(tmp_path / "wall_mm.3dm"))


def run(scene: Scene, spec: dict[str, Any]) -> dict[str, Any]:
    parsed = parse_spec(json.dumps(spec), "spec.json")
    cf = constants_from_spec(parsed, scene, scene_name="wall_mm.3dm", spec_name="spec.json")
    out: dict[str, Any] = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"][0]
    return out


def wall_spec(start: list[float], end: list[float], **top: Any) -> dict[str, Any]:
    mech = {
        "id": "W",
        "groups": [{"objects": ["wall"], "density": 1800}],
        "axis": {"start": start, "end": end},
        "rocking": "one_sided",
    }
    return {"mechanisms": [mech], **top}


@pytest.mark.parametrize(
    ("units", "start", "end"),
    [
        ("file", [500, 0, 0], [500, 1000, 0]),
        ("mm", [500, 0, 0], [500, 1000, 0]),
        ("cm", [50, 0, 0], [50, 100, 0]),
        ("m", [0.5, 0, 0], [0.5, 1.0, 0]),
        (None, [0.5, 0, 0], [0.5, 1.0, 0]),
    ],
)
def test_axis_points_in_the_declared_unit_give_housners_block(
    tmp_path: Path, units: str | None, start: list[float], end: list[float]
) -> None:
    top = {} if units is None else {"units": units}
    w = run(mm_wall(tmp_path), wall_spec(start, end, **top))
    r = 0.5 * math.hypot(0.5, 3.0)
    assert w["positive"]["lam"] == pytest.approx(math.atan(0.5 / 3.0), rel=1e-12)
    assert w["positive"]["p_eq"] == pytest.approx(math.sqrt(3 * G / (4 * r)), rel=1e-12)
    if units is not None:
        assert w["provenance"]["spec_point_units"] == units


def test_an_axis_far_from_the_body_suggests_the_units(tmp_path: Path) -> None:
    # Millimetre coordinates read as metres: the axis is 500 m from the wall.
    with pytest.raises(GeometryError) as err:
        run(mm_wall(tmp_path), wall_spec([500, 0, 0], [500, 1000, 0]))
    text = str(err.value)
    assert "does not touch the body" in text
    assert "read in m [the default] and the scene is in millimeters" in text
    assert '"units" to "file"' in text


def test_crack_and_hinge_points_follow_the_declared_unit(tmp_path: Path) -> None:
    scene = mm_wall(tmp_path)
    crack_m = [[0, 0, 2.0], [0, 1.0, 2.0], [0.5, 0, 2.5]]
    in_m = wall_spec([0.5, 0, 0], [0.5, 1.0, 0])
    in_m["mechanisms"][0]["cracks"] = [{"points": crack_m}]
    in_mm = wall_spec([500, 0, 0], [500, 1000, 0], units="file")
    in_mm["mechanisms"][0]["cracks"] = [{"points": [[1000 * v for v in p] for p in crack_m]}]
    a, b = run(scene, in_m), run(scene, in_mm)
    assert a["geometry"]["mass_kg"] < 1800 * 0.5 * 1.0 * 3.0  # the crack cut the top off
    for key in ("I0", "K", "Q", "phi_cr"):
        assert b["positive"][key] == pytest.approx(a["positive"][key], rel=1e-12), key

    def frame(bld: Any) -> None:
        bld.box("col_left", "Frame", (0, 0, 0), (0.5, 1, 4), "stone")
        bld.box("col_right", "Frame", (3.5, 0, 0), (4.0, 1, 4), "stone")
        bld.box("beam", "Frame", (0, 0, 4), (4.0, 1, 4.5), "stone")

    builder = BUILD.Builder("test")
    frame(builder)
    frame_scene = Scene.from_3dm(builder.write(tmp_path / "frame.3dm"))
    hinges = {"A": [0.5, 0.5, 0], "B": [0, 0.5, 4], "C": [3.5, 0.5, 4], "D": [4, 0.5, 0]}
    mech = {
        "id": "P",
        "typology": "multi_block",
        "rocking": "one_sided",
        "blocks": [[{"objects": [n], "density": 2000}] for n in ("col_left", "beam", "col_right")],
        "hinges": {k: [1000 * v for v in p] for k, p in hinges.items()},
    }
    p = run(frame_scene, {"mechanisms": [mech], "units": "mm"})
    # Makris & Vassiliou (2013): theta_cr = alpha for the symmetric frame.
    assert p["positive"]["phi_cr"] == pytest.approx(math.atan(0.5 / 4.0), rel=1e-10)
