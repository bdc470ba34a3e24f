"""Record formats: each real file detected, read whole, and matching its own header.

The files are the project's shared test records (``formats/`` of the shared records folder
beside the repository, provenance in its README; absent on a clone, where these tests
skip); the expected counts, steps and peaks below are copied from each file's header, and
the samples are compared with an independent parse (plain whitespace splitting).
"""

from __future__ import annotations

import ast
import shutil
from pathlib import Path

import numpy as np
import pytest

from shared_schema.errors import InputError
from shared_schema.rules import RECORD_FORMATS, RECORD_UNITS
from solver_service.core import formats, records
from solver_service.core.formats._text import fixed_width_values
from solver_service.core.records import GroundMotion, detect_format

ESM = "HI.ARS1..HNE.D.20190728.160908.C.ACC.ASC"
KNET = "CHB0031412312349.NS"
KIKNET = "NGNH311106302345.EW2"
COSMOS = "us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c"
DMG = "ce36456p_CE36456.V2"
GEONET = "20180212_211557_WPWS_20.V2A"

#: What each header states: file -> (format, units, [(component, npts, dt [s], |peak|)]).
HEADERS = {
    ESM: ("esm", "cm/s2", [("HNE", 19128, 0.005, 0.300022)]),
    KNET: ("knet", "cm/s2", [("N-S", 6000, 0.01, 8.131)]),
    KIKNET: ("knet", "cm/s2", [("E-W (surface)", 12000, 0.01, 0.708)]),
    COSMOS: ("cosmos", "cm/s2", [("BNZ", 42000, 0.005, 6.851512)]),
    DMG: (
        "dmg",
        "cm/s2",
        [
            ("90 DEG", 3251, 0.02, 267.957),
            ("UP", 3250, 0.02, 94.805),
            ("0 DEG", 3250, 0.02, 256.231),
        ],
    ),
    GEONET: (
        "geonet",
        "mm/s2",
        [("S16W", 5800, 0.02, 41.6), ("S74E", 5800, 0.02, 194.0), ("Up", 5800, 0.02, 27.3)],
    ),
}
CASES = [(f, k) for f, (_, _, chans) in HEADERS.items() for k in range(len(chans))]


@pytest.fixture(scope="module")
def formats_dir(shared_records: Path) -> Path:
    """The shared folder of one real file per strong-motion format."""
    folder = shared_records / "formats"
    if not folder.is_dir():
        pytest.skip(f"strong-motion format files not found at {folder}")
    return folder


def _independent(path: Path, fname: str, k: int) -> np.ndarray:
    """Samples of channel ``k`` in the file's units, by plain splitting of the known layout."""
    lines = path.read_text().splitlines()
    if fname == ESM:
        start = next(i for i, ln in enumerate(lines) if ln.startswith("USER5:")) + 1
        return np.array([float(x) for x in lines[start:]])
    if fname in (KNET, KIKNET):
        scale = lines[13].split()[2]
        num, den = scale.replace("(gal)", "").split("/")
        counts = np.array([float(x) for ln in lines[17:] for x in ln.split()])
        a = counts * float(num) / float(den)
        return a - a.mean()
    if fname == COSMOS:
        return np.array([float(x) for x in lines[53:-1]])
    if fname == DMG:
        heads = [i for i, ln in enumerate(lines) if "POINTS OF ACCEL DATA" in ln]
        stop = next(i for i in range(heads[k], len(lines)) if "POINTS OF VELOC" in lines[i])
        return np.array([float(x) for ln in lines[heads[k] + 1 : stop] for x in ln.split()])
    # GeoNet: 1766 lines per component = 16 text + 10 header + 3 x 580 rows.
    start = 1766 * k + 26
    return np.array([float(x) for ln in lines[start : start + 580] for x in ln.split()])


