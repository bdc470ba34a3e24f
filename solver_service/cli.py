"""The ``rockmech`` command line.

Every command validates its inputs up front; a bad argument exits with status 2 and a
one-line reason on stderr (``error: <field>: <what is wrong>``), and so does a missing
optional extra (the message gives its ``pip install 'rockmech[<extra>]'`` line). Results go
to stdout, warnings, notes and progress to stderr. With ``--json`` a command prints exactly
one JSON document to stdout. SI units throughout, except where an option name says
otherwise (``--a-p-g`` is in g); every ``--help`` shows the units in brackets.
"""

from __future__ import annotations

import contextlib
import difflib
import functools
import importlib
import inspect
import json
import subprocess
import sys
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Iterator, NoReturn, Optional, TypeVar, get_type_hints

import typer
from typer.core import TyperGroup, TyperOption

from cad_maths.mechanisms.build import MechanismFailure
from shared_schema.atomic import remove_stale_temps
from shared_schema.errors import RockmechError
from shared_schema.extras import MissingExtra, extra_for, require
from shared_schema.io import save_constants, stamped
from shared_schema.rules import (
    CRITERIA,
    LENGTH_UNITS,
    PULSE_SHAPES,
    RECORD_FORMATS,
    RECORD_UNITS,
    SF_METHODS,
    printable,
)
from shared_schema.version import __version__

from .core.envelope import LIBRARY_OMEGA, LIBRARY_PATH, build_library, user_library_path
from .core.jit import PATHS, kernel_status
from .core.model import check_positive
from .core.precompile import build as build_kernels
from .core.records import GroundMotion
from .demo import copy_examples, run_demo
from .ida import IM_MEASURES, PEAKS_FILE, parse_levels, run_ida
from .report.html import build_report, input_source, write_report
from .workflows.assess import check_doc, check_multiples, read_site
from .workflows.documents import (
    boundary_doc,
    frequency_grid,
    history_doc,
    log_grid,
    pick_mechanism,
    record_analysis,
    record_pulse_doc,
    solve_pulse,
    time_domain_mechanisms,
)
from .workflows.inputs import (
    constants_from_files,
    constants_keep_going,
    read_constants,
    read_record,
    read_record_spec,
)
from .workflows.limits import (
    CLI_BUDGET_S,
    DEFAULT_LIMITS,
    TimeLimitExceeded,
    check_run,
)
from .workflows.limits import time_limit as run_time_limit
from .workflows.outputs import finite_json, write_envelope, write_history, write_ida, write_record
from .workflows.rundir import check_file_target, check_folder_target, os_reason, run_folder
from .workflows.scaling import Building
from .workflows.tables import checked_table
from .workflows.units import stamp

# typer re-exports click's exceptions, and newer typer vendors click (``typer._click``): the
# classes are taken from the module typer's own BadParameter comes from.
_CLICK = importlib.import_module(typer.BadParameter.__module__)
#: Raised by click for a bare group call that shows the help: not an error to reword.
_HELP_ERROR: Any = getattr(_CLICK, "NoArgsIsHelpError", ())


class _UsageError(_CLICK.ClickException):  # type: ignore[misc,name-defined]
    """A usage error shown as rockmech shows its own: ``error: <option>: <problem>``, exit 2."""

    exit_code = 2

    def show(self, file: Any = None) -> None:
        """Print the one line on stderr."""
        typer.echo(f"error: {self.message}", err=True)


def _param_name(param: Any) -> str:
    """How an error names a parameter: an option as typed (``--p-eq``), an argument by name."""
    if isinstance(param, TyperOption):
        return str(max(param.opts, key=len))
    return str(param.name or param.human_readable_name)


def _usage_line(exc: Any) -> str:
    """One line for click's usage error ``exc``: the option or argument, the problem, a hint."""
    ctx = exc.ctx
    see = f"; see '{ctx.command_path} --help'" if ctx is not None else ""
    problem = str(exc.message).rstrip(".")
    problem = problem[:1].lower() + problem[1:]
    field = ctx.command_path if ctx is not None else "rockmech"
    if isinstance(exc, _CLICK.NoSuchOption):
        field, problem = exc.option_name, "no such option"
        if exc.possibilities:
            problem += f" (did you mean {' or '.join(exc.possibilities)}?)"
    elif isinstance(exc, _CLICK.BadOptionUsage):
        field = exc.option_name
        if "requires an argument" in problem:
            problem = "needs a value"
    elif isinstance(exc, _CLICK.BadParameter):
        if exc.param is not None:
            field = _param_name(exc.param)
        elif exc.param_hint:
            field = str(exc.param_hint)
        if isinstance(exc, _CLICK.MissingParameter):
            kind = exc.param.param_type_name if exc.param is not None else exc.param_type
            problem = f"missing {kind or 'value'}"
    return f"{field}: {problem}{see}"


class _Commands(TyperGroup):
    """The ``rockmech`` command group: click's usage errors as one line, like our own."""

    def make_context(
        self, info_name: Optional[str], args: list[str], parent: Any = None, **extra: Any
    ) -> Any:
        """Parse the group's own options; a usage error becomes one line."""
        try:
            return super().make_context(info_name, args, parent, **extra)
        except _HELP_ERROR:
            raise
        except _CLICK.UsageError as exc:
            raise _UsageError(_usage_line(exc)) from None

    def resolve_command(self, ctx: Any, args: list[str]) -> Any:
        """Find the command; an unknown one is named with the closest commands."""
        name = args[0] if args else ""
        if name and not name.startswith("-") and self.get_command(ctx, name) is None:
            close = difflib.get_close_matches(name, self.list_commands(ctx))
            hint = f" (did you mean {' or '.join(close)}?)" if close else ""
            raise _UsageError(
                f"command: no such command {name!r}{hint}; see '{ctx.command_path} --help'"
            )
        return super().resolve_command(ctx, args)

    def invoke(self, ctx: Any) -> Any:
        """Run a command; a usage error in its arguments becomes one line."""
        try:
            return super().invoke(ctx)
        except _HELP_ERROR:
            raise
        except _CLICK.UsageError as exc:
            raise _UsageError(_usage_line(exc)) from None


app = typer.Typer(
    cls=_Commands,
    name="rockmech",
    help="Rocking collapse mechanisms of masonry: exact rocking solver and tools (SI units).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    # Plain help: rich markup would read the units in brackets ("[rad/s]") as tags and drop them.
    rich_markup_mode=None,
)

F = TypeVar("F", bound=Callable[..., Any])
#: Widest terminal table [characters].
TABLE_WIDTH = 100


def _fail(message: str) -> NoReturn:
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code=2)


def _note(message: str) -> None:
    """Print a warning or note on stderr, so that stdout holds only results."""
    typer.echo(message, err=True)


def _out_note(message: str) -> None:
    """Print a note about the output folder (a swap ended for a killed run, a file kept)."""
    _note(f"note: {message}")


def _skipped_notes(doc: dict[str, Any]) -> None:
    """Print a warning for each mechanism an analysis left out (``doc["skipped"]``)."""
    for skip in doc.get("skipped", []):
        _note(f"warning: {skip['mechanism']} skipped: {skip['reason']}")


def _mechanism_warning(mech_id: str, note: str) -> None:
    """Print a mechanism's warning, naming it once (a note may already start with its id)."""
    named = note.startswith((f"{mech_id}.", f"{mech_id}:", f"{mech_id} "))
    _note(f"warning: {note}" if named else f"warning: {mech_id}: {note}")


