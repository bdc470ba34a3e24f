"""Bad ground-motion records through ``rockmech record --json`` and ``rockmech history``
(issue #14 corpus).

Every format the readers know gets every defect: AT2, two-column, one-column and CSV files are
written into the case's tmp folder; the strong-motion formats (K-NET, ESM, COSMOS V2c, DMG V2,
GeoNet V2A) are mutated copies of the shared real files (the project's shared records folder,
read from beside the repository; those cases skip where it is absent and the files are never
copied into the repository). A bad record gets exit status 2 and ``error: <field>: ...``; a
record the readers can read but should doubt (late start, implausible PGA) gets a warning and
keeps every sample. Cases the code still answers wrongly are strict-xfail with their #14 class.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from corpus_case import Case, params, run_case

REPO = Path(__file__).resolve().parents[2]
FORMATS = REPO.parent / "shared" / "data" / "records" / "formats"
CONSTANTS = REPO / "examples" / "constants" / "rect_walls.json"

DT = 0.01
N = 400
T = np.arange(N) * DT
A_G = 0.3 * np.sin(2 * np.pi * 1.5 * T) * np.exp(-0.2 * T)


def _at2(
    a: np.ndarray = A_G, npts: Any = None, dt: Any = DT, units: str = "G", per_line: int = 5
) -> str:
    """A PEER NGA AT2 file [units of ``units``]."""
    head = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        "Corpus test, 1/1/2000, Station, 0",
        f"ACCELERATION TIME SERIES IN UNITS OF {units}",
    ]
    npts_s = f"NPTS= {len(a) if npts is None else npts:6d}"
    head.append(npts_s if dt is None else f"{npts_s}, DT= {dt} SEC")
    rows = ["".join(f"{x:15.7E}" for x in a[i : i + per_line]) for i in range(0, len(a), per_line)]
    return "\n".join(head + rows) + "\n"


def _two(t: np.ndarray = T, a: np.ndarray = A_G) -> str:
    return "\n".join(f"{ti:.6f} {ai:.6e}" for ti, ai in zip(t, a)) + "\n"


def _one(a: np.ndarray = A_G) -> str:
    return "\n".join(f"{ai:.6e}" for ai in a) + "\n"


def _csv(t: np.ndarray = T, a: np.ndarray = A_G, header: str = "t [s],acc [g]") -> str:
    return header + "\n" + "\n".join(f"{ti:.6f},{ai:.6e}" for ti, ai in zip(t, a)) + "\n"


def _nan_at(a: np.ndarray, i: int = 100) -> np.ndarray:
    b = a.copy()
    b[i] = np.nan
    return b


JUNK = np.random.default_rng(14).bytes(512)
T_NONUNIFORM = T + np.where(np.arange(N) % 2 == 1, 0.003, 0.0)
T_DUP = np.concatenate([T[:50], T[49:-1]])
T_LATE = T + 2.0
T_NEG_DT = T[::-1].copy()


def _n_is(n: int) -> Callable[[Any], bool]:
    return lambda d: d["record"]["n_samples"] == n


def _pga_is(pga: float) -> Callable[[Any], bool]:
    return lambda d: abs(d["record"]["pga_g"] - pga) < 1e-4 * pga


PGA = float(np.max(np.abs(A_G)))

#: Synthetic record cases: (id, file name, content, extra argv, expect, field, problem[, xfail]).
SYNTH: list[tuple[Any, ...]] = [
    # AT2
    ("at2-good", "r.AT2", _at2(), [], "ok", "", "", "", _n_is(N)),
    (
        "at2-truncated",
        "r.AT2",
        _at2()[: len(_at2()) // 2],
        [],
        "error",
        "record|npts",
        "NPTS|count|fewer|truncated",
    ),
    (
        "at2-npts-too-big",
        "r.AT2",
        _at2(npts=N + 37),
        [],
        "error",
        "record|npts",
        "NPTS|count|fewer|truncated",
    ),
    (
        "at2-npts-too-small",
        "r.AT2",
        _at2(npts=N - 37),
        [],
        "error",
        "record|npts",
        "NPTS|count|more|extra",
    ),
    ("at2-npts-zero", "r.AT2", _at2(npts=0), [], "error", "record|npts", "NPTS|count|0|empty"),
    ("at2-nan-sample", "r.AT2", _at2(_nan_at(A_G)), [], "error", "record", "finite|nan|sample"),
    (
        "at2-units-furlong",
        "r.AT2",
        _at2(units="FURLONGS/S2"),
        [],
        "error",
        "units|record",
        "FURLONG|unit",
    ),
    (
        "at2-units-cm",
        "r.AT2",
        _at2(A_G * 981.0, units="CM/S/S"),
        [],
        "ok",
        "",
        "",
        "",
        _pga_is(PGA * 981.0 / 980.665),
    ),
    ("at2-no-dt", "r.AT2", _at2(dt=None), [], "error", "dt|record", "DT|time step"),
    ("at2-dt-zero", "r.AT2", _at2(dt="0.0"), [], "error", "dt", "> 0|positive"),
    ("at2-dt-negative", "r.AT2", _at2(dt="-.01"), [], "error", "dt", "> 0|positive"),
    ("at2-dt-text", "r.AT2", _at2(dt="abc"), [], "error", "dt|record", "DT|abc|number"),
    ("at2-binary-junk", "r.AT2", _at2().encode() + JUNK, [], "error", "record", "."),
    (
        "at2-header-only",
        "r.AT2",
        "\n".join(_at2().splitlines()[:4]) + "\n",
        [],
        "error",
        "record|npts",
        "NPTS|count|no samples|empty",
    ),
    (
        "at2-channel-9",
        "r.AT2",
        _at2(),
        ["--channel", "9"],
        "error",
        "channel",
        "9|one channel|holds",
    ),
    ("at2-huge-pga", "r.AT2", _at2(A_G * 100.0), [], "warn", "", r"PGA.*\(read in g\)|PGA.*units"),
    ("at2-tiny-pga", "r.AT2", _at2(A_G * 1e-4), [], "warn", "", r"PGA.*\(read in g\)|PGA.*units"),
    (
        "at2-as-csv",
        "r.AT2",
        _at2(),
        ["--format", "csv"],
        "error",
        "record|format|dt",
        "csv|column|header",
    ),
    # two columns
    ("two-good", "r.dat", _two(), [], "ok", "", "", "", _n_is(N)),
    (
        "two-truncated-line",
        "r.dat",
        _two().rstrip("\n").rsplit(" ", 1)[0] + "\n",
        [],
        "error",
        "record",
        "line|column|truncated",
    ),
    ("two-nan", "r.dat", _two(a=_nan_at(A_G)), [], "error", "record", "finite|nan"),
    (
        "two-nonuniform",
        "r.dat",
        _two(T_NONUNIFORM),
        [],
        "error",
        "record|dt|time",
        "uniform|step|spacing",
    ),
    (
        "two-duplicate-time",
        "r.dat",
        _two(T_DUP),
        [],
        "error",
        "record|time",
        "duplicate|increas|repeat|uniform",
    ),
    (
        "two-time-backwards",
        "r.dat",
        _two(T_NEG_DT),
        [],
        "error",
        "record|time",
        "increas|negative|backward|uniform",
    ),
    (
        "two-all-same-time",
        "r.dat",
        _two(np.zeros(N)),
        [],
        "error",
        "record|time|dt",
        "increas|dt|zero|duplicate|uniform",
    ),
    (
        "two-late-start",
        "r.dat",
        _two(T_LATE),
        ["--json"],
        "warn",
        "",
        r"start|t\[0\]|shift",
        "",
        _n_is(N),
    ),
    ("two-units-furlong", "r.dat", _two(), ["--units", "furlong"], "error", "units", "g|m/s2"),
    (
        "two-units-m-s2-implausible",
        "r.dat",
        _two(a=A_G * 1e-3),
        ["--units", "m/s2"],
        "warn",
        "",
        r"PGA.*\(read in m/s2\)|PGA.*units",
    ),
    (
        "two-huge-pga",
        "r.dat",
        _two(a=A_G * 100.0),
        [],
        "warn",
        "",
        r"PGA.*\(read in g\)|PGA.*units",
    ),
    ("two-binary-junk", "r.dat", _two().encode() + JUNK, [], "error", "record", "."),
    (
        "two-channel-9",
        "r.dat",
        _two(),
        ["--channel", "9"],
        "error",
        "channel",
        "9|one channel|holds",
    ),
    (
        "two-dt-given-too",
        "r.dat",
        _two(),
        ["--dt", "0.02"],
        "error",
        "dt",
        "time column|ignored|both",
    ),
    (
        "two-text-value",
        "r.dat",
        _two().replace("1.000000e-", "abc", 1)
        if "1.000000e-" in _two()
        else _two().replace(" ", " x", 1),
        [],
        "error",
        "record|format",
        "line|number|x|abc",
    ),
    # one column
    ("one-good", "r.txt", _one(), ["--dt", "0.01", "--units", "g"], "ok", "", "", "", _n_is(N)),
    ("one-no-dt", "r.txt", _one(), ["--units", "g"], "error", "dt", "time step|--dt|dt"),
    ("one-no-units", "r.txt", _one(), ["--dt", "0.01"], "error", "units", "units|g|m/s2"),
    ("one-dt-zero", "r.txt", _one(), ["--dt", "0", "--units", "g"], "error", "dt", "> 0"),
    ("one-dt-negative", "r.txt", _one(), ["--dt", "-0.01", "--units", "g"], "error", "dt", "> 0"),
    ("one-dt-nan", "r.txt", _one(), ["--dt", "nan", "--units", "g"], "error", "dt", "finite"),
    (
        "one-dt-huge",
        "r.txt",
        _one(),
        ["--dt", "1e300", "--units", "g"],
        "error",
        "dt",
        r"outside .*\[1e-06, 1\] s",
    ),
    # the plausibility band warns; the hard range (DT_RANGE_S) refuses
    ("one-dt-coarse", "r.txt", _one(), ["--dt", "0.5", "--units", "g"], "warn", "", r"dt = 0\.5"),
    ("one-dt-tiny", "r.txt", _one(), ["--dt", "1e-9", "--units", "g"], "error", "dt", "1e-06"),
    ("at2-dt-huge", "r.AT2", _at2(dt="1E+30"), [], "error", "dt", r"outside .*\[1e-06, 1\]"),
    (
        "one-accel-1e308-g",
        "r.txt",
        _one(np.where(np.arange(N) == 5, 1e308, A_G)),
        ["--dt", "0.01", "--units", "g"],
        "error",
        "record",
        r"sample 5 is 1e\+308 g, above .*1000 g",
    ),
    (
        "one-accel-mm-as-g",
        "r.txt",
        _one(A_G * 1e4),
        ["--dt", "0.01", "--units", "g"],
        "error",
        "record",
        "above the largest acceleration.*units",
    ),
    (
        "one-nan",
        "r.txt",
        _one(_nan_at(A_G)),
        ["--dt", "0.01", "--units", "g"],
        "error",
        "record",
        "finite|nan",
    ),
    (
        "one-binary-junk",
        "r.txt",
        _one().encode() + JUNK,
        ["--dt", "0.01", "--units", "g"],
        "error",
        "record",
        ".",
    ),
    (
        "one-channel-9",
        "r.txt",
        _one(),
        ["--dt", "0.01", "--units", "g", "--channel", "9"],
        "error",
        "channel",
        "9|one channel|holds",
    ),
    (
        "one-huge-pga",
        "r.txt",
        _one(A_G * 1e3),
        ["--dt", "0.01", "--units", "m/s2"],
        "warn",
        "",
        r"PGA.*\(read in m/s2\)|PGA.*units",
    ),
    # CSV with the units in the header
    ("csv-good", "r.csv", _csv(), [], "ok", "", "", "", _n_is(N)),
    (
        "csv-m-s2",
        "r.csv",
        _csv(a=A_G * 9.80665, header="time [s],acc [m/s2]"),
        [],
        "ok",
        "",
        "",
        "",
        _pga_is(PGA),
    ),
    (
        "csv-units-furlong",
        "r.csv",
        _csv(header="t [s],acc [furlong]"),
        [],
        "error",
        "units|acc",
        "furlong|unit",
    ),
    ("csv-no-units", "r.csv", _csv(header="t,acc"), [], "error", "units", "units|g|m/s2"),
    (
        "csv-header-only",
        "r.csv",
        "t [s],acc [g]\n",
        [],
        "error",
        "record",
        "no samples|empty|rows|at least",
    ),
    ("csv-nan", "r.csv", _csv(a=_nan_at(A_G)), [], "error", "record", "finite|nan"),
    (
        "csv-nonuniform",
        "r.csv",
        _csv(T_NONUNIFORM),
        [],
        "error",
        "record|dt|time",
        "uniform|step|spacing",
    ),
    (
        "csv-duplicate-time",
        "r.csv",
        _csv(T_DUP),
        [],
        "error",
        "record|time",
        "duplicate|increas|repeat|uniform",
    ),
    (
        "csv-late-start",
        "r.csv",
        _csv(T_LATE),
        ["--json"],
        "warn",
        "",
        r"start|t\[0\]|shift",
        "",
        _n_is(N),
    ),
    (
        "csv-text-cell",
        "r.csv",
        _csv().replace(",", ",abc", 5).replace(",abc", ",", 4),
        [],
        "error",
        "record",
        "line|row|number|abc",
    ),
    ("csv-binary-junk", "r.csv", _csv().encode() + JUNK, [], "error", "record", "."),
    (
        "csv-channel-9",
        "r.csv",
        _csv(),
        ["--channel", "9"],
        "error",
        "channel",
        "9|one channel|holds|column",
    ),
    (
        "csv-huge-pga",
        "r.csv",
        _csv(a=A_G * 100.0),
        [],
        "warn",
        "",
        r"PGA.*\(read in g\)|PGA.*units",
    ),
    # any format
    ("empty-file", "r.dat", "", [], "error", "record", "empty|no samples"),
    # #25: empty, binary and other-encoding files say what was expected and what to do
    ("empty-csv", "r.csv", "", [], "error", "record", r"r\.csv is empty \(0 bytes\): expected"),
    ("empty-at2", "r.AT2", "\n\n", [], "error", "record", "holds only blank space: expected"),
    (
        "binary-record",
        "r.dat",
        JUNK,
        [],
        "error",
        "record",
        r"r\.dat is not a text file \(binary data .*export the record as text",
    ),
    (
        "xlsx-record",
        "r.xlsx",
        b"PK\x03\x04" + JUNK,
        [],
        "error",
        "record",
        r"not a text file \(it starts like .*Excel .*workbook.*export the record as text",
    ),
    (
        "csv-windows-1252",
        "r.csv",
        ("# station in Montréal\n" + _csv()).encode("cp1252"),
        [],
        "error",
        "record",
        r"not UTF-8 text: byte \d+ \(line 1\).*Windows-1252.*save it again as UTF-8",
    ),
    ("csv-utf16", "r.csv", _csv().encode("utf-16"), [], "ok", "", "", "", _n_is(N)),
    # a European spreadsheet's CSV: ';' between cells, decimal commas
    ("csv-semicolon", "r.csv", _csv().replace(",", ";"), [], "ok", "", "", "", _n_is(N)),
    (
        "csv-semicolon-decimal-comma",
        "r.csv",
        _csv().replace(",", ";").replace(".", ","),
        [],
        "ok",
        "",
        "",
        "",
        _pga_is(PGA),
    ),
    ("format-unknown", "r.dat", _two(), ["--format", "mp3"], "error", "format", "at2|csv"),
    (
        "units-with-at2",
        "r.AT2",
        _at2(),
        ["--units", "m/s2"],
        "error",
        "units",
        "states|G|g|its own",
    ),
]

# --- issue #36: strong-motion headers cut short or miscounted, built here from scratch --------

#: A record in cm/s² for the strong-motion builders (30 cm/s² peak at 1.5 Hz).
A_CM = 30.0 * np.sin(2 * np.pi * 1.5 * T)
PGA_CM = float(np.max(np.abs(A_CM)))


def _esm(a: np.ndarray = A_CM) -> str:
    """An ESM / ITACA ASCII file (DYNA 1.2: 64 ``KEY: value`` lines to ``USER5:``) in cm/s²."""
    keys = ["EVENT_NAME: CORPUS", "EVENT_ID: TEST-36", "EVENT_DATE_YYYYMMDD: 20000101"]
    keys += [f"FIELD_{k}: " for k in range(27)]
    keys += [f"SAMPLING_INTERVAL_S: {DT:.6f}", f"NDATA: {len(a)}", f"DURATION_S: {len(a) * DT:.3f}"]
    keys += ["STREAM: HNE", "UNITS: cm/s^2", f"PGA_CM/S^2: {np.max(np.abs(a)):.6f}"]
    keys += ["DATA_TYPE: ACCELERATION"]
    keys += [f"FILLER_{k}: " for k in range(len(keys), 63)] + ["USER5: "]
    assert len(keys) == 64
    return "\n".join(keys + [f"{x:.6f}" for x in a]) + "\n"


def _esm_lines(n: int) -> str:
    """The ESM file's first ``n`` lines (a download cut short in its header)."""
    return "".join(_esm().splitlines(keepends=True)[:n])


