"""``POST /api/v1/retrofit`` with a scene (multipart), against ``rockmech retrofit --scene`` (#39).

The bundled search façade (``examples/scenes/search_facade.3dm``, its search spec, the NTC
site) uploaded to the real server: the answer must be the bytes of the ``retrofit.json`` the
command line writes for the same files (the document has no timings or stamps), not close
numbers. The tie put in the scene is checked by hand: one line at the top of the façade F
carrying the largest designed force. The work limit counts the search's estimate once per
search (the scene, the scene with the ties, and per connection upgrade) and refuses before
any search runs; bad input is a
422 naming the request's field, an oversized upload a 413, never a 5xx.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import httpx
import pytest
from api_helpers import EXAMPLES, runner
from servers import TEST_SETTINGS

from solver_service.cli import app

SCENE = EXAMPLES / "scenes" / "search_facade.3dm"
SEARCH = EXAMPLES / "specs" / "search_facade.search.json"
SITE = EXAMPLES / "sites" / "ntc_site.json"
RSPEC = {
    "steel": {"grade": "S275", "diameters_mm": [16, 20, 24]},
    "anchorage": {"capacity_N": 60000.0, "source": "plate punching, designer's calculation"},
}
URL = "/api/v1/retrofit"


def _files(rspec: dict[str, Any], scene: bytes | None = None) -> dict[str, Any]:
    return {
        "scene": (SCENE.name, SCENE.read_bytes() if scene is None else scene),
        "search_spec": (SEARCH.name, SEARCH.read_bytes(), "application/json"),
        "site": (SITE.name, SITE.read_bytes(), "application/json"),
        "spec": ("ties.retrofit.json", json.dumps(rspec).encode(), "application/json"),
    }


@pytest.fixture(scope="module")
def cli_doc(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    """The ``retrofit.json`` of ``rockmech retrofit --scene`` on the same files."""
    folder = tmp_path_factory.mktemp("retrofit_scene")
    rspec = folder / "ties.retrofit.json"
    rspec.write_text(json.dumps(RSPEC), encoding="utf-8")
    args = ["retrofit", "--scene", str(SCENE), "--search-spec", str(SEARCH), "--site",
            str(SITE), "--spec", str(rspec), "-o", str(folder / "out")]  # fmt: skip
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    return (folder / "out" / "retrofit.json").read_bytes()


def test_a_scene_upload_answers_the_clis_retrofit_json_byte_for_byte(
    client: httpx.Client, cli_doc: bytes
) -> None:
    res = client.post(URL, files=_files(RSPEC))
    assert res.status_code == 200, res.text
    assert res.headers["content-type"].startswith("application/json")
    assert res.content == cli_doc
    doc = res.json()
    designed = [m for m in doc["mechanisms"] if m["status"] == "designed"]
    assert designed, "the example has failing wedges of the façade F"
    sa = doc["search_after"]
    # By hand: the designed ties meet at the top of F (the scene's default height, z = 10.5 m
    # for the example's 10.5 m façade), one line carrying the largest of their forces.
    forces = [m["options"][m["chosen"]]["T_star_N"] for m in designed]
    assert {t["status"] for t in sa["ties"]} == {"placed"}
    assert {t["wall"] for t in sa["ties"]} == {"F"} and len({t["object"] for t in sa["ties"]}) == 1
    for tie in sa["ties"]:
        assert tie["force_N"] == pytest.approx(max(forces), rel=1e-12)
        assert tie["at_m"][2] == pytest.approx(10.5, abs=1e-9)
    # the rerun's governing mechanism is its least margin, and it passes
    margins = [r["margin"] for r in sa["rows"] if r["margin"] is not None]
    assert sa["after_margin"] == min(margins) and sa["after_margin"] >= 1.0 - 1e-9


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_with_a_record_it_is_the_clis_retrofit_record(client: httpx.Client, tmp_path: Path) -> None:
    # The first 8 s of El Centro NS (two columns, t [s] and a [g]): each tied mechanism must
    # survive it at the design scale, as rockmech retrofit --record runs it.
    lines = (EXAMPLES / "records" / "elcentro_NS.dat").read_text().splitlines()[:400]
    record = tmp_path / "elcentro_8s.dat"
    record.write_text("\n".join(lines) + "\n")
    rspec = tmp_path / "ties.retrofit.json"
    rspec.write_text(json.dumps(RSPEC), encoding="utf-8")
    args = ["retrofit", "--scene", str(SCENE), "--search-spec", str(SEARCH), "--site",
            str(SITE), "--spec", str(rspec), "--record", str(record),
            "-o", str(tmp_path)]  # fmt: skip
    cli = runner.invoke(app, args)
    assert cli.exit_code == 0, cli.output
    files = {**_files(RSPEC), "record": (record.name, record.read_bytes())}
    res = client.post(URL, files=files, data={"record_units": "g"})
    assert res.status_code == 200, res.text
    assert res.content == (tmp_path / "retrofit.json").read_bytes()
    doc = res.json()
    assert [r["name"] for r in doc["records"]] == ["elcentro_8s"]


def _refusal(client: httpx.Client, url: str, files: Any, limit: int) -> str | None:
    """The up-front work refusal's message at ``limit``, or None (the work was started)."""
    res = client.post(url, files=files, data={"max_evaluations": str(limit)})
    assert res.status_code in (200, 422), res.text
    body = res.json()
    if res.status_code == 200 or "counted before" not in body.get("detail", ""):
        return None
    assert body["field"] == "work_limit", body
    return str(body["detail"])


