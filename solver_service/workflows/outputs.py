"""Files written from the documents: JSON, CSV and PNG, each atomically.

matplotlib is imported by ``solver_service.report.plots`` only when a plot is drawn.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Optional

import numpy as np

from shared_schema.atomic import write_atomic
from shared_schema.constants import ConstantsFile
from shared_schema.documents.envelope import EnvelopeDocument, RecordPulse
from shared_schema.documents.history import HistoryDocument
from shared_schema.documents.ida import IdaDocument
from shared_schema.documents.record import RecordDocument

from ..core.pulses import extract_pulses
from ..core.spectra import response_spectrum
from ..report.plots import plot_envelopes, plot_fragility, plot_ratio_histories, plot_record
from .documents import envelope_doc, history_doc
from .ida.document import ida_csv
from .units import finite_json

#: Natural periods of a history run's record spectrum [s]: 100 log-spaced, 0.02 to 10 s.
RECORD_PERIODS = np.geomspace(0.02, 10.0, 100)

__all__ = [
    "envelope_csv",
    "finite_json",
    "write_envelope",
    "write_history",
    "write_ida",
    "write_record",
]


def envelope_csv(doc: EnvelopeDocument) -> str:
    """Return an envelope document as CSV: f_p [Hz], a_p_min [g] per mechanism, governing."""
    ids = [m.id for m in doc.mechanisms]
    lines = ["f_p_Hz," + ",".join(f"a_p_min_g_{i}" for i in ids) + ",governing"]
    for k, f in enumerate(doc.f_p):
        vals = [m.a_p_min_g[k] for m in doc.mechanisms]
        cells = ["" if v is None else f"{v:.6g}" for v in vals]
        lines.append(f"{f:.6g}," + ",".join(cells) + f",{doc.governing[k] or ''}")
    return "\n".join(lines) + "\n"


def write_envelope(
    cf: ConstantsFile,
    f_p: np.ndarray[Any, Any],
    out_dir: Path,
    *,
    stem: str = "envelope",
    title: str = "",
    method: str = "exact",
    record_pulse: Optional[RecordPulse] = None,
) -> EnvelopeDocument:
    """Write ``<stem>.json``, ``<stem>.csv`` and ``<stem>.png`` (atomically); return the doc.

    ``method`` as ``envelope_doc``; ``record_pulse`` (from ``record_pulse_doc``) is added to
    the JSON and drawn on the plot. The plot draws where each band edge lies.
    """
    doc, envs = envelope_doc(cf, f_p, method=method, record_pulse=record_pulse)
    out_dir.mkdir(parents=True, exist_ok=True)
    data = doc.to_dict()
    write_atomic(out_dir / f"{stem}.json", json.dumps(data, indent=2) + "\n")
    write_atomic(out_dir / f"{stem}.csv", envelope_csv(doc))
    plot_envelopes(
        envs,
        data["critical"],
        out_dir / f"{stem}.png",
        labels={m.id: f"{m.id}: {m.name}" for m in cf.mechanisms},
        title=title,
        pulse_points=None if record_pulse is None else data["record_pulse"]["points"],
        edges=data["critical_edges"],
        fast=method == "library",
    )
    return doc


def write_history(
    cf: ConstantsFile,
    motion: Any,
    scales: list[float],
    out_dir: Path,
    *,
    stem: str = "history",
    title: str = "",
    max_panels: int = 6,
    **options: Any,
) -> HistoryDocument:
    """Write ``<stem>.json``, ``<stem>.png`` and ``<stem>_record.png``; return the doc.

    ``<stem>.png`` shows ``phi/phi_ov`` of every mechanism against time, one panel per
    scale (at most ``max_panels``, evenly chosen, the largest always included);
    ``<stem>_record.png`` the record with its largest sine pulse and its 5 % spectrum.
    ``options`` go to ``history_doc``. Each run is made once, with its time series.
    """
    runs: dict[tuple[str, float], Any] = {}
    doc = history_doc(cf, motion, scales, runs=runs, **options)
    out_dir.mkdir(parents=True, exist_ok=True)
    write_atomic(out_dir / f"{stem}.json", json.dumps(doc.to_dict(), indent=2) + "\n")
    order = sorted(set(scales))
    picks = sorted(
        {order[round(k)] for k in np.linspace(0, len(order) - 1, min(max_panels, len(order)))}
    )
    ids = list(dict.fromkeys(row.mechanism for row in doc.results))  # file order
    panels = [(scale, [(mech_id, runs[(mech_id, scale)]) for mech_id in ids]) for scale in picks]
    plot_ratio_histories(panels, out_dir / f"{stem}.png", title=title or motion.name)
    spectrum = response_spectrum(motion.accel.acc, motion.dt, RECORD_PERIODS, 0.05)
    pulses = extract_pulses(motion.accel, n=1)
    plot_record(motion, out_dir / f"{stem}_record.png", spectrum=spectrum, pulses=pulses)
    return doc


def write_record(
    motion: Any, doc: RecordDocument, spectrum: Any, pulses: list[Any], out_dir: Path
) -> None:
    """Write ``record.json`` and ``record.png`` (the record, its pulses and its spectrum).

    Parameters
    ----------
    motion : GroundMotion
        The record.
    doc, spectrum, pulses
        As ``documents.record_analysis`` returns them.
    out_dir : Path
        Output folder (created if missing).
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    write_atomic(out_dir / "record.json", json.dumps(doc.to_dict(), indent=2) + "\n")
    plot_record(motion, out_dir / "record.png", spectrum=spectrum, pulses=pulses)


def write_ida(doc: IdaDocument, out_dir: Path, *, title: str = "") -> None:
    """Write ``ida.json``, ``ida.csv`` and ``ida.png`` (fragility curves) of an IDA document."""
    out_dir.mkdir(parents=True, exist_ok=True)
    write_atomic(out_dir / "ida.json", json.dumps(doc.to_dict(), indent=2) + "\n")
    write_atomic(out_dir / "ida.csv", ida_csv(doc))
    plot_fragility(doc, out_dir / "ida.png", title=title)
