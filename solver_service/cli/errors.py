"""One-line errors of the ``rockmech`` command: click's usage errors and rockmech's own.

A bad argument exits with status 2 and one line on stderr (``error: <field>: <what is
wrong>``): click's usage errors are reworded here (``Commands``, the command group), and
``user_errors`` turns rockmech's errors, write errors and missing extras raised by a
command into the same line. Nothing here loads a workflow: ``rockmech --help`` pays only
for typer and these few modules.
"""

from __future__ import annotations

import difflib
import functools
import importlib
from collections.abc import Callable
from pathlib import Path
from typing import Any, NoReturn, Optional, TypeVar

import typer
from typer.core import TyperGroup, TyperOption

from shared_schema.atomic import remove_stale_temps
from shared_schema.errors import RockmechError
from shared_schema.extras import MissingExtra, extra_for

from ..workflows.limits import TimeLimitExceeded
from ..workflows.limits import time_limit as run_time_limit
from ..workflows.rundir import os_reason

__all__ = ["Commands", "F", "UsageError", "fail", "note", "user_errors"]

# typer re-exports click's exceptions, and newer typer vendors click (``typer._click``): the
# classes are taken from the module typer's own BadParameter comes from.
_CLICK = importlib.import_module(typer.BadParameter.__module__)
#: Raised by click for a bare group call that shows the help: not an error to reword.
_HELP_ERROR: Any = getattr(_CLICK, "NoArgsIsHelpError", ())

F = TypeVar("F", bound=Callable[..., Any])


class UsageError(_CLICK.ClickException):  # type: ignore[misc,name-defined]
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


class Commands(TyperGroup):
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
            raise UsageError(_usage_line(exc)) from None

    def resolve_command(self, ctx: Any, args: list[str]) -> Any:
        """Find the command; an unknown one is named with the closest commands."""
        name = args[0] if args else ""
        if name and not name.startswith("-") and self.get_command(ctx, name) is None:
            close = difflib.get_close_matches(name, self.list_commands(ctx))
            hint = f" (did you mean {' or '.join(close)}?)" if close else ""
            raise UsageError(
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
            raise UsageError(_usage_line(exc)) from None


def fail(message: str) -> NoReturn:
    """Print ``error: <message>`` on stderr and exit with status 2."""
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code=2)


def note(message: str) -> None:
    """Print a warning or note on stderr, so that stdout holds only results."""
    typer.echo(message, err=True)


def user_errors(fn: F) -> F:
    """Turn rockmech's own errors, write errors and missing extras into one line and exit 2."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            _clean_stale_temps(kwargs)
            with run_time_limit(None if kwargs.get("no_limits") else kwargs.get("time_limit")):
                return fn(*args, **kwargs)
        except TimeLimitExceeded as exc:
            fail(str(exc))
        except RockmechError as exc:
            fail(str(exc))
        except OSError as exc:
            # Read-only folder, full disk, missing permission: one line, not a traceback.
            where = f"{exc.filename}: " if exc.filename else ""
            fail(f"out: {where}{os_reason(exc)}")
        except ModuleNotFoundError as exc:
            # A heavy module imported without ``require``: still name the extra.
            name = exc.name or "a module"
            extra = extra_for(name)
            if extra is not None:
                fail(str(MissingExtra(name, extra)))
            fail(f"{name} is not installed; reinstall rockmech (pip install rockmech)")

    return wrapper  # type: ignore[return-value]


def _clean_stale_temps(kwargs: dict[str, Any]) -> None:
    """Remove temporary files of killed runs beside this run's outputs, with a note each."""
    for key in ("out", "output"):
        target = kwargs.get(key)
        if isinstance(target, Path):
            for folder in dict.fromkeys((target.parent, target)):
                for path in remove_stale_temps(folder):
                    note(f"note: removed {path}, a temporary file left by a run that was killed")
