"""``rockmech search`` and the Python API's ``rockmech.search`` (issue #31)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from search_scenes import EXAMPLE_SCENE, EXAMPLE_SPEC, wedge_facade, wedge_spec, write_spec
from typer.testing import CliRunner

import rockmech
from shared_schema.errors import InputError
from solver_service.cli import app
from solver_service.workflows.inputs import constants_from_scene_files

runner = CliRunner()


def test_cli_writes_the_outputs_and_the_spec_reopens(tmp_path: Path) -> None:
    scene = wedge_facade(tmp_path, windows=[(1.5, 2.7, 1.0, 3.0)])
    spec = write_spec(tmp_path / "s.json", wedge_spec("good", (0.25, 0.12)))
    out = tmp_path / "out"
    res = runner.invoke(app, ["search", str(scene), str(spec), "-o", str(out), "--no-figure"])
    assert res.exit_code == 0, res.output
    assert "wedge_overturning" in res.stdout and "built; wrote" in res.stdout
    names = sorted(p.name for p in out.iterdir())
    assert names == [".rockmech", "constants.json", "search.3dm", "search.json", "search.spec.json"]
    doc = json.loads((out / "search.json").read_text())
    assert doc["kind"] == "search" and doc["candidates"]
    # the spec reopens with the existing constants command, on the input and on search.3dm
    mine = json.loads((out / "constants.json").read_text())["mechanisms"]
    for scene_file in (scene, out / "search.3dm"):
        cf = constants_from_scene_files(scene_file, out / "search.spec.json")
        for m, again in zip(mine, cf.mechanisms):
            assert again.positive.p_eq == pytest.approx(m["positive"]["p_eq"], rel=1e-12)
    res = runner.invoke(
        app,
        ["constants", str(scene), str(out / "search.spec.json"), "-o", str(tmp_path / "c.json")],
    )
    assert res.exit_code == 0, res.output


def test_cli_json_prints_one_document(tmp_path: Path) -> None:
    scene = wedge_facade(tmp_path)
    spec = write_spec(tmp_path / "s.json", wedge_spec("poor", None, lp=False))
    res = runner.invoke(
        app, ["search", str(scene), str(spec), "-o", str(tmp_path / "o"), "--json", "--no-figure"]
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert doc["rankings"]["static"][0] == "S01"
    assert doc["candidates"][0]["lam0"] == pytest.approx(0.5 / 9.0, rel=1e-12)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        ({"walls": [{"id": "F", "object": "nothing", "density": 1800}]}, "walls[0].object"),
        ({"walls": [{"id": "F", "object": "facade", "density": -3}]}, "walls[0].density"),
        ({"ranking": {"band_hz": [5, 1]}}, "ranking.band_hz"),
        ({"families": ["three_block"]}, "families[0]"),
    ],
)
def test_cli_bad_spec_exits_2_naming_the_field(
    tmp_path: Path, edit: dict[str, object], message: str
) -> None:
    scene = wedge_facade(tmp_path)
    spec = write_spec(tmp_path / "s.json", {**wedge_spec("poor", None), **edit})
    res = runner.invoke(app, ["search", str(scene), str(spec), "-o", str(tmp_path / "o")])
    assert res.exit_code == 2
    assert res.stderr.startswith("error: ") and message in res.stderr
    assert not (tmp_path / "o" / "search.json").exists()


def test_cli_missing_junction_names_the_walls(tmp_path: Path) -> None:
    scene = wedge_facade(tmp_path)
    doc = wedge_spec("poor", None)
    del doc["default_junction"]
    spec = write_spec(tmp_path / "s.json", doc)
    res = runner.invoke(app, ["search", str(scene), str(spec), "-o", str(tmp_path / "o")])
    assert res.exit_code == 2
    assert "junctions" in res.stderr and "'F'" in res.stderr


def test_cli_work_limit_refuses_before_searching(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import solver_service.workflows.search as wf

    monkeypatch.setattr(wf, "MAX_EVALUATIONS", 10)
    scene = wedge_facade(tmp_path)
    spec = write_spec(tmp_path / "s.json", wedge_spec("good", (0.25, 0.12)))
    res = runner.invoke(app, ["search", str(scene), str(spec), "-o", str(tmp_path / "o")])
    assert res.exit_code == 2
    assert "error: work_limit:" in res.stderr and "more than the work limit's 10" in res.stderr
    assert "counted before the search ran" in res.stderr
    res = runner.invoke(
        app,
        ["search", str(scene), str(spec), "-o", str(tmp_path / "o"), "--no-limits", "--no-figure"],
    )
    assert res.exit_code == 0, res.output


def test_a_hinge_line_every_millimetre_is_refused_at_once_with_the_estimate(
    tmp_path: Path,
) -> None:
    """Issue #37: the work estimate runs before the search (it took 35 s to refuse)."""
    import time

    doc = json.loads(EXAMPLE_SPEC.read_text())
    doc["candidates"] = {"spacing": 0.001}
    doc["ranking"].pop("site")
    doc["ranking"].pop("records")
    spec = write_spec(tmp_path / "mm.search.json", doc)
    t0 = time.perf_counter()
    with pytest.raises(InputError) as err:
        rockmech.search(EXAMPLE_SCENE, spec)
    elapsed = time.perf_counter() - t0
    assert err.value.field == "work_limit"
    msg = str(err.value)
    assert "at least" in msg and "candidate hinge lines" in msg
    assert "more than the work limit's 200000" in msg
    least = int(msg.split("needs at least ")[1].split(" ")[0])
    assert least > 200_000
    assert elapsed < 10.0, elapsed  # reading the scene and counting; no λ0 was evaluated