def _user_errors(fn: F) -> F:
    """Turn rockmech's own errors, write errors and missing extras into one line and exit 2."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            _clean_stale_temps(kwargs)
            with run_time_limit(None if kwargs.get("no_limits") else kwargs.get("time_limit")):
                return fn(*args, **kwargs)
        except TimeLimitExceeded as exc:
            _fail(str(exc))
        except RockmechError as exc:
            _fail(str(exc))
        except OSError as exc:
            # Read-only folder, full disk, missing permission: one line, not a traceback.
            where = f"{exc.filename}: " if exc.filename else ""
            _fail(f"out: {where}{os_reason(exc)}")
        except ModuleNotFoundError as exc:
            # A heavy module imported without ``require``: still name the extra.
            name = exc.name or "a module"
            extra = extra_for(name)
            if extra is not None:
                _fail(str(MissingExtra(name, extra)))
            _fail(f"{name} is not installed; reinstall rockmech (pip install rockmech)")

    return wrapper  # type: ignore[return-value]


def _clean_stale_temps(kwargs: dict[str, Any]) -> None:
    """Remove temporary files of killed runs beside this run's outputs, with a note each."""
    for key in ("out", "output"):
        target = kwargs.get(key)
        if isinstance(target, Path):
            for folder in dict.fromkeys((target.parent, target)):
                for path in remove_stale_temps(folder):
                    _note(f"note: removed {path}, a temporary file left by a run that was killed")


@contextlib.contextmanager
def _status(message: str) -> Iterator[None]:
    """Show a spinner with ``message`` on stderr while the block runs, on a terminal only."""
    # rich is imported here: only a terminal run draws a spinner.
    from rich.console import Console
    from rich.markup import escape

    console = Console(stderr=True)
    if not console.is_terminal:
        yield
        return
    # A record's or mechanism's name is shown as written, never read as rich markup (#25).
    with console.status(escape(printable(message))):
        yield


def _record_warning(note: str) -> None:
    """Print a record's warning (``read_record``'s ``on_warning``) on stderr."""
    _note(f"warning: record: {note}")


def _choices(values: Iterable[str]) -> str:
    """Return the ``--help`` placeholder of a word from a vocabulary: ``[sine|cosine]``.

    The vocabularies live in ``shared_schema.rules``. A value outside one reaches the domain
    check, so the command line and the REST service give the same one-line message
    (``error: shape: must be one of [...]``); a test pins that.
    """
    return "[" + "|".join(values) + "]"


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    """Lines of an aligned text table at most ``TABLE_WIDTH`` wide.

    The first column (names) is left-aligned and, only if the table would be too wide,
    shortened with ``...``; the other columns are right-aligned. A control character in a
    cell is printed as its escape (``rules.printable``), so no name breaks a row (#25).
    """
    headers = [printable(h) for h in headers]
    rows = [[printable(c) for c in r] for r in rows]
    widths = [max([len(h)] + [len(r[i]) for r in rows]) for i, h in enumerate(headers)]
    spare = TABLE_WIDTH - (sum(widths) + 2 * (len(widths) - 1))
    if spare < 0:
        widths[0] = max(len(headers[0]), widths[0] + spare)

    def fit(text: str, width: int) -> str:
        return text if len(text) <= width else text[: max(width - 3, 1)] + "..."

    def line(cells: Sequence[str]) -> str:
        out = [fit(cells[0], widths[0]).ljust(widths[0])]
        out += [c.rjust(w) for c, w in zip(cells[1:], widths[1:])]
        return "  ".join(out).rstrip()

    return [line(headers)] + [line(r) for r in rows]


def _g4(value: Optional[float]) -> str:
    """Format a number to 4 significant figures (``-`` for none)."""
    return "-" if value is None else f"{value:.4g}"


def _foreign_packages() -> list[str]:
    """Name rockmech's top-level packages loaded from outside its install (a name clash)."""
    homes = {
        name: Path(str(importlib.import_module(name).__file__)).resolve().parent.parent
        for name in ("rockmech", "shared_schema", "cad_maths", "solver_service", "rhino_plugin")
    }
    return [
        f"warning: {name} is loaded from {home}, not from rockmech's install "
        f"({homes['rockmech']}): another package or file has that name (docs/install.md)"
        for name, home in homes.items()
        if home != homes["rockmech"]
    ]


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"rockmech {__version__}")
        typer.echo(kernel_status().describe())
        for line in _foreign_packages():
            _note(line)
        raise typer.Exit()


@app.callback()
def _main(
    version: bool = typer.Option(
        False,
        "--version",
        callback=_print_version,
        is_eager=True,
        help="Print the version, whether the compiled kernels are active, and exit.",
    ),
) -> None:
    """Rocking collapse mechanisms of masonry: exact rocking solver and tools (SI units)."""


def _print_json(doc: Any) -> None:

    typer.echo(json.dumps(finite_json(doc), indent=2, allow_nan=False))


def _fmt_time(value: Optional[float]) -> str:
    return "-" if value is None else f"{value:.4f} s"


# Vocabularies of the choice options: one home, shared_schema.rules.
_SHAPES = _choices(PULSE_SHAPES)
_CRITERIA = _choices(CRITERIA)


# Options that several commands share. An option is defined once here; a set of options that
# commands take together is an option group: a dataclass of their values and one ``_Group``
# of their typer options (CONTRIBUTING.md, "A CLI option").
_JSON_OPT = typer.Option(False, "--json", help="Print one JSON document.")
_CONSTANTS_ARG = typer.Argument(..., help="Kinematic-constants JSON file.")
_CONSTANTS_OR_TABLE_ARG = typer.Argument(
    ..., help="Kinematic-constants JSON file or constants table (.csv, .xlsx)."
)
_CONSTANTS_OUTPUT_OPT = typer.Option(
    ..., "-o", "--output", help="Kinematic-constants JSON to write."
)
_SCENE_ARG = typer.Argument(..., help="Rhino .3dm file, or a scan mesh .ply/.obj/.stl/.off.")
_MESH_UNITS_OPT = typer.Option(
    None,
    "--units",
    metavar=_choices(LENGTH_UNITS),
    help="Length unit of a scan mesh (.ply, .obj, .stl, .off; required there).",
)
_RECORD_ARG = typer.Argument(
    ...,
    help="Record file: PEER AT2, ESM/ITACA, K-NET/KiK-net, COSMOS V2, CSMIP/DMG V2, GeoNet "
    "V2A, two columns (t, a), one column (with --dt) or CSV.",
)


def _criterion_opt(help_text: str) -> Any:
    """Return the ``--criterion`` option with this command's note on its default."""
    return typer.Option(None, "--criterion", metavar=_CRITERIA, help=help_text)


class _Group:
    """An option group: options several commands take together, and their dataclass.

    A command takes a group as one parameter whose default is the group
    (``reading: RecordOptions = _RECORD_OPTIONS``); ``_grouped`` puts the group's options in its
    place in the signature typer reads (so ``--help`` lists them there, in this order) and
    hands the command one dataclass instance of their values.

    Parameters
    ----------
    cls : type
        The dataclass; its fields are named as the options' parameters.
    options : dict
        ``typer.Option`` of each field, in ``--help`` order.
    defaults : dict, optional
        Values of the fields a narrower group (``only``) leaves out; default: each option's.
    """

    def __init__(
        self, cls: type, options: dict[str, Any], defaults: Optional[dict[str, Any]] = None
    ) -> None:
        self.cls, self.options = cls, options
        self.defaults = {k: v.default for k, v in options.items()} if defaults is None else defaults

    def only(self, *names: str) -> Any:
        """Return the group with only the options ``names``; the others keep their defaults."""
        return _Group(self.cls, {k: self.options[k] for k in names}, self.defaults)

    def but(self, **options: Any) -> Any:
        """Return the group with some options defined otherwise (another help text)."""
        return _Group(self.cls, {**self.options, **options}, self.defaults)

    def parameters(self) -> list[inspect.Parameter]:
        """Return the group's options as parameters of a command's signature."""
        hints = get_type_hints(self.cls)
        kind = inspect.Parameter.POSITIONAL_OR_KEYWORD
        return [
            inspect.Parameter(name, kind, default=option, annotation=hints[name])
            for name, option in self.options.items()
        ]

    def pack(self, kwargs: dict[str, Any]) -> Any:
        """Take the group's values out of a command's ``kwargs``; return its dataclass."""
        values = {name: kwargs.pop(name) for name in self.options}
        return self.cls(**{**self.defaults, **values})


