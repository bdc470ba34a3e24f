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

CRCs (archives of version 50 and later)
---------------------------------------
A long chunk whose type code has ``TCODE_CRC`` ends with the CRC-32 (zlib's, initial value 0,
little-endian) of its *own* bytes: the bytes the writer put in it directly, without the
headers and contents of the chunks nested in it, which carry their own
(``ON_BinaryArchive::EndWrite3dmChunk`` and ``EndRead3dmChunk``: the CRC is accumulated only
while the innermost open chunk asks for one). A bit flipped anywhere in such bytes changes
the CRC; openNURBS only counts the mismatch and reads on, and rhino3dm then spent 20-30 s on
one flipped bit of a Brep (and crashed the interpreter on another). :func:`crc_problem`
recomputes the CRCs:

* a chunk whose content is exactly a sequence of chunks (records, class chunks) is checked
  through its children (its own bytes are none: its CRC is that of no bytes, 0);
* in a chunk that mixes raw bytes with nested chunks (an object's data: counts, numbers and
  the chunks of its sub-objects), the nested chunks are found by their headers: a type code
  of the openNURBS categories with ``TCODE_CRC`` (or one of the containers above) and a
  length that fits, whose own CRC (or whose children's) matches. Those are taken out, and
  the CRC of the rest must match. A header of a nested chunk (an anonymous chunk, a class
  id or class data chunk: ``STRONG``) that fits but fails its own CRC makes the file damaged;
* chunks without ``TCODE_CRC`` (the comment block, the user table's plug-in data) cannot be
  checked and are passed.

The search for nested headers uses the top three bytes of an 8-byte length, which are zero
in any file under 1 TB, as an anchor (``bytes.find``), so a 5 MB scene is checked in tens
of milliseconds. A header that only looks like one (raw numbers) is not taken unless its
CRC matches, a chance of 2^-32. The work is bounded (``CRC_WORK_PER_BYTE``); past it the
rest is passed unchecked.
"""

import os
import re
import struct
import zlib
from bisect import bisect_left
from typing import Dict, FrozenSet, List, Optional, Tuple, Union

from shared_schema.errors import InputError

__all__ = [
    "CONTAINERS",
    "MAX_CHUNKS",
    "MAX_DEPTH",
    "STRONG",
    "check_3dm",
    "check_3dm_file",
    "crc_problem",
    "layout_problem",
]

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
#: Type-code bits of the openNURBS categories (legacy geometry, openNURBS object, geometry,
#: annotation, display, render, interface, tolerance, table, table record, user).
TCODE_CATEGORIES = 0x7AF30000
#: ``TCODE_ANONYMOUS_CHUNK``, ``TCODE_OPENNURBS_CLASS_UUID``, ``TCODE_OPENNURBS_CLASS_DATA``:
#: the chunks an object's data nests. One of these whose header fits but whose CRC does not
#: match is damage, not raw numbers that look like a header.
STRONG: FrozenSet[int] = frozenset([0x40008000, 0x0002FFF9, 0x0002FFFB, 0x0002FFFC])
#: ``TCODE_OPENNURBS_CLASS`` and what it holds (``ON_BinaryArchive::WriteObject``): the class
#: id, then (unless the object is null) the class data, user data, and the end mark.
TCODE_CLASS = 0x00027FFA
TCODE_CLASS_UUID = 0x0002FFFB
TCODE_CLASS_DATA = 0x0002FFFC
TCODE_CLASS_END = 0x80027FFF
#: ``TCODE_OPENNURBS_CLASS_USERDATA``: a version byte, a header chunk and the data chunk.
TCODE_CLASS_USERDATA = 0x00027FFD
#: Bytes of CRC work allowed per byte of the file (nested chunks are checked once each).
CRC_WORK_PER_BYTE = 8

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
    return crc_problem(data) if version >= 50 else None


class _CrcCheck:
    """The CRCs of a V5+ archive (see the module's notes); one instance per file."""

    _LONG = struct.Struct("<IQ")

    def __init__(self, data: _Source) -> None:
        self.data = bytes(data)
        self.results: Dict[Tuple[int, int, int], Optional[bool]] = {}
        self.work = 0
        self.budget = CRC_WORK_PER_BYTE * len(self.data) + 1_000_000
        #: (header offset, type code) of the innermost chunk found damaged, if any.
        self.damage: Optional[Tuple[int, int]] = None
        self.headers = self._headers()

    def _headers(self) -> List[int]:
        """Offsets of every byte sequence that may be a nested chunk's header, sorted.

        A header at q (32 or more) has its length's top three bytes, zero, at q + 9 and a
        type code that ``_nested_code`` accepts. ``_HEADER_AT`` finds (in C) every such q + 9
        whose code may pass; each code is then checked exactly.
        """
        data = self.data
        unpack = self._LONG.unpack_from
        return [
            q
            for q in (m.start() - 9 for m in _HEADER_AT.finditer(data, 41))
            if _nested_code(unpack(data, q)[0])
        ]

    def sequence(self, start: int, end: int) -> Optional[List[Tuple[int, int, int]]]:
        """Return (code, content start, content end) of the chunks exactly filling [start, end).

        A short chunk has no content (start = end); None when the chunks do not fill it.
        """
        out: List[Tuple[int, int, int]] = []
        while start < end:
            if end - start < 12:
                return None
            code, length = self._LONG.unpack_from(self.data, start)
            start += 12
            if code & TCODE_SHORT:
                out.append((code, start, start))
                continue
            if length > end - start:
                return None
            out.append((code, start, start + length))
            start += length
        return out

    def chunk(self, code: int, start: int, end: int) -> Optional[bool]:
        """Check the chunk whose content is [start, end).

        Returns
        -------
        True when a CRC in it matched and none failed (it is a real chunk, undamaged as far as
        its CRCs tell), False when one failed or its layout is not openNURBS' (damaged), None
        when nothing in it can be checked.
        """
        key = (code, start, end)
        if key not in self.results:
            self.work += end - start
            self.results[key] = None if self.work > self.budget else self._chunk(code, start, end)
        return self.results[key]

    def children(self, chunks: List[Tuple[int, int, int]]) -> Optional[bool]:
        """Return False if one of ``chunks`` is damaged, else True if one was checked, else None."""
        outcome: Optional[bool] = None
        for code, start, end in chunks:
            if not code & TCODE_SHORT:
                ok = self.chunk(code, start, end)
                if ok is False:
                    self._damaged(code, start)
                    return False
                outcome = outcome or ok
        return outcome

    def _damaged(self, code: int, start: int) -> None:
        """Remember the first (innermost) chunk found damaged: its content starts at ``start``."""
        if self.damage is None:
            self.damage = (start - 12, code)

    def _chunk(self, code: int, start: int, end: int) -> Optional[bool]:
        if not code & TCODE_CRC:
            inner = self.sequence(start, end)
            if code == TCODE_CLASS and not _class_layout(inner):
                return False
            if inner is not None:
                return self.children(inner)
            _, found, damaged = self._mixed(start, end)
            return False if damaged else (True if found else None)
        if end - start < 4:
            return False
        own_end = end - 4
        stored = struct.unpack_from("<I", self.data, own_end)[0]
        inner = self.sequence(start, own_end)
        if inner is not None and stored == 0:  # records, class chunks: no bytes of their own
            return self.children(inner) is not False
        crc, _, damaged = self._mixed(start, own_end)
        return not damaged and crc == stored

    def _mixed(self, start: int, end: int) -> Tuple[int, bool, bool]:
        """Check the raw bytes of [start, end), mixed with nested chunks.

        Returns the CRC of the raw bytes, whether a nested chunk was found, and whether a
        ``STRONG`` one is damaged.
        """
        data, headers = self.data, self.headers
        crc, pos, found = 0, start, False
        i = bisect_left(headers, start)
        while i < len(headers) and headers[i] + 12 <= end:
            q = headers[i]
            i += 1
            if q < pos:
                continue
            code, length = self._LONG.unpack_from(data, q)
            strong = code in STRONG
            if length > end - q - 12:
                if strong:  # a nested chunk's header that no longer fits: a damaged length
                    self._damaged(code, q + 12)
                    return crc, found, True
                continue
            ok = self.chunk(code, q + 12, q + 12 + length)
            if ok:
                crc, pos, found = zlib.crc32(data[pos:q], crc), q + 12 + length, True
            elif ok is False and strong:
                self._damaged(code, q + 12)
                return crc, found, True
        return zlib.crc32(data[pos:end], crc), found, False


def _header_at() -> "re.Pattern[bytes]":
    """Compile the pattern of the candidates of ``_CrcCheck._headers``.

    A candidate is 3 zero bytes (the match's start and the two that follow it, looked ahead
    at so that overlapping candidates are all found) 9 bytes after a type code that may pass
    ``_nested_code``: one with ``TCODE_CRC`` (its second byte 0x80 or more) or a nested code
    without it (looked behind at). The match starts with a literal byte, which the
    regular-expression engine scans for in C.
    """
    plain = sorted(c for c in CONTAINERS | {TCODE_CLASS_USERDATA} if not c & TCODE_CRC)
    codes = [rb".[\x80-\xff].."] + [re.escape(struct.pack("<I", c)) for c in plain]
    return re.compile(rb"\x00(?=\x00\x00)(?<=(?:" + b"|".join(codes) + rb").{5}\x00)", re.DOTALL)


_HEADER_AT = _header_at()


def _class_layout(inner: Optional[List[Tuple[int, int, int]]]) -> bool:
    """Return whether a ``TCODE_OPENNURBS_CLASS`` chunk's chunks are laid out as written.

    openNURBS writes the class id; unless the object is null, the class data, then anything
    (user data, chunks of later versions), then the end mark.
    """
    if not inner or inner[0][0] != TCODE_CLASS_UUID:
        return False
    return len(inner) == 1 or (inner[1][0] == TCODE_CLASS_DATA and inner[-1][0] == TCODE_CLASS_END)


def _nested_code(code: int) -> bool:
    """Return whether ``code`` may head a long chunk nested in raw bytes (``_CrcCheck``)."""
    if code in CONTAINERS or code == TCODE_CLASS_USERDATA:
        return True
    return (
        bool(code & TCODE_CRC)
        and not code & TCODE_SHORT
        and not code & 0xFFFF0000 & ~TCODE_CATEGORIES
    )


def crc_problem(data: _Source) -> Optional[str]:
    """Return which chunk of a V5+ ``.3dm`` file fails its CRC, or None.

    The file's layout must already be sound (:func:`layout_problem` calls this last).

    Parameters
    ----------
    data : bytes
        The whole file.
    """
    check = _CrcCheck(data)
    top = check.sequence(32, len(check.data))
    if top is None:
        return None
    for code, start, end in top:
        if check.chunk(code, start, end) is False:
            at, what = check.damage or (start - 12, code)
            return (
                f"the chunk at byte {at} (type {what:#010x}) fails its CRC check: the file is "
                "damaged; open it in Rhino (Audit3dmFile) and save it again, or use a backup"
            )
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
    problem = layout_problem(data)
    if problem is not None:
        raise InputError(
            f"cannot read {name} as a .3dm file (truncated, corrupt or not a Rhino model): "
            f"{problem}",
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
