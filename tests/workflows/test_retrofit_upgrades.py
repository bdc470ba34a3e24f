"""Connection upgrades of a retrofit from a scene (#39: "connection upgrades are compared the
same way"), and the records run on the reruns' mechanisms.

The bundled search façade (``examples/scenes/search_facade.3dm``), its search spec with the
junction of the façade F and its return wall L made poor (F detaches from L), the NTC site
and El Centro. The retrofit spec upgrades the junction F-L to tied and the level floor_2 to
tied; ``rockmech retrofit --scene`` searches again with each. The references:

* the search run directly on the search spec edited by hand (the junction written
  ``tied``, the level ``tied: true``), its mechanisms checked as the first search's are
  (``rockmech.retrofit`` on its constants: the Circolare 2019 checks with the records'
  demand and the records' least overturning scale over the design scale, ``governs_next``'s
  margins): the same mechanisms, the same governing one, its λ0 to 1e-12 and every margin;
* a tied junction holds both walls it joins (theory: a tied return wall holds the façade),
  so no mechanism of F or L is left; a tied level holds the walls at its height, so no
  moving part reaches below it;
* the order of the upgrades changes nothing.
"""

from __future__ import annotations

import html
import json
import re
from pathlib import Path
from typing import Any

import pytest
from search.search_scenes import EXAMPLE_SCENE, EXAMPLE_SPEC
from typer.testing import CliRunner

import rockmech
from cad_maths.scenes import read_scene
from shared_schema.errors import InputError
from shared_schema.retrofit import parse_retrofit_spec
from shared_schema.search import SearchSpec
from solver_service.cli import app
from solver_service.workflows.assess import read_site
from solver_service.workflows.retrofit_records import read_retrofit_records
from solver_service.workflows.retrofit_scene import retrofit_search
from solver_service.workflows.search import read_search_spec, search_run

runner = CliRunner()
EXAMPLES = EXAMPLE_SPEC.parent.parent
SITE = EXAMPLES / "sites" / "ntc_site.json"
ELCENTRO = EXAMPLES / "records" / "elcentro_NS.dat"
CHURCH = EXAMPLES / "constants" / "church_geometry.json"
STEEL = {
    "steel": {"grade": "S275", "diameters_mm": [16, 20, 24]},
    "anchorage": {"capacity_N": 60000.0, "source": "plate punching, designer's calculation"},
}
UPGRADES = [{"walls": ["F", "L"], "to": "tied"}, {"level": "floor_2", "tied": True}]


def _search_doc(**edit: Any) -> dict[str, Any]:
    """The example's search spec as data, lighter, F-L poor; ``edit`` replaces keys."""
    spec = read_search_spec(EXAMPLE_SPEC)
    doc: dict[str, Any] = json.loads(spec.model_dump_json(exclude_none=True))
    doc["lp"] = False
    doc["ranking"].update(n_frequencies=40, site=str(SITE), records=[])
    doc["junctions"] = [{"walls": ["F", "L"], "connection": "poor"}]
    doc.update(edit)
    return doc


def _files(folder: Path, upgrades: list[dict[str, Any]], search: Any = None) -> list[str]:
    """Write the search spec and the retrofit spec; return the command's file arguments."""
    spec = folder / "poor.search.json"
    spec.write_text(json.dumps(search or _search_doc()), encoding="utf-8")
    rspec = folder / "upgrades.retrofit.json"
    rspec.write_text(json.dumps({**STEEL, "upgrades": upgrades}), encoding="utf-8")
    return [
        "--scene", str(EXAMPLE_SCENE), "--search-spec", str(spec),
        "--site", str(SITE), "--spec", str(rspec),
    ]  # fmt: skip