def _grouped(fn: F) -> F:
    """Let a command take option groups (``_Group``): typer sees each group's options."""
    signature = inspect.signature(fn)
    groups = {
        name: p.default for name, p in signature.parameters.items() if isinstance(p.default, _Group)
    }
    parameters: list[inspect.Parameter] = []
    for p in signature.parameters.values():
        parameters += groups[p.name].parameters() if p.name in groups else [p]

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        for name, group in groups.items():
            kwargs[name] = group.pack(kwargs)
        return fn(*args, **kwargs)

    # Signature refuses a name twice: a group's option named as a command's own parameter.
    wrapper.__signature__ = signature.replace(parameters=parameters)  # type: ignore[attr-defined]
    return wrapper  # type: ignore[return-value]


@dataclass(frozen=True)
class RecordOptions:
    """How to read a record file: the options of every command that reads one."""

    units: Optional[str]
    record_format: Optional[str]
    dt: Optional[float]
    channel: Optional[str]
    component: Optional[str]

    def read(self, path: Path) -> GroundMotion:
        """Read a record as every command does, with its warnings on stderr."""
        return read_record(
            path,
            self.record_format,
            self.units,
            self.dt,
            self.channel,
            self.component,
            on_warning=_record_warning,
        )


_RECORD_OPTIONS: Any = _Group(
    RecordOptions,
    {
        "units": typer.Option(
            None,
            "--units",
            metavar=_choices(RECORD_UNITS),
            help="Acceleration units; files that state their own (AT2, the strong-motion "
            "formats, a CSV column 'acc [g]') are read in them, two-column files default to g, "
            "other files need it.",
        ),
        "record_format": typer.Option(
            None,
            "--format",
            metavar=_choices(RECORD_FORMATS),
            help="Record format (default: detected from the content).",
        ),
        "dt": typer.Option(None, "--dt", help="Time step [s] of a record without a time column."),
        "channel": typer.Option(
            None, "--channel", help="Channel number in a file with several (DMG V2, GeoNet V2A)."
        ),
        "component": typer.Option(
            None, "--component", help="Component of a file with several, as its header names it."
        ),
    },
)


@dataclass(frozen=True)
class Scaling:
    """The scale factor up the structure (history, ida, report)."""

    sf: str
    building_height: Optional[float]
    soil_factor: float
    element_period: float

    @property
    def building(self) -> Building:
        """The building the scale factor is taken in."""
        return Building(self.building_height, self.soil_factor, self.element_period)


_SCALING: Any = _Group(
    Scaling,
    {
        "sf": typer.Option(
            "none",
            "--sf",
            metavar=_choices(SF_METHODS),
            help="Scale factor up the structure for mechanisms with amplification data: none; "
            "eq28 (from the record's 5 % spectrum at T_n = 1/f_n); ec8 (EN 1998-1 §4.3.5.2, "
            "needs --building-height); nzs (NZS 1170.5 C_Hi, needs --building-height).",
        ),
        "building_height": typer.Option(
            None, "--building-height", help="Height of the building H = h_n [m] (ec8, nzs)."
        ),
        "soil_factor": typer.Option(1.0, "--soil-factor", help="EC8 soil factor S [-]."),
        "element_period": typer.Option(
            0.0, "--element-period", help="EC8 period of the element T_a [s]; 0 = rigid."
        ),
    },
)


@dataclass(frozen=True)
class Limits:
    """The size and time limits of a run (the time limit is applied by ``_user_errors``)."""

    no_limits: bool
    time_limit: float

    def check(self, *args: Any, **kwargs: Any) -> None:
        """Refuse a run above the size limits (``workflows.limits.check_run``) unless lifted."""
        if not self.no_limits:
            check_run(*args, **kwargs)


_LIMITS: Any = _Group(
    Limits,
    {
        "no_limits": typer.Option(
            False,
            "--no-limits",
            help=f"Lift the size limits, the REST service's: {DEFAULT_LIMITS['max_samples']} "
            f"record samples, periods or frequencies, {DEFAULT_LIMITS['max_scales']} scale "
            f"factors, {DEFAULT_LIMITS['max_mechanisms']} mechanisms, work that cannot finish "
            f"in {CLI_BUDGET_S:g} s of work, and the time limit.",
        ),
        "time_limit": typer.Option(
            CLI_BUDGET_S,
            "--time-limit",
            metavar="S",
            help="Stop a run that takes longer than S seconds (exit status 2, outputs left as "
            "they were); work that cannot finish in S seconds is refused up front. The REST "
            "service's is ROCKMECH_COMPUTE_TIMEOUT_S.",
        ),
    },
)


@dataclass(frozen=True)
class FrequencyGrid:
    """The pulse frequencies of the envelopes (envelope, report)."""

    f_min: float
    f_max: float
    n: int

    def grid(self) -> Any:
        """Return the log-spaced frequencies [Hz] (checked)."""
        return frequency_grid(self.f_min, self.f_max, self.n)

    def work(self, exact: bool) -> tuple[float, float, int, bool]:
        """Return the envelope's size for ``Limits.check`` (``envelope=``)."""
        return self.f_min, self.f_max, self.n, exact


_FREQUENCIES: Any = _Group(
    FrequencyGrid,
    {
        "f_min": typer.Option(0.1, "--f-min", help="Lowest pulse frequency [Hz]."),
        "f_max": typer.Option(10.0, "--f-max", help="Highest pulse frequency [Hz]."),
        "n": typer.Option(200, "--n", help="Number of log-spaced frequencies."),
    },
)


@dataclass(frozen=True)
class EnvelopeMethod:
    """``--fast`` / ``--exact``: how the envelopes are computed (envelope, report)."""

    fast: bool
    exact: bool

    def name(self) -> str:
        """Return the envelope method: exact unless --fast."""
        if self.fast and self.exact:
            _fail("fast: give --fast or --exact, not both")
        return "library" if self.fast else "exact"


_ENVELOPE_METHOD: Any = _Group(
    EnvelopeMethod,
    {
        "fast": typer.Option(
            False,
            "--fast",
            help="Fast mode: envelopes interpolated from the library (exact where it cannot "
            "interpolate safely): never above the exact values, at most 5 % below; band edges "
            "within a factor 1.05 in frequency (docs/envelopes.md).",
        ),
        "exact": typer.Option(
            False,
            "--exact",
            help="Exact envelopes at every frequency (the default; kept for scripts).",
        ),
    },
)


