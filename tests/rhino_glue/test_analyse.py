"""RM_Analyse: the flow, the local analyses (against the CLI) and the service client.

References: ``rockmech envelope/history/pulse --json`` on the same inputs; for the service
client, a real HTTP server on 127.0.0.1 that records what it receives.
"""

import json
import subprocess
import sys
import threading
from http.server import BaseHTTPRequestHandler, HTTPServer
from pathlib import Path
from typing import Any, ClassVar, Dict, Iterator, List, Tuple

import pytest

from rhino_plugin.flows.analyse import (
    ServiceClient,
    analyse_flow,
    read_constants_files,
    run_envelopes,
    run_history,
    run_pulse,
)
from shared_schema.errors import InputError
from solver_service.workflows.documents import envelope_doc, history_doc, solve_pulse

from .conftest import CANCEL, ROOT, ScriptedPrompter

CHURCH = ROOT / "examples" / "constants" / "church.json"
WALLS = ROOT / "examples" / "constants" / "rect_walls.json"
RECORD = ROOT / "examples" / "records" / "elcentro_NS.dat"


def cli_json(*args: str) -> Any:
    done = subprocess.run(
        [sys.executable, "-c", "from solver_service.cli import app; app()", *args, "--json"],
        check=True,
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    return json.loads(done.stdout)


def test_local_envelopes_equal_the_cli(tmp_path: Path) -> None:
    cf = read_constants_files([str(CHURCH)])
    result = run_envelopes(cf, f_min=0.5, f_max=5.0, n=30, out_dir=str(tmp_path))
    want = cli_json("envelope", str(CHURCH), "--out", str(tmp_path / "cli"),
                    "--f-min", "0.5", "--f-max", "5", "--n", "30")  # fmt: skip
    got = result.doc.to_dict()
    for key in ("f_p", "mechanisms", "critical", "governing"):
        assert got[key] == want[key], key
    assert Path(result.plot or "").stat().st_size > 0
    assert json.loads((tmp_path / "envelope.json").read_text())["critical"] == want["critical"]
    assert result.summary[0] == "critical mechanism by pulse frequency:"
    assert len(result.summary) == 1 + len(want["critical"])


def test_local_history_equals_the_cli(tmp_path: Path) -> None:
    cf = read_constants_files([str(WALLS)])
    result = run_history(
        cf, str(RECORD), units="g", scales=[0.5, 1.0], out_dir=str(tmp_path)
    )  # fmt: skip
    want = cli_json("history", str(WALLS), str(RECORD), "--scale", "0.5", "1")
    strip = ("runtime_s",)
    got = result.doc.to_dict()["results"]
    got_rows = [{k: v for k, v in r.items() if k not in strip} for r in got]
    want_rows = [{k: v for k, v in r.items() if k not in strip} for r in want["results"]]
    assert got_rows == want_rows
    assert Path(result.plot or "").stat().st_size > 0
    assert len(result.summary) == len(want_rows)


def test_history_states_the_record_warning_first(tmp_path: Path) -> None:
    # El Centro (in g) read as cm/s2: PGA 0.000356 g, the warning the CLI prints (#25)
    cf = read_constants_files([str(WALLS)])
    result = run_history(cf, str(RECORD), units="cm/s2", scales=[1.0], out_dir=str(tmp_path))
    assert result.summary[0].startswith("  warning: record: PGA 0.000356 g is outside"), result
    assert "(read in cm/s2)" in result.summary[0]
    assert len(result.summary) == 1 + len(result.doc.to_dict()["results"])


def test_local_pulse_equals_the_cli() -> None:
    cf = read_constants_files([str(WALLS)])
    mech = cf.mechanisms[0]
    result = run_pulse(cf, mech.id, a_p_g=-0.61, f_p=1.59)
    want = cli_json("pulse", "--p-eq", repr(mech.positive.p_eq), "--lam", repr(mech.positive.lam),
                    "--eta", repr(mech.eta), "--a-p-g", "-0.61", "--f-p", "1.59")  # fmt: skip
    got = result.doc.to_dict()
    for key in ("peak_ratio", "overturned", "t_peak", "n_impacts"):
        assert got[key] == want[key], key


def test_constants_files_are_merged_and_duplicate_ids_refused(tmp_path: Path) -> None:
    doc = json.loads(WALLS.read_text())
    first, rest = tmp_path / "first.json", tmp_path / "rest.json"
    first.write_text(json.dumps({**doc, "mechanisms": doc["mechanisms"][:1]}))
    rest.write_text(json.dumps({**doc, "mechanisms": doc["mechanisms"][1:]}))
    merged = read_constants_files([str(first), str(rest)])
    assert [m.id for m in merged.mechanisms] == [m["id"] for m in doc["mechanisms"]]
    with pytest.raises(InputError, match="is in both"):
        read_constants_files([str(WALLS), str(first)])


# ---------------------------------------------------------------------- the flow


@pytest.mark.slow
def test_analyse_flow_envelopes_of_the_current_mechanisms(tmp_path: Path) -> None:
    steps = [
        ("get_option", "Current"),
        ("get_option", "Envelopes"),
        ("get_number", 0.5),
        ("get_number", 5),
    ]
    prompter = ScriptedPrompter(None, steps)
    result = analyse_flow(prompter, str(tmp_path), current=[str(CHURCH)])
    assert result is not None, prompter.messages
    assert prompter.done()
    want = cli_json("envelope", str(CHURCH), "--out", str(tmp_path / "cli"),
                    "--f-min", "0.5", "--f-max", "5")  # fmt: skip
    assert result.doc.to_dict()["critical"] == want["critical"]
    assert any("via the Python API" in m for m in prompter.messages)
    assert any(m.endswith("envelope.png") for m in prompter.messages)


def test_analyse_flow_history_with_several_scales(tmp_path: Path) -> None:
    steps = [
        ("get_option", "File"),
        ("get_file", str(WALLS)),
        ("get_option", "History"),
        ("get_file", str(RECORD)),
        ("get_option", "g"),
        ("get_number", 0.5),
        ("get_number", 1),
        ("get_number", None),
    ]
    prompter = ScriptedPrompter(None, steps)
    result = analyse_flow(prompter, str(tmp_path))
    assert result is not None, prompter.messages
    assert sorted({r["scale"] for r in result.doc.to_dict()["results"]}) == [0.5, 1.0]


@pytest.mark.parametrize("k", range(4))
def test_analyse_flow_cancel_at_any_prompt(k: int, tmp_path: Path) -> None:
    script = [
        ("get_option", "File"),
        ("get_file", str(WALLS)),
        ("get_option", "Pulse"),
        ("get_option", "W1"),
    ]
    steps = [*script[:k], (script[k][0], CANCEL)]
    prompter = ScriptedPrompter(None, steps)
    assert analyse_flow(prompter, str(tmp_path)) is None
    assert prompter.messages == ["RM_Analyse: cancelled."]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("answer", ["fast", -1.0, 0.0])
def test_analyse_flow_refuses_a_bad_frequency(answer: Any, tmp_path: Path) -> None:
    steps = [
        ("get_option", "File"),
        ("get_file", str(WALLS)),
        ("get_option", "Envelopes"),
        ("get_number", answer),
    ]
    prompter = ScriptedPrompter(None, steps)
    assert analyse_flow(prompter, str(tmp_path)) is None
    assert "f_min [Hz]" in prompter.messages[-1]
    assert list(tmp_path.iterdir()) == []


def test_analyse_flow_reports_a_missing_file(tmp_path: Path) -> None:
    steps = [("get_option", "File"), ("get_file", str(tmp_path / "nope.json"))]
    prompter = ScriptedPrompter(None, steps)
    assert analyse_flow(prompter, str(tmp_path)) is None
    assert "constants file not found" in prompter.messages[-1]


# ---------------------------------------------------------------------- the service


class _Recorder(BaseHTTPRequestHandler):
    received: ClassVar[List[Tuple[str, Dict[str, Any]]]] = []
    answers: ClassVar[Dict[str, Tuple[int, Any]]] = {}

    def do_POST(self) -> None:
        body = self.rfile.read(int(self.headers["Content-Length"]))
        assert self.headers["Content-Type"] == "application/json"
        type(self).received.append((self.path, json.loads(body)))
        status, doc = type(self).answers[self.path]
        raw = json.dumps(doc).encode()
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(raw)))
        self.end_headers()
        self.wfile.write(raw)

    def log_message(self, *args: Any) -> None:
        pass