def _cosmos(text_lines: int = 13, a: np.ndarray = A_CM) -> str:
    """A COSMOS V2 file of one channel in cm/s², its first line saying ``text_lines``."""
    head = [f"Corrected acceleration    (Format v01.20 with {text_lines:2d} text lines)"]
    head += [f"corpus text line {k}" for k in range(2, 14)]
    ints = [-999] * 100
    ints[0], ints[1] = 2, 1  # corrected (V2), acceleration
    reals = [-999.0] * 100
    peak = int(np.argmax(np.abs(a)))
    reals[61:65] = [DT * 1000.0, len(a) * DT, float(a[peak]), peak * DT]
    out = [*head, " 100 Integer-header values follow on  10 lines, Format= (10I8)"]
    out += ["".join(f"{v:8d}" for v in ints[k : k + 10]) for k in range(0, 100, 10)]
    out += [" 100 Real-header values follow on  20 lines, Format= (5F15.6)"]
    out += ["".join(f"{v:15.6f}" for v in reals[k : k + 5]) for k in range(0, 100, 5)]
    out += ['   1 Comment line(s) follow, each starting with a "|":', "| corpus"]
    data = f"  {len(a)} acceleration pts, approx  {round(len(a) * DT)} secs, units=cm/sec2(04)"
    out += [data + ",Format=(1E15.6)", *[f"{x:15.6e}" for x in a]]
    return "\n".join([*out, "End-of-data for Chan 1 acceleration"]) + "\n"


