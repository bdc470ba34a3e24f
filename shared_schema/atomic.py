"""Atomic file writes (no third-party imports, so numerical code may use them).

The data go to a temporary file in the target's directory, are flushed, ``fsync``-ed and
renamed over the target, so a reader (or a crash) never sees half a file. The temporary
file's name says whose it is, ``.<name>.<pid>-<token>.rockmech.tmp``: one left by a run that
was killed is recognised by :func:`stale_temps` (its process no longer exists) and removed
by :func:`remove_stale_temps`, which the command line calls on its output folder before a
run.
"""

import os
import re
import secrets
import stat
from pathlib import Path
from typing import List, Union

__all__ = [
    "NEW_FILE_MODE",
    "TEMP_SUFFIX",
    "PathLike",
    "pid_alive",
    "remove_stale_temps",
    "stale_temps",
    "temp_name",
    "write_atomic",
]

PathLike = Union[str, "os.PathLike[str]"]

#: Permissions of a newly created file (an existing file keeps its own).
NEW_FILE_MODE = 0o644
#: Ending of the temporary files of ``write_atomic``.
TEMP_SUFFIX = ".rockmech.tmp"
#: ``.<target name>.<pid>-<token>.rockmech.tmp``.
_TEMP_NAME = re.compile(r"^\..+\.(?P<pid>[0-9]+)-[0-9a-f]+" + re.escape(TEMP_SUFFIX) + "$")


def temp_name(target: str, pid: int, token: str) -> str:
    """Return the name of ``write_atomic``'s temporary file for ``target``.

    Examples
    --------
    >>> temp_name("result.json", 4242, "9f3a")
    '.result.json.4242-9f3a.rockmech.tmp'
    """
    return f".{target}.{pid}-{token}{TEMP_SUFFIX}"


def pid_alive(pid: int) -> bool:
    """Return whether process ``pid`` exists (another user's counts); always True off POSIX.

    Off POSIX there is no harmless probe (``os.kill(pid, 0)`` sends CTRL+C on Windows), so
    every process is taken to be alive and nothing is cleaned there.
    """
    if os.name != "posix":
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process: alive
        return True
    except OverflowError:  # not a pid this system can have
        return False
    return True


def stale_temps(folder: PathLike) -> List[Path]:
    """Return ``write_atomic``'s temporary files in ``folder`` whose process has ended."""
    directory = Path(folder)
    try:
        entries = list(directory.iterdir())
    except OSError:
        return []
    found = []
    for path in entries:
        match = _TEMP_NAME.match(path.name)
        if match is not None and not pid_alive(int(match.group("pid"))) and path.is_file():
            found.append(path)
    return sorted(found)


def remove_stale_temps(folder: PathLike) -> List[Path]:
    """Remove the temporary files left in ``folder`` by killed runs; return those removed.

    A file whose process still runs is left alone, and so is one that cannot be removed.
    """
    removed = []
    for path in stale_temps(folder):
        try:
            path.unlink()
        except OSError:
            continue
        removed.append(path)
    return removed


def write_atomic(path: PathLike, data: Union[str, bytes]) -> None:
    """Write ``data`` to ``path`` atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Target file. Its directory must exist.
    data : str or bytes
        The content; ``str`` is encoded as UTF-8. Written byte for byte (no newline
        translation, also on Windows).

    Raises
    ------
    TypeError
        If ``data`` is neither ``str`` nor ``bytes``.
    OSError
        If the file cannot be written; the previous file is then left unchanged and the
        temporary file is removed.

    Notes
    -----
    The data go to a temporary file in the same directory (named by ``temp_name``), which
    is flushed, ``fsync``-ed and renamed over the target with ``os.replace`` (atomic on POSIX
    and Windows). An existing target keeps its permission bits; a new one gets
    ``NEW_FILE_MODE``.
    """
    if isinstance(data, str):
        payload = data.encode("utf-8")
    elif isinstance(data, bytes):
        payload = data
    else:
        raise TypeError(f"data must be str or bytes, got {type(data).__name__}")
    target = Path(path)
    try:
        mode = stat.S_IMODE(target.stat().st_mode)
    except FileNotFoundError:
        mode = NEW_FILE_MODE
    tmp_name = str(target.parent / temp_name(target.name, os.getpid(), secrets.token_hex(4)))
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    fd = os.open(tmp_name, flags, 0o600)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(payload)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp_name, mode)
        os.replace(tmp_name, target)
    except BaseException:
        try:
            os.unlink(tmp_name)
        except FileNotFoundError:
            pass
        raise
    _fsync_directory(target.parent)


def _fsync_directory(directory: Path) -> None:
    # Make the rename itself durable. Windows cannot open a directory; it is skipped there.
    if os.name != "posix":
        return
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
