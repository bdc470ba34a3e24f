"""The rockmech command line: real runs, JSON outputs and one-line errors."""

from __future__ import annotations

import errno
import json
import math
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from solver_service.cli import app
from solver_service.core.exact import simulate
from solver_service.core.excitation import Pulse
from solver_service.core.model import G, RockingModel
from solver_service.core.records import GroundMotion

runner = CliRunner()
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_pulse_json_reproduces_zhang_makris_onset() -> None:
    # Omega = 5: first overturning at A = 3.0186 (theory §6.5); f_p = 5 p / 2 pi.
    f_p = 5 * 2.0 / (2 * math.pi)
    common = ["pulse", "--p-eq", "2", "--lam", "0.2", "--eta", "0.9", "--f-p", str(f_p), "--json"]
    below = runner.invoke(app, [*common, "--a-p-g", str(-0.2 * 3.015)])
    above = runner.invoke(app, [*common, "--a-p-g", str(-0.2 * 3.022)])
    assert below.exit_code == 0 and above.exit_code == 0, below.output + above.output
    doc_below, doc_above = json.loads(below.stdout), json.loads(above.stdout)
    assert doc_below["overturned"] is False and doc_above["overturned"] is True
    assert doc_above["criterion"] == "exact"
    assert set(doc_below) >= {
        "peak_ratio",
        "overturned",
        "t_overturn",
        "n_impacts",
        "error_estimate",
    }


def test_history_json_matches_the_python_api(tmp_path: Path) -> None:
    record = EXAMPLES / "records" / "elcentro_NS.dat"
    constants = EXAMPLES / "constants" / "rect_walls.json"
    res = runner.invoke(
        app, ["history", str(constants), str(record), "--scale", "0.5", "1", "2", "--json"]
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    rows = {(r["mechanism"], r["scale"]): r for r in doc["results"]}
    assert len(rows) == 9
    motion = GroundMotion.from_two_column(record)
    w1 = json.loads(constants.read_text())["mechanisms"][0]
    wall = RockingModel.symmetric(w1["positive"]["p_eq"], w1["positive"]["lam"], w1["eta"])
    direct = simulate(wall, motion.accel, scale=2.0)
    assert rows[("W1", 2.0)]["peak_ratio"] == direct.peak_ratio
    assert rows[("W1", 2.0)]["overturned"] == direct.overturned


def test_history_writes_json_and_plot(tmp_path: Path) -> None:
    res = runner.invoke(
        app,
        [
            "history",
            str(EXAMPLES / "constants" / "rect_walls.json"),
            str(EXAMPLES / "records" / "elcentro_NS.dat"),
            "--scale",
            "1",
            "--out",
            str(tmp_path),
        ],
    )
    assert res.exit_code == 0, res.output
    assert json.loads((tmp_path / "history.json").read_text())["results"]
    for name in ("history.png", "history_record.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            [
                "pulse",
                "--p-eq",
                "nan",
                "--lam",
                "0.2",
                "--eta",
                "0.9",
                "--a-p-g",
                "1",
                "--f-p",
                "1",
            ],
            "p_eq",
        ),
        (
            ["pulse", "--p-eq", "-2", "--lam", "0.2", "--eta", "0.9", "--a-p-g", "1", "--f-p", "1"],
            "p_eq",
        ),
        (
            ["pulse", "--p-eq", "2", "--lam", "0", "--eta", "0.9", "--a-p-g", "1", "--f-p", "1"],
            "lam",
        ),
        (
            ["pulse", "--p-eq", "2", "--lam", "0.2", "--eta", "1.5", "--a-p-g", "1", "--f-p", "1"],
            "eta",
        ),
        (
            [
                "pulse",
                "--p-eq",
                "2",
                "--lam",
                "0.2",
                "--eta",
                "0.5",
                "--one-sided",
                "--a-p-g",
                "1",
                "--f-p",
                "1",
            ],
            "eta",
        ),
        (
            ["pulse", "--p-eq", "2", "--lam", "0.2", "--one-sided", "--a-p-g", "1", "--f-p", "1"],
            "eta",
        ),
    ],
)
def test_bad_arguments_exit_2_with_one_line(args: list[str], message: str) -> None:
    res = runner.invoke(app, args)
    assert res.exit_code == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0]


def test_history_bad_inputs(tmp_path: Path) -> None:
    constants = EXAMPLES / "constants" / "rect_walls.json"
    bad = tmp_path / "bad.dat"
    bad.write_text("0 0.1\n0.02 nan\n0.04 0.2\n")
    cases = [
        ([str(tmp_path / "missing.json"), str(bad)], "not found"),
        ([str(constants), str(tmp_path / "missing.dat")], "not found"),
        ([str(constants), str(bad)], "not finite"),
        (
            [str(constants), str(EXAMPLES / "records" / "elcentro_NS.dat"), "--scale", "0"],
            "scales[0]",
        ),
    ]
    one_sided = tmp_path / "one_sided.json"
    one_sided.write_text(
        json.dumps({"mechanisms": [{"id": "F9", "rocking": "one_sided", "p_eq": 2.0, "lam": 0.1}]})
    )
    cases.append(
        (
            [str(one_sided), str(EXAMPLES / "records" / "elcentro_NS.dat")],
            "F9: a time history of a one-sided mechanism needs a coefficient of restitution",
        )
    )
    for args, message in cases:
        res = runner.invoke(app, ["history", *args])
        assert res.exit_code == 2, (args, res.output)
        assert message in res.stderr and len(res.stderr.strip().splitlines()) == 1


