"""``rockmech ida``: incremental dynamic analysis, locally or on a Dask cluster.

The command imports the IDA (``solver_service.workflows.ida``: planning, the local and Dask
back ends) and its writer when it runs; the ``--scales`` text is parsed here
(``parse_levels``: a list or a log range).
"""

from __future__ import annotations

import contextlib
import functools
import math
import re
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Optional

import typer

from shared_schema.errors import InputError
from shared_schema.extras import require
from shared_schema.rules import IM_MEASURES, PEAKS_FILE

from ..workflows.rundir import check_folder_target, run_folder
from .errors import fail, note, user_errors
from .history import record_size
from .options import (
    CONSTANTS_ARG,
    JSON_OPT,
    LIMITS,
    RECORD_OPTIONS,
    SCALING,
    Limits,
    RecordOptions,
    Scaling,
    criterion_opt,
    grouped,
)
from .output import choices, g4, out_note, print_json, record_warning, skipped_notes, table

if TYPE_CHECKING:
    from shared_schema.constants import ConstantsFile
    from shared_schema.documents.ida import IdaDocument

    from ..core.records import GroundMotion

__all__ = ["MAX_RANGE_LEVELS", "ida", "parse_levels"]

MAX_RANGE_LEVELS = 1_000_000


def _range_levels(text: str) -> list[float]:
    """Levels of a log range ``start:stop:n``; each fault is named (issue #36).

    Examples
    --------
    >>> [round(v, 6) for v in _range_levels("0.1:10:3")]
    [0.1, 1.0, 10.0]
    """
    parts = text.split(":")
    example = "e.g. 0.1:3:20 (20 levels from 0.1 to 3)"
    if len(parts) != 3:
        raise InputError(
            f"a log range is three numbers start:stop:n, {example}; got {text!r} "
            f"({len(parts)} parts)",
            "scales",
        )
    names = ("start", "stop")
    bounds = []
    for name, part in zip(names, parts[:2]):
        try:
            value = float(part)
        except ValueError:
            raise InputError(
                f"the range's {name} {part.strip()!r} is not a number, in {text!r}; {example}",
                "scales",
            ) from None
        if not math.isfinite(value):
            raise InputError(f"the range's {name} must be finite, got {part.strip()!r}", "scales")
        bounds.append(value)
    lo, hi = bounds
    try:
        count = int(parts[2])
    except ValueError:
        raise InputError(
            f"the range's n (the number of levels, its third number) must be a whole number, "
            f"got {parts[2].strip()!r} in {text!r}; {example}",
            "scales",
        ) from None
    if count < 2:
        raise InputError(
            f"the range {text!r} asks for {count} levels: n (its third number) must be at "
            f"least 2; for one level give the level itself ({parts[0].strip()})",
            "scales",
        )
    if count > MAX_RANGE_LEVELS:
        raise InputError(
            f"the range {text!r} asks for {count} levels, more than {MAX_RANGE_LEVELS:,}; "
            "n (its third number) is the number of levels",
            "scales",
        )
    if lo <= 0.0:
        raise InputError(
            f"the range {text!r} starts at {lo:g}: a log range's start must be > 0 (levels "
            "are spaced evenly on a log scale, and log 0 is -infinity); start at the smallest "
            "intensity of interest, e.g. 0.05",
            "scales",
        )
    if lo >= hi:
        fix = (
            f"write the smaller first, {parts[1].strip()}:{parts[0].strip()}:{count}"
            if lo > hi
            else "give a stop above the start"
        )
        raise InputError(
            f"the range {text!r} starts at {lo:g} and stops at {hi:g}: the start must be "
            f"below the stop; {fix}",
            "scales",
        )
    import numpy as np  # here, not at the top: `rockmech --help` loads no numpy for this

    return [float(v) for v in np.geomspace(lo, hi, count)]


def parse_levels(text: str) -> list[float]:
    """Parse intensity levels: ``"0.1,0.2,0.5"`` or a log range ``"0.1:3:20"`` (start:stop:n).

    Raises
    ------
    InputError
        Text that is neither form, a list with an empty item (``0.5,,1``: the position is
        named, never skipped), or a range whose fault is named (``_range_levels``); field
        ``scales``.
    """
    if ":" in text:
        return _range_levels(text)
    try:
        items = re.split(r"\s*,\s*|\s+", text.strip()) if text.strip() else []
        empty = [k for k, item in enumerate(items, start=1) if not item]
        if not empty:
            return [float(v) for v in items]
    except ValueError:
        raise InputError(
            f"expected a list like 0.1,0.2,0.5 or a log range start:stop:n, got {text!r}",
            "scales",
        ) from None
    # issue #25: "0.5,,1" was read as 0.5,1
    raise InputError(
        f"item {empty[0]} of {text!r} is empty; give one number between each two commas",
        "scales",
    )


