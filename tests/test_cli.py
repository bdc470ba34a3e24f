"""The rockmech command line: real runs, JSON outputs and one-line errors."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

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
    # Omega = 5: first overturning at A = 3.0186 (THEORY §6.5); f_p = 5 p / 2 pi.
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
    assert (tmp_path / "history.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


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
    cases.append(([str(one_sided), str(EXAMPLES / "records" / "elcentro_NS.dat")], "F9.eta"))
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
