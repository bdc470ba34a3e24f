"""The ``rockmech`` command line.

Every command validates its inputs up front; a bad argument exits with status 2 and a
one-line reason on stderr (``error: <field>: <what is wrong>``), and so does a missing
optional extra (the message gives its ``pip install 'rockmech[<extra>]'`` line). Results go
to stdout, warnings, notes and progress to stderr. With ``--json`` a command prints exactly
one JSON document to stdout. SI units throughout, except where an option name says
otherwise (``--a-p-g`` is in g); every ``--help`` shows the units in brackets.

The package loads what a command needs: ``errors`` (one-line errors), ``options`` (the
shared options and option groups), ``output`` (tables, notes, JSON), ``app`` (the typer
application and ``--version``) and one module per family of commands, each of which imports
its workflows inside the command's body, when it runs. ``rockmech --help`` and a one-pulse
``rockmech pulse`` load neither the envelopes, nor scipy.optimize, nor ``cad_maths``, nor
matplotlib (tests/test_cli_imports.py; docs/benchmarks.md times them). The console script
(``main``) has typer build the one command it runs (``command_app``), not all of them.
"""

from __future__ import annotations

import copy
import gc
import sys
from collections.abc import Sequence

import typer

from . import check, envelope, history, ida, pulse, retrofit, search, tools
from .app import CONSOLE, app
from .options import MORE_SCALES

__all__ = ["app", "command_app", "main"]

# The commands, in the order ``rockmech --help`` lists them.
app.command()(pulse.pulse)
app.command(context_settings=MORE_SCALES)(history.history)
app.command("record")(history.record_info)
app.command()(ida.ida)
app.command()(search.constants)
app.command("constants-table")(search.constants_table)
app.command(context_settings=MORE_SCALES)(envelope.envelope)
app.command()(pulse.boundary)
app.add_typer(tools.library_app, name="library")
tools.library_app.command("build")(tools.library_build)
app.command()(tools.demo)
app.command()(tools.examples)
app.command(context_settings=MORE_SCALES)(envelope.report)
app.command()(tools.serve)
app.command()(tools.kernels)
app.command()(check.check)
app.command()(check.assess)
app.command()(retrofit.retrofit)
app.command()(search.search)


def command_app(args: Sequence[str]) -> typer.Typer:
    """Return ``app`` with only the command that ``args`` starts with, or ``app`` itself.

    typer builds the options of every registered command on each call (about as long as a
    one-pulse ``rockmech pulse`` takes to integrate, #38); a process that runs one command
    needs that command's alone. Its help, errors and output are the whole application's:
    the same group (the ``--version`` callback, the usage errors of ``Commands``) holding
    one command. Anything else (no command, an option first, a command group such as
    ``library``, a name that is no command) gets the whole ``app``.
    """
    name = args[0] if args else ""
    chosen = [
        info
        for info in app.registered_commands
        if info.callback is not None
        and name == (info.name or typer.main.get_command_name(info.callback.__name__))
    ]
    if not chosen:
        return app
    light = copy.copy(app)
    light.registered_commands = chosen
    light.registered_groups = []
    return light


def main() -> None:
    """Entry point of the ``rockmech`` console script (one command, then the process ends)."""
    CONSOLE["process"] = True
    try:
        command_app(sys.argv[1:])()
    finally:
        # The process ends: the collector's passes over every object the imported modules
        # hold (pydantic's schemas, typer's commands) would free nothing the end of the
        # process does not, and cost a one-pulse ``rockmech pulse`` a sixth of its time (#38).
        gc.freeze()
