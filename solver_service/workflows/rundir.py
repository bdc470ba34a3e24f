"""A run's output folder, written whole or not at all.

``run_folder(out)`` gives a fresh sibling folder (``.<name>.<pid>.tmp``) to write into; when
the block ends without error the folder replaces ``out`` (the old one is moved aside and
removed), so a reader never sees half of one run and half of another. On an error the
fresh folder is removed and ``out`` is left as it was. Folders left by runs that died
(their process no longer exists) are removed first.

An ``OSError`` (read-only folder, full disk, missing permission) becomes an ``InputError``
with one line naming the folder and the reason, which the command line prints as
``error: ...`` with exit status 2.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Union

from shared_schema.atomic import pid_alive
from shared_schema.errors import InputError

__all__ = ["check_file_target", "check_folder_target", "os_reason", "run_folder", "stale_folders"]

#: Suffixes of the sibling folders of a run in progress and of the folder it replaces.
TMP_SUFFIX = ".tmp"
OLD_SUFFIX = ".old"


def stale_folders(out: Path) -> list[Path]:
    """Return the siblings of ``out`` left by runs whose process has ended."""
    found: list[Path] = []
    prefix = f".{out.name}."
    if not out.parent.is_dir():
        return found
    for path in out.parent.iterdir():
        name = path.name
        if not name.startswith(prefix) or not name.endswith((TMP_SUFFIX, OLD_SUFFIX)):
            continue
        pid_text = name[len(prefix) :].rsplit(".", 1)[0]
        if pid_text.isdigit() and not pid_alive(int(pid_text)):
            found.append(path)
    return found


def os_reason(exc: OSError) -> str:
    """Return a short reason for a write error: full disk, permission, read-only, ..."""
    if exc.errno == errno.ENOSPC:
        return "the disk is full"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return "permission denied"
    if exc.errno == errno.EROFS:
        return "the file system is read-only"
    return exc.strerror or type(exc).__name__


def check_folder_target(out: Union[str, Path], field: str = "out") -> None:
    """Raise ``InputError`` if ``out`` exists and is not a folder (checked before a run)."""
    target = Path(out)
    if target.exists() and not target.is_dir():
        raise InputError(f"{target} is a file; give a folder for the run's outputs", field)


def check_file_target(out: Union[str, Path], field: str = "out") -> None:
    """Check that a file can be written at ``out``, creating its missing parent folders.

    Every command that writes one file calls this before any work, so ``-o out/walls.json``
    works in a fresh folder and an impossible target fails at once.

    Parameters
    ----------
    out : path
        The file to be written (it may exist; it is replaced later).
    field : str
        Names the option in error messages.

    Raises
    ------
    InputError
        ``out`` is an existing folder, or its parent folder cannot be created (a file stands
        in the way, permission, read-only file system); one line naming the folder.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     check_file_target(Path(d) / "out" / "walls.json")
    ...     (Path(d) / "out").is_dir()
    True
    """
    target = Path(out)
    if target.is_dir():
        raise InputError(f"{target} is a folder; give a file name to write", field)
    parent = target.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        # A file where a folder must go: name it rather than print "File exists".
        blocker = next((p for p in (parent, *parent.parents) if p.is_file()), parent)
        raise InputError(f"cannot create folder {parent}: {blocker} is a file", field) from None
    except OSError as exc:
        raise InputError(f"cannot create folder {parent}: {os_reason(exc)}", field) from None


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        with contextlib.suppress(FileNotFoundError):
            path.unlink()


@contextlib.contextmanager
def run_folder(out: Union[str, Path], field: str = "out") -> Iterator[Path]:
    """Yield a fresh folder to write a run into; on success it replaces ``out``.

    Parameters
    ----------
    out : path
        The run's output folder (created, or replaced whole).
    field : str
        Names the option in error messages.

    Raises
    ------
    InputError
        ``out`` is a file, or writing failed (read-only, full disk, permission); one line.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with run_folder(Path(d) / "run") as tmp:
    ...         _ = (tmp / "result.json").write_text("{}")
    ...     sorted(p.name for p in Path(d).iterdir()), (Path(d) / "run" / "result.json").exists()
    (['run'], True)
    """
    target = Path(out)
    check_folder_target(target, field)
    tmp = target.parent / f".{target.name}.{os.getpid()}{TMP_SUFFIX}"
    old = target.parent / f".{target.name}.{os.getpid()}{OLD_SUFFIX}"
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        for path in stale_folders(target):
            _remove(path)
        _remove(tmp)
        _remove(old)
        tmp.mkdir()
    except OSError as exc:
        raise InputError(f"cannot write to {target.parent}: {os_reason(exc)}", field) from None
    try:
        yield tmp
        if target.exists():
            os.replace(target, old)
        os.replace(tmp, target)
    except OSError as exc:
        _remove(tmp)
        if old.exists() and not target.exists():
            with contextlib.suppress(OSError):
                os.replace(old, target)
        raise InputError(f"cannot write to {target}: {os_reason(exc)}", field) from None
    except BaseException:
        # Interrupted (Ctrl+C, the time limit) between the two renames: the old run is kept.
        _remove(tmp)
        if old.exists() and not target.exists():
            with contextlib.suppress(OSError):
                os.replace(old, target)
        raise
    _remove(old)
