"""Cheap checks of uploaded files, made in the app before a compute process reads them.

Uploads never name a path on the server (``safe_filename``). A ``.3dm`` scene is checked
against the openNURBS archive layout (:func:`rhino_plugin.archive_3dm.check_3dm`, the one home
of that check, which the scene reader repeats) before a compute process is spent on it.
"""

from __future__ import annotations

import re
from typing import Optional

__all__ = ["MAX_NAME", "safe_filename"]

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
