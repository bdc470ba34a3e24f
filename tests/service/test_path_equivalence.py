"""One question, one answer, on every path (#27).

The same requests go through every front end that offers them, and every path must give
the same verdict and the same numbers, bit for bit (only ``runtime_s`` differs):

* pulses, a grid over every mechanism of the bundled constants files, both signs, three
  amplitudes and three frequencies: ``rockmech pulse --constants --mechanism --json``, the
  Python API (``rockmech.solve_pulse``), REST ``/pulse`` on the real server, the Rhino flow
  headless (``run_pulse``, local and through the service, and ``analyse_flow`` with a
  scripted user), and Hops ``/hops/pulse`` for the mechanisms its inputs can describe
  (symmetric: ``p_eq``, ``lam``, ``eta``, ``one_sided``). A request that must be refused
  (a mechanism without ``eta``) is refused on every path with the same message;
* envelopes and time histories of each bundled constants file: the command line, the
  Python API, REST, Hops and the Rhino flow (local and through the service).

Among the grid is the case of the issue: ``church_geometry.json`` A1 at +0.3 g, 1.5 Hz,
which the Rhino flow's service path answered for its positive side only (survives) while
its local path overturned.
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path
from typing import Any, Optional, Sequence

import httpx
from api_helpers import EXAMPLES, runner, without_runtime
from servers import Server
from test_hops import hops_payload, outputs

import rockmech
from rhino_plugin.flows.analyse import (
    ServiceClient,
    analyse_flow,
    read_constants_files,
    run_envelopes,
    run_history,
    run_pulse,
)
from shared_schema.errors import RockmechError
from shared_schema.io import read_constants
from solver_service.cli import app
from solver_service.core.records import GroundMotion
from solver_service.workflows.adapter import to_rocking_model
from solver_service.workflows.documents import envelope_doc, frequency_grid, history_doc

CONSTANTS = sorted((EXAMPLES / "constants").glob("*.json"))
RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
AMPLITUDES_G = (0.1, 0.3, 0.6)
FREQUENCIES_HZ = (0.5, 1.5, 4.0)


def _cases() -> list[tuple[Path, str, float, float]]:
    cases = []
    for path in CONSTANTS:
        for mech in read_constants(path).mechanisms:
            for a, sign, f in itertools.product(AMPLITUDES_G, (1.0, -1.0), FREQUENCIES_HZ):
                cases.append((path, mech.id, sign * a, f))
    return cases


CASES = _cases()


def test_the_grid_holds_the_case_of_the_issue() -> None:
    church = EXAMPLES / "constants" / "church_geometry.json"
    assert (church, "A1", 0.3, 1.5) in CASES
    assert len(CASES) >= 200


class Prompter:
    """A user of RM_Analyse, answering its questions in order (headless Rhino)."""

    def __init__(self, answers: Sequence[Any]) -> None:
        self.answers = list(answers)
        self.messages: list[str] = []

    def _next(self) -> Any:
        return self.answers.pop(0)

    def get_option(self, prompt: str, options: Sequence[str], default: int = 0) -> str:
        answer = self._next()
        assert answer in options, (prompt, answer, options)
        return str(answer)

    def get_file(self, prompt: str, extensions: Sequence[str]) -> str:
        return str(self._next())

    def get_number(self, prompt: str, default: Any = None, optional: bool = False) -> Any:
        return self._next()

    def message(self, text: str) -> None:
        self.messages.append(text)


def _outcome(call: Any, *args: Any) -> tuple[str, Any]:
    """``("doc", document without runtime)`` or ``("error", message)`` of one path."""
    try:
        return "doc", without_runtime(call(*args))
    except RockmechError as exc:
        return "error", str(exc)


def _service_message(exc: RockmechError) -> str:
    # The Rhino client names the service and its answer: "<url> answered 422: <detail>".
    text = str(exc)
    return text.split(" answered 422: ", 1)[1] if " answered 422: " in text else text


def _cli(path: Path, mech: str, a: float, f: float) -> tuple[str, Any]:
    args = ["pulse", "--constants", str(path), "--mechanism", mech]
    res = runner.invoke(app, [*args, "--a-p-g", repr(a), "--f-p", repr(f), "--json"])
    if res.exit_code == 0:
        return "doc", without_runtime(json.loads(res.stdout))
    assert res.exit_code == 2, res.output
    return "error", res.stderr.strip().removeprefix("error: ")


def _rest(client: httpx.Client, body: dict[str, Any]) -> tuple[str, Any]:
    res = client.post("/api/v1/pulse", json=body)
    if res.status_code == 200:
        return "doc", without_runtime(res.json())
    assert res.status_code == 422, res.text
    return "error", res.json()["detail"]


def _flow(path: Path, mech: str, a: float, f: float, url: Optional[str]) -> tuple[str, Any]:
    cf = read_constants_files([str(path)])
    client = ServiceClient(url) if url else None
    try:
        return "doc", without_runtime(run_pulse(cf, mech, a_p_g=a, f_p=f, client=client).doc)
    except RockmechError as exc:
        return "error", _service_message(exc)


def _answer(doc: dict[str, Any]) -> dict[str, Any]:
    """The answer of a pulse document: all but the echo of the request (``input``)."""
    return {k: v for k, v in doc.items() if k != "input"}


def _hops(client: httpx.Client, request: dict[str, Any]) -> dict[str, Any]:
    body = hops_payload(**request, shape="sine")
    doc: dict[str, Any] = json.loads(outputs(client.post("/hops/pulse", json=body))["json"][0])
    return without_runtime(doc)


def test_every_pulse_path_gives_the_same_answer(server: Server, client: httpx.Client) -> None:
    by_hops = 0
    refused = 0
    for path, mech_id, a, f in CASES:
        cf = read_constants(path)
        mech = next(m for m in cf.mechanisms if m.id == mech_id)
        body = {
            "mechanism": json.loads(mech.model_dump_json(exclude_none=True)),
            "a_p_g": a,
            "f_p": f,
        }
        case = (path.name, mech_id, a, f)
        want = _outcome(rockmech.solve_pulse, body)
        assert _cli(path, mech_id, a, f) == want, case
        assert _rest(client, body) == want, case
        assert _flow(path, mech_id, a, f, None) == want, case
        assert _flow(path, mech_id, a, f, server.url) == want, case
        if want[0] == "error":
            refused += 1
            continue
        assert want[1]["input"]["mechanism"] == mech_id
        model, side = to_rocking_model(mech), mech.positive
        if model.is_symmetric and not model.is_directional and side.phi_ov == side.lam:
            # Hops takes the short form, which describes this mechanism: the same numbers.
            short = {"p_eq": side.p_eq, "lam": side.lam, "eta": mech.eta, "a_p_g": a, "f_p": f}
            short["one_sided"] = mech.rocking == "one_sided"
            hops = _hops(client, short)
            assert hops == without_runtime(rockmech.solve_pulse(short)), case
            assert _answer(hops) == _answer(want[1]), case
            by_hops += 1
    assert by_hops >= 100 and refused >= 1


def test_the_rhino_flow_asks_and_answers_as_the_api(server: Server, tmp_path: Path) -> None:
    """RM_Analyse with a scripted user, locally and on the service: the issue's case."""
    church = EXAMPLES / "constants" / "church_geometry.json"
    body = {"mechanism": None, "a_p_g": 0.3, "f_p": 1.5}
    body["mechanism"] = json.loads(
        next(m for m in read_constants(church).mechanisms if m.id == "A1").model_dump_json(
            exclude_none=True
        )
    )
    want = without_runtime(rockmech.solve_pulse(body))
    assert want["overturned"] is True  # the service path said "survives"
    for where in ("Local", "Service"):
        prompter = Prompter(["File", church, "Pulse", where, "A1", 0.3, 1.5])
        result = analyse_flow(prompter, str(tmp_path), service_url=server.url)
        assert result is not None, prompter.messages
        assert without_runtime(result.doc) == want, where


