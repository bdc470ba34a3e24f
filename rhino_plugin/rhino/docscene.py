"""The active Rhino document as a scene of prepared geometry.

Each object is converted when a flow first uses it (``mesh``, ``line`` or ``plane``):
meshes as they are, Breps and extrusions meshed by Rhino (``Mesh.CreateFromBrep``, so
curved Breps work too), curves and surfaces tested for straightness and planarity with the
document's tolerance. The rest (welding, winding, closed-solid checks, units) is
:class:`~rhino_plugin.flows.prepared.PreparedScene`'s, tested headless.
"""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import Rhino
import Rhino.Geometry as rg

from cad_maths.scene_3dm import SceneObject
from rhino_plugin.flows.prepared import Prepared, PreparedScene

__all__ = ["DocScene", "kind_of", "prepare"]


def _xyz(p: Any) -> Tuple[float, float, float]:
    return (float(p.X), float(p.Y), float(p.Z))


def kind_of(geo: Any) -> str:
    """Kind name of a RhinoCommon geometry, as the headless reader names it."""
    if isinstance(geo, rg.LineCurve):
        return "line"
    if isinstance(geo, rg.PolylineCurve):
        return "polyline"
    for cls, name in ((rg.Mesh, "mesh"), (rg.Extrusion, "extrusion"), (rg.Brep, "brep")):
        if isinstance(geo, cls):
            return name
    if isinstance(geo, rg.Curve):
        return "curve"
    if isinstance(geo, rg.Surface):
        return "surface"
    return type(geo).__name__.lower()


def _mesh_arrays(mesh: rg.Mesh) -> Tuple[np.ndarray, np.ndarray]:
    v = np.array([_xyz(p) for p in mesh.Vertices.ToPoint3dArray()], dtype=np.float64)
    f = np.array(list(mesh.Faces.ToIntArray(True)), dtype=np.int64).reshape(-1, 3)
    return v, f


def _plane(geo: Any, tol: float) -> Optional[Tuple[Any, Any]]:
    """Return a point and the normal of a planar surface, single-face Brep or curve."""
    if isinstance(geo, rg.Brep) and geo.Faces.Count == 1:
        face = next(iter(geo.Faces))
        ok, plane = face.TryGetPlane(tol)
        if not ok:
            return None
        normal = plane.ZAxis
        if face.OrientationIsReversed:
            normal = -normal
        amp = rg.AreaMassProperties.Compute(geo)
        origin = amp.Centroid if amp is not None else plane.Origin
        return _xyz(origin), _xyz(normal)
    if isinstance(geo, rg.Surface) and not isinstance(geo, rg.Extrusion):
        ok, plane = geo.TryGetPlane(tol)
        return (_xyz(plane.Origin), _xyz(plane.ZAxis)) if ok else None
    if isinstance(geo, rg.Curve):
        ok, plane = geo.TryGetPlane(tol)
        return (_xyz(plane.Origin), _xyz(plane.ZAxis)) if ok else None
    return None


def prepare(geo: Any, tol: float) -> Prepared:
    """Convert a RhinoCommon geometry into a :class:`Prepared` record [model units].

    Parameters
    ----------
    geo : Rhino.Geometry.GeometryBase
    tol : float
        Straightness and planarity tolerance [model units].
    """
    fields: Dict[str, Any] = {}
    problem: Optional[str] = None
    if isinstance(geo, rg.Mesh):
        fields["vertices"], fields["faces"] = _mesh_arrays(geo)
    elif isinstance(geo, (rg.Brep, rg.Extrusion)):
        brep = geo.ToBrep(True) if isinstance(geo, rg.Extrusion) else geo
        meshes = rg.Mesh.CreateFromBrep(brep, rg.MeshingParameters.QualityRenderMesh)
        if meshes:
            joined = rg.Mesh()
            for part in meshes:
                joined.Append(part)
            fields["vertices"], fields["faces"] = _mesh_arrays(joined)
        else:
            problem = "Rhino could not mesh this object"
    if isinstance(geo, rg.Curve):
        if not geo.IsClosed and geo.IsLinear(tol):
            fields["line"] = (_xyz(geo.PointAtStart), _xyz(geo.PointAtEnd))
        elif not geo.IsClosed:
            problem = f"the {kind_of(geo)} is not straight"
    plane = _plane(geo, tol)
    if plane is not None:
        fields["plane"] = plane
    return Prepared(problem=problem, **fields)


class DocScene(PreparedScene):
    """The objects of a Rhino document; each is prepared on first use."""

    _cache: Dict[str, Prepared]
    _tol_model: float

    @classmethod
    def from_doc(cls, doc: Rhino.RhinoDoc) -> "DocScene":
        """Every normal object of ``doc`` (names, full layer paths, ids), in metres."""
        scale = Rhino.RhinoMath.UnitScale(doc.ModelUnitSystem, Rhino.UnitSystem.Meters)
        objects: List[SceneObject] = []
        settings = Rhino.DocObjects.ObjectEnumeratorSettings()
        settings.HiddenObjects = True
        settings.LockedObjects = True
        for rh_obj in doc.Objects.GetObjectList(settings):
            attr = rh_obj.Attributes
            layer = doc.Layers[attr.LayerIndex]
            objects.append(
                SceneObject(
                    id=str(rh_obj.Id),
                    name=attr.Name or "",
                    layer=layer.FullPath if layer is not None else "",
                    kind=kind_of(rh_obj.Geometry),
                    geometry=rh_obj.Geometry,
                )
            )
        tol = float(doc.ModelAbsoluteTolerance)
        scene = cls(
            objects,
            unit_scale=scale,
            units=str(doc.ModelUnitSystem).lower(),
            path=doc.Path or None,
            tolerance=tol * scale,
        )
        scene._cache = {}
        scene._tol_model = tol
        return scene

    def _prepared(self, obj: SceneObject) -> Prepared:
        if obj.id not in self._cache:
            self._cache[obj.id] = prepare(obj.geometry, self._tol_model)
        return self._cache[obj.id]
