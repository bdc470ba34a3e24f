"""The commands' prompt flows over the example scenes: prompts -> spec -> constants file.

Reference: the headless CLI, ``rockmech constants SCENE SPEC`` with the shipped spec of
the same scene. The scripted answers select the same objects and give the same numbers as
that spec, so every constant must come out equal (same code path, same floating point).
"""

import json
import math
import os
from pathlib import Path
from typing import Any, Dict, List, Tuple

import pytest

from rhino_plugin.flows.mechanisms import run_mechanism_command
from shared_schema.io import read_constants

from .conftest import CANCEL, ENTER, ScriptedPrompter

TAIL_DEFAULT = [("get_option", "Computed"), ("get_option", "No")]  # eta, amplification

SCRIPTS: Dict[str, Tuple[str, str, str, List[Tuple[str, Any]]]] = {
    # case: (scene stem, command, mechanism id, steps)
    "rect_wall": (
        "rect_wall",
        "RM_SingleBlock",
        "W1",
        [
            ("get_objects", ["wall"]),
            ("get_number", 1800),
            ("get_objects", []),
            ("get_line", "axis"),
            ("get_option", "Done"),
            ("get_option", "TwoSided"),
            ("get_option", "FromBase"),
            *TAIL_DEFAULT,
        ],
    ),
    "statue_column": (
        "statue_column",
        "RM_SingleBlock",
        "C1",
        [
            ("get_objects", ["column"]),
            ("get_number", 2600),
            ("get_objects", ["statue"]),
            ("get_number", "8500"),  # typed text is accepted when it is a number
            ("get_objects", []),
            ("get_line", "axis"),
            ("get_option", "Done"),
            ("get_option", "TwoSided"),
            ("get_option", "PickOrDraw"),
            ("get_line", "axis_back"),
            *TAIL_DEFAULT,
        ],
    ),
    "facade_crack": (
        "facade",
        "RM_SingleBlock",
        "F2",
        [
            ("get_objects", ["facade"]),
            ("get_number", 1800),
            ("get_objects", []),
            ("get_line", "axis"),
            ("get_option", "PlanarObject"),
            ("get_objects", ["crack"]),
            ("get_option", "AxisSide"),
            ("get_option", "Done"),
            ("get_option", "OneSided"),
            *TAIL_DEFAULT,
        ],
    ),
    "facade_loaded": (
        "facade",
        "RM_LoadedWall",
        "F1",
        [
            ("get_objects", ["facade"]),
            ("get_number", 1800),
            ("get_objects", []),  # no more main-wall groups
            ("get_objects", []),  # no adjacent walls
            ("get_line", "axis"),
            ("get_option", "Done"),
            ("get_checkboxes", ["Floors", "Roof", "Vaults", "Tie-bars"]),
            ("get_objects", ["floor_bearing"]),
            ("get_number", 2400),
            ("get_number", ENTER),  # tributary: the default offered, 0.5
            ("get_objects", ["floor_abutting"]),
            ("get_number", 2400),
            ("get_number", 0.5),
            ("get_objects", []),
            ("get_objects", ["roof"]),
            ("get_number", 350),
            ("get_number", "0.5"),
            ("get_option", "Tied"),
            ("get_objects", ["vault"]),
            ("get_option", "b"),
            ("get_objects", []),
            ("get_objects", ["tie_1"]),
            ("get_number", 20000),
            ("get_objects", ["tie_2"]),
            ("get_number", 20000),
            ("get_objects", []),
            *TAIL_DEFAULT,
        ],
    ),
    "two_block_wall": (
        "two_block_wall",
        "RM_TwoBlock",
        "T1",
        [
            ("get_objects", ["wall"]),
            ("get_number", 1800),
            ("get_objects", []),
            ("get_line", "axis"),
            ("get_option", "Objects"),
            ("get_objects", ["floor"]),
            ("get_number", 2400),
            ("get_number", ENTER),
            ("get_number", 100000),
            ("get_option", "TwoSided"),
            *TAIL_DEFAULT,
        ],
    ),
    **{
        stem: (
            stem,
            "RM_MultiBlock",
            ident,
            [
                ("get_option", "TwoSided"),
                ("get_objects", [b1]),
                ("get_number", d1),
                ("get_objects", []),
                ("get_objects", [b2]),
                ("get_number", d2),
                ("get_objects", []),
                ("get_objects", [b3]),
                ("get_number", d3),
                ("get_objects", []),
                *[("get_line", f"hinge_{n}") for n in "ABCD"],
                ("get_option", "PickOrDraw"),
                *[("get_line", f"hinge_{n}_neg") for n in "ABCD"],
                *TAIL_DEFAULT,
            ],
        )
        for stem, ident, (b1, d1), (b2, d2), (b3, d3) in [
            ("side_aisle", "A1", ("wall", 2200), ("vault", 1800), ("pier", 2600)),
            ("portal_frame", "P1", ("column_left", 2600), ("beam", 2600), ("column_right", 2600)),
        ]
    },
}


