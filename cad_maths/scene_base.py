"""What every scene reader shares: objects, selection, units and the solid-mesh gate.

A scene lists objects (name, layer path, kind, user text, reader-specific geometry) and
turns them into what the mechanisms need, in metres whatever the file's units:
:meth:`BaseScene.mesh` (a closed solid), :meth:`BaseScene.line` (rocking axis, tie-bar) and
:meth:`BaseScene.plane` (crack). The readers are :mod:`cad_maths.scene_3dm` (Rhino
``.3dm`` files), :mod:`cad_maths.scene_mesh` (scan meshes: PLY, OBJ, STL, OFF) and the
Rhino glue's :class:`~rhino_plugin.flows.prepared.PreparedScene`.

Python 3.9-clean: imported by Rhino 8.
"""

import os
import uuid
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

from cad_maths.geometry.mesh import TriMesh
from cad_maths.geometry.topology import orient_outward, weld
from cad_maths.geometry.validate import REPAIRS_KEY
from shared_schema.errors import GeometryError, InputError
from shared_schema.rules import COORDINATE_LIMIT, body_size_note

__all__ = ["BaseScene", "SceneObject", "solid_mesh"]

# How many available names, layers or ids an error message lists.
N_LISTED = 12


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
        """Name, layer (if any) and short id, for messages: ``"wall (Walls, 1a2b3c4d)"``."""
        name = self.name or f"<unnamed {self.kind}>"
        where = f"{self.layer}, " if self.layer else ""
        return f"{name} ({where}{self.id[:8]})"


