"""RM_CodeCheck's flow: the check document and its summary lines, through the Python API."""

from pathlib import Path

import pytest

from rhino_plugin.flows.check import parse_site_text, run_check
from rhino_plugin.flows.params import parse_constants_text
from shared_schema.errors import InputError
from solver_service.workflows.assess import check_doc
from solver_service.workflows.units import stamp

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_code_check_flow_matches_the_workflow_and_summarises_each_mechanism() -> None:
    cf = parse_constants_text((EXAMPLES / "constants" / "church_geometry.json").read_text())
    site = parse_site_text((EXAMPLES / "sites" / "ntc_site.json").read_text())
    result = run_check(cf, site)
    assert result.doc.to_dict() == stamp(check_doc(cf, site), "check")  # units and version added
    lines = result.summary
    assert [ln.split(":")[0] for ln in lines[:4]] == ["F1", "F2", "A1", "T1"]
    # The tied façade fails both: its ties are not verified up to collapse (d0 without them).
    assert lines[0].startswith("F1: linear FAILS (") and "nonlinear FAILS (" in lines[0]
    assert lines[-2].startswith("T1: linear passes (") and "nonlinear passes (" in lines[-2]
    # The example site gives the SLC hazard: the collapse check is in each line. The tie
    # passes at SLV and fails at SLC (e* of its blocks, [C8.7.1.5]).
    assert ", SLC FAILS (" in lines[0] and ", SLC FAILS (" in lines[-2]
    assert lines[-1] == f"governing mechanism: {result.doc.governing}"


def test_short_form_constants_say_why_the_check_did_not_run() -> None:
    cf = parse_constants_text('[{"id": "W1", "p_eq": 2.0, "lam": 0.1, "eta": 0.9}]')
    site = parse_site_text('{"hazard": {"code": "EC8", "a_gR": 0.2, "FC": 1.2}}')
    lines = run_check(cf, site).summary
    assert lines[0] == "W1: linear not run, nonlinear not run"
    assert "virtual_work" in lines[1]


def test_missing_site_is_named() -> None:
    with pytest.raises(InputError) as err:
        parse_site_text("")
    assert err.value.field == "site"
