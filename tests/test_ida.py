"""Incremental dynamic analysis: local runs against direct simulations; a real Dask cluster."""

from __future__ import annotations

import json
import os
import socket
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from shared_schema.errors import InputError
from shared_schema.io import load_constants
from solver_service.cli import app
from solver_service.core.exact import simulate
from solver_service.core.records import GroundMotion
from solver_service.ida import (
    _longest_first,
    _tasks,
    available_cores,
    level_blocks,
    parse_levels,
    run_ida,
)
from solver_service.workflows.adapter import models_from_file

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CONSTANTS = EXAMPLES / "constants" / "rect_walls.json"
LEVELS = [0.2, 0.5, 1.0, 2.0, 3.5]
runner = CliRunner()


@pytest.fixture(scope="module")
def motions(elcentro_path: Path) -> list[GroundMotion]:
    """El Centro N-S and two distinct motions made from it (reversed in time, and negated)."""
    ns = GroundMotion.from_file(elcentro_path, units="g")
    acc = ns.accel.acc
    return [
        ns,
        GroundMotion.from_samples(acc[::-1].copy(), ns.dt, name="reversed"),
        GroundMotion.from_samples(-acc, ns.dt, name="negated"),
    ]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_local_ida_counts_equal_direct_simulations(motions: list[GroundMotion]) -> None:
    cf = load_constants(CONSTANTS)
    seen: list[int] = []
    doc = run_ida(cf, motions, LEVELS[::-1], progress=lambda done, total: seen.append(done))
    assert seen == [1, 2, 3]
    assert doc["intensity"] == {"measure": "scale", "units": "-", "levels": LEVELS}
    assert doc["runs"] == len(motions) * len(LEVELS) * len(cf.mechanisms)
    for model, mech in zip(models_from_file(cf), doc["mechanisms"]):
        verdicts = np.array(
            [[simulate(model, m.accel, scale=s).overturned for s in LEVELS] for m in motions]
        )
        assert mech["n_overturned"] == verdicts.sum(axis=0).tolist()
        assert mech["fraction"] == pytest.approx(verdicts.mean(axis=0).tolist())
        for row, first in zip(verdicts, mech["first_overturning_level"]):
            assert first == (LEVELS[int(np.argmax(row))] if row.any() else None)
    assert doc["backend"]["kind"] == "local" and doc["backend"]["jobs"] == available_cores()
    assert 1 <= available_cores() <= (os.cpu_count() or 1)
    assert "scale_factors" not in doc["mechanisms"][0]


def test_level_blocks_cover_the_levels_and_spread_the_work() -> None:
    assert level_blocks(1, 10, 1) == [(0, 10)]
    for n_rec, n_lev, n_work in [(100, 50, 2), (1, 10, 2), (3, 5, 8), (2, 1, 16), (7, 13, 3)]:
        blocks = level_blocks(n_rec, n_lev, n_work)
        assert [lo for lo, _ in blocks] == sorted({lo for lo, _ in blocks})
        assert blocks[0][0] == 0 and blocks[-1][1] == n_lev
        assert all(b[1] == c[0] for b, c in zip(blocks, blocks[1:]))
        sizes = [hi - lo for lo, hi in blocks]
        assert min(sizes) >= 1 and max(sizes) - min(sizes) <= 1
        assert n_rec * len(blocks) >= min(4 * n_work, n_rec * n_lev)
    assert level_blocks(100, 50, 2) == [(0, 50)]  # enough records: one task per record


def test_local_ida_is_the_same_on_any_number_of_threads(motions: list[GroundMotion]) -> None:
    cf = load_constants(CONSTANTS)
    one = run_ida(cf, motions[:1], LEVELS, jobs=1)
    many = run_ida(cf, motions[:1], LEVELS, jobs=3)
    assert one["backend"]["tasks"] == 1 and many["backend"]["tasks"] == len(LEVELS)
    for key in ("intensity", "records", "mechanisms", "runs", "max_error_estimate"):
        assert one[key] == many[key], key
    model = models_from_file(cf)[1]
    peaks = [simulate(model, motions[0].accel, scale=s).overturned for s in LEVELS]
    assert many["mechanisms"][1]["n_overturned"] == [int(p) for p in peaks]
    with pytest.raises(InputError, match="jobs"):
        run_ida(cf, motions[:1], LEVELS, jobs=0)


