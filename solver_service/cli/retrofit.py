"""``rockmech retrofit``: the least tie force that makes each failing mechanism pass.

The command imports its workflow (the code checks, the retrofit) when it runs.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional, Sequence

import typer

from ..workflows.rundir import check_folder_target, run_folder
from .errors import user_errors
from .options import LIMITS, Limits, grouped
from .output import out_note, record_warning
from .output import table as table_lines
from .retrofit_scene import retrofit_document, search_after_lines

__all__ = ["retrofit"]

#: The limits this command takes: the time limit and --no-limits.
RETROFIT_LIMITS = LIMITS.only("no_limits", "time_limit")


def _kn(value: Optional[float]) -> str:
    return "-" if value is None else f"{value / 1e3:.4g}"


def _ratio(value: Optional[float]) -> str:
    return "-" if value is None else f"{value:.3f}"


def _least(scales: Sequence[Any]) -> Optional[Any]:
    got = [s for s in scales if s.multiple is not None]
    return min(got, key=lambda s: s.multiple) if got else None


def _records_line(m: Any) -> str:
    """Return a mechanism's line: its records' least overturning/design scale, before -> after."""
    first = _least(m.records_before)
    after = None
    if m.chosen is not None:
        after = _least(m.options[m.chosen].records_after)
    name = "-" if first is None else first.record
    return (
        f"  {m.id}: records' least overturning/design scale "
        f"{_ratio(None if first is None else first.multiple)} ({name}) -> "
        f"{_ratio(None if after is None else after.multiple)}"
        + ("" if after is None else f" ({after.record})")
    )


def _print_table(doc: Any) -> None:
    """Print the retrofit's table, a sentence per mechanism and what governs next."""
    # The table's rows (the document summarised) are loaded when the command prints.
    from ..report.retrofit import retrofit_summary

    summary = retrofit_summary(doc)
    rows = []
    for row in summary:
        o = row.option
        rows.append(
            [
                row.id,
                row.status,
                "-" if o is None else f"{o.height_m:.4g}",
                _kn(None if o is None else o.T_star_N),
                "-" if o is None or o.governing is None else o.governing,
                row.bar_text,
                f"{_ratio(row.before_ratio)} -> {_ratio(row.after_ratio)}",
            ]
        )
    headers = [
        "mechanism",
        "status",
        "h_t [m]",
        "T* [kN]",
        "governs",
        "bars",
        "least a_g ratio",
    ]
    for line in table_lines(headers, rows):
        typer.echo(line)
    for row in summary:
        typer.echo(f"  {row.sentence}")
    for m in doc.mechanisms:
        if m.records_before:
            typer.echo(_records_line(m))
    nxt = doc.governs_next
    if nxt is not None and nxt.after is not None and nxt.after_margin is not None:
        typer.echo(
            f"with the ties in, of these mechanisms {nxt.after} governs: margin "
            f"{nxt.after_margin:.3f} ({nxt.after_criterion}); before, {nxt.before} at "
            f"{nxt.before_margin:.3f}"
        )
    if doc.search_after is not None:
        for line in search_after_lines(doc.search_after):
            typer.echo(line)


@user_errors
@grouped
def retrofit(
    constants: Optional[Path] = typer.Argument(
        None, help="Kinematic-constants JSON file (or --scene with --search-spec)."
    ),
    scene: Optional[Path] = typer.Option(
        None,
        "--scene",
        help="Scene (.3dm), or a `rockmech search --out` folder, to search with "
        "--search-spec: the designed ties go in as tie-bars and the search runs again.",
    ),
    search_spec: Optional[Path] = typer.Option(
        None, "--search-spec", help="The search spec (JSON) of --scene."
    ),
    site: Path = typer.Option(..., "--site", help="Site file (SITE.json): hazard, FC, q."),
    spec: Path = typer.Option(
        ...,
        "--spec",
        help="Retrofit spec (JSON): steel grade and bar diameters [mm], the anchorage "
        "resistance [N] with its source, tie heights above each hinge [m].",
    ),
    record: list[Path] = typer.Option(
        [],
        "--record",
        help="Record(s) each tied mechanism must survive at its design scale, by the exact "
        "solver (formats detected; default: the spec's records).",
    ),
    out: Optional[Path] = typer.Option(
        None,
        "-o",
        "--out",
        help="Folder to write retrofit.json into (only that file is replaced).",
    ),
    limits: Limits = RETROFIT_LIMITS,
    as_json: bool = typer.Option(False, "--json", help="Print the retrofit document."),
) -> None:
    """Tie-bars for every mechanism that fails the 2019 checks: least force, bar, checks after."""
    # The retrofit spec's reader is loaded when the command runs.
    from shared_schema.retrofit import read_retrofit_spec

    # The site reader is loaded when the command runs.
    from ..workflows import assess

    # The document's file.
    from ..workflows.retrofit_files import RETROFIT_FILE, retrofit_json, write_retrofit

    # The records' reader.
    from ..workflows.retrofit_records import read_retrofit_records

    if out is not None:
        check_folder_target(out)
    site_file = assess.read_site(site)
    rspec = read_retrofit_spec(spec)
    motions = read_retrofit_records(rspec, spec.parent, record, on_warning=record_warning)
    doc = retrofit_document(constants, scene, search_spec, site_file, rspec, motions, limits)
    if out is not None:
        # Only retrofit.json is replaced: the other outputs in the folder stay.
        with run_folder(out, on_note=out_note, command="retrofit") as tmp:
            write_retrofit(tmp, doc)
    if as_json:
        typer.echo(retrofit_json(doc), nl=False)
        if out is not None:
            typer.echo(f"wrote {out / RETROFIT_FILE}", err=True)
        return
    _print_table(doc)
    if out is not None:
        typer.echo(f"wrote {out / RETROFIT_FILE}")
