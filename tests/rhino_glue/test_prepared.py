"""PreparedScene (what the Rhino glue builds from RhinoCommon objects) against Scene.

Reference: the same flows over the headless ``Scene.from_3dm`` and the CLI's constants.
The prepared records are filled from the ``.3dm`` file's own geometry (meshes in model
units, line ends, planes), which is what the Rhino glue extracts from RhinoCommon.
"""

import json
from pathlib import Path
from typing import Any, List

import numpy as np
import pytest

from rhino_plugin.flows.marks import check_marks
from rhino_plugin.flows.mechanisms import run_mechanism_command
from rhino_plugin.flows.prepared import Prepared, PreparedScene
from shared_schema.errors import GeometryError, RockmechError

from .conftest import ScriptedPrompter
from .test_flows import SCRIPTS, _comparable


def prepared_from(scene: Any, scale: float = 1.0) -> PreparedScene:
    """Prepared records of every object of a headless scene, in units of ``scale`` metres."""
    records: List[Any] = []
    for obj in scene.objects:
        fields: dict = {}
        try:
            mesh = scene.mesh(obj, require_closed=False)
            fields.update(vertices=mesh.vertices / scale, faces=mesh.faces)
        except RockmechError:
            pass
        try:
            start, end = scene.line(obj)
            fields["line"] = (tuple(start / scale), tuple(end / scale))
        except RockmechError:
            pass
        try:
            point, normal = scene.plane(obj)
            fields["plane"] = (tuple(point / scale), tuple(normal))
        except RockmechError:
            pass
        records.append((obj.id, obj.name, obj.layer, obj.kind, Prepared(**fields)))
    units = "meters" if scale == 1.0 else "millimeters"
    # As DocScene does in Rhino: the document's absolute tolerance [m] comes along.
    return PreparedScene.from_records(
        records, unit_scale=scale, units=units, tolerance=scene.tolerance
    )


@pytest.mark.parametrize("case", ["facade_loaded", "facade_crack", "statue_column", "side_aisle"])
def test_prepared_scene_gives_the_cli_constants(
    case: str, scenes: Any, cli_constants: Any, tmp_path: Path
) -> None:
    stem, command, ident, script = SCRIPTS[case]
    scene = prepared_from(scenes[stem])
    prompter = ScriptedPrompter(scene, script)
    result = run_mechanism_command(
        command, prompter, scene, str(tmp_path), scene_name=f"{stem}.3dm", mechanism_id=ident
    )
    assert result is not None, prompter.messages
    written = json.loads(Path(result.constants_path).read_text())["mechanisms"][0]
    assert _comparable(written) == _comparable(cli_constants(stem)[ident])


def test_prepared_scene_in_millimetres_gives_the_same_constants(
    scenes: Any, cli_constants: Any, tmp_path: Path
) -> None:
    stem, command, ident, script = SCRIPTS["statue_column"]
    scene = prepared_from(scenes[stem], scale=1e-3)
    prompter = ScriptedPrompter(scene, script)
    result = run_mechanism_command(
        command, prompter, scene, str(tmp_path), scene_name=f"{stem}.3dm", mechanism_id=ident
    )
    assert result is not None, prompter.messages
    want = cli_constants(stem)[ident]
    got = result.constants.mechanisms[0]
    for side in ("positive", "negative"):
        dumped = getattr(got, side).model_dump(exclude_none=True)
        for key, value in want[side].items():
            assert dumped[key] == pytest.approx(value, rel=1e-9, abs=1e-12)
    assert got.eta == pytest.approx(want["eta"], rel=1e-9)


def test_prepared_open_mesh_is_refused_by_name() -> None:
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    f = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3]])  # a tetrahedron without its 4th face
    scene = PreparedScene.from_records(
        [("1f1e", "shard", "Walls", "mesh", Prepared(vertices=v, faces=f))]
    )
    with pytest.raises(GeometryError, match=r"shard \(Walls, 1f1e\).*not a closed solid"):
        scene.mesh(scene.find("shard")[0])


def test_prepared_problem_is_reported_with_the_object() -> None:
    scene = PreparedScene.from_records(
        [("ab12", "dome", "Vaults", "brep", Prepared(problem="Rhino could not mesh the Brep"))]
    )
    obj = scene.find({"layer": "Vaults"})[0]
    with pytest.raises(GeometryError, match=r"dome .*Rhino could not mesh the Brep"):
        scene.mesh(obj)
    with pytest.raises(GeometryError, match=r"dome .*Rhino could not mesh"):
        scene.line(obj)


def test_check_marks_of_the_rect_wall(scenes: Any, tmp_path: Path) -> None:
    stem, command, ident, script = SCRIPTS["rect_wall"]
    scene = scenes[stem]
    result = run_mechanism_command(
        command, ScriptedPrompter(scene, script), scene, str(tmp_path),
        scene_name="rect_wall.3dm", mechanism_id=ident,
    )  # fmt: skip
    assert result is not None
    marks = {m.label: m.points for m in result.marks}
    assert marks["W1 axis"] == ((0.5, 0.0, 0.0), (0.5, 1.0, 0.0))
    assert marks["W1 G"][0] == pytest.approx((0.25, 0.5, 1.5), abs=1e-12)
    # the other side turns about the opposite base edge, derived from the footprint
    assert np.allclose(marks["W1 axis (negative)"], [(0, 0, 0), (0, 1, 0)], rtol=0, atol=1e-12)
    assert set(marks) == {"W1 axis", "W1 axis (negative)", "W1 G"}


def test_check_marks_of_the_statue_and_the_side_aisle(scenes: Any, tmp_path: Path) -> None:
    out: dict = {}
    for case in ("statue_column", "side_aisle", "two_block_wall"):
        stem, command, ident, script = SCRIPTS[case]
        scene = scenes[stem]
        result = run_mechanism_command(
            command, ScriptedPrompter(scene, script), scene, str(tmp_path / case),
            scene_name=f"{stem}.3dm", mechanism_id=ident,
        )  # fmt: skip
        assert result is not None
        out.update({m.label: m.points for m in result.marks})
    apothem = 0.29743
    assert out["C1 axis (negative)"][0] == pytest.approx((-apothem, -0.3, 0.0), abs=1e-5)
    # hinges are the mid-points of the hinge lines, y in [0, 4]
    assert out["A1 A"][0] == pytest.approx((0.6, 2.0, 0.0))
    assert out["A1 D-"][0] == pytest.approx((4.6, 2.0, 0.0))
    h_c = 2.214230180630209  # two_block_wall.3dm: docs/geometry.md's Eq. 17 example
    assert out["T1 h_c"][0] == pytest.approx((0.3, 1.5, h_c), rel=1e-9)


def test_check_marks_are_in_model_units(scenes: Any, tmp_path: Path) -> None:
    stem, command, ident, script = SCRIPTS["rect_wall"]
    scene = prepared_from(scenes[stem], scale=1e-3)
    result = run_mechanism_command(
        command, ScriptedPrompter(scene, script), scene, str(tmp_path),
        scene_name="rect_wall.3dm", mechanism_id=ident,
    )  # fmt: skip
    assert result is not None
    marks = {m.label: m.points for m in check_marks(result.spec, scene, result.constants)}
    assert marks["W1 G"][0] == pytest.approx((250.0, 500.0, 1500.0), rel=1e-12)
