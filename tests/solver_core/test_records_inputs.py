"""Records as commands read them: channel choice, per-record specs for ida, the record summary."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shared_schema.errors import InputError
from solver_service.cli import app
from solver_service.workflows.inputs import read_record, read_record_spec

runner = CliRunner()
DMG = "ce36456p_CE36456.V2"
GEONET = "20180212_211557_WPWS_20.V2A"


@pytest.fixture(scope="module")
def formats_dir(shared_records: Path) -> Path:
    """The shared folder of one real file per strong-motion format."""
    folder = shared_records / "formats"
    if not folder.is_dir():
        pytest.skip(f"strong-motion format files not found at {folder}")
    return folder


def test_record_spec_csv_gives_each_record_its_options(tmp_path: Path, elcentro_path: Path) -> None:
    (tmp_path / "one.txt").write_text("0.1\n-0.2\n0.3\n")
    spec = tmp_path / "records.csv"
    spec.write_text(
        "# records of the IDA\n"
        "file,format,units,dt,channel,component\n"
        f"{elcentro_path},,,,,\n"
        "one.txt,one_column,cm/s2,0.01,,\n"
    )
    specs = read_record_spec(spec)
    assert [s.file.name for s in specs] == ["elcentro_NS.dat", "one.txt"]
    assert (specs[1].format, specs[1].units, specs[1].dt) == ("one_column", "cm/s2", 0.01)
    one = specs[1].read()
    assert one.dt == 0.01 and one.accel.n == 3 and one.pga == pytest.approx(0.003, rel=1e-12)
    assert specs[0].read().accel.n == 2688  # two-column default: g


def test_record_spec_json_equals_csv(tmp_path: Path) -> None:
    doc = [{"file": "a.V2", "channel": 2}, {"file": "b.V2A", "component": "Up"}]
    spec = tmp_path / "records.json"
    spec.write_text(json.dumps(doc))
    specs = read_record_spec(spec)
    assert (specs[0].channel, specs[1].component) == ("2", "Up")
    assert specs[0].file == tmp_path / "a.V2"


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("file,units\na.txt,furlongs\n", r"row 2, column 'units': must be one of"),
        ("file,dt\na.txt,0\n", r"row 2, column 'dt': must be a number > 0"),
        ("file,dt\na.txt,x\n", r"row 2, column 'dt': must be a number > 0"),
        ("file,format\na.txt,sac\n", r"row 2, column 'format': must be one of"),
        ("file,scale\na.txt,2\n", r"row 2: unknown column 'scale'"),
        ("file,units\n,g\n", r"row 2, column 'file': missing"),
        ("file\na.txt,2\n", r"row 2 has 2 cells, the header 1"),
        ("file\n", r"lists no records"),
    ],
)
def test_bad_record_specs_name_row_and_column(tmp_path: Path, text: str, match: str) -> None:
    spec = tmp_path / "records.csv"
    spec.write_text(text)
    with pytest.raises(InputError, match=match) as err:
        read_record_spec(spec)
    assert err.value.field == "record_spec"


@pytest.mark.parametrize(
    ("text", "match"),
    [("[{", r"records.json: invalid JSON"), ("[" * 5000 + "]" * 5000, "nested deeper than 1000")],
)
def test_bad_json_record_specs_are_named(tmp_path: Path, text: str, match: str) -> None:
    spec = tmp_path / "records.json"
    spec.write_text(text)
    with pytest.raises(InputError, match=match) as err:
        read_record_spec(spec)
    assert err.value.field == "record_spec"


def test_read_record_passes_channel_and_component(formats_dir: Path) -> None:
    assert read_record(formats_dir / DMG, channel=2).metadata["component"] == "UP"
    assert read_record(formats_dir / GEONET, component="S74E").metadata["channel"] == 2


def test_record_command_lists_channels_and_shows_the_header(formats_dir: Path) -> None:
    args = ["record", str(formats_dir / DMG), "--n", "3", "--pulses", "1"]
    missing = runner.invoke(app, args)
    assert missing.exit_code == 2
    assert "error: channel:" in missing.output and "1: 90 DEG, 2: UP, 3: 0 DEG" in missing.output
    chosen = runner.invoke(app, [*args, "--component", "up"])
    assert chosen.exit_code == 0, chosen.output
    assert "3250 samples, dt 0.02 s" in chosen.output
    assert "format dmg, units cm/s2, station 36456 PARKFIELD FAULT ZONE 14, component UP" in (
        chosen.output
    )
    doc = json.loads(runner.invoke(app, [*args, "--channel", "2", "--json"]).stdout)
    record = doc["record"]
    assert (record["format"], record["component"], record["channel"]) == ("dmg", "UP", 2)
    assert (record["units"], record["npts"], record["peak"]) == ("cm/s2", 3250, 94.805)


def test_ida_takes_a_record_spec(tmp_path: Path, formats_dir: Path) -> None:
    constants = tmp_path / "c.csv"
    constants.write_text("id,p_eq,lam,eta\nW1,3.0,0.05,0.9\n")
    spec = tmp_path / "records.csv"
    spec.write_text(f"file,channel,component\n{formats_dir / DMG},1,\n{formats_dir / GEONET},,Up\n")
    result = runner.invoke(
        app, ["ida", str(constants), "--record-spec", str(spec), "--scales", "1", "--json"]
    )
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["runs"] == 2
    none = runner.invoke(app, ["ida", str(constants), "--scales", "1"])
    assert none.exit_code == 2 and "give record files or --record-spec" in none.output
