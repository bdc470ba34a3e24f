"""Every REST endpoint over HTTP, against the rockmech CLI or the Python API for the same input."""

from __future__ import annotations

import json
import math
from pathlib import Path

import httpx
import numpy as np
import pytest
from api_helpers import EXAMPLES, cli_json, without_runtime
from servers import TEST_SETTINGS

from shared_schema.export import build_schema
from solver_service.codes import scale_factors as codes
from solver_service.core.records import GroundMotion
from solver_service.workflows.units import stamp

RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
WALLS = EXAMPLES / "constants" / "rect_walls.json"
CHURCH = EXAMPLES / "constants" / "church.json"


def test_health_reports_the_workers_and_the_budget(client: httpx.Client) -> None:
    res = client.get("/api/v1/health")
    assert res.status_code == 200
    doc = res.json()
    assert doc["status"] == "ok"
    assert doc["compute_workers"] == TEST_SETTINGS["compute_workers"]
    assert doc["compute_timeout_s"] == TEST_SETTINGS["compute_timeout_s"]


def test_openapi_and_the_constants_schema_are_published(client: httpx.Client) -> None:
    api = client.get("/api/v1/openapi.json").json()
    paths = set(api["paths"])
    for name in ("health", "constants", "pulse", "envelope", "history", "spectrum"):
        assert f"/api/v1/{name}" in paths
    assert {"/api/v1/scale-factor", "/api/v1/report"} <= paths
    history = api["paths"]["/api/v1/history"]["post"]["requestBody"]["content"]
    assert set(history) == {"application/json", "multipart/form-data"}
    res = client.get("/api/v1/schema/kinematic-constants.json")
    assert res.status_code == 200
    assert res.json() == build_schema()


@pytest.mark.parametrize(
    "args",
    [
        ["--p-eq", "2", "--lam", "0.2", "--eta", "0.9", "--a-p-g", "-0.61", "--f-p", "1.59"],
        [
            "--p-eq",
            "1.8",
            "--lam",
            "0.15",
            "--eta",
            "-0.5",
            "--a-p-g",
            "0.3",
            "--f-p",
            "0.7",
            "--one-sided",
            "--shape",
            "cosine",
            "--criterion",
            "ratio",
            "--phi-ov",
            "0.12",
        ],
    ],
)
def test_pulse_matches_the_cli(client: httpx.Client, args: list[str]) -> None:
    cli = cli_json("pulse", *args)
    body: dict[str, object] = {}
    it = iter(args)
    for flag in it:
        key = flag.lstrip("-").replace("-", "_")
        if key == "one_sided":
            body[key] = True
        elif key in ("shape", "criterion"):
            body[key] = next(it)
        else:
            body[key] = float(next(it))
    res = client.post("/api/v1/pulse", json=body)
    assert res.status_code == 200, res.text
    assert without_runtime(res.json()) == without_runtime(cli)


def test_envelope_matches_the_cli_and_has_the_critical_bands(
    client: httpx.Client, tmp_path: Path
) -> None:
    cli = cli_json("envelope", str(CHURCH), "--out", str(tmp_path), "--n", "60", "--f-min", "0.2")
    body = {"constants": json.loads(CHURCH.read_text()), "n": 60, "f_min": 0.2}
    res = client.post("/api/v1/envelope", json=body)
    assert res.status_code == 200, res.text
    doc = res.json()
    assert doc == cli
    assert doc["critical"] and {b["mechanism"] for b in doc["critical"]} <= {
        m["id"] for m in doc["mechanisms"]
    }


def test_exact_envelope_of_a_stiff_structure_matches_the_cli(
    client: httpx.Client, tmp_path: Path
) -> None:
    # issue #19: f_p/f_n down to 2e-4 overflowed exp in the pulse response spectrum (a 500).
    amp = {"f_n": 500.0, "h": 5.0, "h_e": 10.0}
    constants = {
        "mechanisms": [{"id": "W", "p_eq": 2.0, "lam": 0.2, "eta": 0.9, "amplification": amp}]
    }
    path = tmp_path / "stiff.json"
    path.write_text(json.dumps(constants))
    options = ["--n", "5", "--f-min", "0.1", "--f-max", "10", "--exact"]
    cli = cli_json("envelope", str(path), "--out", str(tmp_path), *options)
    body = {"constants": constants, "n": 5, "f_min": 0.1, "f_max": 10.0, "method": "exact"}
    res = client.post("/api/v1/envelope", json=body)
    assert res.status_code == 200, res.text
    assert res.json() == cli
    assert all(sf > 1.0 for sf in res.json()["mechanisms"][0]["scale_factor"])


