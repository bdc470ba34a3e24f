"""``rockmech assess --retrofit``: the retrofit table on page one of the assessment report.

On the bundled church (constants with their geometry, the NTC site, El Centro, the bundled
retrofit spec). The reference for the tie force is worked here from the assessment's own
numbers, not from the retrofit's code: [C8.7.1.1] makes α0 affine in the tie force, a tie T
at h_t above the hinge adding T h_t/(g S) (S = Σ P_k δ_PQx,k/g per unit rotation, the
constants' ``virtual_work.S``), and the linear demand does not depend on T, so the ratio
a_g,SLV/a_g is proportional to α0 and reaches 1 at T = (α0/ratio − α0) g S/h_t. The bar is
NTC 2018 [4.2.6]: N_pl,Rd = A f_yk/γ_M0, f_yk = 275 N/mm² (S275, Tab. 4.2.I), γ_M0 = 1.05
(Tab. 4.2.VII). With El Centro the retrofit takes the records' demand in its nonlinear
check as the assessment does (Circ. 2019 C8.7.1.2.1.8), so the linear force by hand is F1's
linear criterion and a lower bound of its T*. The page is opened in a real headless Chromium
and printed to PDF where the machine has them (the test skips, saying why, where it does
not).
"""

from __future__ import annotations

import contextlib
import html
import json
import math
import re
import shlex
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from solver_service.cli import app

pytest.importorskip("jinja2")

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
CHURCH = EXAMPLES / "constants" / "church_geometry.json"
SITE = EXAMPLES / "sites" / "ntc_site.json"
SPEC = EXAMPLES / "specs" / "church.retrofit.json"
G = 9.80665
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run"]
runner = CliRunner()


def _tool(*names: str) -> str:
    for name in names:
        path = shutil.which(name)
        if path:
            return path
    pytest.skip(f"{names[0]} is not on this machine (Debian: chromium, poppler-utils)")


def _assess(out: Path, *extra: str) -> tuple[str, dict[str, Any]]:
    """Run ``rockmech assess`` on the church with ``extra``; return the page and its JSON."""
    args = ["assess", str(CHURCH), str(SITE), "--record", str(RECORD), "--multiple", "1",
            "-o", str(out), *extra, "--json"]  # fmt: skip
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    return out.read_text(encoding="utf-8"), json.loads(res.stdout)


def _page_one(page: str) -> str:
    start = page.index('id="summary">')
    return page[start : page.index("</section>", start)]


def _table(page: str) -> dict[str, list[str]]:
    """The retrofit table's cells (tags stripped), by mechanism id."""
    body = page.split('<table id="retrofit-table">', 1)[1].split("</table>", 1)[0]
    rows = {}
    for mech, cells in re.findall(r'<tr data-mechanism="([^"]+)"[^>]*>(.*?)</tr>', body, re.S):
        texts = re.findall(r"<td[^>]*>(.*?)</td>", cells, re.S)
        rows[mech] = [html.unescape(re.sub(r"<[^>]+>", " ", t)).split() for t in texts]
    return {k: [" ".join(c) for c in v] for k, v in rows.items()}


@pytest.fixture(scope="module")
def with_spec(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, dict[str, Any]]:
    return _assess(tmp_path_factory.mktemp("spec") / "report.html", "--retrofit", str(SPEC))