def _comparable(entry: Dict[str, Any]) -> Dict[str, Any]:
    """A constants entry without what names the spec file (description, spec path)."""
    out = json.loads(json.dumps(entry))
    out.pop("name", None)
    out["provenance"].pop("spec", None)
    return out


def _run(case: str, scenes: Any, out: Path, steps: Any = None) -> Tuple[Any, ScriptedPrompter]:
    stem, command, ident, script = SCRIPTS[case]
    scene = scenes[stem]
    prompter = ScriptedPrompter(scene, script if steps is None else steps)
    result = run_mechanism_command(
        command, prompter, scene, str(out), scene_name=f"{stem}.3dm", mechanism_id=ident
    )
    return result, prompter


@pytest.mark.parametrize("case", sorted(SCRIPTS))
def test_flow_writes_the_constants_of_the_headless_cli(
    case: str, scenes: Any, cli_constants: Any, tmp_path: Path
) -> None:
    stem, _command, ident, _ = SCRIPTS[case]
    result, prompter = _run(case, scenes, tmp_path)
    assert result is not None, prompter.messages
    assert prompter.done(), f"questions left unasked: {prompter.steps}"
    written = json.loads(Path(result.constants_path).read_text())["mechanisms"]
    assert len(written) == 1
    assert _comparable(written[0]) == _comparable(cli_constants(stem)[ident])
    # the files are the headless path's: the spec reads back and the constants validate
    assert read_constants(result.constants_path).mechanisms[0].id == ident
    spec = json.loads(Path(result.spec_path).read_text())
    assert spec["mechanisms"][0]["typology"] == result.spec.mechanisms[0].typology
    assert sorted(os.listdir(tmp_path)) == sorted(
        [f"{stem}.{ident}.spec.json", f"{stem}.{ident}.constants.json"]
    )


def test_written_spec_reproduces_the_constants_through_the_cli(scenes: Any, tmp_path: Path) -> None:
    """The flow's spec file is a headless input: the CLI on it gives the same constants."""
    import subprocess
    import sys

    result, _ = _run("facade_loaded", scenes, tmp_path)
    assert result is not None
    again = tmp_path / "again.json"
    subprocess.run(
        [
            sys.executable,
            "-c",
            "from solver_service.cli import app; app()",
            "constants",
            str(Path(__file__).resolve().parents[2] / "examples/scenes/facade.3dm"),
            result.spec_path,
            "-o",
            str(again),
        ],
        check=True,
        capture_output=True,
    )
    first = json.loads(Path(result.constants_path).read_text())["mechanisms"][0]
    second = json.loads(again.read_text())["mechanisms"][0]
    assert first == second


def test_drawn_axis_gives_the_constants_of_the_axis_object(
    scenes: Any, cli_constants: Any, tmp_path: Path
) -> None:
    steps = list(SCRIPTS["rect_wall"][3])
    steps[3] = ("get_line", ((0.5, 0.0, 0.0), (0.5, 1.0, 0.0)))  # the axis line's end points
    result, prompter = _run("rect_wall", scenes, tmp_path, steps)
    assert result is not None, prompter.messages
    spec = json.loads(Path(result.spec_path).read_text())["mechanisms"][0]
    assert spec["axis"] == {"start": [0.5, 0.0, 0.0], "end": [0.5, 1.0, 0.0]}
    got = result.constants.mechanisms[0]
    want = cli_constants("rect_wall")["W1"]
    assert "negative" not in want  # symmetric wall: one side stored
    positive = got.positive.model_dump(exclude_none=True)
    for key, value in want["positive"].items():
        assert positive[key] == value, key
    assert got.eta == want["eta"]


