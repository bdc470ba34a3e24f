"""Plane cuts of closed solids (cracks), in double precision with manifold3d.

``manifold3d.Mesh`` and trimesh's boolean wrapper round coordinates to float32
(0.15 comes back as 0.149999857), so the solid is passed as a ``Mesh64`` and read back
with ``to_mesh64``. Coordinates are shifted to the bounding-box centre before the cut,
so a scene far from the origin keeps its accuracy.

Notation
--------
point : (3,) a point of the plane [m]
normal : (3,) plane normal; the "positive" side is the one it points to
"""

from typing import Tuple

import numpy as np

from shared_schema.errors import GeometryError, InputError
from shared_schema.extras import require

from .mesh import TriMesh
from .validate import check_solid

__all__ = ["cut_by_plane", "split_by_plane"]

#: A side with less than this × the body's volume counts as empty [-].
EMPTY_RTOL = 1e-12


def _plane(point: np.ndarray, normal: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    p = np.asarray(point, dtype=np.float64).reshape(-1)
    n = np.asarray(normal, dtype=np.float64).reshape(-1)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise InputError(f"must be a finite 3-vector, got {point!r}", "point")
    if n.shape != (3,) or not np.all(np.isfinite(n)) or not np.linalg.norm(n) > 0.0:
        raise InputError(f"must be a finite non-zero 3-vector, got {normal!r}", "normal")
    return p, n / np.linalg.norm(n)


def _to_trimesh(solid: object, ref: np.ndarray, mesh: TriMesh, side: str) -> TriMesh:
    out = solid.to_mesh64()  # type: ignore[attr-defined]
    verts = np.asarray(out.vert_properties, dtype=np.float64)[:, :3] + ref
    faces = np.asarray(out.tri_verts, dtype=np.int64)
    meta = dict(mesh.meta)
    meta["cut_side"] = side
    return TriMesh(verts, faces, mesh.name, meta)


def split_by_plane(mesh: TriMesh, point: np.ndarray, normal: np.ndarray) -> Tuple[TriMesh, TriMesh]:
    """Split a closed solid by a plane into two capped, watertight solids.

    Parameters
    ----------
    mesh : TriMesh
        A valid solid (see ``check_solid``) [m].
    point : (3,) float
        A point of the plane [m].
    normal : (3,) float
        Plane normal; its length does not matter.

    Returns
    -------
    positive, negative : TriMesh
        The parts on the side the normal points to and on the other side. Both keep
        ``mesh.name``; ``meta["cut_side"]`` says which side each is.

    Raises
    ------
    InputError
        If ``point`` or ``normal`` is invalid.
    GeometryError
        If the mesh is not a valid solid, or the plane misses it (one side is empty).

    Notes
    -----
    ``manifold3d.Manifold.split_by_plane`` in double precision; the caps are exact
    polygons of the section, so V(positive) + V(negative) = V to rounding.
    """
    manifold3d = require("manifold3d", "geometry", "to cut solids")

    p, n = _plane(point, normal)
    check_solid(mesh, repair=False)
    v = mesh.vertices
    ref = 0.5 * (v.min(axis=0) + v.max(axis=0))
    data = manifold3d.Mesh64(
        vert_properties=np.ascontiguousarray(v - ref),
        tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64),
    )
    solid = manifold3d.Manifold(data)
    if solid.status() != manifold3d.Error.NoError:
        raise GeometryError(f"{mesh.name}: manifold3d rejects the mesh ({solid.status()})")
    volume = solid.volume()
    pos, neg = solid.split_by_plane(n.tolist(), float(np.dot(p - ref, n)))
    for part, side in ((pos, "positive"), (neg, "negative")):
        if part.is_empty() or not part.volume() > EMPTY_RTOL * volume:
            other = "negative" if side == "positive" else "positive"
            raise GeometryError(
                f"{mesh.name}: the cut plane through {p.tolist()} with normal "
                f"{n.tolist()} misses the body (it lies entirely on the {other} side)"
            )
    return _to_trimesh(pos, ref, mesh, "positive"), _to_trimesh(neg, ref, mesh, "negative")


def cut_by_plane(
    mesh: TriMesh, point: np.ndarray, normal: np.ndarray, *, keep: str = "positive"
) -> TriMesh:
    """Cut a closed solid by a plane and keep one side, capped and watertight.

    Parameters
    ----------
    mesh : TriMesh
        A valid solid [m].
    point : (3,) float
        A point of the plane [m].
    normal : (3,) float
        Plane normal; its length does not matter.
    keep : {"positive", "negative"}, optional
        Keep the side the normal points to, or the other one.

    Returns
    -------
    TriMesh
        The kept part, with ``mesh.name``.

    Raises
    ------
    InputError
        If ``keep`` is not "positive" or "negative", or the plane is invalid.
    GeometryError
        If the mesh is not a valid solid or the plane misses it.

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box(extents=[1.0, 1.0, 1.0])
    >>> top = cut_by_plane(TriMesh(box.vertices, box.faces, "box"), [0, 0, 0.3], [0, 0, 1])
    >>> round(float(top.vertices[:, 2].min()), 12), float(top.vertices[:, 2].max())
    (0.3, 0.5)
    """
    if keep not in ("positive", "negative"):
        raise InputError(f"must be 'positive' or 'negative', got {keep!r}", "keep")
    pos, neg = split_by_plane(mesh, point, normal)
    return pos if keep == "positive" else neg
