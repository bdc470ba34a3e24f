"""The IDA document: the reduction of a run's tasks, the fragility fits and the CSV."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from shared_schema.constants import ConstantsFile
from shared_schema.documents.ida import IdaDocument
from shared_schema.rules import IM_MEASURES

from ...core.fragility import fit_lognormal

__all__ = ["Totals", "ida_csv", "ida_document"]


class Totals:
    """The reduction of a run's tasks: counts, first levels, error estimates, timing."""

    def __init__(self, n_records: int, n_mech: int, n_levels: int, n_runs: int) -> None:
        self.counts = np.zeros((n_mech, n_levels), dtype=np.int64)
        self.first = np.full((n_records, n_mech), n_levels, dtype=np.int64)
        self.factors: list[dict[str, float]] = [{} for _ in range(n_records)]
        self.max_error = 0.0
        self.incomplete = 0
        self.kernel_s = 0.0
        self.criteria: set[str] = set()
        self.methods: set[str] = set()
        self.timing: list[tuple[str, float, float, float]] = []
        self.runs_done = 0
        self.n_runs = n_runs

    def add(self, part: dict[str, Any]) -> None:
        """Add the reduced runs of one task (``task.run_task``)."""
        block, idx = slice(part["lo"], part["hi"], part["step"]), part["records"]
        self.counts[:, block] += part["counts"]
        self.first[idx] = np.minimum(self.first[idx], part["first"])
        if part["factors"] is not None:
            for i, factors in zip(idx, part["factors"]):
                self.factors[i] = factors
        self.max_error = float(np.maximum(self.max_error, part["max_error"]))
        self.incomplete += part["incomplete"]
        self.kernel_s += part["kernel_s"]
        self.criteria.add(part["criterion"])
        self.methods.add(part["method"])
        self.timing.append((part["lane"], part["start"], part["end"], part["kernel_s"]))
        self.runs_done += len(idx) * part["counts"].size

    def task_stats(self) -> dict[str, Any]:
        """Mean task time and per-task overhead [s] (see ``run_ida``)."""
        lanes: dict[str, list[tuple[float, float, float]]] = {}
        for lane, start, end, kernel in self.timing:
            lanes.setdefault(lane, []).append((start, end, kernel))
        busy = gaps = kernel_s = 0.0
        for runs in lanes.values():
            runs.sort()
            busy += sum(end - start for start, end, _ in runs)
            kernel_s += sum(k for *_, k in runs)
            gaps += sum(max(0.0, b[0] - a[1]) for a, b in zip(runs, runs[1:]))
        n = max(len(self.timing), 1)
        overhead = (busy - kernel_s + gaps) / n
        task = busy / n
        starts = [start for _, start, _, _ in self.timing] or [0.0]
        ends = [end for _, _, end, _ in self.timing] or [0.0]
        return {
            "lanes": len(lanes),
            "task_s": task,
            "overhead_per_task_s": overhead,
            "overhead_fraction": overhead / task if task > 0 else 0.0,
            "gap_per_task_s": gaps / n,
            "span_s": max(ends) - min(starts),
        }


def ida_document(
    cf: ConstantsFile, motions: Sequence[Any], lv: list[float], measure: str, totals: Totals
) -> dict[str, Any]:
    """Build the IDA document's results from the reduced runs (counts, first levels, fits).

    ``run_ida`` adds the timing, the backend and the optional sections, and types it.
    """
    n_rec = len(motions)
    mechanisms = []
    for i, mech in enumerate(cf.mechanisms):
        counts = totals.counts[i]
        entry: dict[str, Any] = {
            "id": mech.id,
            "n_overturned": [int(c) for c in counts],
            "fraction": [float(c) / n_rec for c in counts],
            "first_overturning_level": [
                lv[int(k)] if k < len(lv) else None for k in totals.first[:, i]
            ],
            "fragility": fit_lognormal(lv, counts, n_rec).to_dict(),
        }
        factors = [f.get(mech.id) for f in totals.factors]
        if any(f is not None for f in factors):
            entry["scale_factors"] = factors
        mechanisms.append(entry)
    return {
        "intensity": {"measure": measure, "units": IM_MEASURES[measure], "levels": lv},
        "records": [
            {
                "name": m.name,
                "pga_g": m.pga_g,
                "dt_s": float(m.dt),
                "n_samples": len(m.accel.acc),
            }
            for m in motions
        ],
        "criterion": ", ".join(sorted(totals.criteria)),
        "method": ", ".join(sorted(totals.methods)),
        "mechanisms": mechanisms,
        "runs": totals.n_runs,
        "max_error_estimate": totals.max_error,
    }


def ida_csv(doc: IdaDocument) -> str:
    """Return the overturned fractions as CSV: level, then one column per mechanism."""
    head = f"{doc.intensity.measure}_{doc.intensity.units}"
    lines = [head + "," + ",".join(f"fraction_{m.id}" for m in doc.mechanisms)]
    for j, level in enumerate(doc.intensity.levels):
        cells = [f"{m.fraction[j]:.6g}" for m in doc.mechanisms]
        lines.append(f"{level:.6g}," + ",".join(cells))
    return "\n".join(lines) + "\n"