class BaseScene:
    """Objects of a scene and their conversion to metres; readers add the geometry.

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
        # metres per unit as an exact ratio (numerator, denominator): 1000 mm is exactly 1 m
        self._ratio: Tuple[float, float] = (self.unit_scale, 1.0)
        self._layer_paths: List[str] = []

    def __repr__(self) -> str:
        n = len(self.objects)
        return f"{type(self).__name__}({self.path!r}, {n} objects, units={self.units!r})"

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
            Unknown selector key, nothing matches (the message lists available names or
            layers), or a name that several objects share (the message lists their ids;
            select them by id or by layer).
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
            raise InputError(
                f"no object with {key} {value!r} in {where}{avail}{self._miss_hint()}", "selector"
            )
        if key == "name" and len(hits) > 1:
            # one rocking body per name: merging namesakes silently is issue #14
            where = os.path.basename(self.path) if self.path else "the scene"
            ids = ", ".join(repr(o.id) for o in hits[:N_LISTED])
            more = f", ... ({len(hits)} in all)" if len(hits) > N_LISTED else ""
            raise InputError(
                f"{len(hits)} objects are named {value!r} in {where} (ids {ids}{more}); select "
                'each by {"id": ...}, or put them on one layer and select {"layer": ...}, or '
                "give them distinct names",
                "selector",
            )
        return hits

    # ------------------------------------------------------------------ conversion

    def _to_m(self, xyz: Any, obj: Optional[SceneObject] = None) -> np.ndarray:
        """Coordinates in file units -> metres, refusing what the maths cannot take.

        Raises
        ------
        GeometryError
            A coordinate that is not finite, or beyond ``rules.COORDINATE_LIMIT`` in the
            file's units (checked here, so that no NaN or overflow reaches the geometry).
        """
        num, den = self._ratio
        a = np.asarray(xyz, dtype=np.float64)
        what = obj.label() if obj is not None else "a point of the scene"
        finite = np.isfinite(a)
        if not finite.all():
            k = int(np.argmin(finite.all(axis=-1))) if a.ndim > 1 else 0
            raise GeometryError(
                f"{what}: coordinates must be finite, but point {k} is "
                f"{np.atleast_2d(a)[k].tolist()} (NaN or infinite); repair or re-export it"
            )
        if a.size and float(np.abs(a).max()) > COORDINATE_LIMIT:
            raise GeometryError(f"{what}: {_far_coordinates(a, self.units)}")
        if num != 1.0:
            a = a * num
        if den != 1.0:
            a = a / den
        return a

    #: True for a reader whose file carries no unit (a scan: the user gives ``units``).
    scan = False

    def extent(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Lowest and highest corner of an object's bounding box [m].

        Readers with a cheaper bounding box than the mesh override this.
        """
        v = self.mesh(obj, require_closed=False).vertices
        return v.min(axis=0), v.max(axis=0)

    def size_note(self, object_ids: List[str], what: str) -> Optional[str]:
        """Warn when the objects' bounding box is an implausible size for a rocking body.

        The one plausibility check of a scene's size (``rules.BODY_SIZE_PLAUSIBLE``): a body
        of kilometres or of millimetres was most likely read in the wrong length unit; the
        note names the unit the file was read in and the one that fits.
        """
        wanted = set(object_ids)
        boxes = [self.extent(o) for o in self.objects if o.id in wanted]
        if not boxes:
            return None
        lo = np.min([b[0] for b in boxes], axis=0)
        hi = np.max([b[1] for b in boxes], axis=0)
        size = float(np.linalg.norm(hi - lo))
        return body_size_note(size, self.unit_scale, self.units, what, self.scan)

    def _miss_hint(self) -> str:
        """Extra advice appended when a selector matches nothing (reader-specific)."""
        return ""

    # ------------------------------------------------------------------ geometry

    def mesh(self, obj: SceneObject, require_closed: bool = True) -> TriMesh:
        """Return the object as a triangle mesh in metres, oriented outward."""
        raise NotImplementedError(f"{type(self).__name__} has no mesh reader")

    def line(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Start and end points [m] of a straight line object."""
        raise NotImplementedError(f"{type(self).__name__} has no line reader")

    def plane(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Return a point [m] and the unit normal of a planar object."""
        raise NotImplementedError(f"{type(self).__name__} has no plane reader")


def _norm_id(value: str) -> str:
    try:
        return str(uuid.UUID(value.strip()))
    except ValueError:
        return value.strip().lower()


#: A mesh whose vertices lie within this share of its size of one plane is flat (a surface).
FLAT_RTOL = 1e-9


def _is_flat(v: np.ndarray) -> bool:
    """Tell whether every vertex lies in one plane, within ``FLAT_RTOL`` of the mesh's size."""
    centred = v - v.mean(axis=0)
    size = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    if size == 0.0:
        return True
    # the smallest singular direction is the normal of the best-fitting plane
    normal = np.linalg.svd(centred, full_matrices=False)[2][-1]
    return float(np.abs(centred @ normal).max()) <= FLAT_RTOL * size


def solid_mesh(
    v: np.ndarray, f: np.ndarray, obj: SceneObject, *, require_closed: bool = True
) -> TriMesh:
    """Weld, orient outward and check a triangle mesh of a scene object.

    Merging coincident vertices changes no geometry and is not reported (an STL file or a
    Rhino render mesh repeats every corner); the repairs that change the mesh, degenerate
    faces removed and faces reversed (an inward-facing mesh, or an inconsistent winding),
    are listed in the mesh's ``meta[REPAIRS_KEY]``, which ``check_solid`` reports as
    warnings naming the object (docs/geometry.md).

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
    name = obj.name or obj.label()
    n_given = int(np.asarray(f).reshape(-1, 3).shape[0])
    v, f = weld(v, f)
    if f.shape[0] == 0:
        raise GeometryError(f"{obj.label()}: the {obj.kind} has no faces")
    repairs = []
    if f.shape[0] < n_given:
        # faces with a repeated vertex once coincident vertices are merged: zero area
        repairs.append(
            f"{name}: removed {n_given - f.shape[0]} degenerate faces (zero area: two of "
            "their corners coincide)"
        )
    oriented, closed, n_open = orient_outward(v, f)
    if require_closed and not closed and _is_flat(v):
        # issue #36: a surface drawn for the wall was told to be closed with Cap/Join
        raise GeometryError(
            f"{obj.label()}: the {obj.kind} is flat: its {v.shape[0]} vertices lie in one "
            "plane, so it has zero volume (a surface, not a solid body); model the body with "
            "its thickness, as a closed solid (Rhino: ExtrudeSrf or OffsetSrf with Solid=Yes)"
        )
    if require_closed and not closed:
        raise GeometryError(
            f"{obj.label()}: the {obj.kind} is not a closed solid ({n_open} open or "
            "non-manifold edges); close it in Rhino (Cap, Join, or MeshRepair / FillMeshHoles)"
        )
    n_flipped = int(np.count_nonzero(np.any(oriented != f, axis=1)))
    if n_flipped == f.shape[0]:
        repairs.append(
            f"{name}: faced inward (inside out); all {n_flipped} faces were reversed to face "
            "outward"
        )
    elif n_flipped:
        repairs.append(
            f"{name}: {n_flipped} of its {f.shape[0]} faces were reversed to make the winding "
            "consistent and outward"
        )
    meta: Dict[str, Any] = {"id": obj.id, "layer": obj.layer, "kind": obj.kind}
    if repairs:
        meta[REPAIRS_KEY] = repairs
    return TriMesh(v, oriented, name, meta)


#: An object whose size is below this share of its distance from the origin is taken to be
#: placed in georeferenced coordinates (UTM, a national grid) rather than read in a wrong unit.
GEOREFERENCED_RATIO = 1e-3


def _far_coordinates(a: np.ndarray, units: str) -> str:
    """Say why coordinates beyond ``COORDINATE_LIMIT`` are refused, and what to do.

    A small object far from the origin is georeferenced (a scan in UTM or national-grid
    coordinates): the fix is a local origin, not another unit. A large one was most likely
    read in the wrong unit.
    """
    pts = np.atleast_2d(a)
    far = float(np.abs(pts).max())
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    size = float(np.linalg.norm(hi - lo))
    said = (
        f"a coordinate of {far:g} {units} is beyond the largest magnitude accepted, "
        f"{COORDINATE_LIMIT:g} {units}"
    )
    if size <= GEOREFERENCED_RATIO * far:
        centre = ", ".join(f"{c:.0f}" for c in np.round(0.5 * (lo + hi), -1 if far > 1e4 else 0))
        return (
            f"{said}, but the object is only {size:.4g} {units} across: its coordinates are "
            f"georeferenced (UTM, a national grid), not in a wrong unit. Move the model to a "
            f"local origin before reading it, subtracting about ({centre}) {units} (Rhino: "
            "Move; CloudCompare: Edit > Apply transformation), and give the spec's points in "
            "that local frame"
        )
    return f"{said}; check the file's units, or move the model near the origin"
