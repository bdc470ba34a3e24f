"""Cheap checks of uploaded files, made in the app before a compute process reads them.

Uploads never name a path on the server (``safe_filename``). A ``.3dm`` scene is checked
against the openNURBS archive layout before rhino3dm sees it: rhino3dm trusts the lengths a
file declares, and a 20 kB file with one length set to 2^63 - 1 kept it busy for half a
minute. The check takes milliseconds and refuses such files with the message ``rockmech
constants`` gives for any unreadable scene.

The openNURBS layout (``opennurbs_archive.h``)
----------------------------------------------
A 32-byte header, ``"3D Geometry File Format "`` and the archive version right-aligned in 8
characters, then a sequence of chunks: a 4-byte type code and a length, 4 bytes in archives
before version 50 and 8 bytes from version 50 (Rhino 5) on, both little-endian. Type codes
with the ``TCODE_SHORT`` bit hold a value in the length field and no content; the others are
followed by ``length`` bytes of content. Tables (``TCODE_TABLE``) hold sequences of chunks
themselves (their records, whose content is the object's own, are not followed); a chunk
with ``TCODE_CRC`` ends with a 4-byte CRC inside its length. Every declared length, at the
top level and in tables, must fit in what is left of the enclosing chunk, and the top level
must end with ``TCODE_ENDOFFILE``.
"""

from __future__ import annotations

import re
import struct
from typing import Optional

from shared_schema.errors import InputError

__all__ = ["MAX_NAME", "check_3dm", "safe_filename"]

#: Longest file name kept from an upload (characters).
MAX_NAME = 100
#: Characters kept in an uploaded file's name; others become "_".
_NAME_OK = re.compile(r"[^A-Za-z0-9._-]")

_HEADER = b"3D Geometry File Format "
#: openNURBS type-code bits and codes (opennurbs_3dm.h).
TCODE_SHORT = 0x80000000
TCODE_TABLE = 0x10000000
TCODE_CRC = 0x00008000
TCODE_ENDOFFILE = 0x00007FFF
#: Deepest nesting of tables followed (real files nest one deep).
MAX_DEPTH = 8


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


def _layout_problem(data: bytes) -> Optional[str]:
    """Return what is wrong with the chunk layout of a .3dm file, or None."""
    if len(data) < 32 or not data.startswith(_HEADER):
        return "no .3dm header"
    try:
        version = int(data[24:32].decode("ascii").strip())
    except ValueError:
        return "no archive version in the header"
    size = 8 if version >= 50 else 4
    fmt = "<IQ" if size == 8 else "<II"
    step = 4 + size
    # (start, end, depth) of chunk sequences still to walk.
    todo = [(32, len(data), 0)]
    top_ended = False
    while todo:
        pos, end, depth = todo.pop()
        while pos < end:
            if end - pos < step:
                return f"a chunk header at byte {pos} is cut off"
            code, length = struct.unpack_from(fmt, data, pos)
            pos += step
            if code & TCODE_SHORT:
                continue
            if length > end - pos:
                return f"a chunk at byte {pos - step} declares {length} bytes; {end - pos} remain"
            if depth == 0 and code == TCODE_ENDOFFILE:
                top_ended = True
            if code & TCODE_TABLE and depth < MAX_DEPTH:
                inner = length - 4 if code & TCODE_CRC else length
                if inner >= 0:
                    todo.append((pos, pos + inner, depth + 1))
            pos += length
    if not top_ended:
        return "no end-of-file chunk"
    return None


def check_3dm(data: bytes, name: str) -> None:
    """Refuse a ``.3dm`` upload whose declared sizes do not fit the file.

    Raises
    ------
    InputError
        The message ``rockmech constants`` gives for an unreadable scene (field ``scene``).
    """
    problem = _layout_problem(data)
    if problem is not None:
        raise InputError(
            f"cannot read {name} as a .3dm file (truncated, corrupt or not a Rhino model)",
            "scene",
        )
