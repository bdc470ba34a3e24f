"""Constants tables: a table round-trips to the same constants file as the equivalent JSON.

Bad tables are refused with the row (as a spreadsheet numbers it) and the column.
"""

from __future__ import annotations

import csv
import json
import math
import sys
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from shared_schema import io as constants_io
from shared_schema.errors import InputError
from shared_schema.io import parse_constants, stamped
from solver_service.cli import app
from solver_service.workflows.inputs import read_constants
from solver_service.workflows.tables import COLUMNS, XLSX_HINT, constants_from_table

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "constants"
runner = CliRunner()


def _rows(mechanisms: list[dict[str, Any]], columns: list[str]) -> list[list[Any]]:
    """One row per mechanism: the value each column's place in the mechanism holds."""
    out = []
    for mech in mechanisms:
        flat = {**mech, **mech.get("positive", {})}
        row = []
        for col in columns:
            where = COLUMNS[col][0]
            source: Any = flat if where[0] == "positive" else mech
            for key in where[1:] if where[0] == "positive" else where:
                source = source.get(key) if isinstance(source, dict) else None
            row.append("" if source is None else source)
        out.append(row)
    return out


def _write_csv(path: Path, columns: list[str], rows: list[list[Any]]) -> Path:
    with path.open("w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        writer.writerow(columns)
        writer.writerows([[repr(c) if isinstance(c, float) else c for c in r] for r in rows])
    return path


CHURCH_COLUMNS = ["id", "name", "typology", "rocking", "p_eq", "lam", "phi_ov", "eta"]
CHURCH_COLUMNS += ["eta_source", "f_n", "h_e", "h", "source"]


def test_church_table_round_trips_to_the_same_constants_as_its_json(tmp_path: Path) -> None:
    reference = constants_io.read_constants(EXAMPLES / "church.json")
    mechanisms = json.loads((EXAMPLES / "church.json").read_text())["mechanisms"]
    table = _write_csv(tmp_path / "church.csv", CHURCH_COLUMNS, _rows(mechanisms, CHURCH_COLUMNS))
    cf = constants_from_table(table)
    assert cf.model_dump(exclude_none=True) == reference.model_dump(exclude_none=True)
    # and through the command, byte for byte against the JSON written the same way
    out = tmp_path / "church.json"
    result = runner.invoke(app, ["constants-table", str(table), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "8 mechanism(s)" in result.output
    assert (
        constants_io.read_constants(out).model_dump_json() == stamped(reference).model_dump_json()
    )


def test_utf16_and_semicolon_tables_give_the_same_constants(tmp_path: Path) -> None:
    # Excel's "Unicode Text" is UTF-16; a European Excel writes ';' and decimal commas (#25)
    text = (EXAMPLES / "walls.csv").read_text(encoding="utf-8")
    want = constants_from_table(EXAMPLES / "walls.csv").model_dump()
    utf16 = tmp_path / "walls_utf16.csv"
    utf16.write_bytes(text.encode("utf-16"))
    rows = list(csv.reader(text.splitlines()))
    semi = tmp_path / "walls_semicolon.csv"
    with semi.open("w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f, delimiter=";")
        for row in rows:
            writer.writerow([c.replace(".", ",") if c[:1].isdigit() else c for c in row])
    assert "2,210517525" in semi.read_text() and "0.25 m" in semi.read_text()
    for path in (utf16, semi):
        assert constants_from_table(path).model_dump() == want, path.name
    # a text cell that looks like a decimal comma stays text (only numeric columns convert)
    semi.write_text("id;p_eq;lam;eta\n1,5;2,5;0,2;0,9\n", encoding="utf-8")
    mech = constants_from_table(semi).mechanisms[0]
    assert (mech.id, mech.positive.p_eq, mech.positive.lam) == ("1,5", 2.5, 0.2)


def test_physical_constants_round_trip_and_are_checked_for_consistency(tmp_path: Path) -> None:
    doc = json.loads((EXAMPLES / "rect_walls.json").read_text())
    for mech in doc["mechanisms"]:
        mech.pop("geometry")  # free-form: a table has no place for it
    reference = parse_constants(json.dumps(doc))
    columns = ["id", "name", "typology", "rocking", "I0", "K", "Q", "phi_cr", "M_F"]
    columns += ["p_eq", "lam", "phi_ov", "eta", "eta_source", "source"]
    rows = _rows(doc["mechanisms"], columns)
    cf = constants_from_table(_write_csv(tmp_path / "walls.csv", columns, rows))
    assert cf.model_dump() == reference.model_dump()
    rows[1][columns.index("lam")] = 0.5  # disagrees with K phi_cr / (g Q)
    with pytest.raises(InputError, match=r"walls\.csv row 3, column 'lam': given lam = 0\.5"):
        constants_from_table(_write_csv(tmp_path / "walls.csv", columns, rows))


def test_units_in_headers_and_degrees(tmp_path: Path) -> None:
    f = tmp_path / "t.csv"
    f.write_text(
        "ID,p_eq [rad/s],λ,phi_ov (deg),eta [-],f_n [Hz],h_e [m],h (m)\nW1,2.0,0.2,10,0.9,4,6,9\n"
    )
    mech = constants_from_table(f).mechanisms[0]
    assert mech.positive.phi_ov == pytest.approx(math.radians(10.0), rel=1e-15)
    assert mech.positive.lam == 0.2 and mech.amplification is not None
    assert (mech.amplification.f_n, mech.amplification.h_e, mech.amplification.h) == (4, 6, 9)


def test_negative_side_columns(tmp_path: Path) -> None:
    f = tmp_path / "t.csv"
    f.write_text("id,p_eq,lam,p_eq_neg,lam_neg,phi_ov_neg,eta\nA,2,0.2,2.5,0.3,0.25,0.9\n")
    mech = constants_from_table(f).mechanisms[0]
    assert mech.negative is not None
    assert (mech.negative.p_eq, mech.negative.lam, mech.negative.phi_ov) == (2.5, 0.3, 0.25)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("id,p_eq,lam\nW1,2.0,abc\n", r"row 2, column 'lam': not a number: 'abc'"),
        ("id,p_eq,lam\nW1,2.0,0.2\nW2,-1,0.2\n", r"row 3, column 'p_eq': .*greater than 0"),
        ("id,p_eq,lam,eta\n\nW1,2.0,0.2,-0.5\n", r"row 3, column 'eta': must be >= 0"),
        ("id,p_eq,lam\nW1,2.0,\n", r"row 2, column 'lam': .*lam is missing"),
        ("id,p_eq,lam,f_n,h_e\nW1,2,0.2,4,6\n", r"row 2, column 'h': Field required"),
        ("id,p_eq,lam\nW1,2,0.2\nW1,3,0.3\n", r"row 3, column 'id': duplicate mechanism id 'W1'"),
        ("id,p_eq,lam\n,2,0.2\n", r"row 2, column 'id': missing"),
        ("id,p_eq,lam,typology\nW1,2,0.2,arch\n", r"row 2, column 'typology': Input should be"),
        ("id,p_eq,lamda\nW1,2,0.2\n", r"row 1, column 3 'lamda': unknown; columns are"),
        ("id,p_eq [Hz],lam\nW1,2,0.2\n", r"row 1, column 'p_eq \[Hz\]': unit 'Hz', expected"),
        ("id,lam,lambda\nW1,0.2,0.2\n", r"row 1: columns 'lam' and 'lambda' are both lam"),
        ("p_eq,lam\n2,0.2\n", r"row 1: no 'id' column"),
        ("id,p_eq,lam\nW1,2,0.2,7\n", r"row 2, column 4: a value under no column name"),
        ("id,p_eq,lam\nW1,2,inf\n", r"row 2, column 'lam': must be finite"),
        ("id,p_eq,lam\n", r"a header but no mechanism rows"),
        ("", r"is empty"),
    ],
)
def test_bad_tables_name_the_row_and_column(tmp_path: Path, text: str, match: str) -> None:
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(InputError, match=match) as err:
        constants_from_table(f)
    assert err.value.field == "table"
    result = runner.invoke(app, ["constants-table", str(f), "-o", str(tmp_path / "c.json")])
    assert result.exit_code == 2 and "error: table: bad.csv" in result.output
    assert not (tmp_path / "c.json").exists()


def test_xlsx_table_gives_the_same_constants(tmp_path: Path) -> None:
    openpyxl = pytest.importorskip("openpyxl")
    mechanisms = json.loads((EXAMPLES / "church.json").read_text())["mechanisms"]
    book = openpyxl.Workbook()
    sheet = book.active
    sheet.append(CHURCH_COLUMNS)
    for row in _rows(mechanisms, CHURCH_COLUMNS):
        sheet.append([None if c == "" else c for c in row])
    sheet.append(["X1", None, None, None, 2.0, "abc"])
    path = tmp_path / "church.xlsx"
    book.save(path)
    with pytest.raises(InputError, match=r"church\.xlsx row 10, column 'lam': not a number"):
        constants_from_table(path)
    sheet.delete_rows(10)
    book.save(path)
    reference = constants_io.read_constants(EXAMPLES / "church.json")
    assert read_constants(path).model_dump() == reference.model_dump()


def test_xlsx_without_openpyxl_gives_the_install_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "t.xlsx"
    path.write_bytes(b"PK")
    monkeypatch.setitem(sys.modules, "openpyxl", None)
    with pytest.raises(InputError, match="needs openpyxl") as err:
        constants_from_table(path)
    assert XLSX_HINT in str(err.value) and "pip install" in XLSX_HINT


def test_history_accepts_a_table_where_constants_are_expected(
    tmp_path: Path, elcentro_path: Path
) -> None:
    table = tmp_path / "walls.csv"
    table.write_text("id,p_eq,lam,eta\nW1,2.2,0.083,0.99\nW2,1.6,0.17,0.96\n")
    as_json = tmp_path / "walls.json"
    as_json.write_text(
        json.dumps(
            {
                "mechanisms": [
                    {"id": "W1", "p_eq": 2.2, "lam": 0.083, "eta": 0.99},
                    {"id": "W2", "p_eq": 1.6, "lam": 0.17, "eta": 0.96},
                ]
            }
        )
    )
    docs = []
    for constants in (table, as_json):
        result = runner.invoke(app, ["history", str(constants), str(elcentro_path), "--json"])
        assert result.exit_code == 0, result.output
        docs.append(json.loads(result.stdout))
    strip = ("runtime_s", "input")
    rows = [[{k: v for k, v in r.items() if k not in strip} for r in d["results"]] for d in docs]
    assert rows[0] == rows[1] and len(rows[0]) == 2


#: The shipped example table's walls: thickness and height [m] of each rectangular block.
WALLS_CSV_BLOCKS = {"W1": (0.25, 3.0), "W2": (0.50, 3.0), "P1": (0.25, 1.0), "F1": (0.60, 6.0)}


def test_shipped_walls_table_holds_housner_closed_forms() -> None:
    """examples/constants/walls.csv (README): each row is a rectangular block in closed form.

    p_eq = sqrt(3 g / 4R), lam = phi_ov = alpha = atan(b/h) (Housner 1963); eta = 1 - 1.5
    sin^2(alpha) two-sided, 1 - 1.5 cos^2(alpha) one-sided (Eq. 26 with I_O = 4/3 M R^2).
    The cells hold 10 significant digits.
    """
    cf = constants_from_table(EXAMPLES / "walls.csv")
    assert [m.id for m in cf.mechanisms] == list(WALLS_CSV_BLOCKS)
    g = 9.80665
    for mech in cf.mechanisms:
        t, height = WALLS_CSV_BLOCKS[mech.id]
        assert f"{t:.2f} m x {height:.1f} m" in (mech.name or "")
        r, alpha = math.hypot(t / 2, height / 2), math.atan(t / height)
        side = mech.positive
        assert side.p_eq == pytest.approx(math.sqrt(3 * g / (4 * r)), rel=1e-9)
        assert side.lam == pytest.approx(alpha, rel=1e-9)
        assert side.phi_ov == pytest.approx(alpha, rel=1e-9)
        two_sided = mech.rocking == "two_sided"
        trig = math.sin(alpha) if two_sided else math.cos(alpha)
        assert mech.eta == pytest.approx(1 - 1.5 * trig**2, rel=1e-9)
    (parapet,) = [m for m in cf.mechanisms if m.amplification is not None]
    assert parapet.id == "P1" and parapet.amplification is not None
    assert parapet.amplification.h == 10.0  # on the roof
