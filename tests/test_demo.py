"""The bundled demo runs end to end and its constants are the analytic ones."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from shared_schema.io import read_constants, stamped
from solver_service.core.model import G
from solver_service.demo import DEMO_SCALES, DEMO_WALLS, demo_constants, run_demo

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_rectangular_wall_constants_are_housners() -> None:
    for mech, (_, _, b, h, rocking) in zip(demo_constants().mechanisms, DEMO_WALLS):
        r = 0.5 * math.hypot(b, h)
        alpha = math.atan(b / h)
        assert mech.positive.p_eq == pytest.approx(math.sqrt(3 * G / (4 * r)), rel=1e-12)
        assert mech.positive.lam == pytest.approx(alpha, rel=1e-12)
        expected_eta = (
            1 - 1.5 * math.cos(alpha) ** 2
            if rocking == "one_sided"
            else 1 - 1.5 * math.sin(alpha) ** 2
        )
        assert mech.eta == pytest.approx(expected_eta, rel=1e-12)


def test_committed_example_matches_the_demo_constants() -> None:
    committed = read_constants(EXAMPLES / "constants" / "rect_walls.json")
    assert committed == demo_constants()


def test_demo_writes_constants_results_and_plot(tmp_path: Path) -> None:
    paths = run_demo(tmp_path)
    assert read_constants(paths["constants"]) == stamped(demo_constants())
    doc = json.loads(paths["history"].read_text())
    assert len(doc["results"]) == len(DEMO_WALLS) * len(DEMO_SCALES)
    assert all(0.0 <= r["peak_ratio"] <= 1.0 or not r["overturned"] for r in doc["results"])
    # The slender brick wall overturns under El Centro at full scale; PNG is a real image.
    w1 = next(r for r in doc["results"] if r["mechanism"] == "W1" and r["scale"] == 1.0)
    assert w1["overturned"] is True
    assert paths["plot"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # The example church's envelopes: every mechanism, critical bands covering the range.
    env = json.loads(paths["envelope"].read_text())
    assert len(env["mechanisms"]) == len(
        json.loads((EXAMPLES / "constants" / "church.json").read_text())["mechanisms"]
    )
    assert env["critical"][0]["f_min"] == pytest.approx(0.1)
    assert env["critical"][-1]["f_max"] == pytest.approx(10.0)
    assert paths["envelope_plot"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert paths["envelope_csv"].read_text().count("\n") == 201
    hist = json.loads(paths["church_history"].read_text())
    assert hist["scale_factor_method"] == "eq28" and hist["scale_factors"]
    assert all(v["value"] >= 1.0 for v in hist["scale_factors"].values())
    # The CAD path end to end: scene -> constants -> envelope.
    facade = json.loads(paths["facade_constants"].read_text())
    assert [m["id"] for m in facade["mechanisms"]] == ["F1", "F2"]
    assert facade["mechanisms"][0]["provenance"]["scene"] == "facade.3dm"
    env_f = json.loads(paths["facade_envelope"].read_text())
    assert {m["id"] for m in env_f["mechanisms"]} == {"F1", "F2"} and env_f["critical"]
    assert paths["facade_envelope_plot"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(tmp_path.glob(".*"))  # no temporary files left behind