SYNTH += [
    # the builders give readable files: the peak is the samples' (cm/s² to g by 980.665)
    ("esm-good", "r.ASC", _esm(), [], "ok", "", "", "", _pga_is(PGA_CM / 980.665)),
    ("cosmos-good", "r.V2c", _cosmos(), [], "ok", "", "", "", _pga_is(PGA_CM / 980.665)),
    (
        # cut within the keys that identify the format: was "cannot tell the format"
        "esm-header-cut-at-line-20",
        "r.ASC",
        _esm_lines(20),
        [],
        "error",
        "record",
        r"r\.ASC: the ESM / ITACA header stops after line 20 \(FIELD_16:\), before its last key "
        r"USER5: .*the file is truncated; .*\(it lacks NDATA, SAMPLING_INTERVAL_S, UNITS\)",
    ),
    (
        # cut after them: was "header says 400 samples, but the file has 0"
        "esm-header-cut-at-line-40",
        "r.ASC",
        _esm_lines(40),
        [],
        "error",
        "record",
        r"the ESM / ITACA header stops after line 40 \(FILLER_39:\), before its last key USER5: "
        r"\(a DYNA 1\.2 header has 64 'KEY: value' lines",
    ),
    (
        # was "line 201: expected the integer-header line"
        "cosmos-text-lines-200",
        "r.V2c",
        _cosmos(200),
        [],
        "error",
        "record",
        r"r\.V2c line 1 says the channel's text header has 200 lines, but its integer-header "
        r"line is line 14, after 13 text lines .*it should read 'with 13 text lines'",
    ),
    (
        "cosmos-header-cut-in-text",
        "r.V2c",
        "".join(_cosmos().splitlines(keepends=True)[:10]),
        [],
        "error",
        "record",
        r"says the channel's text header has 13 lines, but the file ends after 10 lines .*the "
        r"file is truncated or its header is too long",
    ),
]

