"""Headless reading of Rhino ``.3dm`` scenes: solids as triangle meshes, axes, crack planes.

A :class:`Scene` lists the objects of a ``.3dm`` file (name, full layer path, kind, user text)
and turns them into what the mechanisms need, in metres whatever the file's model units:

- :meth:`Scene.mesh`: a closed solid as a :class:`~rhino_plugin.geometry.mesh.TriMesh`, from
  a Mesh, from a Brep or Extrusion with planar faces (tessellated here, holes included), or
  from the render meshes stored in the file for curved Breps;
- :meth:`Scene.line`: the end points of a line (rocking axis, tie-bar);
- :meth:`Scene.plane`: a point and unit normal of a planar object (crack).

rhino3dm is imported lazily, inside the functions that need it. rhino3dm has no Brep
meshing, so planar faces are triangulated by :func:`triangulate_polygon` (ear clipping, holes
joined to the outer boundary by bridge edges). A curved Brep face with no stored render mesh
cannot be meshed headless and raises :class:`~shared_schema.errors.GeometryError` saying how
to fix the file.

Runs inside Rhino 8 (CPython 3.9).
"""

import math
import os
import uuid
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from rhino_plugin.geometry.mesh import TriMesh
from shared_schema.errors import GeometryError, InputError
from shared_schema.extras import require

__all__ = ["Scene", "SceneObject", "solid_mesh", "triangulate_polygon"]

# Vertices closer than this fraction of the object's bounding-box diagonal are welded.
MERGE_RTOL = 1e-9
# A triangulation whose area differs from the polygon's by more than this fraction is rejected.
AREA_RTOL = 1e-9
# Straight segments per curved Brep edge bounding a planar face.
EDGE_SAMPLES = 32
# Points sampled along a curved closed curve to fit its plane.
CURVE_SAMPLES = 64
# Planarity tolerance relative to the object's size when the file has no absolute tolerance.
PLANAR_RTOL = 1e-6
# How many available names or layers an error message lists.
N_LISTED = 12

# Model unit -> metres as an exact ratio (numerator, denominator), so 1000 mm is exactly 1 m.
_UNIT_RATIO: Dict[str, Tuple[float, float]] = {
    "Angstroms": (1.0, 1e10),
    "Nanometers": (1.0, 1e9),
    "Microns": (1.0, 1e6),
    "Millimeters": (1.0, 1e3),
    "Centimeters": (1.0, 1e2),
    "Decimeters": (1.0, 1e1),
    "Meters": (1.0, 1.0),
    "Dekameters": (1e1, 1.0),
    "Hectometers": (1e2, 1.0),
    "Kilometers": (1e3, 1.0),
    "Microinches": (254.0, 1e10),
    "Mils": (254.0, 1e7),
    "Inches": (254.0, 1e4),
    "Feet": (3048.0, 1e4),
    "Yards": (9144.0, 1e4),
    "Miles": (1609344.0, 1e3),
    # A file without units is read as metres.
    "None": (1.0, 1.0),
    "Unset": (1.0, 1.0),
}

_CURVE_KINDS = {"LineCurve": "line", "PolylineCurve": "polyline"}


def _rhino3dm() -> Any:
    """Import rhino3dm lazily (heavy, and its bundled type stubs are incomplete)."""
    return require("rhino3dm", "geometry", "to read .3dm scenes")


@dataclass(frozen=True)
class SceneObject:
    """One object of a scene.

    Attributes
    ----------
    id : str
        Object GUID.
    name : str
        Object name (``''`` if unnamed).
    layer : str
        Full layer path, ``"Parent::Child"``.
    kind : str
        ``"mesh"``, ``"brep"``, ``"extrusion"``, ``"line"``, ``"polyline"``, ``"curve"``,
        ``"point"``, ``"surface"``, or the lower-case rhino3dm type name of anything else
        (``"subd"``, ``"instancereference"``, ...).
    user_text : dict of str to str
        User strings of the geometry, overridden by those of the object attributes.
    geometry : rhino3dm.GeometryBase
        The rhino3dm geometry, in file units.
    """

    id: str
    name: str
    layer: str
    kind: str
    user_text: Dict[str, str] = field(default_factory=dict)
    geometry: Any = field(default=None, repr=False, compare=False)

    def label(self) -> str:
        """Name, layer and short id, for messages: ``"wall (Walls, 1a2b3c4d)"``."""
        name = self.name or f"<unnamed {self.kind}>"
        return f"{name} ({self.layer}, {self.id[:8]})"


