"""The assessment report: verdict table on page one, in a real headless browser and in the PDF.

The browser tests use Debian's ``chromium`` and poppler's ``pdftotext`` and skip, with the
reason, where they are absent.
"""

import contextlib
import html
import json
import re
import shlex
import shutil
import subprocess
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shared_schema.constants import parse_constants
from shared_schema.site import parse_site
from solver_service.cli import app
from solver_service.core.records import GroundMotion
from solver_service.workflows.assess import assessment_document, site_spectrum
from solver_service.workflows.pages import assessment_histories

pytest.importorskip("jinja2")

from solver_service.report.assess import render_assessment, sig
from solver_service.report.html import input_source

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
CHURCH_GEOMETRY = EXAMPLES / "constants" / "church_geometry.json"
CHURCH_SHORT = EXAMPLES / "constants" / "church.json"
NTC_SITE = EXAMPLES / "sites" / "ntc_site.json"
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run"]
runner = CliRunner()


def _tool(*names: str) -> str:
    for name in names:
        path = shutil.which(name)
        if path:
            return path
    pytest.skip(f"{names[0]} is not on this machine (Debian: chromium, poppler-utils)")


def _assess(tmp_path: Path, constants: Path, *extra: str) -> Path:
    out = tmp_path / "report.html"
    args = ["assess", str(constants), str(NTC_SITE), "--record", str(RECORD), "-o", str(out)]
    res = runner.invoke(app, [*args, *extra])
    assert res.exit_code == 0, res.output
    return out


def test_sig_gives_four_significant_figures() -> None:
    assert [sig(v) for v in (2, 0.2, 1234.5, 0.000123456, 1.0e7)] == [
        "2.000",
        "0.2000",
        "1234",
        "1.235e-04",
        "1.000e+07",
    ]


def test_short_form_church_gets_notes_in_every_row_not_an_abort() -> None:
    cf = parse_constants(CHURCH_SHORT.read_bytes())
    site = parse_site(NTC_SITE.read_bytes())
    motion = GroundMotion.from_two_column(RECORD)
    doc = assessment_document(cf, site, [motion], multiples=(1.0,))
    text = render_assessment(
        doc, cf, site, site_spectrum(site), assessment_histories(cf, doc, [motion])
    )
    rows = re.findall(r'<tr data-mechanism="([^"]+)"', text)
    assert rows == [m.id for m in cf.mechanisms]
    assert text.count("no virtual_work in the constants") >= len(rows)
    # F1 is one-sided without eta: its dynamics and envelope say why they did not run.
    f1 = next(r for r in doc.mechanisms if r.id == "F1")
    assert f1.envelope is not None and "eta" in (f1.envelope.note or "")


def test_each_number_of_the_worked_checks_names_its_clause() -> None:
    cf = parse_constants(CHURCH_GEOMETRY.read_bytes())
    site = parse_site(NTC_SITE.read_bytes())
    doc = assessment_document(cf, site, [], multiples=(1.0,))
    text = render_assessment(doc, cf, site, site_spectrum(site), {})
    tables = re.findall(r'<table class="worked">(.*?)</table>', text, flags=re.S)
    assert len(tables) == 2 * len(cf.mechanisms)  # linear and nonlinear, per mechanism
    for table in tables:
        rows = re.findall(
            r"<tr><td>(.*?)</td><td class=\"n\">(.*?)</td><td>(.*?)</td>"
            r'<td class="note">(.*?)</td></tr>',
            table,
            flags=re.S,
        )
        assert rows, table[:200]
        for label, _, _, clause in rows:
            assert clause.strip(), f"{label} has no clause"
    assert "[C8.7.1.10]" in text and "[C8.7.1.11]" in text and "[C8.7.1.8]" in text
    assert "Circolare 21 gennaio 2019 n. 7" in text
    # The checks are drawn on the capacity curve (ADRS) for every mechanism.
    assert text.count("<figcaption>" + "F1: the checks on the capacity curve (ADRS)") == 1
    assert text.count("the checks on the capacity curve (ADRS)") == 2 * len(
        cf.mechanisms
    )  # alt too
    # F1's ties are not verified: the report says so and d0 is without them.
    assert "ties not verified" in text


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_project_fields_are_escaped_and_a_user_template_wins(tmp_path: Path) -> None:
    cf = parse_constants(CHURCH_GEOMETRY.read_bytes())
    data = json.loads(NTC_SITE.read_text(encoding="utf-8"))
    data["project"]["client"] = "<script>alert(1)</script>"
    site = parse_site(data)
    doc = assessment_document(cf, site, [], multiples=(1.0,))
    text = render_assessment(doc, cf, site, site_spectrum(site), {})
    assert "<script>alert(1)</script>" not in text and "&lt;script&gt;" in text
    firm = tmp_path / "firm"
    firm.mkdir()
    (firm / "assess.html.j2").write_text(
        "<h1>ACME</h1>{% for v in verdicts %}<p>{{ v.row.id }}</p>{% endfor %}", encoding="utf-8"
    )
    text = render_assessment(doc, cf, site, site_spectrum(site), {}, template_dir=firm)
    assert text == "<h1>ACME</h1><p>F1</p><p>F2</p><p>A1</p><p>T1</p>"


