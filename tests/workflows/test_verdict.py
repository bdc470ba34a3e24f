"""One verdict per mechanism and for the building (#27): the rule, case by case.

The rows are shaped as ``check_doc``/``assessment_doc`` write them (only the keys the rule
reads); the last test runs the real documents of the bundled church.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Optional

from typer.testing import CliRunner

from shared_schema.constants import parse_constants
from shared_schema.site import parse_site
from solver_service.cli import app
from solver_service.workflows.assess import check_doc
from solver_service.workflows.verdict import RULE, conclusion

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _check(ratio: Optional[float]) -> dict[str, Any]:
    if ratio is None:
        return {"status": "not_run", "passes": None, "note": "no virtual_work in the constants"}
    return {"status": "ok", "capacity_ratio": ratio, "passes": ratio >= 1.0}


def _row(
    mid: str,
    lin: Optional[float],
    non: Optional[float],
    survives: Optional[list[bool]] = None,
    margin: Optional[float] = None,
) -> dict[str, Any]:
    verdicts = [r >= 1.0 for r in (lin, non) if r is not None]
    row: dict[str, Any] = {
        "id": mid,
        "name": f"wall {mid}",
        "linear": _check(lin),
        "nonlinear": _check(non),
        "passes": None if len(verdicts) < 2 else all(verdicts),
    }
    if survives is not None:
        row["dynamics"] = [
            {"record": f"R{i}", "survives_design": s, "runs": []} for i, s in enumerate(survives)
        ]
        row["envelope"] = (
            {"pulses": [{"record": "R0", "margin": margin, "f_p": 2.0}]} if margin else {}
        )
    return row


def _doc(*rows: dict[str, Any], records: bool = True) -> dict[str, Any]:
    doc: dict[str, Any] = {
        "method": {"name": "circ2019", "standard": "Circ. 2019 §C8.7.1"},
        "site": {"limit_state": "SLV"},
        "mechanisms": list(rows),
    }
    if records:
        doc["records"] = [{"name": "R0"}]
    return doc


def test_a_failed_code_check_governs_even_where_the_records_survive() -> None:
    c = conclusion(_doc(_row("W1", 0.8, 1.2, [True]), _row("W2", 1.5, 0.5, [True])), "Casa")
    assert c["verdict"] == "fails" and c["rule"] == RULE
    w1, w2 = c["mechanisms"]
    assert w1["verdict"] == w2["verdict"] == "fails"
    assert w1["governs"].startswith("linear kinematic check at SLV (Circ. 2019 §C8.7.1.2.1.7)")
    assert w2["governs"].startswith("nonlinear kinematic check")
    assert "does not lift the code check's verdict" in w1["reason"]
    # The most critical is the lowest ratio among the failures: W2 at 0.5.
    assert c["sentence"] == (
        "The local collapse mechanisms of Casa do not satisfy Circ. 2019 §C8.7.1 at SLV: 2 of 2 "
        "mechanisms fail, the most critical being W2 (wall W2), whose capacity is 0.5 of the "
        "demand (a_g,SLV/a_g < 1)."
    )


def test_a_record_that_overturns_at_design_fails_a_mechanism_that_passes_the_code() -> None:
    c = conclusion(_doc(_row("W1", 1.3, 1.1, [True, False]), _row("W2", 2.0, 2.0, [True])))
    w1, w2 = c["mechanisms"]
    assert (w1["verdict"], w2["verdict"]) == ("fails", "passes")
    assert w1["governs"] == "rocking time history at the design scale"
    assert "R1 scaled to the site spectrum overturns it" in w1["reason"]
    assert c["sentence"].startswith("The mechanisms do not satisfy")
    assert "W1 (wall W1) because it overturns at the design level" in c["sentence"]


def test_everything_passes_and_the_sentence_says_on_what() -> None:
    c = conclusion(_doc(_row("W1", 1.3, 1.1, [True]), _row("W2", 2.0, 1.05, [True])), "Torre")
    assert c["verdict"] == "passes"
    assert c["sentence"] == (
        "The local collapse mechanisms of Torre satisfy Circ. 2019 §C8.7.1 at SLV: all 2 "
        "mechanisms pass (lowest capacity/demand 1.05, W2), and none overturns at the design "
        "level in the rocking time histories on 1 record(s) scaled to the site spectrum."
    )
    # A check document (no records): the code check alone.
    c = conclusion(_doc(_row("W1", 1.3, 1.1), records=False))
    assert c["sentence"].endswith("all 1 mechanisms pass (lowest capacity/demand 1.1, W1).")


def test_a_pass_on_one_check_says_which_check_did_not_run() -> None:
    row = _row("W1", 1.4, None, [True])
    row["passes"] = True  # check_doc: the verdicts of the checks that ran
    (w1,) = conclusion(_doc(row))["mechanisms"]
    assert w1["verdict"] == "passes"
    assert w1["reason"].startswith("passes every code check that ran; the lowest: linear")
    assert w1["reason"].endswith("(not run: nonlinear: no virtual_work in the constants)")


def test_a_check_that_could_not_run_makes_the_verdict_incomplete_not_a_pass() -> None:
    c = conclusion(_doc(_row("W1", 1.3, 1.1, [True]), _row("W2", None, None, [True])))
    assert c["verdict"] == "incomplete"
    assert c["mechanisms"][1]["verdict"] == "incomplete"
    assert "no virtual_work" in c["mechanisms"][1]["reason"]
    assert "could not be run for 1 of 2 mechanisms (W2)" in c["sentence"]


def test_where_the_pulse_margin_disagrees_the_time_history_governs_and_it_is_said() -> None:
    c = conclusion(
        _doc(_row("A1", 1.3, 1.1, [False], margin=5.23), _row("B1", 1.3, 1.1, [True], margin=0.7))
    )
    a1, b1 = c["mechanisms"]
    assert (
        a1["verdict"] == "fails" and "would not overturn it (margin 5.23 > 1)" in a1["pulse_margin"]
    )
    assert b1["verdict"] == "passes" and "(margin 0.7 < 1)" in b1["pulse_margin"]
    assert "the time history" in a1["pulse_margin"] and "governs" in b1["pulse_margin"]


def test_every_path_carries_the_conclusion_of_the_real_church() -> None:
    constants = EXAMPLES / "constants" / "church_geometry.json"
    site = EXAMPLES / "sites" / "ntc_site.json"
    doc = check_doc(parse_constants(constants.read_bytes()), parse_site(site.read_bytes()))
    res = CliRunner().invoke(app, ["check", str(constants), str(site), "--json"])
    assert res.exit_code == 0, res.output
    cli = json.loads(res.stdout)
    assert cli["conclusion"] == doc["conclusion"]
    by_id = {m["id"]: m for m in doc["conclusion"]["mechanisms"]}
    assert {k: v["verdict"] for k, v in by_id.items()} == {
        "F1": "fails",
        "F2": "fails",
        "A1": "fails",
        "T1": "passes",
    }
    assert (
        by_id["F1"]["code_check"]["capacity_ratio"]
        == doc["mechanisms"][0]["nonlinear"]["capacity_ratio"]
    )