@app.command()
@_user_errors
def pulse(
    p_eq: Optional[float] = typer.Option(
        None, "--p-eq", help="Frequency parameter p_eq [rad/s] (or --constants)."
    ),
    lam: Optional[float] = typer.Option(
        None, "--lam", help="Static load multiplier lambda [-] (or --constants)."
    ),
    a_p_g: float = typer.Option(
        ...,
        "--a-p-g",
        help="Signed pulse amplitude [g]; > 0 first pushes towards negative "
        "rotation (Housner's convention), < 0 first opens the mechanism.",
    ),
    f_p: float = typer.Option(..., "--f-p", help="Pulse frequency [Hz]."),
    eta: Optional[float] = typer.Option(
        None, "--eta", help="Coefficient of restitution [-] (<= 0 one-sided)."
    ),
    one_sided: bool = typer.Option(False, "--one-sided", help="One-sided rocking."),
    phi_ov: Optional[float] = typer.Option(
        None, "--phi-ov", help="Overturning rotation [rad]; defaults to lambda."
    ),
    constants: Optional[Path] = typer.Option(
        None,
        "--constants",
        help="Kinematic-constants JSON: run one of its mechanisms (both sides, each impact "
        "direction's eta) instead of --p-eq, --lam, --eta, --phi-ov, --one-sided.",
    ),
    mechanism: Optional[str] = typer.Option(
        None, "--mechanism", help="Mechanism id in --constants (default: the first)."
    ),
    shape: str = typer.Option("sine", "--shape", metavar=_SHAPES, help="Pulse shape."),
    criterion: Optional[str] = _criterion_opt(
        "Overturning verdict: exact (default for pulses) or ratio."
    ),
    as_json: bool = _JSON_OPT,
) -> None:
    """Response of one mechanism to a one-cycle sine or cosine acceleration pulse."""
    request: dict[str, Any] = {"a_p_g": a_p_g, "f_p": f_p, "shape": shape}
    short = {"p_eq": p_eq, "lam": lam, "eta": eta, "phi_ov": phi_ov}
    request.update({k: v for k, v in short.items() if v is not None})
    request.update({"one_sided": True} if one_sided else {})
    request.update({"criterion": criterion} if criterion is not None else {})
    if constants is not None:
        request["mechanism"] = pick_mechanism(read_constants(constants), mechanism)
    elif mechanism is not None:
        _fail("mechanism: needs --constants (the file that holds it)")
    doc = solve_pulse(request)
    if as_json:
        _print_json(doc)
        return
    verdict = "OVERTURNS" if doc["overturned"] else "survives"
    name = f"{doc['input']['mechanism']}: " if "mechanism" in doc["input"] else ""
    typer.echo(
        f"{name}Pulse {shape} a_p = {a_p_g:g} g, f_p = {f_p:g} Hz "
        f"(Omega = {doc['input']['omega_ratio']:.4g}, A = {doc['input']['amplitude_ratio']:.4g}):"
        f" {verdict} [{doc['criterion']} criterion]"
    )
    typer.echo(
        f"  peak |phi|/phi_ov = {doc['peak_ratio']:.6f} at {doc['t_peak']:.4f} s "
        f"(error estimate {doc['error_estimate']:.1e}); impacts: {doc['n_impacts']}; "
        f"t_overturn: {_fmt_time(doc['t_overturn'])}"
    )
    for note in doc["warnings"]:
        _note(f"warning: {note}")


def _record_size(motions: Sequence[GroundMotion]) -> tuple[int, float]:
    """Return (samples [-], time step [s]) bounding the work of each record in ``motions``."""
    return max(len(m.accel.acc) for m in motions), max(m.dt for m in motions)


def _history_options(
    scaling: Scaling, criterion: Optional[str], at_height: Optional[float]
) -> dict[str, Any]:
    """Return the options of ``write_history`` / ``history_doc`` (history, report)."""
    return {
        "sf": scaling.sf,
        "building": scaling.building,
        "criterion": criterion,
        "at_height": at_height,
    }


#: Context of a command that takes several values after one ``--scale`` (``_scales``).
_MORE_SCALES = {"allow_extra_args": True, "ignore_unknown_options": True}


def _scales(first: list[float], extra: list[str]) -> list[float]:
    """Collect the --scale values, also those typed after the first (``--scale 0.5 1 2``)."""
    scales = list(first)
    for token in extra:
        try:
            scales.append(float(token))
        except ValueError:
            _fail(f"unexpected argument {token!r}")
    return scales


@app.command(context_settings=_MORE_SCALES)
@_user_errors
@_grouped
def history(
    ctx: typer.Context,
    constants: Path = _CONSTANTS_OR_TABLE_ARG,
    record: Path = _RECORD_ARG,
    scale: list[float] = typer.Option(
        [1.0], "--scale", help="Scale factors on the record, e.g. --scale 0.5 1 2."
    ),
    reading: RecordOptions = _RECORD_OPTIONS,
    scaling: Scaling = _SCALING,
    at_height: Optional[float] = typer.Option(
        None,
        "--at-height",
        help="Also report the peak displacement [m] of a point this far [m] above each "
        "mechanism's rotation axis (to compare with shake-table tests).",
    ),
    criterion: Optional[str] = _criterion_opt(
        "Overturning verdict: ratio (default for records) or exact."
    ),
    out: Optional[Path] = typer.Option(
        None,
        "--out",
        help="Folder for history.json, history.png (phi/phi_ov per scale) and "
        "history_record.png (record, largest pulse and spectrum).",
    ),
    limits: Limits = _LIMITS,
    as_json: bool = _JSON_OPT,
) -> None:
    """Time history of every mechanism in CONSTANTS under RECORD at each scale factor."""
    scales = _scales(scale, ctx.args)
    limits.check(scales=len(scales))
    if out is not None:
        check_folder_target(out)
    cf = read_constants(constants, time_domain=True)
    motion = reading.read(record)
    limits.check(cf, scales=len(scales), record=_record_size([motion]))
    options = _history_options(scaling, criterion, at_height)
    runs = len(scales) * len(cf.mechanisms)
    with _status(f"history: {runs} runs of {motion.name}"):
        if out is not None:
            with run_folder(out, on_note=_out_note) as tmp:
                doc = write_history(cf, motion, scales, tmp, **options)
        else:
            doc = history_doc(cf, motion, scales, **options)
    if as_json:
        _print_json(doc)
        return
    typer.echo(
        f"{motion.name}: PGA {motion.pga_g:.3f} g, dt {motion.dt:g} s, "
        f"{motion.duration:.2f} s; criterion: {doc['criterion']}"
    )
    for mech_id, info in doc.get("scale_factors", {}).items():
        typer.echo(f"  SF {mech_id}: {info['value']:.4f} = {info['formula']}")
    disp = at_height is not None
    headers = ["mechanism", "scale", "peak |phi|/phi_ov", "overturned", "t_ov [s]", "impacts"]
    headers += ["error"] + (["u_peak [m]"] if disp else [])
    rows = []
    for row in doc["results"]:
        cells = [
            str(row["mechanism"]),
            _g4(row["scale"]),
            _g4(row["peak_ratio"]),
            "yes" if row["overturned"] else "no",
            _g4(row["t_overturn"]),
            str(row["n_impacts"]),
            f"{row['error_estimate']:.1e}",
        ]
        rows.append(cells + ([_g4(row["peak_displacement_m"])] if disp else []))
    for line in _table(headers, rows):
        typer.echo(line)
    for mech_id, notes in doc.get("warnings", {}).items():
        for note in notes:
            _mechanism_warning(mech_id, note)
    for note in doc.get("option_warnings", []):
        _note(f"warning: {note}")
    _skipped_notes(doc)
    if out is not None:
        typer.echo(f"wrote {out / 'history.json'}, history.png, history_record.png")


