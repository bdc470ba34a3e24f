"""Incremental dynamic analysis: local runs against direct simulations; a real Dask cluster."""

from __future__ import annotations

import contextlib
import gc
import json
import math
import os
import random
import signal
import socket
import sys
import time
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any, Optional

import numpy as np
import pytest
from typer.testing import CliRunner

from shared_schema.documents.ida import IdaDocument
from shared_schema.errors import InputError
from shared_schema.io import read_constants
from solver_service.cli import app
from solver_service.cli.ida import parse_levels
from solver_service.core.exact import simulate
from solver_service.core.records import GroundMotion
from solver_service.workflows import ida
from solver_service.workflows.adapter import models_from_file
from solver_service.workflows.ida import (
    MIN_TASK_S,
    PEAKS_FILE,
    TASK_S,
    available_cores,
    plan_tasks,
    run_ida,
    task_seconds,
)
from solver_service.workflows.ida import dask as ida_dask
from solver_service.workflows.limits import TimeLimitExceeded, time_limit

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CONSTANTS = EXAMPLES / "constants" / "rect_walls.json"
LEVELS = [0.2, 0.5, 1.0, 2.0, 3.5]
#: What a document holds that depends on the path and the cutting: timing and the backend.
TIMING = {"runtime_s", "compute_s", "backend"}
runner = CliRunner()
#: LocalCluster options: no dashboard, and the scheduler's HTTP server (its metrics, there
#: even without a dashboard) on a free port, not 8787, which tests running at once share.
NO_DASHBOARD: dict[str, Any] = {
    "dashboard_address": None,
    "scheduler_kwargs": {"dashboard_address": ":0"},
}


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