class Scene:
    """The objects of a ``.3dm`` file and their conversion to metres.

    Parameters
    ----------
    objects : list of SceneObject
        The objects, in file order.
    unit_scale : float
        Metres per model unit [m/unit].
    units : str
        Model unit name, lower case (``"millimeters"``).
    path : str, optional
        Where the scene was read from (or the upload's name).
    tolerance : float
        Model absolute tolerance [m] (0 if the file has none).

    Examples
    --------
    >>> scene = Scene.from_3dm("examples/scenes/rect_wall.3dm")  # doctest: +SKIP
    >>> wall = scene.find("wall")[0]  # doctest: +SKIP
    >>> mesh = scene.mesh(wall)  # doctest: +SKIP
    """

    def __init__(
        self,
        objects: List[SceneObject],
        unit_scale: float = 1.0,
        units: str = "meters",
        path: Optional[str] = None,
        tolerance: float = 0.0,
    ) -> None:
        self.objects = list(objects)
        self.unit_scale = float(unit_scale)
        self.units = units
        self.path = path
        self.tolerance = float(tolerance)
        self._ratio = (self.unit_scale, 1.0)
        self._file: Any = None  # keeps the File3dm (owner of the geometry) alive
        self._layer_paths: List[str] = []

    def __repr__(self) -> str:
        return f"Scene({self.path!r}, {len(self.objects)} objects, units={self.units!r})"

    # ------------------------------------------------------------------ reading

    @classmethod
    def from_3dm(cls, path: Union[str, "os.PathLike[str]"]) -> "Scene":
        """Read a ``.3dm`` file.

        Parameters
        ----------
        path : str or path-like
            The file.

        Raises
        ------
        InputError
            The file does not exist or is not a readable ``.3dm`` file (field ``"scene"``).
        """
        rhino3dm = _rhino3dm()

        p = os.fspath(path)
        if not os.path.isfile(p):
            raise InputError(f"file not found: {p}", "scene")
        model = rhino3dm.File3dm.Read(p)
        if model is None:
            raise InputError(
                f"cannot read {p} as a .3dm file (truncated, corrupt or not a Rhino model)",
                "scene",
            )
        return cls._from_file(model, p)

    @classmethod
    def from_bytes(cls, data: bytes, name: str = "upload.3dm") -> "Scene":
        """Read a ``.3dm`` file from memory (an upload).

        Parameters
        ----------
        data : bytes
            The file's content.
        name : str
            Name used in messages and as :attr:`path`.

        Raises
        ------
        InputError
            The bytes are not a readable ``.3dm`` file (field ``"scene"``).
        """
        rhino3dm = _rhino3dm()

        model = rhino3dm.File3dm.FromByteArray(bytes(data)) if data else None
        if model is None:
            raise InputError(
                f"cannot read {name} as a .3dm file (truncated, corrupt or not a Rhino model)",
                "scene",
            )
        return cls._from_file(model, name)

    @classmethod
    def _from_file(cls, model: Any, path: str) -> "Scene":
        settings = model.Settings
        unit = settings.ModelUnitSystem.name
        if unit not in _UNIT_RATIO:
            raise InputError(
                f"{path} uses model units {unit!r}, which rockmech cannot convert to metres; "
                "set the model units to mm, cm or m in Rhino (Document Properties > Units)",
                "scene",
            )
        num, den = _UNIT_RATIO[unit]
        layers = model.Layers
        paths = [layers[i].FullPath or layers[i].Name or "" for i in range(len(layers))]
        objects = []
        for obj in model.Objects:
            geo = obj.Geometry
            attr = obj.Attributes
            text = dict(geo.GetUserStrings()) if geo is not None else {}
            text.update(dict(attr.GetUserStrings()))
            li = attr.LayerIndex
            objects.append(
                SceneObject(
                    id=str(attr.Id),
                    name=attr.Name or "",
                    layer=paths[li] if 0 <= li < len(paths) else "",
                    kind=_kind(geo),
                    user_text=text,
                    geometry=geo,
                )
            )
        tol = float(settings.ModelAbsoluteTolerance)
        scene = cls(
            objects,
            unit_scale=num / den,
            units=unit.lower(),
            path=path,
            tolerance=tol * num / den if tol > 0.0 and math.isfinite(tol) else 0.0,
        )
        scene._ratio = (num, den)
        scene._layer_paths = [p for p in paths if p]
        scene._file = model
        return scene

    # ------------------------------------------------------------------ selection

    @property
    def layers(self) -> List[str]:
        """Full paths of the file's layers (or of the objects' layers), sorted."""
        return sorted(set(self._layer_paths) | {o.layer for o in self.objects if o.layer})

    def find(self, selector: Union[str, Dict[str, str]]) -> List[SceneObject]:
        """Return the objects matching a selector, in file order.

        Parameters
        ----------
        selector : str or dict
            An object name, or one of ``{"name": ...}``, ``{"layer": ...}`` (full path, or
            its last components such as ``"North"`` for ``"Walls::North"``; objects on
            sublayers are included) and ``{"id": ...}`` (GUID, any case, braces allowed).

        Returns
        -------
        list of SceneObject
            At least one object.

        Raises
        ------
        InputError
            Unknown selector key, or nothing matches (the message lists available names or
            layers).
        """
        if isinstance(selector, str):
            key, value = "name", selector
        elif isinstance(selector, dict) and len(selector) == 1:
            key, value = next(iter(selector.items()))
            value = str(value)
        else:
            raise InputError(
                f"a selector is an object name or a one-key dict name/layer/id, got {selector!r}",
                "selector",
            )
        if key == "name":
            hits = [o for o in self.objects if o.name == value]
            pool = sorted({o.name for o in self.objects if o.name})
        elif key == "layer":
            roots = [p for p in self.layers if p == value or p.endswith("::" + value)]
            hits = [
                o
                for o in self.objects
                if any(o.layer == r or o.layer.startswith(r + "::") for r in roots)
            ]
            pool = self.layers
        elif key == "id":
            want = _norm_id(value)
            hits = [o for o in self.objects if _norm_id(o.id) == want]
            pool = []
        else:
            raise InputError(
                f"unknown selector key {key!r} in {selector!r}; use 'name', 'layer' or 'id'",
                "selector",
            )
        if not hits:
            where = os.path.basename(self.path) if self.path else "the scene"
            listed = ", ".join(repr(p) for p in pool[:N_LISTED])
            more = f", ... ({len(pool)} in all)" if len(pool) > N_LISTED else ""
            plural = {"name": "names", "layer": "layers", "id": "ids"}[key]
            avail = f"; available {plural}: {listed}{more}" if pool else ""
            raise InputError(f"no object with {key} {value!r} in {where}{avail}", "selector")
        return hits

    # ------------------------------------------------------------------ conversion

    def _to_m(self, xyz: Any) -> np.ndarray:
        num, den = self._ratio
        a = np.asarray(xyz, dtype=np.float64)
        if num != 1.0:
            a = a * num
        if den != 1.0:
            a = a / den
        return a

    def mesh(self, obj: SceneObject, require_closed: bool = True) -> TriMesh:
        """Return the object as a triangle mesh in metres, oriented outward.

        Parameters
        ----------
        obj : SceneObject
            A Mesh, a Brep or an Extrusion.
        require_closed : bool
            Raise if the result is not a closed, manifold surface.

        Returns
        -------
        TriMesh
            Vertices (n, 3) [m], welded at ``MERGE_RTOL`` times the bounding-box diagonal;
            triangles counter-clockwise seen from outside (positive volume) when closed.
            ``meta`` holds ``id``, ``layer`` and ``kind``.

        Raises
        ------
        GeometryError
            Not a solid kind, a curved Brep face with no stored render mesh, a face that
            cannot be triangulated, or (with ``require_closed``) an open surface.

        Notes
        -----
        Planar faces are triangulated in their own plane from their trim loops (outer
        boundary and holes), using the Brep's vertices so neighbouring faces share them
        exactly. The outward side is the face normal, flipped where the face orientation is
        reversed; a final pass makes the winding consistent and the volume positive.
        """
        rhino3dm = _rhino3dm()

        geo = obj.geometry
        if isinstance(geo, rhino3dm.Mesh):
            v, f = _mesh_arrays(geo)
        elif isinstance(geo, rhino3dm.Extrusion):
            brep = geo.ToBrep(True)
            if brep is None:
                raise GeometryError(f"{obj.label()}: the extrusion cannot be converted to a Brep")
            # a curved extrusion stores one render mesh for the whole object
            v, f = self._brep_arrays(brep, obj, geo.GetMesh(rhino3dm.MeshType.Render))
        elif isinstance(geo, rhino3dm.Brep):
            v, f = self._brep_arrays(geo, obj)
        else:
            raise GeometryError(
                f"{obj.label()}: a {obj.kind} is not a solid; select a closed mesh, "
                "polysurface or extrusion"
            )
        return solid_mesh(self._to_m(v), f, obj, require_closed=require_closed)

    def _brep_arrays(
        self, brep: Any, obj: SceneObject, stored: Any = None
    ) -> Tuple[np.ndarray, np.ndarray]:
        """Own tessellation if every face is planar, else the stored render meshes."""
        rhino3dm = _rhino3dm()

        faces = brep.Faces
        n = len(faces)
        size = _diag(brep.GetBoundingBox())
        tol = self.tolerance / self.unit_scale if self.tolerance > 0.0 else PLANAR_RTOL * size
        planar = [faces[i].IsPlanar(tol) for i in range(n)]
        if all(planar):
            return _tessellate_planar_brep(brep, obj)
        if stored is not None and stored.Faces.Count > 0:
            return _mesh_arrays(stored)
        meshes = [faces[i].GetMesh(rhino3dm.MeshType.Render) for i in range(n)]
        missing = [i for i in range(n) if meshes[i] is None or meshes[i].Faces.Count == 0]
        if missing:
            curved = [i for i in missing if not planar[i]]
            raise GeometryError(
                f"{obj.label()}: {len(curved)} curved face(s) (e.g. face {curved[0]}) and the "
                "file stores no render mesh for them, which rockmech cannot make headless; "
                "mesh it in Rhino (Mesh command) and use the mesh, or save the file with "
                "render meshes (not SaveSmall)"
            )
        vs, fs, offset = [], [], 0
        for m in meshes:
            v, f = _mesh_arrays(m)
            vs.append(v)
            fs.append(f + offset)
            offset += v.shape[0]
        return np.vstack(vs), np.vstack(fs)

    def line(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Start and end points of a straight line object.

        Parameters
        ----------
        obj : SceneObject
            A line, a 2-point polyline, or any curve that is straight.

        Returns
        -------
        start, end : (3,) float
            End points [m].

        Raises
        ------
        GeometryError
            Not a curve, not straight, or of zero length.
        """
        rhino3dm = _rhino3dm()

        geo = obj.geometry
        if not isinstance(geo, rhino3dm.Curve):
            raise GeometryError(f"{obj.label()}: a {obj.kind} is not a line; draw a Line")
        a, b = geo.PointAtStart, geo.PointAtEnd
        start = self._to_m([a.X, a.Y, a.Z])
        end = self._to_m([b.X, b.Y, b.Z])
        length = float(np.linalg.norm(end - start))
        if length == 0.0 or geo.IsClosed:
            raise GeometryError(f"{obj.label()}: the {obj.kind} is closed or has zero length")
        tol = self.tolerance / self.unit_scale if self.tolerance > 0.0 else 0.0
        tol = max(tol, PLANAR_RTOL * length / self.unit_scale)
        if not geo.IsLinear(tol):
            raise GeometryError(
                f"{obj.label()}: the {obj.kind} is not straight; an axis or a tie-bar must be a "
                "Line (or a 2-point polyline)"
            )
        return start, end

    def plane(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Return a point and the unit normal of a planar object.

        Parameters
        ----------
        obj : SceneObject
            A planar surface, a single-face planar Brep, a planar closed curve, an open
            polyline of at least 3 points that are coplanar, or a planar mesh.

        Returns
        -------
        point : (3,) float
            A point of the plane [m]: the centroid of the object's points.
        normal : (3,) float
            Unit normal: the surface's normal (Brep face orientation included), or by the
            right-hand rule along the curve's points.

        Raises
        ------
        GeometryError
            The object is not planar, or is degenerate.
        """
        rhino3dm = _rhino3dm()

        geo = obj.geometry
        surface_normal: Optional[np.ndarray] = None
        if isinstance(geo, rhino3dm.Brep):
            if len(geo.Faces) != 1:
                raise GeometryError(
                    f"{obj.label()}: a Brep with {len(geo.Faces)} faces is not a plane; use a "
                    "single planar surface"
                )
            face = geo.Faces[0]
            loops = _face_loops(geo, face)
            pts = np.array(loops[0]) if loops else _surface_points(face)
            surface_normal = _surface_normal(face) * (-1.0 if face.OrientationIsReversed else 1.0)
        elif isinstance(geo, rhino3dm.Surface) and not isinstance(geo, rhino3dm.Extrusion):
            pts = _surface_points(geo)
            surface_normal = _surface_normal(geo)
        elif isinstance(geo, rhino3dm.Curve):
            pl = geo.TryGetPolyline()
            if pl is not None and pl.Count >= (4 if geo.IsClosed else 3):
                pts = np.array([[pl[i].X, pl[i].Y, pl[i].Z] for i in range(pl.Count)])
                if geo.IsClosed:
                    pts = pts[:-1]
            elif geo.IsClosed:
                d = geo.Domain
                ts = np.linspace(d.T0, d.T1, CURVE_SAMPLES, endpoint=False)
                pts = np.array([_xyz(geo.PointAt(float(t))) for t in ts])
            else:
                raise GeometryError(
                    f"{obj.label()}: an open {obj.kind} does not define a plane; draw a planar "
                    "closed curve, a 3-point polyline or a planar surface"
                )
        elif isinstance(geo, rhino3dm.Mesh):
            v, f = _mesh_arrays(geo)
            pts = v
            surface_normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]).sum(0)
        else:
            raise GeometryError(
                f"{obj.label()}: a {obj.kind} does not define a plane; use a planar surface, "
                "a planar closed curve or a 3-point polyline"
            )
        pts = self._to_m(pts)
        point = pts.mean(axis=0)
        normal = surface_normal if surface_normal is not None else _newell(pts)
        norm = float(np.linalg.norm(normal))
        size = float(np.linalg.norm(pts.max(0) - pts.min(0)))
        if pts.shape[0] < 3 or norm <= 1e-12 * max(size, 1e-300) ** 2:
            raise GeometryError(f"{obj.label()}: the {obj.kind} is degenerate (no plane)")
        normal = normal / norm
        tol = max(self.tolerance, PLANAR_RTOL * size)
        off = float(np.abs((pts - point) @ normal).max())
        if off > tol:
            raise GeometryError(
                f"{obj.label()}: the {obj.kind} is not planar (points {off:.3g} m off its mean "
                f"plane, tolerance {tol:.3g} m)"
            )
        return point, normal