def test_console_script_runs_as_a_real_process() -> None:
    exe = Path(sys.executable).parent / "rockmech"
    proc = subprocess.run(
        [
            str(exe),
            "pulse",
            "--p-eq",
            "2",
            "--lam",
            "0.2",
            "--eta",
            "0.9",
            "--a-p-g",
            "-1",
            "--f-p",
            "0.5",
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(proc.stdout)
    direct = simulate(RockingModel.symmetric(2, 0.2, 0.9), Pulse(a_p=-1 * G, f_p=0.5))
    assert doc["peak_ratio"] == direct.peak_ratio and doc["overturned"] == direct.overturned


# --- Envelopes, boundaries and the library (issue: envelopes) ------------------------------


def test_envelope_writes_json_csv_and_plot(tmp_path: Path) -> None:
    res = runner.invoke(
        app,
        [
            "envelope",
            str(EXAMPLES / "constants" / "church.json"),
            "--out",
            str(tmp_path),
            "--f-min",
            "0.2",
            "--f-max",
            "8",
            "--n",
            "60",
        ],
    )
    assert res.exit_code == 0, res.output
    doc = json.loads((tmp_path / "envelope.json").read_text())
    assert len(doc["f_p"]) == 60 and {"f_p": "Hz", "a_p": "g"}.items() <= doc["units"].items()
    assert len(doc["mechanisms"]) >= 5
    bands = doc["critical"]
    assert bands and bands[0]["f_min"] == doc["f_p"][0] and bands[-1]["f_max"] == doc["f_p"][-1]
    for band in bands:
        assert band["mechanism"] in {m["id"] for m in doc["mechanisms"]}
    # Each band's mechanism has the lowest ground-level amplitude inside the band.
    for k in range(len(doc["f_p"])):
        values = {m["id"]: m["a_p_min_g"][k] for m in doc["mechanisms"] if m["a_p_min_g"][k]}
        assert doc["governing"][k] == min(values, key=values.__getitem__)
    csv = (tmp_path / "envelope.csv").read_text().splitlines()
    assert len(csv) == 61 and csv[0].startswith("f_p_Hz,")
    assert (tmp_path / "envelope.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_boundary_json_gives_every_interval() -> None:
    res = runner.invoke(app, ["boundary", "--eta", "0.9", "--omega", "5", "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert doc["omega"] == 5 and doc["eta"] == 0.9
    rounded = [
        [round(lo, 4), None if hi is None else round(hi, 4)]
        for lo, hi in doc["overturning_intervals"]
    ]
    assert rounded == [[3.0186, 6.3181], [7.1681, None]]


def test_boundary_one_sided_reports_the_governing_direction() -> None:
    res = runner.invoke(app, ["boundary", "--one-sided", "--omega", "2", "--json"])
    doc = json.loads(res.stdout)
    assert doc["governing_direction"] == "positive"
    assert doc["a_min"] == pytest.approx(1.8007, abs=1e-4)
    assert set(doc["directions"]) == {"positive", "negative"}


def test_library_build_writes_a_loadable_library(tmp_path: Path) -> None:
    from solver_service.core.envelope import OverturningLibrary, boundary_curve

    out = tmp_path / "lib.npz"
    res = runner.invoke(
        app, ["library", "build", "--out", str(out), "--n-omega", "6", "--eta-step", "0.5"]
    )
    assert res.exit_code == 0, res.output
    lib = OverturningLibrary.load(out)
    assert list(lib.eta) == [0.0, 0.5, 1.0] and lib.omega.size == 6
    np.testing.assert_allclose(lib.a_min_two_sided[1], boundary_curve(lib.omega, 0.5).a_min)


@pytest.mark.slow
def test_library_build_without_out_writes_the_user_cache_which_envelopes_read_first(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import hashlib

    from solver_service.core.envelope import LIBRARY_PATH, OverturningLibrary, user_library_path

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    shipped = hashlib.sha256(LIBRARY_PATH.read_bytes()).hexdigest()
    user = user_library_path()
    assert user is not None and user.parent == tmp_path / "cache" / "rockmech"
    assert OverturningLibrary.load().path == LIBRARY_PATH
    church = EXAMPLES / "constants" / "church.json"
    before = runner.invoke(
        app, ["envelope", str(church), "--out", str(tmp_path / "a"), "--n", "9", "--fast"]
    )
    assert before.exit_code == 0 and before.stderr == "", before.output
    res = runner.invoke(app, ["library", "build", "--n-omega", "5", "--eta-step", "0.5"])
    assert res.exit_code == 0, res.output
    assert res.stdout.startswith(f"wrote {user}: 3 two-sided curves")
    # The installed package is never written.
    assert hashlib.sha256(LIBRARY_PATH.read_bytes()).hexdigest() == shipped
    lib = OverturningLibrary.load()
    assert lib.path == user and lib.omega.size == 5 and list(lib.eta) == [0.0, 0.5, 1.0]
    after = runner.invoke(
        app, ["envelope", str(church), "--out", str(tmp_path / "b"), "--n", "9", "--fast"]
    )
    assert after.exit_code == 0, after.output
    assert (
        after.stderr
        == f"note: envelopes interpolated in the library {user} (not the shipped library)\n"
    )
    doc = json.loads((tmp_path / "b" / "envelope.json").read_text())
    assert doc["method"]["library_file"] == f"{user} (not the shipped library)"
    assert doc["method"]["generated"] == lib.metadata["generated"]
    user.unlink()
    doc = json.loads((tmp_path / "a" / "envelope.json").read_text())
    assert doc["method"]["library_file"] == "shipped with rockmech"
    assert OverturningLibrary.load().path == LIBRARY_PATH


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["boundary", "--eta", "1.5", "--omega", "2"], "eta"),
        (["boundary", "--omega", "2"], "eta"),
        (["boundary", "--eta", "0.9", "--omega", "-1"], "omega"),
        (["envelope", "CONST", "--out", "OUT", "--f-min", "5", "--f-max", "1"], "f_min"),
        (["envelope", "EMPTY", "--out", "OUT"], "mechanisms"),
        (["envelope", "BAD_HE", "--out", "OUT"], "h_e"),
    ],
)
def test_envelope_and_boundary_bad_input(tmp_path: Path, args: list[str], message: str) -> None:
    empty = tmp_path / "empty.json"
    empty.write_text('{"mechanisms": []}')
    bad_he = tmp_path / "bad_he.json"
    bad_he.write_text(
        json.dumps(
            {
                "mechanisms": [
                    {
                        "id": "T1",
                        "p_eq": 3.0,
                        "lam": 0.2,
                        "eta": 0.9,
                        "amplification": {"f_n": 5.0, "h_e": 0.0, "h": 10.0},
                    }
                ]
            }
        )
    )
    table = {
        "CONST": str(EXAMPLES / "constants" / "church.json"),
        "EMPTY": str(empty),
        "BAD_HE": str(bad_he),
        "OUT": str(tmp_path / "out"),
    }
    res = runner.invoke(app, [table.get(a, a) for a in args])
    assert res.exit_code == 2, res.output
    assert message in res.stderr and len(res.stderr.strip().splitlines()) == 1


# --- Record formats through rockmech history ------------------------------------------------


def test_history_reads_csv_and_one_column_records(tmp_path: Path) -> None:
    constants = str(EXAMPLES / "constants" / "rect_walls.json")
    data = np.loadtxt(EXAMPLES / "records" / "elcentro_NS.dat")
    csv = tmp_path / "ec.csv"
    csv.write_text("time_s,acc_cm_s2\n" + "\n".join(f"{t},{a * 980.665}" for t, a in data))
    one = tmp_path / "ec.txt"
    one.write_text("\n".join(str(a) for a in data[:, 1]))
    ref = json.loads(
        runner.invoke(
            app, ["history", constants, str(EXAMPLES / "records" / "elcentro_NS.dat"), "--json"]
        ).stdout
    )
    for args in (
        [str(csv), "--units", "cm/s2"],
        [str(one), "--units", "g", "--dt", "0.02", "--format", "one_column"],
    ):
        res = runner.invoke(app, ["history", constants, *args, "--json"])
        assert res.exit_code == 0, res.output
        got = json.loads(res.stdout)
        for a, b in zip(got["results"], ref["results"]):
            assert a["peak_ratio"] == pytest.approx(b["peak_ratio"], rel=1e-9, abs=1e-12)
            assert a["overturned"] == b["overturned"]
    missing = runner.invoke(app, ["history", constants, str(csv)])
    assert missing.exit_code == 2 and "units" in missing.stderr


def test_history_reads_peer_at2(shared_records: Path) -> None:
    res = runner.invoke(
        app,
        [
            "history",
            str(EXAMPLES / "constants" / "rect_walls.json"),
            str(shared_records / "RSN126_GAZLI_GAZ000.AT2"),
            "--json",
        ],
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert doc["record"]["npts"] == 2048 and doc["record"]["pga_g"] == pytest.approx(
        0.702, abs=1e-3
    )
    assert doc["record"]["station"] == "Karakyr"


def test_history_with_eq28_scales_only_the_amplified_mechanisms(tmp_path: Path) -> None:
    from solver_service.codes.scale_factors import sf_eq28
    from solver_service.core.spectra import response_spectrum

    constants = tmp_path / "c.json"
    constants.write_text(
        json.dumps(
            {
                "mechanisms": [
                    {"id": "GROUND", "p_eq": 2.2, "lam": 0.17, "eta": 0.95},
                    {
                        "id": "TOWER",
                        "p_eq": 2.2,
                        "lam": 0.17,
                        "eta": 0.95,
                        "amplification": {"f_n": 3.0, "h_e": 10.0, "h": 12.0},
                    },
                ]
            }
        )
    )
    record = EXAMPLES / "records" / "elcentro_NS.dat"
    res = runner.invoke(
        app, ["history", str(constants), str(record), "--scale", "0.4", "--sf", "eq28", "--json"]
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    motion = GroundMotion.from_two_column(record)
    sa_g = response_spectrum(motion.accel.acc, motion.dt, [1 / 3.0]).psa[0] / G
    factor = sf_eq28(sa_g, motion.pga_g, 12.0, 10.0)["value"]
    assert doc["scale_factors"]["TOWER"]["value"] == pytest.approx(factor, rel=1e-12)
    assert "GROUND" not in doc["scale_factors"]
    rows = {r["mechanism"]: r for r in doc["results"]}
    assert rows["GROUND"]["effective_scale"] == 0.4
    assert rows["TOWER"]["effective_scale"] == pytest.approx(0.4 * factor, rel=1e-12)
    direct = simulate(RockingModel.symmetric(2.2, 0.17, 0.95), motion.accel, scale=0.4 * factor)
    assert rows["TOWER"]["peak_ratio"] == direct.peak_ratio
    bad = runner.invoke(app, ["history", str(constants), str(record), "--sf", "ec99"])
    assert bad.exit_code == 2 and "sf" in bad.stderr


def _two_level_constants(tmp_path: Path) -> Path:
    constants = tmp_path / "c.json"
    constants.write_text(
        json.dumps(
            {
                "mechanisms": [
                    {"id": "GROUND", "p_eq": 2.2, "lam": 0.17, "eta": 0.95},
                    {
                        "id": "TOWER",
                        "p_eq": 2.2,
                        "lam": 0.17,
                        "eta": 0.95,
                        "amplification": {"f_n": 3.0, "h_e": 10.0, "h": 12.0},
                    },
                ]
            }
        )
    )
    return constants


@pytest.mark.parametrize(
    ("method", "extra", "expected"),
    [
        # EN 1998-1 §4.3.5.2, rigid element (T_a = 0): 3(1 + z/H)/2 - 0.5, times S.
        ("ec8", ["--soil-factor", "1.15"], 1.15 * (1.5 * (1 + 12.0 / 20.0) - 0.5)),
        # NZS 1170.5 C_Hi: h_i = 12 m is not < 12 m, nor < 0.2 h_n: the cap 3.0.
        ("nzs", [], 3.0),
    ],
)
def test_history_with_code_scale_factors(
    tmp_path: Path, method: str, extra: list[str], expected: float
) -> None:
    constants = _two_level_constants(tmp_path)
    record = EXAMPLES / "records" / "elcentro_NS.dat"
    args = ["history", str(constants), str(record), "--scale", "0.3", "--sf", method]
    res = runner.invoke(app, [*args, "--building-height", "20", *extra, "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert doc["scale_factor_method"] == method
    info = doc["scale_factors"]["TOWER"]
    assert info["value"] == pytest.approx(expected, rel=1e-14)
    assert info["formula"] and info["inputs"]
    rows = {r["mechanism"]: r for r in doc["results"]}
    assert rows["TOWER"]["effective_scale"] == pytest.approx(0.3 * expected, rel=1e-14)
    assert rows["GROUND"]["effective_scale"] == 0.3
    motion = GroundMotion.from_two_column(record)
    direct = simulate(RockingModel.symmetric(2.2, 0.17, 0.95), motion.accel, scale=0.3 * expected)
    assert rows["TOWER"]["peak_ratio"] == direct.peak_ratio
    # Without the building height, and with the mechanism above the building: clear errors.
    missing = runner.invoke(app, args)
    assert missing.exit_code == 2 and "building_height" in missing.stderr
    low = runner.invoke(app, [*args, "--building-height", "8"])
    assert low.exit_code == 2 and "'TOWER' sits at h = 12 m, above the building" in low.stderr


def test_history_displacement_at_a_height(tmp_path: Path) -> None:
    record = EXAMPLES / "records" / "elcentro_NS.dat"
    constants = EXAMPLES / "constants" / "rect_walls.json"
    res = runner.invoke(
        app,
        ["history", str(constants), str(record), "--scale", "0.6", "--at-height", "2.5", "--json"],
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert doc["displacement"]["height_m"] == 2.5
    from shared_schema.io import read_constants
    from solver_service.workflows.adapter import models_from_file

    motion = GroundMotion.from_two_column(record)
    for model, row in zip(models_from_file(read_constants(constants)), doc["results"]):
        dense = simulate(model, motion.accel, scale=0.6, dense=True)
        assert dense.ratio is not None
        # Independent: the largest |phi| over the traced response, in radians, times z.
        phi = np.where(dense.ratio >= 0, model.positive.phi_ov, model.neg.phi_ov) * dense.ratio
        peak_phi = float(np.max(np.abs(phi)))
        if not row["overturned"]:
            assert row["peak_displacement_m"] == pytest.approx(2.5 * peak_phi, rel=1e-9)
        assert "peak_displacement_is_bound" not in row
    bad = runner.invoke(app, ["history", str(constants), str(record), "--at-height", "0"])
    assert bad.exit_code == 2 and "at_height" in bad.stderr


def test_record_command_gives_pulses_and_the_spectrum(tmp_path: Path) -> None:
    from solver_service.core.pulses import extract_pulses
    from solver_service.core.spectra import response_spectrum

    record = EXAMPLES / "records" / "elcentro_NS.dat"
    res = runner.invoke(
        app, ["record", str(record), "--n", "20", "--pulses", "3", "--out", str(tmp_path), "--json"]
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    motion = GroundMotion.from_two_column(record)
    assert doc["record"]["n_samples"] == 2688
    assert doc["record"]["pga_g"] == pytest.approx(motion.pga_g)
    expected = extract_pulses(motion.accel, n=3)
    assert [p["f_p_hz"] for p in doc["pulses"]] == [p.f_p for p in expected]
    periods = np.geomspace(0.02, 10.0, 20)
    spec = response_spectrum(motion.accel.acc, motion.dt, periods)
    assert doc["spectrum"]["psa_g"] == pytest.approx(list(spec.psa_g), rel=1e-12)
    assert (tmp_path / "record.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert json.loads((tmp_path / "record.json").read_text()) == doc
    bad = runner.invoke(app, ["record", str(record), "--t-min", "0"])
    assert bad.exit_code == 2 and "t_min" in bad.stderr


def test_envelope_with_a_records_pulse_agrees_with_the_exact_solver(tmp_path: Path) -> None:
    record = EXAMPLES / "records" / "elcentro_NS.dat"
    constants = EXAMPLES / "constants" / "rect_walls.json"
    res = runner.invoke(
        app,
        [
            "envelope",
            str(constants),
            "--out",
            str(tmp_path),
            "--exact",
            "--n",
            "12",
            "--record",
            str(record),
            "--record-scale",
            "0.3",
            "1",
            "3",
            "--json",
        ],
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    rp = doc["record_pulse"]
    assert [p["scale"] for p in rp["points"]] == [0.3, 1.0, 3.0]
    from shared_schema.io import read_constants
    from solver_service.workflows.adapter import models_from_file

    # Each verdict against a direct exact run of that pulse (both directions; governing).
    for point in rp["points"]:
        for model in models_from_file(read_constants(constants)):
            a_min = rp["a_p_min_g_at_f_p"][model.name]
            if abs(point["a_p_g"] / a_min - 1) < 1e-3:
                continue  # too close to the boundary to be a fair check
            runs = [
                simulate(model, Pulse(sign * point["a_p_g"] * G, point["f_p_hz"]))
                for sign in (1.0, -1.0)
            ]
            collapsed = any(r.collapsed for r in runs)
            assert collapsed == (model.name in point["overturns"]), (point, model.name)
    assert any(p["overturns"] for p in rp["points"])
    assert not rp["points"][0]["overturns"]


def test_history_warns_where_the_linear_model_is_off(tmp_path: Path) -> None:
    from solver_service.core.nonlinear import linearisation_warnings

    constants = tmp_path / "c.json"
    constants.write_text(
        json.dumps(
            {
                "mechanisms": [
                    {"id": "SLENDER", "p_eq": 2.0, "lam": 0.1, "eta": 0.95},
                    {"id": "SQUAT", "p_eq": 2.0, "lam": 0.6, "eta": 0.5},
                ]
            }
        )
    )
    record = str(EXAMPLES / "records" / "elcentro_NS.dat")
    res = runner.invoke(app, ["history", str(constants), record, "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    expected = linearisation_warnings(RockingModel.symmetric(2.0, 0.6, 0.5))
    assert expected and doc["warnings"] == {"SQUAT": expected}
    table = runner.invoke(app, ["history", str(constants), record])
    assert f"warning: SQUAT: {expected[0]}" in table.stderr
    assert "SLENDER:" not in table.stderr


def test_history_skips_a_mechanism_without_eta_with_a_note_and_runs_the_others() -> None:
    church = EXAMPLES / "constants" / "church.json"
    record = EXAMPLES / "records" / "elcentro_NS.dat"
    res = runner.invoke(app, ["history", str(church), str(record), "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    no_eta = [m["id"] for m in json.loads(church.read_text())["mechanisms"] if "eta" not in m]
    assert no_eta, "the example church keeps an envelope-only mechanism"
    assert [s["mechanism"] for s in doc["skipped"]] == no_eta
    assert "restitution" in doc["skipped"][0]["reason"]
    ran = {r["mechanism"] for r in doc["results"]}
    assert ran and not ran & set(no_eta)
    # The rows of the others equal a run of the file without the skipped mechanism.
    full = json.loads(church.read_text())
    full["mechanisms"] = [m for m in full["mechanisms"] if "eta" in m]
    assert len(full["mechanisms"]) == len(ran)


def test_history_with_no_runnable_mechanism_names_them_all(tmp_path: Path) -> None:
    path = tmp_path / "c.json"
    path.write_text(
        json.dumps({"mechanisms": [{"id": "F", "rocking": "one_sided", "p_eq": 2.0, "lam": 0.2}]})
    )
    res = runner.invoke(app, ["history", str(path), str(EXAMPLES / "records" / "elcentro_NS.dat")])
    assert res.exit_code == 2
    assert "mechanisms" in res.stderr and "F:" in res.stderr and "restitution" in res.stderr


def test_options_that_cannot_apply_warn_and_impossible_values_fail() -> None:
    constants = EXAMPLES / "constants" / "rect_walls.json"  # no amplification data
    record = EXAMPLES / "records" / "elcentro_NS.dat"
    res = runner.invoke(app, ["history", str(constants), str(record), "--sf", "ec8", "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert any("sf ec8 has no effect" in n for n in doc["option_warnings"])
    text = runner.invoke(app, ["history", str(constants), str(record), "--sf", "ec8"])
    assert "warning: sf ec8 has no effect" in text.stderr
    plain = runner.invoke(app, ["history", str(constants), str(record), "--json"])
    assert [r["peak_ratio"] for r in doc["results"]] == [
        r["peak_ratio"] for r in json.loads(plain.stdout)["results"]
    ]
    res = runner.invoke(app, ["history", str(constants), str(record), "--building-height", "12"])
    assert "building_height has no effect with sf none" in res.stderr
    res = runner.invoke(
        app, ["history", str(constants), str(record), "--sf", "ec8", "--building-height", "-5"]
    )
    assert res.exit_code == 2 and "building_height: must be finite and > 0" in res.stderr


# --- Conventions: help, choices, streams, tables ---------------------------------------------


def _commands() -> list[tuple[list[str], Any]]:
    import typer.main

    out: list[tuple[list[str], Any]] = []

    def walk(cmd: Any, path: list[str]) -> None:
        if hasattr(cmd, "commands"):  # a group
            for name, sub in cmd.commands.items():
                walk(sub, [*path, name])
        else:
            out.append((path, cmd))

    walk(typer.main.get_command(app), [])
    return out


def test_every_help_shows_the_units_and_bracketed_text_of_its_options() -> None:
    import re

    commands = _commands()
    assert len(commands) >= 11
    seen = 0
    for path, cmd in commands:
        res = runner.invoke(app, [*path, "--help"])
        assert res.exit_code == 0, (path, res.output)
        shown = " ".join(res.stdout.split())
        texts = [p.help or "" for p in cmd.params] + [cmd.help or ""]
        for text in texts:
            for token in re.findall(r"\[[^\]\[]+\]", text):
                assert " ".join(token.split()) in shown, (path, token)
                seen += 1
    assert seen >= 40  # [rad/s], [g], [s], [m], [Hz], [-] ... across the commands


def test_choice_options_list_the_vocabularies_of_shared_schema_rules() -> None:
    from shared_schema.rules import CRITERIA, PULSE_SHAPES, RECORD_FORMATS, RECORD_UNITS, SF_METHODS

    expected = {
        ("pulse", "--shape"): PULSE_SHAPES,
        ("pulse", "--criterion"): CRITERIA,
        ("history", "--sf"): SF_METHODS,
        ("history", "--units"): tuple(RECORD_UNITS),
        ("history", "--format"): RECORD_FORMATS,
        ("ida", "--measure"): ("scale", "pga"),
        ("boundary", "--shape"): PULSE_SHAPES,
    }
    for (command, option), values in expected.items():
        res = runner.invoke(app, [command, "--help"])
        assert f"{option} [{'|'.join(values)}]" in res.stdout, (command, option)


def test_version_option() -> None:
    from rockmech import __version__

    res = runner.invoke(app, ["--version"])
    first, second = res.stdout.splitlines()
    assert res.exit_code == 0 and first == f"rockmech {__version__}"
    # read without loading numba (tests/solver_core/test_kernel_cache.py)
    assert second.startswith("compiled kernels: numba ")
    assert "installed, loaded when a solver path first runs" in second


def test_history_table_is_aligned_within_100_columns_at_4_significant_figures(
    tmp_path: Path,
) -> None:
    long_id = "NORTH_FACADE_GABLE_OVERTURNING_ABOUT_THE_BASE_WITH_RETURN_WALLS"
    doc = json.loads((EXAMPLES / "constants" / "rect_walls.json").read_text())
    doc["mechanisms"][0]["id"] = long_id
    path = tmp_path / "walls.json"
    path.write_text(json.dumps(doc))
    record = str(EXAMPLES / "records" / "elcentro_NS.dat")
    args = ["history", str(path), record, "--scale", "0.5", "1", "--at-height", "2.5"]
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    as_json = json.loads(runner.invoke(app, [*args, "--json"]).stdout)
    lines = res.stdout.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("mechanism"))
    table = lines[start : start + 1 + len(as_json["results"])]
    assert all(len(line) <= 100 for line in res.stdout.splitlines()), max(map(len, lines))
    # Right-aligned columns end at the same place on every row.
    assert len({len(line) for line in table}) == 1, table
    for line, row in zip(table[1:], as_json["results"]):
        cells = line.split()
        assert cells[-1] == f"{row['peak_displacement_m']:.4g}"
        assert f"{row['peak_ratio']:.4g}" in cells
    first = table[1].split()[0]
    assert first.endswith("...") and long_id.startswith(first[:-3]), first
    assert "warning" not in res.stdout


def test_serve_prints_the_address_it_listens_on(monkeypatch: pytest.MonkeyPatch) -> None:
    from solver_service.api import server

    calls: list[Any] = []
    monkeypatch.setattr(server, "run", calls.append)
    res = runner.invoke(app, ["serve", "--host", "127.0.0.1", "--port", "8765"])
    assert res.exit_code == 0, res.output
    assert res.stdout.splitlines()[0].endswith("serving on http://127.0.0.1:8765")
    assert calls and calls[0].port == 8765


# --- #19: a run's outputs are committed together; write errors are one line ------------------

RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
WALLS = EXAMPLES / "constants" / "rect_walls.json"


def _writing_commands(target: Path) -> dict[str, list[str]]:
    """Every command that writes, each aimed at ``target``."""
    c, r = str(WALLS), str(RECORD)
    return {
        "history": ["history", c, r, "--out", str(target)],
        "envelope": ["envelope", c, "--n", "5", "--out", str(target)],
        "record": ["record", r, "--n", "5", "--out", str(target)],
        "ida": ["ida", c, r, "--scales", "1", "--out", str(target)],
        "demo": ["demo", "--out", str(target)],
        "report": ["report", c, "--n", "5", "-o", str(target / "r.html")],
        "assess": ["assess", c, str(EXAMPLES / "sites" / "ntc_site.json"), "-o", str(target)],
        "constants-table": ["constants-table", str(target) + ".csv", "-o", str(target)],
    }


@pytest.mark.parametrize("command", ["history", "envelope", "record", "ida", "demo", "report"])
def test_an_unwritable_output_is_one_line_and_exit_2_in_every_command(
    tmp_path: Path, command: str
) -> None:
    # Tests run as root, where chmod does not stop a write: a path under a file cannot be
    # written by anyone (ENOTDIR), whatever the permissions.
    blocker = tmp_path / "file"
    blocker.write_text("x")
    res = runner.invoke(app, _writing_commands(blocker / "run")[command])
    assert res.exception is None or isinstance(res.exception, SystemExit), repr(res.exception)
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert lines[-1].startswith("error: out: ") and str(blocker) in lines[-1], res.stderr
    assert "Traceback" not in res.stderr


@pytest.mark.parametrize("command", ["history", "envelope", "record", "ida", "demo"])
def test_out_naming_a_file_is_refused_before_any_work(tmp_path: Path, command: str) -> None:
    target = tmp_path / "taken.json"
    target.write_text("keep me")
    res = runner.invoke(app, _writing_commands(target)[command])
    assert res.exit_code == 2, res.output
    assert "error: out:" in res.stderr and "is a file" in res.stderr
    assert target.read_text() == "keep me"


@pytest.mark.parametrize("command", ["report", "assess", "constants-table"])
def test_a_file_option_naming_a_folder_is_refused(tmp_path: Path, command: str) -> None:
    folder = tmp_path / "folder"
    (folder / "r.html").mkdir(parents=True)
    argv = _writing_commands(folder)[command]
    res = runner.invoke(app, argv)
    assert res.exit_code == 2, res.output
    last = res.stderr.strip().splitlines()[-1]
    assert re.match(r"error: (out|output): .* is a folder", last), last


def _file_commands(target: Path) -> dict[str, list[str]]:
    """Every command that writes one file, aimed at ``target``, and its option's field name."""
    scene, spec = EXAMPLES / "scenes" / "rect_wall.3dm", EXAMPLES / "specs" / "rect_wall.spec.json"
    site, table = EXAMPLES / "sites" / "ntc_site.json", EXAMPLES / "constants" / "walls.csv"
    return {
        "constants": ["constants", str(scene), str(spec), "-o", str(target)],
        "constants-table": ["constants-table", str(table), "-o", str(target)],
        "report": ["report", str(WALLS), "--n", "5", "-o", str(target)],
        "assess": ["assess", str(WALLS), str(site), "-o", str(target)],
    }


#: The option name each single-file command gives in its errors.
FILE_FIELDS = {"constants": "output", "constants-table": "output", "report": "out", "assess": "out"}


@pytest.mark.parametrize("command", ["constants", "constants-table"])
def test_a_file_output_creates_its_missing_parent_folders(tmp_path: Path, command: str) -> None:
    target = tmp_path / "out" / "deeper" / "c.json"
    res = runner.invoke(app, _file_commands(target)[command])
    assert res.exit_code == 0, res.output
    doc = json.loads(target.read_text(encoding="utf-8"))
    assert [m["id"] for m in doc["mechanisms"]] == (
        ["W1"] if command == "constants" else ["W1", "W2", "P1", "F1"]
    )


@pytest.mark.parametrize("command", sorted(FILE_FIELDS))
def test_a_file_output_whose_folder_cannot_be_made_is_one_line_before_any_work(
    tmp_path: Path, command: str
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    res = runner.invoke(app, _file_commands(blocker / "sub" / "c.json")[command])
    assert res.exit_code == 2, res.output
    assert res.stderr.strip() == (
        f"error: {FILE_FIELDS[command]}: cannot create folder {blocker / 'sub'}: "
        f"{blocker} is a file"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_full_disk_and_permission_errors_are_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from shared_schema import io
    from solver_service.workflows import outputs

    def full(path: object, data: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(outputs, "write_atomic", full)
    res = runner.invoke(app, _writing_commands(tmp_path / "ida")["ida"])
    assert res.exit_code == 2 and "the disk is full" in res.stderr.splitlines()[-1], res.output
    # No half run and no stage left: the folder holds only rockmech's lock.
    assert [str(p.relative_to(tmp_path)) for p in sorted(tmp_path.rglob("*"))] == [
        "ida",
        "ida/.rockmech",
        "ida/.rockmech/lock",
    ]

    def denied(model: object, path: object) -> None:
        raise PermissionError(errno.EACCES, "Permission denied", str(path))

    monkeypatch.setattr(io, "write_constants", denied)
    table = tmp_path / "t.csv"
    table.write_text("id,name,p_eq,lam,eta\nW1,wall,2.0,0.2,0.9\n")
    res = runner.invoke(app, ["constants-table", str(table), "-o", str(tmp_path / "c.json")])
    assert res.exit_code == 2, res.output
    assert res.stderr.strip() == f"error: out: {tmp_path / 'c.json'}: permission denied"


def test_a_run_stopped_mid_write_leaves_the_old_run_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from solver_service.workflows import outputs

    out = tmp_path / "run"
    argv = ["history", str(WALLS), str(RECORD), "--scale", "0.5", "--out", str(out)]
    assert runner.invoke(app, argv).exit_code == 0
    (out / "note.txt").write_text("the user's own")
    old = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}

    def killed(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt  # the JSON and one plot are written, the record plot is not

    monkeypatch.setattr(outputs, "plot_record", killed)
    res = runner.invoke(app, [*argv[:-3], "1", "2", "--out", str(out)])
    assert isinstance(res.exception, KeyboardInterrupt) or res.exit_code != 0
    monkeypatch.undo()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]
    assert sorted(p.name for p in (out / ".rockmech").iterdir()) == ["lock", "manifest.json"]
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == old

    # A run whose process died mid-write left its stage: the next run removes it and
    # replaces its own outputs; the user's file stays.
    stale = out / ".rockmech" / "stage-1-dead"
    stale.mkdir()
    (stale / ".lock").write_bytes(b"")
    (stale / "history.json").write_text("half")
    assert runner.invoke(app, argv).exit_code == 0
    assert sorted(p.name for p in out.iterdir()) == [
        ".rockmech",
        "history.json",
        "history.png",
        "history_record.png",
        "note.txt",
    ]
    assert (out / "note.txt").read_text() == "the user's own"
    assert sorted(p.name for p in (out / ".rockmech").iterdir()) == ["lock", "manifest.json"]


def test_size_limits_name_the_option_and_no_limits_lifts_them(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from solver_service.workflows import limits

    monkeypatch.setitem(limits.DEFAULT_LIMITS, "max_scales", 2)
    argv = ["history", str(WALLS), str(RECORD), "--scale", "0.5", "1", "2", "--json"]
    res = runner.invoke(app, argv)
    assert res.exit_code == 2
    assert res.stderr.strip() == (
        "error: scales: 3 scale factors exceed the limit of 2; give --no-limits to lift it"
    )
    res = runner.invoke(app, [*argv, "--no-limits"])
    assert res.exit_code == 0, res.output
    assert len(json.loads(res.stdout)["results"]) == 9


def test_record_pulses_below_one_names_pulses() -> None:
    res = runner.invoke(app, ["record", str(RECORD), "--pulses", "0"])
    assert res.exit_code == 2 and res.stderr.strip() == "error: pulses: must be >= 1, got 0"


def test_progress_goes_to_stderr_on_a_terminal_and_nowhere_otherwise(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    argv = ["envelope", str(WALLS), "--n", "5", "--out", str(tmp_path / "e"), "--json"]
    plain = runner.invoke(app, argv)
    assert plain.exit_code == 0 and plain.stderr == "", plain.stderr
    from rich.console import Console

    monkeypatch.setattr(Console, "is_terminal", property(lambda self: True))
    shown = runner.invoke(app, argv)
    assert shown.exit_code == 0, shown.output
    assert json.loads(shown.stdout) == json.loads(plain.stdout)  # stdout: the JSON only
    assert "envelopes: 3 mechanisms x 5 frequencies" in shown.stderr


def test_examples_copies_the_bundled_examples_and_never_touches_the_users_files(
    tmp_path: Path,
) -> None:
    folder = tmp_path / "work"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    dest = folder / "examples"
    res = runner.invoke(app, ["examples", str(dest)])
    assert res.exit_code == 0, res.output
    shipped = sorted(
        p.relative_to(EXAMPLES).as_posix()
        for p in EXAMPLES.rglob("*")
        if p.is_file() and p.suffix not in (".py", ".pyc") and "__pycache__" not in p.parts
    )
    copied = sorted(
        p.relative_to(dest).as_posix()
        for p in dest.rglob("*")
        if p.is_file() and ".rockmech" not in p.relative_to(dest).parts
    )
    assert copied == shipped and len(copied) >= 25
    assert res.stdout == f"wrote {len(shipped)} example files to {dest}\n"
    for rel in shipped:
        assert (dest / rel).read_bytes() == (EXAMPLES / rel).read_bytes(), rel
    # The README's commands run on the copy.
    out = runner.invoke(
        app, ["envelope", str(dest / "constants" / "church.json"), "--out", str(tmp_path / "o")]
    )
    assert out.exit_code == 0, out.output
    # Again: only its own files are replaced; a file of the user's beside them survives.
    (dest / "my_site.json").write_text("{}")
    assert runner.invoke(app, ["examples", str(dest)]).exit_code == 0
    assert (dest / "my_site.json").read_text() == "{}"
    assert (folder / "notes.txt").read_text() == "mine"
    # An example the user changed is kept, and the copy stops with one line naming it.
    church = dest / "constants" / "church.json"
    church.write_text(church.read_text() + " ")
    changed = church.read_bytes()
    res = runner.invoke(app, ["examples", str(dest)])
    assert res.exit_code == 2
    assert res.stderr.startswith(f"error: out: {church} was changed after rockmech wrote it")
    assert church.read_bytes() == changed