def test_the_work_limit_counts_the_search_twice_before_any_runs(client: httpx.Client) -> None:
    # The one search's count N, complete (not "at least"): raise the limit until it is.
    limit, n = 100, 0
    for _ in range(10):
        detail = _refusal(client, URL, _files(RSPEC), limit)
        assert detail is not None and "before any search ran" in detail
        got = re.search(r"needing (at least )?(\d+) evaluations", detail)
        assert got is not None, detail
        n = int(got.group(2))
        if not got.group(1):
            break
        assert f"at least {2 * n} in all" in detail
        limit = 2 * n
    else:
        pytest.fail("the count stayed a lower bound")
    # 2 N in all: refused just under it, started at it
    detail = _refusal(client, URL, _files(RSPEC), 2 * n - 1)
    assert (
        detail is not None and f"{2 * n} in all, more than the work limit's {2 * n - 1}" in detail
    )
    assert _refusal(client, URL, _files(RSPEC), 2 * n) is None
    # the search route counts the same N for one search: refused up front at N - 1, not at N
    search = {"scene": _files(RSPEC)["scene"], "spec": (SEARCH.name, _without_paths(SEARCH))}
    one = _refusal(client, "/api/v1/search", search, n - 1)
    assert one is not None and f"needs at least {n} evaluations" in one
    assert _refusal(client, "/api/v1/search", search, n) is None


def _without_paths(spec: Path) -> bytes:
    """The search spec without its ranking's file paths (the search route refuses them)."""
    doc = json.loads(spec.read_text(encoding="utf-8"))
    for key in ("site", "records"):
        doc["ranking"].pop(key, None)
    return json.dumps(doc).encode()


@pytest.mark.parametrize(
    ("edit", "field", "words"),
    [
        ({"mechanisms": {"F9": {}}}, "spec.mechanisms.F9", "no mechanism 'F9'"),
        ({"anchorage": {"capacity_N": 60000.0}}, "spec.anchorage.source", "required"),
        ({"steel": {"grade": "S460", "diameters_mm": [16]}}, "spec.steel.grade", "S235"),
        ({"tie_lines": ["no_such_line"]}, "spec.tie_lines[0]", "no object with name"),
    ],
    ids=["unknown_mechanism", "no_source", "grade", "tie_line"],
)
def test_a_bad_retrofit_spec_is_a_422_naming_the_field(
    client: httpx.Client, edit: dict[str, Any], field: str, words: str
) -> None:
    res = client.post(URL, files=_files({**RSPEC, **edit}))
    assert res.status_code == 422, res.text
    body = res.json()
    assert body["field"] == field and words in body["detail"], body


def test_tie_lines_pass_through_the_scene_route(client: httpx.Client) -> None:
    # The example's line tie_1 crosses F at z = 9 m: by hand, a candidate 9 − 7.0 = 2.0 m
    # above S10's hinge and 9 − 7.9 = 1.1 m above S11's (the wedges of F hinged at 7.0 and
    # 7.9 m fail); S13, hinged at 9.5 m, is noted, not given it.
    res = client.post(URL, files=_files({**RSPEC, "tie_lines": ["tie_1"]}))
    assert res.status_code == 200, res.text
    by = {m["id"]: m for m in res.json()["mechanisms"]}
    for ident, hinge in (("S10", 7.0), ("S11", 7.9)):
        (opt,) = by[ident]["options"]
        assert opt["height_m"] == pytest.approx(9.0 - hinge, abs=1e-9)
        assert "tie line 'tie_1'" in opt["height_source"]
    assert any("'tie_1'" in d and "below the hinge" in d for d in by["S13"]["decisions"])


def test_a_missing_part_names_it(client: httpx.Client) -> None:
    files = _files(RSPEC)
    del files["search_spec"]
    res = client.post(URL, files=files)
    assert res.status_code == 422, res.text
    assert res.json()["field"] == "search_spec" and "file part" in res.json()["detail"]


def test_an_oversized_scene_is_a_413_naming_the_limit(client: httpx.Client) -> None:
    limit = TEST_SETTINGS["max_body_bytes"]
    res = client.post(URL, files=_files(RSPEC, scene=SCENE.read_bytes() + b"\0" * limit))
    assert res.status_code == 413, res.text
    assert str(limit) in res.json()["detail"]


def test_the_work_limit_counts_each_upgrades_search(client: httpx.Client) -> None:
    # One connection upgrade: the scene, with the ties, with the upgrade, with them all: 4 N.
    upgraded = {**RSPEC, "upgrades": [{"walls": ["F", "L"], "to": "tied"}]}
    detail = _refusal(client, URL, _files(upgraded), 100)
    assert detail is not None and "4 times" in detail, detail
    got = re.search(r"needing (at least )?(\d+) evaluations .*: (at least )?(\d+) in all", detail)
    assert got is not None, detail
    assert int(got.group(4)) == 4 * int(got.group(2))