@pytest.fixture(scope="module")
def mixed(motions: list[GroundMotion]) -> list[GroundMotion]:
    """Records of 1/4, full and 1/2 length and the three full ones: packs of unequal records."""
    acc, dt = motions[0].accel.acc, motions[0].dt
    return [
        GroundMotion.from_samples(acc[: acc.size // 4], dt, name="quarter"),
        *motions,
        GroundMotion.from_samples(acc[: acc.size // 2], dt, name="half"),
    ]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _results(doc: IdaDocument, *drop: str) -> dict[str, Any]:
    """The document's JSON without its timing and backend: what must not depend on the path."""
    return {k: v for k, v in doc.to_dict().items() if k not in TIMING and k not in drop}


def _peak_rows(path: Path) -> list[tuple[Any, ...]]:
    """The rows of a peaks file, sorted by (record, mechanism, level)."""
    pq = pytest.importorskip("pyarrow.parquet")
    table = pq.read_table(path).to_pydict()
    rows = list(zip(*(table[k] for k in table)))
    return sorted(rows, key=lambda r: (r[0], r[2], r[3]))


def test_local_ida_counts_equal_direct_simulations(motions: list[GroundMotion]) -> None:
    cf = read_constants(CONSTANTS)
    seen: list[tuple[int, int]] = []
    doc = run_ida(
        cf, motions, LEVELS[::-1], progress=lambda done, total: seen.append((done, total))
    )
    n_runs = len(motions) * len(LEVELS) * len(cf.mechanisms)
    assert seen[0] == (0, n_runs) and seen[-1] == (n_runs, n_runs)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)
    assert doc.intensity.to_dict() == {"measure": "scale", "units": "-", "levels": LEVELS}
    assert doc.measure == "scale" and doc.levels == LEVELS
    assert doc.runs == n_runs
    for model, mech in zip(models_from_file(cf), doc.mechanisms):
        verdicts = np.array(
            [[simulate(model, m.accel, scale=s).overturned for s in LEVELS] for m in motions]
        )
        assert doc.find(mech.id) is mech
        assert mech.n_overturned == verdicts.sum(axis=0).tolist()
        assert mech.fraction == pytest.approx(verdicts.mean(axis=0).tolist())
        for row, first in zip(verdicts, mech.first_overturning_level):
            assert first == (LEVELS[int(np.argmax(row))] if row.any() else None)
    backend = doc.backend
    assert backend.kind == "local" and backend.jobs == available_cores()
    assert backend.tasks >= 1 and 0 < backend.task_s and backend.overhead_per_task_s >= 0
    assert 1 <= available_cores() <= (os.cpu_count() or 1)
    assert "scale_factors" not in doc.to_dict()["mechanisms"][0]


def test_plan_covers_every_run_once_in_tasks_of_the_aimed_size() -> None:
    rng = random.Random(7)
    for n_rec, n_lev, task_s in [(50, 20, 1.0), (3, 50, 0.1), (1, 7, 1e-9), (40, 1, 0.5)]:
        costs = [rng.uniform(0.0, 3.0) * rng.choice([0.01, 1.0]) for _ in range(n_rec)]
        packs, tasks = plan_tasks(costs, n_lev, task_s)
        assert sorted(i for p in packs for i in p) == list(range(n_rec))  # each record once
        cover = np.zeros((n_rec, n_lev), dtype=int)
        for t in tasks:
            assert 0 <= t.lo < t.hi <= n_lev and t.step >= 1
            for i in packs[t.pack]:
                cover[i, t.lo : t.hi : t.step] += 1
        assert (cover == 1).all()  # every run in exactly one task
        assert [t.cost_s for t in tasks] == sorted((t.cost_s for t in tasks), reverse=True)
        assert sum(t.cost_s for t in tasks) == pytest.approx(sum(costs))
        short = [t for t in tasks if len(packs[t.pack]) > 1 or costs[packs[t.pack][0]] <= task_s]
        dear = max((c for c in costs if c <= task_s), default=0.0)
        for k, pack in enumerate(packs):
            blocks = [t for t in tasks if t.pack == k]
            if len(pack) == 1 and costs[pack[0]] > task_s:  # a long record: interleaved levels
                n_blocks = min(n_lev, math.ceil(costs[pack[0]] / task_s))
                assert len(blocks) == n_blocks
                assert sorted((t.lo, t.step) for t in blocks) == [
                    (b, n_blocks) for b in range(n_blocks)
                ]
            else:  # short records dealt into packs run at all levels, estimates within one
                assert len(blocks) == 1 and (blocks[0].lo, blocks[0].hi, blocks[0].step) == (
                    0,
                    n_lev,
                    1,
                )
                assert max(t.cost_s for t in short) - blocks[0].cost_s <= dear + 1e-12
        if short:  # as many packs as the short records' work holds tasks of task_s
            work = sum(t.cost_s for t in short)
            assert len(short) == min(
                sum(len(packs[t.pack]) for t in short), max(1, round(work / task_s))
            )
    assert task_seconds(1e4, 16) == TASK_S and task_seconds(1.0, 16) == MIN_TASK_S
    assert task_seconds(32.0, 16) == pytest.approx(0.25)  # 8 tasks per worker thread


def test_plan_mixes_records_of_each_kind_into_every_pack() -> None:
    # 4 kinds of record x 25 variants, each kind's variants alike in cost: every pack gets
    # a share of each kind (a true cost the estimate misjudges for one kind evens out), where
    # packs of consecutive records by cost would hold one or two kinds each.
    costs = [0.04 + 0.01 * kind + 1e-6 * v for kind in range(4) for v in range(25)]
    packs, tasks = plan_tasks(costs, 10, 0.5)
    assert len(packs) == len(tasks) == round(sum(costs) / 0.5)
    for pack in packs:
        shares = [[i // 25 for i in pack].count(k) for k in range(4)]
        assert min(shares) >= 1 and max(shares) - min(shares) <= 2, shares


def _interleaving_task_s(cf: Any, mixed: list[GroundMotion]) -> float:
    """A task size that cuts the full-length records into interleaved blocks of 2-3 levels."""
    costs = ida.record_costs(cf, mixed, len(LEVELS))
    task_s = max(costs) / 2.5
    _, tasks = plan_tasks(costs, len(LEVELS), task_s)
    assert any(t.step > 1 and len(range(t.lo, t.hi, t.step)) > 1 for t in tasks)
    return task_s


@pytest.mark.parametrize(
    ("jobs", "task_s"), [(1, 1e-9), (3, 1e-9), (3, 0.002), (2, 1e9), (3, None)]
)
def test_results_are_identical_on_every_cutting_and_number_of_threads(
    mixed: list[GroundMotion], jobs: int, task_s: Optional[float]
) -> None:
    cf = read_constants(CONSTANTS)
    if task_s is None:  # interleaved blocks of levels beside a pack of short records
        task_s = _interleaving_task_s(cf, mixed)
    reference = run_ida(cf, mixed, LEVELS, jobs=1, task_s=1e9)  # one task, one thread
    assert reference.backend.tasks == 1
    doc = run_ida(cf, mixed, LEVELS, jobs=jobs, task_s=task_s)
    if task_s < 1e-6:  # every record cut into single levels
        assert doc.backend.tasks == len(mixed) * len(LEVELS)
    assert [r.name for r in doc.records] == [m.name for m in mixed]
    assert _results(doc) == _results(reference)  # counts bit for bit; fits hence identical


def test_pga_intensity_scales_each_record_to_the_level(motions: list[GroundMotion]) -> None:
    cf = read_constants(CONSTANTS)
    levels = [0.1, 0.3, 0.6]
    doc = run_ida(cf, motions, levels, measure="pga")
    assert doc.intensity.units == "g" and doc.measure == "pga"
    model = models_from_file(cf)[0]
    expected = [
        sum(simulate(model, m.accel, scale=lv / m.pga_g).overturned for m in motions)
        for lv in levels
    ]
    assert doc.mechanisms[0].n_overturned == expected


def test_peaks_file_holds_every_run_as_a_direct_simulation_gives_it(
    mixed: list[GroundMotion], tmp_path: Path
) -> None:
    pq = pytest.importorskip("pyarrow.parquet")
    cf = read_constants(CONSTANTS)
    path = tmp_path / "peaks.parquet"
    doc = run_ida(cf, mixed, LEVELS, jobs=2, task_s=1e-9, peaks=path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["peaks.parquet"]  # no temp left
    n_runs = len(mixed) * len(cf.mechanisms) * len(LEVELS)
    assert doc.to_dict()["peaks"] == {"file": "peaks.parquet", "rows": n_runs}
    table = pq.read_table(path)
    assert table.num_rows == n_runs and table.schema.metadata[b"intensity_measure"] == b"scale"
    rows = _peak_rows(path)
    models = models_from_file(cf)
    ids = [m.id for m in cf.mechanisms]
    for record, name, mech, level, peak, over, err, status in rows:
        assert name == mixed[record].name
        direct = simulate(models[ids.index(mech)], mixed[record].accel, scale=level)
        assert peak == pytest.approx(direct.peak_ratio, rel=1e-12, abs=1e-15)
        assert over == direct.overturned and status == direct.status
        assert 0 <= err <= doc.max_error_estimate
    for j, mech in enumerate(doc.mechanisms):
        for k, level in enumerate(LEVELS):
            hits = [r for r in rows if r[2] == ids[j] and r[3] == level and r[5]]
            assert len(hits) == mech.n_overturned[k]
    # Other cuttings (one task; interleaved blocks of levels), the same rows (in another order).
    again = tmp_path / "again.parquet"
    run_ida(cf, mixed, LEVELS, jobs=1, task_s=1e9, peaks=again)
    assert _peak_rows(again) == rows
    interleaved = tmp_path / "interleaved.parquet"
    run_ida(cf, mixed, LEVELS, jobs=2, task_s=_interleaving_task_s(cf, mixed), peaks=interleaved)
    assert _peak_rows(interleaved) == rows


def test_a_stopped_run_leaves_no_peaks_file(motions: list[GroundMotion], tmp_path: Path) -> None:
    pytest.importorskip("pyarrow")
    cf = read_constants(CONSTANTS)

    def stop(done: int, total: int) -> None:
        if done:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_ida(
            cf, motions, LEVELS, jobs=2, task_s=1e-9, peaks=tmp_path / "p.parquet", progress=stop
        )
    assert list(tmp_path.iterdir()) == []


def test_dask_local_cluster_gives_the_local_numbers_on_every_cutting(
    mixed: list[GroundMotion], tmp_path: Path
) -> None:
    distributed = pytest.importorskip("distributed")
    pytest.importorskip("pyarrow")
    cf = read_constants(CONSTANTS)
    local = run_ida(cf, mixed, LEVELS, jobs=1, task_s=1e9, peaks=tmp_path / "local.parquet")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, **NO_DASHBOARD
    ) as cluster:
        address = cluster.scheduler_address
        remote = run_ida(cf, mixed, LEVELS, scheduler=address, peaks=tmp_path / "dask.parquet")
        # Single levels: tasks share the scattered records (each fetched once per worker).
        cut = run_ida(cf, mixed, LEVELS, scheduler=address, task_s=1e-9)
        # The command line says, in one note, that the workers run Dask's defaults.
        res = runner.invoke(
            app,
            [
                *("ida", str(CONSTANTS), str(EXAMPLES / "records" / "elcentro_NS.dat")),
                *("--scales", "1,2", "--scheduler", address, "--no-progress"),
            ],
        )
    assert remote.backend.kind == "dask"
    assert remote.backend.n_workers == 2 and remote.backend.threads == 2
    # Dask's own defaults: the document names each setting that differs from rockmech's.
    assert remote.backend.settings_differ == [
        "distributed.admin.tick.interval: 20ms on 2 of 2 workers (rockmech: 1s)",
        "distributed.worker.profile.enabled: True on 2 of 2 workers (rockmech: False)",
    ]
    assert res.exit_code == 0, res.output
    [note] = [line for line in res.stderr.splitlines() if "rockmech's settings" in line]
    assert note.startswith("note: the Dask workers run without rockmech's settings")
    assert "tick.interval: 20ms on 2 of 2 workers" in note and "docs/cluster.md" in note
    assert cut.backend.tasks == len(mixed) * len(LEVELS)
    assert remote.peaks is not None and local.peaks is not None
    assert remote.peaks.to_dict() == {"file": "dask.parquet", "rows": local.peaks.rows}
    assert _results(remote, "peaks") == _results(local, "peaks") == _results(cut)
    assert _peak_rows(tmp_path / "dask.parquet") == _peak_rows(tmp_path / "local.parquet")


def test_a_scheduler_without_workers_or_with_another_rockmech_is_a_clear_error(
    motions: list[GroundMotion], monkeypatch: pytest.MonkeyPatch
) -> None:
    distributed = pytest.importorskip("distributed")
    cf = read_constants(CONSTANTS)
    with distributed.LocalCluster(n_workers=0, **NO_DASHBOARD) as cluster:
        address = cluster.scheduler_address
        with pytest.raises(InputError, match=f"no worker joined the Dask scheduler at {address}"):
            run_ida(cf, motions[:1], [1.0], scheduler=address, timeout=1.0)
    with distributed.LocalCluster(
        n_workers=1, processes=False, protocol="tcp", **NO_DASHBOARD
    ) as cluster:
        monkeypatch.setattr(ida_dask, "worker_version", lambda: "0.0.1")
        with pytest.raises(InputError, match=r"runs rockmech 0\.0\.1, this machine"):
            run_ida(cf, motions[:1], [1.0], scheduler=cluster.scheduler_address)


def test_unreachable_scheduler_is_a_clear_error_not_a_hang(motions: list[GroundMotion]) -> None:
    address = f"tcp://127.0.0.1:{_free_port()}"
    start = time.perf_counter()
    with pytest.raises(InputError, match=f"cannot reach the Dask scheduler at {address}"):
        run_ida(read_constants(CONSTANTS), motions[:1], [1.0], scheduler=address, timeout=1.0)
    assert time.perf_counter() - start < 30.0  # bounded by the timeout, with margin
    res = runner.invoke(
        app,
        [
            *("ida", str(CONSTANTS), str(EXAMPLES / "records" / "elcentro_NS.dat")),
            *("--scales", "1", "--scheduler", address, "--timeout", "1"),
        ],
    )
    assert res.exit_code == 2 and address in res.stderr and "scheduler" in res.stderr


@pytest.mark.parametrize(
    ("address", "problem"),
    [
        ("not-a-url", "it needs a host and a port number"),
        ("tcp://host", "it needs a host and a port number"),
        ("tcp://host:0", "it needs a host and a port number"),
        ("host:99999", "it needs a host and a port number"),
        ("tcp://:8786", "it needs a host and a port number"),
        ("udp://host:8786", "unknown scheme 'udp'"),
    ],
)
def test_a_malformed_scheduler_address_is_refused_before_any_connection(
    motions: list[GroundMotion], address: str, problem: str
) -> None:
    pytest.importorskip("distributed")
    start = time.perf_counter()
    with pytest.raises(InputError, match="expected a Dask scheduler address") as err:
        run_ida(read_constants(CONSTANTS), motions[:1], [1.0], scheduler=address)
    assert err.value.field == "scheduler" and problem in str(err.value)
    assert time.perf_counter() - start < 5.0  # no connection tried, no timeout waited


@pytest.mark.parametrize("address", ["tcp://sched.example:8786", "10.0.0.5:8786", "tls://h:1"])
def test_well_formed_addresses_pass_the_address_check(address: str) -> None:
    ida_dask._check_address(address)


def test_cli_ida_writes_json_csv_plot_and_peaks(tmp_path: Path, elcentro_path: Path) -> None:
    pytest.importorskip("pyarrow")
    (tmp_path / "notes.txt").write_text("mine")
    res = runner.invoke(
        app,
        [
            *("ida", str(CONSTANTS), str(elcentro_path), str(elcentro_path)),
            *("--scales", "0.3:3:6", "--out", str(tmp_path), "--no-progress", "--peaks"),
        ],
    )
    assert res.exit_code == 0, res.output
    doc = json.loads((tmp_path / "ida.json").read_text())
    assert doc["intensity"]["levels"] == pytest.approx(np.geomspace(0.3, 3, 6).tolist())
    csv = (tmp_path / "ida.csv").read_text().splitlines()
    assert csv[0] == "scale_-,fraction_W1,fraction_W2,fraction_F1" and len(csv) == 7
    assert (tmp_path / "ida.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = _peak_rows(tmp_path / PEAKS_FILE)
    assert len(rows) == doc["runs"] == 2 * 6 * 3 and doc["peaks"]["rows"] == doc["runs"]
    assert (tmp_path / "notes.txt").read_text() == "mine"
    assert "median" in res.stdout and f"ida.png, {PEAKS_FILE}" in res.stdout
    assert "locally on" in res.stdout and "tasks, overhead" in res.stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--scales", "abc"], "scales: expected a list"),
        (["--scales", "0,1"], "scales[0]"),
        (["--scales", "1,1"], "repeated"),
        (["--scales", "1", "--measure", "pgv"], "measure: must be one of"),
        (["--scales", "1", "--timeout", "0"], "timeout"),
        (["--scales", "1", "--jobs", "0"], "jobs: must be a whole number >= 1"),
        (["--scales", "1", "--peaks"], "peaks: --peaks writes ida_peaks.parquet into the --out"),
        (["--scales", "1", "--scheduler", "not-a-url"], "scheduler: expected a Dask scheduler"),
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
    church = read_constants(EXAMPLES / "constants" / "church.json")
    no_eta = [m.id for m in church.mechanisms if m.eta is None]
    assert no_eta == ["F1"]
    levels = [0.5, 1.0, 2.0]
    doc = run_ida(church, motions[:1], levels, jobs=1)
    assert doc.skipped is not None and [s.mechanism for s in doc.skipped] == ["F1"]
    assert "eta" in doc.skipped[0].reason
    kept = church.model_copy(update={"mechanisms": church.mechanisms[1:]})
    alone = run_ida(kept, motions[:1], levels, jobs=1)
    assert [m.id for m in doc.mechanisms] == [m.id for m in alone.mechanisms]
    assert [m.n_overturned for m in doc.mechanisms] == [m.n_overturned for m in alone.mechanisms]
    assert "skipped" not in alone.to_dict()
    rec = tmp_path / "r.dat"
    rec.write_text("".join(f"{0.02 * i:.2f} {0.1 * np.sin(i / 3):.5f}\n" for i in range(200)))
    res = CliRunner().invoke(
        app, ["ida", str(EXAMPLES / "constants" / "church.json"), str(rec), "--scales", "1,2"]
    )
    assert res.exit_code == 0, res.output
    assert "warning: F1 skipped" in res.stderr
    assert f"x {len(church.mechanisms) - 1} mechanisms" in res.stdout


def test_a_worker_lost_during_the_run_costs_its_tasks_not_the_run(
    mixed: list[GroundMotion],
) -> None:
    distributed = pytest.importorskip("distributed")
    dask = pytest.importorskip("dask")
    cf = read_constants(CONSTANTS)
    local = run_ida(cf, mixed, LEVELS, jobs=1)
    killed: list[int] = []
    # Started with rockmech's Dask settings (docs/cluster.md): the nannies hand them to the
    # workers they start, the one started again after the kill included.
    with (
        dask.config.set(ida.DASK_SETTINGS),
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, **NO_DASHBOARD
        ) as cluster,
    ):
        nanny = next(iter(cluster.workers.values()))

        def kill_one(done: int, total: int) -> None:
            if done and not killed:  # after the first task: the others are on the workers
                killed.append(nanny.process.process.pid)
                os.kill(killed[0], 9)

        remote = run_ida(
            cf, mixed, LEVELS, scheduler=cluster.scheduler_address, task_s=1e-9, progress=kill_one
        )
    assert killed
    assert _results(remote) == _results(local)
    assert "settings_differ" not in remote.to_dict()["backend"]


def test_a_half_built_dask_future_says_nothing_when_collected(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # Ctrl+C inside distributed.Future.__init__ leaves an object whose __del__ raises; the
    # CI run saw "Exception ignored in: Future.__del__" after the one-line message. The hook
    # a Dask run installs drops exactly that and passes every other unraisable error on.
    distributed = pytest.importorskip("distributed")
    seen: list[Any] = []
    hook = ida_dask._QuietHalfBuilt(seen.append)
    old = sys.unraisablehook
    sys.unraisablehook = hook
    try:
        half = distributed.Future.__new__(distributed.Future)
        del half
        gc.collect()
    finally:
        sys.unraisablehook = old
    assert seen == [] and "Exception ignored" not in capsys.readouterr().err
    other = types.SimpleNamespace(exc_value=AttributeError("x"), object=time.sleep)
    hook(other)
    assert seen == [other]


def _stopped_in_the_first_fill(
    mixed: list[GroundMotion],
    monkeypatch: pytest.MonkeyPatch,
    capfd: pytest.CaptureFixture[str],
    inside: Callable[[], None],
    stop: type[BaseException],
    limit: Optional[float] = None,
) -> None:
    """Run ``inside`` in the Dask feed's first call; the run must stop with ``stop`` after it.

    Checks that the call ran to its end (it submitted tasks), that the run left no task on
    the scheduler, and that nothing was printed.
    """
    distributed = pytest.importorskip("distributed")
    calls: list[int] = []
    fill = ida_dask._DaskFeed.fill

    def interrupted_fill(feed: Any) -> None:
        if not calls:
            inside()
        fill(feed)
        calls.append(len(feed.running))  # reached: the signal did not cut the call

    monkeypatch.setattr(ida_dask._DaskFeed, "fill", interrupted_fill)
    limited = time_limit(limit) if limit is not None else contextlib.nullcontext()
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, protocol="tcp", **NO_DASHBOARD
    ) as cluster:
        with pytest.raises(stop), limited:
            cf = read_constants(CONSTANTS)
            run_ida(cf, mixed, LEVELS, scheduler=cluster.scheduler_address, task_s=1e-9)
        assert calls and calls[0] > 0  # the first fill ran to its end and submitted tasks
        scheduler = cluster.scheduler
        deadline = time.monotonic() + 30
        while scheduler.tasks and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not scheduler.tasks  # cancelled, with the run's records and constants
    err = capfd.readouterr().err
    assert "Traceback" not in err and "Exception ignored" not in err


def test_ctrl_c_inside_a_dask_call_is_held_until_the_call_returns(
    mixed: list[GroundMotion], monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    # A Ctrl+C that landed inside distributed's scatter or submit left half-built futures and
    # tracebacks (#30). Now it is held while the client talks to the cluster: the call
    # finishes, then the run stops with KeyboardInterrupt and cancels its tasks.
    # Python's own handler, as a terminal gives it (a test run in the background of a
    # non-interactive shell starts with SIGINT ignored); put back after the test.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        # raise_signal: the handler runs before the next bytecode, inside the call
        _stopped_in_the_first_fill(
            mixed, monkeypatch, capfd, lambda: signal.raise_signal(signal.SIGINT), KeyboardInterrupt
        )
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # put back
    finally:
        signal.signal(signal.SIGINT, previous)


def test_the_time_limit_inside_a_dask_call_is_held_until_the_call_returns(
    mixed: list[GroundMotion], monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    # The command line's time limit (SIGALRM) could cut distributed's calls in half as Ctrl+C
    # did: it is held the same way, and the run stops with the limit's error once the call
    # has returned.
    before = signal.getsignal(signal.SIGALRM)
    _stopped_in_the_first_fill(
        mixed, monkeypatch, capfd, lambda: time.sleep(1.0), TimeLimitExceeded, limit=0.3
    )
    assert signal.getsignal(signal.SIGALRM) is before