def test_longest_tasks_start_first_and_results_keep_record_order(
    motions: list[GroundMotion],
) -> None:
    # Records of 1/4, full and 1/2 length: the full one is submitted first, yet the document
    # lists the records in the order given, with the numbers of a one-thread run.
    acc, dt = motions[0].accel.acc, motions[0].dt
    cut = [
        GroundMotion.from_samples(acc[: acc.size // 4], dt, name="quarter"),
        GroundMotion.from_samples(acc, dt, name="full"),
        GroundMotion.from_samples(acc[: acc.size // 2], dt, name="half"),
    ]
    payloads = [{"acc": m.accel.acc, "levels": LEVELS} for m in cut]
    tasks = _tasks(payloads, 2)
    assert len(tasks) == 9  # 3 records x 3 level blocks (1, 2 and 2 levels)
    order = _longest_first(tasks)
    assert sorted(order) == list(range(9))
    work = [tasks[k][1]["acc"].size * len(tasks[k][1]["levels"]) for k in order]
    assert work == sorted(work, reverse=True)
    assert [tasks[k][0] for k in order[:3]] == [1, 1, 1]  # the full record's blocks first
    assert tasks[order[-1]][0] == 0  # the quarter record's one-level block last
    cf = load_constants(CONSTANTS)
    one = run_ida(cf, cut, LEVELS, jobs=1)
    two = run_ida(cf, cut, LEVELS, jobs=2)
    assert [r["name"] for r in two["records"]] == ["quarter", "full", "half"]
    for key in ("records", "mechanisms", "max_error_estimate"):
        assert one[key] == two[key], key


def test_pga_intensity_scales_each_record_to_the_level(motions: list[GroundMotion]) -> None:
    cf = load_constants(CONSTANTS)
    levels = [0.1, 0.3, 0.6]
    doc = run_ida(cf, motions, levels, im="pga")
    assert doc["intensity"]["units"] == "g"
    model = models_from_file(cf)[0]
    expected = [
        sum(simulate(model, m.accel, scale=lv / m.pga_g).overturned for m in motions)
        for lv in levels
    ]
    assert doc["mechanisms"][0]["n_overturned"] == expected


def test_dask_local_cluster_gives_the_local_numbers(motions: list[GroundMotion]) -> None:
    distributed = pytest.importorskip("distributed")
    cf = load_constants(CONSTANTS)
    local = run_ida(cf, motions, LEVELS)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        remote = run_ida(cf, motions, LEVELS, scheduler=cluster.scheduler_address)
        # One record: the levels are cut into blocks so both workers get work.
        single = run_ida(cf, motions[:1], LEVELS, scheduler=cluster.scheduler_address)
    assert remote["backend"]["kind"] == "dask"
    assert remote["backend"]["n_workers"] == 2
    for key in ("intensity", "records", "mechanisms", "runs", "max_error_estimate", "criterion"):
        assert remote[key] == local[key], key
    assert single["backend"]["tasks"] == len(LEVELS) > len(single["records"])
    local_single = run_ida(cf, motions[:1], LEVELS, jobs=1)
    for key in ("intensity", "records", "mechanisms", "runs", "max_error_estimate", "criterion"):
        assert single[key] == local_single[key], key


def test_unreachable_scheduler_is_a_clear_error_not_a_hang(motions: list[GroundMotion]) -> None:
    address = f"tcp://127.0.0.1:{_free_port()}"
    start = time.perf_counter()
    with pytest.raises(InputError, match=f"cannot reach the Dask scheduler at {address}"):
        run_ida(load_constants(CONSTANTS), motions[:1], [1.0], scheduler=address, timeout=1.0)
    assert time.perf_counter() - start < 30.0  # bounded by the timeout, with margin
    res = runner.invoke(
        app,
        [
            *("ida", str(CONSTANTS), str(EXAMPLES / "records" / "elcentro_NS.dat")),
            *("--scales", "1", "--scheduler", address, "--timeout", "1"),
        ],
    )
    assert res.exit_code == 2 and address in res.stderr and "scheduler" in res.stderr


def test_cli_ida_writes_json_csv_and_plot(tmp_path: Path, elcentro_path: Path) -> None:
    res = runner.invoke(
        app,
        [
            *("ida", str(CONSTANTS), str(elcentro_path), str(elcentro_path)),
            *("--scales", "0.3:3:6", "--out", str(tmp_path), "--no-progress"),
        ],
    )
    assert res.exit_code == 0, res.output
    doc = json.loads((tmp_path / "ida.json").read_text())
    assert doc["intensity"]["levels"] == pytest.approx(np.geomspace(0.3, 3, 6).tolist())
    csv = (tmp_path / "ida.csv").read_text().splitlines()
    assert csv[0] == "scale_-,fraction_W1,fraction_W2,fraction_F1" and len(csv) == 7
    assert (tmp_path / "ida.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "median" in res.stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--scales", "abc"], "scales: expected a list"),
        (["--scales", "0,1"], "scales[0]"),
        (["--scales", "1,1"], "repeated"),
        (["--scales", "1", "--im", "pgv"], "im: must be one of"),
        (["--scales", "1", "--timeout", "0"], "timeout"),
        (["--scales", "1", "--jobs", "0"], "jobs: must be a whole number >= 1"),
    ],
)
def test_cli_ida_bad_input(args: list[str], message: str) -> None:
    record = str(EXAMPLES / "records" / "elcentro_NS.dat")
    res = runner.invoke(app, ["ida", str(CONSTANTS), record, *args])
    assert res.exit_code == 2 and message in res.stderr, res.output


def test_parse_levels() -> None:
    assert parse_levels("0.1, 0.2,0.5") == [0.1, 0.2, 0.5]
    assert parse_levels("1:100:3") == pytest.approx([1.0, 10.0, 100.0])
    with pytest.raises(InputError, match="scales"):
        parse_levels("1:0.5:3")


def test_a_mechanism_without_eta_is_skipped_with_a_note_not_fatal(
    motions: list[GroundMotion], tmp_path: Path
) -> None:
    church = load_constants(EXAMPLES / "constants" / "church.json")
    no_eta = [m.id for m in church.mechanisms if m.eta is None]
    assert no_eta == ["F1"]
    levels = [0.5, 1.0, 2.0]
    doc = run_ida(church, motions[:1], levels, jobs=1)
    assert [s["mechanism"] for s in doc["skipped"]] == ["F1"]
    assert "eta" in doc["skipped"][0]["reason"]
    kept = church.model_copy(update={"mechanisms": church.mechanisms[1:]})
    alone = run_ida(kept, motions[:1], levels, jobs=1)
    assert [m["id"] for m in doc["mechanisms"]] == [m["id"] for m in alone["mechanisms"]]
    assert [m["n_overturned"] for m in doc["mechanisms"]] == [
        m["n_overturned"] for m in alone["mechanisms"]
    ]
    assert "skipped" not in alone
    rec = tmp_path / "r.dat"
    rec.write_text("".join(f"{0.02 * i:.2f} {0.1 * np.sin(i / 3):.5f}\n" for i in range(200)))
    res = CliRunner().invoke(
        app, ["ida", str(EXAMPLES / "constants" / "church.json"), str(rec), "--scales", "1,2"]
    )
    assert res.exit_code == 0, res.output
    assert "warning: F1 skipped" in res.stderr
    assert f"x {len(church.mechanisms) - 1} mechanisms" in res.stdout
