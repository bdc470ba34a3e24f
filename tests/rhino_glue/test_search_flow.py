"""RM_Search and RM_SearchMechanisms: the flow over a real scene, against ``rockmech search``.

The command's flow runs on the example scene as read by rhino3dm (Rhino's document is the
same objects), writes ``<model>.search/`` and draws the best ranked mechanisms; the
component's function searches named prepared geometry; the service path posts the saved
model and the spec as a multipart form.
"""

import json
import threading
from http.server import BaseHTTPRequestHandler, HTTPServer
from pathlib import Path
from typing import Any, ClassVar, Dict, Iterator, List, Tuple

import pytest

from cad_maths.scenes import read_scene
from rhino_plugin.flows.search import search_flow, search_prepared
from shared_schema.errors import InputError
from shared_schema.search import SearchSpec
from solver_service.workflows.search import read_search_spec, search_run

from .conftest import ScriptedPrompter
from .test_prepared import prepared_from

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "examples" / "scenes" / "search_facade.3dm"
SPEC = ROOT / "examples" / "specs" / "search_facade.search.json"


def _without_timings(doc: Dict[str, Any]) -> Dict[str, Any]:
    return {k: v for k, v in doc.items() if k != "timings"}


@pytest.mark.slow
def test_command_flow_writes_the_search_folder_and_draws_the_best_mechanisms(
    tmp_path: Path,
) -> None:
    scene = read_scene(SCENE)
    ask = ScriptedPrompter(scene, [("get_file", str(SPEC))])
    result = search_flow(ask, scene, str(tmp_path), scene_name=SCENE.name)
    assert result is not None and ask.done()
    out = tmp_path / "search_facade.search"
    assert sorted(p.name for p in out.iterdir()) == [
        ".rockmech",
        "constants.json",
        "search.3dm",
        "search.json",
        "search.png",
        "search.spec.json",
    ]
    assert result.plot == str(out / "search.png")
    reference = _reference().doc
    assert _without_timings(json.loads((out / "search.json").read_text())) == json.loads(
        json.dumps(_without_timings(reference.to_dict()))
    )
    first = result.doc.rankings.dynamic[0]
    assert result.summary[0].startswith(f"{first}: ")
    labels = [m.label for m in result.marks]
    assert f"{first} hinge" in labels and any(lb.startswith(f"{first} crack") for lb in labels)
    assert ask.messages[0] == f"RM_Search: wrote {out}"


def _reference(spec: Any = None) -> Any:
    """``rockmech search``'s run on the example (the command line's workflow)."""
    return search_run(
        read_scene(SCENE),
        read_search_spec(SPEC) if spec is None else spec,
        scene_name=SCENE.name,
        spec_name=SPEC.name,
        spec_dir=SPEC.parent,
    )


def test_component_searches_named_geometry_like_the_command_line(scenes: Any) -> None:
    scene = scenes["search_facade"]
    prepared = prepared_from(scene)
    names = [o.name for o in scene.objects]
    records = [(n, prepared.find(n)[0].kind, prepared.find(n)[0].geometry) for n in names]
    spec = json.loads(SPEC.read_text())
    del spec["ranking"]
    run = search_prepared(records, json.dumps(spec))
    reference = _reference(SearchSpec.model_validate(spec))
    assert [c.lam0 for c in run.doc.candidates] == [c.lam0 for c in reference.doc.candidates]
    assert run.doc.rankings.dynamic == reference.doc.rankings.dynamic


def test_component_refuses_file_paths_in_the_ranking() -> None:
    with pytest.raises(InputError) as err:
        search_prepared([], SPEC.read_text())
    assert err.value.field == "ranking"


class _Recorder(BaseHTTPRequestHandler):
    received: ClassVar[List[Tuple[str, str, bytes]]] = []
    answer: ClassVar[Dict[str, Any]] = {}

    def do_POST(self) -> None:
        body = self.rfile.read(int(self.headers["Content-Length"]))
        type(self).received.append((self.path, self.headers["Content-Type"], body))
        out = json.dumps(type(self).answer).encode()
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(out)))
        self.end_headers()
        self.wfile.write(out)

    def log_message(self, *args: Any) -> None:
        pass


@pytest.fixture()
def service() -> Iterator[str]:
    server = HTTPServer(("127.0.0.1", 0), _Recorder)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


def test_service_path_posts_the_saved_model_and_the_spec(service: str, tmp_path: Path) -> None:
    scene = read_scene(SCENE)
    answer = _reference().doc.to_dict()
    _Recorder.received, _Recorder.answer = [], answer
    ask = ScriptedPrompter(scene, [("get_file", str(SPEC))])
    result = search_flow(
        ask,
        scene,
        str(tmp_path),
        scene_name=SCENE.name,
        scene_path=str(SCENE),
        service_url=service,
    )
    # the answer is validated into the typed document and read back byte for byte
    assert result is not None and json.dumps(result.doc.to_dict()) == json.dumps(answer)
    ((path, ctype, body),) = _Recorder.received
    assert path == "/api/v1/search" and ctype.startswith("multipart/form-data; boundary=")
    assert SCENE.read_bytes() in body and SPEC.read_bytes() in body
    assert b'name="scene"; filename="search_facade.3dm"' in body
    assert not (tmp_path / "search_facade.search").exists()  # the service's answer only
