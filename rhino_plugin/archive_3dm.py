"""Cheap layout check of a ``.3dm`` file, made before rhino3dm reads it.

rhino3dm trusts the lengths a file declares: a 20 kB upload with one length set to 2^63 - 1
kept it busy for half a minute (49 s measured with the length of an object record, read
from memory). :func:`check_3dm` walks the file's chunks in milliseconds and refuses such
files with the message ``rockmech constants`` gives for any unreadable scene. The service
calls it on an upload before a compute process is spent; :meth:`Scene.from_3dm` and
:meth:`Scene.from_bytes` call it before rhino3dm.

Standard library only (the service's app process imports it), Python 3.9-clean.

The openNURBS layout (``opennurbs_3dm.h``, ``opennurbs_archive.h``)
-------------------------------------------------------------------
A 32-byte header, ``"3D Geometry File Format "`` and the archive version right-aligned in 8
characters, then a sequence of chunks: a 4-byte type code and a length, 4 bytes in archives
before version 50 and 8 bytes from version 50 (Rhino 5) on, both little-endian. Type codes
with the ``TCODE_SHORT`` bit hold a value in the length field and no content; the others are
followed by ``length`` bytes of content. A chunk with ``TCODE_CRC`` ends with a 4-byte CRC
inside its length.

Chunks whose content is itself a sequence of chunks are walked too (``CONTAINERS``): tables
(``TCODE_TABLE``), the records of objects, lights, layers, materials and the other model
components (``TCODE_OBJECT_RECORD`` and the records "derived from ON_..."), the class chunk of
every stored object (``TCODE_OPENNURBS_CLASS``: class id, data, user data, end) and the
user-data lists of attributes. An object's own data (``TCODE_OPENNURBS_CLASS_DATA``), user data
and the settings records mix raw bytes with chunks and are not walked. Every declared length
walked must fit in what is left of the enclosing chunk, and the top level must end with
``TCODE_ENDOFFILE``. The walk is bounded: ``MAX_DEPTH`` levels and ``MAX_CHUNKS`` chunks; past
either, what is left is not walked (the file is not refused for it).
"""

import os
import struct
from typing import FrozenSet, List, Optional, Tuple, Union

from shared_schema.errors import InputError

__all__ = ["CONTAINERS", "MAX_CHUNKS", "MAX_DEPTH", "check_3dm", "check_3dm_file", "layout_problem"]

_HEADER = b"3D Geometry File Format "
#: openNURBS type-code bits and codes (opennurbs_3dm.h).
TCODE_SHORT = 0x80000000
TCODE_TABLE = 0x10000000
TCODE_TABLEREC = 0x20000000
TCODE_CRC = 0x00008000
TCODE_ENDOFFILE = 0x00007FFF
#: Chunks (besides tables) whose content is a sequence of chunks (opennurbs_3dm.h): the
#: object, light, material, layer, group, font, dimension-style, instance-definition,
#: hatch-pattern, linetype, texture-mapping, history and bitmap records; the openNURBS class
#: chunk; the user-data lists of object and light attributes.
CONTAINERS: FrozenSet[int] = frozenset(
    [TCODE_TABLEREC | TCODE_CRC | code for code in (0x40, 0x50, 0x60, 0x70, 0x90)]
    + [TCODE_TABLEREC | TCODE_CRC | code for code in range(0x73, 0x7C) if code != 0x79]
    + [0x00027FFA, 0x02000073, 0x02000062]
)
#: Deepest nesting walked (real files nest four deep: table, record, class, class id).
MAX_DEPTH = 8
#: Most chunks walked (a scene of 10,000 objects has about 100,000).
MAX_CHUNKS = 2_000_000

_Source = Union[bytes, bytearray, memoryview]


def layout_problem(data: _Source) -> Optional[str]:
    """Return what is wrong with the chunk layout of a ``.3dm`` file, or None.

    Parameters
    ----------
    data : bytes
        The whole file.

    Examples
    --------
    >>> layout_problem(b"not a model")
    'no .3dm header'
    """
    if len(data) < 32 or bytes(data[:24]) != _HEADER:
        return "no .3dm header"
    try:
        version = int(bytes(data[24:32]).decode("ascii").strip())
    except ValueError:
        return "no archive version in the header"
    fmt = "<IQ" if version >= 50 else "<II"
    step = struct.calcsize(fmt)
    # (start, end, depth) of chunk sequences still to walk.
    todo: List[Tuple[int, int, int]] = [(32, len(data), 0)]
    top_ended = False
    walked = 0
    while todo:
        pos, end, depth = todo.pop()
        while pos < end:
            if end - pos < step:
                return f"a chunk header at byte {pos} is cut off"
            code, length = struct.unpack_from(fmt, data, pos)
            pos += step
            walked += 1
            if walked > MAX_CHUNKS:
                return None  # the rest is left to rhino3dm: no file is refused for its size
            if code & TCODE_SHORT:
                continue
            if length > end - pos:
                return f"a chunk at byte {pos - step} declares {length} bytes; {end - pos} remain"
            if depth == 0 and code == TCODE_ENDOFFILE:
                top_ended = True
            nested = (code & TCODE_TABLE and depth == 0) or code in CONTAINERS
            if nested and depth < MAX_DEPTH:
                inner = length - 4 if code & TCODE_CRC else length
                if inner >= 0:
                    todo.append((pos, pos + inner, depth + 1))
            pos += length
    if not top_ended:
        return "no end-of-file chunk"
    return None


def check_3dm(data: _Source, name: str) -> None:
    """Refuse a ``.3dm`` file whose declared sizes do not fit the file.

    Parameters
    ----------
    data : bytes
        The whole file.
    name : str
        The file's name, for the message.

    Raises
    ------
    InputError
        The message ``rockmech constants`` gives for an unreadable scene (field ``scene``).
    """
    if layout_problem(data) is not None:
        raise InputError(
            f"cannot read {name} as a .3dm file (truncated, corrupt or not a Rhino model)",
            "scene",
        )


def check_3dm_file(path: Union[str, "os.PathLike[str]"]) -> None:
    """:func:`check_3dm` on a file on disk, named by its path in the message.

    Raises
    ------
    InputError
        As :func:`check_3dm`; also when the file cannot be read (field ``scene``).
    """
    p = os.fspath(path)
    try:
        with open(p, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        raise InputError(f"cannot read {p}: {exc.strerror or exc}", "scene") from None
    check_3dm(data, p)