@user_errors
@grouped
def ida(
    constants: Path = CONSTANTS_ARG,
    records: Optional[list[Path]] = typer.Argument(
        None, help="Record files (any supported format); or --record-spec."
    ),
    record_spec: Optional[Path] = typer.Option(
        None,
        "--record-spec",
        help="CSV (columns file, format, units, dt, channel, component) or JSON list of "
        "records, each with its own options; file names relative to the spec.",
    ),
    scales: str = typer.Option(
        ...,
        "--scales",
        help="Intensity levels: a list 0.25,0.5,1,2 or a log range start:stop:n (0.1:3:20).",
    ),
    measure: str = typer.Option(
        "scale",
        "--measure",
        metavar=choices(IM_MEASURES),
        help="Intensity measure: scale (factor on each record) or pga [g].",
    ),
    reading: RecordOptions = RECORD_OPTIONS,
    scaling: Scaling = SCALING,
    criterion: Optional[str] = criterion_opt("Overturning verdict: ratio (default) or exact."),
    scheduler: Optional[str] = typer.Option(
        None,
        "--scheduler",
        help="dask.distributed scheduler address (tcp://host:8786); default: run locally.",
    ),
    timeout: float = typer.Option(
        10.0, "--timeout", help="Seconds to wait for the Dask scheduler to answer [s]."
    ),
    jobs: Optional[int] = typer.Option(
        None, "--jobs", help="Threads of a local run, >= 1 (default: one per usable core)."
    ),
    progress: Optional[bool] = typer.Option(
        None, "--progress/--no-progress", help="Progress bar (default: on a terminal)."
    ),
    out: Optional[Path] = typer.Option(
        None, "--out", help="Folder for ida.json, ida.csv and ida.png (fragility curves)."
    ),
    peaks: bool = typer.Option(
        False,
        "--peaks",
        help=f"Also write every run's peak to {PEAKS_FILE} in --out (needs the parquet extra).",
    ),
    limits: Limits = LIMITS,
    as_json: bool = JSON_OPT,
) -> None:
    """Incremental dynamic analysis: overturned fraction per intensity and fragility fits."""
    # The IDA is loaded when the command runs (#38).
    from ..workflows.ida import run as workflow

    cf, motions, levels = _read_inputs(
        constants, records, record_spec, reading, scales, out, peaks, limits
    )
    run = functools.partial(
        workflow.run_ida,
        cf,
        motions,
        levels,
        measure=measure,
        sf=scaling.sf,
        building=scaling.building,
        criterion=criterion,
    )
    doc = _run_and_write(
        run,
        _RunsBar(progress),
        scheduler=scheduler,
        timeout=timeout,
        jobs=jobs,
        out=out,
        peaks=peaks,
        title=f"Fragility: {constants.name}",
    )
    skipped_notes(doc)
    if as_json:
        print_json(doc.to_dict())
        return
    _print_summary(doc, len(motions), len(levels), out, peaks)


class _RunsBar:
    """The IDA's progress bar on stderr: runs done of the runs in all.

    Parameters
    ----------
    progress : bool, optional
        Show the bar (``--progress/--no-progress``); ``None`` shows it on a terminal.

    Attributes
    ----------
    bar : rich.progress.Progress
        The bar, entered (``with bar.bar:``) while the runs run; transient.
    seen : list of int
        ``[runs done, runs in all]`` as last reported, for the note of a stopped run.
    """

    def __init__(self, progress: Optional[bool]) -> None:
        # rich is loaded when the command runs
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

        console = Console(stderr=True)
        show = console.is_terminal if progress is None else progress
        self.bar = Progress(
            "[progress.description]{task.description}",
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            console=console,
            disable=not show,
            transient=True,
        )
        self._task = self.bar.add_task("runs", total=None)
        self.seen = [0, 0]  # runs done, runs in all

    def advance(self, done: int, total: int) -> None:
        """Show ``done`` runs of ``total`` (the IDA's ``progress`` callback).

        Parameters
        ----------
        done : int
            Runs done so far.
        total : int
            Runs in all.
        """
        self.seen[:] = [done, total]
        self.bar.update(self._task, completed=done, total=total)


def _print_summary(
    doc: IdaDocument, n_records: int, n_levels: int, out: Optional[Path], peaks: bool
) -> None:
    """Print the IDA's summary: where and how long it ran, each mechanism's fragility, the files.

    Parameters
    ----------
    doc : IdaDocument
        The IDA's document (``ida.json``).
    n_records : int
        Records the IDA ran.
    n_levels : int
        Intensity levels the IDA ran.
    out : Path, optional
        The output folder the files were written to.
    peaks : bool
        Whether the peaks file was written too.
    """
    backend, err = doc.backend, doc.max_error_estimate
    where = (
        f"locally on {backend.jobs} threads"
        if backend.kind == "local"
        else f"on Dask at {backend.scheduler} ({backend.threads} worker threads)"
    )
    typer.echo(
        f"{doc.runs} runs ({n_records} records x {n_levels} levels x "
        f"{len(doc.mechanisms)} mechanisms) {where} in {doc.runtime_s:.2f} s "
        f"({backend.tasks} tasks, overhead {100 * backend.overhead_fraction:.1f} % of "
        f"task time); largest error estimate {'n/a' if err is None else f'{err:.1e}'}"
    )
    if backend.settings_differ:
        note(
            "note: the Dask workers run without rockmech's settings, which keep Dask's own "
            f"background work off the cores ({'; '.join(backend.settings_differ)}); "
            'see docs/cluster.md, "Dask\'s settings"'
        )
    unit = doc.intensity.units
    rows, notes = [], []
    for mech in doc.mechanisms:
        fit = mech.fragility
        rows.append([mech.id, g4(fit.median), g4(fit.beta)])
        if fit.note:
            notes.append(f"  {mech.id}: {fit.note}")
    for line in table(["mechanism", f"median [{unit}]", "beta [-]"], rows) + notes:
        typer.echo(line)
    if out is not None:
        typer.echo(
            f"wrote {out / 'ida.json'}, ida.csv, ida.png" + (f", {PEAKS_FILE}" if peaks else "")
        )


