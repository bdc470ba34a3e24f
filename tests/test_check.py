"""`rockmech check` and the check document: verdicts, notes instead of aborts, JSON names.

The numbers of the Circolare 2019 checks are worked by hand in
``tests/codes/test_circ2019.py``; here: what reaches the user, end to end.
"""

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
    # One block: [C8.7.1.5] has one term (the centroid of its forces), e* = 1.
    assert lin["e_star"] == pytest.approx(1.0, abs=1e-12)
    assert lin["a0_star"] == pytest.approx((0.5 / 3.0) * G / (1.0 * 1.35), rel=1e-12)
    # A two-sided user-defined block is free-standing by default (C8.7.1.2.1.3) and, with no
    # E, L, t or unit weight, T0 is unknown: the demand is the spectrum's peak a_g S F0.
    assert w1["free_standing"]["value"] is True
    assert lin["T0"] is None and "T0 unknown" in lin["demand_rule"]
    assert lin["demand_activation"] == pytest.approx(0.25 * 1.34 * 2.4 * G, rel=1e-9)
    assert w1["passes"] == (lin["passes"] and w1["nonlinear"]["passes"])
    # The short-form mechanism gets a note, never an abort.
    assert s1["linear"]["status"] == "not_run" and "virtual_work" in s1["linear"]["note"]
    assert s1["passes"] is None
    assert doc["governing"] == "W1"
    assert doc["method"]["name"] == "circ2019"


def test_above_ground_without_building_is_incomplete_not_silent() -> None:
    data = block_file(amplification={"f_n": 2.0, "h_e": 6.0, "h": 6.0})
    doc = check_doc(parse_constants(data), parse_site(NTC_SITE))
    lin, non = doc["mechanisms"][0]["linear"], doc["mechanisms"][0]["nonlinear"]
    assert lin["passes"] is None and "building" in lin["note"]
    assert non["passes"] is None and non["SLV"]["passes"] is None
    site = dict(NTC_SITE, building={"height": 9.0, "storeys": 3})
    doc = check_doc(parse_constants(data), parse_site(site))
    row = doc["mechanisms"][0]
    # One T1 rule: no building.T1 in the site, so Circolare 2019 [C7.3.2], not 1/f_n.
    assert row["T1"] == pytest.approx(0.05 * 9.0**0.75, rel=1e-12)
    assert "[C7.3.2]" in row["T1_source"]
    # The constants' f_n (the dynamics' period) is not the check's: the row says so.
    assert "1/f_n = 0.5 s" in row["linear"]["note"] and "building.T1" in row["linear"]["note"]
    floor = row["linear"]["floor"]
    assert floor["psi"] == pytest.approx(6.0 / 9.0) and floor["gamma"] == pytest.approx(9 / 7)
    assert isinstance(row["linear"]["passes"], bool)


def test_cli_check_table_and_json(tmp_path: Path) -> None:
    cpath, spath = tmp_path / "c.json", tmp_path / "site.json"
    cpath.write_text(json.dumps(block_file()), encoding="utf-8")
    spath.write_text(json.dumps(NTC_SITE), encoding="utf-8")
    res = runner.invoke(app, ["check", str(cpath), str(spath)])
    assert res.exit_code == 0, res.output
    assert "W1" in res.output and "S1" in res.output and "note: S1" in res.output
    assert "T_SLV" in res.output and "Circolare 21 gennaio 2019" in res.output
    assert "W1: SLC" in res.output
    res = runner.invoke(app, ["check", str(cpath), str(spath), "--json"])
    doc = json.loads(res.output)
    lin, non = doc["mechanisms"][0]["linear"], doc["mechanisms"][0]["nonlinear"]
    assert set(lin) >= {"alpha0", "M_star", "e_star", "a0_star", "a_g_SLV", "clauses"}
    assert set(non) >= {"d0", "d_SLV", "T_SLV", "passes", "SLV", "SLC", "clauses"}
    assert "[C8.7.1.10]" in non["clauses"]["T_SLV"]
    assert "[C8.7.1.11]" in non["SLC"]["clauses"]["T_SLC"]


def test_cli_check_2009_forms_on_request(tmp_path: Path) -> None:
    cpath, spath = tmp_path / "c.json", tmp_path / "site.json"
    cpath.write_text(json.dumps(block_file()), encoding="utf-8")
    site = dict(NTC_SITE, local_mechanisms={"method": "circ2009"})
    spath.write_text(json.dumps(site), encoding="utf-8")
    res = runner.invoke(app, ["check", str(cpath), str(spath), "--json"])
    doc = json.loads(res.output)
    assert doc["method"]["name"] == "circ2009" and "2009" in doc["method"]["standard"]
    lin = doc["mechanisms"][0]["linear"]
    assert lin["method"] == "circ2009" and "2019" not in lin["standard"]
    # The 2009 ground demand a_g S / q.
    assert lin["demand_ground"] == pytest.approx(0.25 * 1.34 * G / 2.0, rel=1e-12)