#: The shared strong-motion files: name -> (format, options picking one channel).
REAL = {
    "CHB0031412312349.NS": ("knet", []),
    "NGNH311106302345.EW2": ("knet", []),
    "HI.ARS1..HNE.D.20190728.160908.C.ACC.ASC": ("esm", []),
    "us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c": ("cosmos", []),
    "ce36456p_CE36456.V2": ("dmg", ["--channel", "1"]),
    "20180212_211557_WPWS_20.V2A": ("geonet", ["--channel", "1"]),
}
#: Header sample counts (or durations) of the single-channel files, and a wrong one.
NPTS = {
    "CHB0031412312349.NS": ("Duration Time(s)  60", "Duration Time(s)  70"),
    "NGNH311106302345.EW2": ("Duration Time(s)  120", "Duration Time(s)  130"),
    "HI.ARS1..HNE.D.20190728.160908.C.ACC.ASC": ("NDATA: 19128", "NDATA: 19378"),
    "us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c": (
        "42000 acceleration pts",
        "42250 acceleration pts",
    ),
}
#: Units words of the headers, and the same header with a unit no reader knows.
UNITS_WORD = {
    "CHB0031412312349.NS": ("(gal)/", "(furlong)/"),
    "NGNH311106302345.EW2": ("(gal)/", "(furlong)/"),
    "HI.ARS1..HNE.D.20190728.160908.C.ACC.ASC": ("UNITS: cm/s^2", "UNITS: furlong/s^2"),
    "us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c": (
        "units=cm/sec2(04)",
        "units=furlong(99)",
    ),
}
_FLOAT = re.compile(r"-?\d*\.?\d+(?:[eE][-+]?\d+)?")


