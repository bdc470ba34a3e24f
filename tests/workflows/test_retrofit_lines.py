"""Candidate ties drawn in the scene (#39): the retrofit spec's ``tie_lines``.

The bundled search façade (``examples/scenes/search_facade.3dm``: the façade F is the box
x 0 to 0.5 m, y 0 to 8 m, z 0 to 10.5 m, its outer face x = 0) with lines added on a layer
``Retrofit::Candidates``; everything runs through ``rockmech retrofit --scene ...
--search-spec ...``. The references, by hand:

* a horizontal line across F at z = Z_LINE is a candidate of each mechanism of F whose hinge
  (the constants' ``positive.axis_point_m``) is below Z_LINE, at the height Z_LINE − z_hinge
  on the outer face; its T* is the one the spec's ``heights_m`` gives at that height (to
  1e-12: one computation);
* of a mechanism of F whose hinge is above Z_LINE the line is no candidate, and the document
  says why;
* a line through the back wall B alone, which no mechanism turns, is said in the document;
* a line away from every wall: refused, naming the line and the nearest wall with the gap
  (F's outer face is at x = 0: a line at x = -2 m is 2 m from it); a sloped line: refused,
  naming the line and its slope.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import rhino3dm
from search.search_scenes import BUILD, EXAMPLE_SCENE, EXAMPLE_SPEC
from typer.testing import CliRunner

from cad_maths.scenes import read_scene
from solver_service.cli import app
from solver_service.workflows.assess import read_site
from solver_service.workflows.search import read_search_spec, search_run

SITE = EXAMPLE_SPEC.parent.parent / "sites" / "ntc_site.json"
RSPEC: dict[str, Any] = {
    "steel": {"grade": "S275", "diameters_mm": [16, 20, 24]},
    "anchorage": {"capacity_N": 60000.0, "source": "plate punching, designer's calculation"},
}
LAYER = "Retrofit::Candidates"
Z_LINE = 8.7


def _scene(tmp_path: Path, *lines: tuple[str, Any, Any]) -> Path:
    """The example scene with ``lines`` (name, start, end [m]) on ``LAYER``."""
    b = BUILD.Builder("lines")
    b.model = rhino3dm.File3dm.Read(str(EXAMPLE_SCENE))
    for name, a, e in lines:
        b.line(name, LAYER, a, e)
    return Path(b.write(tmp_path / "lines.3dm"))


def _lighter() -> Any:
    """The example's search spec, lighter: the ranking's band does not enter the retrofit."""
    spec = read_search_spec(EXAMPLE_SPEC)
    lighter = spec.ranking.model_copy(update={"n_frequencies": 40})
    return spec.model_copy(update={"lp": False, "ranking": lighter})


def _run(tmp_path: Path, scene: Path, rspec: dict[str, Any]) -> Any:
    """``rockmech retrofit --scene SCENE --search-spec SPEC --json``: exit code and output."""
    lighter = _lighter()
    spec_path = tmp_path / "light.search.json"
    spec_path.write_text(lighter.model_dump_json(exclude_none=True), encoding="utf-8")
    rpath = tmp_path / "ties.retrofit.json"
    rpath.write_text(json.dumps(rspec), encoding="utf-8")
    args = ["--scene", str(scene), "--search-spec", str(spec_path)]
    return CliRunner().invoke(
        app, ["retrofit", *args, "--site", str(SITE), "--spec", str(rpath), "--json"]
    )


def _ok(res: Any) -> dict[str, Any]:
    assert res.exit_code == 0, res.output
    doc: dict[str, Any] = json.loads(res.stdout)
    return doc


def _refused(res: Any) -> str:
    assert res.exit_code == 2 and "Traceback" not in res.output, res.output
    out: str = res.output
    return out


@pytest.fixture(scope="module")
def across(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, Any], Path]:
    tmp = tmp_path_factory.mktemp("across")
    scene = _scene(
        tmp,
        ("tie_across", (0.0, 3.0, Z_LINE), (6.0, 3.0, Z_LINE)),
        ("tie_back", (7.0, 4.0, 5.0), (5.5, 4.0, 5.0)),
    )
    doc = _ok(_run(tmp, scene, {**RSPEC, "tie_lines": [{"layer": "Candidates"}]}))
    return doc, scene


def _hinge_z(doc: dict[str, Any]) -> dict[str, float]:
    """Each mechanism's hinge z [m], from the first search's constants (``search_run``)."""
    run = search_run(read_scene(EXAMPLE_SCENE), _lighter(), site=read_site(SITE), motions=[])
    assert run.constants is not None
    names = {m["name"]: m["id"] for m in doc["mechanisms"]}
    out = {}
    for m in run.constants.mechanisms:
        assert names[m.name] == m.id  # the same search
        out[m.id] = float(m.geometry["positive"]["axis_point_m"][2])
    return out


def test_a_line_across_the_facade_is_a_candidate_at_its_height(
    across: tuple[dict[str, Any], Path], tmp_path: Path
) -> None:
    doc, scene = across
    tmp = scene.parent
    hinge = _hinge_z(doc)
    facade = {m["id"] for m in doc["mechanisms"] if m["id"] in hinge}
    tied = below = 0
    heights: dict[str, dict[str, Any]] = {}
    for m in doc["mechanisms"]:
        lines = [o for o in m["options"] if "tie line 'tie_across'" in o["height_source"]]
        said = " ".join(m["decisions"])
        if lines:
            (o,) = m["options"]  # the line's only: no default heights beside it
            assert o["height_m"] == Z_LINE - hinge[m["id"]]
            assert LAYER in o["height_source"] and "crossing wall F" in o["height_source"]
            assert any(
                d.startswith("candidate ties: the retrofit spec's tie lines")
                for d in m["decisions"]
            )
            heights[m["id"]] = {"heights_m": [Z_LINE - hinge[m["id"]]]}
            tied += 1
        elif "tie line 'tie_across'" in said:
            assert hinge[m["id"]] >= Z_LINE and "at or below the hinge" in said
            below += 1
    assert tied >= 2 and below >= 1 and facade
    # a line through the back wall only, which no mechanism turns: said in the decisions
    assert any("'tie_back'" in d and "crosses wall B" in d for d in doc["decisions"])
    # T* at the line's height is the one heights_m gives there, to 1e-12
    res = _run(tmp, EXAMPLE_SCENE, {**RSPEC, "mechanisms": heights})
    by = {m["id"]: m for m in _ok(res)["mechanisms"]}
    for m in doc["mechanisms"]:
        if m["id"] not in heights:
            continue
        (o,) = m["options"]
        (want,) = by[m["id"]]["options"]
        assert want["height_m"] == o["height_m"]
        if want["T_star_N"] is None:
            assert o["T_star_N"] is None and o["status"] == want["status"]
        else:
            assert o["T_star_N"] == pytest.approx(want["T_star_N"], rel=1e-12, abs=0.0)


def test_a_line_missing_every_wall_is_refused_naming_it_and_the_gap(tmp_path: Path) -> None:
    # 2 m outside F's outer face (x = 0), along it: F is the nearest wall, 2 m away
    scene = _scene(tmp_path, ("stray", (-2.0, 1.0, 4.0), (-2.0, 6.0, 4.0)))
    out = _refused(_run(tmp_path, scene, {**RSPEC, "tie_lines": ["stray"]}))
    assert "error: tie_lines[0]:" in out
    assert "'stray'" in out and LAYER in out and "nearest wall is F, 2 m" in out


def test_a_sloped_line_is_refused_naming_its_slope(tmp_path: Path) -> None:
    # rises 0.6 m over 6 m: slope 0.1
    scene = _scene(tmp_path, ("sloped", (0.0, 3.0, 4.0), (6.0, 3.0, 4.6)))
    out = _refused(_run(tmp_path, scene, {**RSPEC, "tie_lines": [{"layer": "Candidates"}]}))
    assert "error: tie_lines[0]:" in out and "'sloped'" in out and "slope 0.1 " in out


def test_tie_lines_are_refused_on_the_constants_route(tmp_path: Path) -> None:
    rpath = tmp_path / "ties.retrofit.json"
    rpath.write_text(json.dumps({**RSPEC, "tie_lines": ["tie_1"]}), encoding="utf-8")
    constants = EXAMPLE_SCENE.parent.parent / "constants" / "church_geometry.json"
    res = CliRunner().invoke(
        app, ["retrofit", str(constants), "--site", str(SITE), "--spec", str(rpath)]
    )
    out = _refused(res)
    assert "error: tie_lines:" in out and "--scene" in out