def test_history_upload_matches_the_cli(client: httpx.Client) -> None:
    cli = cli_json("history", str(WALLS), str(RECORD), "--scale", "0.5", "1", "2")
    files = {
        "constants": (WALLS.name, WALLS.read_bytes(), "application/json"),
        "record": (RECORD.name, RECORD.read_bytes(), "text/plain"),
    }
    res = client.post("/api/v1/history", files=files, data={"scales": ["0.5", "1", "2"]})
    assert res.status_code == 200, res.text
    assert without_runtime(res.json()) == without_runtime(cli)


@pytest.fixture
def church(tmp_path: Path) -> Path:
    """The example church, with a restitution for every mechanism (time histories need it)."""
    doc = json.loads(CHURCH.read_text())
    for mech in doc["mechanisms"]:
        if mech.get("eta") is None:
            mech["eta"] = -0.5 if mech.get("rocking") == "one_sided" else 0.9
    path = tmp_path / "church_eta.json"
    path.write_text(json.dumps(doc))
    return path


def test_history_with_eq28_and_displacement_matches_the_cli(
    client: httpx.Client, church: Path
) -> None:
    cli = cli_json("history", str(church), str(RECORD), "--sf", "eq28", "--at-height", "2.5")
    files = {
        "constants": (church.name, church.read_bytes()),
        "record": (RECORD.name, RECORD.read_bytes()),
    }
    res = client.post("/api/v1/history", files=files, data={"sf": "eq28", "at_height": "2.5"})
    assert res.status_code == 200, res.text
    doc = res.json()
    assert without_runtime(doc) == without_runtime(cli)
    assert doc["scale_factors"] and all("effective_scale" in r for r in doc["results"])


def test_history_json_samples_match_the_python_api(client: httpx.Client) -> None:
    motion = GroundMotion.from_file(RECORD, units="g")
    accel_g = [float(v) for v in motion.accel.acc / 9.80665]
    body = {
        "constants": json.loads(WALLS.read_text()),
        "record": {"accel": accel_g, "dt": motion.dt, "units": "g", "name": "elcentro"},
        "scales": [0.5, 1.0],
    }
    res = client.post("/api/v1/history", json=body)
    assert res.status_code == 200, res.text
    doc = res.json()
    cli = cli_json("history", str(WALLS), str(RECORD), "--scale", "0.5", "1")
    # Same samples (t0 differs: the file's first time stamp is 0 too), same results.
    assert [without_runtime(r) for r in doc["results"]] == [
        without_runtime(r) for r in cli["results"]
    ]
    assert doc["record"]["source"] == "request body" and doc["record"]["npts"] == len(accel_g)


def test_spectrum_matches_the_cli_record_command(client: httpx.Client) -> None:
    cli = cli_json("record", str(RECORD), "--t-min", "0.05", "--t-max", "4", "--n", "40")
    files = {"record": (RECORD.name, RECORD.read_bytes())}
    data = {"t_min": "0.05", "t_max": "4", "n": "40"}
    res = client.post("/api/v1/spectrum", files=files, data=data)
    assert res.status_code == 200, res.text
    assert without_runtime(res.json()) == without_runtime(cli)


def test_spectrum_of_json_samples_is_the_exact_sdof_peak(client: httpx.Client) -> None:
    # A 1 Hz sine of 0.1 g for 2 s: PSA at T_n = 1 s is the resonant peak of a 5 % oscillator.
    dt = 0.005
    t = np.arange(0.0, 2.0 + dt / 2, dt)
    body = {
        "record": {"accel": list(0.1 * np.sin(2 * np.pi * t)), "dt": dt, "units": "g"},
        "t_min": 0.5,
        "t_max": 2.0,
        "n": 3,
    }
    res = client.post("/api/v1/spectrum", json=body)
    assert res.status_code == 200, res.text
    spec = res.json()["spectrum"]
    assert spec["periods_s"] == pytest.approx([0.5, 1.0, 2.0], rel=1e-12)
    from solver_service.core.spectra import response_spectrum

    direct = response_spectrum(0.1 * 9.80665 * np.sin(2 * np.pi * t), dt, [0.5, 1.0, 2.0])
    assert spec["psa_g"] == pytest.approx(list(direct.psa_g), rel=1e-12)


