"""The command line's time limit and its cleaning of temporary files left by killed runs."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shared_schema.atomic import temp_name
from shared_schema.constants import parse_constants
from solver_service.cli import app
from solver_service.workflows import limits

pytestmark = pytest.mark.skipif(
    not hasattr(signal, "setitimer"), reason="the time limit and pid probes are POSIX-only"
)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
WALLS = EXAMPLES / "constants" / "rect_walls.json"
runner = CliRunner()


def _contents(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def test_a_run_past_its_time_limit_stops_with_one_line_and_keeps_the_old_outputs(
    tmp_path: Path,
) -> None:
    out = tmp_path / "run"
    assert (
        runner.invoke(app, ["envelope", str(WALLS), "--n", "20", "--out", str(out)]).exit_code == 0
    )
    old = _contents(out)
    argv = ["envelope", str(WALLS), "--exact", "--n", "2000", "--out", str(out)]
    # A limit the up-front estimate lets through (it assumes twice the measured speed),
    # which the run itself then passes.
    steps = limits.envelope_steps(parse_constants(WALLS.read_text()), 0.1, 10.0, 2000)
    seconds = round(1.25 * limits.shortest_time(envelope_steps=steps), 2)
    res = runner.invoke(app, [*argv, "--time-limit", str(seconds)])
    assert res.exit_code == 2, res.output
    assert res.stderr == (
        f"error: time-limit: the run did not finish within its time limit of {seconds:g} s; "
        "give --time-limit with more seconds, or --no-limits to lift it\n"
    )
    assert _contents(out) == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]  # no temporary folder left


def test_no_limits_lifts_the_time_limit(tmp_path: Path) -> None:
    argv = ["envelope", str(WALLS), "--exact", "--n", "30", "--out", str(tmp_path / "run")]
    res = runner.invoke(app, [*argv, "--time-limit", "0.001", "--no-limits"])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == [
        ".rockmech",
        "envelope.csv",
        "envelope.json",
        "envelope.png",
    ]


def test_the_time_limit_sets_the_up_front_work_budget(tmp_path: Path) -> None:
    stiff = tmp_path / "stiff.json"
    stiff.write_text(
        json.dumps({"mechanisms": [{"id": "W", "eta": 0.9, "positive": {"p_eq": 500, "lam": 0.2}}]})
    )
    out = tmp_path / "run"
    argv = ["envelope", str(stiff), "--exact", "--n", "400", "--out", str(out)]
    # About 1.3e8 steps: 12 s at twice the measured rate on two cores.
    res = runner.invoke(app, [*argv, "--time-limit", "1"])
    assert res.exit_code == 2
    assert res.stderr.startswith("error: method: the run would take 1.")
    assert "closed-form steps of exact envelopes" in res.stderr
    assert "more than its time limit of 1 s" in res.stderr
    assert "give --time-limit with more seconds, or --no-limits" in res.stderr
    assert not out.exists()


def test_stale_temps_of_killed_runs_are_removed_with_a_note(tmp_path: Path) -> None:
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        capture_output=True,
        text=True,
        check=True,
    )
    stale = tmp_path / temp_name("constants.json", int(dead.stdout), "1a2b")
    live = tmp_path / temp_name("constants.json", os.getpid(), "3c4d")
    stale.write_text("half")
    live.write_text("being written")
    out = tmp_path / "run"
    res = runner.invoke(app, ["envelope", str(WALLS), "--n", "20", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert f"note: removed {stale}, a temporary file left by a run that was killed\n" in res.stderr
    assert not stale.exists() and live.read_text() == "being written"
    res = runner.invoke(app, ["envelope", str(WALLS), "--n", "20", "--out", str(out)])
    assert "note: removed" not in res.stderr
