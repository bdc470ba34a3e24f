"""The retrofit from a scene (#39, "what governs next"): the search again with the ties in.

The bundled search façade (``examples/scenes/search_facade.3dm``, its search spec, the NTC
site): the retrofit designs the ties of the failing wedges of the façade F, the ties go into
the scene as tie-bar lines at the top of F, and the search runs again. The references:

* the rerun's λ0 of every tied mechanism (the search's refinement and the constants builder,
  reading the tie-bar line from the scene) against the retrofit's own closed form for a
  constant tie on those constants (``with_tie``: [C8.7.1.1], α0 gains T h_t/(g S)), to 1e-9;
* the mechanisms of the side walls L and R, which the ties do not touch, keep their λ0;
* the governing mechanism after is the least margin of the rerun's mechanisms, and every
  tied mechanism passes (it carries at least its own T*).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from search.search_scenes import EXAMPLE_SCENE, EXAMPLE_SPEC
from typer.testing import CliRunner

from cad_maths.scenes import read_scene
from shared_schema.retrofit import parse_retrofit_spec
from solver_service.cli import app
from solver_service.workflows.assess import read_site
from solver_service.workflows.retrofit import with_tie
from solver_service.workflows.retrofit_files import retrofit_json
from solver_service.workflows.retrofit_scene import retrofit_search
from solver_service.workflows.search import read_search_spec

SITE = EXAMPLE_SPEC.parent.parent / "sites" / "ntc_site.json"
RSPEC = {
    "steel": {"grade": "S275", "diameters_mm": [16, 20, 24]},
    "anchorage": {"capacity_N": 60000.0, "source": "plate punching, designer's calculation"},
}


def _lighter() -> Any:
    """The example's search spec, lighter: the ranking's band does not enter the retrofit."""
    spec = read_search_spec(EXAMPLE_SPEC)
    lighter = spec.ranking.model_copy(update={"n_frequencies": 40})
    return spec.model_copy(update={"lp": False, "ranking": lighter})


@pytest.fixture(scope="module")
def run() -> Any:
    spec = _lighter()
    return retrofit_search(
        read_scene(EXAMPLE_SCENE),
        spec,
        read_site(SITE),
        parse_retrofit_spec(RSPEC),
        scene_name=EXAMPLE_SCENE.name,
    )


def test_designed_ties_go_to_the_top_of_the_facade_as_one_line(run: Any) -> None:
    doc = run.doc
    designed = [m for m in doc.mechanisms if m.status == "designed"]
    assert designed, "the example has failing wedges of F"
    sa = doc.search_after
    assert sa is not None and run.after is not None
    bld = run.before.result.building
    forces = [m.options[m.chosen].T_star_N for m in designed]
    for tie in sa.ties:
        assert tie.status == "placed" and tie.wall == "F"
        f = bld.walls["F"].frame
        s, n, z = f.to_frame(np.asarray(tie.at_m))
        assert n == pytest.approx(0.0, abs=1e-9)
        assert s == pytest.approx(bld.walls["F"].length / 2.0, rel=1e-9)  # the axis' middle
        assert z == pytest.approx(bld.walls["F"].z_hi, abs=1e-9)  # the scene's default height
        assert f.to_frame(np.asarray(tie.end_m))[1] == pytest.approx(f.thickness, abs=1e-9)
        # one point: one line carrying the largest designed force
        assert tie.force_N == pytest.approx(max(forces), rel=1e-12)
        m = doc.find(tie.mechanism)
        assert m.options[m.chosen].height_source.startswith("default from the scene")
    assert len({t.object for t in sa.ties}) == 1


def test_rerun_lambda0_of_tied_mechanisms_is_the_closed_form(run: Any) -> None:
    sa = run.doc.search_after
    tie = sa.ties[0]
    before = {m.name: m for m in run.before.constants.mechanisms}
    z_tie = tie.at_m[2]
    checked = untouched = 0
    for row in sa.rows:
        mech = before.get(row.name)
        if mech is None:
            continue  # the refinement moved (another crack or hinge): no twin to compare
        if row.ties:
            h_t = z_tie - mech.geometry["positive"]["axis_point_m"][2]
            assert h_t > 0.0
            tied = with_tie(mech, tie.force_N, h_t, listed=False)
            want = tied.positive.virtual_work.alpha0
            assert row.lam0 == pytest.approx(want, rel=1e-9)
            assert row.lam0 > mech.positive.virtual_work.alpha0
            checked += 1
        else:
            assert row.facade in ("L", "R")
            assert row.lam0 == pytest.approx(mech.positive.virtual_work.alpha0, rel=1e-12)
            untouched += 1
    assert checked >= 3 and untouched == 2


def test_governing_after_is_the_least_margin_and_every_tied_one_passes(run: Any) -> None:
    doc = run.doc
    sa = doc.search_after
    margins = [(r.margin, r.id) for r in sa.rows if r.margin is not None]
    least = min(margins)
    assert (sa.after_margin, sa.after) == least
    row = next(r for r in sa.rows if r.id == sa.after)
    assert sa.after_lam0 == row.lam0 and sa.after_facade == row.facade
    assert sa.least_lam0_value == min(r.lam0 for r in sa.rows)
    # before: the least code-check margin of the first search, as governs_next has it
    assert sa.before == doc.governs_next.before
    assert sa.before_margin == pytest.approx(doc.governs_next.before_margin, rel=1e-12)
    assert sa.before_margin < 1.0 <= sa.after_margin
    designed = {m.name for m in doc.mechanisms if m.status == "designed"}
    for r in sa.rows:
        if r.name in designed:
            assert r.margin is not None and r.margin >= 1.0 - 1e-9, r.id
    assert sa.moved is (sa.after_name != sa.before_name)
    assert all(math.isfinite(r.lam0) for r in sa.rows)


def test_document_carries_search_after_and_a_plain_retrofit_does_not(run: Any) -> None:
    text = retrofit_json(run.doc)
    assert '"search_after": {' in text
    plain = run.doc.model_copy(update={"search_after": None})
    assert "search_after" not in retrofit_json(plain)


def test_cli_retrofit_from_a_scene_writes_the_same_document(run: Any, tmp_path: Path) -> None:
    spec = tmp_path / "light.search.json"
    spec.write_text(_lighter().model_dump_json(exclude_none=True), encoding="utf-8")
    rspec = tmp_path / "ties.retrofit.json"
    rspec.write_text(json.dumps(RSPEC), encoding="utf-8")
    args = ["--site", str(SITE), "--spec", str(rspec)]
    scene = ["--scene", str(EXAMPLE_SCENE), "--search-spec", str(spec)]
    res = CliRunner().invoke(app, ["retrofit", *scene, *args, "--json"])
    assert res.exit_code == 0, res.output
    got = json.loads(res.stdout)
    want = json.loads(retrofit_json(run.doc))
    assert got["search_after"] == want["search_after"]
    assert got["mechanisms"] == want["mechanisms"]
    # refusals: one line naming the field, exit 2, no traceback
    for extra, field in (
        (["--scene", str(EXAMPLE_SCENE)], "search_spec"),
        (
            [str(EXAMPLE_SCENE.parent.parent / "constants" / "church_geometry.json"), *scene],
            "constants",
        ),
        ([], "constants"),
    ):
        res = CliRunner().invoke(app, ["retrofit", *extra, *args])
        assert res.exit_code == 2 and "Traceback" not in res.output, res.output
        assert f"error: {field}:" in res.output


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_cli_retrofit_from_a_search_run_folder(run: Any, tmp_path: Path) -> None:
    spec = tmp_path / "light.search.json"
    doc = json.loads(_lighter().model_dump_json(exclude_none=True))
    doc["ranking"].update(site=str(SITE), records=[])  # the search's own ranking, from here
    spec.write_text(json.dumps(doc), encoding="utf-8")
    rspec = tmp_path / "ties.retrofit.json"
    rspec.write_text(json.dumps(RSPEC), encoding="utf-8")
    folder = tmp_path / "run"
    res = CliRunner().invoke(app, ["search", str(EXAMPLE_SCENE), str(spec), "--out", str(folder)])
    assert res.exit_code == 0, res.output
    args = ["--site", str(SITE), "--spec", str(rspec), "--json"]
    res = CliRunner().invoke(
        app, ["retrofit", "--scene", str(folder), "--search-spec", str(spec), *args]
    )
    assert res.exit_code == 0, res.output
    got = json.loads(res.stdout)
    assert got["search_after"] == json.loads(retrofit_json(run.doc))["search_after"]
    # another search spec (a denser façade) does not rebuild the run: refused, naming it
    other = json.loads(spec.read_text(encoding="utf-8"))
    other["walls"][0]["density"] = 1900.0
    spec.write_text(json.dumps(other), encoding="utf-8")
    res = CliRunner().invoke(
        app, ["retrofit", "--scene", str(folder), "--search-spec", str(spec), *args]
    )
    assert res.exit_code == 2 and "error: search_spec:" in res.output, res.output


def test_a_tie_above_the_moving_part_is_refused_there_and_its_mechanism_still_governs() -> None:
    # S10 (hinge at z = 7 m): the scene's wall ends 3.5 m above its hinge (the builder's
    # top_m); a tie asked for at 3.7 m meets no block that moves: refused, said, not placed
    high = {**RSPEC, "mechanisms": {"S10": {"heights_m": [3.7]}}}
    got = retrofit_search(
        read_scene(EXAMPLE_SCENE), _lighter(), read_site(SITE), parse_retrofit_spec(high)
    )
    m = got.doc.find("S10")
    assert m.status == "not_achievable"
    (opt,) = m.options
    assert opt.status == "above_moving_part"
    assert "its top is 3.5 m above the hinge" in opt.decisions[0]
    sa = got.doc.search_after
    by = {t.mechanism: t for t in sa.ties}
    assert "S10" not in by
    assert by["S11"].status == "placed" and by["S13"].status == "placed"
    # the rerun: S10, untied, governs, failing
    s10 = m.name
    row = next(r for r in sa.rows if r.name == s10)
    assert row.margin is not None and row.margin < 1.0
    assert sa.after_name == s10 and sa.after_margin == row.margin and not sa.moved
