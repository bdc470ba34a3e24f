"""Scan meshes as scenes: PLY, OBJ, STL and OFF files read with trimesh.

A scan (photogrammetry, laser) is a triangle mesh with no units and no line or plane
objects, so a :class:`MeshScene` differs from a ``.3dm`` scene in three ways:

- the length unit is given by the caller (``units``: mm, cm, m, in or ft) and is required;
- its objects are the meshes the file names: OBJ objects (``o`` lines), else OBJ groups
  (``g`` lines), else one object named after the file's stem (PLY, STL, OFF, plain OBJ);
- axes, cracks and hinges must be given in the spec by points [m] (``axis.start``/``end``,
  ``crack.points``); asking a scan for a line or a plane names the object and says so.

Every mesh goes through the same welding, winding and closed-solid checks as a ``.3dm``
mesh (:func:`~cad_maths.scene_base.solid_mesh`). trimesh is imported lazily, with
``process=False`` so that it neither merges nor reorders anything before those checks.

Python 3.9-clean (the Rhino side may import it; trimesh <= 4.12 works).
"""

import io
import os
import re
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

from cad_maths.geometry.mesh import TriMesh
from cad_maths.scene_base import BaseScene, SceneObject, solid_mesh
from shared_schema.errors import GeometryError, InputError

__all__ = ["SCAN_FORMATS", "UNITS", "MeshScene", "unit_ratio"]

#: File extensions read as scan meshes (lower case, without the dot).
SCAN_FORMATS = ("ply", "obj", "stl", "off")

#: Length units a scan may be given in: short name -> (long name, exact metres ratio
#: (numerator, denominator)), so that 1000 mm is exactly 1 m.
UNITS: Dict[str, Tuple[str, Tuple[float, float]]] = {
    "mm": ("millimeters", (1.0, 1e3)),
    "cm": ("centimeters", (1.0, 1e2)),
    "m": ("meters", (1.0, 1.0)),
    "in": ("inches", (254.0, 1e4)),
    "ft": ("feet", (3048.0, 1e4)),
}

#: What a spec for a scan must do instead of naming line or plane objects.
POINTS_HINT = (
    "a scan mesh has no line or plane objects: give the axis by its 'start' and 'end' "
    "points [m], each crack by three 'points' [m], and hinges as points"
)

# OBJ statements that name objects and groups (trimesh merges repeated names).
_OBJ_NAME = re.compile(rb"^[ \t]*([og])[ \t]+([^\r\n]*?)[ \t]*$", re.M)


def unit_ratio(units: Optional[str], name: str) -> Tuple[str, Tuple[float, float]]:
    """Long unit name and exact metres ratio of a scan's ``units``.

    Parameters
    ----------
    units : str or None
        ``"mm"``, ``"cm"``, ``"m"``, ``"in"`` or ``"ft"`` (long names such as
        ``"millimeters"`` are accepted too).
    name : str
        The file's name, for the message.

    Raises
    ------
    InputError
        ``units`` missing or unknown (field ``"units"``).
    """
    choices = ", ".join(UNITS)
    if units is None or not str(units).strip():
        ext = os.path.splitext(name)[1].lower() or "scan"
        raise InputError(
            f"{os.path.basename(name)}: a {ext} file carries no length unit; give units "
            f"({choices})",
            "units",
        )
    key = str(units).strip().lower()
    for short, (long, ratio) in UNITS.items():
        if key in (short, long, long.rstrip("s")):
            return long, ratio
    raise InputError(f"unknown units {units!r}; use one of {choices}", "units")


