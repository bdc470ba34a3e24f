"""``rockmech check`` and ``rockmech assess``: code checks, and the assessment report.

Each command imports its workflow (the code checks, the assessment report) when it runs.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import typer

from ..workflows.rundir import check_file_target
from .errors import user_errors
from .options import CONSTANTS_ARG, JSON_OPT, RECORD_OPTIONS, RecordOptions, grouped
from .output import print_json, status

__all__ = ["assess", "check"]


def _verdict(check: Any) -> str:
    """Return a check's verdict in one word (``n/a``: it did not run)."""
    if check.status != "ok":
        return "n/a"
    return {True: "pass", False: "FAIL", None: "incomplete"}[check.passes]


def _num(value: Any, width: int, digits: int = 4) -> str:
    """Return a number right-aligned in ``width`` to ``digits`` figures ("-" for None)."""
    if value is None:
        return f"{'-':>{width}}"
    return f"{value:>{width}.{digits}g}"


@user_errors
def check(
    constants: Path = CONSTANTS_ARG,
    site: Path = typer.Argument(..., help="Site file (SITE.json): hazard, FC, q, building."),
    as_json: bool = JSON_OPT,
) -> None:
    """Code checks of every mechanism (Circolare 2019 §C8.7.1: linear SLV, nonlinear SLV/SLC)."""
    # The check document's variants, for the summary table: loaded with the checks.
    from shared_schema.documents.check import (
        Linear2009,
        Linear2019,
        NoCurve2019,
        Nonlinear2009,
        Nonlinear2019,
    )

    # The code checks and their readers are loaded when the command runs (#38).
    from ..workflows import assess, inputs

    doc = assess.check_document(inputs.read_constants(constants), assess.read_site(site))
    if as_json:
        print_json(doc)
        return
    s = doc.site
    typer.echo(f"method: {doc.method.name}: {doc.method.standard}")
    typer.echo(f"{s.code}: a_g S = {s.pga_g:.4f} g, FC = {s.FC:g}, q = {s.q:g}")
    if s.T1 is not None:
        typer.echo(f"T1 = {s.T1:.4g} s ({s.T1_source})")
    period = "T_SLV s" if doc.method.name == "circ2019" else "Ts s"
    typer.echo(
        f"{'mechanism':<10}{'alpha0':>9}{'e*':>8}{'a0* m/s2':>10}{'demand':>9}{'linear':>8}"
        f"{'d m':>9}{'demand':>9}{period:>8}{'nonlinear':>11}"
    )
    for row in doc.mechanisms:
        lin, non = row.linear, row.nonlinear
        if isinstance(lin, (Linear2019, Linear2009)):
            left = (
                f"{_num(lin.alpha0, 9)}{_num(lin.e_star, 8)}{_num(lin.a0_star, 10)}"
                f"{_num(lin.demand, 9)}{_verdict(lin):>8}"
            )
        else:
            left = f"{'-':>9}{'-':>8}{'-':>10}{'-':>9}{_verdict(lin):>8}"
        if isinstance(non, Nonlinear2009):
            d, t = non.du_star, non.Ts
        elif isinstance(non, (Nonlinear2019, NoCurve2019)):
            d, t = non.d_SLV, non.T_SLV
        if isinstance(non, (Nonlinear2019, NoCurve2019, Nonlinear2009)):
            right = f"{_num(d, 9)}{_num(non.demand, 9)}{_num(t, 8, 3)}{_verdict(non):>11}"
        else:
            right = f"{'-':>9}{'-':>9}{'-':>8}{_verdict(non):>11}"
        typer.echo(f"{row.id:<10}" + left + right)
        if isinstance(non, Nonlinear2019):
            slc = non.SLC
            state = {True: "pass", False: "FAIL", None: "not evaluated"}[slc.passes]
            typer.echo(
                f"  {row.id}: SLC d = {slc.d:.4g} m, demand = {slc.demand:.4g} m, "
                f"T_SLC = {slc.T_SLC:.3g} s, a_g,SLC = {slc.a_g_capacity:.4g} g: {state}"
            )
        notes: set[str] = {c.note for c in (lin, non) if c.note}
        for text in sorted(notes):
            typer.echo(f"  note: {row.id}: {text}")
    if doc.governing is not None:
        typer.echo(f"governing mechanism: {doc.governing}")


# assess reads records without --channel and --component
@user_errors
@grouped
def assess(
    constants: Path = CONSTANTS_ARG,
    site: Path = typer.Argument(..., help="Site file (SITE.json)."),
    record: list[Path] = typer.Option([], "--record", help="Record(s) for the dynamic verdict."),
    out: Path = typer.Option(..., "-o", "--out", help="HTML report to write."),
    pdf: bool = typer.Option(False, "--pdf", help="Also print it to PDF (headless Chromium)."),
    multiple: list[float] = typer.Option(
        [0.5, 1.0, 1.5, 2.0], "--multiple", help="Multiples of the design scale to run."
    ),
    reading: RecordOptions = RECORD_OPTIONS,
    template_dir: Optional[Path] = typer.Option(
        None, "--template-dir", help="Folder whose assess.html.j2 overrides the layout."
    ),
    retrofit: Optional[Path] = typer.Option(
        None,
        "--retrofit",
        help="Retrofit spec (JSON), or the retrofit.json of rockmech retrofit: page one "
        "shows the tie-bars that make each failing mechanism pass.",
    ),
    as_json: bool = typer.Option(False, "--json", help="Also print the assessment JSON."),
) -> None:
    """Assessment report: code checks beside rocking dynamics for every mechanism."""
    # jinja2 (the report extra) is loaded only by this command.
    from ..report.assess import print_pdf

    # The report's inputs block and writer.
    from ..report.html import input_source, write_report

    # The code checks' readers and the document's stamp.
    from ..workflows import assess as workflow

    # The constants reader.
    from ..workflows import inputs

    # The assessment and its page's figures, run when the command runs.
    from ..workflows.pages import assess_report

    multiple = workflow.check_multiples(multiple)
    check_file_target(out)
    cf, site_file = inputs.read_constants(constants, time_domain=True), workflow.read_site(site)
    motions = [reading.read(r) for r in record]
    rspec = None
    if retrofit is not None:
        # The retrofit spec's (or retrofit.json's) reader, only with --retrofit.
        from ..workflows.retrofit_files import read_retrofit_input

        rspec = read_retrofit_input(retrofit)
    sources = [
        input_source("constants", constants.name, constants.read_bytes()),
        input_source("site", site.name, site.read_bytes()),
    ] + [input_source("record", r.name, r.read_bytes()) for r in record]
    if retrofit is not None:
        sources.append(input_source("retrofit", retrofit.name, retrofit.read_bytes()))
    options = {
        "multiples": multiple,
        "units": reading.units,
        "format": reading.record_format,
        "dt": reading.dt,
        "channel": reading.channel,
        "component": reading.component,
    }
    with status("assess: code checks and rocking dynamics"):
        doc, text = assess_report(
            cf,
            site_file,
            motions,
            multiples=multiple,
            sources=sources,
            options=options,
            template_dir=template_dir,
            retrofit=rspec,
        )
    # With --json, stdout carries exactly one JSON document; the file notes go to stderr.
    typer.echo(f"wrote {write_report(text, out)}", err=as_json)
    if pdf:
        typer.echo(f"wrote {print_pdf(out, out.with_suffix('.pdf'))}", err=as_json)
    if as_json:
        print_json(workflow.typed_assessment(doc))