def test_report_loads_every_plot_in_chromium(tmp_path: Path) -> None:
    exe = _tool("chromium", "chromium-browser", "google-chrome")
    page = _assess(tmp_path, CHURCH_GEOMETRY)
    dom = subprocess.run(
        [exe, *CHROMIUM_FLAGS, "--dump-dom", page.resolve().as_uri()],
        check=True,
        capture_output=True,
        timeout=120,
    ).stdout.decode("utf-8")
    loaded = re.search(r'data-plots-loaded="(\d+)/(\d+)"', dom)
    assert loaded is not None
    assert loaded.group(1) == loaded.group(2) and int(loaded.group(2)) >= 1 + 3 * 4
    assert re.findall(r'<tr data-mechanism="([^"]+)"', dom) == ["F1", "F2", "A1", "T1"]


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_pdf_first_page_shows_the_verdict_table(tmp_path: Path) -> None:
    _tool("chromium", "chromium-browser", "google-chrome")
    pdftotext = _tool("pdftotext")
    page = _assess(tmp_path, CHURCH_GEOMETRY, "--pdf")
    pdf = page.with_suffix(".pdf")
    assert pdf.read_bytes()[:5] == b"%PDF-"
    first = subprocess.run(
        [pdftotext, "-layout", "-f", "1", "-l", "1", str(pdf), "-"],
        check=True,
        capture_output=True,
        timeout=60,
    ).stdout.decode("utf-8")
    assert "Verdict" in first and "A. Engineer" in first and "2026-11-23" in first
    for mech_id, verdict in (("F1", "FAILS"), ("F2", "FAILS"), ("A1", "FAILS"), ("T1", "PASSES")):
        line = next(ln for ln in first.splitlines() if ln.strip().startswith(mech_id))
        assert verdict in line, line
    # Page one ends in the one sentence a client can quote: the JSON's conclusion.
    res = runner.invoke(
        app,
        ["assess", str(CHURCH_GEOMETRY), str(NTC_SITE), "--record", str(RECORD),
         "-o", str(tmp_path / "again.html"), "--json"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout[res.stdout.index("{") :])
    sentence = doc["conclusion"]["sentence"]
    assert sentence.startswith("The local collapse mechanisms of Example stone church")
    # F1 governs, and the sentence quotes its capacity ratio as the document holds it.
    governing = doc["conclusion"]["mechanisms"][0]
    ratio = governing["code_check"]["capacity_ratio"]
    assert 0.2 < ratio < 0.5  # the church's façade: 0.313 with the 2019 readings (e* by blocks)
    assert "do not satisfy" in sentence and "F1" in sentence and f"{ratio:.3f}" in sentence
    # (a word broken at a hyphen across two lines is read back as "tie- bars")
    words = " ".join(first.split()).replace("- ", "-")
    assert words.endswith(" ".join(sentence.split())), words[-400:]


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_short_form_church_pdf_first_page_has_every_row(tmp_path: Path) -> None:
    _tool("chromium", "chromium-browser", "google-chrome")
    pdftotext = _tool("pdftotext")
    page = _assess(tmp_path, CHURCH_SHORT, "--pdf")
    first = subprocess.run(
        [pdftotext, "-layout", "-f", "1", "-l", "1", str(page.with_suffix(".pdf")), "-"],
        check=True,
        capture_output=True,
        timeout=60,
    ).stdout.decode("utf-8")
    ids = [m.id for m in parse_constants(CHURCH_SHORT.read_bytes()).mechanisms]
    starts = [ln.split()[0] for ln in first.splitlines() if ln.split() and ln.split()[0] in ids]
    assert starts == ids
    assert "no virtual_work" in first


def _page_and_doc(tmp_path: Path) -> tuple[str, dict]:
    cf = parse_constants(CHURCH_GEOMETRY.read_bytes())
    site = parse_site(NTC_SITE.read_bytes())
    motion = GroundMotion.from_two_column(RECORD)
    doc = assessment_document(cf, site, [motion], multiples=[1.0, 2.0])
    sources = [
        input_source("constants", CHURCH_GEOMETRY.name, CHURCH_GEOMETRY.read_bytes()),
        input_source("site", NTC_SITE.name, NTC_SITE.read_bytes()),
        input_source("record", RECORD.name, RECORD.read_bytes()),
    ]
    page = render_assessment(
        doc,
        cf,
        site,
        site_spectrum(site),
        assessment_histories(cf, doc, [motion]),
        sources=sources,
        options={"multiples": [1.0, 2.0]},
    )
    return page, doc.to_dict()


def test_hazard_table_has_one_row_per_quantity_with_its_unit_and_source(tmp_path: Path) -> None:
    page, _ = _page_and_doc(tmp_path)
    table = page.split('<table id="hazard-table">', 1)[1].split("</table>", 1)[0]
    rows = re.findall(r"<tr><td>(.*?)</td><td>(.*?)</td><td class=\"n\">(.*?)</td><td>(.*?)</td>"
                      r"<td class=\"note\">(.*?)</td></tr>", table)  # fmt: skip
    quantities = [r[0] for r in rows]
    assert len(rows) >= 20 and len(set(quantities)) == len(quantities)
    assert all(r[3] and r[4] for r in rows)  # a unit ("–" where none) and a source each
    by_name = {r[0]: r for r in rows}
    assert by_name["reference peak ground acceleration on rock"][2:4] == ("0.2600", "g")
    assert by_name["peak ground acceleration at the site"][2:4] == ("0.3002", "g")
    assert by_name["fundamental period of the building"][2:5] == ("0.6000", "s", "site building.T1")
    assert by_name["end of the plateau"][3] == "s" and "[3.2.5]" in by_name["end of the plateau"][4]
    # No raw key of the site file or of the document is shown as a quantity.
    for raw in ("a_g_g", "Tc_star_s", "Tc_star", "xi_percent", "limit_states"):
        assert f">{raw}<" not in page


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_the_printed_command_gives_every_number_of_the_page_again(tmp_path: Path) -> None:
    page, doc = _page_and_doc(tmp_path)
    commands = re.findall(r"<code>(rockmech assess .*?)</code>", page)
    assert len(commands) == 1
    argv = shlex.split(html.unescape(commands[0]))
    assert argv[:2] == ["rockmech", "assess"] and "--json" in argv
    # In a folder holding the inputs under the provenance table's names.
    for src in (CHURCH_GEOMETRY, NTC_SITE, RECORD):
        shutil.copy(src, tmp_path / src.name)
    with contextlib.chdir(tmp_path):
        res = runner.invoke(app, argv[1:])
    assert res.exit_code == 0, res.output
    again = json.loads(res.stdout)

    def numbers(d: dict) -> dict:
        return {
            "conclusion": d["conclusion"],
            "mechanisms": [
                (r["id"], r["linear"].get("capacity_ratio"), r["nonlinear"].get("capacity_ratio"),
                 [[x["peak_ratio"] for x in dd["runs"]] for dd in r["dynamics"]])
                for r in d["mechanisms"]
            ],
            "site": d["site"],
        }  # fmt: skip

    assert numbers(again) == numbers(doc)
