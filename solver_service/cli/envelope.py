"""``rockmech envelope`` and ``rockmech report``: overturning envelopes, and the HTML report.

Each command imports its workflow (the envelopes, the report's renderer) when it runs.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import Optional

import typer

from ..workflows.rundir import check_file_target, check_folder_target, run_folder
from .errors import fail, note, user_errors
from .history import history_options, record_size
from .options import (
    CONSTANTS_ARG,
    CONSTANTS_OR_TABLE_ARG,
    ENVELOPE_METHOD,
    FREQUENCIES,
    LIMITS,
    RECORD_OPTIONS,
    SCALING,
    EnvelopeMethod,
    FrequencyGrid,
    Limits,
    RecordOptions,
    Scaling,
    criterion_opt,
    grouped,
    scales,
)
from .output import g4, out_note, print_json, skipped_notes, status, table

__all__ = ["envelope", "report"]


@user_errors
@grouped
def envelope(
    ctx: typer.Context,
    constants: Path = CONSTANTS_OR_TABLE_ARG,
    out: Path = typer.Option(..., "--out", help="Folder for envelope.json, .csv and .png."),
    frequencies: FrequencyGrid = FREQUENCIES,
    envelope_method: EnvelopeMethod = ENVELOPE_METHOD,
    record: Optional[Path] = typer.Option(
        None,
        "--record",
        help="Draw this record's largest sine pulse on the plot, at each --record-scale.",
    ),
    record_scale: list[float] = typer.Option(
        [0.5, 1.0, 2.0], "--record-scale", help="Scale factors of the record's pulse [-]."
    ),
    reading: RecordOptions = RECORD_OPTIONS,
    limits: Limits = LIMITS,
    as_json: bool = typer.Option(False, "--json", help="Also print the JSON document."),
) -> None:
    """Minimum overturning sine-pulse amplitude of every mechanism, and the critical bands."""
    # The envelopes and their writer are loaded when the command runs (#38).
    from ..workflows import documents, inputs, outputs

    method = envelope_method.name()
    limits.check(envelope=frequencies.work(exact=False))
    f_p = frequencies.grid()
    check_folder_target(out)
    cf = inputs.read_constants(constants, time_domain=True)
    limits.check(cf, envelope=frequencies.work(exact=method == "exact"))
    pulse = None
    if record is not None:
        motion = reading.read(record)
        pulse = documents.record_pulse_doc(
            cf, motion, scales(record_scale, ctx.args), method=method
        )
    elif ctx.args:
        fail(f"unexpected argument {ctx.args[0]!r}")
    kind = "exact envelopes" if method == "exact" else "envelopes (fast mode, library)"
    with (
        status(f"{kind}: {len(cf.mechanisms)} mechanisms x {frequencies.n} frequencies"),
        run_folder(out, on_note=out_note, command="envelope") as tmp,
    ):
        doc = outputs.write_envelope(
            cf,
            f_p,
            tmp,
            method=method,
            title=f"Overturning envelopes: {constants.name}",
            record_pulse=pulse,
        )
    library_file = getattr(doc.method, "library_file", "shipped with rockmech")
    if library_file != "shipped with rockmech":
        note(f"note: envelopes interpolated in the library {library_file}")
    if as_json:
        print_json(doc)
        return
    typer.echo(f"wrote {out / 'envelope.json'}, envelope.csv, envelope.png")
    typer.echo("critical mechanism by pulse frequency:")
    rows = [[b.mechanism, g4(b.f_min), g4(b.f_max)] for b in doc.critical]
    for line in table(["mechanism", "f_min [Hz]", "f_max [Hz]"], rows):
        typer.echo(line)
    if pulse is not None:
        p = pulse.pulse
        typer.echo(
            f"largest pulse of {pulse.record}: {abs(p.a_p_g):.4f} g at "
            f"{p.f_p_hz:.3f} Hz (t = {p.t_start_s:.2f} s)"
        )
        for point in pulse.points:
            names = ", ".join(point.overturns) or "none"
            typer.echo(f"  x{point.scale:g}: {point.a_p_g:.4f} g overturns {names}")


@user_errors
@grouped
def report(
    ctx: typer.Context,
    constants: Path = CONSTANTS_ARG,
    out: Path = typer.Option(..., "-o", "--out", help="HTML file to write."),
    record: Optional[Path] = typer.Option(
        None, "--record", help="Record for time histories and its spectrum (any format)."
    ),
    scale: list[float] = typer.Option([1.0], "--scale", help="Scale factors on the record."),
    reading: RecordOptions = RECORD_OPTIONS,
    scaling: Scaling = SCALING,
    at_height: Optional[float] = typer.Option(
        None, "--at-height", help="Also tabulate the peak displacement [m] this far [m] up."
    ),
    criterion: Optional[str] = criterion_opt(
        "Verdict of the time histories: ratio (default) or exact."
    ),
    frequencies: FrequencyGrid = FREQUENCIES,
    envelope_method: EnvelopeMethod = ENVELOPE_METHOD,
    title: Optional[str] = typer.Option(None, "--title", help="Title of the report."),
    limits: Limits = LIMITS,
) -> None:
    """One self-contained HTML report: constants, envelopes, and with --record its histories."""
    # The report's inputs block and writer are loaded when the command runs (#38).
    from ..report.html import input_source, write_report

    # The constants reader and the mechanisms the time histories run.
    from ..workflows import documents, inputs

    # The report's analyses, run when the command runs.
    from ..workflows.pages import build_report

    factors = scales(scale, ctx.args)
    method = envelope_method.name()
    check_file_target(out)
    limits.check(scales=len(factors), envelope=frequencies.work(exact=False))
    f_p = frequencies.grid()
    cf = inputs.read_constants(constants, time_domain=True)
    sources = [input_source("constants", constants.name, constants.read_bytes())]
    motion = None
    if record is not None:
        motion = reading.read(record)
        sources.append(input_source("record", record.name, record.read_bytes()))
    size = None if motion is None else record_size([motion])
    envelope = frequencies.work(exact=method == "exact")
    limits.check(cf, scales=len(factors), record=size, envelope=envelope)
    options = {"scales": factors, **asdict(scaling), "at_height": at_height, "criterion": criterion}
    options.update(asdict(frequencies), method=method)
    with status("report: envelopes and histories"):
        text = build_report(
            cf,
            f_p,
            motion=motion,
            scales=factors,
            history=history_options(scaling, criterion, at_height),
            method=method,
            title=title or f"rockmech report: {constants.name}",
            sources=sources,
            request=options,
        )
    if motion is not None:
        # the page lists them too; say so here as history does
        skipped_notes({"skipped": documents.time_domain_mechanisms(cf)[1]})
    typer.echo(f"wrote {write_report(text, out)}")