@pytest.mark.parametrize(
    ("body", "expected"),
    [
        (
            {"method": "eq28", "sa_g": 0.19, "pga_g": 0.155, "h": 4.6, "h_e": 4.54},
            codes.sf_eq28(0.19, 0.155, 4.6, 4.54),
        ),
        (
            {"method": "ec8", "z": 6.0, "H": 10.0, "T_a": 0.1, "T_1": 0.5, "S": 1.15},
            codes.sf_ec8(6.0, 10.0, 0.1, 0.5, 1.15),
        ),
        ({"method": "nzs", "h_i": 4.6, "h_n": 4.6}, codes.sf_nzs(4.6, 4.6)),
    ],
)
def test_scale_factor_matches_the_code_formulas(
    client: httpx.Client, body: dict[str, object], expected: dict[str, object]
) -> None:
    res = client.post("/api/v1/scale-factor", json=body)
    assert res.status_code == 200, res.text
    assert res.json() == stamp(expected, "scale_factor")


def test_scale_factor_eq28_from_a_record_matches_the_history_factor(
    client: httpx.Client, church: Path
) -> None:
    history = cli_json("history", str(church), str(RECORD), "--sf", "eq28")
    doc = json.loads(church.read_text())
    mech = next(m for m in doc["mechanisms"] if "amplification" in m)
    amp = mech["amplification"]
    motion = GroundMotion.from_file(RECORD, units="g")
    record = {"accel": list(motion.accel.acc / 9.80665), "dt": motion.dt, "units": "g"}
    body = {"method": "eq28", "record": record, "f_n": amp["f_n"], "h": amp["h"], "h_e": amp["h_e"]}
    res = client.post("/api/v1/scale-factor", json=body)
    assert res.status_code == 200, res.text
    expected = history["scale_factors"][mech["id"]]
    assert math.isclose(res.json()["value"], expected["value"], rel_tol=1e-12)


def test_constants_from_an_uploaded_scene_match_the_cli(
    client: httpx.Client, tmp_path: Path
) -> None:
    scene = EXAMPLES / "scenes" / "facade.3dm"
    spec = EXAMPLES / "specs" / "facade.spec.json"
    out = tmp_path / "facade.json"
    cli = cli_json("constants", str(scene), str(spec), "-o", str(out))
    files = {
        "scene": (scene.name, scene.read_bytes(), "application/octet-stream"),
        "spec": (spec.name, spec.read_bytes(), "application/json"),
    }
    res = client.post("/api/v1/constants", files=files)
    assert res.status_code == 200, res.text
    assert res.json() == cli
    assert json.loads(out.read_text()) == cli


def test_report_is_html_with_every_section(client: httpx.Client) -> None:
    files = {
        "constants": (WALLS.name, WALLS.read_bytes()),
        "record": (RECORD.name, RECORD.read_bytes()),
    }
    res = client.post("/api/v1/report", files=files, data={"scales": ["0.5", "1"], "n": "40"})
    assert res.status_code == 200, res.text
    assert res.headers["content-type"].startswith("text/html")
    page = res.text
    for heading in (
        "Kinematic constants",
        "Overturning envelopes and critical mechanism",
        "Critical bands",
        "Record and elastic response spectrum",
        "Time histories",
        "Error estimates",
        "Inputs and provenance",
    ):
        assert f">{heading}" in page, heading
    import hashlib

    assert hashlib.sha256(RECORD.read_bytes()).hexdigest() in page
    assert hashlib.sha256(WALLS.read_bytes()).hexdigest() in page
    assert page.count('<img class="plot"') == 3
    assert "http://" not in page and "https://" not in page  # self-contained


def test_operations_have_readable_ids_and_tags(client: httpx.Client) -> None:
    api = client.get("/api/v1/openapi.json").json()
    ops = {
        path: (op["operationId"], op["tags"])
        for path, item in api["paths"].items()
        for op in item.values()
    }
    assert ops["/api/v1/pulse"] == ("pulse", ["solver"])
    assert ops["/api/v1/scale-factor"] == ("scale_factor", ["solver"])
    assert ops["/api/v1/history"] == ("history", ["records"])
    assert ops["/api/v1/constants"] == ("constants", ["geometry"])
    assert ops["/api/v1/check"] == ("check", ["assessment"])
    assert ops["/api/v1/assess"] == ("assess", ["assessment"])
    assert ops["/api/v1/retrofit"] == ("retrofit", ["assessment"])
    assert [t["name"] for t in api["tags"]] == [
        "service",
        "solver",
        "records",
        "geometry",
        "reports",
        "assessment",
    ]