def test_the_work_estimate_is_a_lower_bound_of_the_search_s_work() -> None:
    from cad_maths.scenes import read_scene
    from cad_maths.search.families import Budget, enumerate_candidates, work_estimate
    from cad_maths.search.model import building_from_scene
    from solver_service.workflows.search import read_search_spec

    bld = building_from_scene(read_scene(EXAMPLE_SCENE), read_search_spec(EXAMPLE_SPEC))
    est = work_estimate(bld)
    budget = Budget()
    cands, _ = enumerate_candidates(bld, budget)
    assert est.complete and 0 < est.evaluations <= budget.used
    assert est.refinements >= len(cands)
    # a limit just below the estimate refuses before any evaluation
    with pytest.raises(InputError, match="counted before the search ran"):
        enumerate_candidates(bld, Budget(est.evaluations - 1))


def test_python_api_search(tmp_path: Path) -> None:
    run = rockmech.search(EXAMPLE_SCENE, EXAMPLE_SPEC)
    assert isinstance(run, rockmech.SearchRun)
    (tmp_path / "constants.json").write_text("the user's own file\n")
    (tmp_path / "notes.txt").write_text("kept\n")
    # Written as --out writes: a file rockmech did not write is never replaced.
    with pytest.raises(InputError, match=r"constants\.json was not written by rockmech"):
        rockmech.write_search(run, tmp_path, figure=True)
    (tmp_path / "constants.json").unlink()
    paths = rockmech.write_search(run, tmp_path, figure=True)
    assert (tmp_path / "notes.txt").read_text() == "kept\n"
    assert all(p.parent == tmp_path for p in paths)
    assert {p.name for p in paths} == {
        "search.json",
        "search.spec.json",
        "constants.json",
        "search.3dm",
        "search.png",
    }
    assert (tmp_path / "search.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("unit", "field"),
    [
        ((0.25, 0.001), "default_junction.unit.height"),
        ((3.0, 0.12), "default_junction.unit.length"),
    ],
)
def test_an_implausible_masonry_unit_gets_a_warning_naming_the_field(
    tmp_path: Path, unit: tuple[float, float], field: str
) -> None:
    """Issue #37: a 1 mm course gave β_bond 89.6° and λ0 +53 % without a word."""
    import math

    scene = wedge_facade(tmp_path)
    spec = write_spec(tmp_path / "s.json", wedge_spec("good", unit, families=["overturning"]))
    run = rockmech.search(scene, spec)
    (note,) = [n for n in run.doc.to_dict()["warnings"] if field in n]
    assert note.startswith(f"{field} = {unit[0] if 'length' in field else unit[1]:g} m ")
    assert not [
        n for n in run.doc.to_dict()["notes"] if field in n
    ]  # a warning, not among the notes
    assert f"{math.degrees(math.atan(unit[0] / (2 * unit[1]))):.1f} deg" in note
    # a plausible unit says nothing
    spec = write_spec(
        tmp_path / "t.json", wedge_spec("good", (0.25, 0.06), families=["overturning"])
    )
    quiet = rockmech.search(scene, spec).doc.to_dict()
    assert not [n for n in quiet["warnings"] + quiet["notes"] if "unit." in n]


def test_cli_pauses_the_collector_while_it_works_and_restores_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The collector is off during the search and back on after it, on success and on error."""
    import gc

    from solver_service.workflows import search as workflow

    seen: list[bool] = []
    real = workflow.search_from_files

    def spy(*args: object, **kwargs: object) -> object:
        seen.append(gc.isenabled())
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(workflow, "search_from_files", spy)
    scene = wedge_facade(tmp_path)
    spec = write_spec(tmp_path / "s.json", wedge_spec("good", (0.25, 0.12)))
    assert gc.isenabled()
    res = runner.invoke(
        app, ["search", str(scene), str(spec), "-o", str(tmp_path / "o"), "--no-figure"]
    )
    assert res.exit_code == 0, res.output
    assert seen == [False] and gc.isenabled()
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    res = runner.invoke(
        app, ["search", str(scene), str(bad), "-o", str(tmp_path / "p"), "--no-figure"]
    )
    assert res.exit_code != 0 and "Traceback" not in res.output
    assert seen == [False, False] and gc.isenabled()