# ---------------------------------------------------------------------- helpers


def _kind(geo: Any) -> str:
    if geo is None:
        return "none"
    name = type(geo).__name__
    if name in _CURVE_KINDS:
        return _CURVE_KINDS[name]
    if name in ("Mesh", "Brep", "Extrusion", "Point"):
        return name.lower()
    if name.endswith("Curve"):
        return "curve"
    if name.endswith("Surface"):
        return "surface"
    return name.lower()


def _norm_id(value: str) -> str:
    try:
        return str(uuid.UUID(value.strip()))
    except ValueError:
        return value.strip().lower()


def _xyz(p: Any) -> Tuple[float, float, float]:
    return (p.X, p.Y, p.Z)


def _diag(bbox: Any) -> float:
    a, b = bbox.Min, bbox.Max
    return math.sqrt((b.X - a.X) ** 2 + (b.Y - a.Y) ** 2 + (b.Z - a.Z) ** 2)


def _mesh_arrays(mesh: Any) -> Tuple[np.ndarray, np.ndarray]:
    """Double-precision vertices (n, 3) and triangles (m, 3) of a rhino3dm Mesh."""
    pts = mesh.Vertices.ToPoint3dArray()
    v = np.array([(p.X, p.Y, p.Z) for p in pts], dtype=np.float64).reshape(-1, 3)
    faces = mesh.Faces
    q = np.array([faces[i] for i in range(faces.Count)], dtype=np.int64).reshape(-1, 4)
    quad = q[:, 2] != q[:, 3]
    f = np.vstack([q[:, :3], q[quad][:, [0, 2, 3]]])
    return v, f


