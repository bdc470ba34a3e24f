"""The search's own scene: the objects it uses, as meshes and lines in metres.

The search reads each wall, level and tie of the input scene once and keeps them here;
the constants builder then computes every kept mechanism from this scene (no re-meshing),
and ``rockmech search`` writes it, with the crack layer, as a ``.3dm`` that the search
spec reopens. Objects keep the input's ids and names, so the same spec also reopens the
input scene, except where openings drawn as solids were cut out of a wall: that wall is a
new object (its name gains ``OPENINGS_SUFFIX``), so that the input scene, whose wall has
no voids, cannot be used by mistake.

Python 3.9-clean: imported by Rhino 8.
"""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from cad_maths.geometry.mesh import TriMesh
from cad_maths.scene_base import BaseScene, SceneObject
from shared_schema.errors import GeometryError

__all__ = ["OPENINGS_SUFFIX", "MemoryScene"]

#: Name suffix of a wall with the openings drawn as solids cut out of it.
OPENINGS_SUFFIX = " (openings cut)"


class MemoryScene(BaseScene):
    """A scene of prepared meshes and lines [m] (``geometry`` of each object).

    Parameters
    ----------
    objects : list of SceneObject
        Each ``geometry`` is a ``TriMesh`` (solid) or a pair of points (line).
    path : str, optional
        The input scene's name (for messages and provenance).
    tolerance : float
        Model absolute tolerance [m].
    source_units : str
        The input scene's units (provenance only: the objects are in metres).
    """

    def __init__(
        self,
        objects: List[SceneObject],
        path: Optional[str] = None,
        tolerance: float = 0.0,
        source_units: str = "meters",
    ) -> None:
        super().__init__(objects, unit_scale=1.0, units="meters", path=path, tolerance=tolerance)
        self.source_units = source_units

    def mesh(self, obj: SceneObject, require_closed: bool = True) -> TriMesh:
        """Return the object's mesh [m]."""
        if not isinstance(obj.geometry, TriMesh):
            raise GeometryError(f"{obj.label()}: a {obj.kind} is not a solid")
        return obj.geometry

    def line(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Return a line object's end points [m]."""
        geo: Any = obj.geometry
        if not (isinstance(geo, tuple) and len(geo) == 2):
            raise GeometryError(f"{obj.label()}: a {obj.kind} is not a line")
        return np.asarray(geo[0], dtype=float), np.asarray(geo[1], dtype=float)

    def plane(self, obj: SceneObject) -> Tuple[np.ndarray, np.ndarray]:
        """Refuse: the search gives cracks by points; no object of this scene is a plane."""
        raise GeometryError(f"{obj.label()}: the search's scene has no plane objects")

    def add(self, obj: SceneObject) -> None:
        """Add an object (once: an id already present is kept as it is)."""
        if all(o.id != obj.id for o in self.objects):
            self.objects.append(obj)

    def by_id(self) -> Dict[str, SceneObject]:
        """Return the objects by id."""
        return {o.id: o for o in self.objects}
