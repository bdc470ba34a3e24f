"""Paths the Python way: the one place a path argument of rockmech is normalised and checked.

Every public function that reads or writes a file takes ``str`` or ``os.PathLike`` (a
``pathlib.Path``), as ``open`` does. :func:`as_path` turns either into a ``Path`` and refuses
anything else with an ``InputError`` naming the argument and the type it got (never a
``TypeError`` or an ``AttributeError`` from deep inside a reader); :func:`readable_file`
also checks that the path names a file that can be read, and says which of "not found",
"a folder" or "cannot be read" it is, naming the path; :func:`readable_folder` does the same
for a folder an argument names (files are read from it). A reader of a JSON document also
takes an open file (``open(path, "rb")``, ``io.BytesIO``, a text file): :func:`read_source`
returns the bytes of either, with a name for the messages.

No third-party imports, and Python 3.9-clean (Rhino 8 imports it).
"""

import os
from pathlib import Path
from typing import IO, Tuple, Union

from shared_schema.errors import InputError

__all__ = [
    "PATH_TYPES",
    "SOURCE_TYPES",
    "PathLike",
    "Source",
    "as_path",
    "is_file_object",
    "is_path",
    "read_source",
    "readable_file",
    "readable_folder",
]

#: A file path: a string or an ``os.PathLike`` (``pathlib.Path``).
PathLike = Union[str, "os.PathLike[str]"]
#: A file to read: a path, or an open file (binary or text; :func:`read_source`).
Source = Union[str, "os.PathLike[str]", IO[bytes], IO[str]]
#: What a path argument may be, in words, for the messages.
PATH_TYPES = "a path (str or os.PathLike, e.g. pathlib.Path)"
#: What a reading argument that also takes an open file may be (:func:`read_source`).
SOURCE_TYPES = PATH_TYPES + " or an open file"


def is_path(value: object) -> bool:
    """Return whether ``value`` is a path :func:`as_path` takes (``str`` or ``os.PathLike``).

    Examples
    --------
    >>> is_path("walls.json"), is_path(Path("walls.json")), is_path(b"walls.json")
    (True, True, False)
    """
    return isinstance(value, (str, os.PathLike))


def _what(value: object) -> str:
    """Name the type of a refused path argument, with a hint where one helps."""
    if isinstance(value, (bytes, bytearray)):
        return "bytes; decode a bytes path first (os.fsdecode(path))"
    if hasattr(value, "read"):
        return f"an open file ({type(value).__name__}); pass the file's path instead"
    return type(value).__name__


def as_path(value: object, field: str, expected: str = PATH_TYPES) -> Path:
    """Return ``value`` as a ``Path``; refuse what is not a path with ``InputError``.

    Parameters
    ----------
    value : str or os.PathLike
        The path argument as the caller gave it.
    field : str
        The argument's name, for the message (``"constants"``, ``"scene"``, ``"out"``).
    expected : str
        What the argument may be, in words (a caller that also takes an object says so).

    Returns
    -------
    Path

    Raises
    ------
    InputError
        ``value`` is neither ``str`` nor ``os.PathLike`` (bytes, an open file, a dict, None),
        is an empty string, or is an ``os.PathLike`` whose ``os.fspath`` is not a ``str``.

    Examples
    --------
    >>> as_path("examples/constants/walls.csv", "table").name
    'walls.csv'
    >>> try:
    ...     as_path(3, "record")
    ... except InputError as exc:
    ...     print(exc.field, "|", exc.reason)
    record | must be a path (str or os.PathLike, e.g. pathlib.Path), got int
    """
    if isinstance(value, str):
        text: object = value
    elif isinstance(value, os.PathLike):
        text = os.fspath(value)
    else:
        raise InputError(f"must be {expected}, got {_what(value)}", field)
    if not isinstance(text, str):
        raise InputError(f"must be {expected}, got a path-like of {_what(text)}", field)
    if not text:
        raise InputError(f"must be {expected}, got an empty string", field)
    return Path(text)