def _read_inputs(
    constants: Path,
    records: Optional[list[Path]],
    record_spec: Optional[Path],
    reading: RecordOptions,
    scales: str,
    out: Optional[Path],
    peaks: bool,
    limits: Limits,
) -> tuple[ConstantsFile, list[GroundMotion], list[float]]:
    """Check the IDA's options and read its constants, records and levels.

    Parameters
    ----------
    constants : Path
        The constants file (time-domain checked).
    records : list of Path, optional
        Record files, read with ``reading``.
    record_spec : Path, optional
        A record spec (``--record-spec``), each record with its own options.
    reading : RecordOptions
        How the record files are read (``--format``, ``--units``, ...).
    scales : str
        The ``--scales`` text (``parse_levels``).
    out : Path, optional
        The output folder, checked as a target.
    peaks : bool
        ``--peaks``: needs ``out`` and the parquet extra.
    limits : Limits
        The work limits, checked on the levels, the constants and the records.

    Returns
    -------
    cf : ConstantsFile
        The constants.
    motions : list of GroundMotion
        The records (files, then the spec's).
    levels : list of float
        The intensity levels, in the measure's unit.
    """
    # The readers of the IDA's inputs are loaded when the command runs (#38).
    from ..workflows import inputs

    levels = parse_levels(scales)
    limits.check(scales=len(levels))
    if out is not None:
        check_folder_target(out)
    if peaks:
        if out is None:
            fail(f"peaks: --peaks writes {PEAKS_FILE} into the --out folder; give --out DIR")
        require("pyarrow.parquet", "parquet", "for ida --peaks")
    cf = inputs.read_constants(constants, time_domain=True)
    motions = [reading.read(p) for p in records or []]
    specs = inputs.read_record_spec(record_spec) if record_spec else []
    motions += [spec.read(on_warning=record_warning) for spec in specs]
    if not motions:
        fail("records: give record files or --record-spec")
    limits.check(cf, scales=len(levels), record=record_size(motions), records=len(motions))
    return cf, motions, levels


def _run_and_write(
    run: Callable[..., IdaDocument],
    bar: _RunsBar,
    *,
    scheduler: Optional[str],
    timeout: float,
    jobs: Optional[int],
    out: Optional[Path],
    peaks: bool,
    title: str,
) -> IdaDocument:
    """Run the IDA under its progress bar and write its files; a stopped run writes nothing.

    Parameters
    ----------
    run : callable
        ``run_ida`` with its constants, records, levels and options bound; given here its
        ``scheduler``, ``progress``, ``timeout``, ``jobs`` and ``peaks``.
    bar : _RunsBar
        The progress bar.
    scheduler : str, optional
        The Dask scheduler's address; ``None`` runs locally.
    timeout : float
        Seconds to wait for the Dask scheduler [s], checked positive.
    jobs : int, optional
        Threads of a local run.
    out : Path, optional
        The output folder (``ida.json``, ``ida.csv``, ``ida.png``).
    peaks : bool
        Stream every run's peak into the output folder's stage.
    title : str
        The fragility figure's title.

    Returns
    -------
    IdaDocument
        The IDA's document.

    Raises
    ------
    typer.Exit
        Code 130 on Ctrl-C, after a note of the runs done.
    """
    # The solver's own check of a positive number.
    from ..core.model import check_positive

    # The writer of the IDA's files.
    from ..workflows import outputs

    try:
        # With --peaks the output folder's stage is open during the run (the peaks stream
        # into it); a stopped run leaves the folder as it was.
        with contextlib.ExitStack() as stack:
            folder = functools.partial(run_folder, on_note=out_note, command="ida")
            stage = stack.enter_context(folder(out)) if out is not None and peaks else None
            with bar.bar:
                doc = run(
                    scheduler=scheduler,
                    progress=bar.advance,
                    timeout=check_positive(timeout, "timeout"),
                    jobs=jobs,
                    peaks=None if stage is None else stage / PEAKS_FILE,
                )
            if out is not None:
                stage = stage or stack.enter_context(folder(out))
                outputs.write_ida(doc, stage, title=title)
    except KeyboardInterrupt:
        where = "its tasks on the cluster were cancelled" if scheduler else "no task is left"
        done = f"{bar.seen[0]} of {bar.seen[1]}" if bar.seen[1] else "0"
        note(f"interrupted: stopped after {done} runs; {where}; nothing written")
        raise typer.Exit(code=130) from None
    return doc