def test_crack_by_three_points_matches_the_crack_surface(
    scenes: Any, cli_constants: Any, tmp_path: Path
) -> None:
    steps = list(SCRIPTS["facade_crack"][3])
    # three points of the crack plane: normal (0, 1, 1)/sqrt(2) through (., 1, 8), (., 6, 3)
    steps[4:6] = [
        ("get_option", "ThreePoints"),
        ("get_points", [(0, 1, 8), (0.6, 1, 8), (0, 6, 3)]),
    ]
    result, prompter = _run("facade_crack", scenes, tmp_path, steps)
    assert result is not None, prompter.messages
    got = result.constants.mechanisms[0]
    want = cli_constants("facade")["F2"]
    assert got.geometry["volume_m3"] == pytest.approx(want["geometry"]["volume_m3"], rel=1e-12)
    positive = got.positive.model_dump(exclude_none=True)
    for key, value in want["positive"].items():
        assert positive[key] == pytest.approx(value, rel=1e-10, abs=1e-12), key
    assert got.eta == pytest.approx(want["eta"], rel=1e-10)


def test_eta_override_and_amplification_reach_the_constants(scenes: Any, tmp_path: Path) -> None:
    steps = [
        *SCRIPTS["rect_wall"][3][:-2],
        ("get_option", "Override"),
        ("get_number", 0.85),
        ("get_option", "Yes"),
        ("get_number", 6.2),
        ("get_number", 4.7),
        ("get_number", 3.1),
    ]
    result, prompter = _run("rect_wall", scenes, tmp_path, steps)
    assert result is not None, prompter.messages
    mech = result.constants.mechanisms[0]
    assert (mech.eta, mech.eta_source) == (0.85, "user")
    assert mech.amplification.model_dump() == {"f_n": 6.2, "h_e": 4.7, "h": 3.1}


# ---------------------------------------------------------------------- bad input


def _assert_nothing_written(out: Path, prompter: ScriptedPrompter, *needles: str) -> None:
    assert os.listdir(out) == []
    text = "\n".join(prompter.messages)
    assert "Nothing was written" in text or "nothing was written" in text
    for needle in needles:
        assert needle in text, text


@pytest.mark.parametrize("case", sorted(SCRIPTS))
def test_cancel_at_any_prompt_writes_nothing(case: str, scenes: Any, tmp_path: Path) -> None:
    script = SCRIPTS[case][3]
    for k in range(len(script)):
        out = tmp_path / f"step{k}"
        out.mkdir()
        steps = [*script[:k], (script[k][0], CANCEL)]
        result, prompter = _run(case, scenes, out, steps)
        assert result is None
        assert prompter.done(), f"step {k}: the flow went on after the cancel"
        _assert_nothing_written(out, prompter, "cancelled")


@pytest.mark.parametrize("case", sorted(SCRIPTS))
def test_empty_first_selection_is_refused(case: str, scenes: Any, tmp_path: Path) -> None:
    script = SCRIPTS[case][3]
    k = next(i for i, (method, _) in enumerate(script) if method == "get_objects")
    result, prompter = _run(case, scenes, tmp_path, [*script[:k], ("get_objects", [])])
    assert result is None
    _assert_nothing_written(tmp_path, prompter, "nothing was selected", ".objects")


@pytest.mark.parametrize(
    ("case", "step"),
    [("facade_crack", 0), ("facade_loaded", 0), ("facade_loaded", 7), ("facade_loaded", 14)],
)
def test_surface_offered_as_a_solid_is_refused_by_name(
    case: str, step: int, scenes: Any, tmp_path: Path
) -> None:
    """The crack, a planar surface, offered as a wall, a floor or a roof."""
    script = SCRIPTS[case][3]
    assert script[step][0] == "get_objects"
    result, prompter = _run(case, scenes, tmp_path, [*script[:step], ("get_objects", ["crack"])])
    assert result is None
    _assert_nothing_written(tmp_path, prompter, "crack (Cracks", "is not a solid")


