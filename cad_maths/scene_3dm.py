"""Headless reading of Rhino ``.3dm`` scenes: solids as triangle meshes, axes, crack planes.

A :class:`Scene` lists the objects of a ``.3dm`` file (name, full layer path, kind, user text)
and turns them into what the mechanisms need, in metres whatever the file's model units:

- :meth:`Scene.mesh`: a closed solid as a :class:`~cad_maths.geometry.mesh.TriMesh`, from
  a Mesh, from a Brep or Extrusion with planar faces (tessellated here, holes included), or
  from the render meshes stored in the file for curved Breps;
- :meth:`Scene.line`: the end points of a line (rocking axis, tie-bar);
- :meth:`Scene.plane`: a point and unit normal of a planar object (crack).

rhino3dm is imported lazily, inside the functions that need it. rhino3dm has no Brep
meshing, so planar faces are triangulated in their plane by
:func:`~cad_maths.geometry.polygon.triangulate_polygon`; selection, units and the
welding and winding of solids are :mod:`cad_maths.scene_base`'s, shared with the other
scene readers. A curved Brep face with no stored render mesh
cannot be meshed headless and raises :class:`~shared_schema.errors.GeometryError` saying how
to fix the file.

Runs inside Rhino 8 (CPython 3.9).
"""

import math
import os
from itertools import chain
from operator import attrgetter
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

from cad_maths.archive_3dm import check_3dm, check_3dm_file
from cad_maths.geometry.mesh import TriMesh
from cad_maths.geometry.polygon import newell, triangulate_polygon
from cad_maths.scene_base import BaseScene, SceneObject, solid_mesh
from shared_schema.errors import GeometryError, InputError
from shared_schema.extras import require

__all__ = ["Scene", "SceneObject", "solid_mesh", "triangulate_polygon"]

# Straight segments per curved Brep edge bounding a planar face.
EDGE_SAMPLES = 32
# Points sampled along a curved closed curve to fit its plane.
CURVE_SAMPLES = 64
# Planarity tolerance relative to the object's size when the file has no absolute tolerance.
PLANAR_RTOL = 1e-6

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

# (x, y, z) of a rhino3dm point, at C speed
_XYZ = attrgetter("X", "Y", "Z")

_CURVE_KINDS = {"LineCurve": "line", "PolylineCurve": "polyline"}


def _rhino3dm() -> Any:
    """Import rhino3dm lazily (heavy, and its bundled type stubs are incomplete)."""
    return require("rhino3dm", "geometry", "to read .3dm scenes")


class Scene(BaseScene):
    """The objects of a ``.3dm`` file and their conversion to metres.

    Constructed as ``BaseScene``; ``from_3dm`` and ``from_bytes`` read a file.

    Examples
    --------
    >>> scene = Scene.from_3dm("examples/scenes/rect_wall.3dm")
    >>> wall = scene.find("wall")[0]
    >>> mesh = scene.mesh(wall)
    >>> wall.kind, mesh.n_triangles
    ('brep', 12)
    """

    #: The File3dm the geometry belongs to, kept alive with the scene (set when read).
    _file: Any = None

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
        check_3dm_file(p)  # rhino3dm trusts the lengths a file declares
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

        if data:
            check_3dm(data, name)  # rhino3dm trusts the lengths a file declares
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

    # ------------------------------------------------------------------ conversion

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
        return solid_mesh(self._to_m(v, obj), f, obj, require_closed=require_closed)

    def extent(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Lowest and highest corner of the object's bounding box [m] (rhino3dm's own)."""
        box = getattr(obj.geometry, "GetBoundingBox", None)
        if box is None:
            return super().extent(obj)
        b = box()
        lo = self._to_m([b.Min.X, b.Min.Y, b.Min.Z], obj)
        return lo, self._to_m([b.Max.X, b.Max.Y, b.Max.Z], obj)

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
        start = self._to_m([a.X, a.Y, a.Z], obj)
        end = self._to_m([b.X, b.Y, b.Z], obj)
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
        pts = self._to_m(pts, obj)
        point = pts.mean(axis=0)
        normal = surface_normal if surface_normal is not None else newell(pts)
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


def _xyz(p: Any) -> Tuple[float, float, float]:
    return (p.X, p.Y, p.Z)


def _diag(bbox: Any) -> float:
    a, b = bbox.Min, bbox.Max
    return math.sqrt((b.X - a.X) ** 2 + (b.Y - a.Y) ** 2 + (b.Z - a.Z) ** 2)


def _mesh_arrays(mesh: Any) -> Tuple[np.ndarray, np.ndarray]:
    """Double-precision vertices (n, 3) and triangles (m, 3) of a rhino3dm Mesh.

    rhino3dm (8.x) has no bulk accessor: vertices come as a list of ``Point3d`` and faces
    one tuple per call. Streaming them into ``np.fromiter`` through C-level ``map`` and
    ``attrgetter`` is the fastest exact path measured (``str(Point3d)`` rounds, and
    ``Mesh.Encode`` is slower than the copy), and builds no intermediate tuples.
    """
    pts = mesh.Vertices.ToPoint3dArray()
    v = np.fromiter(
        chain.from_iterable(map(_XYZ, pts)), dtype=np.float64, count=3 * len(pts)
    ).reshape(-1, 3)
    faces = mesh.Faces
    n = faces.Count
    q = np.fromiter(
        chain.from_iterable(map(faces.__getitem__, range(n))), dtype=np.int64, count=4 * n
    ).reshape(-1, 4)
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
        nrm = newell(rings3[0])
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
