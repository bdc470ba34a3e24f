"""Options that several ``rockmech`` commands take, defined once, and option groups.

A single shared option is a module constant here (``JSON_OPT``, ``RECORD_ARG``...). A set of
options that commands take together is an option group: a dataclass of their values and one
``Group`` of their typer options (``RECORD_OPTIONS``, ``SCALING``, ``LIMITS``,
``FREQUENCIES``, ``ENVELOPE_METHOD``); CONTRIBUTING.md, "A CLI option". The help texts are
built here at import, so this module loads only the vocabularies and the limits: the
dataclasses' methods import the workflow they call when a command runs.
"""

from __future__ import annotations

import functools
import inspect
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional, get_type_hints

import typer

from shared_schema.rules import (
    CRITERIA,
    LENGTH_UNITS,
    PULSE_SHAPES,
    RECORD_FORMATS,
    RECORD_UNITS,
    SF_METHODS,
)

from ..workflows.limits import CLI_BUDGET_S, DEFAULT_LIMITS, check_run
from .errors import F, fail
from .output import choices, record_warning

if TYPE_CHECKING:
    from ..core.records import GroundMotion
    from ..workflows.scaling import Building

__all__ = [
    "CONSTANTS_ARG",
    "CONSTANTS_OR_TABLE_ARG",
    "CONSTANTS_OUTPUT_OPT",
    "CRITERIA_CHOICES",
    "ENVELOPE_METHOD",
    "FREQUENCIES",
    "JSON_OPT",
    "LIMITS",
    "MESH_UNITS_OPT",
    "MORE_SCALES",
    "RECORD_ARG",
    "RECORD_OPTIONS",
    "SCALING",
    "SCENE_ARG",
    "SHAPES",
    "EnvelopeMethod",
    "FrequencyGrid",
    "Group",
    "Limits",
    "RecordOptions",
    "Scaling",
    "criterion_opt",
    "grouped",
    "scales",
]

# Vocabularies of the choice options: one home, shared_schema.rules.
SHAPES = choices(PULSE_SHAPES)
CRITERIA_CHOICES = choices(CRITERIA)

JSON_OPT = typer.Option(False, "--json", help="Print one JSON document.")
CONSTANTS_ARG = typer.Argument(..., help="Kinematic-constants JSON file.")
CONSTANTS_OR_TABLE_ARG = typer.Argument(
    ..., help="Kinematic-constants JSON file or constants table (.csv, .xlsx)."
)
CONSTANTS_OUTPUT_OPT = typer.Option(
    ..., "-o", "--output", help="Kinematic-constants JSON to write."
)
SCENE_ARG = typer.Argument(..., help="Rhino .3dm file, or a scan mesh .ply/.obj/.stl/.off.")
MESH_UNITS_OPT = typer.Option(
    None,
    "--units",
    metavar=choices(LENGTH_UNITS),
    help="Length unit of a scan mesh (.ply, .obj, .stl, .off; required there).",
)
RECORD_ARG = typer.Argument(
    ...,
    help="Record file: PEER AT2, ESM/ITACA, K-NET/KiK-net, COSMOS V2, CSMIP/DMG V2, GeoNet "
    "V2A, two columns (t, a), one column (with --dt) or CSV.",
)

#: Context of a command that takes several values after one ``--scale`` (``scales``).
MORE_SCALES = {"allow_extra_args": True, "ignore_unknown_options": True}


def criterion_opt(help_text: str) -> Any:
    """Return the ``--criterion`` option with this command's note on its default."""
    return typer.Option(None, "--criterion", metavar=CRITERIA_CHOICES, help=help_text)


def scales(first: list[float], extra: list[str]) -> list[float]:
    """Collect the --scale values, also those typed after the first (``--scale 0.5 1 2``)."""
    values = list(first)
    for token in extra:
        try:
            values.append(float(token))
        except ValueError:
            fail(f"unexpected argument {token!r}")
    return values


class Group:
    """An option group: options several commands take together, and their dataclass.

    A command takes a group as one parameter whose default is the group
    (``reading: RecordOptions = RECORD_OPTIONS``); ``grouped`` puts the group's options in its
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
        return Group(self.cls, {k: self.options[k] for k in names}, self.defaults)

    def but(self, **options: Any) -> Any:
        """Return the group with some options defined otherwise (another help text)."""
        return Group(self.cls, {**self.options, **options}, self.defaults)

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


def grouped(fn: F) -> F:
    """Let a command take option groups (``Group``): typer sees each group's options."""
    signature = inspect.signature(fn)
    groups = {
        name: p.default for name, p in signature.parameters.items() if isinstance(p.default, Group)
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
        # The record readers are loaded when a command reads a record.
        from ..workflows.inputs import read_record

        return read_record(
            path,
            self.record_format,
            self.units,
            self.dt,
            self.channel,
            self.component,
            on_warning=record_warning,
        )


RECORD_OPTIONS: Any = Group(
    RecordOptions,
    {
        "units": typer.Option(
            None,
            "--units",
            metavar=choices(RECORD_UNITS),
            help="Acceleration units; files that state their own (AT2, the strong-motion "
            "formats, a CSV column 'acc [g]') are read in them, two-column files default to g, "
            "other files need it.",
        ),
        "record_format": typer.Option(
            None,
            "--format",
            metavar=choices(RECORD_FORMATS),
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
        # The scaling workflow is loaded when a command scales a record.
        from ..workflows.scaling import Building

        return Building(self.building_height, self.soil_factor, self.element_period)


SCALING: Any = Group(
    Scaling,
    {
        "sf": typer.Option(
            "none",
            "--sf",
            metavar=choices(SF_METHODS),
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
    """The size and time limits of a run (the time limit is applied by ``user_errors``)."""

    no_limits: bool
    time_limit: float

    def check(self, *args: Any, **kwargs: Any) -> None:
        """Refuse a run above the size limits (``workflows.limits.check_run``) unless lifted."""
        if not self.no_limits:
            check_run(*args, **kwargs)


LIMITS: Any = Group(
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
        # The documents are loaded when a command computes envelopes.
        from ..workflows.documents import frequency_grid

        return frequency_grid(self.f_min, self.f_max, self.n)

    def work(self, exact: bool) -> tuple[float, float, int, bool]:
        """Return the envelope's size for ``Limits.check`` (``envelope=``)."""
        return self.f_min, self.f_max, self.n, exact


FREQUENCIES: Any = Group(
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
            fail("fast: give --fast or --exact, not both")
        return "library" if self.fast else "exact"


ENVELOPE_METHOD: Any = Group(
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