@pytest.fixture(scope="module")
def doc(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    folder = tmp_path_factory.mktemp("upgrades")
    args = _files(folder, UPGRADES)
    out = folder / "out"
    res = runner.invoke(app, ["retrofit", *args, "--record", str(ELCENTRO), "--out", str(out)])
    assert res.exit_code == 0, res.output
    got: dict[str, Any] = json.loads((out / "retrofit.json").read_text(encoding="utf-8"))
    # the table names each upgrade's governing mechanism
    up = got["search_after"]["upgrades"][0]
    assert (
        f"search again with junction F-L: poor -> tied: {up['after']} governs, margin "
        f"{up['after_margin']:.3f} ({up['after_criterion']})" in res.stdout
    ), res.stdout
    return got


def _by_hand(doc: dict[str, Any], folder: Path) -> tuple[Any, Any]:
    """The search on a hand-edited spec and its first-run checks (``rockmech.retrofit``)."""
    run = search_run(read_scene(EXAMPLE_SCENE), doc, site=read_site(SITE), motions=[])
    assert run.constants is not None
    (folder / "c.json").write_text(run.constants.model_dump_json(), encoding="utf-8")
    (folder / "r.json").write_text(json.dumps(STEEL), encoding="utf-8")
    checked = rockmech.retrofit(folder / "c.json", SITE, folder / "r.json", records=[ELCENTRO])
    return run, checked


def _same_as_by_hand(after: dict[str, Any], run: Any, checked: Any) -> None:
    """The rerun's rows are the hand-edited search's mechanisms, margins as the first run's."""
    rows = after["rows"]
    assert [r["name"] for r in rows] == [m.name for m in run.constants.mechanisms]
    lam0 = {d.id: d.lam0 for d in run.doc.candidates}
    margins = {r.id: r for r in checked.governs_next.rows}
    for row in rows:
        assert row["lam0"] == pytest.approx(lam0[row["id"]], rel=1e-12)
        m = margins[row["id"]]
        assert row["margin"] == pytest.approx(m.before_margin, rel=1e-12)
        assert row["criterion"] == m.before_criterion
        # the records ran on the rerun's mechanism: the first run's scales, to 1e-12
        want = checked.find(row["id"]).records_before
        assert [r["record"] for r in row["records"]] == [r.record for r in want] == ["elcentro_NS"]
        for got, ref in zip(row["records"], want):
            assert ref.overturning_scale is not None
            assert got["overturning_scale"] == pytest.approx(ref.overturning_scale, rel=1e-12)
            assert got["design_scale"] == pytest.approx(ref.design_scale, rel=1e-12)
    gov = checked.governs_next.before
    assert after["after"] == gov
    assert after["after_name"] == checked.find(gov).name
    assert after["after_lam0"] == pytest.approx(lam0[gov], rel=1e-12)
    assert after["after_margin"] == pytest.approx(checked.governs_next.before_margin, rel=1e-12)


def test_a_poor_junction_tied_removes_the_mechanisms_that_detach_there(
    doc: dict[str, Any], tmp_path: Path
) -> None:
    first = [m["name"] for m in doc["mechanisms"]]
    assert any(" of F " in n for n in first) and any(" of L " in n for n in first)
    up = doc["search_after"]["upgrades"][0]
    assert up["upgrades"] == ["junction F-L: poor -> tied"] and up["indices"] == [0]
    assert not up["with_ties"]
    assert up["rows"], "the side wall R is left"
    assert all(r["facade"] not in ("F", "L") for r in up["rows"])
    assert up["moved"] is True  # the first search's governing wedge of F is gone
    hand = _search_doc(junctions=[{"walls": ["F", "L"], "connection": "tied"}])
    _same_as_by_hand(up, *_by_hand(hand, tmp_path))


def test_a_level_tied_removes_the_mechanisms_that_cross_it(
    doc: dict[str, Any], tmp_path: Path
) -> None:
    up = doc["search_after"]["upgrades"][1]
    assert up["upgrades"] == ["level floor_2: tied"] and up["indices"] == [1]
    hand = _search_doc()
    hand["levels"][1]["tied"] = True
    run, checked = _by_hand(hand, tmp_path)
    _same_as_by_hand(up, run, checked)
    # every moving part of the rerun starts at or above floor_2, which now holds the walls
    bld = run.result.building
    z_floor = min(c.point[2] for cs in bld.contacts.values() for c in cs if c.level.id == "floor_2")
    assert len(up["rows"]) < len(doc["mechanisms"])
    for mech in run.constants.mechanisms:
        assert mech.geometry["positive"]["axis_point_m"][2] >= z_floor - 1e-9, mech.name


def test_every_upgrade_with_the_ties_and_the_records_on_the_ties_rerun(
    doc: dict[str, Any],
) -> None:
    sa = doc["search_after"]
    both = sa["together"]
    assert both["with_ties"] and both["indices"] == [0, 1]
    assert both["upgrades"] == ["junction F-L: poor -> tied", "level floor_2: tied"]
    # F-L tied holds F and L; floor_2 tied holds R at its height: R above it may remain
    assert all(r["facade"] == "R" for r in both["rows"])
    # the ties' rerun: every mechanism ran on the record, and its margin counts it
    nxt = doc["governs_next"]
    assert sa["before"] == nxt["before"]
    assert sa["before_margin"] == pytest.approx(nxt["before_margin"], rel=1e-12)
    assert sa["rows"]
    for row in sa["rows"]:
        assert [r["record"] for r in row["records"]] == ["elcentro_NS"]
        multiples = [r["multiple"] for r in row["records"] if r["multiple"] is not None]
        assert multiples and row["margin"] <= min(multiples) + 1e-12
        if row["criterion"].startswith("record"):
            assert row["margin"] == min(multiples)
    least = min(sa["rows"], key=lambda r: r["margin"])
    assert (sa["after"], sa["after_margin"]) == (least["id"], least["margin"])
    assert "records are not run" not in " ".join(sa["basis"])


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_the_order_of_the_upgrades_changes_nothing(doc: dict[str, Any]) -> None:
    rspec = parse_retrofit_spec({**STEEL, "upgrades": UPGRADES[::-1], "records": [str(ELCENTRO)]})
    got = retrofit_search(
        read_scene(EXAMPLE_SCENE),
        SearchSpec.model_validate(_search_doc()),
        read_site(SITE),
        rspec,
        read_retrofit_records(rspec, None),
    ).doc.search_after
    assert got is not None
    want = doc["search_after"]
    flipped = [u.model_dump(mode="json") for u in got.upgrades[::-1]]
    for mine, theirs in zip(flipped, want["upgrades"]):
        assert mine["indices"] != theirs["indices"]
        mine["indices"] = theirs["indices"]
        assert mine == theirs
    together = got.together.model_dump(mode="json") if got.together is not None else {}
    assert together["upgrades"] == want["together"]["upgrades"][::-1]
    for key in ("after", "after_margin", "after_lam0", "rows", "moved"):
        assert together[key] == want["together"][key]
    assert got.model_dump(mode="json")["rows"] == want["rows"]


def _refusal(args: list[str]) -> str:
    res = runner.invoke(app, ["retrofit", *args])
    assert res.exit_code == 2 and "Traceback" not in res.output, res.output
    return str(res.output)


@pytest.mark.parametrize(
    ("upgrades", "field", "words"),
    [
        ([{"walls": ["F", "X"], "to": "tied"}], "upgrades[0].walls", "no wall 'X'"),
        ([UPGRADES[0], {"walls": ["F", "B"], "to": "tied"}], "upgrades[1].walls", "do not meet"),
        ([{"level": "attic", "tied": True}], "upgrades[0].level", "no level 'attic'"),
        ([{"walls": ["F", "L"], "to": "poor"}], "upgrades[0].to", "'good' or 'tied'"),
        ([{"walls": ["F", "R"], "to": "good", "unit": {"length": 0.3, "height": 0.2}}],
         "upgrades[0].to", "already good"),
        ([UPGRADES[0], {"walls": ["L", "F"], "to": "tied"}], "upgrades[1].walls", "the same"),
        ([{"walls": ["F", "L"], "to": "good"}], "upgrades[0]", "'unit'"),
        ([{"walls": ["F", "L"]}], "upgrades[0]", "needs 'to'"),
        ([{"level": "floor_1", "tied": False}], "upgrades[0]", "'tied': true"),
        ([{"level": "floor_1", "walls": ["F", "L"], "to": "tied"}], "upgrades[0]", "either"),
    ],
)  # fmt: skip
def test_bad_upgrades_are_refused_naming_the_field(
    upgrades: list[dict[str, Any]], field: str, words: str, tmp_path: Path
) -> None:
    out = _refusal(_files(tmp_path, upgrades))
    assert f"error: {field}" in out and words in out, out


def test_no_change_and_a_missing_junction_are_refused(tmp_path: Path) -> None:
    tied = _search_doc(junctions=[{"walls": ["F", "L"], "connection": "tied"}])
    out = _refusal(_files(tmp_path, [UPGRADES[0]], tied))
    assert "error: upgrades[0].to:" in out and "already tied" in out, out
    tied["levels"][1]["tied"] = True
    out = _refusal(_files(tmp_path, [UPGRADES[1]], tied))
    assert "error: upgrades[0].tied:" in out and "already tied" in out, out
    # tied -> good weakens
    good = {"walls": ["F", "L"], "to": "good", "unit": {"length": 0.3, "height": 0.2}}
    out = _refusal(_files(tmp_path, [good], _search_doc(junctions=tied["junctions"])))
    assert "error: upgrades[0].to:" in out and "weaker" in out, out
    # without a default_junction, a junction the spec does not list has no connection
    listed = _search_doc()
    del listed["default_junction"]
    out = _refusal(_files(tmp_path, [{"walls": ["R", "B"], "to": "tied"}], listed))
    assert "error: upgrades[0].walls:" in out and "no junction R-B" in out, out


def test_a_retrofit_from_constants_refuses_upgrades(tmp_path: Path) -> None:
    args = _files(tmp_path, UPGRADES)
    out = _refusal([str(CHURCH), *args[4:]])
    assert "error: upgrades:" in out and "--scene" in out, out
    spec = parse_retrofit_spec({**STEEL, "upgrades": UPGRADES})
    with pytest.raises(InputError, match="--scene") as err:
        rockmech.retrofit(CHURCH, SITE, spec)
    assert err.value.field == "upgrades"


def test_the_work_estimate_counts_a_search_again_per_upgrade() -> None:
    from solver_service.workflows.limits import (
        check_retrofit_work,
        retrofit_checks,
        retrofit_reruns,
        shortest_time,
    )

    cf, site = rockmech.read_constants(CHURCH), read_site(SITE)
    spec = parse_retrofit_spec({**STEEL, "upgrades": UPGRADES})
    # the ties' search, one per upgrade, one with them all
    assert retrofit_reruns(spec) == 1 + 2 + 1
    alone = retrofit_checks(cf, site, spec)
    budget = shortest_time(retrofit_checks=alone)
    check_retrofit_work(cf, site, spec, budget, "more time")
    with pytest.raises(InputError, match="4 searches again") as err:
        check_retrofit_work(cf, site, spec, budget, "more time", reruns=retrofit_reruns(spec))
    assert f"plans {alone + 4 * len(cf.mechanisms)} code checks" in str(err.value)


@pytest.mark.slow  # the quick loop's budget: a search, a retrofit and a report
def test_page_one_of_the_report_has_a_row_per_upgrade(tmp_path: Path) -> None:
    pytest.importorskip("jinja2")
    # three mechanisms built: the report draws fewer figures
    few = _search_doc()
    few["candidates"] = {**few.get("candidates", {}), "keep": 3}
    args = _files(tmp_path, UPGRADES, few)
    folder = tmp_path / "run"
    res = runner.invoke(app, ["search", str(EXAMPLE_SCENE), args[3], "--out", str(folder)])
    assert res.exit_code == 0, res.output
    res = runner.invoke(app, ["retrofit", "--scene", str(folder), *args[2:], "--out", str(folder)])
    assert res.exit_code == 0, res.output
    rdoc = json.loads((folder / "retrofit.json").read_text(encoding="utf-8"))
    report = tmp_path / "report.html"
    res = runner.invoke(
        app,
        ["assess", str(folder / "constants.json"), str(SITE), "-o", str(report),
         "--retrofit", str(folder / "retrofit.json")],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    page = report.read_text(encoding="utf-8")
    one = page[page.index('id="summary">') :]
    body = one.split('<table id="retrofit-table">', 1)[1].split("</table>", 1)[0]
    rows = dict(re.findall(r'<tr data-upgrade="([^"]+)"[^>]*>(.*?)</tr>', body, re.S))
    assert list(rows) == ["0", "1", "together"]
    sa = rdoc["search_after"]
    for key, u in [("0", sa["upgrades"][0]), ("1", sa["upgrades"][1])]:
        text = html.unescape(re.sub(r"<[^>]+>", " ", rows[key]))
        assert u["upgrades"][0].replace("->", "→") in text
        assert f"{u['after']} governs (λ0 {u['after_lam0']:.3g})" in text
        assert f"→ {u['after_margin']:.3g}" in text
    assert "no mechanism is left" in html.unescape(rows["together"])
    # after the mechanisms' rows, which stay one per mechanism
    assert body.index('data-upgrade="0"') > body.rindex("data-mechanism=")
