"""Tests of reading and writing kinematic-constants files (shared_schema.io)."""

import json
import os
import stat
from pathlib import Path

import pytest
from pydantic_core import PydanticSerializationError

import shared_schema.atomic as atomic
from shared_schema.constants import ConstantsFile, Mechanism, parse_constants
from shared_schema.errors import InputError
from shared_schema.io import read_constants, stamped, write_atomic, write_constants
from shared_schema.version import __version__

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "constants"

W1 = {
    "id": "W1",
    "rocking": "two_sided",
    "p_eq": 2.15,
    "lam": 0.25,
    "eta": 0.90,
    "amplification": {"f_n": 6.22, "h_e": 4.66, "h": 3.11},
}


def leftovers(directory):
    """Files in ``directory`` other than the expected ones (e.g. temporary files)."""
    return sorted(p.name for p in Path(directory).iterdir())


# --- round trip --------------------------------------------------------------------------


def test_published_table_form_round_trips_and_omits_absent_sections(tmp_path):
    original = parse_constants({"mechanisms": [W1]})
    path = tmp_path / "walls.json"
    write_constants(original, path)
    text = path.read_text(encoding="utf-8")
    assert text.endswith("}\n")
    assert "null" not in text
    saved = json.loads(text)
    mech = saved["mechanisms"][0]
    assert set(mech) == {
        "id",
        "name",
        "typology",
        "rocking",
        "positive",
        "eta",
        "eta_source",
        "amplification",
    }
    assert mech["positive"] == {"p_eq": 2.15, "lam": 0.25, "phi_ov": 0.25}
    assert saved["schema_version"] == "1.0"
    assert saved["units"]["p_eq"] == "rad/s"
    assert saved["rockmech_version"] == __version__  # the writer's version
    assert read_constants(path) == stamped(original)


def test_physical_form_round_trips_exactly(tmp_path):
    side = {"I0": 10000.0, "K": 40000.0, "Q": 2000.0, "phi_cr": 0.1, "M_F": 1000.0}
    original = parse_constants(
        [
            {
                "id": "L1",
                "typology": "single_block_loaded",
                "positive": side,
                "negative": side,
                "geometry": {"b": 0.5, "h": 3.0, "note": None, "ratios": [1, 2.5]},
                "provenance": {"tool": "test"},
            }
        ]
    )
    path = tmp_path / "loaded.json"
    write_constants(original, path)
    loaded = read_constants(path)
    assert loaded == stamped(original)
    # Derived values are written next to the physical ones; nulls inside free-form data stay.
    mech = json.loads(path.read_text())["mechanisms"][0]
    assert mech["negative"]["lam"] == original.mechanisms[0].negative.lam
    assert mech["geometry"]["note"] is None


def test_saving_twice_gives_identical_bytes(tmp_path):
    cf = parse_constants([W1])
    write_constants(cf, tmp_path / "a.json")
    write_constants(read_constants(tmp_path / "a.json"), tmp_path / "b.json")
    assert (tmp_path / "a.json").read_bytes() == (tmp_path / "b.json").read_bytes()


# --- loading -----------------------------------------------------------------------------


def test_missing_file_names_the_file(tmp_path):
    path = tmp_path / "nowhere.json"
    with pytest.raises(InputError) as info:
        read_constants(path)
    assert info.value.field == str(path)
    assert str(info.value) == f"{path}: constants file not found"


def test_directory_instead_of_file_is_an_input_error(tmp_path):
    with pytest.raises(InputError) as info:
        read_constants(tmp_path)
    assert str(info.value) == f"{tmp_path}: is a folder, not a constants file"


def test_invalid_json_names_the_file_and_position(tmp_path):
    path = tmp_path / "broken.json"
    path.write_text('{"mechanisms": [\n  {"id": "W1",}\n]}\n')
    with pytest.raises(InputError) as info:
        read_constants(path)
    message = str(info.value)
    assert message.startswith(f"{path}: invalid JSON")
    assert "line 2" in message


def test_invalid_value_names_file_mechanism_and_field(tmp_path):
    path = tmp_path / "walls.json"
    bad = dict(W1, id="W2", p_eq=-2.15)
    path.write_text(json.dumps({"mechanisms": [W1, bad]}))
    with pytest.raises(InputError) as info:
        read_constants(path)
    assert str(info.value) == (
        f"{path}: mechanisms[1] (id 'W2').positive.p_eq: Input should be greater than 0"
    )
    # The original error, with the field path alone, is kept as the cause.
    assert info.value.__cause__.field == "mechanisms[1] (id 'W2').positive.p_eq"


