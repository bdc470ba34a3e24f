"""The triangle mesh type shared by the scene reader and the geometry kernel.

Units are metres once a mesh leaves ``scene_3dm`` (file units are converted on reading).
"""

from dataclasses import dataclass, field
from typing import Any, Dict

import numpy as np

__all__ = ["TriMesh"]


@dataclass(frozen=True)
class TriMesh:
    """An indexed triangle mesh.

    Attributes
    ----------
    vertices : (n, 3) float
        Vertex coordinates [m], float64.
    faces : (m, 3) int
        Vertex indices of each triangle, counter-clockwise seen from outside for a closed
        solid, int64.
    name : str
        Name of the object it comes from (used in every error message about it).
    meta : dict
        Where it comes from: object id, layer, source kind (mesh, brep, extrusion, ...).
    """

    vertices: np.ndarray
    faces: np.ndarray
    name: str = "mesh"
    meta: Dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        v = np.ascontiguousarray(self.vertices, dtype=np.float64)
        f = np.ascontiguousarray(self.faces, dtype=np.int64)
        if v.ndim != 2 or v.shape[1] != 3:
            raise ValueError(f"{self.name}: vertices must have shape (n, 3), got {v.shape}")
        if f.ndim != 2 or f.shape[1] != 3:
            raise ValueError(f"{self.name}: faces must have shape (m, 3), got {f.shape}")
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)

    @property
    def n_triangles(self) -> int:
        """Number of triangles."""
        return int(self.faces.shape[0])

    def transformed(self, matrix: np.ndarray) -> "TriMesh":
        """Return the mesh moved by a 4x4 homogeneous transform (rotation/translation/scale)."""
        m = np.asarray(matrix, dtype=np.float64)
        v = self.vertices @ m[:3, :3].T + m[:3, 3]
        return TriMesh(v, self.faces, self.name, dict(self.meta))