@pytest.fixture(scope="module")
def open_box_scene(tmp_path_factory: pytest.TempPathFactory) -> Any:
    """A .3dm with a closed box, the same box without its top (open) and a base axis."""
    import rhino3dm

    from cad_maths.scene_3dm import Scene

    model = rhino3dm.File3dm()
    model.Settings.ModelUnitSystem = rhino3dm.UnitSystem.Meters
    corners = [
        (0, 0, 0),
        (1, 0, 0),
        (1, 1, 0),
        (0, 1, 0),
        (0, 0, 3),
        (1, 0, 3),
        (1, 1, 3),
        (0, 1, 3),
    ]
    quads = [(0, 3, 2, 1), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7), (4, 5, 6, 7)]
    for name, faces in (("closed_box", quads), ("open_box", quads[:-1])):
        mesh = rhino3dm.Mesh()
        for x, y, z in corners:
            mesh.Vertices.Add(x, y, z)  # small integers: exact in float32
        for quad in faces:
            mesh.Faces.AddFace(*quad)
        attr = rhino3dm.ObjectAttributes()
        attr.Name = name
        model.Objects.AddMesh(mesh, attr)
    attr = rhino3dm.ObjectAttributes()
    attr.Name = "axis"
    model.Objects.AddLine(rhino3dm.Point3d(1, 0, 0), rhino3dm.Point3d(1, 1, 0), attr)
    path = tmp_path_factory.mktemp("open") / "open_box.3dm"
    assert model.Write(str(path), 8)
    return Scene.from_3dm(path)


def test_open_object_is_refused_by_name(open_box_scene: Any, tmp_path: Path) -> None:
    steps = [("get_objects", ["closed_box", "open_box"])]
    prompter = ScriptedPrompter(open_box_scene, steps)
    result = run_mechanism_command(
        "RM_SingleBlock", prompter, open_box_scene, str(tmp_path), scene_name="open_box.3dm"
    )
    assert result is None
    _assert_nothing_written(tmp_path, prompter, "open_box", "is not a closed solid")


def test_closed_box_of_the_same_file_is_accepted(open_box_scene: Any, tmp_path: Path) -> None:
    """The open-box file itself is fine: the closed box gives the block's exact constants."""
    steps = [
        ("get_objects", ["closed_box"]),
        ("get_number", 2000),
        ("get_objects", []),
        ("get_line", "axis"),
        ("get_option", "Done"),
        ("get_option", "OneSided"),
        *TAIL_DEFAULT,
    ]
    prompter = ScriptedPrompter(open_box_scene, steps)
    result = run_mechanism_command(
        "RM_SingleBlock", prompter, open_box_scene, str(tmp_path), scene_name="open_box.3dm"
    )
    assert result is not None, prompter.messages
    side = result.constants.mechanisms[0].positive
    # 1 x 1 x 3 m block about a base edge: R = sqrt(0.5^2 + 1.5^2), alpha = atan(1/3)
    assert side.phi_cr == pytest.approx(math.atan(1 / 3), rel=1e-12)
    mass = 2000 * 3.0
    i_o = mass * (1.0**2 + 3.0**2) / 3.0  # about a base edge parallel to y
    assert side.I0 == pytest.approx(i_o, rel=1e-12)


@pytest.mark.parametrize(
    "answer", ["abc", "", None, -1800, 0, float("nan"), float("inf"), True, 1e308, 30001]
)
def test_bad_density_is_refused(answer: Any, scenes: Any, tmp_path: Path) -> None:
    script = SCRIPTS["rect_wall"][3]
    result, prompter = _run("rect_wall", scenes, tmp_path, [*script[:1], ("get_number", answer)])
    assert result is None
    _assert_nothing_written(tmp_path, prompter, "W1.groups[0].density", "density")


