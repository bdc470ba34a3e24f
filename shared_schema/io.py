"""Reading and writing kinematic-constants files.

Writes are atomic: the text goes to a temporary file in the target's directory, is flushed
to disk and then renamed over the target, so a reader (or a crash) never sees half a file.
Errors are ``InputError`` and name the file; validation errors also name the mechanism
(index and id) and the field.
"""

from shared_schema.atomic import write_atomic
from shared_schema.constants import ConstantsFile, parse_constants
from shared_schema.errors import InputError
from shared_schema.paths import PathLike, as_path
from shared_schema.text import decode_text
from shared_schema.version import __version__

__all__ = [
    "CONSTANTS_EXPECTED",
    "parse_constants",
    "read_constants",
    "stamped",
    "write_atomic",
    "write_constants",
]


#: What a constants file must be, for the messages on empty or binary files.
CONSTANTS_EXPECTED = (
    'a kinematic-constants file (JSON, {"mechanisms": [...]}; or a constants table, .csv or .xlsx)'
)


def read_constants(path: PathLike) -> ConstantsFile:
    """Read and validate a kinematic-constants file.

    Parameters
    ----------
    path : str or os.PathLike
        A JSON file: an object ``{"schema_version": ..., "mechanisms": [...]}`` (only
        ``mechanisms`` is required) or a bare list of mechanisms; UTF-8 (a byte-order mark
        is allowed) or UTF-16 with one (``shared_schema.text.decode_text``).

    Returns
    -------
    ConstantsFile
        The validated file, with derived constants filled in.

    Raises
    ------
    InputError
        If the path is not a ``str`` or ``os.PathLike`` (field ``constants``), or the file is
        missing, a folder, unreadable, empty or binary, is not JSON, or holds invalid values.
        The message starts with the file name; for invalid values it then names the
        mechanism and the field, e.g. ``walls.json: mechanisms[1] (id 'W2').positive.p_eq: ...``.
    """
    file = as_path(path, "constants")
    if file.is_dir():
        raise InputError("is a folder, not a constants file", str(file))
    try:
        raw = file.read_bytes()
    except FileNotFoundError:
        raise InputError("constants file not found", str(file)) from None
    except OSError as exc:
        raise InputError(f"cannot read constants file: {exc.strerror or exc}", str(file)) from exc
    text = decode_text(raw, "the file", str(file), CONSTANTS_EXPECTED)
    try:
        return parse_constants(text)
    except InputError as exc:
        raise InputError(str(exc), str(file)) from exc


def stamped(model: ConstantsFile) -> ConstantsFile:
    """Return the constants with ``rockmech_version`` set to this version (the writer's).

    Every constants file rockmech writes or answers carries it, beside its ``units``.
    """
    return model.model_copy(update={"rockmech_version": __version__})


def write_constants(constants: ConstantsFile, path: PathLike) -> None:
    """Write a kinematic-constants file atomically.

    Parameters
    ----------
    constants : ConstantsFile
        The constants. Absent optional values (``None``) are omitted, so an optional
        section that was not given does not appear in the file.
    path : str or os.PathLike
        Target file; it is replaced atomically.

    Raises
    ------
    InputError
        If ``constants`` is not a ``ConstantsFile`` (field ``constants``; the object comes
        first, the path second), the path is not a ``str`` or ``os.PathLike`` (field
        ``path``), or the file cannot be written (e.g. its folder does not exist, or it is
        a folder; field ``path``, the message naming it).

    Notes
    -----
    The JSON is built completely before anything is written, so a serialisation error
    leaves the previous file untouched. Output: indent 2, UTF-8, trailing newline.
    """
    if not isinstance(constants, ConstantsFile):
        first = isinstance(path, ConstantsFile)
        hint = "; the constants come first: write_constants(constants, path)" if first else ""
        raise InputError(
            f"must be a ConstantsFile, got {type(constants).__name__}{hint}", "constants"
        )
    target = as_path(path, "path")
    text = stamped(constants).model_dump_json(indent=2, exclude_none=True) + "\n"
    if target.is_dir():
        raise InputError(f"cannot write constants file: it is a folder: {target}", "path")
    try:
        write_atomic(target, text)
    except OSError as exc:
        raise InputError(
            f"cannot write constants file: {target}: {exc.strerror or exc}", "path"
        ) from exc