class MeshScene(BaseScene):
    """The meshes of a scan file, in metres.

    Construct with :meth:`from_file` or :meth:`from_bytes`. Each object's ``geometry`` is
    a ``(vertices, faces)`` pair in file units; ``kind`` is ``"mesh"``, ``layer`` ``""``
    and ``id`` ``"<name>#<k>"`` (k counts the file's meshes from 0).

    Examples
    --------
    >>> scene = MeshScene.from_file("examples/scenes/scan_wall.ply", units="mm")
    >>> mesh = scene.mesh(scene.find("scan_wall")[0])
    >>> mesh.vertices.max(axis=0).round(3).tolist()  # x, y, z [m]
    [0.614, 4.0, 5.0]
    """

    scan = True

    def __init__(
        self,
        objects: List[SceneObject],
        unit_scale: float = 1.0,
        units: str = "meters",
        path: Optional[str] = None,
        tolerance: float = 0.0,
    ) -> None:
        super().__init__(objects, unit_scale, units, path, tolerance)
        # OBJ names used by more than one object (trimesh merged them): name -> count
        self._repeated: Dict[str, int] = {}

    # ------------------------------------------------------------------ reading

    @classmethod
    def from_file(
        cls, path: Union[str, "os.PathLike[str]"], *, units: Optional[str]
    ) -> "MeshScene":
        """Read a ``.ply``, ``.obj``, ``.stl`` or ``.off`` file.

        Parameters
        ----------
        path : str or path-like
            The file.
        units : str
            Its length unit: mm, cm, m, in or ft (required: these formats carry none).

        Raises
        ------
        InputError
            Missing file (field ``"scene"``), missing or unknown ``units`` (``"units"``),
            or a file trimesh cannot read (``"scene"``).
        """
        p = os.fspath(path)
        if not os.path.isfile(p):
            raise InputError(f"file not found: {p}", "scene")
        with open(p, "rb") as fh:
            data = fh.read()
        return cls.from_bytes(data, p, units=units)

    @classmethod
    def from_bytes(cls, data: bytes, name: str, *, units: Optional[str]) -> "MeshScene":
        """Read a scan from memory (an upload); ``name``'s extension gives the format.

        Parameters
        ----------
        data : bytes
            The file's content.
        name : str
            File name (``"wall.ply"``): its extension selects the reader and its stem
            names a single-mesh file's object.
        units : str
            Length unit of the coordinates (see :data:`UNITS`).

        Raises
        ------
        InputError
            Unknown extension, missing or unknown ``units``, or unreadable content.
        """
        ext = os.path.splitext(name)[1].lower().lstrip(".")
        if ext not in SCAN_FORMATS:
            raise InputError(
                f"{os.path.basename(name)}: not a scan mesh; use "
                + ", ".join("." + e for e in SCAN_FORMATS),
                "scene",
            )
        long, (num, den) = unit_ratio(units, name)
        stem = os.path.splitext(os.path.basename(name))[0] or "mesh"
        base = os.path.basename(name)
        data = bytes(data)
        if not data.strip():
            raise InputError(
                f"{base} is {'empty (0 bytes)' if not data else 'blank'}: expected a .{ext} "
                "scan mesh; check that it was saved or copied completely",
                "scene",
            )
        if ext == "ply":
            _check_ply(data, base)
        elif ext == "stl":
            _check_stl(data, base)
        elif ext == "off":
            _check_off(data, base)
        try:
            parts, repeated = _load(data, ext, stem)
        except InputError:
            raise
        except Exception as exc:  # trimesh raises many kinds on bad input
            raise InputError(_unreadable(data, ext, base, exc), "scene") from None
        for part_name, v, f in parts:
            _check_indices(v, f, part_name, base, one_based=ext == "obj")
            if f.size == 0:
                # issue #36: random bytes read as an empty mesh were "the mesh has no faces"
                raise InputError(
                    f"{base}: no faces could be read: it is not a valid .{ext} mesh (or holds "
                    f"only points); export the mesh again as .{ext}",
                    "scene",
                )
        objects = [
            SceneObject(id=f"{nm}#{k}", name=nm, layer="", kind="mesh", geometry=(v, f))
            for k, (nm, v, f) in enumerate(parts)
        ]
        scene = cls(objects, unit_scale=num / den, units=long, path=name)
        scene._ratio = (num, den)
        scene._repeated = repeated
        return scene

    # ------------------------------------------------------------------ selection

    def find(self, selector: Union[str, Dict[str, str]]) -> List[SceneObject]:
        """Return the objects matching a selector (see :meth:`BaseScene.find`).

        Raises
        ------
        InputError
            As :meth:`BaseScene.find`; also for a name that several OBJ objects share
            (trimesh merges them, so they cannot be told apart).
        """
        hits = super().find(selector)
        name = selector if isinstance(selector, str) else selector.get("name")
        if name is not None and name in self._repeated:
            where = os.path.basename(self.path) if self.path else "the scene"
            raise InputError(
                f"{self._repeated[name]} meshes are named {name!r} in {where}; give each "
                "rocking body its own OBJ object name",
                "selector",
            )
        return hits

    def _miss_hint(self) -> str:
        return f" ({POINTS_HINT})"

    # ------------------------------------------------------------------ geometry

    def mesh(self, obj: SceneObject, require_closed: bool = True) -> TriMesh:
        """Return the object as a triangle mesh in metres, oriented outward.

        Raises
        ------
        GeometryError
            No faces, or (with ``require_closed``) not a closed solid; names the object.
        """
        v, f = obj.geometry
        return solid_mesh(self._to_m(v, obj), f, obj, require_closed=require_closed)

    def extent(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Lowest and highest corner of the mesh's vertices [m]."""
        v = self._to_m(obj.geometry[0], obj)
        return v.min(axis=0), v.max(axis=0)

    def line(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Refuse: a scan has no line objects (the message says what to give instead)."""
        raise GeometryError(f"{obj.label()}: a mesh is not a line; {POINTS_HINT}")

    def plane(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Refuse: a scan has no plane objects (the message says what to give instead)."""
        raise GeometryError(f"{obj.label()}: a mesh does not define a plane; {POINTS_HINT}")


def _load(
    data: bytes, ext: str, stem: str
) -> Tuple[List[Tuple[str, np.ndarray, np.ndarray]], Dict[str, int]]:
    """Meshes of a scan file as (name, vertices, faces), and OBJ names used twice."""
    import trimesh  # heavy optional dependency (geometry extra)

    if ext != "obj":
        m = trimesh.load_mesh(io.BytesIO(data), file_type=ext, process=False)
        return [(stem, _vertices(m.vertices), _faces(m.faces))], {}
    from trimesh.exchange.obj import load_obj  # the OBJ reader keeps names apart

    statements = _OBJ_NAME.findall(data)
    objects = [n.decode("utf-8", "replace") for k, n in statements if k == b"o"]
    groups = [n.decode("utf-8", "replace") for k, n in statements if k == b"g"]
    by_objects = bool(objects)
    loaded = load_obj(
        io.BytesIO(data),
        group_material=False,
        skip_materials=True,
        maintain_order=True,
        split_objects=by_objects,
        split_groups=not by_objects and bool(groups),
    )
    geometry: Dict[str, Dict[str, Any]] = (
        loaded.get("geometry", {}) if "geometry" in loaded else {"geometry": loaded}
    )
    names = objects if by_objects else groups
    repeated = {n: names.count(n) for n in set(names) if names.count(n) > 1}
    parts = []
    single = len(geometry) == 1 and not names
    for key, kw in geometry.items():
        faces = kw.get("faces")
        if faces is None or len(faces) == 0:
            continue
        parts.append((stem if single else key, _vertices(kw["vertices"]), _faces(faces)))
    if not parts:
        raise InputError(f"{stem}.obj has no faces", "scene")
    return parts, repeated


def _vertices(v: Any) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(v, dtype=np.float64).reshape(-1, 3))


def _faces(f: Any) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(f, dtype=np.int64).reshape(-1, 3))


