"""The ``rockmech`` typer application and its own option, ``--version``.

The commands are registered on ``app`` by ``solver_service.cli`` (its ``__init__``), in the
order ``rockmech --help`` lists them.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import typer

from shared_schema.version import __version__

from .errors import Commands, note

__all__ = ["CONSOLE", "app"]

#: ``process`` is set by ``solver_service.cli.main`` (the ``rockmech`` console script): the
#: process runs one command and ends, so a command may choose for the whole process
#: (``pulse`` runs the pure-Python kernels without loading numba). Not set where the app is
#: called in a longer-lived process (tests, a notebook).
CONSOLE = {"process": False}

app = typer.Typer(
    cls=Commands,
    name="rockmech",
    help="Rocking collapse mechanisms of masonry: exact rocking solver and tools (SI units).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    # Plain help: rich markup would read the units in brackets ("[rad/s]") as tags and drop them.
    rich_markup_mode=None,
)


def _foreign_packages() -> list[str]:
    """Name rockmech's top-level packages loaded from outside its install (a name clash)."""
    # Where each package would be imported from, without running it (cad_maths loads nothing).
    homes = {
        name: Path(str(_origin(name))).resolve().parent.parent
        for name in ("rockmech", "shared_schema", "cad_maths", "solver_service", "rhino_plugin")
    }
    return [
        f"warning: {name} is loaded from {home}, not from rockmech's install "
        f"({homes['rockmech']}): another package or file has that name (docs/install.md)"
        for name, home in homes.items()
        if home != homes["rockmech"]
    ]


def _origin(name: str) -> object:
    """Return the file a top-level package is (or would be) imported from (None: none)."""
    spec = importlib.util.find_spec(name)
    return None if spec is None else spec.origin


def _print_version(value: bool) -> None:
    if value:
        # What is known of the compiled kernels without loading numba (#38): rockmech
        # kernels loads it and checks everything.
        from ..core.kernel_cache import version_line

        typer.echo(f"rockmech {__version__}")
        typer.echo(version_line())
        for line in _foreign_packages():
            note(line)
        raise typer.Exit()


@app.callback()
def _main(
    version: bool = typer.Option(
        False,
        "--version",
        callback=_print_version,
        is_eager=True,
        help="Print the version, what is known of the compiled kernels (without loading "
        "numba), and exit.",
    ),
) -> None:
    """Rocking collapse mechanisms of masonry: exact rocking solver and tools (SI units)."""
