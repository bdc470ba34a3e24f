"""Bad input over HTTP: always a 4xx, with the message ``rockmech`` prints for the same input."""

from __future__ import annotations

import json
from pathlib import Path

import httpx
import pytest
from api_helpers import EXAMPLES, cli_error
from servers import TEST_SETTINGS

RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
WALLS = EXAMPLES / "constants" / "rect_walls.json"
SCENE = EXAMPLES / "scenes" / "facade.3dm"
SPEC = EXAMPLES / "specs" / "facade.spec.json"
NTC = EXAMPLES / "sites" / "ntc_site.json"
PULSE = {"p_eq": 2.0, "lam": 0.2, "eta": 0.9, "a_p_g": -0.61, "f_p": 1.59}


def _detail(res: httpx.Response, status: int) -> str:
    assert res.status_code == status, res.text
    doc = res.json()
    assert set(doc) <= {"detail", "field", "error"}
    return str(doc["detail"])


def _history_upload(client: httpx.Client, record: Path, **data: object) -> httpx.Response:
    files = {
        "constants": (WALLS.name, WALLS.read_bytes()),
        "record": (record.name, record.read_bytes()),
    }
    return client.post("/api/v1/history", files=files, data=data)


def test_oversized_upload_gets_413_naming_the_limit(client: httpx.Client, tmp_path: Path) -> None:
    limit = TEST_SETTINGS["max_body_bytes"]
    big = tmp_path / "big.dat"
    big.write_bytes(b"0.0 0.0\n" * (limit // 8 + 1000))
    detail = _detail(_history_upload(client, big), 413)
    assert str(limit) in detail and "ROCKMECH_MAX_BODY_BYTES" in detail


def test_oversized_chunked_body_gets_413(client: httpx.Client) -> None:
    limit = TEST_SETTINGS["max_body_bytes"]

    def chunks():  # no Content-Length: the server counts what arrives
        yield b'{"p_eq": 2.0, "pad": "'
        for _ in range(limit // 65536 + 2):
            yield b"x" * 65536
        yield b'"}'

    res = client.post(
        "/api/v1/pulse", content=chunks(), headers={"content-type": "application/json"}
    )
    assert str(limit) in _detail(res, 413)


def test_truncated_3dm_gives_the_cli_message(client: httpx.Client, tmp_path: Path) -> None:
    scene = tmp_path / SCENE.name
    scene.write_bytes(SCENE.read_bytes()[:30000])
    (tmp_path / SPEC.name).write_bytes(SPEC.read_bytes())
    expected = cli_error("constants", scene.name, SPEC.name, "-o", "out.json", cwd=tmp_path)
    files = {"scene": (scene.name, scene.read_bytes()), "spec": (SPEC.name, SPEC.read_bytes())}
    res = client.post("/api/v1/constants", files=files)
    assert _detail(res, 422) == expected
    assert res.json()["field"] == "scene"


def test_spec_naming_missing_objects_gives_the_cli_message(
    client: httpx.Client, tmp_path: Path
) -> None:
    spec = json.loads(SPEC.read_text())
    spec["mechanisms"][1]["groups"][0]["objects"] = ["no_such_wall"]
    path = tmp_path / "missing.spec.json"
    path.write_text(json.dumps(spec))
    (tmp_path / SCENE.name).write_bytes(SCENE.read_bytes())
    expected = cli_error("constants", SCENE.name, path.name, "-o", "out.json", cwd=tmp_path)
    assert "no_such_wall" in expected
    files = {"scene": (SCENE.name, SCENE.read_bytes()), "spec": (path.name, path.read_bytes())}
    assert _detail(client.post("/api/v1/constants", files=files), 422) == expected


def test_spec_with_a_file_path_is_refused(client: httpx.Client) -> None:
    spec = json.loads(SPEC.read_text())
    spec["thrust_table"] = "/etc/passwd"
    files = {"scene": (SCENE.name, SCENE.read_bytes()), "spec": ("s.json", json.dumps(spec))}
    res = client.post("/api/v1/constants", files=files)
    assert "no file paths" in _detail(res, 422)
    assert res.json()["field"] == "thrust_table"


def test_record_with_nan_gives_the_cli_message(client: httpx.Client, tmp_path: Path) -> None:
    record = tmp_path / "nan_record.dat"
    record.write_text("0.00 0.0\n0.01 0.1\n0.02 nan\n0.03 0.0\n")
    (tmp_path / WALLS.name).write_bytes(WALLS.read_bytes())
    expected = cli_error("history", WALLS.name, record.name, cwd=tmp_path)
    assert "not finite" in expected
    assert _detail(_history_upload(client, record), 422) == expected


def test_nan_and_infinity_in_json_are_refused(client: httpx.Client) -> None:
    body = (
        '{"constants": {"mechanisms": [{"id": "W", "p_eq": 2, "lam": 0.2, "eta": 0.9}]},'
        ' "record": {"accel": [0.0, NaN, 0.1], "dt": 0.01, "units": "g"}}'
    )
    res = client.post("/api/v1/history", content=body, headers={"content-type": "application/json"})
    assert _detail(res, 422) == "record.accel[1]: Input should be a finite number"
    res = client.post(
        "/api/v1/pulse",
        content=json.dumps({**PULSE, "f_p": 1e999}),
        headers={"content-type": "application/json"},
    )
    assert _detail(res, 422) == "f_p: Input should be a finite number"


@pytest.mark.parametrize("value", [True, "2.0", None, [2.0]])
def test_a_bool_or_a_string_is_not_a_number(client: httpx.Client, value: object) -> None:
    res = client.post("/api/v1/pulse", json={**PULSE, "p_eq": value})
    if value is None:  # null is "not given": the short form then lacks p_eq
        assert _detail(res, 422).startswith("p_eq: required, unless the mechanism is given")
    else:
        assert _detail(res, 422).startswith("p_eq: Input should be a valid number")


def test_form_text_true_is_not_a_number(client: httpx.Client) -> None:
    res = _history_upload(client, RECORD, scales="true")
    assert _detail(res, 422).startswith("scales[0]: Input should be a valid number")


def test_wrong_content_types_get_415(client: httpx.Client) -> None:
    res = client.post(
        "/api/v1/pulse", content=json.dumps(PULSE), headers={"content-type": "text/plain"}
    )
    assert "application/json" in _detail(res, 415)
    res = client.post("/api/v1/constants", json={"scene": "x"})
    assert "multipart/form-data" in _detail(res, 415)
    res = client.post(
        "/api/v1/history", content=b"<xml/>", headers={"content-type": "application/xml"}
    )
    assert "application/xml" in _detail(res, 415)


@pytest.mark.parametrize(
    ("args", "body"),
    [
        (["--eta", "1.3"], {"eta": 1.3}),
        (["--eta", "-0.2"], {"eta": -0.2}),
        (["--f-p", "0"], {"f_p": 0.0}),
        (["--shape", "square"], {"shape": "square"}),
        (["--criterion", "maybe"], {"criterion": "maybe"}),
    ],
)
def test_pulse_range_errors_match_the_cli(
    client: httpx.Client, args: list[str], body: dict[str, object]
) -> None:
    base = ["--p-eq", "2", "--lam", "0.2", "--eta", "0.9", "--a-p-g", "-0.61", "--f-p", "1.59"]
    flags = dict(zip(base[::2], base[1::2]))
    flags.update(dict(zip(args[::2], args[1::2])))
    expected = cli_error("pulse", *[x for kv in flags.items() for x in kv])
    assert _detail(client.post("/api/v1/pulse", json={**PULSE, **body}), 422) == expected


def test_invalid_constants_give_the_cli_message_with_the_field_for_the_file(
    client: httpx.Client, tmp_path: Path
) -> None:
    doc = json.loads(WALLS.read_text())
    doc["mechanisms"][1]["positive"]["p_eq"] = -1.0
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    expected = cli_error("history", path.name, str(RECORD), cwd=tmp_path)
    assert expected.startswith("bad.json: mechanisms[1] (id 'W2').positive.p_eq")
    res = client.post("/api/v1/envelope", json={"constants": doc})
    assert _detail(res, 422) == "constants" + expected[len("bad.json") :]
    # Uploaded, the file's own name labels the message, exactly as on the command line.
    files = {
        "constants": (path.name, path.read_bytes()),
        "record": (RECORD.name, RECORD.read_bytes()),
    }
    assert _detail(client.post("/api/v1/history", files=files), 422) == expected


def test_a_derived_p_eq_that_underflows_is_422_naming_the_side(
    client: httpx.Client, tmp_path: Path
) -> None:
    # issue #19: sqrt(K/I0) = 0.0 passed, then failed the compute process's own validation
    # of the job (p_eq > 0): a 500.
    side = {"I0": 1e300, "K": 5e-324, "Q": 1.0, "phi_cr": 0.1}
    doc = {"mechanisms": [{"id": "W", "p_eq": 2.0, "lam": 0.2, "negative": side}]}
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    expected = cli_error("check", path.name, str(NTC), cwd=tmp_path)
    assert expected.startswith("bad.json: mechanisms[0] (id 'W').negative.p_eq: sqrt(K/I0) = 0.0")
    res = client.post("/api/v1/check", json={"constants": doc, "site": json.loads(NTC.read_text())})
    assert _detail(res, 422) == "constants" + expected[len("bad.json") :]
    assert res.json()["field"] == "constants.mechanisms[0] (id 'W').negative.p_eq"


def test_unknown_sf_gives_the_cli_message(client: httpx.Client) -> None:
    expected = cli_error("history", str(WALLS), str(RECORD), "--sf", "bogus")
    assert _detail(_history_upload(client, RECORD, sf="bogus"), 422) == expected


@pytest.mark.parametrize(
    ("endpoint", "body", "limit"),
    [
        ("/api/v1/envelope", {"n": 100_001}, "max_samples"),
        ("/api/v1/envelope", {"mechanisms": 21}, "max_mechanisms"),
        ("/api/v1/history", {"samples": 100_001}, "max_samples"),
        ("/api/v1/history", {"scales": 21}, "max_scales"),
    ],
)
def test_size_limits_give_422_with_the_limit(
    client: httpx.Client, endpoint: str, body: dict[str, int], limit: str
) -> None:
    mech = [
        {"id": f"M{i}", "p_eq": 2.0, "lam": 0.2, "eta": 0.9}
        for i in range(body.get("mechanisms", 1))
    ]
    request: dict[str, object] = {"constants": {"mechanisms": mech}}
    if "n" in body:
        request["n"] = body["n"]
    if endpoint.endswith("history"):
        request["record"] = {"accel": [0.0] * body.get("samples", 10), "dt": 0.01, "units": "g"}
        request["scales"] = [1.0] * body.get("scales", 1)
    detail = _detail(client.post(endpoint, json=request), 422)
    assert str(TEST_SETTINGS[limit]) in detail and f"ROCKMECH_{limit.upper()}" in detail


def test_malformed_and_deeply_nested_json_are_4xx(client: httpx.Client) -> None:
    headers = {"content-type": "application/json"}
    res = client.post("/api/v1/pulse", content=b'{"p_eq": ', headers=headers)
    assert res.status_code == 422
    res = client.post("/api/v1/history", content=b'{"p_eq": ', headers=headers)
    assert res.status_code == 422
    deep = b"[" * 100_000 + b"]" * 100_000
    for endpoint in ("/api/v1/pulse", "/api/v1/history"):
        res = client.post(endpoint, content=deep, headers=headers)
        assert 400 <= res.status_code < 500, (endpoint, res.text)


def test_unknown_paths_and_methods_are_json_4xx(client: httpx.Client) -> None:
    assert _detail(client.get("/api/v1/nothing"), 404) == "Not Found"
    assert _detail(client.get("/api/v1/pulse"), 405) == "Method Not Allowed"


def test_a_record_without_units_gets_the_cli_message(client: httpx.Client, tmp_path: Path) -> None:
    record = tmp_path / "one.txt"
    record.write_text("0.0\n0.1\n-0.1\n0.0\n")
    (tmp_path / WALLS.name).write_bytes(WALLS.read_bytes())
    expected = cli_error("history", WALLS.name, record.name, "--dt", "0.01", cwd=tmp_path)
    assert _detail(_history_upload(client, record, dt="0.01"), 422) == expected


@pytest.mark.parametrize(
    ("endpoint", "body"),
    [
        (
            "/api/v1/history",
            {
                "constants": {"mechanisms": [{"id": "W", "p_eq": 2.0, "lam": 0.2, "eta": 0.9}]},
                "record": {"accel": [0.0, 0.3, 0.0], "dt": 1e12, "units": "g"},
            },
        ),
    ],
)
def test_absurd_work_gets_422_at_once(
    client: httpx.Client, endpoint: str, body: dict[str, object]
) -> None:
    detail = _detail(client.post(endpoint, json=body), 422)
    limit = 20 * TEST_SETTINGS["max_samples"]
    assert f"at most {limit} per run (20 x ROCKMECH_MAX_SAMPLES)" in detail


@pytest.mark.parametrize(
    ("endpoint", "body"),
    [
        ("/api/v1/spectrum", {"record": {"accel": [0.0, 0.1], "dt": 40965.0, "units": "g"}}),
        (
            "/api/v1/scale-factor",
            {
                "method": "eq28",
                "h": 3.0,
                "h_e": 4.0,
                "f_n": 2.0,
                "record": {"accel": [0.0, 0.3, 0.0], "dt": 1e12, "units": "g"},
            },
        ),
    ],
)
def test_a_record_time_step_outside_its_range_gets_422(
    client: httpx.Client, endpoint: str, body: dict[str, object]
) -> None:
    detail = _detail(client.post(endpoint, json=body), 422)
    assert "is outside the range a record can have, [1e-06, 1] s" in detail