def readable_file(value: object, field: str, expected: str = PATH_TYPES) -> Path:
    """Return ``value`` as a ``Path`` if it names a file that can be read; else ``InputError``.

    Parameters
    ----------
    value : str or os.PathLike
        The path argument as the caller gave it (:func:`as_path`).
    field : str
        The argument's name, for the message.
    expected : str
        What the argument may be, in words (:func:`as_path`).

    Returns
    -------
    Path

    Raises
    ------
    InputError
        Field ``field``; the message names the path: ``file not found: <path>``, ``is a
        folder, not a file: <path>``, ``is not a regular file: <path>`` (a device or a pipe)
        or ``cannot be read: <path>: <reason>`` (permissions, an I/O error).

    Notes
    -----
    The file is opened (and closed) to learn whether it can be read: ``os.access`` answers
    for the real user id and misses what only opening finds out. A device or a named pipe is
    refused before that, as opening a pipe waits for a writer.
    """
    path = as_path(value, field, expected)
    try:
        if path.is_dir():
            raise InputError(f"is a folder, not a file: {path}", field)
        if not path.exists():
            raise InputError(f"file not found: {path}", field)
        if not path.is_file():
            raise InputError(f"is not a regular file: {path}", field)
        with open(path, "rb"):
            pass
    except OSError as exc:
        raise InputError(f"cannot be read: {path}: {exc.strerror or exc}", field) from None
    return path


def readable_folder(value: object, field: str, expected: str = PATH_TYPES) -> Path:
    """Return ``value`` as a ``Path`` if it names an existing folder; else ``InputError``.

    For an argument that names a folder files are read from (a spec's folder, against which
    its relative paths are taken).

    Parameters
    ----------
    value : str or os.PathLike
        The path argument as the caller gave it (:func:`as_path`).
    field : str
        The argument's name, for the message.
    expected : str
        What the argument may be, in words (:func:`as_path`).

    Returns
    -------
    Path

    Raises
    ------
    InputError
        Field ``field``; the message names the path: ``folder not found: <path>``, ``is a
        file, not a folder: <path>`` or ``cannot be read: <path>: <reason>``.

    Examples
    --------
    >>> readable_folder("no such folder", "spec_dir")
    Traceback (most recent call last):
    ...
    shared_schema.errors.InputError: spec_dir: folder not found: no such folder
    """
    path = as_path(value, field, expected)
    try:
        if path.is_dir():
            return path
        if path.exists():
            raise InputError(f"is a file, not a folder: {path}", field)
    except OSError as exc:
        raise InputError(f"cannot be read: {path}: {exc.strerror or exc}", field) from None
    raise InputError(f"folder not found: {path}", field)


def is_file_object(value: object) -> bool:
    """Return whether ``value`` is an open file (it has ``read``; not a path nor bytes).

    Examples
    --------
    >>> import io
    >>> is_file_object(io.BytesIO(b"{}")), is_file_object("walls.json")
    (True, False)
    """
    if isinstance(value, (str, bytes, bytearray, os.PathLike)):
        return False
    return callable(getattr(value, "read", None))


def read_source(value: object, field: str, expected: str = SOURCE_TYPES) -> Tuple[bytes, str]:
    """Return the content of a file given as a path or as an open file, and its name.

    Parameters
    ----------
    value : str, os.PathLike or file object
        A path (:func:`readable_file`), or an open file in binary or text mode (read from
        its position to its end; a text file's text is encoded as UTF-8).
    field : str
        The argument's name, for the message.
    expected : str
        What the argument may be, in words.

    Returns
    -------
    bytes
        The content.
    str
        The file's name for the messages: the path's last part, an open file's ``name``
        (its last part), or ``"<open file>"`` where it has none.

    Raises
    ------
    InputError
        As :func:`readable_file` for a path; ``cannot be read: <name>: <reason>`` for a file
        that fails to read (closed, opened for writing) or reads as neither bytes nor text.

    Examples
    --------
    >>> import io
    >>> read_source(io.BytesIO(b'{"a": 1}'), "site")
    (b'{"a": 1}', '<open file>')
    """
    if is_file_object(value):
        label = getattr(value, "name", None)
        name = os.path.basename(label) if isinstance(label, str) and label else "<open file>"
        try:
            data = value.read()  # type: ignore[attr-defined]
        except (OSError, ValueError) as exc:  # closed, or opened for writing only
            raise InputError(f"cannot be read: {name}: {exc}", field) from None
        if isinstance(data, str):
            data = data.encode("utf-8")
        if not isinstance(data, (bytes, bytearray)):
            got = type(data).__name__
            raise InputError(f"cannot be read: {name}: read() gave {got}, not bytes", field)
        return bytes(data), name
    path = readable_file(value, field, expected)
    try:
        return path.read_bytes(), path.name
    except OSError as exc:
        raise InputError(f"cannot be read: {path}: {exc.strerror or exc}", field) from None