def _truncate(text: str) -> str:
    lines = text.splitlines(keepends=True)
    return "".join(lines[: int(len(lines) * 0.6)])


def _nan_in_data(text: str, at: float = 0.15) -> str:
    """Replace one sample (the last number of the line a fraction ``at`` into the file) by NaN.

    The line is in the first channel's accelerations for ``at`` 0.15 in a one-channel file
    and 0.05 in a three-channel one (whose channels also hold velocity and displacement).
    """
    lines = text.splitlines(keepends=True)
    i = int(len(lines) * at)
    while not _FLOAT.search(lines[i]):
        i += 1
    last = list(_FLOAT.finditer(lines[i]))[-1]
    lines[i] = lines[i][: last.start()] + "NaN" + lines[i][last.end() :]
    return "".join(lines)


def _nan_multi(text: str) -> str:
    return _nan_in_data(text, 0.05)


def _npts_changed(name: str) -> Callable[[str], str]:
    old, new = NPTS[name]
    return lambda text: text.replace(old, new, 1)


def _units_changed(name: str) -> Callable[[str], str]:
    old, new = UNITS_WORD[name]
    return lambda text: text.replace(old, new, 1)


#: Strong-motion cases: (id, file, mutation of its text (or None), extra argv, expect, field,
#: problem[, xfail[, check]]).
REAL_CASES: list[tuple[Any, ...]] = []
for _name, (_fmt, _pick) in REAL.items():
    _tag = f"{_fmt}-{_name[:8]}"
    # a truncated multi-channel file loses its last channel
    _last = ["--channel", "3"] if _pick else []
    REAL_CASES += [
        (f"{_tag}-good", _name, None, _pick, "ok", "", ""),
        (
            f"{_tag}-truncated",
            _name,
            _truncate,
            _last,
            "error",
            "record|npts|channel",
            "count|fewer|truncated|points|samples|end|channel",
        ),
        (
            f"{_tag}-nan-sample",
            _name,
            _nan_multi if _pick else _nan_in_data,
            _pick,
            "error",
            "record",
            "finite|nan|number|sample",
        ),
        (f"{_tag}-binary-junk", _name, "junk", _pick, "error", "record", "."),
        (
            f"{_tag}-channel-9",
            _name,
            None,
            ["--channel", "9"],
            "error",
            "channel",
            "9|holds|channels",
        ),
        (
            f"{_tag}-component-xyz",
            _name,
            None,
            ["--component", "XYZ"],
            "error",
            "component",
            "XYZ|holds|channels",
        ),
        (
            f"{_tag}-as-at2",
            _name,
            None,
            [*_pick, "--format", "at2"],
            "error",
            "record|format",
            "AT2|NPTS|not an acceleration record",
        ),
    ]
    if _name in NPTS:
        REAL_CASES.append(
            (
                f"{_tag}-npts-mismatch",
                _name,
                _npts_changed(_name),
                _pick,
                "error",
                "record|npts",
                "header says|count|points|samples|not a number",
            )
        )
    if _name in UNITS_WORD:
        REAL_CASES.append(
            (
                f"{_tag}-units-word",
                _name,
                _units_changed(_name),
                _pick,
                "error",
                "units|record",
                "furlong|unit",
            )
        )


