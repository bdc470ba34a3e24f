"""How the ``rockmech`` commands print: tables, numbers, notes, JSON and the spinner.

Results go to stdout; warnings, notes and progress to stderr (``errors.note``).
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Iterable, Iterator, Sequence
from typing import Any, Optional

import typer

from shared_schema.rules import printable

from .errors import note

__all__ = [
    "TABLE_WIDTH",
    "choices",
    "fmt_time",
    "g4",
    "mechanism_warning",
    "out_note",
    "print_json",
    "record_warning",
    "skipped_notes",
    "status",
    "table",
]

#: Widest terminal table [characters].
TABLE_WIDTH = 100


def out_note(message: str) -> None:
    """Print a note about the output folder (a swap ended for a killed run, a file kept)."""
    note(f"note: {message}")


def skipped_notes(doc: Any) -> None:
    """Print a warning for each mechanism an analysis left out (its ``skipped``).

    ``doc`` is a document's JSON form or a typed document (``shared_schema.documents``).
    """
    skipped = doc.get("skipped", []) if isinstance(doc, dict) else doc.skipped or []
    for skip in skipped:
        mech, reason = (
            (skip["mechanism"], skip["reason"])
            if isinstance(skip, dict)
            else (
                skip.mechanism,
                skip.reason,
            )
        )
        note(f"warning: {mech} skipped: {reason}")


def mechanism_warning(mech_id: str, text: str) -> None:
    """Print a mechanism's warning, naming it once (a note may already start with its id)."""
    named = text.startswith((f"{mech_id}.", f"{mech_id}:", f"{mech_id} "))
    note(f"warning: {text}" if named else f"warning: {mech_id}: {text}")


def record_warning(text: str) -> None:
    """Print a record's warning (``read_record``'s ``on_warning``) on stderr."""
    note(f"warning: record: {text}")


@contextlib.contextmanager
def status(message: str) -> Iterator[None]:
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


def choices(values: Iterable[str]) -> str:
    """Return the ``--help`` placeholder of a word from a vocabulary: ``[sine|cosine]``.

    The vocabularies live in ``shared_schema.rules``. A value outside one reaches the domain
    check, so the command line and the REST service give the same one-line message
    (``error: shape: must be one of [...]``); a test pins that.
    """
    return "[" + "|".join(values) + "]"


def table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
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


def g4(value: Optional[float]) -> str:
    """Format a number to 4 significant figures (``-`` for none)."""
    return "-" if value is None else f"{value:.4g}"


def fmt_time(value: Optional[float]) -> str:
    """Format a time [s] to 4 decimals (``-`` for none)."""
    return "-" if value is None else f"{value:.4f} s"


def print_json(doc: Any) -> None:
    """Print one JSON document on stdout (non-finite numbers as null)."""
    # The document's cleaner is loaded when a command prints JSON.
    from ..workflows.units import finite_json

    typer.echo(json.dumps(finite_json(doc), indent=2, allow_nan=False))
