"""The typed documents of ``shared_schema.documents`` (issue #38).

Each document ``rockmech ... --json`` prints is read back by its model (which refuses
unknown keys) and written again byte for byte: the same keys in the same order, the same
ints and floats, the same absent sections. The reference is the command's own output, as
text; the typed fields are checked against numbers of that text read independently.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from pydantic import ValidationError
from typer.testing import CliRunner

from shared_schema.documents.assess import AssessDocument
from shared_schema.documents.base import Document
from shared_schema.documents.boundary import BoundaryDocument
from shared_schema.documents.check import CheckDocument, Nonlinear2009, Nonlinear2019, NotRun
from shared_schema.documents.envelope import EnvelopeDocument
from shared_schema.documents.history import HistoryDocument
from shared_schema.documents.ida import IdaDocument
from shared_schema.documents.pulse import PulseDocument
from shared_schema.documents.record import RecordDocument
from shared_schema.errors import InputError
from solver_service.cli import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
C = EXAMPLES / "constants"
RECORD = str(EXAMPLES / "records" / "elcentro_NS.dat")
SITE = str(EXAMPLES / "sites" / "ntc_site.json")
EC8 = str(EXAMPLES / "sites" / "ec8_site.json")

#: (model, command) pairs: every optional section appears in at least one.
CASES = {
    "pulse": (PulseDocument, ["pulse", "--p-eq", "2", "--lam", "0.2", "--eta", "0.95",
                              "--a-p-g", "0.282", "--f-p", "0.32"]),
    "pulse_asymmetric": (PulseDocument, ["pulse", "--constants", str(C / "church_geometry.json"),
                                         "--mechanism", "A1", "--a-p-g", "0.3", "--f-p", "1"]),
    "boundary": (BoundaryDocument, ["boundary", "--omega", "3", "--eta", "0.9"]),
    "boundary_one_sided": (BoundaryDocument, ["boundary", "--omega", "2", "--one-sided"]),
    "envelope_fast": (EnvelopeDocument, ["envelope", str(C / "church.json"), "--n", "9",
                                         "--fast", "--record", RECORD, "--out", "{tmp}/e"]),
    "history_sf": (HistoryDocument, ["history", str(C / "church.json"), RECORD, "--scale", "1",
                                     "--sf", "eq28", "--at-height", "2.5"]),
    "record": (RecordDocument, ["record", RECORD, "--pulses", "2", "--n", "20"]),
    "ida": (IdaDocument, ["ida", str(C / "rect_walls.json"), RECORD, "--scales", "0.5,1,2",
                          "--jobs", "1"]),
    "ida_sf_skipped": (IdaDocument, ["ida", str(C / "church.json"), RECORD, "--scales", "1,2",
                                     "--sf", "eq28", "--jobs", "1", "--no-progress"]),
    "check_ec8": (CheckDocument, ["check", str(C / "church.json"), EC8]),
    "assess": (AssessDocument, ["assess", str(C / "church_geometry.json"), SITE, "--record",
                                RECORD, "--multiple", "1", "-o", "{tmp}/a.html"]),
}  # fmt: skip


def _cli(argv: list[str], tmp: Path) -> str:
    res = CliRunner().invoke(app, [a.replace("{tmp}", str(tmp)) for a in argv] + ["--json"])
    assert res.exit_code == 0, res.output
    return res.stdout


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_printed_document_reads_back_and_prints_byte_for_byte(name: str, tmp_path: Path) -> None:
    model, argv = CASES[name]
    text = _cli(argv, tmp_path)
    doc = model.model_validate_json(text)
    assert isinstance(doc, Document)
    assert json.dumps(doc.to_dict(), indent=2) + "\n" == text
    # The model refuses a key it does not know, naming it.
    data = json.loads(text)
    data["surprise"] = 1
    with pytest.raises(ValidationError, match="surprise"):
        model.model_validate(data)


def test_typed_fields_are_the_printed_numbers(tmp_path: Path) -> None:
    text = _cli(CASES["envelope_fast"][1], tmp_path)
    raw = json.loads(text)
    env = EnvelopeDocument.model_validate_json(text)
    assert env.method.source == "library" and env.method.exact_points >= 0
    f1 = next(m for m in raw["mechanisms"] if m["id"] == "F1")
    assert env.find("F1").a_p_min_g == f1["a_p_min_g"]
    # critical_at: the nearest tabulated frequency on a log scale decides.
    for k, f in enumerate(raw["f_p"]):
        assert env.critical_at(f * 1.01) == raw["governing"][k]
    with pytest.raises(InputError, match=r"no mechanism 'X'; the document has \['F1'") as err:
        env.find("X")
    assert err.value.field == "mechanism"
    with pytest.raises(InputError) as bad:
        env.critical_at(math.nan)
    assert bad.value.field == "f_p"
    hist = HistoryDocument.model_validate_json(_cli(CASES["history_sf"][1], tmp_path))
    rows: Any = json.loads(json.dumps(hist.to_dict()))["results"]
    g1 = next(r for r in rows if r["mechanism"] == "G1")
    run = hist.find("G1", 1.0)
    assert run.effective_scale == g1["effective_scale"] > 1.0  # amplified up the structure
    assert run.applied_scale == run.effective_scale
    assert run.peak_displacement_m == g1["peak_displacement_m"]
    assert hist.skipped is not None and hist.skipped[0].mechanism == "F1"  # no eta


def test_the_reader_metadata_of_a_record_block_is_kept_in_order(tmp_path: Path) -> None:
    text = _cli(CASES["record"][1], tmp_path)
    doc = RecordDocument.model_validate_json(text)
    keys = list(json.loads(text)["record"])
    assert keys[:5] == ["name", "n_samples", "dt_s", "pga_g", "duration_s"]
    assert list(doc.record.to_dict()) == keys and len(keys) > 5


def test_the_ida_document_reads_as_the_printed_numbers(tmp_path: Path) -> None:
    text = _cli(CASES["ida_sf_skipped"][1], tmp_path)
    raw = json.loads(text)
    doc = IdaDocument.model_validate_json(text)
    assert doc.measure == raw["intensity"]["measure"] == "scale"
    assert doc.levels == raw["intensity"]["levels"] == [1.0, 2.0]
    for entry in raw["mechanisms"]:
        mech = doc.find(entry["id"])
        assert mech.fraction == entry["fraction"]
        assert mech.n_overturned == entry["n_overturned"]
        # The fraction is the count over the records, read from the text independently.
        assert mech.fraction == [n / len(raw["records"]) for n in entry["n_overturned"]]
        assert mech.fragility.median == entry["fragility"].get("median")
        assert mech.fragility.note == entry["fragility"].get("note", "")
        assert mech.scale_factors == entry.get("scale_factors")
    above = [m for m in raw["mechanisms"] if "scale_factors" in m]
    assert above and all(f > 1.0 for m in above for f in m["scale_factors"] if f is not None)
    assert doc.scale_factor_method == "eq28" and doc.backend.kind == "local"
    assert doc.skipped is not None and [s.mechanism for s in doc.skipped] == ["F1"]
    with pytest.raises(InputError, match=r"no mechanism 'F1'") as err:
        doc.find("F1")
    assert err.value.field == "mechanism"


def _check_text(constants: Path, site: dict[str, Any], tmp: Path) -> str:
    path = tmp / "site.json"
    path.write_text(json.dumps(site), encoding="utf-8")
    return _cli(["check", str(constants), str(path)], tmp)


def test_every_variant_of_a_check_reads_back_typed_and_prints_byte_for_byte(
    tmp_path: Path,
) -> None:
    site = json.loads(Path(SITE).read_text(encoding="utf-8"))
    seen: set[str] = set()
    for constants, method in [
        (C / "church_geometry.json", "circ2019"),
        (C / "church_geometry.json", "circ2009"),
        (C / "church.json", "circ2019"),  # short form: no virtual_work, no check runs
    ]:
        text = _check_text(constants, dict(site, local_mechanisms={"method": method}), tmp_path)
        raw = json.loads(text)
        doc = CheckDocument.model_validate_json(text)
        assert json.dumps(doc.to_dict(), indent=2) + "\n" == text
        assert doc.site.params.to_dict() == raw["site"]["params"]
        assert doc.conclusion.verdict == raw["conclusion"]["verdict"]
        for row, mech in zip(raw["mechanisms"], doc.mechanisms):
            for name, typed in (("linear", mech.linear), ("nonlinear", mech.nonlinear)):
                block = row[name]
                seen.add(type(typed).__name__)
                assert typed.status == block["status"] and typed.passes == block.get("passes")
                if block["status"] == "not_run":
                    assert isinstance(typed, NotRun) and "virtual_work" in typed.note
                    continue
                assert typed.method == method
                assert typed.capacity_ratio == block["capacity_ratio"]
            non = mech.nonlinear
            if isinstance(non, Nonlinear2019):  # the limit states as printed
                assert non.SLV.T_SLV == row["nonlinear"]["SLV"]["T_SLV"]
                assert non.SLC.capacity_ratio == row["nonlinear"]["SLC"]["capacity_ratio"]
                assert mech.nonlinear_ratio == row["nonlinear"]["capacity_ratio"]
                above = row["nonlinear"].get("floor")
                assert (non.floor is None) == (above is None)
            if isinstance(non, Nonlinear2009):
                assert non.Ts == row["nonlinear"]["Ts"] and len(non.curve.d_star) > 2
    assert seen == {
        "Linear2019", "Nonlinear2019", "Linear2009", "Nonlinear2009", "NotRun"
    }  # fmt: skip
    # A block of one variant with a key of another is refused, naming it.
    data = json.loads(_check_text(C / "church_geometry.json", site, tmp_path))
    data["mechanisms"][0]["linear"]["du_star"] = 0.1
    with pytest.raises(ValidationError, match="du_star"):
        CheckDocument.model_validate(data)