def _sub(old: str, new: str) -> Callable[[str], str]:
    """A mutation replacing the first ``old`` by ``new`` (which must be there)."""

    def mutate(text: str) -> str:
        assert old in text, old
        return text.replace(old, new, 1)

    return mutate


def _subs(*pairs: tuple[str, str]) -> Callable[[str], str]:
    def mutate(text: str) -> str:
        for old, new in pairs:
            text = _sub(old, new)(text)
        return text

    return mutate


def _cosmos_short_real_header(text: str) -> str:
    """The COSMOS file with a real header of 40 values on 8 lines (its last 12 lines cut)."""
    lines = text.splitlines(keepends=True)
    k = next(i for i, ln in enumerate(lines) if "Real-header values follow" in ln)
    lines[k] = "  40 Real-header values follow on   8 lines, Format= (5F15.6)\n"
    return "".join(lines[: k + 9] + lines[k + 21 :])


def _cosmos_real_lines_missing(text: str) -> str:
    """The COSMOS file with 3 of its 20 real-header lines gone (the count line unchanged)."""
    lines = text.splitlines(keepends=True)
    k = next(i for i, ln in enumerate(lines) if "Real-header values follow" in ln)
    return "".join(lines[: k + 18] + lines[k + 21 :])


KNET = "CHB0031412312349.NS"
COSMOS = "us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c"
ESM = "HI.ARS1..HNE.D.20190728.160908.C.ACC.ASC"
GEONET = "20180212_211557_WPWS_20.V2A"
#: #25: every header value a reader uses, checked against the data it describes.
REAL_CASES += [
    (
        "knet-scale-divides-by-zero",
        KNET,
        _sub("7845(gal)/8223790", "7845(gal)/0"),
        [],
        "error",
        "record",
        r"Scale Factor '7845\(gal\)/0' divides by 0 counts; correct it",
    ),
    (
        # x10 with no peak to check it: a 3.49 g record on which every wall overturns
        "knet-scale-x10-max-acc-empty",
        KNET,
        _subs(("7845(gal)/8223790", "78450(gal)/8223790"), ("8.131", "")),
        [],
        "error",
        "record",
        r"full scale of 78450 gal \(80 g\), outside \[980\.665, 9806\.65\] gal",
    ),
    (
        "knet-scale-negative",
        KNET,
        _sub("7845(gal)/8223790", "-7845(gal)/8223790"),
        [],
        "error",
        "record",
        r"Scale Factor '-7845\(gal\)/8223790' is negative or zero, which would flip",
    ),
    (
        "knet-scale-counts-x10",
        KNET,
        _sub("7845(gal)/8223790", "7845(gal)/822379"),
        [],
        "error",
        "record",
        r"822379 counts at full scale, outside \[2097152, 16777216\]",
    ),
    (
        "knet-count-beyond-full-scale",
        KNET,
        _subs(("    3742     3738", " 9999999     3738"), ("8.131", "")),
        [],
        "error",
        "record",
        r"count 0 is 9999999, beyond the recorder's full scale of 8223790 counts",
    ),
    (
        "knet-max-acc-empty",
        KNET,
        _sub("8.131", ""),
        [],
        "warn",
        "",
        r"'Max\. Acc\. \(gal\)' is empty, so the Scale Factor .* could not be checked",
    ),
    (
        "knet-freq-zero",
        KNET,
        _sub("100Hz", "0Hz"),
        [],
        "error",
        "record",
        r"Sampling Freq\(Hz\) is 0 Hz, outside \[1, 1e\+06\] Hz",
    ),
    (
        "cosmos-data-format-zero",
        COSMOS,
        _sub("Format=(1E15.6)", "Format=(0E15.6)"),
        [],
        "error",
        "record",
        r"gives 0 values a line .*at least 1 value a line",
    ),
    (
        "cosmos-integer-format-zero",
        COSMOS,
        _sub("Format= (10I8)", "Format= (0I8)"),
        [],
        "error",
        "record",
        r"line 14: .*gives 0 values a line",
    ),
    (
        "cosmos-short-real-header",
        COSMOS,
        _cosmos_short_real_header,
        [],
        "error",
        "record",
        r"the real header has 40 values, but the COSMOS V2 format has 100 .*62 sampling",
    ),
    (
        "cosmos-real-header-lines-missing",
        COSMOS,
        _cosmos_real_lines_missing,
        [],
        "error",
        "record",
        r"real header line 4[0-9]: not a number",
    ),
    (
        "cosmos-approx-secs",
        COSMOS,
        _sub("approx  210 secs", "approx  300 secs"),
        [],
        "error",
        "record",
        r"says approx 300 secs, but 42000 points at real header 62's 5 ms last 210 s",
    ),
    (
        "cosmos-length-mismatch",
        COSMOS,
        _sub("210.000000      -6.851512", "250.000000      -6.851512"),
        [],
        "error",
        "record",
        r"real header 63 \(length\) is 250\.000000 s, but 42000 samples at 0\.005 s last 210",
    ),
    (
        "cosmos-interval-zero",
        COSMOS,
        _sub("       5.000000     210.000000", "       0.000000     210.000000"),
        [],
        "error",
        "record",
        r"real header 62 \(sampling interval\) must be > 0 ms, got 0",
    ),
    (
        "esm-duration-mismatch",
        ESM,
        _sub("DURATION_S: 95.640", "DURATION_S: 120.000"),
        [],
        "error",
        "record",
        r"DURATION_S is 120\.000 s, but 19128 samples at 0\.005 s last 95\.64 s",
    ),
    (
        "esm-ndata-fraction",
        ESM,
        _sub("NDATA: 19128", "NDATA: 19128.5"),
        [],
        "error",
        "record",
        r"NDATA must be a whole number >= 2, got 19128\.5",
    ),
    (
        # the time step's warning names seconds and the header field, not the cm/s2 units
        "esm-dt-coarse",
        ESM,
        _subs(
            ("SAMPLING_INTERVAL_S: 0.005000", "SAMPLING_INTERVAL_S: 0.500000"),
            ("DURATION_S: 95.640", "DURATION_S: 9564.000"),
        ),
        [],
        "warn",
        "",
        r"time step dt = 0\.5 s(?![^\n]*cm/s2)[^\n]*read as seconds from the header's "
        r"SAMPLING_INTERVAL_S",
    ),
    (
        "geonet-points-text",
        GEONET,
        _sub("Number of points  5800", "Number of points  5900"),
        ["--channel", "1"],
        "error",
        "record",
        r"says 'Number of points 5900', but the numeric header .* says 5800",
    ),
    (
        "geonet-interval-text",
        GEONET,
        _sub("data at 0.020 sec intervals", "data at 0.010 sec intervals"),
        ["--channel", "1"],
        "error",
        "record",
        r"data at 0\.010 sec intervals, but the numeric header .* says 0\.02 s",
    ),
]
#: The #25 header cases that ``history`` runs too (a wrong scale overturns every wall).
HISTORY_HEADER = ("knet-scale-x10-max-acc-empty", "knet-max-acc-empty", "esm-dt-coarse")