@pytest.mark.parametrize(("fname", "k"), CASES)
def test_every_file_reads_whole_and_matches_its_header(
    formats_dir: Path, fname: str, k: int
) -> None:
    fmt, units, chans = HEADERS[fname]
    component, npts, dt, peak = chans[k]
    path = formats_dir / fname
    assert detect_format(path) == fmt
    motion = GroundMotion.from_file(path, channel=k + 1 if len(chans) > 1 else None)
    meta = motion.metadata
    assert (meta["format"], meta["units"], meta["component"]) == (fmt, units, component)
    assert motion.accel.n == npts == meta["npts"]
    assert motion.dt == pytest.approx(dt, rel=1e-12) and meta["dt"] == motion.dt
    expected = _independent(path, fname, k)
    assert expected.size == npts
    si = expected * RECORD_UNITS[units]
    np.testing.assert_allclose(motion.accel.acc, si, rtol=1e-12, atol=1e-12 * np.max(np.abs(si)))
    # The header prints the peak rounded to its last digit.
    digits = len(str(peak).split(".")[1])
    file_peak = motion.pga / RECORD_UNITS[units]
    assert abs(file_peak - peak) <= 0.5 * 10.0**-digits + 1e-9
    assert meta["peak"] == peak and meta["source"] == fname
    assert meta["pga_g"] == pytest.approx(motion.pga_g, rel=1e-12)


def test_knet_peak_matches_the_header_only_with_the_mean_removed(formats_dir: Path) -> None:
    motion = GroundMotion.from_file(formats_dir / KNET)
    raw = _independent(formats_dir / KNET, KNET, 0) + motion.metadata["mean_removed"]
    assert np.max(np.abs(raw)) == pytest.approx(10.5916, abs=1e-4)  # counts x scale: not 8.131
    assert abs(motion.pga * 100.0 - 8.131) < 5e-4
    assert motion.metadata["scale_factor"] == "7845(gal)/8223790"
    assert motion.metadata["station"] == "CHB003"


@pytest.mark.parametrize("fname", [DMG, GEONET])
def test_several_channels_must_be_chosen_and_are_listed(formats_dir: Path, fname: str) -> None:
    with pytest.raises(InputError, match="holds 3 acceleration channels") as err:
        GroundMotion.from_file(formats_dir / fname)
    assert err.value.field == "channel"
    for component, *_ in HEADERS[fname][2]:
        assert component in str(err.value)
    with pytest.raises(InputError, match="no channel '4'") as err:
        GroundMotion.from_file(formats_dir / fname, channel=4)
    assert err.value.field == "channel"
    with pytest.raises(InputError, match="no component 'N45E'") as err:
        GroundMotion.from_file(formats_dir / fname, component="N45E")
    assert err.value.field == "component"


def test_component_is_chosen_by_name_case_and_spaces_ignored(formats_dir: Path) -> None:
    up = GroundMotion.from_file(formats_dir / GEONET, component="UP")
    assert up.metadata["channel"] == 3 and up.name == "20180212_211557_WPWS_20_3"
    assert up.metadata["channels"] == "1: S16W, 2: S74E, 3: Up"
    deg = GroundMotion.from_file(formats_dir / DMG, component="0deg")
    assert deg.metadata["channel"] == 3 and deg.metadata["station"].startswith("36456")
    both = GroundMotion.from_file(formats_dir / DMG, channel="2", component="up")
    assert both.accel.n == 3250
    with pytest.raises(InputError, match="no component") as err:
        GroundMotion.from_file(formats_dir / DMG, channel=1, component="UP")
    assert err.value.field == "component"


def test_single_channel_files_refuse_another_channel(formats_dir: Path) -> None:
    assert GroundMotion.from_file(formats_dir / ESM, channel=1, component="hne").accel.n == 19128
    with pytest.raises(InputError, match="no channel '2'") as err:
        GroundMotion.from_file(formats_dir / ESM, channel=2)
    assert err.value.field == "channel"


def test_stated_units_win_and_a_contradiction_is_an_error(formats_dir: Path) -> None:
    assert GroundMotion.from_file(formats_dir / GEONET, channel=1, units="mm/s2").pga == (
        pytest.approx(0.0416, rel=1e-12)
    )
    with pytest.raises(InputError, match="states units 'cm/s2', got 'g'") as err:
        GroundMotion.from_file(formats_dir / ESM, units="g")
    assert err.value.field == "units"
    with pytest.raises(InputError, match="states its own time step") as err:
        GroundMotion.from_file(formats_dir / KNET, dt=0.01)
    assert err.value.field == "dt"


def _tampered(formats_dir: Path, tmp_path: Path, fname: str, old: str, new: str) -> Path:
    text = (formats_dir / fname).read_text()
    assert old in text
    out = tmp_path / fname
    out.write_text(text.replace(old, new, 1))
    return out


