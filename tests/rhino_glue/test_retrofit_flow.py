"""RM_Retrofit: the command's flow on the bundled church, against ``rockmech retrofit``.

The flow is what the Rhino command runs beneath its glue (which only draws the marks as
lines and text dots): it asks for the three files, writes ``<model>.retrofit/retrofit.json``
(the bytes ``rockmech retrofit`` writes), prints the sentences and places each designed
tie's bars. The bars' places are worked here from the constants' geometry: the church's F1
hinge runs from (0, 0, 0) along +y, its centre of mass is at x = 0.297, y = 3.0 m, so the
wall is 6 m long and inward is +x; the spec puts 2 bars 6.2 m long at 8 m (the higher of its
two heights, which needs the less force).
"""

import json
from pathlib import Path
from typing import Any, Dict, List, Tuple

import pytest
from typer.testing import CliRunner

from rhino_plugin.flows.retrofit import RETROFIT_LAYER, retrofit_flow, retrofit_lines
from shared_schema.errors import InputError
from solver_service.cli import app

from .conftest import ScriptedPrompter
from .test_prepared import prepared_from

ROOT = Path(__file__).resolve().parents[2]
CHURCH = ROOT / "examples" / "constants" / "church_geometry.json"
SITE = ROOT / "examples" / "sites" / "ntc_site.json"
SPEC = ROOT / "examples" / "specs" / "church.retrofit.json"
FILES = [("get_file", str(CHURCH)), ("get_file", str(SITE)), ("get_file", str(SPEC))]


def test_the_flow_writes_rockmech_retrofits_file_and_places_the_bars(tmp_path: Path) -> None:
    ask = ScriptedPrompter(None, FILES)
    # A model in millimetres: 1 model unit = 0.001 m.
    result = retrofit_flow(ask, str(tmp_path), stem="church", unit_scale=0.001)
    assert ask.done()
    out = tmp_path / "church.retrofit" / "retrofit.json"
    assert result.files == [str(out)]
    cli = CliRunner().invoke(
        app,
        ["retrofit", str(CHURCH), "--site", str(SITE), "--spec", str(SPEC), "-o",
         str(tmp_path / "cli")],
    )  # fmt: skip
    assert cli.exit_code == 0, cli.output
    assert out.read_bytes() == (tmp_path / "cli" / "retrofit.json").read_bytes()
    assert ask.messages[0] == f"RM_Retrofit: 4 mechanism(s) via the Python API; wrote {out}"
    assert ask.messages[1:] == retrofit_lines(result.doc) == result.summary
    assert result.summary[0].startswith("2 Ø16 S275 ties at 8 m, 15.1 kN each, make F1 pass")
    f1 = result.doc.find("F1")
    t_bar = f1.options[f1.chosen or 0].T_star_N / 2 / 1e3  # type: ignore[operator]
    f1_marks = [m for m in result.marks if m.label.startswith("F1 ")]
    assert [m.label for m in f1_marks] == [
        f"F1 tie 1/2: Ø16 S275, {t_bar:.3g} kN",
        f"F1 tie 2/2: Ø16 S275, {t_bar:.3g} kN",
    ]
    # In mm: anchorages on the outer face (x = 0) at 8 m, at a quarter and three quarters of
    # the 6 m wall; each bar 6.2 m inward (+x).
    for mark, y in zip(f1_marks, (1500.0, 4500.0)):
        (a, b) = mark.points
        assert a == pytest.approx((0.0, y, 8000.0), abs=1e-6)
        assert b == pytest.approx((6200.0, y, 8000.0), abs=1e-6)
    # F2: one bar at the default height (the top of the moving part), centred on its G.
    (f2,) = [m for m in result.marks if m.label.startswith("F2 ")]
    geo = json.loads(CHURCH.read_text())["mechanisms"][1]["geometry"]
    h2 = result.doc.find("F2").options[0].height_m
    assert f2.points[0] == pytest.approx((0.0, geo["com_m"][1] * 1e3, h2 * 1e3), abs=1e-6)
    assert f2.points[1][0] == pytest.approx(6200.0)
    # A1 and T1 get no tie: nothing drawn for them.
    assert {m.label.split()[0] for m in result.marks} == {"F1", "F2"}
    assert RETROFIT_LAYER == "rockmech retrofit"


def test_the_flow_runs_on_the_service_with_the_same_answer(server: object, tmp_path: Path) -> None:
    local = retrofit_flow(ScriptedPrompter(None, FILES), str(tmp_path / "a"), stem="church")
    ask = ScriptedPrompter(None, FILES)
    remote = retrofit_flow(
        ask,
        str(tmp_path / "b"),
        stem="church",
        service_url=server.url,  # type: ignore[attr-defined]
    )
    assert remote.doc == local.doc and remote.marks == local.marks
    assert "via the service" in ask.messages[0]
    a = (tmp_path / "a" / "church.retrofit" / "retrofit.json").read_bytes()
    assert (tmp_path / "b" / "church.retrofit" / "retrofit.json").read_bytes() == a


def test_a_bad_spec_names_the_field_and_writes_nothing(tmp_path: Path) -> None:
    spec = json.loads(SPEC.read_text())
    spec["steel"]["grade"] = "S460"
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(spec))
    ask = ScriptedPrompter(None, [FILES[0], FILES[1], ("get_file", str(bad))])
    with pytest.raises(InputError) as info:
        retrofit_flow(ask, str(tmp_path), stem="church")
    assert info.value.field == "steel.grade"
    assert not (tmp_path / "church.retrofit").exists()


# --- the scene route: the document's objects searched with a search spec (#39) -------------