#: PLY element names -> plural words for messages.
_PLY_WORDS = {"vertex": "vertices", "face": "faces", "edge": "edges"}


def _ply_header(data: bytes, name: str) -> Tuple[str, List[Tuple[str, int]], int]:
    """Return the format, elements ``(name, count)`` and data start of a PLY header.

    Raises
    ------
    InputError
        No ``ply`` first line or ``end_header``, or an ``element`` line without a count.
    """
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise InputError(
            f"{name} is not a PLY file: a PLY file starts with the line 'ply' and its header "
            "ends with 'end_header'; export the mesh again as PLY",
            "scene",
        )
    fmt, elements = "", []
    for line in data[:end].decode("ascii", "replace").splitlines():
        words = line.split()
        if words[:1] == ["format"] and len(words) > 1:
            fmt = words[1]
        elif words[:1] == ["element"]:
            if len(words) != 3 or not words[2].isdigit():
                raise InputError(
                    f"{name}: PLY header line {line.strip()!r} must read 'element <name> "
                    "<count>'; export the mesh again",
                    "scene",
                )
            elements.append((words[1], int(words[2])))
    start = data.find(b"\n", end)
    return fmt, elements, (len(data) if start < 0 else start + 1)


def _promised(elements: List[Tuple[str, int]]) -> str:
    """``12 vertices and 20 faces``: what a PLY header promises."""
    said = [f"{n} {_PLY_WORDS.get(e, e)}" for e, n in elements]
    return " and ".join([", ".join(said[:-1]), said[-1]] if len(said) > 1 else said)


