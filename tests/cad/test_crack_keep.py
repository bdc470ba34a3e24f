"""A crack's kept side can be named by a point on it, and crack errors name crack and keep.

#14: ``keep`` was ``positive``/``negative`` relative to a plane normal the user cannot see.
Reference: Housner's block (theory §2.1), lam = atan(b/h) of the part kept.
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
from shared_schema.errors import GeometryError, InputError
from shared_schema.spec import parse_spec


def wall(tmp_path: Path) -> Scene:
    b = BUILD.Builder("test")
    b.box("wall", "Walls", (0, 0, 0), (0.5, 1.0, 3.0), "brick")
    b.line("axis", "Axes", (0.5, 0, 0), (0.5, 1.0, 0))
    b.line("top_axis", "Axes", (0.5, 0, 2.0), (0.5, 1.0, 2.0))
    return Scene.from_3dm(b.write(tmp_path / "wall.3dm"))


def run(scene: Scene, crack: dict[str, Any], axis: str = "axis") -> dict[str, Any]:
    mech = {
        "id": "W",
        "rocking": "one_sided",
        "groups": [{"objects": ["wall"], "density": 1800}],
        "axis": {"object": axis},
        "cracks": [crack],
    }
    parsed = parse_spec(json.dumps({"mechanisms": [mech]}), "spec.json")
    cf = constants_from_spec(parsed, scene, scene_name="wall.3dm", spec_name="spec.json")
    out: dict[str, Any] = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"][0]
    return out


# A horizontal crack at z = 2 m; its three points give a normal pointing up.
AT_2M = [[0, 0, 2.0], [0.5, 0, 2.0], [0, 1.0, 2.0]]


def test_keep_point_picks_the_side_whatever_the_normal(tmp_path: Path) -> None:
    scene = wall(tmp_path)
    low = run(scene, {"points": AT_2M, "keep_point": [0.25, 0.5, 1.0]})
    assert low["positive"]["lam"] == pytest.approx(math.atan(0.5 / 2.0), rel=1e-12)
    flipped = [AT_2M[0], AT_2M[2], AT_2M[1]]  # the other normal: same kept part
    assert run(scene, {"points": flipped, "keep_point": [0.25, 0.5, 1.0]})["positive"][
        "lam"
    ] == pytest.approx(math.atan(0.5 / 2.0), rel=1e-12)
    high = run(scene, {"points": AT_2M, "keep_point": [0.25, 0.5, 2.5]}, axis="top_axis")
    assert high["positive"]["lam"] == pytest.approx(math.atan(0.5 / 1.0), rel=1e-12)


def test_crack_errors_name_the_crack_and_its_keep(tmp_path: Path) -> None:
    scene = wall(tmp_path)
    above = [[0, 0, 5.0], [0.5, 0, 5.0], [0, 1.0, 5.0]]
    with pytest.raises(GeometryError) as err:
        run(scene, {"points": above, "keep_point": [0.25, 0.5, 1.0]})
    assert "W.cracks[0] (keep_point = [0.25, 0.5, 1.0]): the crack plane misses the body" in str(
        err.value
    )
    with pytest.raises(GeometryError, match=r"W.cracks\[0\] \(keep = 'negative'\)"):
        run(scene, {"points": above, "keep": "negative"})
    with pytest.raises(InputError, match="keep_point lies on the crack plane"):
        run(scene, {"points": AT_2M, "keep_point": [0.1, 0.1, 2.0]})
    with pytest.raises(InputError, match="either 'keep' or 'keep_point'"):
        parse_spec(
            json.dumps(
                {
                    "mechanisms": [
                        {
                            "id": "W",
                            "groups": [{"objects": ["wall"], "density": 1800}],
                            "axis": {"object": "axis"},
                            "cracks": [
                                {"points": AT_2M, "keep": "positive", "keep_point": [0, 0, 1]}
                            ],
                        }
                    ]
                }
            )
        )
