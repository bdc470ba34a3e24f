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
from api_helpers import EXAMPLES, Server, runner, without_runtime
from test_hops import hops_payload, outputs

import rockmech
from rhino_plugin.flows.analyse import (
    ServiceClient,
    analyse_flow,
    load_constants_files,
    run_pulse,
)
from shared_schema.errors import RockmechError
from shared_schema.io import load_constants
from solver_service.cli import app
from solver_service.workflows.adapter import to_rocking_model

CONSTANTS = sorted((EXAMPLES / "constants").glob("*.json"))
RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
AMPLITUDES_G = (0.1, 0.3, 0.6)
FREQUENCIES_HZ = (0.5, 1.5, 4.0)


def _cases() -> list[tuple[Path, str, float, float]]:
    cases = []
    for path in CONSTANTS:
        for mech in load_constants(path).mechanisms:
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
    cf = load_constants_files([str(path)])
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
        cf = load_constants(path)
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
        next(m for m in load_constants(church).mechanisms if m.id == "A1").model_dump_json(
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