def _check_ply(data: bytes, name: str) -> None:
    """Refuse an ASCII PLY whose data lines are not the count its header promises.

    trimesh reads such a file without a word: surplus vertices become faces' numbers, or a
    face too many is dropped (``element face 13`` over 12 faces gives a mesh with 12).
    Binary PLY is checked by trimesh's length test (see :func:`_unreadable`).
    """
    fmt, elements, start = _ply_header(data, name)
    if fmt != "ascii":
        return
    lines = sum(1 for line in data[start:].splitlines() if line.strip())
    want = sum(n for _, n in elements)
    if lines != want:
        raise InputError(
            f"{name}: the PLY header promises {_promised(elements)} ({want} data lines), but "
            f"the file has {lines} data lines: it is truncated or its header was edited; "
            "export the mesh again",
            "scene",
        )


#: Bytes of a binary STL before its triangles (80-byte header, 4-byte count), and per triangle.
_STL_HEAD, _STL_TRIANGLE = 84, 50


def _check_stl(data: bytes, name: str) -> None:
    """Refuse an STL file that holds no triangles, or fewer than its count says (issue #36).

    An ASCII STL starts with ``solid`` and lists ``facet`` blocks; a binary one is an 80-byte
    header, a triangle count, then 50 bytes a triangle. trimesh reads random bytes, or a
    binary file cut short, as a mesh of no faces without a word.
    """
    layout = (
        "an STL file is text ('solid', then 'facet' blocks) or binary (an 80-byte header, "
        "the triangle count, then 50 bytes a triangle)"
    )
    if data.lstrip()[:5].lower() == b"solid" and b"facet" in data[:4096]:
        if b"endsolid" not in data[-1024:]:
            raise InputError(
                f"{name}: the ASCII STL does not end with 'endsolid': the file is truncated; "
                "export the mesh again",
                "scene",
            )
        return
    if len(data) < _STL_HEAD:
        raise InputError(
            f"{name} is not a valid STL file: {len(data)} bytes, fewer than the {_STL_HEAD} of "
            f"a binary STL's header ({layout}); export the mesh again as STL",
            "scene",
        )
    count = int.from_bytes(data[80:84], "little")
    need = _STL_HEAD + _STL_TRIANGLE * count
    if count == 0 or len(data) < need:
        said = (
            "gives 0 triangles"
            if count == 0
            else f"gives {count} triangles ({need} bytes), but the file is {len(data)} bytes"
        )
        raise InputError(
            f"{name} is not a valid STL file: read as a binary STL, its header {said} "
            f"({layout}); the file is truncated or not an STL: export the mesh again as STL",
            "scene",
        )


