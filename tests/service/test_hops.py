"""Grasshopper Hops components over HTTP: metadata, solves and errors, against the REST API."""

from __future__ import annotations

import json
from typing import Any

import httpx
import pytest
from api_helpers import EXAMPLES, cli_error, without_runtime

from solver_service.core.records import GroundMotion

CHURCH = (EXAMPLES / "constants" / "church.json").read_text()
WALLS = (EXAMPLES / "constants" / "rect_walls.json").read_text()
RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
PULSE = {"p_eq": 2.0, "lam": 0.2, "a_p_g": -0.61, "f_p": 1.59, "eta": 0.9}


def _item(value: Any) -> dict[str, Any]:
    if isinstance(value, bool):
        return {"type": "System.Boolean", "data": json.dumps(value)}
    if isinstance(value, int):
        return {"type": "System.Int32", "data": json.dumps(value)}
    if isinstance(value, float):
        return {"type": "System.Double", "data": json.dumps(value)}
    return {"type": "System.String", "data": json.dumps(value)}


def hops_payload(**inputs: Any) -> dict[str, Any]:
    """A solve request as Hops sends it: one input tree per parameter, branch {0}."""
    values = []
    for name, value in inputs.items():
        items = [_item(v) for v in value] if isinstance(value, list) else [_item(value)]
        values.append({"ParamName": name, "InnerTree": {"{0}": items}})
    return {"absetol": 0.001, "angletol": 1.0, "values": values}


def outputs(res: httpx.Response) -> dict[str, list[Any]]:
    """Decode a Hops answer into {output name: [values]}."""
    assert res.status_code == 200, res.text
    out = {}
    for param in res.json()["values"]:
        items = param["InnerTree"]["0"]
        out[param["ParamName"]] = [json.loads(item["data"]) for item in items]
    return out


def test_components_publish_their_metadata(client: httpx.Client) -> None:
    listing = client.get("/hops/").json()
    assert {c["Uri"] for c in listing} == {"/pulse", "/envelope", "/history"}
    meta = client.get("/hops/pulse").json()
    assert [p["Name"] for p in meta["Inputs"]] == [
        "p_eq",
        "lam",
        "a_p_g",
        "f_p",
        "eta",
        "one_sided",
        "shape",
    ]
    assert meta["Outputs"][0]["Name"] == "overturned"
    assert client.get("/hops/nothing").status_code == 404


def test_pulse_component_matches_the_rest_endpoint(client: httpx.Client) -> None:
    rest = client.post("/api/v1/pulse", json=PULSE).json()
    out = outputs(
        client.post("/hops/pulse", json=hops_payload(**PULSE, one_sided=False, shape="sine"))
    )
    assert out["overturned"] == [rest["overturned"]]
    assert out["peak_ratio"] == [rest["peak_ratio"]]
    assert out["t_overturn"] == [rest["t_overturn"]]
    assert out["n_impacts"] == [rest["n_impacts"]]
    assert without_runtime(json.loads(out["json"][0])) == without_runtime(rest)


def test_legacy_solve_route_with_a_pointer(client: httpx.Client) -> None:
    payload = {**hops_payload(**PULSE, one_sided=False, shape="sine"), "pointer": "pulse"}
    out = outputs(client.post("/hops/solve", json=payload))
    assert out["overturned"] == [True]


def test_envelope_component_matches_the_rest_endpoint(client: httpx.Client) -> None:
    rest = client.post(
        "/api/v1/envelope",
        json={"constants": json.loads(CHURCH), "f_min": 0.2, "f_max": 8.0, "n": 30},
    ).json()
    out = outputs(
        client.post(
            "/hops/envelope", json=hops_payload(constants=CHURCH, f_min=0.2, f_max=8.0, n=30)
        )
    )
    assert out["f_p"] == rest["f_p"]
    assert out["governing"] == [g or "" for g in rest["governing"]]
    lowest = [
        min(v for v in col if v is not None)
        for col in zip(*(m["a_p_min_g"] for m in rest["mechanisms"]))
    ]
    assert out["a_p_min_g"] == lowest
    assert len(out["bands"]) == len(rest["critical"])
    assert json.loads(out["json"][0]) == rest


