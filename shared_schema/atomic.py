"""Atomic file writes (no third-party imports, so numerical code may use them).

The data go to a temporary file in the target's directory, are flushed, ``fsync``-ed and
renamed over the target, so a reader (or a crash) never sees half a file.
"""

import os
import stat
import tempfile
from pathlib import Path
from typing import Union

__all__ = ["NEW_FILE_MODE", "PathLike", "write_atomic"]

PathLike = Union[str, "os.PathLike[str]"]

#: Permissions of a newly created file (an existing file keeps its own).
NEW_FILE_MODE = 0o644


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
    The data go to a temporary file in the same directory, which is flushed, ``fsync``-ed and
    renamed over the target with ``os.replace`` (atomic on POSIX and Windows). An existing
    target keeps its permission bits; a new one gets ``NEW_FILE_MODE``.
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
    fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
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