def _surface_normal(srf: Any) -> np.ndarray:
    du, dv = srf.Domain(0), srf.Domain(1)
    n = srf.NormalAt(0.5 * (du.T0 + du.T1), 0.5 * (dv.T0 + dv.T1))
    return np.array([n.X, n.Y, n.Z], dtype=np.float64)


def _surface_points(srf: Any) -> np.ndarray:
    du, dv = srf.Domain(0), srf.Domain(1)
    return np.array(
        [
            _xyz(srf.PointAt(u, v))
            for u, v in ((du.T0, dv.T0), (du.T1, dv.T0), (du.T1, dv.T1), (du.T0, dv.T1))
        ],
        dtype=np.float64,
    )


def _newell(pts: np.ndarray) -> np.ndarray:
    """Newell's area vector of a closed polygon (n, 3): twice the vector area."""
    c = pts - pts.mean(axis=0)
    return np.cross(c, np.roll(c, -1, axis=0)).sum(axis=0)


Point3 = Tuple[float, float, float]
# A loop point: (-1, vertex index) for a Brep vertex, (edge index, j) for the j-th interior
# point of a curved or polyline edge; two faces sharing an edge produce the same keys.
Key = Tuple[int, int]


def _edge_interior(edge: Any) -> List[Point3]:
    """Interior points of a Brep edge, from its start to its end (none if straight)."""
    if edge.IsLinear():
        return []
    pl = edge.TryGetPolyline()
    if pl is not None and pl.Count >= 2:
        pts = [_xyz(pl[i]) for i in range(pl.Count)]
        a = np.array(_xyz(edge.PointAtStart))
        if np.linalg.norm(np.array(pts[-1]) - a) < np.linalg.norm(np.array(pts[0]) - a):
            pts.reverse()
        return pts[1:-1]
    d = edge.Domain
    return [
        _xyz(edge.PointAt(d.T0 + (d.T1 - d.T0) * j / EDGE_SAMPLES)) for j in range(1, EDGE_SAMPLES)
    ]


