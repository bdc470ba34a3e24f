"""Reading and writing kinematic-constants files.

Writes are atomic: the text goes to a temporary file in the target's directory, is flushed
to disk and then renamed over the target, so a reader (or a crash) never sees half a file.
Errors are ``InputError`` and name the file; validation errors also name the mechanism
(index and id) and the field.
"""

import os
import stat
import tempfile
from pathlib import Path
from typing import Union

from shared_schema.constants import ConstantsFile, parse_constants
from shared_schema.errors import InputError

__all__ = ["load_constants", "parse_constants", "save_constants", "write_json_atomic"]

PathLike = Union[str, "os.PathLike[str]"]

#: Permissions of a newly created file (an existing file keeps its own).
NEW_FILE_MODE = 0o644


def write_json_atomic(path: PathLike, data: Union[str, bytes]) -> None:
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


def load_constants(path: PathLike) -> ConstantsFile:
    """Read and validate a kinematic-constants file.

    Parameters
    ----------
    path : str or os.PathLike
        A JSON file: an object ``{"schema_version": ..., "mechanisms": [...]}`` (only
        ``mechanisms`` is required) or a bare list of mechanisms. A UTF-8 byte-order mark
        is allowed.

    Returns
    -------
    ConstantsFile
        The validated file, with derived constants filled in.

    Raises
    ------
    InputError
        If the file is missing or unreadable, is not JSON, or holds invalid values. The
        message starts with the file name; for invalid values it then names the mechanism
        and the field, e.g. ``walls.json: mechanisms[1] (id 'W2').positive.p_eq: ...``.
    """
    file = Path(path)
    try:
        raw = file.read_bytes()
    except FileNotFoundError:
        raise InputError("constants file not found", str(file)) from None
    except OSError as exc:
        raise InputError(f"cannot read constants file: {exc.strerror or exc}", str(file)) from exc
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(f"constants file is not UTF-8 text: {exc}", str(file)) from exc
    try:
        return parse_constants(text)
    except InputError as exc:
        raise InputError(str(exc), str(file)) from exc


def save_constants(path: PathLike, model: ConstantsFile) -> None:
    """Write a kinematic-constants file atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Target file; it is replaced atomically.
    model : ConstantsFile
        The constants. Absent optional values (``None``) are omitted, so an optional
        section that was not given does not appear in the file.

    Raises
    ------
    InputError
        If the file cannot be written (e.g. its directory does not exist).

    Notes
    -----
    The JSON is built completely before anything is written, so a serialisation error
    leaves the previous file untouched. Output: indent 2, UTF-8, trailing newline.
    """
    text = model.model_dump_json(indent=2, exclude_none=True) + "\n"
    try:
        write_json_atomic(path, text)
    except OSError as exc:
        raise InputError(
            f"cannot write constants file: {exc.strerror or exc}", os.fspath(path)
        ) from exc