@pytest.fixture()
def service() -> Iterator[Tuple[str, Any]]:
    _Recorder.received = []
    _Recorder.answers = {}
    server = HTTPServer(("127.0.0.1", 0), _Recorder)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/", _Recorder
    finally:
        server.shutdown()
        server.server_close()


@pytest.fixture(scope="module")
def answers() -> Dict[str, Dict[str, Any]]:
    """Real documents the service could answer for WALLS (made here with the workflows).

    The envelope's critical band is replaced by one the flow could not compute itself (W1
    over 0.1-10 Hz): what the flow keeps and summarises is the service's answer.
    """
    import numpy as np

    from solver_service.core.records import GroundMotion

    cf = read_constants_files([str(WALLS)])
    env = envelope_doc(cf, np.array([0.5, 2.0]))[0].to_dict()
    env["critical"] = [{"mechanism": "W1", "f_min": 0.1, "f_max": 10.0}]
    motion = GroundMotion.from_file(str(RECORD), units="g")
    hist = history_doc(cf, motion, [1.0]).to_dict()
    pulse = solve_pulse({"mechanism": cf.mechanisms[0], "a_p_g": 0.3, "f_p": 1.0}).to_dict()
    return {"envelope": env, "history": hist, "pulse": pulse}


def test_service_envelopes_post_the_constants_and_keep_the_answer(
    service: Any, tmp_path: Path, answers: Dict[str, Dict[str, Any]]
) -> None:
    url, recorder = service
    answer = answers["envelope"]
    recorder.answers["/api/v1/envelope"] = (200, answer)
    cf = read_constants_files([str(WALLS)])
    result = run_envelopes(cf, f_min=0.2, f_max=8.0, n=50, out_dir=str(tmp_path),
                           client=ServiceClient(url))  # fmt: skip
    path, body = recorder.received[0]
    assert path == "/api/v1/envelope"
    assert (body["f_min"], body["f_max"], body["n"]) == (0.2, 8.0, 50)
    assert [m["id"] for m in body["constants"]["mechanisms"]] == [m.id for m in cf.mechanisms]
    assert result.doc.to_dict() == answer  # validated into the envelope document
    assert json.loads((tmp_path / "envelope.json").read_text()) == answer
    assert result.summary == ["critical mechanism by pulse frequency:", "  W1: 0.1 to 10 Hz"]