def test_cli_refuses_a_t1_conflict_and_unknown_ids(tmp_path: Path) -> None:
    cpath, spath = tmp_path / "c.json", tmp_path / "site.json"
    cpath.write_text(
        json.dumps(block_file(amplification={"f_n": 3.1, "h_e": 6.0, "h": 6.0})), encoding="utf-8"
    )
    spath.write_text(
        json.dumps(dict(NTC_SITE, building={"height": 12.0, "storeys": 4, "T1": 0.6})),
        encoding="utf-8",
    )
    res = runner.invoke(app, ["check", str(cpath), str(spath)])
    assert res.exit_code == 2 and "error: building.T1:" in res.output
    assert "Traceback" not in res.output
    spath.write_text(
        json.dumps(dict(NTC_SITE, local_mechanisms={"mechanisms": {"Z9": {}}})), encoding="utf-8"
    )
    res = runner.invoke(app, ["check", str(cpath), str(spath)])
    assert res.exit_code == 2 and "local_mechanisms.mechanisms.Z9" in res.output


def test_slc_is_checked_where_the_site_gives_its_hazard() -> None:
    site = json.loads(json.dumps(NTC_SITE))
    site["hazard"]["limit_states"] = {"SLC": {"a_g": 0.32, "F0": 2.45, "Tc_star": 0.32}}
    doc = check_doc(parse_constants(block_file()), parse_site(site))
    row = doc["mechanisms"][0]
    slc = row["nonlinear"]["SLC"]
    assert slc["a_g"] == pytest.approx(0.32) and isinstance(slc["passes"], bool)
    assert row["passes_SLC"] == slc["passes"]
    assert doc["site"]["limit_states"]["SLC"]["source"] == "hazard.limit_states.SLC"
    # The SLC demand is the SLC spectrum's at 10 %: soil C with a_g = 0.32 g, F0 = 2.45.
    s_s = min(max(1.70 - 0.60 * 2.45 * 0.32, 1.0), 1.5)
    t_c = 1.05 * 0.32**-0.33 * 0.32
    t_d = 4 * 0.32 + 1.6
    t = slc["T_SLC"]
    assert t_c < t < t_d
    want = 0.32 * s_s * (10 / 15) ** 0.5 * 2.45 * t_c / t * G * t**2 / (4 * math.pi**2)
    assert slc["demand"] == pytest.approx(want, rel=1e-12)


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
    # The two-block strip: both blocks' centres move alike, so [C8.7.1.5] by blocks gives
    # e* = 1 (over the solid, a triangle of displacements: 3/4; theory §11.1).
    t1 = next(r for r in doc["mechanisms"] if r["id"] == "T1")
    assert t1["linear"]["e_star"] == pytest.approx(1.0, rel=1e-6)


def test_ec8_site_says_which_method_it_applies() -> None:
    site = parse_site({"hazard": {"code": "EC8", "a_gR": 0.2, "FC": 1.2}})
    doc = check_doc(parse_constants(block_file()), site)
    assert "EN 1998-1" in doc["site"]["method_note"]
    lin = doc["mechanisms"][0]["linear"]
    # EC8 ground A, type 1: S = 1; free-standing with T0 unknown: the plateau a_g S 2.5.
    assert lin["demand_activation"] == pytest.approx(0.2 * 2.5 * G, rel=1e-12)
    assert lin["a0_star"] == pytest.approx((0.5 / 3.0) * G / (1.0 * 1.2), rel=1e-12)


@pytest.mark.slow
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


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_cli_assess_reads_one_channel_of_a_multi_channel_record(
    tmp_path: Path, shared_records: Path
) -> None:
    # A CSMIP/DMG V2 file holds three channels: assess takes --channel / --component as every
    # other record-reading command does, and its report's command repeats the choice.
    dmg = shared_records / "formats" / "ce36456p_CE36456.V2"
    if not dmg.is_file():
        pytest.skip(f"shared strong-motion record not found at {dmg} (not part of a clone)")
    constants = EXAMPLES / "constants" / "rect_walls.json"
    site = EXAMPLES / "sites" / "ntc_site.json"
    base = ["assess", str(constants), str(site), "--record", str(dmg), "--multiple", "1"]
    res = runner.invoke(app, [*base, "-o", str(tmp_path / "none.html")])
    assert res.exit_code == 2
    assert "holds 3 acceleration channels" in res.stderr
    out = tmp_path / "report.html"
    res = runner.invoke(app, [*base, "--channel", "3", "-o", str(out), "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    by_component = runner.invoke(
        app, [*base, "--component", "0 DEG", "-o", str(tmp_path / "b.html"), "--json"]
    )
    assert by_component.exit_code == 0, by_component.output
    assert json.loads(by_component.stdout)["records"] == doc["records"]
    assert "--channel 3" in out.read_text(encoding="utf-8")