def _check_off(data: bytes, name: str) -> None:
    """Refuse an ASCII OFF file whose lines fall short of what its header promises (issue #36).

    An OFF file is the line ``OFF``, the counts ``vertices faces edges``, one line per
    vertex (x y z) and one per face (its corner count, then the corners). trimesh reads a
    file cut short as a mesh with faces missing ("not a closed solid") or with numpy's words.
    """
    rows = []
    for k, line in enumerate(data.decode("latin-1").splitlines(), start=1):
        text = line.split("#", 1)[0].split()
        if text:
            rows.append((k, text))
    if not rows or not rows[0][1][0].upper().endswith("OFF"):
        raise InputError(
            f"{name} is not an OFF file: an OFF file starts with the line 'OFF', then the "
            "counts 'vertices faces edges'; export the mesh again as OFF",
            "scene",
        )
    if any(t.upper() == "BINARY" for t in rows[0][1]):
        return  # binary OFF: trimesh checks its length
    counts, body = rows[0][1][1:], rows[1:]
    if not counts and body:
        counts, body = body[0][1], body[1:]
    try:
        n_v, n_f = int(counts[0]), int(counts[1])
    except (IndexError, ValueError):
        raise InputError(
            f"{name}: the OFF header must give the counts 'vertices faces edges' after 'OFF', "
            f"got {' '.join(counts)!r}: the file is truncated or damaged; export it again",
            "scene",
        ) from None
    if len(body) < n_v + n_f:
        raise InputError(
            f"{name}: the OFF header promises {n_v} vertices and {n_f} faces ({n_v + n_f} "
            f"lines), but the file has {len(body)}: it is truncated or its header was edited; "
            "export the mesh again",
            "scene",
        )
    for k, row in body[:n_v]:
        if len(row) < 3:
            raise InputError(
                f"{name} line {k}: a vertex has {len(row)} coordinates, not 3: the file is "
                "truncated or damaged; export the mesh again",
                "scene",
            )
    for k, row in body[n_v : n_v + n_f]:
        corners = int(row[0]) if row[0].isdigit() else -1
        if corners < 3 or len(row) < 1 + corners:
            raise InputError(
                f"{name} line {k}: a face reads {' '.join(row)!r}, but a face is its corner "
                "count (3 or more), then that many vertex numbers: the file is truncated or "
                "damaged; export the mesh again",
                "scene",
            )


def _unreadable(data: bytes, ext: str, name: str, exc: Exception) -> str:
    """Return the message for a scan file trimesh could not read."""
    if ext == "ply" and "length" in str(exc):
        _, elements, start = _ply_header(data, name)
        return (
            f"{name}: the PLY header promises {_promised(elements)}, but the {len(data) - start} "
            "bytes of binary data after it do not hold that many: the file is truncated or its "
            "header was edited; export the mesh again"
        )
    if ext == "obj" and isinstance(exc, IndexError):
        n_vertices = len(re.findall(rb"^[ \t]*v[ \t]", data, re.M))
        faces = re.findall(rb"^[ \t]*f[ \t]+([^\r\n]*)", data, re.M)
        refs = [int(r) for line in faces for r in re.findall(rb"(?:^|\s)(-?\d+)", line)]
        bad = next((r for r in refs if r == 0 or abs(r) > n_vertices), None)
        if bad is not None:
            return (
                f"{name}: a face refers to vertex {bad}, but the file defines {n_vertices} "
                f"vertices ('v' lines, numbered from 1): the file is truncated or its faces "
                "come from another file; export the mesh again"
            )
    return f"cannot read {name} as a .{ext} mesh ({type(exc).__name__}: {exc})"


def _check_indices(
    v: np.ndarray, f: np.ndarray, part: str, name: str, one_based: bool = False
) -> None:
    """Refuse faces that name a vertex the file does not have (trimesh keeps them)."""
    if f.size == 0:
        return
    lo, hi = int(f.min()), int(f.max())
    if lo < 0 or hi >= len(v):
        bad = lo if lo < 0 else hi
        shown = bad + 1 if one_based else bad
        numbering = "numbered from 1" if one_based else "numbered from 0"
        raise InputError(
            f"{name}: a face of {part!r} refers to vertex {shown}, but it has {len(v)} "
            f"vertices ({numbering}): the file is truncated or its faces come from another "
            "file; export the mesh again",
            "scene",
        )
