"""``rockmech history`` and ``rockmech record``: a record, and mechanisms under it in time.

Each command imports its workflow when it runs.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional

import typer

from ..workflows.rundir import check_folder_target, run_folder
from .errors import note, user_errors
from .options import (
    CONSTANTS_OR_TABLE_ARG,
    JSON_OPT,
    LIMITS,
    RECORD_ARG,
    RECORD_OPTIONS,
    SCALING,
    Limits,
    RecordOptions,
    Scaling,
    criterion_opt,
    grouped,
    scales,
)
from .output import (
    g4,
    mechanism_warning,
    out_note,
    print_json,
    skipped_notes,
    status,
    table,
)

if TYPE_CHECKING:
    from ..core.records import GroundMotion

__all__ = ["history", "history_options", "record_info", "record_size"]


def record_size(motions: Sequence[GroundMotion]) -> tuple[int, float]:
    """Return (samples [-], time step [s]) bounding the work of each record in ``motions``."""
    return max(len(m.accel.acc) for m in motions), max(m.dt for m in motions)


def history_options(
    scaling: Scaling, criterion: Optional[str], at_height: Optional[float]
) -> dict[str, Any]:
    """Return the options of ``write_history`` / ``history_doc`` (history, report)."""
    return {
        "sf": scaling.sf,
        "building": scaling.building,
        "criterion": criterion,
        "at_height": at_height,
    }


@user_errors
@grouped
def history(
    ctx: typer.Context,
    constants: Path = CONSTANTS_OR_TABLE_ARG,
    record: Path = RECORD_ARG,
    scale: list[float] = typer.Option(
        [1.0], "--scale", help="Scale factors on the record, e.g. --scale 0.5 1 2."
    ),
    reading: RecordOptions = RECORD_OPTIONS,
    scaling: Scaling = SCALING,
    at_height: Optional[float] = typer.Option(
        None,
        "--at-height",
        help="Also report the peak displacement [m] of a point this far [m] above each "
        "mechanism's rotation axis (to compare with shake-table tests).",
    ),
    criterion: Optional[str] = criterion_opt(
        "Overturning verdict: ratio (default for records) or exact."
    ),
    out: Optional[Path] = typer.Option(
        None,
        "--out",
        help="Folder for history.json, history.png (phi/phi_ov per scale) and "
        "history_record.png (record, largest pulse and spectrum).",
    ),
    limits: Limits = LIMITS,
    as_json: bool = JSON_OPT,
) -> None:
    """Time history of every mechanism in CONSTANTS under RECORD at each scale factor."""
    # The history workflow and its writer are loaded when the command runs (#38).
    from ..workflows import documents, inputs, outputs

    factors = scales(scale, ctx.args)
    limits.check(scales=len(factors))
    if out is not None:
        check_folder_target(out)
    cf = inputs.read_constants(constants, time_domain=True)
    motion = reading.read(record)
    limits.check(cf, scales=len(factors), record=record_size([motion]))
    options = history_options(scaling, criterion, at_height)
    runs = len(factors) * len(cf.mechanisms)
    with status(f"history: {runs} runs of {motion.name}"):
        if out is not None:
            with run_folder(out, on_note=out_note, command="history") as tmp:
                doc = outputs.write_history(cf, motion, factors, tmp, **options)
        else:
            doc = documents.history_doc(cf, motion, factors, **options)
    if as_json:
        print_json(doc)
        return
    typer.echo(
        f"{motion.name}: PGA {motion.pga_g:.3f} g, dt {motion.dt:g} s, "
        f"{motion.duration:.2f} s; criterion: {doc.criterion}"
    )
    for mech_id, info in (doc.scale_factors or {}).items():
        typer.echo(f"  SF {mech_id}: {info.value:.4f} = {info.formula}")
    disp = at_height is not None
    headers = ["mechanism", "scale", "peak |phi|/phi_ov", "overturned", "t_ov [s]", "impacts"]
    headers += ["error"] + (["u_peak [m]"] if disp else [])
    rows = []
    for row in doc.results:
        cells = [
            row.mechanism,
            g4(row.scale),
            g4(row.peak_ratio),
            "yes" if row.overturned else "no",
            g4(row.t_overturn),
            str(row.n_impacts),
            f"{row.error_estimate:.1e}",
        ]
        rows.append(cells + ([g4(row.peak_displacement_m)] if disp else []))
    for line in table(headers, rows):
        typer.echo(line)
    for mech_id, notes in (doc.warnings or {}).items():
        for text in notes:
            mechanism_warning(mech_id, text)
    for text in doc.option_warnings or []:
        note(f"warning: {text}")
    skipped_notes(doc)
    if out is not None:
        typer.echo(f"wrote {out / 'history.json'}, history.png, history_record.png")


@user_errors
@grouped
def record_info(
    record: Path = RECORD_ARG,
    reading: RecordOptions = RECORD_OPTIONS,
    zeta: float = typer.Option(0.05, "--damping", help="Damping ratio of the spectrum [-]."),
    t_min: float = typer.Option(0.02, "--t-min", help="Shortest period of the spectrum [s]."),
    t_max: float = typer.Option(10.0, "--t-max", help="Longest period of the spectrum [s]."),
    n: int = typer.Option(100, "--n", help="Number of log-spaced periods."),
    pulses: int = typer.Option(5, "--pulses", help="How many of the largest pulses to list."),
    f_min: Optional[float] = typer.Option(None, "--f-min", help="Pulse search: lowest f_p [Hz]."),
    f_max: Optional[float] = typer.Option(None, "--f-max", help="Pulse search: highest f_p [Hz]."),
    out: Optional[Path] = typer.Option(
        None, "--out", help="Folder for record.json and record.png (record and spectrum)."
    ),
    limits: Limits = LIMITS,
    as_json: bool = JSON_OPT,
) -> None:
    """Describe a record: metadata, largest sine pulses and exact response spectrum."""
    # The record's analysis and its writer are loaded when the command runs (#38).
    from ..workflows import documents, outputs

    limits.check(periods=n)
    if out is not None:
        check_folder_target(out)
    motion = reading.read(record)
    limits.check(record=record_size([motion]))
    periods = documents.log_grid(t_min, t_max, n, names=("t_min", "t_max"))
    with status(f"record: spectrum at {len(periods)} periods and pulses"):
        doc, spectrum, found = documents.record_analysis(
            motion, periods, zeta, n_pulses=pulses, f_min=f_min, f_max=f_max
        )
    if out is not None:
        with run_folder(out, on_note=out_note, command="record") as tmp:
            outputs.write_record(motion, doc, spectrum, found, tmp)
    if as_json:
        print_json(doc)
        return
    typer.echo(
        f"{motion.name}: {len(motion.accel.acc)} samples, dt {motion.dt:g} s, "
        f"{motion.duration:.2f} s, PGA {motion.pga_g:.4f} g"
    )
    meta = motion.metadata
    typer.echo(
        "  "
        + ", ".join(
            f"{key} {meta[key]}"
            for key in ("format", "units", "station", "component", "channels")
            if meta.get(key) not in (None, "")
        )
    )
    typer.echo("largest one-cycle sine pulses (a_p signed: > 0 first accelerates positively):")
    rows = [[f"{p.a_p_g:+.4g}", g4(p.f_p_hz), g4(p.t_start_s)] for p in doc.pulses]
    for line in table(["a_p [g]", "f_p [Hz]", "t_start [s]"], rows):
        typer.echo(line)
    spec = doc.spectrum
    psa = [-1.0 if v is None else v for v in spec.psa_g]
    k = max(range(len(psa)), key=lambda i: psa[i])
    typer.echo(
        f"spectrum ({100 * zeta:g} %): peak PSA {spec.psa_g[k]:.4f} g at "
        f"T = {spec.periods_s[k]:.3f} s (computed in {(spec.runtime_s or 0.0) * 1e3:.1f} ms)"
    )
    if out is not None:
        typer.echo(f"wrote {out / 'record.json'}, record.png")