def test_service_answer_that_is_not_the_document_is_refused_naming_the_field(
    service: Any, tmp_path: Path, answers: Dict[str, Dict[str, Any]]
) -> None:
    url, recorder = service
    wrong = {k: v for k, v in answers["envelope"].items() if k != "critical"}
    recorder.answers["/api/v1/envelope"] = (200, wrong)
    cf = read_constants_files([str(WALLS)])
    with pytest.raises(InputError, match=r"/envelope is not its EnvelopeDocument: critical: "):
        run_envelopes(cf, out_dir=str(tmp_path), client=ServiceClient(url))
    recorder.answers["/api/v1/pulse"] = (200, dict(answers["pulse"], overturned="maybe"))
    with pytest.raises(InputError, match=r"/pulse is not its PulseDocument: overturned: ") as err:
        run_pulse(cf, "W1", a_p_g=0.3, f_p=1.0, client=ServiceClient(url))
    assert err.value.field == "service"


def test_service_history_sends_the_record_in_si(
    service: Any, tmp_path: Path, answers: Dict[str, Dict[str, Any]]
) -> None:
    from solver_service.core.records import GroundMotion

    url, recorder = service
    recorder.answers["/api/v1/history"] = (200, answers["history"])
    cf = read_constants_files([str(WALLS)])
    run_history(cf, str(RECORD), units="g", scales=[1.0, 2.0], out_dir=str(tmp_path),
                client=ServiceClient(url))  # fmt: skip
    _, body = recorder.received[0]
    motion = GroundMotion.from_file(str(RECORD), units="g")
    assert body["record"]["units"] == "m/s2"
    assert body["record"]["dt"] == motion.dt
    assert body["record"]["accel"] == [float(a) for a in motion.accel.acc]
    assert body["scales"] == [1.0, 2.0]