def test_page_one_carries_the_tie_that_makes_f1_pass(with_spec: tuple[str, dict]) -> None:
    page, doc = with_spec
    one = _page_one(page)
    assert 'id="retrofit-table"' in one  # on page one, before the site section
    table = _table(page)
    assert list(table) == ["F1", "F2", "A1", "T1"]
    # The reference: F1's linear check before the tie, from the assessment document, and
    # its virtual work from the constants.
    row = next(r for r in doc["mechanisms"] if r["id"] == "F1")
    lin = row["sides"]["positive"]["linear"]
    constants = json.loads(CHURCH.read_text())
    f1 = next(m for m in constants["mechanisms"] if m["id"] == "F1")
    s_work = f1["positive"]["virtual_work"]["S"]
    a0, ratio = lin["alpha0"], lin["capacity_ratio"]
    assert ratio < 1.0
    heights = json.loads(SPEC.read_text())["mechanisms"]["F1"]["heights_m"]
    t_hand = min((a0 / ratio - a0) * G * s_work / h for h in heights)  # the higher tie
    rdoc = doc["retrofit"]
    m = next(x for x in rdoc["mechanisms"] if x["id"] == "F1")
    tie = m["options"][m["chosen"]]
    assert tie["height_m"] == max(heights)
    assert tie["T_linear_N"] == pytest.approx(t_hand, rel=1e-6)
    # With El Centro's demand (C8.7.1.2.1.8), the nonlinear SLV check needs more than the
    # linear one: it governs, and the tie carries its force.
    assert tie["governing"] == "nonlinear SLV"
    assert tie["T_star_N"] == tie["T_nonlinear_SLV_N"] > t_hand
    # Two bars share it; Ø16 S275 carries π 16²/4 · 275/1.05 = 52.7 kN.
    per_bar = tie["T_star_N"] / 2
    assert tie["bar"]["diameter_mm"] == 16.0
    assert tie["bar"]["N_pl_Rd_N"] == pytest.approx(math.pi * 64.0 * 275.0 / 1.05, rel=1e-12)
    assert per_bar <= tie["bar"]["N_pl_Rd_N"]
    mech, status, bars, force, governs, ratios = table["F1"]
    assert (mech, status, bars, governs) == ("F1", "tie designed", "2 Ø16 S275 at 8 m",
                                             "nonlinear SLV")  # fmt: skip
    found = re.fullmatch(r"([0-9.]+) \(([0-9.]+)\)", force)
    assert found is not None, force
    total, each = found.groups()
    assert float(total) == float(f"{tie['T_star_N'] / 1e3:.3g}")  # 3 significant figures
    assert float(each) == float(f"{per_bar / 1e3:.3g}")
    before, after = re.findall(r"[0-9.]+", ratios)[:2]
    least_before = min(
        r for r in (row["linear"]["capacity_ratio"], row["nonlinear"]["capacity_ratio"])
    )
    assert float(before) == float(f"{least_before:.3g}") and float(after) >= 1.0
    # The sentence a client can quote, in the retrofit's section after page one.
    detail = html.unescape(page.split('<section id="retrofit">', 1)[1].split("</section>", 1)[0])
    assert f"2 Ø16 S275 ties at 8 m, {per_bar / 1e3:.3g} kN each, make F1 pass" in detail
    # A1 and T1 are chains of blocks: each says why it gets no tie.
    assert table["A1"][1] == "not retrofitted by a tie" and table["A1"][2] == "–"
    assert "A1: not retrofitted by a tie: typology multi_block" in detail
    # With El Centro the nonlinear demand of F2 and A1 is also the record's (C8.7.1.2.1.8):
    # the retrofit run from the spec takes it too, so its "before" is the assessment's and
    # nothing is flagged.
    for r in doc["mechanisms"]:
        b = next(x for x in rdoc["mechanisms"] if x["id"] == r["id"])["before"]
        assert b["SLV_ratio"] == pytest.approx(r["nonlinear"]["capacity_ratio"], rel=1e-9)
    assert "†" not in html.unescape(one)
    # The anchorage resistance is the user's, shown with its source.
    assert "60.0 kN per tie (illustrative: plate punching" in detail