# --- envelopes and time histories --------------------------------------------------------------

N_ENVELOPE = 30


def _cli_doc(*argv: str) -> dict[str, Any]:
    res = runner.invoke(app, [*argv, "--json"])
    assert res.exit_code == 0, res.output
    return dict(json.loads(res.stdout))


def test_every_envelope_path_gives_the_same_answer(
    server: Server, client: httpx.Client, tmp_path: Path
) -> None:
    for path in CONSTANTS:
        text = path.read_text()
        cf = read_constants(path)
        out = tmp_path / path.stem
        want = without_runtime(envelope_doc(cf, frequency_grid(0.1, 10.0, N_ENVELOPE))[0])
        got = {
            "cli": _cli_doc("envelope", str(path), "--n", str(N_ENVELOPE), "--out", str(out)),
            "file": json.loads((out / "envelope.json").read_text()),
            "rest": client.post(
                "/api/v1/envelope", json={"constants": json.loads(text), "n": N_ENVELOPE}
            ).json(),
        }
        body = hops_payload(constants=text, f_min=0.1, f_max=10.0, n=N_ENVELOPE)
        got["hops"] = json.loads(outputs(client.post("/hops/envelope", json=body))["json"][0])
        flows = read_constants_files([str(path)])
        for where, url in (("flow", None), ("flow-service", server.url)):
            result = run_envelopes(
                flows,
                n=N_ENVELOPE,
                out_dir=str(tmp_path / f"{path.stem}-{where}"),
                client=ServiceClient(url) if url else None,
            )
            got[where] = result.doc
        for where, doc in got.items():
            assert without_runtime(doc) == want, (path.name, where)