@app.command("record")
@_user_errors
@_grouped
def record_info(
    record: Path = _RECORD_ARG,
    reading: RecordOptions = _RECORD_OPTIONS,
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
    limits: Limits = _LIMITS,
    as_json: bool = _JSON_OPT,
) -> None:
    """Describe a record: metadata, largest sine pulses and exact response spectrum."""
    limits.check(periods=n)
    if out is not None:
        check_folder_target(out)
    motion = reading.read(record)
    limits.check(record=_record_size([motion]))
    periods = log_grid(t_min, t_max, n, names=("t_min", "t_max"))
    with _status(f"record: spectrum at {len(periods)} periods and pulses"):
        doc, spectrum, found = record_analysis(
            motion, periods, zeta, n_pulses=pulses, f_min=f_min, f_max=f_max
        )
    if out is not None:
        with run_folder(out, on_note=_out_note) as tmp:
            write_record(motion, doc, spectrum, found, tmp)
    if as_json:
        _print_json(doc)
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
    rows = [[f"{p['a_p_g']:+.4g}", _g4(p["f_p_hz"]), _g4(p["t_start_s"])] for p in doc["pulses"]]
    for line in _table(["a_p [g]", "f_p [Hz]", "t_start [s]"], rows):
        typer.echo(line)
    spec = doc["spectrum"]
    k = max(range(len(spec["psa_g"])), key=lambda i: spec["psa_g"][i])
    typer.echo(
        f"spectrum ({100 * zeta:g} %): peak PSA {spec['psa_g'][k]:.4f} g at "
        f"T = {spec['periods_s'][k]:.3f} s (computed in {spec['runtime_s'] * 1e3:.1f} ms)"
    )
    if out is not None:
        typer.echo(f"wrote {out / 'record.json'}, record.png")


@app.command()
@_user_errors
@_grouped
def ida(
    constants: Path = _CONSTANTS_ARG,
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
    im: str = typer.Option(
        "scale",
        "--im",
        metavar=_choices(IM_MEASURES),
        help="Intensity measure: scale (factor on each record) or pga [g].",
    ),
    reading: RecordOptions = _RECORD_OPTIONS,
    scaling: Scaling = _SCALING,
    criterion: Optional[str] = _criterion_opt("Overturning verdict: ratio (default) or exact."),
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
    limits: Limits = _LIMITS,
    as_json: bool = _JSON_OPT,
) -> None:
    """Incremental dynamic analysis: overturned fraction per intensity and fragility fits."""
    # long: the progress bar and the summary table
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

    levels = parse_levels(scales)
    limits.check(scales=len(levels))
    if out is not None:
        check_folder_target(out)
    if peaks:
        if out is None:
            _fail(f"peaks: --peaks writes {PEAKS_FILE} into the --out folder; give --out DIR")
        require("pyarrow.parquet", "parquet", "for ida --peaks")
    cf = read_constants(constants, time_domain=True)
    motions = [reading.read(p) for p in records or []]
    specs = read_record_spec(record_spec) if record_spec else []
    motions += [spec.read(on_warning=_record_warning) for spec in specs]
    if not motions:
        _fail("records: give record files or --record-spec")
    limits.check(cf, scales=len(levels), record=_record_size(motions), records=len(motions))
    console = Console(stderr=True)
    show = console.is_terminal if progress is None else progress
    bar = Progress(
        "[progress.description]{task.description}",
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=console,
        disable=not show,
        transient=True,
    )
    task = bar.add_task("runs", total=None)
    seen = [0, 0]  # runs done, runs in all

    def advance(done: int, total: int) -> None:
        seen[:] = [done, total]
        bar.update(task, completed=done, total=total)

    try:
        # With --peaks the output folder's stage is open during the run (the peaks stream
        # into it); a stopped run leaves the folder as it was.
        with contextlib.ExitStack() as stack:
            folder = functools.partial(run_folder, on_note=_out_note)
            stage = stack.enter_context(folder(out)) if out is not None and peaks else None
            with bar:
                doc = run_ida(
                    cf,
                    motions,
                    levels,
                    im=im,
                    sf=scaling.sf,
                    building=scaling.building,
                    criterion=criterion,
                    scheduler=scheduler,
                    progress=advance,
                    timeout=check_positive(timeout, "timeout"),
                    jobs=jobs,
                    peaks=None if stage is None else stage / PEAKS_FILE,
                )
            if out is not None:
                stage = stage or stack.enter_context(folder(out))
                write_ida(doc, stage, title=f"Fragility: {constants.name}")
    except KeyboardInterrupt:
        where = "its tasks on the cluster were cancelled" if scheduler else "no task is left"
        done = f"{seen[0]} of {seen[1]}" if seen[1] else "0"
        _note(f"interrupted: stopped after {done} runs; {where}; nothing written")
        raise typer.Exit(code=130) from None
    _skipped_notes(doc)
    if as_json:
        _print_json(stamp(doc, "ida"))
        return
    backend = doc["backend"]
    where = (
        f"locally on {backend['jobs']} threads"
        if backend["kind"] == "local"
        else f"on Dask at {backend['scheduler']} ({backend['threads']} worker threads)"
    )
    typer.echo(
        f"{doc['runs']} runs ({len(motions)} records x {len(levels)} levels x "
        f"{len(doc['mechanisms'])} mechanisms) {where} in {doc['runtime_s']:.2f} s "
        f"({backend['tasks']} tasks, overhead {100 * backend['overhead_fraction']:.1f} % of "
        f"task time); largest error estimate {doc['max_error_estimate']:.1e}"
    )
    if backend.get("settings_differ"):
        _note(
            "note: the Dask workers run without rockmech's settings, which keep Dask's own "
            f"background work off the cores ({'; '.join(backend['settings_differ'])}); "
            'see docs/cluster.md, "Dask\'s settings"'
        )
    unit = doc["intensity"]["units"]
    rows, notes = [], []
    for mech in doc["mechanisms"]:
        fit = mech["fragility"]
        rows.append([str(mech["id"]), _g4(fit.get("median")), _g4(fit.get("beta"))])
        if "note" in fit:
            notes.append(f"  {mech['id']}: {fit['note']}")
    for line in _table(["mechanism", f"median [{unit}]", "beta [-]"], rows) + notes:
        typer.echo(line)
    if out is not None:
        typer.echo(
            f"wrote {out / 'ida.json'}, ida.csv, ida.png" + (f", {PEAKS_FILE}" if peaks else "")
        )


@app.command()
@_user_errors
def constants(
    scene: Path = _SCENE_ARG,
    spec: Path = typer.Argument(..., help="Mechanism spec (JSON)."),
    output: Path = _CONSTANTS_OUTPUT_OPT,
    as_json: bool = typer.Option(False, "--json", help="Also print the constants JSON."),
    keep_going: bool = typer.Option(
        False,
        "--keep-going",
        help=(
            "Write the mechanisms that succeed and list the ones that fail (exit status 1 "
            "when any failed). Without it, any failure writes nothing and lists every failure."
        ),
    ),
    units: Optional[str] = _MESH_UNITS_OPT,
) -> None:
    """Kinematic constants of every mechanism in SPEC from the solids of SCENE."""
    check_file_target(output, "output")
    failures: list[MechanismFailure] = []
    with _status(f"constants: reading {scene.name}"):
        if keep_going:
            cf, failures = constants_keep_going(scene, spec, units)
        else:
            cf = constants_from_files(scene, spec, units)
    save_constants(output, cf)
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
        for note in notes if isinstance(notes, list) else []:
            _mechanism_warning(m.id, str(note))
    if as_json:
        _print_json(json.loads(stamped(cf).model_dump_json(exclude_none=True)))
        if failures:
            raise typer.Exit(code=1)
        return
    typer.echo(f"wrote {output}")
    rows = []
    for m in cf.mechanisms:
        side = m.positive
        rows.append([m.id, _g4(side.p_eq), _g4(side.lam), _g4(side.phi_ov), _g4(m.eta)])
    headers = ["mechanism", "p_eq [rad/s]", "lam [-]", "phi_ov [rad]", "eta [-]"]
    for line in _table(headers, rows):
        typer.echo(line)
    if failures:
        raise typer.Exit(code=1)


