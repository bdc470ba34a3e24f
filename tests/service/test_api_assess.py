"""``POST /check`` and ``POST /assess`` over HTTP, against ``rockmech check`` / ``rockmech assess``.

The reference is the command line run in-process on the same files (El Centro as a file
there, as samples in the request); the numbers must be the same, not close.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import httpx
import pytest
from api_helpers import EXAMPLES, cli_error, cli_json
from servers import TEST_SETTINGS

from rhino_plugin.flows.analyse import ServiceClient
from rhino_plugin.flows.check import run_check
from shared_schema.constants import parse_constants
from shared_schema.errors import InputError
from shared_schema.site import parse_site
from solver_service.api.jobs import run_job
from solver_service.api.jobspec import AssessHtmlJob, AssessJob, AssessPdfJob, check_job
from solver_service.core.records import GroundMotion
from solver_service.report.assess import chromium
from solver_service.workflows.assess import NO_VIRTUAL_WORK, check_doc
from solver_service.workflows.units import stamp

RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
GEOMETRY = EXAMPLES / "constants" / "church_geometry.json"
SHORT = EXAMPLES / "constants" / "church.json"
NTC = EXAMPLES / "sites" / "ntc_site.json"


#: A two-sample record.
TINY = {"accel": [0.0, 0.1], "dt": 0.01, "units": "g"}


def _json(path: Path) -> Any:
    return json.loads(path.read_text(encoding="utf-8"))


def _elcentro() -> dict[str, Any]:
    """El Centro NS as request samples: the file's own values in g, its step and name."""
    motion = GroundMotion.from_file(str(RECORD), units="g")
    rows = [line.split() for line in RECORD.read_text().splitlines() if line.strip()]
    accel = [float(r[1]) for r in rows]
    assert len(accel) == motion.accel.n
    return {"accel": accel, "dt": motion.dt, "units": "g", "name": motion.name}


def _assess_body(**extra: Any) -> dict[str, Any]:
    return {"constants": _json(GEOMETRY), "site": _json(NTC), "records": [_elcentro()], **extra}


def test_check_equals_rockmech_check_json(client: httpx.Client) -> None:
    res = client.post("/api/v1/check", json={"constants": _json(GEOMETRY), "site": _json(NTC)})
    assert res.status_code == 200, res.text
    doc = res.json()
    assert doc == cli_json("check", str(GEOMETRY), str(NTC))
    assert [m["id"] for m in doc["mechanisms"]] == ["F1", "F2", "A1", "T1"]
    assert all(m["linear"]["status"] == "ok" for m in doc["mechanisms"])
    assert doc["governing"] in {"F1", "F2", "A1", "T1"}


@pytest.mark.slow
def test_assess_json_equals_rockmech_assess_on_el_centro(
    client: httpx.Client, tmp_path: Path
) -> None:
    res = client.post("/api/v1/assess", json=_assess_body())
    assert res.status_code == 200, res.text
    assert res.headers["content-type"].startswith("application/json")
    doc = res.json()
    want = cli_json(
        "assess", str(GEOMETRY), str(NTC), "--record", str(RECORD), "-o", str(tmp_path / "a.html")
    )
    assert doc == want
    assert doc["multiples"] == [0.5, 1.0, 1.5, 2.0]
    assert doc["records"][0]["name"] == "elcentro_NS"
    runs = doc["mechanisms"][0]["dynamics"][0]["runs"]
    assert [r["multiple"] for r in runs] == [0.5, 1.0, 1.5, 2.0]


def test_assess_html_has_the_verdict_table_and_provenance(client: httpx.Client) -> None:
    res = client.post("/api/v1/assess", json=_assess_body(format="html", multiples=[1.0]))
    assert res.status_code == 200, res.text
    assert res.headers["content-type"].startswith("text/html")
    page = res.text
    assert '<table id="verdict-table">' in page
    rows = re.findall(r'<tr data-mechanism="([^"]+)"', page)
    assert rows == ["F1", "F2", "A1", "T1"]
    assert "A. Engineer" in page  # the site's project fields fill page one
    assert page.count("<h2>Provenance</h2>") == 1
    assert "http://" not in page and "https://" not in page  # self-contained


@pytest.mark.slow
def test_assess_pdf_is_the_page_printed_by_headless_chromium(client: httpx.Client) -> None:
    if chromium() is None:
        pytest.skip("no Chromium on this machine (apt-get install chromium)")
    res = client.post("/api/v1/assess", json=_assess_body(format="pdf", multiples=[1.0]))
    assert res.status_code == 200, res.text
    assert res.headers["content-type"] == "application/pdf"
    assert res.content.startswith(b"%PDF-") and res.content.rstrip().endswith(b"%%EOF")
    assert len(res.content) > 10_000


