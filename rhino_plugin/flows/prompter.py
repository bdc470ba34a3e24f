"""The questions a command asks, as a small interface.

A :class:`Prompter` is what a command flow talks to. Rhino implements it with
``Rhino.Input.Custom`` getters and an Eto dialog (``rhino_plugin.rhino.prompts``); tests
implement it with scripted answers. Objects are answered by their id (GUID string) in the
scene the flow works on; picked or drawn points are in the scene's model units.

Every method raises :class:`Cancelled` when the user presses Escape or closes a dialog: the
command then stops and writes nothing.

Python 3.9-clean: imported by Rhino 8.
"""

from typing import Any, Dict, List, Optional, Protocol, Sequence, Tuple, Union

__all__ = ["KINDS", "Cancelled", "LineAnswer", "Point", "Prompter"]

#: A point in model units.
Point = Tuple[float, float, float]

#: A rotation axis or hinge: the id of a picked line object, or two drawn points.
LineAnswer = Union[str, Tuple[Point, Point]]

#: What a selection may ask for: closed solids, straight lines, or planar objects.
KINDS = ("solid", "line", "plane")


class Cancelled(Exception):
    """The user cancelled a prompt (Escape, or a dialog closed with Cancel)."""


class Prompter(Protocol):
    """The questions a command flow may ask.

    Methods
    -------
    get_objects(prompt, kind, multiple, optional)
        Object ids; ``[]`` only when ``optional`` and the user pressed Enter.
    get_number(prompt, default, optional)
        The number typed; headless prompters may return the raw text, which the flow
        checks; ``None`` only when ``optional`` and the user pressed Enter.
    get_line(prompt)
        A :data:`LineAnswer`.
    get_points(prompt, count)
        ``count`` points [model units].
    get_option(prompt, options, default)
        One of ``options``.
    get_checkboxes(title, items)
        ``{item: ticked}`` for every item.
    get_file(prompt, extensions, save)
        A file path.
    message(text)
        Show a line on the command line.
    """

    def get_objects(
        self, prompt: str, kind: str = "solid", multiple: bool = True, optional: bool = False
    ) -> List[str]:
        """Return the ids of the selected objects of ``kind`` (one of :data:`KINDS`)."""
        ...

    def get_number(
        self, prompt: str, default: Optional[float] = None, optional: bool = False
    ) -> Any:
        """Return the number entered (or the raw text), ``None`` if skipped."""
        ...

    def get_line(self, prompt: str) -> LineAnswer:
        """Return a picked line object's id or two drawn points [model units]."""
        ...

    def get_points(self, prompt: str, count: int) -> List[Point]:
        """Return ``count`` picked points [model units]."""
        ...

    def get_option(self, prompt: str, options: Sequence[str], default: int = 0) -> str:
        """Return the chosen option."""
        ...

    def get_checkboxes(self, title: str, items: Sequence[str]) -> Dict[str, bool]:
        """Return which items the user ticked."""
        ...

    def get_file(self, prompt: str, extensions: Sequence[str], save: bool = False) -> str:
        """Return a file path chosen by the user."""
        ...

    def message(self, text: str) -> None:
        """Show ``text`` to the user (the command line in Rhino)."""
        ...