@pytest.mark.parametrize(
    ("fname", "old", "new", "match"),
    [
        (ESM, "NDATA: 19128", "NDATA: 19129", "header says 19129 samples, but the file has 19128"),
        (ESM, "PGA_CM/S^2: 0.300022", "PGA_CM/S^2: 0.310022", "header states peak 0.310022"),
        (ESM, "UNITS: cm/s^2", "UNITS: furlongs", "unknown acceleration units"),
        (ESM, "DATA_TYPE: ACCELERATION", "DATA_TYPE: VELOCITY", "not ACCELERATION"),
        (KNET, "Max. Acc. (gal)   8.131", "Max. Acc. (gal)   10.592", "header states peak 10.592"),
        (KNET, "7845(gal)/8223790", "7845/8223790", "not of the form"),
        (KNET, "Duration Time(s)  60", "Duration Time(s)  61", "header says 6100 samples"),
        (COSMOS, "-6.851512", "-6.951512", "header states peak 6.951512"),
        (DMG, "PEAK ACCELERATION =  -267.957", "PEAK ACCELERATION =  -266.957", "peak 266.957"),
        (DMG, " 3251 POINTS OF ACCEL", " 3252 POINTS OF ACCEL", "3252 samples"),
        (GEONET, "peak    -41.6 mm/s/s", "peak    -42.6 mm/s/s", "header states peak 42.6 mm/s2"),
        (GEONET, "peak    -41.6 mm/s/s", "peak    -41.6 furlongs", "unknown acceleration units"),
    ],
)
def test_a_file_contradicting_its_header_is_refused(
    formats_dir: Path, tmp_path: Path, fname: str, old: str, new: str, match: str
) -> None:
    path = _tampered(formats_dir, tmp_path, fname, old, new)
    kwargs = {"channel": 1} if len(HEADERS[fname][2]) > 1 else {}
    with pytest.raises(InputError, match=match) as err:
        GroundMotion.from_file(path, **kwargs)  # type: ignore[arg-type]
    assert err.value.field == "record"


def test_a_lost_sample_is_refused(formats_dir: Path, tmp_path: Path) -> None:
    lines = (formats_dir / ESM).read_text().splitlines(keepends=True)
    path = tmp_path / ESM
    path.write_text("".join(lines[:-1]))
    with pytest.raises(InputError, match="header says 19128 samples, but the file has 19127"):
        GroundMotion.from_file(path)


def test_a_surplus_sample_is_refused(formats_dir: Path, tmp_path: Path) -> None:
    # One more line of DMG acceleration before the velocity block.
    extra = "     1.000     2.000\r\n 3251 POINTS OF VELOC"
    path = _tampered(formats_dir, tmp_path, DMG, " 3251 POINTS OF VELOC", extra)
    with pytest.raises(InputError, match="header says 3251 samples, but the file has 3253"):
        GroundMotion.from_file(path, channel=1)


def test_fixed_width_fields_read_numbers_that_touch() -> None:
    rows = [(1, " -1000.000-10000.500     2.250"), (2, "     4.000")]
    np.testing.assert_array_equal(
        fixed_width_values(rows, 10, 4, "x"), [-1000.0, -10000.5, 2.25, 4.0]
    )
    with pytest.raises(InputError, match="header says 5 samples, but the file has 4"):
        fixed_width_values(rows, 10, 5, "x")


# --- CSV units from the header row ------------------------------------------------------


@pytest.mark.parametrize(
    ("column", "units"),
    [
        ("acc [g]", "g"),
        ("a (m/s2)", "m/s2"),
        ("accel_cm/s2", "cm/s2"),
        ("Acceleration (cm/s^2)", "cm/s2"),
        ("a [m/s²]", "m/s2"),
        ("acc [gal]", "cm/s2"),
        ("acc_mm/s/s", "mm/s2"),
    ],
)
def test_csv_units_are_read_from_the_column_name(tmp_path: Path, column: str, units: str) -> None:
    f = tmp_path / "r.csv"
    f.write_text(f"t [s],{column}\n0,1.5\n0.01,-2.0\n0.02,0.5\n")
    motion = GroundMotion.from_file(f)
    assert motion.metadata["units"] == units and motion.metadata["units_from"] == "header"
    np.testing.assert_allclose(motion.accel.acc, np.array([1.5, -2.0, 0.5]) * RECORD_UNITS[units])
    assert GroundMotion.from_file(f, units=units).accel.n == 3  # agreeing units are fine