def _synth_case(row: tuple[Any, ...], command: str) -> Case:
    cid, name, _content, extra, expect, fld, problem = row[:7]
    xfail = row[7] if len(row) > 7 else ""
    check = row[8] if len(row) > 8 and command == "record" else None
    argv = _argv(command, f"{{tmp}}/{name}", extra, check is not None)
    return Case(f"{command}-{cid}", argv, expect, fld, problem, check=check, xfail=xfail)


def _argv(command: str, record: str, extra: list[str], as_json: bool) -> list[str]:
    extra = [a for a in extra if a != "--json"]
    if command == "record":
        return ["record", record, *extra, "--n", "20", *(["--json"] if as_json else [])]
    return ["history", str(CONSTANTS), record, *extra]


def _real_case(row: tuple[Any, ...], command: str) -> Case:
    cid, _name, _mut, extra, expect, fld, problem = row[:7]
    xfail = row[7] if len(row) > 7 else ""
    if expect == "ok":
        # two of the real records are weak for their units: that warning is the right answer
        expect, problem = "ok", ""
    argv = _argv(command, "{tmp}/" + _name, extra, command == "record")
    return Case(f"{command}-{cid}", argv, expect, fld, problem, xfail=xfail)


SYNTH_ROWS = {row[0]: row for row in SYNTH}
REAL_ROWS = {row[0]: row for row in REAL_CASES}
#: ``history`` runs a subset: the defects of each format that a user meets most.
HISTORY_SYNTH = [r for r in SYNTH if not r[0].endswith(("-as-csv", "-text", "-dt-given-too"))]
HISTORY_REAL = [
    r
    for r in REAL_CASES
    if r[0].endswith(("-good", "-truncated", "-nan-sample")) or r[0] in HISTORY_HEADER
]
CASES = (
    [_synth_case(r, "record") for r in SYNTH]
    + [_synth_case(r, "history") for r in HISTORY_SYNTH]
    + [_real_case(r, "record") for r in REAL_CASES]
    + [_real_case(r, "history") for r in HISTORY_REAL]
)


def _write(case: Case, tmp: Path) -> None:
    key = case.id.split("-", 1)[1]
    if key in SYNTH_ROWS:
        _cid, name, content = SYNTH_ROWS[key][:3]
        path = tmp / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
        return
    _cid, name, mutate = REAL_ROWS[key][:3]
    source = FORMATS / name
    if not source.is_file():
        pytest.skip(f"shared strong-motion record not found at {source} (not part of a clone)")
    data = source.read_bytes()
    if mutate == "junk":
        data = data + JUNK
    elif mutate is not None:
        data = mutate(data.decode("latin-1")).encode("latin-1")
    (tmp / name).write_bytes(data)


@pytest.mark.parametrize("case", params(CASES))
def test_record_case(case: Case, tmp_path: Path) -> None:
    _write(case, tmp_path)
    argv = [a.replace("{tmp}", str(tmp_path)) for a in case.argv]
    run_case(case, argv)


def test_record_corpus_is_large() -> None:
    assert len(CASES) >= 100