def _face_loop_keys(
    brep: Any, face: Any, edge_pts: Dict[int, List[Point3]]
) -> Tuple[List[List[Key]], int]:
    """Loops of a face as point keys, outer loops first, and the number of outer loops.

    ``edge_pts`` caches the interior points of the edges met so far.
    """
    rhino3dm = _rhino3dm()

    outer: List[List[Key]] = []
    inner: List[List[Key]] = []
    for li in range(len(face.Loops)):
        loop = face.Loops[li]
        kind = loop.LoopType
        if kind not in (rhino3dm.BrepLoopType.Outer, rhino3dm.BrepLoopType.Inner):
            continue  # slits and curves-on-surface bound no area
        keys: List[Key] = []
        trims = loop.Trims
        for ti in range(loop.TrimCount):
            trim = trims[ti]
            ei = trim.EdgeIndex
            if ei < 0:  # singular trim at a pole
                continue
            keys.append((-1, trim.StartVertexIndex))
            if ei not in edge_pts:
                edge_pts[ei] = _edge_interior(brep.Edges[ei])
            interior = [(ei, j) for j in range(len(edge_pts[ei]))]
            keys.extend(reversed(interior) if trim.IsReversed else interior)
        (outer if kind == rhino3dm.BrepLoopType.Outer else inner).append(keys)
    return outer + inner, len(outer)


def _key_point(brep: Any, key: Key, edge_pts: Dict[int, List[Point3]]) -> Point3:
    ei, j = key
    return _xyz(brep.Vertices[j].Location) if ei < 0 else edge_pts[ei][j]


def _face_loops(brep: Any, face: Any) -> List[List[Point3]]:
    """3D points of a face's loops, outer loop first, in trim order."""
    edge_pts: Dict[int, List[Point3]] = {}
    loops, _ = _face_loop_keys(brep, face, edge_pts)
    return [[_key_point(brep, k, edge_pts) for k in loop] for loop in loops]