@pytest.mark.parametrize(
    ("case", "value", "field", "words"),
    [
        ("facade_loaded", 1e300, "F1.tie_bars[0].force", "must be at most 1e+09 N"),
        ("two_block_wall", 1e308, "T1.f_mt", "must be at most 1e+08 Pa"),
        ("two_block_wall", 40000.0, "T1.overburden.density", "must be at most 30000 kg/m^3"),
    ],
)
def test_a_value_beyond_its_range_is_refused_at_the_prompt(
    case: str, value: float, field: str, words: str, scenes: Any, tmp_path: Path
) -> None:
    """The prompts obey the spec's ranges (shared_schema.rules), before any geometry."""
    script = SCRIPTS[case][3]
    good = {"force": 20000, "f_mt": 100000, "density": 2400}[field.rsplit(".", 1)[-1]]
    k = script.index(("get_number", good))
    result, prompter = _run(case, scenes, tmp_path, [*script[:k], ("get_number", value)])
    assert result is None
    _assert_nothing_written(tmp_path, prompter, field, words)


@pytest.mark.parametrize(
    ("case", "k", "value", "field"),
    [
        ("facade_loaded", 0, 1.5, "F1.floors[0].tributary"),
        ("facade_loaded", 2, 0.0, "F1.roof.tributary"),
        ("two_block_wall", 0, -0.5, "T1.overburden.tributary"),
    ],
)
def test_a_tributary_share_outside_0_1_is_refused_at_the_prompt(
    case: str, k: int, value: float, field: str, scenes: Any, tmp_path: Path
) -> None:
    script = SCRIPTS[case][3]
    ok = _run(case, scenes, tmp_path / "ok")[1]
    i = [j for j, (_, prompt) in enumerate(ok.asked) if "tributary" in prompt][k]
    out = tmp_path / "bad"
    out.mkdir()
    result, prompter = _run(case, scenes, out, [*script[:i], ("get_number", value)])
    assert result is None
    _assert_nothing_written(out, prompter, field, "tributary share")


def test_a_line_is_not_a_solid(scenes: Any, tmp_path: Path) -> None:
    SCRIPTS["rect_wall"][3]
    result, prompter = _run("rect_wall", scenes, tmp_path, [("get_objects", ["axis"])])
    assert result is None
    _assert_nothing_written(tmp_path, prompter, "axis", "not a solid")


def test_a_solid_is_not_an_axis(scenes: Any, tmp_path: Path) -> None:
    script = SCRIPTS["rect_wall"][3]
    result, prompter = _run("rect_wall", scenes, tmp_path, [*script[:3], ("get_line", "wall")])
    assert result is None
    _assert_nothing_written(tmp_path, prompter, "wall", "not a line")


def test_out_of_range_eta_is_refused(scenes: Any, tmp_path: Path) -> None:
    steps = [*list(SCRIPTS["rect_wall"][3][:-2]), ("get_option", "Override"), ("get_number", 1.3)]
    result, prompter = _run("rect_wall", scenes, tmp_path, steps)
    assert result is None
    _assert_nothing_written(tmp_path, prompter, "W1.eta", "must be <= 1")


def test_geometry_error_after_the_prompts_writes_nothing(scenes: Any, tmp_path: Path) -> None:
    """An axis that does not touch the body fails in the constants step: no file."""
    steps = list(SCRIPTS["rect_wall"][3])
    steps[3] = ("get_line", ((3.0, 0.0, 0.0), (3.0, 1.0, 0.0)))
    result, prompter = _run("rect_wall", scenes, tmp_path, steps)
    assert result is None
    _assert_nothing_written(tmp_path, prompter, "does not touch the body")


def test_failed_constants_write_removes_the_new_spec(scenes: Any, tmp_path: Path) -> None:
    (tmp_path / "rect_wall.W1.constants.json").mkdir()  # the constants cannot be written
    result, prompter = _run("rect_wall", scenes, tmp_path)
    assert result is None
    assert os.listdir(tmp_path) == ["rect_wall.W1.constants.json"]
    assert "cannot write constants file" in "\n".join(prompter.messages)


def test_ids_are_numbered_per_scene(scenes: Any, tmp_path: Path) -> None:
    scene = scenes["rect_wall"]
    for want in ("SB1", "SB2"):
        prompter = ScriptedPrompter(scene, SCRIPTS["rect_wall"][3])
        result = run_mechanism_command(
            "RM_SingleBlock", prompter, scene, str(tmp_path), scene_name="rect_wall.3dm"
        )
        assert result is not None
        assert result.constants.mechanisms[0].id == want
        assert math.isfinite(result.constants.mechanisms[0].positive.p_eq)
