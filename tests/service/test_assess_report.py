"""The assessment report: verdict table on page one, in a real headless browser and in the PDF.

The browser tests use Debian's ``chromium`` and poppler's ``pdftotext`` and skip, with the
reason, where they are absent.
"""

import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shared_schema.constants import parse_constants
from shared_schema.site import parse_site
from solver_service.cli import app
from solver_service.core.records import GroundMotion
from solver_service.workflows.assess import assessment_doc

pytest.importorskip("jinja2")

from solver_service.report.assess import render_assessment, sig

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
    doc = assessment_doc(cf, site, [motion], multiples=(1.0,))
    text = render_assessment(doc, cf, site, [motion])
    rows = re.findall(r'<tr data-mechanism="([^"]+)">', text)
    assert rows == [m.id for m in cf.mechanisms]
    assert text.count("no virtual_work in the constants") >= len(rows)
    # F1 is one-sided without eta: its dynamics and envelope say why they did not run.
    f1 = next(r for r in doc["mechanisms"] if r["id"] == "F1")
    assert "eta" in f1["envelope"]["note"]


def test_each_number_of_the_worked_checks_names_its_clause() -> None:
    cf = parse_constants(CHURCH_GEOMETRY.read_bytes())
    site = parse_site(NTC_SITE.read_bytes())
    doc = assessment_doc(cf, site, [], multiples=(1.0,))
    text = render_assessment(doc, cf, site, [])
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


def test_project_fields_are_escaped_and_a_user_template_wins(tmp_path: Path) -> None:
    cf = parse_constants(CHURCH_GEOMETRY.read_bytes())
    data = json.loads(NTC_SITE.read_text(encoding="utf-8"))
    data["project"]["client"] = "<script>alert(1)</script>"
    site = parse_site(data)
    doc = assessment_doc(cf, site, [], multiples=(1.0,))
    text = render_assessment(doc, cf, site, [])
    assert "<script>alert(1)</script>" not in text and "&lt;script&gt;" in text
    firm = tmp_path / "firm"
    firm.mkdir()
    (firm / "assess.html.j2").write_text(
        "<h1>ACME</h1>{% for v in verdicts %}<p>{{ v.row.id }}</p>{% endfor %}", encoding="utf-8"
    )
    text = render_assessment(doc, cf, site, [], template_dir=firm)
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
    assert re.findall(r'<tr data-mechanism="([^"]+)">', dom) == ["F1", "F2", "A1", "T1"]


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
    for mech_id, verdict in (("F1", "fails"), ("F2", "fails"), ("A1", "fails"), ("T1", "passes")):
        line = next(ln for ln in first.splitlines() if ln.strip().startswith(mech_id))
        assert verdict in line, line
    assert "Governing mechanism for the code check" in first


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
