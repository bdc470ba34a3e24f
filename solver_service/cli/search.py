"""``rockmech constants``, ``constants-table`` and ``search``: kinematic constants from models.

Each command imports its workflow (the CAD readers and builder of ``cad_maths``, the search)
when it runs.
"""

from __future__ import annotations

import contextlib
import gc
import json
from pathlib import Path
from typing import TYPE_CHECKING, Iterator, Optional

import typer

from ..workflows.rundir import check_file_target, check_folder_target, run_folder
from .errors import note, user_errors
from .options import (
    CONSTANTS_OUTPUT_OPT,
    LIMITS,
    MESH_UNITS_OPT,
    SCENE_ARG,
    Limits,
    grouped,
)
from .output import g4, mechanism_warning, out_note, print_json, status
from .output import table as table_lines

if TYPE_CHECKING:
    from cad_maths.mechanisms.build import MechanismFailure
    from shared_schema.documents.search import SearchDocument

__all__ = ["constants", "constants_table", "search"]


@user_errors
def constants(
    scene: Path = SCENE_ARG,
    spec: Path = typer.Argument(..., help="Mechanism spec (JSON)."),
    output: Path = CONSTANTS_OUTPUT_OPT,
    as_json: bool = typer.Option(False, "--json", help="Also print the constants JSON."),
    keep_going: bool = typer.Option(
        False,
        "--keep-going",
        help=(
            "Write the mechanisms that succeed and list the ones that fail (exit status 1 "
            "when any failed). Without it, any failure writes nothing and lists every failure."
        ),
    ),
    units: Optional[str] = MESH_UNITS_OPT,
) -> None:
    """Kinematic constants of every mechanism in SPEC from the solids of SCENE."""
    # The constants file's writer is loaded when the command runs (#38).
    from shared_schema import io

    # The CAD readers and the builder are loaded when the command runs.
    from ..workflows import inputs

    check_file_target(output, "output")
    failures: list[MechanismFailure] = []
    with status(f"constants: reading {scene.name}"):
        if keep_going:
            cf, failures = inputs.constants_and_failures_from_scene_files(scene, spec, units)
        else:
            cf = inputs.constants_from_scene_files(scene, spec, units)
    io.write_constants(cf, output)
    if failures:
        typer.echo(
            f"error: {len(failures)} of {len(failures) + len(cf.mechanisms)} mechanisms failed "
            f"and are not in {output}:",
            err=True,
        )
        for failure in failures:
            typer.echo(f"  {failure.message}", err=True)
    # each mechanism's warnings (mesh repairs, implausible sizes) on stderr, --json or not
    for m in cf.mechanisms:
        notes = (m.provenance or {}).get("warnings") or []
        for text in notes if isinstance(notes, list) else []:
            mechanism_warning(m.id, str(text))
    if as_json:
        print_json(json.loads(io.stamped(cf).model_dump_json(exclude_none=True)))
        if failures:
            raise typer.Exit(code=1)
        return
    typer.echo(f"wrote {output}")
    rows = []
    for m in cf.mechanisms:
        side = m.positive
        rows.append([m.id, g4(side.p_eq), g4(side.lam), g4(side.phi_ov), g4(m.eta)])
    headers = ["mechanism", "p_eq [rad/s]", "lam [-]", "phi_ov [rad]", "eta [-]"]
    for line in table_lines(headers, rows):
        typer.echo(line)
    if failures:
        raise typer.Exit(code=1)


@user_errors
def constants_table(
    table: Path = typer.Argument(..., help="Table, one mechanism per row (.csv or .xlsx)."),
    output: Path = CONSTANTS_OUTPUT_OPT,
) -> None:
    """Turn a table of mechanisms (id, p_eq, lam, eta, f_n, h_e, h...) into a constants file."""
    # The constants file's writer is loaded when the command runs (#38).
    from shared_schema import io

    # The table reader is loaded when the command runs.
    from ..workflows.tables import checked_table

    check_file_target(output, "output")
    cf, range_error = checked_table(table)
    if range_error is not None:
        # a constants file may hold it; the time-domain commands (and REST) refuse it
        note(f"warning: {range_error}; envelope, history, ida, report and assess refuse it")
    io.write_constants(cf, output)
    typer.echo(f"wrote {output}: {len(cf.mechanisms)} mechanism(s) from {table.name}")


