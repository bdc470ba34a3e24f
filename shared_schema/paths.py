"""Paths the Python way: the one place a path argument of rockmech is normalised and checked.

Every public function that reads or writes a file takes ``str`` or ``os.PathLike`` (a
``pathlib.Path``), as ``open`` does. :func:`as_path` turns either into a ``Path`` and refuses
anything else with an ``InputError`` naming the argument and the type it got (never a
``TypeError`` or an ``AttributeError`` from deep inside a reader); :func:`readable_file`
also checks that the path names a file that can be read, and says which of "not found",
"a folder" or "cannot be read" it is, naming the path; :func:`readable_folder` does the same
for a folder an argument names (files are read from it).

No third-party imports, and Python 3.9-clean (Rhino 8 imports it).
"""

import os
from pathlib import Path
from typing import Union

from shared_schema.errors import InputError

__all__ = ["PATH_TYPES", "PathLike", "as_path", "is_path", "readable_file", "readable_folder"]

#: A file path: a string or an ``os.PathLike`` (``pathlib.Path``).
PathLike = Union[str, "os.PathLike[str]"]
#: What a path argument may be, in words, for the messages.
PATH_TYPES = "a path (str or os.PathLike, e.g. pathlib.Path)"


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
