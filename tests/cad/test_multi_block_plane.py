"""Three blocks, four hinges (A4): the mechanism's plane is checked against every hinge.

A hinge off the plane, or a hinge line that is not normal to it, used to change the
constants without a word (a hinge 0.3 m off tilted the plane by 4.9 deg). The reference
frame here is the symmetric portal frame of Makris & Vassiliou (2013), whose exact
equivalent block (theta_cr = alpha, p_eq = p sqrt((1 + 2 gamma)/(1 + 3 gamma))) is known.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Callable

import pytest
from cad_scenes import BUILD

from cad_maths.mechanisms.build import constants_from_spec
from cad_maths.scene_3dm import Scene
from shared_schema.errors import InputError
from shared_schema.spec import parse_spec

G = 9.80665


def frame(b: Any) -> None:
    b.box("col_left", "Frame", (0, 0, 0), (0.5, 1, 4), "stone")
    b.box("col_right", "Frame", (3.5, 0, 0), (4.0, 1, 4), "stone")
    b.box("beam", "Frame", (0, 0, 4), (4.0, 1, 4.5), "stone")
    b.line("hA", "Hinges", (0.5, 0, 0), (0.5, 1, 0))
    b.line("hA_skew", "Hinges", (0.45, 0, 0), (0.55, 1, 0))  # 5.7 deg off the normal


def scene_of(tmp_path: Path, fill: Callable[[Any], None]) -> Scene:
    b = BUILD.Builder("test")
    fill(b)
    return Scene.from_3dm(b.write(tmp_path / "scene.3dm"))


def spec(**hinges: Any) -> dict[str, Any]:
    pos: dict[str, Any] = {
        "A": [0.5, 0.5, 0],
        "B": [0, 0.5, 4],
        "C": [3.5, 0.5, 4],
        "D": [4, 0.5, 0],
    }
    pos.update(hinges)
    return {
        "id": "P",
        "typology": "multi_block",
        "blocks": [
            [{"objects": ["col_left"], "density": 2000}],
            [{"objects": ["beam"], "density": 2000}],
            [{"objects": ["col_right"], "density": 2000}],
        ],
        "hinges": pos,
        "hinges_negative": {
            "A": [0, 0.5, 0],
            "B": [0.5, 0.5, 4],
            "C": [4, 0.5, 4],
            "D": [3.5, 0.5, 0],
        },
    }


def run(scene: Scene, mech: dict[str, Any]) -> dict[str, Any]:
    parsed = parse_spec(json.dumps({"mechanisms": [mech]}), "spec.json")
    cf = constants_from_spec(parsed, scene, scene_name="scene.3dm", spec_name="spec.json")
    out: dict[str, Any] = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"][0]
    return out


def makris_vassiliou() -> tuple[float, float]:
    alpha = math.atan(0.5 / 4.0)
    r = 0.5 * math.hypot(0.5, 4.0)
    gamma = (4.0 * 0.5) / (2 * 0.5 * 4.0)
    return alpha, math.sqrt(3 * G / (4 * r)) * math.sqrt((1 + 2 * gamma) / (1 + 3 * gamma))


@pytest.mark.parametrize(("hinge", "point"), [("B", [0, 0.8, 4]), ("A", [0.5, 0.8, 0])])
def test_a_hinge_off_the_plane_is_refused_and_named(
    tmp_path: Path, hinge: str, point: list[float]
) -> None:
    scene = scene_of(tmp_path, frame)
    with pytest.raises(InputError) as err:
        run(scene, spec(**{hinge: point}))
    assert err.value.field == f"P.hinges.{hinge}"
    assert "do not lie in one vertical plane" in str(err.value)
    assert "tolerance" in str(err.value)


def test_hinges_within_the_tolerance_give_the_exact_frame_and_the_offsets_are_reported(
    tmp_path: Path,
) -> None:
    scene = scene_of(tmp_path, frame)
    p = run(scene, spec(B=[0, 0.502, 4]))  # 2 mm off; tolerance 1e-3 x 5.7 m
    alpha, p_eq = makris_vassiliou()
    # Projection onto the fitted plane moves B in the plane by a second-order amount only.
    assert p["positive"]["phi_cr"] == pytest.approx(alpha, rel=1e-6)
    assert p["positive"]["p_eq"] == pytest.approx(p_eq, rel=1e-6)
    plane = p["geometry"]["multi_block"]["plane"]
    offsets = plane["hinge_offsets_m"]
    # Least squares in plan: B's residual is 2 mm less the fitted line's shift and tilt.
    assert 0.001 < abs(offsets["hinges.B"]) < 0.002
    assert abs(offsets["hinges.B"]) == max(abs(v) for v in offsets.values())
    assert plane["tolerance_m"] == pytest.approx(
        max(1e-3 * math.hypot(4.0, 4.0), scene.tolerance), rel=1e-3
    )
    assert "points" in plane["hinge_axes"]


def test_a_hinge_line_not_normal_to_the_plane_is_refused(tmp_path: Path) -> None:
    scene = scene_of(tmp_path, frame)
    with pytest.raises(InputError) as err:
        run(scene, spec(A="hA_skew"))
    assert err.value.field == "P.hinges.A"
    assert "5.711 deg off the normal" in str(err.value)
    p = run(scene, spec(A="hA"))  # a line across the plane: its mid-point is the hinge
    alpha, p_eq = makris_vassiliou()
    assert p["positive"]["phi_cr"] == pytest.approx(alpha, rel=1e-10)
    assert p["positive"]["p_eq"] == pytest.approx(p_eq, rel=1e-10)
    assert "line objects checked normal" in p["geometry"]["multi_block"]["plane"]["hinge_axes"]