@contextlib.contextmanager
def collector_paused() -> Iterator[None]:
    """Pause Python's cyclic garbage collector while the command works (#37).

    The search makes many short-lived containers but few reference cycles (about 4000
    objects in all on the palazzo); with the collector on, its passes walk the objects the
    imports left (numpy, scipy, matplotlib) again and again, about 5 % of the palazzo's run.
    Reference counting still frees everything not in a cycle; the collector is switched back
    on (if it was on) when the block ends, and collects the cycles at its next full pass.
    The objects made meanwhile are moved to the oldest generation first (``gc.freeze`` then
    ``gc.unfreeze``), so that switching it back on does not walk them all at once.
    """
    was_on = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        gc.unfreeze()
        if was_on:
            gc.enable()


# the search's --no-limits lifts its own work limits
SEARCH_LIMITS = LIMITS.but(
    no_limits=typer.Option(
        False,
        "--no-limits",
        help="Lift the search's work limits (evaluations of the static multiplier and "
        "macro-blocks of the global check) and the time limit.",
    )
)


@user_errors
@grouped
def search(
    scene: Path = SCENE_ARG,
    spec: Path = typer.Argument(..., help="Search spec (JSON): walls, levels, junctions, ranking."),
    out: Path = typer.Option(
        ...,
        "-o",
        "--out",
        help="Folder for search.json, search.spec.json, constants.json, search.3dm, search.png.",
    ),
    units: Optional[str] = MESH_UNITS_OPT,
    site: Optional[Path] = typer.Option(
        None, "--site", help="Site file (SITE.json) for the code check (default: the spec's)."
    ),
    record: list[Path] = typer.Option(
        [], "--record", help="Record(s) to rank the top mechanisms on (default: the spec's)."
    ),
    exact: bool = typer.Option(
        False, "--exact", help="Envelopes by the exact solver instead of the library."
    ),
    figure: bool = typer.Option(True, "--figure/--no-figure", help="Draw search.png."),
    limits: Limits = SEARCH_LIMITS,
    as_json: bool = typer.Option(False, "--json", help="Print search.json."),
) -> None:
    """Find a façade's collapse mechanisms and rank them by how they rock (issue #31)."""
    # the search's workflow is loaded by this command only
    from ..workflows.search import search_from_files, write_search_files

    check_folder_target(out)
    with status(f"search: {scene.name}"), collector_paused():
        run = search_from_files(
            scene,
            spec,
            units=units,
            site=site,
            records=record,
            exact=exact,
            limits=not limits.no_limits,
        )
        with run_folder(out, on_note=out_note, command="search") as tmp:
            write_search_files(run, tmp, figure=figure)
    doc = run.doc
    for warning in doc.warnings:
        note(f"warning: {warning}")
    for text in doc.notes:
        note(f"note: {text}")
    for fail in doc.failures:
        note(f"warning: {fail.error}")
    if as_json:
        print_json(doc)
        return
    _print_ranking(doc, out, figure)


def _print_ranking(doc: SearchDocument, out: Path, figure: bool) -> None:
    """Print the search's ranking table (the top 15), its LP checks and what it wrote.

    Parameters
    ----------
    doc : SearchDocument
        The search's document (``search.json``).
    out : Path
        The output folder the files were written to.
    figure : bool
        Whether ``search.png`` was drawn.
    """
    rows = []
    for d in doc.ranked[:15]:
        score = None if d.overturning is None else d.overturning.band_score_g
        rows.append(
            [
                d.id,
                d.family,
                f"{d.facade} {d.direction}",
                g4(d.lam0),
                g4(d.lam_linearised),
                g4(score),
                str(d.rank_static),
            ]
        )
    band = doc.band.band_hz
    headers = [
        "mechanism",
        "family",
        "facade",
        "lam0 [-]",
        "lam [-]",
        f"a_p {band[0]:g}-{band[1]:g} Hz [g]",
        "static rank",
    ]
    for line in table_lines(headers, rows):
        typer.echo(line)
    for check in doc.lp:
        typer.echo(f"{check.facade} {check.direction}: {check.message}")
    c = doc.counts
    typer.echo(
        f"{c.candidates} mechanisms ({c.evaluations} evaluations of lam0), {c.built} "
        f"built; wrote {out / 'search.json'}, search.spec.json, constants.json, search.3dm"
        + (", search.png" if figure else "")
    )
