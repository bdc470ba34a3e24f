"""``history --out`` runs every (mechanism, scale) once and plots those same runs."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from shared_schema.io import read_constants
from solver_service.core import exact
from solver_service.core.records import GroundMotion
from solver_service.workflows.documents import history_doc
from solver_service.workflows.outputs import write_history

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def church_and_record() -> tuple[Any, Any]:
    cf = read_constants(EXAMPLES / "constants" / "church.json")
    motion = GroundMotion.from_two_column(EXAMPLES / "records" / "elcentro_NS.dat", units="g")
    return cf, motion


def test_runs_with_time_series_give_the_batch_document_exactly(church_and_record: Any) -> None:
    cf, motion = church_and_record
    scales = [0.5, 1.0, 2.0]
    batch = history_doc(cf, motion, scales, sf="eq28")
    runs: dict[tuple[str, float], Any] = {}
    dense = history_doc(cf, motion, scales, sf="eq28", runs=runs)
    assert dense.results == batch.results
    ran = {r.mechanism for r in batch.results}
    assert set(runs) == {(m, s) for m in ran for s in scales}
    for (mech_id, scale), res in runs.items():
        assert res.t is not None and res.ratio is not None
        row = batch.find(mech_id, scale)
        assert row.peak_ratio == res.peak_ratio
        if not res.collapsed:  # the trace of a survivor peaks at the reported ratio
            assert row.peak_ratio == pytest.approx(float(np.max(np.abs(res.ratio))), abs=1e-9)


def test_write_history_simulates_each_run_once(
    church_and_record: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cf, motion = church_and_record
    calls = {"simulate": 0, "batch": 0}
    real_simulate, real_batch = exact.simulate, exact.simulate_batch

    def counted_simulate(*args: Any, **kwargs: Any) -> Any:
        calls["simulate"] += 1
        return real_simulate(*args, **kwargs)

    def counted_batch(*args: Any, **kwargs: Any) -> Any:
        calls["batch"] += 1
        return real_batch(*args, **kwargs)

    # scaling imports the exact solver when it runs (#38): counted where it is looked up
    monkeypatch.setattr(exact, "simulate", counted_simulate)
    monkeypatch.setattr(exact, "simulate_batch", counted_batch)
    doc = write_history(cf, motion, [0.5, 1.0], tmp_path, sf="eq28")
    assert calls == {"simulate": len(doc.results), "batch": 0}
    assert (tmp_path / "history.json").read_text() == json.dumps(doc.to_dict(), indent=2) + "\n"
    assert (tmp_path / "history.png").stat().st_size > 0