def _record_g() -> tuple[list[float], float]:
    """The record's samples in g as written in the file, and its step [s] as read."""
    rows = [line.split() for line in RECORD.read_text().splitlines() if line.strip()]
    return [float(r[1]) for r in rows], GroundMotion.from_file(RECORD, units="g").dt


def _answer_rows(doc: dict[str, Any]) -> Any:
    """The verdicts and numbers of a history document (the record's description aside)."""
    return without_runtime({k: doc[k] for k in ("results", "criterion", "method") if k in doc})


def test_every_history_path_gives_the_same_answer(
    server: Server, client: httpx.Client, tmp_path: Path
) -> None:
    accel_g, dt = _record_g()
    motion = GroundMotion.from_file(RECORD, units="g")
    scales = [0.5, 1.0, 2.0]
    for path in (
        EXAMPLES / "constants" / "rect_walls.json",
        EXAMPLES / "constants" / "church.json",
    ):
        text = path.read_text()
        cf = read_constants(path)
        want = _answer_rows(history_doc(cf, motion, scales).to_dict())
        assert sum(r["overturned"] for r in want["results"]) >= 1  # something to disagree on
        got = {
            "cli": _cli_doc("history", str(path), str(RECORD), "--scale", *map(str, scales)),
            "rest": client.post(
                "/api/v1/history",
                json={
                    "constants": json.loads(text),
                    "record": {"accel": accel_g, "dt": dt, "units": "g", "name": "r"},
                    "scales": scales,
                },
            ).json(),
        }
        body = hops_payload(constants=text, accel_g=accel_g, dt=dt, scales=scales)
        got["hops"] = json.loads(outputs(client.post("/hops/history", json=body))["json"][0])
        flows = read_constants_files([str(path)])
        for where, url in (("flow", None), ("flow-service", server.url)):
            result = run_history(
                flows,
                str(RECORD),
                units="g",
                scales=scales,
                out_dir=str(tmp_path / f"{path.stem}-{where}"),
                client=ServiceClient(url) if url else None,
            )
            got[where] = result.doc.to_dict()
        for where, doc in got.items():
            assert _answer_rows(doc) == want, (path.name, where)