def _tessellate_planar_brep(brep: Any, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
    """Triangulate every (planar) face of a Brep in its plane, sharing points by key."""
    index: Dict[Key, int] = {}
    coords: List[Point3] = []
    tris: List[Tuple[int, int, int]] = []
    edge_pts: Dict[int, List[Point3]] = {}
    faces = brep.Faces
    for fi in range(len(faces)):
        face = faces[fi]
        loops, n_outer = _face_loop_keys(brep, face, edge_pts)
        if n_outer != 1:
            raise GeometryError(f"{obj.label()}: face {fi} has {n_outer} outer loops; expected one")
        ids_loops = []
        for keys in loops:
            ids = []
            for k in keys:
                if k not in index:
                    index[k] = len(coords)
                    coords.append(_key_point(brep, k, edge_pts))
                ids.append(index[k])
            ids_loops.append(ids)
        rings3 = [np.array([coords[i] for i in ids], dtype=np.float64) for ids in ids_loops]
        nrm = _newell(rings3[0])
        if float(np.linalg.norm(nrm)) == 0.0:
            continue  # a zero-area face bounds nothing
        # the outward side: the surface normal, reversed with the face
        outward = _surface_normal(face) * (-1.0 if face.OrientationIsReversed else 1.0)
        if float(np.dot(nrm, outward)) < 0.0:
            nrm = -nrm
        e3 = nrm / np.linalg.norm(nrm)
        e1 = np.cross(np.eye(3)[int(np.argmin(np.abs(e3)))], e3)
        e1 /= np.linalg.norm(e1)
        frame = np.column_stack([e1, np.cross(e3, e1)])  # (e1, e2, e3) right-handed
        origin = rings3[0].mean(axis=0)
        rings2 = [(r - origin) @ frame for r in rings3]
        try:
            local = triangulate_polygon(rings2[0], rings2[1:])
        except ValueError as exc:
            raise GeometryError(f"{obj.label()}: cannot triangulate face {fi}: {exc}") from None
        flat = [i for ids in ids_loops for i in ids]
        tris.extend((flat[a], flat[b], flat[c]) for a, b, c in local)
    v = np.array(coords, dtype=np.float64).reshape(-1, 3)
    return v, np.array(tris, dtype=np.int64).reshape(-1, 3)


def solid_mesh(
    v: np.ndarray, f: np.ndarray, obj: SceneObject, *, require_closed: bool = True
) -> TriMesh:
    """Weld, orient outward and check a triangle mesh of a scene object.

    Parameters
    ----------
    v : (n, 3) float
        Vertices [m].
    f : (m, 3) int
        Triangles.
    obj : SceneObject
        The object the mesh came from (named in errors and kept in the mesh's metadata).
    require_closed : bool
        Refuse a mesh with open or non-manifold edges.

    Raises
    ------
    GeometryError
        No faces, or not closed when ``require_closed``.
    """
    v, f = _weld(v, f)
    if f.shape[0] == 0:
        raise GeometryError(f"{obj.label()}: the {obj.kind} has no faces")
    f, closed, n_open = _orient_outward(v, f)
    if require_closed and not closed:
        raise GeometryError(
            f"{obj.label()}: the {obj.kind} is not a closed solid ({n_open} open or "
            "non-manifold edges); close it in Rhino (Cap, Join, or MeshRepair / FillMeshHoles)"
        )
    return TriMesh(
        v, f, obj.name or obj.label(), {"id": obj.id, "layer": obj.layer, "kind": obj.kind}
    )


def _weld(v: np.ndarray, f: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Merge vertices closer than MERGE_RTOL x diagonal; drop degenerate and unused."""
    if v.shape[0] == 0:
        return v, f.reshape(-1, 3)
    size = float(np.linalg.norm(v.max(0) - v.min(0)))
    tol = MERGE_RTOL * size if size > 0.0 else 1.0
    key = np.round((v - v.min(0)) / tol).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    f = inverse[f]
    good = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])
    f = f[good]
    # keep first-occurrence coordinates, renumbered in first-occurrence order
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    used = np.zeros(order.size, dtype=bool)
    used[rank[f].ravel()] = True
    new = np.cumsum(used) - 1
    return v[first[order]][used], new[rank[f]]


def _orient_outward(v: np.ndarray, f: np.ndarray) -> Tuple[np.ndarray, bool, int]:
    """Make the winding consistent and the volume of each closed shell positive.

    Returns
    -------
    faces : (m, 3) int
        Re-oriented triangles (unchanged if the surface is not closed).
    closed : bool
        Every edge is shared by exactly two triangles, and the surface is orientable.
    n_bad : int
        Number of edges not shared by exactly two triangles.
    """
    m = f.shape[0]
    e = np.stack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]], axis=1).reshape(-1, 2)
    lo, hi = np.minimum(e[:, 0], e[:, 1]), np.maximum(e[:, 0], e[:, 1])
    _, inv, count = np.unique(lo * (int(f.max()) + 1) + hi, return_inverse=True, return_counts=True)
    n_bad = int(np.count_nonzero(count != 2))
    if n_bad:
        return f, False, n_bad
    pair = np.argsort(inv.reshape(-1), kind="stable").reshape(-1, 2)
    fa, fb = pair[:, 0] // 3, pair[:, 1] // 3
    # both uses of an edge running the same way means the two triangles disagree
    same = e[pair[:, 0], 0] == e[pair[:, 1], 0]
    if same.any():
        flip, comp = _propagate(m, fa, fb, same)
        if flip is None:
            return f, False, 0  # non-orientable (Moebius-like)
        f = np.where(flip[:, None], f[:, ::-1], f)
    else:
        comp = _components(m, fa, fb)
    c = v.mean(axis=0)
    a, b, cc = v[f[:, 0]] - c, v[f[:, 1]] - c, v[f[:, 2]] - c
    vol6 = np.einsum("ij,ij->i", a, np.cross(b, cc))
    negative = np.bincount(comp, weights=vol6) < 0.0
    if negative.any():
        f = np.where(negative[comp][:, None], f[:, ::-1], f)
    return f, True, 0


def _propagate(
    m: int, fa: np.ndarray, fb: np.ndarray, same: np.ndarray
) -> Tuple[Optional[np.ndarray], np.ndarray]:
    """Return which triangles to flip for a consistent winding, and shell labels."""
    adj: List[List[Tuple[int, bool]]] = [[] for _ in range(m)]
    for a, b, s in zip(fa.tolist(), fb.tolist(), same.tolist()):
        adj[a].append((b, s))
        adj[b].append((a, s))
    flip = np.zeros(m, dtype=bool)
    comp = np.full(m, -1, dtype=np.int64)
    n_comp = 0
    for seed in range(m):
        if comp[seed] >= 0:
            continue
        comp[seed] = n_comp
        stack = [seed]
        while stack:
            a = stack.pop()
            for b, s in adj[a]:
                want = bool(flip[a]) ^ s
                if comp[b] < 0:
                    comp[b] = n_comp
                    flip[b] = want
                    stack.append(b)
                elif bool(flip[b]) != want:
                    return None, comp
        n_comp += 1
    return flip, comp


def _components(m: int, fa: np.ndarray, fb: np.ndarray) -> np.ndarray:
    """Shell label of each triangle (triangles linked by shared edges)."""
    try:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components
    except ImportError:  # Rhino's Python may lack scipy: union-find
        parent = list(range(m))

        def root(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for a, b in zip(fa.tolist(), fb.tolist()):
            ra, rb = root(a), root(b)
            if ra != rb:
                parent[ra] = rb
        _, comp = np.unique([root(i) for i in range(m)], return_inverse=True)
        return np.asarray(comp).reshape(-1)
    graph = coo_matrix((np.ones(fa.size), (fa, fb)), shape=(m, m))
    return np.asarray(connected_components(graph, directed=False)[1])


# ---------------------------------------------------------------------- triangulation


def _area2(p: np.ndarray) -> float:
    """Twice the signed area of a polygon (n, 2), positive counter-clockwise."""
    x, y = p[:, 0], p[:, 1]
    return float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def triangulate_polygon(
    outer: np.ndarray, holes: Sequence[np.ndarray] = ()
) -> List[Tuple[int, int, int]]:
    """Triangulate a simple polygon with holes by ear clipping.

    Parameters
    ----------
    outer : (n, 2) float
        Outer boundary, either orientation, not repeating the first point.
    holes : sequence of (k, 2) float
        Hole boundaries, inside ``outer`` and disjoint.

    Returns
    -------
    list of (int, int, int)
        Triangles, counter-clockwise, as indices into the concatenation
        ``[outer, holes[0], holes[1], ...]``. Every input vertex is used; collinear
        vertices are kept (they are needed where a neighbouring face has a vertex there).

    Raises
    ------
    ValueError
        The polygon is degenerate or self-intersecting (the triangles would not cover it).

    Notes
    -----
    Each hole is joined to the boundary by a bridge edge from its right-most vertex to the
    nearest visible boundary vertex (holes in decreasing order of x), which gives one weakly
    simple polygon; ears are then clipped. The result is checked: the triangle areas must sum
    to the polygon's area within ``AREA_RTOL``.

    Examples
    --------
    >>> sq = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], float)
    >>> hole = np.array([[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]], float)
    >>> len(triangulate_polygon(sq, [hole]))
    8
    """
    rings_in = [np.asarray(outer, dtype=np.float64)] + [
        np.asarray(h, dtype=np.float64) for h in holes
    ]
    pts = np.vstack(rings_in)
    size = float(np.linalg.norm(pts.max(0) - pts.min(0))) if pts.size else 0.0
    if size == 0.0:
        raise ValueError("the polygon is degenerate (zero size)")
    eps = 1e-12 * size * size  # area tolerance for orientation tests
    rings: List[List[int]] = []
    start = 0
    for k, r in enumerate(rings_in):
        ids = list(range(start, start + r.shape[0]))
        start += r.shape[0]
        a2 = _area2(r) if r.shape[0] >= 3 else 0.0
        if abs(a2) <= eps:
            if k == 0:
                raise ValueError("the outer boundary has zero area")
            continue  # a zero-area hole removes nothing
        if (a2 > 0.0) != (k == 0):
            ids.reverse()  # outer counter-clockwise, holes clockwise
        rings.append(ids)
    target = sum(abs(_area2(pts[r])) * (1 if k == 0 else -1) for k, r in enumerate(rings))
    ring = rings[0]
    holes_sorted = sorted(rings[1:], key=lambda h: -float(pts[h, 0].max()))
    for hole in holes_sorted:
        ring = _bridge(pts, ring, hole, holes_sorted, eps)
    tris = _ear_clip(pts, ring, eps)
    if len(tris) != len(ring) - 2:  # a zero-area triangle was left: T-junction
        raise ValueError("degenerate boundary (zero-width spike or repeated vertex)")
    got = sum(_cross(pts[a], pts[b], pts[c]) for a, b, c in tris)
    if abs(got - target) > AREA_RTOL * max(abs(target), eps) + 8 * eps:
        raise ValueError(
            f"triangulation covers area {got / 2:.6g} instead of {target / 2:.6g} "
            "(self-intersecting boundary or overlapping holes)"
        )
    return tris


def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _segments_cross(
    p1: np.ndarray, p2: np.ndarray, q1: np.ndarray, q2: np.ndarray, eps: float
) -> bool:
    """Whether segments p1p2 and q1q2 intersect (touching included, shared ends excluded)."""
    d1 = _cross(q1, q2, p1)
    d2 = _cross(q1, q2, p2)
    d3 = _cross(p1, p2, q1)
    d4 = _cross(p1, p2, q2)
    if ((d1 > eps and d2 < -eps) or (d1 < -eps and d2 > eps)) and (
        (d3 > eps and d4 < -eps) or (d3 < -eps and d4 > eps)
    ):
        return True

    def on(a: np.ndarray, b: np.ndarray, p: np.ndarray, d: float) -> bool:
        return (
            abs(d) <= eps
            and min(a[0], b[0]) <= p[0] <= max(a[0], b[0])
            and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])
        )

    return on(q1, q2, p1, d1) or on(q1, q2, p2, d2) or on(p1, p2, q1, d3) or on(p1, p2, q2, d4)


def _locally_inside(
    pts: np.ndarray, prev: int, cur: int, nxt: int, p: np.ndarray, eps: float
) -> bool:
    """Whether direction cur->p starts into the interior (left side) at vertex cur."""
    c = pts[cur]
    a, b = pts[nxt], pts[prev]
    if _cross(b, c, a) >= 0.0:  # convex corner (interior angle <= 180 deg)
        return _cross(c, a, p) > eps and _cross(c, p, b) > eps
    return not (_cross(c, b, p) >= -eps and _cross(c, p, a) >= -eps)


def _bridge(
    pts: np.ndarray, ring: List[int], hole: List[int], holes: List[List[int]], eps: float
) -> List[int]:
    """Splice a hole into the ring through a bridge edge to a visible ring vertex."""
    hm = max(range(len(hole)), key=lambda i: (pts[hole[i], 0], -pts[hole[i], 1]))
    m = hole[hm]
    pm = pts[m]
    edges = [(ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring))]
    for h in holes:
        edges.extend((h[i], h[(i + 1) % len(h)]) for i in range(len(h)))
    hprev, hnext = hole[hm - 1], hole[(hm + 1) % len(hole)]
    cands = sorted(range(len(ring)), key=lambda i: float(np.sum((pts[ring[i]] - pm) ** 2)))
    for i in cands:
        p = ring[i]
        pp = pts[p]
        if np.array_equal(pp, pm):
            continue
        if not _locally_inside(pts, ring[i - 1], p, ring[(i + 1) % len(ring)], pm, eps):
            continue
        if not _locally_inside(pts, hprev, m, hnext, pp, eps):
            continue
        blocked = False
        for a, b in edges:
            if a in (p, m) or b in (p, m):
                continue
            if np.array_equal(pts[a], pp) or np.array_equal(pts[b], pp):
                continue
            if _segments_cross(pm, pp, pts[a], pts[b], eps):
                blocked = True
                break
        if not blocked:
            k = hm
            loop = hole[k:] + hole[:k] + [m]
            return ring[: i + 1] + loop + ring[i:]
    raise ValueError("a hole cannot be joined to the boundary (does it lie outside it?)")


def _ear_clip(pts: np.ndarray, ring: List[int], eps: float) -> List[Tuple[int, int, int]]:
    tris: List[Tuple[int, int, int]] = []
    ring = list(ring)
    strict = True
    i = 0
    stall = 0
    while len(ring) > 3:
        n = len(ring)
        a, b, c = ring[(i - 1) % n], ring[i % n], ring[(i + 1) % n]
        if _is_ear(pts, ring, a, b, c, eps, strict):
            tris.append((a, b, c))
            del ring[i % n]
            i = (i - 1) % len(ring)
            stall = 0
            strict = True
            continue
        i = (i + 1) % n
        stall += 1
        if stall > n:
            if not strict:
                raise ValueError("no ear found (self-intersecting boundary?)")
            strict = False
            stall = 0
    if len(ring) == 3:
        a, b, c = ring
        if _cross(pts[a], pts[b], pts[c]) > eps:
            tris.append((a, b, c))
    return tris


def _is_ear(
    pts: np.ndarray, ring: List[int], a: int, b: int, c: int, eps: float, strict: bool
) -> bool:
    pa, pb, pc = pts[a], pts[b], pts[c]
    if _cross(pa, pb, pc) <= eps:
        return False
    # a bridge revisits the same point: only points elsewhere can block the ear
    for k in ring:
        if k in (a, b, c):
            continue
        p = pts[k]
        if np.array_equal(p, pa) or np.array_equal(p, pb) or np.array_equal(p, pc):
            continue
        lim = -eps if strict else eps
        if _cross(pa, pb, p) >= lim and _cross(pb, pc, p) >= lim and _cross(pc, pa, p) >= lim:
            return False
    return True