@app.command("constants-table")
@_user_errors
def constants_table(
    table: Path = typer.Argument(..., help="Table, one mechanism per row (.csv or .xlsx)."),
    output: Path = _CONSTANTS_OUTPUT_OPT,
) -> None:
    """Turn a table of mechanisms (id, p_eq, lam, eta, f_n, h_e, h...) into a constants file."""
    check_file_target(output, "output")
    cf, range_error = checked_table(table)
    if range_error is not None:
        # a constants file may hold it; the time-domain commands (and REST) refuse it
        _note(f"warning: {range_error}; envelope, history, ida, report and assess refuse it")
    save_constants(output, cf)
    typer.echo(f"wrote {output}: {len(cf.mechanisms)} mechanism(s) from {table.name}")


@app.command(context_settings=_MORE_SCALES)
@_user_errors
@_grouped
def envelope(
    ctx: typer.Context,
    constants: Path = _CONSTANTS_OR_TABLE_ARG,
    out: Path = typer.Option(..., "--out", help="Folder for envelope.json, .csv and .png."),
    frequencies: FrequencyGrid = _FREQUENCIES,
    envelope_method: EnvelopeMethod = _ENVELOPE_METHOD,
    record: Optional[Path] = typer.Option(
        None,
        "--record",
        help="Draw this record's largest sine pulse on the plot, at each --record-scale.",
    ),
    record_scale: list[float] = typer.Option(
        [0.5, 1.0, 2.0], "--record-scale", help="Scale factors of the record's pulse [-]."
    ),
    reading: RecordOptions = _RECORD_OPTIONS,
    limits: Limits = _LIMITS,
    as_json: bool = typer.Option(False, "--json", help="Also print the JSON document."),
) -> None:
    """Minimum overturning sine-pulse amplitude of every mechanism, and the critical bands."""
    method = envelope_method.name()
    limits.check(envelope=frequencies.work(exact=False))
    f_p = frequencies.grid()
    check_folder_target(out)
    cf = read_constants(constants, time_domain=True)
    limits.check(cf, envelope=frequencies.work(exact=method == "exact"))
    pulse = None
    if record is not None:
        motion = reading.read(record)
        pulse = record_pulse_doc(cf, motion, _scales(record_scale, ctx.args), method=method)
    elif ctx.args:
        _fail(f"unexpected argument {ctx.args[0]!r}")
    kind = "exact envelopes" if method == "exact" else "envelopes (fast mode, library)"
    with (
        _status(f"{kind}: {len(cf.mechanisms)} mechanisms x {frequencies.n} frequencies"),
        run_folder(out, on_note=_out_note) as tmp,
    ):
        doc = write_envelope(
            cf,
            f_p,
            tmp,
            method=method,
            title=f"Overturning envelopes: {constants.name}",
            record_pulse=pulse,
        )
    library_file = doc["method"].get("library_file", "shipped with rockmech")
    if library_file != "shipped with rockmech":
        _note(f"note: envelopes interpolated in the library {library_file}")
    if as_json:
        _print_json(doc)
        return
    typer.echo(f"wrote {out / 'envelope.json'}, envelope.csv, envelope.png")
    typer.echo("critical mechanism by pulse frequency:")
    rows = [[str(b["mechanism"]), _g4(b["f_min"]), _g4(b["f_max"])] for b in doc["critical"]]
    for line in _table(["mechanism", "f_min [Hz]", "f_max [Hz]"], rows):
        typer.echo(line)
    if pulse is not None:
        p = pulse["pulse"]
        typer.echo(
            f"largest pulse of {pulse['record']}: {abs(p['a_p_g']):.4f} g at "
            f"{p['f_p_hz']:.3f} Hz (t = {p['t_start_s']:.2f} s)"
        )
        for point in pulse["points"]:
            names = ", ".join(point["overturns"]) or "none"
            typer.echo(f"  x{point['scale']:g}: {point['a_p_g']:.4f} g overturns {names}")


@app.command()
@_user_errors
def boundary(
    omega: float = typer.Option(..., "--omega", help="Frequency ratio omega_p / p_eq [-]."),
    eta: Optional[float] = typer.Option(
        None, "--eta", help="Coefficient of restitution [-] (one-sided: default 0)."
    ),
    one_sided: bool = typer.Option(False, "--one-sided", help="One-sided rocking."),
    shape: str = typer.Option("sine", "--shape", metavar=_SHAPES, help="Pulse shape."),
    as_json: bool = _JSON_OPT,
) -> None:
    """Every overturning interval in A = a_p/(g lam) at one frequency ratio (exact)."""
    doc = boundary_doc(omega, eta, one_sided=one_sided, shape=shape)
    if as_json:
        _print_json(doc)
        return
    spans = ", ".join(
        f"[{lo:.5g}, {'A_max' if hi is None else f'{hi:.5g}'}]"
        for lo, hi in doc["overturning_intervals"]
    )
    typer.echo(
        f"Omega = {omega:g}, eta = {doc['eta']:g} ({doc['rocking']}): "
        f"overturns for A in {spans or 'none'}"
    )
    typer.echo(
        f"  scan ratio {doc['search']['scan_ratio']:.4f}, bisection to {doc['search']['rtol']:g}"
    )


library_app = typer.Typer(help="The library of dimensionless overturning curves.")
app.add_typer(library_app, name="library")