def test_the_documents_retrofit_is_rockmech_retrofits(with_spec: tuple[str, dict]) -> None:
    _, doc = with_spec
    res = runner.invoke(
        app,
        ["retrofit", str(CHURCH), "--site", str(SITE), "--spec", str(SPEC), "--record",
         str(RECORD), "--json"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert doc["retrofit"] == json.loads(res.stdout)


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_a_retrofit_json_gives_the_same_table(with_spec: tuple[str, dict], tmp_path: Path) -> None:
    res = runner.invoke(
        app,
        ["retrofit", str(CHURCH), "--site", str(SITE), "--spec", str(SPEC), "--record",
         str(RECORD), "-o", str(tmp_path)],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    page, doc = _assess(tmp_path / "r.html", "--retrofit", str(tmp_path / "retrofit.json"))
    assert _table(page) == _table(with_spec[0])
    assert doc["retrofit"] == with_spec[1]["retrofit"]


def test_a_retrofit_json_made_without_the_records_is_flagged(tmp_path: Path) -> None:
    """A retrofit.json sized on the site spectrum alone, beside an assessment with records."""
    res = runner.invoke(
        app,
        ["retrofit", str(CHURCH), "--site", str(SITE), "--spec", str(SPEC), "-o", str(tmp_path)],
    )
    assert res.exit_code == 0, res.output
    page, doc = _assess(tmp_path / "r.html", "--retrofit", str(tmp_path / "retrofit.json"))
    rdoc, one, table = doc["retrofit"], _page_one(page), _table(page)
    assert rdoc["records"] == []
    # With El Centro the nonlinear demand of F2 and A1 is also the record's (C8.7.1.2.1.8):
    # their assessment ratios are below the document's, sized on the site spectrum; said.
    sentences = html.unescape(page.split('id="retrofit-sentences"', 1)[1].split("</ul>", 1)[0])
    for mid in ("F2", "A1"):
        r = next(x for x in doc["mechanisms"] if x["id"] == mid)
        b = next(x for x in rdoc["mechanisms"] if x["id"] == mid)["before"]
        assert r["nonlinear"]["capacity_ratio"] < b["SLV_ratio"]
        assert (
            f"{mid}: with the records' demand (Circ. 2019 C8.7.1.2.1.8) this assessment's "
            f"a_g,SLV/a_g nonlinear is {r['nonlinear']['capacity_ratio']:.3g}; the retrofit's "
            f"{b['SLV_ratio']:.3g} is the site spectrum's alone"
        ) in sentences
    assert "F1: with the records" not in sentences  # F1's record demand is the spectrum's
    assert "† F2, A1: with the records' demand" in html.unescape(one)  # flagged on page one
    assert [r for r in table if table[r][-1].endswith("†") or "† " in table[r][-1]] == ["F2", "A1"]


def test_a_retrofit_json_of_another_site_is_refused(tmp_path: Path) -> None:
    site = json.loads(SITE.read_text())
    site["hazard"]["a_g"] = site["hazard"]["a_g"] * 0.8
    other = tmp_path / "other_site.json"
    other.write_text(json.dumps(site))
    res = runner.invoke(
        app,
        ["retrofit", str(CHURCH), "--site", str(other), "--spec", str(SPEC), "-o", str(tmp_path)],
    )
    assert res.exit_code == 0, res.output
    made = tmp_path / "retrofit.json"
    args = ["assess", str(CHURCH), str(SITE), "--record", str(RECORD), "--multiple", "1",
            "-o", str(tmp_path / "r.html"), "--retrofit", str(made)]  # fmt: skip
    res = runner.invoke(app, args)
    assert res.exit_code == 2, res.output
    (line,) = res.stderr.strip().splitlines()
    assert line.startswith("error: retrofit: the retrofit document's F1 has ")
    assert "made from other constants or another site" in line
    assert not (tmp_path / "r.html").exists()


def test_a_retrofit_json_made_with_records_needs_them(tmp_path: Path) -> None:
    """Made with El Centro, shown beside an assessment without it: F2's "before" differs."""
    res = runner.invoke(
        app,
        ["retrofit", str(CHURCH), "--site", str(SITE), "--spec", str(SPEC), "--record",
         str(RECORD), "-o", str(tmp_path)],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    args = ["assess", str(CHURCH), str(SITE), "-o", str(tmp_path / "r.html"),
            "--retrofit", str(tmp_path / "retrofit.json")]  # fmt: skip
    res = runner.invoke(app, args)
    assert res.exit_code == 2, res.output
    (line,) = res.stderr.strip().splitlines()
    assert line.startswith("error: retrofit: the retrofit document's F2 has "), line
    assert "or other records than its elcentro_NS;" in line
    assert not (tmp_path / "r.html").exists()


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (lambda s: s["steel"].update(grade="S460"), "error: retrofit.steel.grade: "),
        (
            lambda s: s["anchorage"].pop("source"),
            "error: retrofit.anchorage.source: Field required",
        ),
        (lambda s: s["mechanisms"].update(F9={}), "error: retrofit.mechanisms.F9: no mechanism"),
    ],
    ids=["grade", "no_source", "unknown_mechanism"],
)
def test_a_bad_retrofit_spec_is_one_line_naming_the_field(
    tmp_path: Path, change: Any, words: str
) -> None:
    spec = json.loads(SPEC.read_text())
    change(spec)
    path = tmp_path / "bad.retrofit.json"
    path.write_text(json.dumps(spec))
    args = ["assess", str(CHURCH), str(SITE), "-o", str(tmp_path / "r.html"),
            "--retrofit", str(path)]  # fmt: skip
    res = runner.invoke(app, args)
    assert res.exit_code == 2, res.output
    (line,) = res.stderr.strip().splitlines()
    assert line.startswith(words), line


def test_without_retrofit_the_page_and_document_have_none(tmp_path: Path) -> None:
    page, doc = _assess(tmp_path / "r.html")
    assert "retrofit" not in doc and 'id="retrofit-table"' not in page


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_the_printed_command_gives_the_retrofit_again(
    with_spec: tuple[str, dict], tmp_path: Path
) -> None:
    page, doc = with_spec
    (command,) = re.findall(r"<code>(rockmech assess .*?)</code>", page)
    argv = shlex.split(html.unescape(command))
    assert "--retrofit" in argv and argv[argv.index("--retrofit") + 1] == SPEC.name
    for src in (CHURCH, SITE, RECORD, SPEC):
        shutil.copy(src, tmp_path / src.name)
    with contextlib.chdir(tmp_path):
        res = runner.invoke(app, argv[1:])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["retrofit"] == doc["retrofit"]


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_the_table_in_chromium_and_on_the_pdfs_first_page(tmp_path: Path) -> None:
    exe = _tool("chromium", "chromium-browser", "google-chrome")
    pdftotext = _tool("pdftotext")
    out = tmp_path / "report.html"
    _assess(out, "--retrofit", str(SPEC), "--pdf")
    dom = subprocess.run(
        [exe, *CHROMIUM_FLAGS, "--dump-dom", out.resolve().as_uri()],
        check=True,
        capture_output=True,
        timeout=120,
    ).stdout.decode("utf-8")
    loaded = re.search(r'data-plots-loaded="(\d+)/(\d+)"', dom)
    assert loaded is not None and loaded.group(1) == loaded.group(2)
    assert re.findall(r'<tr data-mechanism="([^"]+)" data-status="([^"]+)"', dom) == [
        ("F1", "designed"),
        ("F2", "designed"),
        ("A1", "not_applicable"),
        ("T1", "not_applicable"),
    ]
    first = subprocess.run(
        [pdftotext, "-layout", "-f", "1", "-l", "1", str(out.with_suffix(".pdf")), "-"],
        check=True,
        capture_output=True,
        timeout=60,
    ).stdout.decode("utf-8")
    words = " ".join(first.split())
    # Page one of the print ends with the retrofit table, each row on a line of its own.
    assert "Retrofit: tie-bars for the mechanisms that fail" in words
    lines = {ln.split()[0]: " ".join(ln.split()) for ln in first.splitlines() if ln.split()}
    # F1's tie is sized on the nonlinear SLV check with El Centro's demand (C8.7.1.2.1.8).
    assert lines["F1"].startswith(
        "F1 tie designed 2 Ø16 S275 at 8 m 34.6 (17.3) nonlinear SLV 0.313 → 1.00"
    )
    assert lines["F2"].startswith("F2 tie designed 1 Ø16 S275 at 8 m 15.8 linear SLV")
    assert lines["A1"].startswith("A1 not retrofitted by a tie")
    second = subprocess.run(
        [pdftotext, "-f", "2", "-l", "2", str(out.with_suffix(".pdf")), "-"],
        check=True,
        capture_output=True,
        timeout=60,
    ).stdout.decode("utf-8")
    assert "2 Ø16 S275 ties at 8 m, 17.3 kN each, make F1 pass" in " ".join(second.split())
