"""A scene of geometry already taken out of Rhino: triangle arrays, line ends and planes.

Inside Rhino the objects are RhinoCommon objects. The headless reader
(:class:`~cad_maths.scene_3dm.Scene`) takes rhino3dm objects, and rhino3dm has no
CPython 3.9 wheel for macOS, so Rhino 8 cannot rely on it. The Rhino glue
(``rhino_plugin.rhino.docscene``) and the Grasshopper components therefore turn each object
into a :class:`Prepared` record (a triangle mesh in model units, a straight line's end
points, or a plane), and :class:`PreparedScene` serves those records through the
:class:`~cad_maths.scene_3dm.Scene` interface: ``find`` by name, layer or id, and
``mesh``, ``line``, ``plane`` in metres, with the same welding, winding and closed-solid
checks as a ``.3dm`` read headless.

Python 3.9-clean: imported by Rhino 8.
"""

from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from cad_maths.geometry.mesh import TriMesh
from cad_maths.scene_3dm import Scene, SceneObject, solid_mesh
from shared_schema.errors import GeometryError

__all__ = ["Prepared", "PreparedScene"]

Point = Tuple[float, float, float]


@dataclass(frozen=True)
class Prepared:
    """What rockmech needs of one object, in model units.

    Attributes
    ----------
    vertices : (n, 3) float, optional
        Triangle-mesh vertices of a solid [model units].
    faces : (m, 3) int, optional
        Triangles (vertex indices).
    line : ((3,), (3,)) float, optional
        End points of a straight line [model units].
    plane : ((3,), (3,)) float, optional
        A point on the plane [model units] and its normal.
    problem : str, optional
        Why the object could not be turned into what was asked (it is reported, with the
        object's name, when the object is used as that).
    """

    vertices: Optional[np.ndarray] = None
    faces: Optional[np.ndarray] = None
    line: Optional[Tuple[Point, Point]] = None
    plane: Optional[Tuple[Point, Point]] = None
    problem: Optional[str] = None


class PreparedScene(Scene):
    """A :class:`~cad_maths.scene_3dm.Scene` whose objects carry :class:`Prepared` records.

    Parameters
    ----------
    objects : list of SceneObject
        ``geometry`` of each is a :class:`Prepared`.
    unit_scale : float
        Metres per model unit [m/unit].
    units : str
        Model unit name, lower case.
    path : str, optional
        The document's file (for messages and provenance).
    tolerance : float
        Model absolute tolerance [m].
    """

    @classmethod
    def from_records(
        cls,
        records: Sequence[Tuple[str, str, str, str, Prepared]],
        *,
        unit_scale: float = 1.0,
        units: str = "meters",
        path: Optional[str] = None,
        tolerance: float = 0.0,
    ) -> "PreparedScene":
        """Build a scene from ``(id, name, layer, kind, prepared)`` tuples."""
        objects = [
            SceneObject(id=str(i), name=n, layer=la, kind=k, geometry=g)
            for i, n, la, k, g in records
        ]
        return cls(objects, unit_scale=unit_scale, units=units, path=path, tolerance=tolerance)

    def _prepared(self, obj: SceneObject) -> Prepared:
        geo = obj.geometry
        if not isinstance(geo, Prepared):
            raise GeometryError(f"{obj.label()}: no geometry was prepared for this object")
        return geo

    def mesh(self, obj: SceneObject, require_closed: bool = True) -> TriMesh:
        """Return the object as a closed triangle mesh in metres, oriented outward.

        Raises
        ------
        GeometryError
            Not a solid, no triangles, or (with ``require_closed``) an open surface; the
            message names the object.
        """
        geo = self._prepared(obj)
        if geo.vertices is None or geo.faces is None:
            why = geo.problem or f"a {obj.kind} is not a solid"
            raise GeometryError(
                f"{obj.label()}: {why}; select a closed mesh, polysurface or extrusion"
            )
        v = self._to_m(np.asarray(geo.vertices, dtype=np.float64).reshape(-1, 3), obj)
        f = np.asarray(geo.faces, dtype=np.int64).reshape(-1, 3)
        return solid_mesh(v, f, obj, require_closed=require_closed)

    def line(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Return the end points [m] of a straight line object."""
        geo = self._prepared(obj)
        if geo.line is None:
            why = geo.problem or f"a {obj.kind} is not a line"
            raise GeometryError(f"{obj.label()}: {why}; draw a Line (or a 2-point polyline)")
        start, end = self._to_m(geo.line[0], obj), self._to_m(geo.line[1], obj)
        if float(np.linalg.norm(end - start)) == 0.0:
            raise GeometryError(f"{obj.label()}: the {obj.kind} has zero length")
        return start, end

    def plane(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Return a point [m] and the unit normal of a planar object."""
        geo = self._prepared(obj)
        if geo.plane is None:
            why = geo.problem or f"a {obj.kind} does not define a plane"
            raise GeometryError(
                f"{obj.label()}: {why}; use a planar surface, a planar closed curve or a "
                "3-point polyline"
            )
        point = self._to_m(geo.plane[0], obj)
        normal = np.asarray(geo.plane[1], dtype=np.float64)
        norm = float(np.linalg.norm(normal))
        if not norm > 0.0:
            raise GeometryError(f"{obj.label()}: the {obj.kind} is degenerate (no plane)")
        return point, normal / norm