@library_app.command("build")
@_user_errors
def library_build(
    out: Optional[Path] = typer.Option(
        None,
        "--out",
        help=(
            "Output .npz (default: the user's cache folder, which envelopes read before the "
            "shipped library; the installed package is never written)."
        ),
    ),
    n_omega: int = typer.Option(400, "--n-omega", help="Omega points, log-spaced in [0.05, 50]."),
    eta_step: float = typer.Option(0.02, "--eta-step", help="Step of eta in [0, 1]."),
) -> None:
    """Compute A_min(Omega; eta) for eta in [0, 1] and the one-sided curve (about 4 s)."""
    import numpy as np
    from rich.console import Console
    from rich.progress import Progress

    target = out if out is not None else user_library_path()
    if target is None:
        _fail("out: no user cache folder here (platformdirs is missing); give --out FILE")
    check_file_target(target)
    if n_omega < 2:
        _fail(f"n_omega: must be >= 2, got {n_omega}")
    if not 0.0 < eta_step <= 1.0:
        _fail(f"eta_step: must be in (0, 1], got {eta_step}")
    omega = np.geomspace(LIBRARY_OMEGA[0], LIBRARY_OMEGA[1], n_omega)
    eta = np.unique(np.append(np.round(np.arange(0.0, 1.0, eta_step), 12), 1.0))

    # Progress on stderr, and only on a terminal.
    console = Console(stderr=True)
    with Progress(transient=True, console=console, disable=not console.is_terminal) as bar:
        task = bar.add_task("overturning curves", total=None)

        def tick(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        lib = build_library(omega=omega, eta=eta, progress=tick)
    path = lib.save(target)
    typer.echo(
        f"wrote {path}: {lib.eta.size} two-sided curves + one-sided, {lib.omega.size} Omega, "
        f"{lib.metadata['build_seconds']} s"
    )
    if out is None:
        typer.echo(
            "  envelopes now read it instead of the shipped library (their method names it); "
            f"delete it to go back to {LIBRARY_PATH.name}"
        )


@app.command()
@_user_errors
def demo(
    out: Path = typer.Option(Path("out"), "--out", help="Output folder."),
    record: Optional[Path] = typer.Option(
        None, "--record", help="Two-column record in g (default: bundled El Centro 1940 N-S)."
    ),
) -> None:
    """Run the bundled example: rectangular walls on El Centro 1940, exact integration."""
    with run_folder(out, on_note=_out_note) as tmp:
        written = run_demo(tmp, record, on_skip=lambda note: _note(f"note: {note}"))
    paths = {kind: out / path.relative_to(tmp) for kind, path in written.items()}
    for kind, path in paths.items():
        typer.echo(f"wrote {kind}: {path}")
    summary = json.loads(paths["history"].read_text())
    rows = [
        [
            str(row["mechanism"]),
            _g4(row["scale"]),
            _g4(row["peak_ratio"]),
            "OVERTURNS" if row["overturned"] else "survives",
        ]
        for row in summary["results"]
    ]
    for line in _table(["mechanism", "scale", "peak |phi|/phi_ov", "verdict"], rows):
        typer.echo(line)


@app.command()
@_user_errors
def examples(
    out: Path = typer.Argument(
        Path("examples"), help="Folder to copy the examples into (default: ./examples)."
    ),
) -> None:
    """Copy the bundled examples (scenes, specs, constants, records, sites) into a folder.

    The README's commands use examples/... paths: run them from the folder holding OUT.
    Only files an earlier copy wrote are replaced; your own files there are never touched.
    """
    written = copy_examples(out, on_note=_out_note)
    typer.echo(f"wrote {len(written)} example files to {out}")


@app.command(context_settings=_MORE_SCALES)
@_user_errors
@_grouped
def report(
    ctx: typer.Context,
    constants: Path = _CONSTANTS_ARG,
    out: Path = typer.Option(..., "-o", "--out", help="HTML file to write."),
    record: Optional[Path] = typer.Option(
        None, "--record", help="Record for time histories and its spectrum (any format)."
    ),
    scale: list[float] = typer.Option([1.0], "--scale", help="Scale factors on the record."),
    reading: RecordOptions = _RECORD_OPTIONS,
    scaling: Scaling = _SCALING,
    at_height: Optional[float] = typer.Option(
        None, "--at-height", help="Also tabulate the peak displacement [m] this far [m] up."
    ),
    criterion: Optional[str] = _criterion_opt(
        "Verdict of the time histories: ratio (default) or exact."
    ),
    frequencies: FrequencyGrid = _FREQUENCIES,
    envelope_method: EnvelopeMethod = _ENVELOPE_METHOD,
    title: Optional[str] = typer.Option(None, "--title", help="Title of the report."),
    limits: Limits = _LIMITS,
) -> None:
    """One self-contained HTML report: constants, envelopes, and with --record its histories."""
    scales = _scales(scale, ctx.args)
    method = envelope_method.name()
    check_file_target(out)
    limits.check(scales=len(scales), envelope=frequencies.work(exact=False))
    f_p = frequencies.grid()
    cf = read_constants(constants, time_domain=True)
    sources = [input_source("constants", constants.name, constants.read_bytes())]
    motion = None
    if record is not None:
        motion = reading.read(record)
        sources.append(input_source("record", record.name, record.read_bytes()))
    size = None if motion is None else _record_size([motion])
    envelope = frequencies.work(exact=method == "exact")
    limits.check(cf, scales=len(scales), record=size, envelope=envelope)
    options = {"scales": scales, **asdict(scaling), "at_height": at_height, "criterion": criterion}
    options.update(asdict(frequencies), method=method)
    with _status("report: envelopes and histories"):
        text = build_report(
            cf,
            f_p,
            motion=motion,
            scales=scales,
            history=_history_options(scaling, criterion, at_height),
            method=method,
            title=title or f"rockmech report: {constants.name}",
            sources=sources,
            request=options,
        )
    if motion is not None:
        # the page lists them too; say so here as history does
        _skipped_notes({"skipped": time_domain_mechanisms(cf)[1]})
    typer.echo(f"wrote {write_report(out, text)}")


@app.command()
@_user_errors
def serve(
    host: Optional[str] = typer.Option(
        None, "--host", help="Interface to bind (default 127.0.0.1: this machine only)."
    ),
    port: Optional[int] = typer.Option(None, "--port", help="TCP port (default 8000)."),
    workers: Optional[int] = typer.Option(None, "--workers", help="Compute processes (default 2)."),
    timeout: Optional[float] = typer.Option(
        None, "--timeout", help="Compute time budget per request [s] (default 30)."
    ),
) -> None:
    """Run the REST service (FastAPI + uvicorn); settings also from ROCKMECH_* variables."""
    for module in ("fastapi", "uvicorn", "pydantic_settings"):
        require(module, "service", "for rockmech serve")
    # The service extra is loaded only by the command that needs it.
    from .api.server import run, settings_with

    settings = settings_with(
        host=host, port=port, compute_workers=workers, compute_timeout_s=timeout
    )
    _kernels_ahead()
    host_part = f"[{settings.host}]" if ":" in settings.host else settings.host
    typer.echo(f"rockmech {__version__} serving on http://{host_part}:{settings.port}")
    typer.echo(f"  docs: http://{host_part}:{settings.port}/api/v1/docs (Ctrl+C to stop)")
    run(settings)


def _kernels_ahead() -> None:
    """Compile the kernels once, in a child process, before the workers start (#28).

    Each worker then loads them from numba's cache in under a second, instead of every
    worker compiling them at once at start-up. The child prints a progress line only when it
    compiles.
    """
    code = "import sys; from solver_service.core.precompile import main; sys.exit(main())"
    subprocess.run([sys.executable, "-c", code], check=False)


@app.command()
@_user_errors
def kernels() -> None:
    """Compile the solver's kernels now (numba), so that no later run waits for it."""
    status = kernel_status()
    if status.active and len(status.built) < len(PATHS):
        status = build_kernels()
    typer.echo(status.describe())


def _verdict(check: dict[str, Any]) -> str:
    if check.get("status") != "ok":
        return "n/a"
    return {True: "pass", False: "FAIL", None: "incomplete"}[check["passes"]]


@app.command()
@_user_errors
def check(
    constants: Path = _CONSTANTS_ARG,
    site: Path = typer.Argument(..., help="Site file (SITE.json): hazard, FC, q, building."),
    as_json: bool = _JSON_OPT,
) -> None:
    """Code checks of every mechanism (Circolare 2019 §C8.7.1: linear SLV, nonlinear SLV/SLC)."""
    doc = check_doc(read_constants(constants), read_site(site))
    if as_json:
        _print_json(stamp(doc, "check"))
        return
    s = doc["site"]
    typer.echo(f"method: {doc['method']['name']}: {doc['method']['standard']}")
    typer.echo(f"{s['code']}: a_g S = {s['pga_g']:.4f} g, FC = {s['FC']:g}, q = {s['q']:g}")
    if s.get("T1") is not None:
        typer.echo(f"T1 = {s['T1']:.4g} s ({s['T1_source']})")
    period = "T_SLV s" if doc["method"]["name"] == "circ2019" else "Ts s"
    typer.echo(
        f"{'mechanism':<10}{'alpha0':>9}{'e*':>8}{'a0* m/s2':>10}{'demand':>9}{'linear':>8}"
        f"{'d m':>9}{'demand':>9}{period:>8}{'nonlinear':>11}"
    )
    for row in doc["mechanisms"]:
        lin, non = row["linear"], row["nonlinear"]
        if lin.get("status") == "ok":
            left = (
                f"{lin['alpha0']:>9.4g}{lin['e_star']:>8.4g}{lin['a0_star']:>10.4g}"
                f"{lin['demand']:>9.4g}{_verdict(lin):>8}"
            )
        else:
            left = f"{'-':>9}{'-':>8}{'-':>10}{'-':>9}{_verdict(lin):>8}"
        if non.get("status") == "ok":
            d = non.get("d_SLV", non.get("du_star"))
            t = non.get("T_SLV", non.get("Ts"))
            right = f"{_num(d, 9)}{_num(non.get('demand'), 9)}{_num(t, 8, 3)}{_verdict(non):>11}"
        else:
            right = f"{'-':>9}{'-':>9}{'-':>8}{_verdict(non):>11}"
        typer.echo(f"{row['id']:<10}" + left + right)
        slc = non.get("SLC") if non.get("status") == "ok" else None
        if slc is not None:
            state = {True: "pass", False: "FAIL", None: "not evaluated"}[slc["passes"]]
            typer.echo(
                f"  {row['id']}: SLC d = {slc['d']:.4g} m, demand = {slc['demand']:.4g} m, "
                f"T_SLC = {slc['T_SLC']:.3g} s, a_g,SLC = {slc['a_g_capacity']:.4g} g: {state}"
            )
        for note in sorted({lin.get("note"), non.get("note")} - {None, ""}):
            typer.echo(f"  note: {row['id']}: {note}")
    if doc["governing"] is not None:
        typer.echo(f"governing mechanism: {doc['governing']}")


def _num(value: Any, width: int, digits: int = 4) -> str:
    """Return a number right-aligned in ``width`` to ``digits`` figures ("-" for None)."""
    if value is None:
        return f"{'-':>{width}}"
    return f"{value:>{width}.{digits}g}"


# assess reads records without --channel and --component
@app.command()
@_user_errors
@_grouped
def assess(
    constants: Path = _CONSTANTS_ARG,
    site: Path = typer.Argument(..., help="Site file (SITE.json)."),
    record: list[Path] = typer.Option([], "--record", help="Record(s) for the dynamic verdict."),
    out: Path = typer.Option(..., "-o", "--out", help="HTML report to write."),
    pdf: bool = typer.Option(False, "--pdf", help="Also print it to PDF (headless Chromium)."),
    multiple: list[float] = typer.Option(
        [0.5, 1.0, 1.5, 2.0], "--multiple", help="Multiples of the design scale to run."
    ),
    reading: RecordOptions = _RECORD_OPTIONS,
    template_dir: Optional[Path] = typer.Option(
        None, "--template-dir", help="Folder whose assess.html.j2 overrides the layout."
    ),
    as_json: bool = typer.Option(False, "--json", help="Also print the assessment JSON."),
) -> None:
    """Assessment report: code checks beside rocking dynamics for every mechanism."""
    # jinja2 (the report extra) is loaded only by this command.
    from .report.assess import assess_report, print_pdf

    multiple = check_multiples(multiple)
    check_file_target(out)
    cf, site_file = read_constants(constants, time_domain=True), read_site(site)
    motions = [reading.read(r) for r in record]
    sources = [
        input_source("constants", constants.name, constants.read_bytes()),
        input_source("site", site.name, site.read_bytes()),
    ] + [input_source("record", r.name, r.read_bytes()) for r in record]
    options = {
        "multiples": multiple,
        "units": reading.units,
        "format": reading.record_format,
        "dt": reading.dt,
        "channel": reading.channel,
        "component": reading.component,
    }
    with _status("assess: code checks and rocking dynamics"):
        doc, text = assess_report(
            cf,
            site_file,
            motions,
            multiples=multiple,
            sources=sources,
            options=options,
            template_dir=template_dir,
        )
    # With --json, stdout carries exactly one JSON document; the file notes go to stderr.
    typer.echo(f"wrote {write_report(out, text)}", err=as_json)
    if pdf:
        typer.echo(f"wrote {print_pdf(out, out.with_suffix('.pdf'))}", err=as_json)
    if as_json:
        _print_json(stamp(doc, "assess"))


# the search's --no-limits lifts its own work limits
_SEARCH_LIMITS = _LIMITS.but(
    no_limits=typer.Option(
        False,
        "--no-limits",
        help="Lift the search's work limits (evaluations of the static multiplier and "
        "macro-blocks of the global check) and the time limit.",
    )
)


@app.command()
@_user_errors
@_grouped
def search(
    scene: Path = _SCENE_ARG,
    spec: Path = typer.Argument(..., help="Search spec (JSON): walls, levels, junctions, ranking."),
    out: Path = typer.Option(
        ...,
        "-o",
        "--out",
        help="Folder for search.json, search.spec.json, constants.json, search.3dm, search.png.",
    ),
    units: Optional[str] = _MESH_UNITS_OPT,
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
    limits: Limits = _SEARCH_LIMITS,
    as_json: bool = typer.Option(False, "--json", help="Print search.json."),
) -> None:
    """Find a façade's collapse mechanisms and rank them by how they rock (issue #31)."""
    # the search's workflow is loaded by this command only
    from .workflows.search import search_from_files, write_search

    check_folder_target(out)
    with _status(f"search: {scene.name}"):
        run = search_from_files(
            scene,
            spec,
            units=units,
            site=site,
            records=record,
            exact=exact,
            limits=not limits.no_limits,
        )
        with run_folder(out, on_note=_out_note) as tmp:
            write_search(run, tmp, figure=figure)
    doc = run.doc
    for warning in doc["warnings"]:
        _note(f"warning: {warning}")
    for note in doc["notes"]:
        _note(f"note: {note}")
    for fail in doc["failures"]:
        _note(f"warning: {fail['error']}")
    if as_json:
        _print_json(doc)
        return
    by_id = {d["id"]: d for d in doc["candidates"]}
    order = doc["rankings"]["dynamic"] or doc["rankings"]["static"]
    rows = []
    for mid in order[:15]:
        d = by_id[mid]
        score = (d.get("overturning") or {}).get("band_score_g")
        rows.append(
            [
                mid,
                d["family"],
                f"{d['facade']} {d['direction']}",
                _g4(d["lam0"]),
                _g4(d.get("lam_linearised")),
                _g4(score),
                str(d["rank_static"]),
            ]
        )
    band = doc["band"]["band_hz"]
    headers = [
        "mechanism",
        "family",
        "facade",
        "lam0 [-]",
        "lam [-]",
        f"a_p {band[0]:g}-{band[1]:g} Hz [g]",
        "static rank",
    ]
    for line in _table(headers, rows):
        typer.echo(line)
    for check in doc["lp"]:
        typer.echo(f"{check['facade']} {check['direction']}: {check['message']}")
    c = doc["counts"]
    typer.echo(
        f"{c['candidates']} mechanisms ({c['evaluations']} evaluations of lam0), {c['built']} "
        f"built; wrote {out / 'search.json'}, search.spec.json, constants.json, search.3dm"
        + (", search.png" if figure else "")
    )


def main() -> None:  # pragma: no cover - console entry point
    """Entry point of the ``rockmech`` console script."""
    app()
