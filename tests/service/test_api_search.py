"""``POST /api/v1/search`` on the real server: the command line's document (issue #31)."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from typing import Any

import httpx
import pytest
from api_helpers import cli_json

from shared_schema.documents.search import SearchDocument

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
# The search tests' scene helpers (tests/search is not a package).
_loader = importlib.util.spec_from_file_location(
    "search_scenes_service", ROOT / "tests" / "search" / "search_scenes.py"
)
assert _loader is not None and _loader.loader is not None
SCENES: Any = importlib.util.module_from_spec(_loader)
_loader.loader.exec_module(SCENES)
EXAMPLE_SCENE, EXAMPLE_SPEC = SCENES.EXAMPLE_SCENE, SCENES.EXAMPLE_SPEC
wedge_facade, wedge_spec = SCENES.wedge_facade, SCENES.wedge_spec


def _files(scene: Path, spec: Path, **extra: Path) -> dict[str, tuple[str, bytes, str]]:
    files = {
        "scene": (scene.name, scene.read_bytes(), "application/octet-stream"),
        "spec": (spec.name, spec.read_bytes(), "application/json"),
    }
    for name, path in extra.items():
        files[name] = (path.name, path.read_bytes(), "application/octet-stream")
    return files


def _without_timings(doc: dict[str, object]) -> dict[str, object]:
    return {k: v for k, v in doc.items() if k != "timings"}


def test_search_answers_the_command_lines_document(client: httpx.Client, tmp_path: Path) -> None:
    scene = wedge_facade(tmp_path, windows=[(1.5, 2.7, 1.0, 3.0)])
    spec = tmp_path / "search.json"
    spec.write_text(json.dumps(wedge_spec("good", (0.25, 0.12))))
    cli = cli_json("search", str(scene), str(spec), "-o", str(tmp_path / "out"), "--no-figure")
    res = client.post("/api/v1/search", files=_files(scene, spec))
    assert res.status_code == 200, res.text
    assert _without_timings(res.json()) == _without_timings(cli)


def test_search_with_an_uploaded_site_and_record(client: httpx.Client, tmp_path: Path) -> None:
    doc = json.loads(EXAMPLE_SPEC.read_text())
    doc["ranking"] = {"keep": 3, "n_frequencies": 50}
    spec = tmp_path / "search.json"
    spec.write_text(json.dumps(doc))
    site = EXAMPLES / "sites" / "ntc_site.json"
    record = EXAMPLES / "records" / "elcentro_NS.dat"
    res = client.post(
        "/api/v1/search",
        files=_files(EXAMPLE_SCENE, spec, site=site, record=record),
        data={"record_units": "g", "max_evaluations": "50000"},
    )
    assert res.status_code == 200, res.text
    # the route's declared document (extra="forbid") takes the answer and gives it back
    # byte for byte
    out = SearchDocument.model_validate(res.json())
    assert json.dumps(out.to_dict()) == json.dumps(res.json())
    for mid in out.rankings.dynamic[:3]:
        cand = out.find(mid)
        assert cand.records is not None and cand.records[0].record == "elcentro_NS"
        assert cand.code_check is not None
        assert cand.code_check.alpha0 == pytest.approx(cand.lam0, rel=1e-9)
    # the service's max_mechanisms (20 on the test server) cuts the built list, and says so
    assert len(out.rankings.dynamic) <= 20


def test_search_declares_its_document_as_the_response_model() -> None:
    from fastapi.routing import APIRoute

    from solver_service.api.routes import search

    (route,) = [r for r in search.router.routes if isinstance(r, APIRoute)]
    assert route.response_model is SearchDocument


@pytest.mark.parametrize(
    ("edit", "data", "field"),
    [
        ({"ranking": {"site": "site.json"}}, {}, "ranking"),
        ({}, {"max_evaluations": "5"}, "work_limit"),
        ({"walls": [{"id": "F", "object": "nope", "density": 1800}]}, {}, "walls[0].object"),
        ({}, {"max_evaluations": "0"}, "max_evaluations"),
    ],
)
def test_search_refuses_with_422_naming_the_field(
    client: httpx.Client, tmp_path: Path, edit: dict[str, object], data: dict[str, str], field: str
) -> None:
    scene = wedge_facade(tmp_path)
    spec = tmp_path / "search.json"
    spec.write_text(json.dumps({**wedge_spec("good", (0.25, 0.12)), **edit}))
    res = client.post("/api/v1/search", files=_files(scene, spec), data=data)
    assert res.status_code == 422, res.text
    assert field in res.json()["detail"] or res.json().get("field") == field


def test_search_refuses_a_broken_3dm(client: httpx.Client, tmp_path: Path) -> None:
    scene = tmp_path / "broken.3dm"
    scene.write_bytes(b"3D Geometry File Format        8" + b"\x00" * 40)
    spec = tmp_path / "search.json"
    spec.write_text(json.dumps(wedge_spec("poor", None)))
    res = client.post("/api/v1/search", files=_files(scene, spec))
    assert res.status_code == 422, res.text
