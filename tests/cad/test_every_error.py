"""One bad mechanism no longer blocks the others: every error at once, and ``--keep-going``.

#14 ("CAD forgiveness"): the first failing mechanism used to stop the run, hiding every other
error; now every mechanism's error is reported at once, and ``rockmech constants
--keep-going`` writes the valid ones and lists the failed ones.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from cad_scenes import BUILD
from typer.testing import CliRunner

from cad_maths.mechanisms.build import constants_from_spec
from cad_maths.scene_3dm import Scene
from shared_schema.errors import GeometryError, InputError
from shared_schema.spec import parse_spec
from solver_service.cli import app


def write_scene(path: Path) -> Path:
    b = BUILD.Builder("test")
    b.box("wall", "Walls", (0, 0, 0), (0.5, 1.0, 3.0), "brick")
    b.line("axis", "Axes", (0.5, 0, 0), (0.5, 1.0, 0))
    b.line("far_axis", "Axes", (2.5, 0, 0), (2.5, 1.0, 0))  # 2 m from the wall
    return b.write(path / "scene.3dm")


GOOD = {"id": "OK", "groups": [{"objects": ["wall"], "density": 1800}], "axis": {"object": "axis"}}
FAR = {
    "id": "FAR",
    "groups": [{"objects": ["wall"], "density": 1800}],
    "axis": {"object": "far_axis"},
}
MISSING = {
    "id": "GONE",
    "groups": [{"objects": ["nothing"], "density": 1800}],
    "axis": {"object": "axis"},
}


def spec_text(*mechs: dict[str, Any]) -> str:
    return json.dumps({"mechanisms": list(mechs)})


def test_every_failing_mechanism_is_reported_at_once(tmp_path: Path) -> None:
    scene = Scene.from_3dm(write_scene(tmp_path))
    spec = parse_spec(spec_text(FAR, GOOD, MISSING), "spec.json")
    with pytest.raises(GeometryError) as err:
        constants_from_spec(spec, scene, scene_name="scene.3dm", spec_name="spec.json")
    text = str(err.value)
    assert text.startswith("2 of 3 mechanisms failed:")
    assert "FAR.axis: the axis does not touch the body" in text
    assert "GONE: selector: no object with name 'nothing'" in text
    assert "OK" not in text.replace("GONE", "")


def test_a_spec_of_one_mechanism_keeps_its_own_error(tmp_path: Path) -> None:
    scene = Scene.from_3dm(write_scene(tmp_path))
    spec = parse_spec(spec_text(FAR), "spec.json")
    with pytest.raises(GeometryError) as err:
        constants_from_spec(spec, scene, scene_name="scene.3dm", spec_name="spec.json")
    # issue #36: the message says where the body's base is (the 0.5 x 1 m wall stands on z = 0)
    assert str(err.value) == (
        "FAR.axis: the axis does not touch the body (closest vertex 2.0000 m away); a rocking "
        "axis is an edge of the body's base, where it rests on its support: the base is at "
        "z = 0 m, over x 0 to 0.5 m, y 0 to 1 m"
    )


def test_keep_going_writes_the_valid_mechanisms_and_lists_the_failed_ones(tmp_path: Path) -> None:
    scene = write_scene(tmp_path)
    spec = tmp_path / "spec.json"
    spec.write_text(spec_text(FAR, GOOD, MISSING))
    out = tmp_path / "constants.json"
    runner = CliRunner()
    res = runner.invoke(app, ["constants", str(scene), str(spec), "-o", str(out)])
    assert res.exit_code == 2 and not out.exists()
    assert "FAR.axis" in res.output and "GONE: selector" in res.output
    res = runner.invoke(app, ["constants", str(scene), str(spec), "-o", str(out), "--keep-going"])
    assert res.exit_code == 1, res.output
    doc = json.loads(out.read_text())
    assert [m["id"] for m in doc["mechanisms"]] == ["OK"]
    # The written mechanism is Housner's 0.5 x 3 m block: lam = alpha = atan(b/h).
    assert doc["mechanisms"][0]["positive"]["lam"] == pytest.approx(math.atan(0.5 / 3.0), rel=1e-12)
    assert "2 of 3 mechanisms failed and are not in" in res.output
    assert "FAR.axis: the axis does not touch the body" in res.output
    assert "GONE: selector: no object with name 'nothing'" in res.output
    everything_bad = tmp_path / "bad.json"
    everything_bad.write_text(spec_text(FAR, MISSING))
    res = runner.invoke(
        app,
        [
            "constants",
            str(scene),
            str(everything_bad),
            "-o",
            str(tmp_path / "x.json"),
            "--keep-going",
        ],
    )
    assert res.exit_code == 2 and not (tmp_path / "x.json").exists()
    assert "2 of 2 mechanisms failed" in res.output


def test_spec_errors_of_several_mechanisms_are_listed_together() -> None:
    bad_density = dict(GOOD, id="A", groups=[{"objects": ["wall"], "density": -1}])
    bad_eta = dict(GOOD, id="B", eta=2.0)
    with pytest.raises(InputError) as err:
        parse_spec(spec_text(bad_density, bad_eta), "spec.json")
    text = str(err.value)
    assert "mechanisms[0] (id 'A').groups[0].density" in text
    assert "mechanisms[1] (id 'B').eta" in text
    assert len(text.splitlines()) == 2
