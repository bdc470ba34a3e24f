"""`rockmech check` and the check document: verdicts, notes instead of aborts, JSON names."""

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shared_schema.constants import parse_constants
from shared_schema.site import parse_site
from solver_service.cli import app
from solver_service.core.model import G
from solver_service.workflows.assess import check_doc

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
runner = CliRunner()

NTC_SITE = {
    "hazard": {"code": "NTC2018", "a_g": 0.25, "F0": 2.4, "Tc_star": 0.3, "soil": "C", "FC": 1.35}
}


def block_file(b: float = 0.5, h: float = 3.0, rho: float = 1800.0, **extra: object) -> dict:
    m = rho * b * h
    return {
        "mechanisms": [
            {
                "id": "W1",
                "positive": {
                    "p_eq": 2.2,
                    "lam": math.atan(b / h),
                    "virtual_work": {
                        "alpha0": b / h,
                        "mass": m,
                        "S": m * h / 2,
                        "J": m * h * h / 3,
                    },
                },
                "eta": 0.95,
                **extra,
            },
            {"id": "S1", "p_eq": 2.0, "lam": 0.1, "eta": 0.9},
        ]
    }


def test_check_doc_block_and_short_form_note() -> None:
    doc = check_doc(parse_constants(block_file()), parse_site(NTC_SITE))
    w1, s1 = doc["mechanisms"]
    lin = w1["linear"]
    assert lin["e_star"] == pytest.approx(0.75, abs=1e-12)
    assert lin["a0_star"] == pytest.approx((0.5 / 3.0) * G / (0.75 * 1.35), rel=1e-12)
    assert lin["demand_ground"] == pytest.approx(0.25 * 1.34 * G / 2.0, rel=1e-12)
    assert w1["passes"] == (lin["passes"] and w1["nonlinear"]["passes"])
    # The short-form mechanism gets a note, never an abort.
    assert s1["linear"]["status"] == "not_run" and "virtual_work" in s1["linear"]["note"]
    assert s1["passes"] is None
    assert doc["governing"] == "W1"


def test_above_ground_without_building_is_incomplete_not_silent() -> None:
    data = block_file(amplification={"f_n": 2.0, "h_e": 6.0, "h": 6.0})
    doc = check_doc(parse_constants(data), parse_site(NTC_SITE))
    lin = doc["mechanisms"][0]["linear"]
    assert lin["passes"] is None and "building" in lin["note"]
    site = dict(NTC_SITE, building={"height": 9.0, "storeys": 3})
    doc = check_doc(parse_constants(data), parse_site(site))
    lin = doc["mechanisms"][0]["linear"]
    assert lin["T1"] == pytest.approx(0.5)  # 1/f_n of the mechanism
    assert lin["psi"] == pytest.approx(6.0 / 9.0) and lin["gamma"] == pytest.approx(9 / 7)
    assert isinstance(lin["passes"], bool)


def test_cli_check_table_and_json(tmp_path: Path) -> None:
    cpath, spath = tmp_path / "c.json", tmp_path / "site.json"
    cpath.write_text(json.dumps(block_file()), encoding="utf-8")
    spath.write_text(json.dumps(NTC_SITE), encoding="utf-8")
    res = runner.invoke(app, ["check", str(cpath), str(spath)])
    assert res.exit_code == 0, res.output
    assert "W1" in res.output and "S1" in res.output and "note: S1" in res.output
    res = runner.invoke(app, ["check", str(cpath), str(spath), "--json"])
    doc = json.loads(res.output)
    assert set(doc["mechanisms"][0]["linear"]) >= {"alpha0", "M_star", "e_star", "a0_star"}
    assert set(doc["mechanisms"][0]["nonlinear"]) >= {"d0_star", "du_star", "Ts", "passes"}


def test_cli_check_bad_site_names_the_field(tmp_path: Path) -> None:
    cpath, spath = tmp_path / "c.json", tmp_path / "site.json"
    cpath.write_text(json.dumps(block_file()), encoding="utf-8")
    spath.write_text(json.dumps({"hazard": {"code": "NTC2018", "a_g": 0.2}}), encoding="utf-8")
    res = runner.invoke(app, ["check", str(cpath), str(spath)])
    assert res.exit_code == 2
    assert "hazard.NTC2018" in res.output and "Traceback" not in res.output


def test_example_church_from_geometry_checks_every_mechanism() -> None:
    cf = parse_constants((EXAMPLES / "constants" / "church_geometry.json").read_bytes())
    site = parse_site((EXAMPLES / "sites" / "ntc_site.json").read_bytes())
    doc = check_doc(cf, site)
    assert [r["linear"]["status"] for r in doc["mechanisms"]] == ["ok"] * 4
    # The two-block strip is a triangle of displacements: e* = 3/4 (theory §11.1).
    t1 = next(r for r in doc["mechanisms"] if r["id"] == "T1")
    assert t1["linear"]["e_star"] == pytest.approx(0.75, rel=1e-6)


def test_ec8_site_says_which_method_it_applies() -> None:
    site = parse_site({"hazard": {"code": "EC8", "a_gR": 0.2, "FC": 1.2}})
    doc = check_doc(parse_constants(block_file()), site)
    assert "EN 1998-1" in doc["site"]["method_note"]
    lin = doc["mechanisms"][0]["linear"]
    # EC8 ground A, type 1: S = 1, so the ground demand is a_g g / q.
    assert lin["demand_ground"] == pytest.approx(0.2 * G / 2.0, rel=1e-12)
    assert lin["a0_star"] == pytest.approx((0.5 / 3.0) * G / (0.75 * 1.2), rel=1e-12)


def test_cli_assess_json_prints_one_document(tmp_path: Path) -> None:
    pytest.importorskip("jinja2")
    out = tmp_path / "r.html"
    args = [
        "assess",
        str(EXAMPLES / "constants" / "church_geometry.json"),
        str(EXAMPLES / "sites" / "ntc_site.json"),
        "-o",
        str(out),
        "--json",
    ]
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert [r["id"] for r in doc["mechanisms"]] == ["F1", "F2", "A1", "T1"]
    assert out.is_file() and "wrote" in res.stderr
