"""Reading two-column records: every sample kept, bad files rejected with a reason."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest

from shared_schema.errors import InputError
from solver_service.core.model import G
from solver_service.core.records import GroundMotion


def test_el_centro_is_read_completely(elcentro_path: Path) -> None:
    raw = np.loadtxt(elcentro_path)
    motion = GroundMotion.from_two_column(elcentro_path, units="g")
    assert motion.accel.n == raw.shape[0] == 2688
    assert motion.dt == pytest.approx(0.02, rel=1e-12)
    np.testing.assert_array_equal(motion.accel.acc, raw[:, 1] * G)  # last line included
    assert motion.pga_g == pytest.approx(0.349, abs=5e-4)
    assert motion.metadata["units"] == "g" and motion.name == "elcentro_NS"


@pytest.mark.parametrize(("units", "factor"), [("m/s2", 1.0), ("cm/s2", 0.01)])
def test_units_are_converted_to_si(tmp_path: Path, units: str, factor: float) -> None:
    f = tmp_path / "r.txt"
    f.write_text("# t a\n0, 1.5\n0.1, -2.0\n0.2, 0.5\n")
    motion = GroundMotion.from_two_column(f, units=units)
    np.testing.assert_allclose(motion.accel.acc, np.array([1.5, -2.0, 0.5]) * factor)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("0 0.1\n0.02 nan\n0.04 0.2\n", "not finite"),
        ("0 0.1\n0.04 0.2\n0.02 0.3\n", "strictly increasing"),
        ("0 0.1\n0.02 0.2\n0.05 0.3\n", "not uniform"),
        ("0 0.1\n", "at least 2 samples"),
        ("", r"is empty \(0 bytes\): expected a ground-motion record"),
        ("0 0.1 7\n0.02 0.2 7\n", "expected 2 columns"),
        ("0 0.1\n0.02 abc\n", "not a number"),
    ],
)
def test_bad_records_are_rejected_with_a_reason(tmp_path: Path, text: str, match: str) -> None:
    f = tmp_path / "bad.dat"
    f.write_text(text)
    with pytest.raises(InputError, match=match) as err:
        GroundMotion.from_two_column(f)
    assert err.value.field == "record"


def test_missing_file_and_unknown_units(tmp_path: Path, elcentro_path: Path) -> None:
    with pytest.raises(InputError, match="not found"):
        GroundMotion.from_two_column(tmp_path / "nope.dat")
    with pytest.raises(InputError, match="units"):
        GroundMotion.from_two_column(elcentro_path, units="furlongs")


# --- PEER AT2 --------------------------------------------------------------------------

#: README table of the shared records folder: file -> (NPTS, DT [s], PGA [g]).
AT2_TABLE = {
    "RSN126_GAZLI_GAZ000.AT2": (2048, 0.0066, 0.702),
    "RSN183_IMPVALL.H_H-E08140.AT2": (7554, 0.005, 0.610),
    "RSN948_NORTHR_CAM009.AT2": (3499, 0.01, 0.091),
    "RSN982_NORTHR_JEN292.AT2": (5720, 0.005, 0.617),
}
AT2_HEADER = (
    "PEER NGA STRONG MOTION DATABASE RECORD\n"
    "Gazli USSR, 5/17/1976, Karakyr, 0\n"
    "ACCELERATION TIME SERIES IN UNITS OF G\n"
)


@pytest.mark.parametrize("fname", sorted(AT2_TABLE))
def test_at2_keeps_every_sample_including_the_last_line(shared_records: Path, fname: str) -> None:
    npts, dt, pga_g = AT2_TABLE[fname]
    path = shared_records / fname
    # Independent parse: every token after the 4 header lines.
    tokens = path.read_text().splitlines()[4:]
    expected = np.array([float(x) for line in tokens for x in line.split()])
    motion = GroundMotion.from_at2(path)
    assert motion.accel.n == expected.size == npts
    assert motion.dt == dt and motion.metadata["dt"] == dt and motion.metadata["npts"] == npts
    np.testing.assert_array_equal(motion.accel.acc, expected * G)
    assert motion.pga_g == pytest.approx(pga_g, abs=1e-3)
    assert motion.metadata["pga_g"] == pytest.approx(motion.pga_g, rel=1e-12)
    assert motion.metadata["units"] == "g" and motion.metadata["source"] == fname
    assert GroundMotion.from_file(path).accel.n == npts  # detected by extension


def test_at2_metadata_from_line_two(shared_records: Path) -> None:
    meta = GroundMotion.from_at2(shared_records / "RSN126_GAZLI_GAZ000.AT2").metadata
    assert (meta["event"], meta["date"]) == ("Gazli USSR", "5/17/1976")
    assert (meta["station"], meta["component"]) == ("Karakyr", "0")
    assert meta["header"] == "Gazli USSR, 5/17/1976, Karakyr, 0"


@pytest.mark.parametrize(
    "line4",
    [
        "NPTS=   5, DT=   .0100 SEC,",
        "NPTS=5,DT=0.01 SEC",
        "NPTS = 5 , DT = 1.0E-02 SEC,   0 POLE @    30.00000 HZ",
        "    5    .0100    NPTS, DT",
    ],
)
def test_at2_header_spacing_variants(tmp_path: Path, line4: str) -> None:
    f = tmp_path / "x.at2"
    f.write_text(AT2_HEADER + line4 + "\n  .1E-01  -.2E-01  .3E-01\n  .4E-01  .5E-01\n")
    motion = GroundMotion.from_file(f)
    assert motion.dt == 0.01 and motion.accel.n == 5
    np.testing.assert_array_equal(motion.accel.acc, np.array([0.01, -0.02, 0.03, 0.04, 0.05]) * G)


@pytest.mark.parametrize(
    ("body", "match"),
    [
        ("NPTS=   6, DT=   .0100 SEC\n .1 .2 .3\n .4 .5\n", "NPTS=6, but the file has 5"),
        ("NPTS=   4, DT=   .0100 SEC\n .1 .2 .3\n .4 .5\n", "NPTS=4, but the file has 5"),
        ("NPTS=   3, DT=   .0100 SEC\n .1 nan .3\n", "not finite"),
        ("NPTS=   3, DT=   .0100 SEC\n .1 x .3\n", "line 5: not a number"),
        ("NPTS=   3 SEC\n .1 .2 .3\n", "line 4: cannot find NPTS and DT"),
        ("NPTS=   0, DT=   .0100 SEC\n", "at least 2 samples"),
    ],
)
def test_bad_at2_is_rejected_naming_the_file(tmp_path: Path, body: str, match: str) -> None:
    f = tmp_path / "bad.AT2"
    f.write_text(AT2_HEADER + body)
    with pytest.raises(InputError, match=match) as err:
        GroundMotion.from_at2(f)
    assert err.value.field == "record" and "bad.AT2" in str(err.value)


def test_at2_with_bad_header_or_units_is_rejected(tmp_path: Path) -> None:
    f = tmp_path / "v.AT2"
    f.write_text(AT2_HEADER.replace("ACCELERATION", "VELOCITY") + "NPTS= 2, DT= .01\n1 2\n")
    with pytest.raises(InputError, match="not an acceleration record"):
        GroundMotion.from_at2(f)
    f.write_text(AT2_HEADER.replace("OF G", "OF FT/S/S") + "NPTS= 2, DT= .01\n1 2\n")
    with pytest.raises(InputError, match="unknown units"):
        GroundMotion.from_at2(f)
    f.write_text("PEER NGA\nx\n")
    with pytest.raises(InputError, match="4 header lines"):
        GroundMotion.from_at2(f)
    f.write_text(AT2_HEADER + "NPTS= 2, DT= .01\n1 2\n")
    with pytest.raises(InputError, match="states units 'g'") as err:
        GroundMotion.from_file(f, units="m/s2")
    assert err.value.field == "units"
    with pytest.raises(InputError, match="own time step") as err:
        GroundMotion.from_file(f, dt=0.02)
    assert err.value.field == "dt"


# --- one column and CSV: round trips of El Centro -------------------------------------


def test_one_column_round_trip(tmp_path: Path, elcentro_path: Path) -> None:
    ref = GroundMotion.from_two_column(elcentro_path, units="g")
    raw = np.loadtxt(elcentro_path)
    f = tmp_path / "elc.txt"
    f.write_text("# El Centro NS [g]\n\n" + "\n".join(repr(x) for x in raw[:, 1].tolist()) + "\n")
    motion = GroundMotion.from_one_column(f, 0.02, "g")
    np.testing.assert_array_equal(motion.accel.acc, ref.accel.acc)
    assert motion.dt == 0.02 and motion.metadata["format"] == "one_column"
    auto = GroundMotion.from_file(f, units="g", dt=0.02)
    np.testing.assert_array_equal(auto.accel.acc, ref.accel.acc)


@pytest.mark.parametrize(
    ("header", "kwargs"),
    [
        ("time,acc", {}),
        ("t_s, accel_g", {}),
        ("acc,time", {"time_column": "TIME", "accel_column": "acc"}),
    ],
)
def test_csv_round_trip(
    tmp_path: Path, elcentro_path: Path, header: str, kwargs: dict[str, Any]
) -> None:
    ref = GroundMotion.from_two_column(elcentro_path, units="g")
    raw = np.loadtxt(elcentro_path)
    cols = raw if header.startswith("t") else raw[:, ::-1]
    f = tmp_path / "elc.csv"
    f.write_text(header + "\n" + "\n".join(f"{a!r},{b!r}" for a, b in cols.tolist()) + "\n")
    motion = GroundMotion.from_csv(f, "g", **kwargs)
    np.testing.assert_array_equal(motion.accel.acc, ref.accel.acc)
    assert motion.dt == ref.dt and motion.accel.n == 2688
    if not kwargs:
        auto = GroundMotion.from_file(f, units="g")
        np.testing.assert_array_equal(auto.accel.acc, ref.accel.acc)


def test_csv_without_time_column_uses_dt(tmp_path: Path) -> None:
    f = tmp_path / "a.csv"
    f.write_text("acc_cm_s2\n1.0\n-2.0\n3.0\n")
    motion = GroundMotion.from_csv(f, "cm/s2", dt=0.01)
    np.testing.assert_allclose(motion.accel.acc, [0.01, -0.02, 0.03], rtol=1e-15)
    assert motion.dt == 0.01
    g = tmp_path / "b.csv"
    g.write_text("t,x,y\n0,1,5\n0.1,2,6\n0.2,3,7\n")
    assert GroundMotion.from_csv(g, "m/s2", accel_column="y", dt=0.5).accel.acc.tolist() == [
        5.0,
        6.0,
        7.0,
    ]
    np.testing.assert_array_equal(
        GroundMotion.from_csv(g, "m/s2", accel_column=2).accel.acc, [5, 6, 7]
    )


@pytest.mark.parametrize(
    ("text", "kwargs", "field", "match"),
    [
        ("acc\n1\n2\n", {}, "dt", "no time column; give dt"),
        ("t,a\n0,1\n0.1,2\n", {"time_column": "t", "dt": 0.1}, "dt", "not both"),
        ("t,a,b\n0,1,2\n0.1,2,3\n", {"dt": 0.1}, "accel_column", "name the acceleration"),
        ("t,a\n0,1\n0.1,2\n", {"accel_column": "b"}, "accel_column", "no column 'b'"),
        ("t,a\n0,1\n0.1,2\n", {"time_column": 5}, "time_column", "column index 5"),
        ("t,a\n0,1\n0.1,2\n", {"accel_column": "t"}, "accel_column", "same column"),
        ("t,a\n0,1\n0.1,nan\n0.2,1\n", {}, "record", "not finite"),
        ("t,a\n0,1\n0.2,2\n0.1,1\n", {}, "record", "strictly increasing"),
        ("t,a\n0,1\n0.1,2\n0.3,1\n", {}, "record", "not uniform"),
        ("t,a\n0,1\n0.1\n", {}, "record", "line 3: expected 2 columns"),
        ("t,a\n0,1\n0.1,x\n", {}, "record", "line 3: not a number"),
        ("t,a\n", {}, "record", "at least 2 samples"),
        ("", {}, "record", r"is empty \(0 bytes\)"),
        ("t,a\n0,1\n0.1,2\n", {"dt": -1.0}, "dt", "> 0"),
    ],
)
def test_bad_csv_is_rejected_with_a_reason(
    tmp_path: Path, text: str, kwargs: dict[str, Any], field: str, match: str
) -> None:
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(InputError, match=match) as err:
        GroundMotion.from_csv(f, "g", **kwargs)
    assert err.value.field == field


@pytest.mark.parametrize(
    ("text", "dt", "field", "match"),
    [
        ("0.1\n0.2\n", 0.0, "dt", "> 0"),
        ("0.1\n0.2\n", float("nan"), "dt", "> 0"),
        ("0.1\n0.2\n", float("inf"), "dt", "> 0"),
        ("0.1\nnan\n0.2\n", 0.01, "record", "not finite"),
        ("0.1\n0.2 0.3\n", 0.01, "record", "bad.txt line 2: expected 1 column"),
        ("0.1\nabc\n", 0.01, "record", "line 2: not a number"),
        ("0.1\n", 0.01, "record", "at least 2 samples"),
        ("# only a comment\n\n", 0.01, "record", "at least 2 samples"),
    ],
)
def test_bad_one_column_is_rejected_with_a_reason(
    tmp_path: Path, text: str, dt: float, field: str, match: str
) -> None:
    f = tmp_path / "bad.txt"
    f.write_text(text)
    with pytest.raises(InputError, match=match) as err:
        GroundMotion.from_one_column(f, dt, "g")
    assert err.value.field == field


def test_one_column_and_csv_reject_unknown_units(tmp_path: Path) -> None:
    f = tmp_path / "a.txt"
    f.write_text("1\n2\n")
    reads: list[Callable[[], GroundMotion]] = [
        lambda: GroundMotion.from_one_column(f, 0.1, "ft/s2"),
        lambda: GroundMotion.from_csv(f, "ft/s2", dt=0.1),
        lambda: GroundMotion.from_file(f, units="ft/s2", dt=0.1),
    ]
    for read in reads:
        with pytest.raises(InputError, match="must be one of") as err:
            read()
        assert err.value.field == "units"


# --- from_file: dispatch and detection ------------------------------------------------


def test_from_file_detects_two_and_one_column(tmp_path: Path, elcentro_path: Path) -> None:
    ref = GroundMotion.from_two_column(elcentro_path, units="g")
    two = GroundMotion.from_file(elcentro_path, units="g")
    assert two.metadata["format"] == "two_column"
    np.testing.assert_array_equal(two.accel.acc, ref.accel.acc)
    one = tmp_path / "one.dat"
    one.write_text("# header comment\n1.0\n2.0\n")
    assert GroundMotion.from_file(one, units="m/s2", dt=0.5).metadata["format"] == "one_column"
    # An explicit format overrides detection (a .dat file that is CSV).
    c = tmp_path / "c.dat"
    c.write_text("time,acc\n0,1\n0.5,2\n")
    assert GroundMotion.from_file(c, format="csv", units="g").dt == 0.5
    # A PEER file without the .AT2 extension is recognised by its first line.
    p = tmp_path / "peer.txt"
    p.write_text(AT2_HEADER + "NPTS= 2, DT= .01\n1 2\n")
    assert GroundMotion.from_file(p).metadata["format"] == "at2"


def test_from_file_errors_name_the_file_and_field(tmp_path: Path, elcentro_path: Path) -> None:
    with pytest.raises(InputError, match="give units: g, m/s2, cm/s2") as err:
        GroundMotion.from_file(elcentro_path)
    assert err.value.field == "units" and "elcentro_NS.dat" in str(err.value)
    with pytest.raises(InputError, match="has a time column") as err:
        GroundMotion.from_file(elcentro_path, units="g", dt=0.02)
    assert err.value.field == "dt"
    with pytest.raises(InputError, match=r"unknown record format 'xlsx' for elcentro_NS\.dat") as e:
        GroundMotion.from_file(elcentro_path, format="xlsx", units="g")
    assert e.value.field == "format" and "'at2', 'two_column', 'one_column', 'csv'" in str(e.value)
    three = tmp_path / "three.dat"
    three.write_text("0 1 2\n0.1 2 3\n")
    with pytest.raises(InputError, match=r"cannot tell the format of three\.dat") as err:
        GroundMotion.from_file(three, units="g")
    assert err.value.field == "format" and "one_column" in str(err.value)
    words = tmp_path / "words.txt"
    words.write_text("hello world\n")
    with pytest.raises(InputError, match=r"cannot tell the format of words\.txt"):
        GroundMotion.from_file(words, units="g")
    one = tmp_path / "one.dat"
    one.write_text("1\n2\n")
    with pytest.raises(InputError, match=r"one_column file one\.dat needs a time step") as err:
        GroundMotion.from_file(one, units="g")
    assert err.value.field == "dt"
    with pytest.raises(InputError, match="give units") as err:
        GroundMotion.from_file(one, dt=0.1)
    empty = tmp_path / "empty.dat"
    empty.write_text("\n# nothing\n")
    with pytest.raises(InputError, match=r"empty\.dat is empty") as err:
        GroundMotion.from_file(empty, units="g")
    assert err.value.field == "record"
    with pytest.raises(InputError, match="not found"):
        GroundMotion.from_file(tmp_path / "nope.dat", units="g")
    with pytest.raises(InputError, match="not found"):
        GroundMotion.from_file(tmp_path / "nope.AT2")


def test_a_time_column_starting_before_zero_is_shifted_with_a_note(tmp_path: Path) -> None:
    t = np.arange(-2.0, 2.0, 0.01)
    a = 0.2 * np.sin(2 * np.pi * t)
    shifted, plain = tmp_path / "neg.dat", tmp_path / "zero.dat"
    np.savetxt(shifted, np.column_stack([t, a]))
    np.savetxt(plain, np.column_stack([t + 2.0, a]))
    m1 = GroundMotion.from_file(shifted, units="g")
    m0 = GroundMotion.from_file(plain, units="g")
    assert m1.accel.n == t.size  # every sample kept
    assert np.array_equal(m1.accel.acc, m0.accel.acc)
    assert m1.accel.t0 == 0.0 and m1.metadata["time_shift_s"] == 2.0
    assert any("shifted by 2 s" in w for w in m1.warnings)
    assert not m0.warnings


@pytest.mark.parametrize(
    ("amplitude", "units", "dt", "expect"),
    [
        (0.3, "g", 0.01, None),
        (0.3, "cm/s2", 0.01, "PGA"),  # a record in g read as cm/s2: PGA 0.0003 g
        (30.0, "g", 0.01, "PGA"),
        (0.3, "g", 0.5, "dt"),
        (0.3, "g", 5e-5, "dt"),
    ],
)
def test_an_implausible_record_gets_a_warning_naming_its_units(
    tmp_path: Path, amplitude: float, units: str, dt: float, expect: Any
) -> None:
    t = dt * np.arange(2000)
    path = tmp_path / "rec.dat"
    np.savetxt(path, np.column_stack([t, amplitude * np.sin(t)]))
    motion = GroundMotion.from_file(path, units=units)
    # the PGA warning names the acceleration units read; the time step's names seconds and
    # where the step came from, never the acceleration units (#25)
    said = f"read in {units}" if expect == "PGA" else "read as seconds from the time column"
    if expect is None:
        assert motion.warnings == []
    else:
        notes = [w for w in motion.warnings if w.startswith(expect) or f"{expect} =" in w]
        assert notes and all(said in w for w in notes), motion.warnings
        if expect == "dt":
            assert not any(f"read in {units}" in w for w in notes), notes


def test_a_record_starting_before_zero_is_refused_by_the_solver_view() -> None:
    from solver_service.core.excitation import SampledAccel

    with pytest.raises(InputError, match="t0: must be finite and >= 0"):
        SampledAccel(np.zeros(10), 0.01, t0=-2.0)
    later = SampledAccel(np.zeros(10), 0.01, t0=5.0)
    assert later.time[0] == 5.0