def test_nan_literal_in_file_is_rejected(tmp_path):
    path = tmp_path / "nan.json"
    path.write_text('[{"id": "W1", "p_eq": NaN, "lam": 0.25}]')
    with pytest.raises(InputError, match=r"\(id 'W1'\)\.positive\.p_eq: .*finite"):
        read_constants(path)


def test_bare_list_file_and_byte_order_mark_are_accepted(tmp_path):
    path = tmp_path / "list.json"
    path.write_bytes(b"\xef\xbb\xbf" + json.dumps([W1, dict(W1, id="W2")]).encode())
    cf = read_constants(path)
    assert [m.id for m in cf.mechanisms] == ["W1", "W2"]


def test_non_utf8_file_is_an_input_error(tmp_path):
    path = tmp_path / "latin1.json"
    path.write_bytes('[{"id": "Fa\u00e7ade", "p_eq": 2, "lam": 0.2}]'.encode("latin-1"))
    with pytest.raises(InputError, match="not UTF-8"):
        read_constants(path)


# --- atomic writes -----------------------------------------------------------------------


def test_write_atomic_writes_str_and_bytes_exactly(tmp_path):
    path = tmp_path / "x.json"
    write_atomic(path, '{"a": "\u00e9"}\r\n')
    assert path.read_bytes() == '{"a": "\u00e9"}\r\n'.encode()
    write_atomic(str(path), b"[1]\n")
    assert path.read_bytes() == b"[1]\n"
    assert leftovers(tmp_path) == ["x.json"]


def test_write_atomic_rejects_other_types_before_touching_the_disk(tmp_path):
    with pytest.raises(TypeError, match="str or bytes"):
        write_atomic(tmp_path / "x.json", {"a": 1})
    assert leftovers(tmp_path) == []


def test_failed_rename_leaves_previous_file_and_no_temporary_file(tmp_path, monkeypatch):
    path = tmp_path / "x.json"
    path.write_text("old\n")

    def fail_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(atomic.os, "replace", fail_replace)
    with pytest.raises(OSError, match="No space"):
        write_atomic(path, "new\n")
    assert path.read_text() == "old\n"
    assert leftovers(tmp_path) == ["x.json"]


def test_failing_serialisation_leaves_previous_file_and_no_temporary_file(tmp_path):
    path = tmp_path / "walls.json"
    write_constants(parse_constants([W1]), path)
    before = path.read_bytes()
    good = parse_constants([W1]).mechanisms[0]
    # model_construct skips validation, so an object JSON cannot hold gets through to dumping.
    broken_mech = Mechanism.model_construct(**dict(good.__dict__, geometry={"mesh": object()}))
    broken = ConstantsFile.model_construct(
        schema_version="1.0", units=parse_constants([W1]).units, mechanisms=[broken_mech]
    )
    with pytest.raises(PydanticSerializationError):
        write_constants(broken, path)
    assert path.read_bytes() == before
    assert leftovers(tmp_path) == ["walls.json"]


def test_save_into_missing_directory_is_an_input_error(tmp_path):
    path = tmp_path / "no" / "such" / "dir.json"
    with pytest.raises(InputError, match="cannot write constants file"):
        write_constants(parse_constants([W1]), path)


@pytest.mark.skipif(os.name != "posix", reason="POSIX permission bits")
def test_existing_file_keeps_its_permissions(tmp_path):
    path = tmp_path / "x.json"
    path.write_text("old\n")
    path.chmod(0o640)
    write_atomic(path, "new\n")
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    write_atomic(tmp_path / "fresh.json", "new\n")
    assert stat.S_IMODE((tmp_path / "fresh.json").stat().st_mode) == atomic.NEW_FILE_MODE


# --- the church example ------------------------------------------------------------------


def test_church_example_loads_with_plausible_constants():
    cf = read_constants(EXAMPLES / "church.json")
    assert len(cf.mechanisms) >= 6
    kinds = {m.rocking for m in cf.mechanisms}
    assert kinds == {"one_sided", "two_sided"}
    assert sum(m.amplification is not None for m in cf.mechanisms) >= 2
    for m in cf.mechanisms:
        assert m.name is not None and m.name != m.id, m.id
        assert 1.0 <= m.positive.p_eq <= 5.0, m.id
        assert 0.05 <= m.positive.lam <= 0.4, m.id
        if m.eta is not None and m.rocking == "two_sided":
            assert 0.8 <= m.eta <= 0.97, m.id
        if m.eta is not None and m.rocking == "one_sided":
            assert -0.75 <= m.eta <= -0.5, m.id
        if m.amplification is not None:
            assert 0.5 <= m.amplification.f_n <= 15.0, m.id