SCENE = ROOT / "examples" / "scenes" / "search_facade.3dm"
SEARCH = ROOT / "examples" / "specs" / "search_facade.search.json"
TIES = {
    "steel": {"grade": "S275", "diameters_mm": [16, 20, 24]},
    "anchorage": {"capacity_N": 60000.0, "source": "plate punching, designer's calculation"},
}


@pytest.fixture(scope="module")
def scene_files(tmp_path_factory: pytest.TempPathFactory) -> Dict[str, Path]:
    """The retrofit spec, and ``rockmech retrofit --scene``'s retrofit.json on the example."""
    folder = tmp_path_factory.mktemp("scene_route")
    spec = folder / "ties.retrofit.json"
    spec.write_text(json.dumps(TIES), encoding="utf-8")
    cli = CliRunner().invoke(
        app,
        ["retrofit", "--scene", str(SCENE), "--search-spec", str(SEARCH), "--site", str(SITE),
         "--spec", str(spec), "-o", str(folder / "cli")],
    )  # fmt: skip
    assert cli.exit_code == 0, cli.output
    return {"spec": spec, "cli": folder / "cli" / "retrofit.json"}


def _scene_steps(spec: Path) -> List[Tuple[str, Any]]:
    return [("get_option", "SceneSearch"), ("get_file", str(SEARCH)), ("get_file", str(SITE)),
            ("get_file", str(spec))]  # fmt: skip


def test_the_scene_route_is_rockmech_retrofit_scene_and_draws_the_tie_lines(
    scenes: Any, scene_files: Dict[str, Path], tmp_path: Path
) -> None:
    # The document's objects as DocScene gives them in Rhino (prepared records).
    scene = prepared_from(scenes["search_facade"])
    ask = ScriptedPrompter(scene, _scene_steps(scene_files["spec"]))
    result = retrofit_flow(
        ask, str(tmp_path), stem="search_facade", scene=scene, scene_name=SCENE.name
    )
    assert ask.done() and ask.asked[0] == ("get_option", "Mechanisms from")
    out = tmp_path / "search_facade.retrofit" / "retrofit.json"
    assert result.files == [str(out)]
    assert out.read_bytes() == scene_files["cli"].read_bytes()
    assert ask.messages[0] == (
        f"RM_Retrofit: {len(result.doc.mechanisms)} mechanism(s) via the Python API; wrote {out}"
    )
    sa = result.doc.search_after
    assert sa is not None and sa.after is not None
    assert ask.messages[1:] == result.summary
    assert result.summary[-1].startswith(f"Searched again with the ties: {sa.after} governs")
    # By hand (examples/scenes/build_scenes.py): the façade F has its outer face at x = 0, its
    # inner face at x = 0.5 m, runs along y over 8 m and rises 10.5 m; the designed ties meet
    # at its top, at the middle of the hinge axis: one line (0, 4, 10.5) -> (0.5, 4, 10.5) m
    # carrying the largest designed force.
    designed = [m for m in result.doc.mechanisms if m.status == "designed"]
    force = max(m.options[m.chosen or 0].T_star_N or 0.0 for m in designed)
    (mark,) = result.marks
    assert mark.points[0] == pytest.approx((0.0, 4.0, 10.5), abs=1e-9)
    assert mark.points[1] == pytest.approx((0.5, 4.0, 10.5), abs=1e-9)
    name = "retrofit tie " + "+".join(m.id for m in designed)
    assert mark.label == f"{name}: {force / 1e3:.3g} kN on F"


def test_the_scene_route_on_the_service_gives_the_same_answer(
    server: object, scenes: Any, scene_files: Dict[str, Path], tmp_path: Path
) -> None:
    scene = prepared_from(scenes["search_facade"])
    ask = ScriptedPrompter(scene, _scene_steps(scene_files["spec"]))
    remote = retrofit_flow(
        ask,
        str(tmp_path),
        stem="search_facade",
        unit_scale=0.001,
        service_url=server.url,  # type: ignore[attr-defined]
        scene=scene,
        scene_name=SCENE.name,
        scene_path=str(SCENE),
    )
    assert "via the service" in ask.messages[0]
    out = tmp_path / "search_facade.retrofit" / "retrofit.json"
    assert out.read_bytes() == scene_files["cli"].read_bytes()
    # in millimetres: the same line, a thousand times the metres
    (mark,) = remote.marks
    assert mark.points[0] == pytest.approx((0.0, 4000.0, 10500.0), abs=1e-6)
    assert mark.points[1] == pytest.approx((500.0, 4000.0, 10500.0), abs=1e-6)


def test_the_scene_route_on_the_service_needs_a_saved_model(
    scenes: Any, scene_files: Dict[str, Path], tmp_path: Path
) -> None:
    scene = prepared_from(scenes["search_facade"])
    ask = ScriptedPrompter(scene, _scene_steps(scene_files["spec"]))
    with pytest.raises(InputError) as info:
        retrofit_flow(ask, str(tmp_path), stem="m", service_url="http://127.0.0.1:9", scene=scene)
    assert info.value.field == "scene" and "save the model" in info.value.reason
    assert not (tmp_path / "m.retrofit").exists()


def test_in_a_document_the_constants_route_asks_its_three_files(
    scenes: Any, tmp_path: Path
) -> None:
    scene = prepared_from(scenes["search_facade"])
    ask = ScriptedPrompter(scene, [("get_option", "Constants"), *FILES])
    result = retrofit_flow(ask, str(tmp_path), stem="church", scene=scene)
    assert ask.done()
    alone = retrofit_flow(ScriptedPrompter(None, FILES), str(tmp_path / "b"), stem="church")
    assert result.doc == alone.doc and result.marks == alone.marks
    assert result.doc.search_after is None