def test_assess_pdf_without_chromium_is_501_naming_it(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    # A deployment without a browser (PATH holds none): the page is computed nowhere and the
    # answer says what is missing and what to do.
    monkeypatch.setenv("PATH", str(tmp_path))
    job = AssessPdfJob(**_assess_body(format="pdf", multiples=[1.0]))
    limits = {"max_samples": 500_000, "max_mechanisms": 100, "max_scales": 100}
    out = run_job(job, [], limits)
    assert out.status == 501
    detail = json.loads(out.body)["detail"]
    assert "needs a headless Chromium, which this deployment lacks" in detail
    assert "apt-get install chromium" in detail and "format html" in detail


def test_bad_site_is_422_naming_the_field_as_rockmech_does(
    client: httpx.Client, tmp_path: Path
) -> None:
    site = _json(NTC)
    site["hazard"]["a_g"] = -0.26
    res = client.post("/api/v1/check", json={"constants": _json(GEOMETRY), "site": site})
    assert res.status_code == 422, res.text
    err = res.json()
    assert err["field"] == "site.hazard.NTC2018.a_g"
    bad = tmp_path / "site.json"
    bad.write_text(json.dumps(site))
    assert err["detail"] == "site: " + cli_error("check", str(GEOMETRY), str(bad))


@pytest.mark.parametrize(
    "virtual_work",
    [
        {"alpha0": 0.1, "mass": 72522.0, "S": 1e-200, "J": 1.8e6},  # S^2 underflows: e* = 0
        {"alpha0": 0.1, "mass": 1e300, "S": 1e200, "J": 1e100},  # S^2 and mass J overflow
    ],
)
def test_virtual_work_out_of_double_range_is_422_as_rockmech_says(
    client: httpx.Client, tmp_path: Path, virtual_work: dict[str, float]
) -> None:
    # issue #19: a participating mass fraction e* = S^2/(mass J) of 0 was a 500
    # (ZeroDivisionError in the linear check), inf/inf a NaN.
    constants = _json(GEOMETRY)
    constants["mechanisms"][0]["positive"]["virtual_work"] = virtual_work
    res = client.post("/api/v1/check", json={"constants": constants, "site": _json(NTC)})
    assert res.status_code == 422, res.text
    err = res.json()
    assert err["field"] == "constants.mechanisms[0] (id 'F1').positive.virtual_work.S"
    assert "out of any physical range" in err["detail"]
    bad = tmp_path / "constants.json"
    bad.write_text(json.dumps(constants))
    message = cli_error("check", str(bad), str(NTC))
    assert err["detail"] == "constants: " + message.removeprefix(f"{bad}: ")


def test_a_record_without_a_complete_cycle_is_assessed(client: httpx.Client) -> None:
    # issue #19: one crossing through a zero sample made the pulse search an IndexError (500).
    record = {"accel": [0.1, 0.0, -0.1], "dt": 0.01, "units": "g", "name": "one crossing"}
    res = client.post("/api/v1/assess", json=_assess_body(records=[record], multiples=[1.0]))
    assert res.status_code == 200, res.text
    assert [r["name"] for r in res.json()["records"]] == ["one crossing"]


def test_constants_without_virtual_work_answer_rows_that_say_why(client: httpx.Client) -> None:
    res = client.post("/api/v1/check", json={"constants": _json(SHORT), "site": _json(NTC)})
    assert res.status_code == 200, res.text
    doc = res.json()
    assert doc == cli_json("check", str(SHORT), str(NTC))
    for row in doc["mechanisms"]:
        for method in ("linear", "nonlinear"):
            assert row[method]["status"] == "not_run"
            assert row[method]["note"] == NO_VIRTUAL_WORK
        assert row["passes"] is None
    assert doc["governing"] is None


@pytest.mark.parametrize(
    ("change", "field", "text"),
    [
        ({"records": [TINY] * 6}, "records", "at most 5"),
        ({"multiples": [1.0] * 9}, "multiples", "at most 8"),
        ({"multiples": [1.0, 0.0]}, "multiples[1]", "greater than 0"),
        ({"format": "docx"}, "format", "'json', 'html' or 'pdf'"),
    ],
)
def test_assess_request_out_of_bounds_is_422(
    client: httpx.Client, change: dict[str, Any], field: str, text: str
) -> None:
    res = client.post("/api/v1/assess", json=_assess_body(**change))
    assert res.status_code == 422, res.text
    assert res.json()["field"] == field
    assert text in res.json()["detail"]


def test_records_over_the_sample_limit_together_are_refused_up_front(
    client: httpx.Client,
) -> None:
    n = TEST_SETTINGS["max_samples"] // 2 + 5_000
    record = {"accel": [0.0, 0.01] * (n // 2), "dt": 0.01, "units": "g"}
    res = client.post("/api/v1/assess", json=_assess_body(records=[record, record]))
    assert res.status_code == 422, res.text
    err = res.json()
    assert err["field"] == "records"
    assert f"{2 * (n // 2) * 2} record samples exceed" in err["detail"]
    assert "ROCKMECH_MAX_SAMPLES" in err["detail"]


def test_stiff_mechanism_on_a_record_is_refused_before_any_run(client: httpx.Client) -> None:
    # p_eq dt = 1000 segments per sample over 2999 intervals: past 20 x max_samples per run
    # (p_eq at the top of its time-domain range, dt at the top of a record's).
    body = _assess_body(
        constants={"mechanisms": [{"id": "W1", "p_eq": 1.0e3, "lam": 0.1, "eta": 0.9}]},
        records=[{"accel": [0.0, 0.1] * 1500, "dt": 1.0, "units": "g"}],
    )
    res = client.post("/api/v1/assess", json=body)
    assert res.status_code == 422, res.text
    assert res.json()["field"] == "records[0]"
    assert "closed-form steps" in res.json()["detail"]


def test_html_pages_past_the_budget_or_answer_size_are_refused() -> None:
    mechs = [{"id": f"W{i}", "p_eq": 2.0, "lam": 0.1, "eta": 0.9} for i in range(10)]
    body = {
        "constants": {"mechanisms": mechs},
        "site": _json(NTC),
        "records": [{"accel": [0.0, 0.1, 0.0], "dt": 0.01, "units": "g"}] * 5,
    }
    limits = {**TEST_SETTINGS, "budget_s": 1.0, "max_answer_bytes": 64 * 2**20}
    check_job(AssessJob.model_validate(body), limits)  # the document is cheap
    with pytest.raises(InputError, match="would draw 71 figures") as err:
        check_job(AssessHtmlJob.model_validate(body), limits)
    assert err.value.field == "format"
    small = {**limits, "budget_s": 100.0, "max_answer_bytes": 1_000_000}
    with pytest.raises(InputError, match="about 4 MiB") as err:
        check_job(AssessHtmlJob.model_validate(body), small)
    assert err.value.field == "format"


def test_code_check_flow_through_the_service_equals_the_python_api(server: Any) -> None:
    cf = parse_constants(GEOMETRY.read_bytes())
    site = parse_site(NTC.read_bytes())
    result = run_check(cf, site, client=ServiceClient(server.url))
    assert result.doc.to_dict() == stamp(check_doc(cf, site), "check")  # units and version added
    assert result.summary == run_check(cf, site).summary


def test_code_check_flow_reports_the_services_refusal(server: Any) -> None:
    limit = TEST_SETTINGS["max_mechanisms"]
    mechs = [{"id": f"W{i}", "p_eq": 2.0, "lam": 0.1, "eta": 0.9} for i in range(limit + 1)]
    cf = parse_constants(json.dumps(mechs))
    site = parse_site(NTC.read_bytes())
    want = f"answered 422: constants: {limit + 1} mechanisms exceed"
    with pytest.raises(InputError, match=want) as err:
        run_check(cf, site, client=ServiceClient(server.url))
    assert err.value.field == "service"


def test_site_contradicting_the_constants_is_422_as_rockmech_says(
    client: httpx.Client, tmp_path: Path
) -> None:
    # The site's building.T1 (0.6 s) against the two-block wall's 1/f_n (0.32 s): one first
    # period decides the check (Circolare 2019 [C7.3.2], docs/theory.md §11.5).
    constants = _json(GEOMETRY)
    constants["mechanisms"][3]["amplification"] = {"f_n": 3.1, "h_e": 3.0, "h": 3.0}
    res = client.post("/api/v1/check", json={"constants": constants, "site": _json(NTC)})
    assert res.status_code == 422, res.text
    err = res.json()
    bad = tmp_path / "constants.json"
    bad.write_text(json.dumps(constants))
    message = cli_error("check", str(bad), str(NTC))
    assert message.startswith("building.T1: ")
    assert err["field"].endswith("building.T1")
    assert message.split(": ", 1)[1] in err["detail"]


def test_assess_adds_the_records_demand_to_the_nonlinear_check(client: httpx.Client) -> None:
    # Circolare 2019 §C8.7.1.2.1.8: with records, the largest spectral displacement over
    # [T0, T_SLV] at the design scale; the larger of it and the code spectrum's governs.
    res = client.post("/api/v1/assess", json=_assess_body(multiples=[1.0]))
    assert res.status_code == 200, res.text
    for row in res.json()["mechanisms"]:
        slv = row["nonlinear"]["SLV"]
        assert slv["demand_records"] is not None and slv["records"][0]["at_T"] <= slv["T_SLV"]
        assert slv["demand"] == max(slv["demand_code"], slv["demand_records"])
        assert "[C8.7.1.10]" in slv["clauses"]["T_SLV"]