def test_history_component_matches_the_rest_endpoint(client: httpx.Client) -> None:
    motion = GroundMotion.from_file(RECORD, units="g")
    accel_g = [float(v) for v in motion.accel.acc / 9.80665]
    rest = client.post(
        "/api/v1/history",
        json={
            "constants": json.loads(WALLS),
            "record": {"accel": accel_g, "dt": motion.dt, "units": "g", "name": "grasshopper"},
            "scales": [0.5, 1.0],
        },
    ).json()
    out = outputs(
        client.post(
            "/hops/history",
            json=hops_payload(constants=WALLS, accel_g=accel_g, dt=motion.dt, scales=[0.5, 1.0]),
        )
    )
    assert out["mechanism"] == [r["mechanism"] for r in rest["results"]]
    assert out["peak_ratio"] == [r["peak_ratio"] for r in rest["results"]]
    assert out["overturned"] == [r["overturned"] for r in rest["results"]]
    assert without_runtime(json.loads(out["json"][0])) == without_runtime(rest)


def _errors(res: httpx.Response, status: int) -> list[str]:
    assert res.status_code == status, res.text
    doc = res.json()
    assert doc["values"] == []
    return list(doc["errors"])


def test_out_of_range_input_gives_the_cli_message(client: httpx.Client) -> None:
    expected = cli_error(
        "pulse", "--p-eq", "2", "--lam", "0.2", "--eta", "1.3", "--a-p-g", "-0.61", "--f-p", "1.59"
    )
    body = hops_payload(**{**PULSE, "eta": 1.3}, one_sided=False, shape="sine")
    assert _errors(client.post("/hops/pulse", json=body), 422) == [expected]


@pytest.mark.parametrize(
    "item",
    [
        {"type": "System.Double", "data": "true"},
        {"type": "System.Double", "data": "NaN"},
        {"type": "System.String", "data": json.dumps("2.0")},
    ],
)
def test_a_bool_nan_or_text_is_not_a_number(client: httpx.Client, item: dict[str, str]) -> None:
    body = hops_payload(**PULSE, one_sided=False, shape="sine")
    body["values"][0]["InnerTree"]["{0}"] = [item]
    (message,) = _errors(client.post("/hops/pulse", json=body), 422)
    assert "p_eq" in message or "number" in message


def test_missing_input_and_malformed_requests_are_4xx(client: httpx.Client) -> None:
    body = hops_payload(**PULSE)  # one_sided and shape missing
    (message,) = _errors(client.post("/hops/pulse", json=body), 422)
    assert message == "Missing value for required input one_sided"
    _errors(
        client.post("/hops/pulse", content=b"{nope", headers={"content-type": "application/json"}),
        422,
    )
    _errors(client.post("/hops/pulse", json=[1, 2]), 400)
    _errors(client.post("/hops/pulse", json={"values": [{"ParamName": "p_eq"}]}), 422)
    _errors(client.post("/hops/nothing", json=hops_payload()), 404)


def test_invalid_constants_text_gives_the_constants_message(client: httpx.Client) -> None:
    doc = json.loads(WALLS)
    doc["mechanisms"][0]["eta"] = 2.0
    body = hops_payload(constants=json.dumps(doc), f_min=0.2, f_max=8.0, n=10)
    (message,) = _errors(client.post("/hops/envelope", json=body), 422)
    assert message.startswith("constants: mechanisms[0] (id 'W1').eta")


def test_component_defaults_are_the_rest_defaults(client: httpx.Client) -> None:
    from shared_schema.api import EnvelopeRequest, PulseRequest

    pulse = {p["Name"]: p for p in client.get("/hops/pulse").json()["Inputs"]}
    assert "Default" not in pulse["eta"]  # required, as for ``rockmech pulse`` and REST
    assert pulse["shape"]["Default"] == PulseRequest.model_fields["shape"].default
    envelope = {p["Name"]: p for p in client.get("/hops/envelope").json()["Inputs"]}
    for name in ("f_min", "f_max", "n"):
        assert envelope[name]["Default"] == EnvelopeRequest.model_fields[name].default


def test_a_deep_body_is_refused_as_rest_refuses_it(client: httpx.Client) -> None:
    # The one depth limit of every JSON body (api.bodies.MAX_BODY_DEPTH); Hops answered 400
    # "JSON nested too deeply" at about 1000 levels, and read any depth below it.
    deep = b'{"values": ' + b"[" * 250 + b"]" * 250 + b"}"
    headers = {"content-type": "application/json"}
    (message,) = _errors(client.post("/hops/pulse", content=deep, headers=headers), 422)
    rest = client.post("/api/v1/pulse", content=deep, headers=headers)
    assert rest.status_code == 422
    assert message == rest.json()["detail"] == "the request body is nested deeper than 200 levels"
    # An input's own JSON text nested too deeply is refused by name too.
    body = hops_payload(**PULSE, one_sided=False, shape="sine")
    body["values"][0]["InnerTree"]["{0}"][0]["data"] = "[" * 5000 + "]" * 5000
    (message,) = _errors(client.post("/hops/pulse", json=body), 422)
    assert "nested too deeply" in message