def test_csv_units_contradicting_or_missing_are_errors(tmp_path: Path) -> None:
    f = tmp_path / "r.csv"
    f.write_text("t,acc [g]\n0,1.5\n0.01,-2.0\n")
    with pytest.raises(InputError, match="states units 'g', got 'm/s2'") as err:
        GroundMotion.from_file(f, units="m/s2")
    assert err.value.field == "units"
    f.write_text("t,acc\n0,1.5\n0.01,-2.0\n")
    with pytest.raises(InputError, match=r"column 'acc' of r\.csv does not state them") as err:
        GroundMotion.from_file(f)
    assert err.value.field == "units"
    assert GroundMotion.from_file(f, units="g").metadata["units_from"] == "given"
    f.write_text("t [ms],acc [g]\n0,1.5\n10,-2.0\n")
    with pytest.raises(InputError, match="give time in seconds") as err:
        GroundMotion.from_file(f)
    assert err.value.field == "time_column"


def test_plain_column_files_keep_their_detection(tmp_path: Path) -> None:
    two = tmp_path / "two.txt"
    two.write_text("0 0.1\n0.02 0.2\n")
    one = tmp_path / "one.txt"
    one.write_text("0.1\n0.2\n")
    assert (detect_format(two), detect_format(one)) == ("two_column", "one_column")
    assert detect_format(tmp_path / "x.csv") == "csv" and detect_format(tmp_path / "x.AT2") == "at2"


def test_copy_with_another_name_is_still_detected(formats_dir: Path, tmp_path: Path) -> None:
    for fname, (fmt, *_) in HEADERS.items():
        copy = tmp_path / f"record_{fmt}.txt"
        shutil.copy(formats_dir / fname, copy)
        assert detect_format(copy) == fmt


def test_every_record_format_has_its_reader_in_formats() -> None:
    """One home for the readers (#38): a module of ``formats`` per format, none in ``records``."""
    for fmt in RECORD_FORMATS:
        module = getattr(formats, fmt)
        assert callable(module.read), fmt
        if fmt != "csv":
            assert formats.DT_SOURCES[fmt] == module.DT_SOURCE, fmt
    for fmt in formats.READERS:
        assert formats.READERS[fmt] == (getattr(formats, fmt).sniff, getattr(formats, fmt).read)
    # records reads files and builds GroundMotion; it parses no format of its own
    tree = ast.parse(Path(records.__file__).read_text(encoding="utf-8"))
    imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    assert not imported & {"re", "csv"}
    calls = {
        n.func.attr
        for n in ast.walk(tree)
        if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)
    }
    assert "splitlines" not in calls


def test_column_readers_read_the_bundled_record_as_a_plain_split_does(elcentro_path: Path) -> None:
    text = elcentro_path.read_text(encoding="utf-8")
    rows = [ln.split("#")[0].split() for ln in text.splitlines()]
    t, a = np.array([r for r in rows if r], dtype=float).T
    two = formats.two_column.read(text, elcentro_path.name, "g")
    np.testing.assert_array_equal(two.values, a)
    assert two.dt == pytest.approx(0.02, rel=1e-9) and two.units == "g"
    assert (two.metadata["format"], two.metadata["npts"]) == ("two_column", a.size)
    one = formats.one_column.read("\n".join(map(repr, a.tolist())), "a.txt", 0.02, "g")
    np.testing.assert_array_equal(one.values, a)
    table = "t [s],acc [g]\n" + "\n".join(f"{x!r},{y!r}" for x, y in zip(t.tolist(), a.tolist()))
    csv = formats.csv.read(table, "a.csv")
    np.testing.assert_array_equal(csv.values, a)
    assert (csv.units, csv.metadata["units_from"], csv.dt) == ("g", "header", pytest.approx(0.02))
    assert formats.format_of(text, "x.dat") == "two_column"
    assert formats.format_of(table, "x.txt", ".CSV") == "csv"
    # the same record through GroundMotion, in SI
    motion = GroundMotion.from_file(elcentro_path, units="g")
    np.testing.assert_allclose(motion.accel.acc, a * 9.80665, rtol=1e-15)