def test_service_error_detail_becomes_the_message(service: Any) -> None:
    url, recorder = service
    recorder.answers["/api/v1/pulse"] = (422, {"detail": "f_p: must be > 0, got -1"})
    cf = read_constants_files([str(WALLS)])
    with pytest.raises(InputError, match=r"answered 422: f_p: must be > 0, got -1"):
        run_pulse(cf, "W1", a_p_g=0.3, f_p=1.0, client=ServiceClient(url))


def test_unreachable_service_is_a_clear_error() -> None:
    import socket

    with socket.socket() as sock:  # a free port that nothing listens on
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    cf = read_constants_files([str(WALLS)])
    with pytest.raises(InputError, match="cannot reach the rockmech service"):
        run_pulse(cf, "W1", a_p_g=0.3, f_p=1.0, client=ServiceClient(f"http://127.0.0.1:{port}"))


def test_service_url_must_be_http() -> None:
    with pytest.raises(InputError, match="must start with http"):
        ServiceClient("ftp://example")


def test_service_payloads_match_the_api_request_models(
    service: Any, tmp_path: Path, answers: Dict[str, Dict[str, Any]]
) -> None:
    """The bodies validate against shared_schema.api's request models, where present."""
    api = pytest.importorskip("shared_schema.api", reason="the REST request models are absent")
    url, recorder = service
    for endpoint in ("envelope", "history", "pulse"):
        recorder.answers[f"/api/v1/{endpoint}"] = (200, answers[endpoint])
    cf = read_constants_files([str(WALLS)])
    client = ServiceClient(url)
    run_envelopes(cf, out_dir=str(tmp_path), client=client)
    run_history(cf, str(RECORD), units="g", scales=[1.0], out_dir=str(tmp_path), client=client)
    run_pulse(cf, "W1", a_p_g=0.3, f_p=1.0, client=client)
    models = {"envelope": api.EnvelopeRequest, "history": api.HistoryRequest,
              "pulse": api.PulseRequest}  # fmt: skip
    for path, body in recorder.received:
        models[path.rsplit("/", 1)[1]].model_validate_json(json.dumps(body))


def test_a_service_retrofit_that_is_not_the_document_is_refused_naming_the_field(
    service: Any, tmp_path: Path
) -> None:
    # RM_Retrofit on the service: its answer is validated into the retrofit document too.
    from rhino_plugin.flows.retrofit import retrofit_flow

    from .conftest import ScriptedPrompter

    examples = Path(__file__).resolve().parents[2] / "examples"
    files = [
        ("get_file", str(examples / "constants" / "church_geometry.json")),
        ("get_file", str(examples / "sites" / "ntc_site.json")),
        ("get_file", str(examples / "specs" / "church.retrofit.json")),
    ]
    url, recorder = service
    recorder.answers["/api/v1/retrofit"] = (200, {"rockmech_version": "0", "mechanisms": "x"})
    with pytest.raises(InputError, match=r"/retrofit is not its RetrofitDoc: ") as err:
        retrofit_flow(ScriptedPrompter(None, files), str(tmp_path), stem="c", service_url=url)
    assert err.value.field == "service"
    assert not (tmp_path / "c.retrofit").exists()  # nothing written from a wrong answer
