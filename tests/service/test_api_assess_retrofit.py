"""``POST /api/v1/assess`` with a ``retrofit`` spec, against ``rockmech assess --retrofit`` (#39).

On the bundled church (constants with their geometry, the NTC site, El Centro as samples in
the request and as the file on the command line, the bundled retrofit spec): the document
must be the one ``rockmech assess --retrofit --json`` prints, not close numbers. The tie force
is checked once more by hand from the assessment's own numbers ([C8.7.1.1]: α0 affine in
the tie force, a tie T at h_t above the hinge adding T h_t/(g S), so the linear ratio
reaches 1 at T = (α0/ratio − α0) g S/h_t; tests/service/test_assess_retrofit.py gives the
reasoning clause by clause). A spec naming a mechanism that is not there is a 422 naming
``retrofit.mechanisms.F9``; the HTML page carries the table on page one.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import httpx
import pytest
from api_helpers import EXAMPLES, cli_json

from solver_service.core.records import GroundMotion

RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
CHURCH = EXAMPLES / "constants" / "church_geometry.json"
SITE = EXAMPLES / "sites" / "ntc_site.json"
SPEC = EXAMPLES / "specs" / "church.retrofit.json"
G = 9.80665
#: A two-sample record: the assessment's dynamics cost nothing (the bad-input cases).
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


def _body(record: dict[str, Any], **extra: Any) -> dict[str, Any]:
    return {"constants": _json(CHURCH), "site": _json(SITE), "records": [record],
            "multiples": [1.0], "retrofit": _json(SPEC), **extra}  # fmt: skip


def test_assess_with_a_retrofit_is_the_clis_document(client: httpx.Client, tmp_path: Path) -> None:
    res = client.post("/api/v1/assess", json=_body(_elcentro()))
    assert res.status_code == 200, res.text
    doc = res.json()
    want = cli_json("assess", str(CHURCH), str(SITE), "--record", str(RECORD), "--multiple", "1",
                    "-o", str(tmp_path / "a.html"), "--retrofit", str(SPEC))  # fmt: skip
    assert doc == want
    # By hand: F1's linear force from the assessment's own linear check and the constants' S.
    row = next(r for r in doc["mechanisms"] if r["id"] == "F1")
    lin = row["sides"]["positive"]["linear"]
    f1 = next(m for m in _json(CHURCH)["mechanisms"] if m["id"] == "F1")
    a0, ratio = lin["alpha0"], lin["capacity_ratio"]
    heights = _json(SPEC)["mechanisms"]["F1"]["heights_m"]
    t_hand = min((a0 / ratio - a0) * G * f1["positive"]["virtual_work"]["S"] / h for h in heights)
    m = next(x for x in doc["retrofit"]["mechanisms"] if x["id"] == "F1")
    tie = m["options"][m["chosen"]]
    assert tie["T_linear_N"] == pytest.approx(t_hand, rel=1e-6)
    assert tie["T_star_N"] >= t_hand and tie["after"]["linear_ratio"] >= 1.0 - 1e-9
    assert [r["name"] for r in doc["retrofit"]["records"]] == [_elcentro()["name"]]


def test_without_a_retrofit_the_document_has_none(client: httpx.Client) -> None:
    body = _body(TINY)
    del body["retrofit"]
    res = client.post("/api/v1/assess", json=body)
    assert res.status_code == 200, res.text
    assert "retrofit" not in res.json()


@pytest.mark.parametrize(
    ("edit", "field", "words"),
    [
        ({"mechanisms": {"F9": {}}}, "retrofit.mechanisms.F9", "no mechanism 'F9'"),
        ({"steel": {"grade": "S460", "diameters_mm": [16]}}, "retrofit.steel.grade", "S235"),
    ],
    ids=["unknown_mechanism", "grade"],
)
def test_a_bad_retrofit_is_a_422_naming_the_field(
    client: httpx.Client, edit: dict[str, Any], field: str, words: str
) -> None:
    res = client.post("/api/v1/assess", json=_body(TINY, retrofit={**_json(SPEC), **edit}))
    assert res.status_code == 422, res.text
    body = res.json()
    assert body["field"] == field and words in body["detail"], body


def test_the_page_carries_the_retrofit_table_on_page_one(client: httpx.Client) -> None:
    pytest.importorskip("jinja2")
    res = client.post("/api/v1/assess", json=_body(TINY, format="html"))
    assert res.status_code == 200, res.text
    page = res.text
    start = page.index('id="summary">')
    one = page[start : page.index("</section>", start)]
    assert 'id="retrofit-table"' in one and 'data-mechanism="F1"' in one
