"""Cheap checks of uploaded files, made in the app before a compute process reads them.

Uploads never name a path on the server (``safe_filename``). A ``.3dm`` scene is checked
against the openNURBS archive layout (:func:`cad_maths.archive_3dm.check_3dm`, the one home
of that check, which the scene reader repeats) before a compute process is spent on it. A
record file is refused when its lines of numbers alone prove it holds more samples than a
request may carry (``check_record_lines``): every record format has at least one sample on
each data line, so the count is a lower bound, made on the bytes without parsing them (a
one-column record of 7.5 million lines, 30 MB, took a compute process 3-14 s and 874 MB to
parse before it was refused).
"""

from __future__ import annotations

import re
from typing import Optional

from shared_schema.errors import InputError

__all__ = ["MAX_NAME", "RECORD_HEADER_LINES", "check_record_lines", "data_lines", "safe_filename"]

#: Lines with digits a record file may have besides its data (headers: PEER 4, K-NET 17,
#: ESM 64, COSMOS a few dozen; comments), counted generously.
RECORD_HEADER_LINES = 1000
#: Digits become "1"; every other byte but the newline is dropped (``data_lines``).
_DIGITS = bytes.maketrans(b"0123456789", b"1111111111")
_NOT_DIGIT_OR_NEWLINE = bytes(b for b in range(256) if b not in b"0123456789\n")


def data_lines(data: bytes) -> int:
    r"""Count the lines of ``data`` that hold at least one digit (C speed, one copy).

    Examples
    --------
    >>> data_lines(b"# header\n0.1\n\n-0.2 0.3\n4")
    3
    """
    kept = data.translate(_DIGITS, _NOT_DIGIT_OR_NEWLINE)
    return kept.count(b"1\n") + (1 if kept.endswith(b"1") else 0)


def check_record_lines(data: bytes, max_samples: int, field: str = "record") -> None:
    """Refuse a record file that certainly holds more than ``max_samples`` samples.

    Raises
    ------
    InputError
        More than ``max_samples + RECORD_HEADER_LINES`` lines hold numbers (the message
        names ``ROCKMECH_MAX_SAMPLES``).
    """
    limit = max_samples + RECORD_HEADER_LINES
    if data.count(b"\n") < limit:  # fewer lines of any kind: nothing to count
        return
    lines = data_lines(data)
    if lines > limit:
        raise InputError(
            f"the file has {lines} lines of numbers, so more than the service's limit of "
            f"{max_samples} samples per request (ROCKMECH_MAX_SAMPLES); resample or cut the "
            "record, or run it with the rockmech command line",
            field,
        )


#: Longest file name kept from an upload (characters).
MAX_NAME = 100
#: Characters kept in an uploaded file's name; others become "_".
_NAME_OK = re.compile(r"[^A-Za-z0-9._-]")


def safe_filename(name: Optional[str], default: str) -> str:
    """Return the last component of an uploaded file's name, with only safe characters.

    Examples
    --------
    >>> safe_filename("../../etc/passwd", "record.dat")
    'passwd'
    >>> safe_filename("", "record.dat")
    'record.dat'
    """
    base = re.split(r"[\\/]", name or "")[-1]
    base = _NAME_OK.sub("_", base).lstrip(".")[-MAX_NAME:]
    return base or default
