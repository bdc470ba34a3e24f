"""Test meshes with known mass properties, built in double precision."""

from typing import Optional, Sequence, Tuple

import numpy as np

from cad_maths.geometry.mesh import TriMesh


def box(lo: Sequence[float], hi: Sequence[float], name: str = "box") -> TriMesh:
    """Axis-aligned box [lo, hi], 8 vertices, 12 outward triangles."""
    lo_, hi_ = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    bits = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=bool)
    verts = np.where(bits, hi_, lo_)
    faces = np.array(
        [
            [0, 2, 3], [0, 3, 1],  # z = lo
            [4, 5, 7], [4, 7, 6],  # z = hi
            [0, 1, 5], [0, 5, 4],  # y = lo
            [2, 6, 7], [2, 7, 3],  # y = hi
            [0, 4, 6], [0, 6, 2],  # x = lo
            [1, 3, 7], [1, 7, 5],  # x = hi
        ]
    )  # fmt: skip
    return TriMesh(verts, faces, name)


def prism(
    outer: np.ndarray,
    z0: float,
    z1: float,
    holes: Sequence[np.ndarray] = (),
    name: str = "prism",
) -> TriMesh:
    """Right prism over a CCW polygon (with CW-wound holes), from z0 to z1."""
    import manifold3d

    loops = [np.asarray(outer, dtype=float)] + [np.asarray(h, dtype=float) for h in holes]
    pts = np.vstack(loops)
    k = len(pts)
    cap = np.asarray(manifold3d.triangulate([np.ascontiguousarray(p) for p in loops]))
    verts = np.vstack([np.c_[pts, np.full(k, z0)], np.c_[pts, np.full(k, z1)]])
    faces = [cap[:, ::-1], cap + k]
    start = 0
    for loop in loops:
        idx = np.arange(start, start + len(loop))
        nxt = np.roll(idx, -1)
        faces.append(np.c_[idx, nxt, nxt + k])
        faces.append(np.c_[idx, nxt + k, idx + k])
        start += len(loop)
    return TriMesh(verts, np.vstack(faces), name)


def regular_polygon(n: int, radius: float) -> np.ndarray:
    """CCW regular n-gon with circumradius ``radius`` centred at the origin."""
    t = 2.0 * np.pi * np.arange(n) / n
    return radius * np.c_[np.cos(t), np.sin(t)]


def rotation(axis: Sequence[float], angle: float) -> np.ndarray:
    """Rotation matrix (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


def moved(
    mesh: TriMesh, rot: np.ndarray, shift: Sequence[float], name: Optional[str] = None
) -> TriMesh:
    """Rigidly moved copy: x -> R x + t."""
    return TriMesh(mesh.vertices @ rot.T + np.asarray(shift), mesh.faces, name or mesh.name)


def convex(points: np.ndarray, name: str = "hull") -> TriMesh:
    """Convex hull of points, outward."""
    import trimesh

    hull = trimesh.convex.convex_hull(np.asarray(points, dtype=float))
    return TriMesh(np.asarray(hull.vertices), np.asarray(hull.faces), name)


def from_manifold(solid: object, name: str) -> TriMesh:
    out = solid.to_mesh64()  # type: ignore[attr-defined]
    return TriMesh(np.asarray(out.vert_properties)[:, :3], np.asarray(out.tri_verts), name)


def to_manifold(mesh: TriMesh) -> object:
    import manifold3d

    return manifold3d.Manifold(
        manifold3d.Mesh64(
            vert_properties=np.ascontiguousarray(mesh.vertices),
            tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64),
        )
    )


def unshared(mesh: TriMesh) -> TriMesh:
    """Same triangles, each with its own three vertices (as CAD exporters often write)."""
    verts = mesh.vertices[mesh.faces].reshape(-1, 3)
    return TriMesh(verts, np.arange(len(verts)).reshape(-1, 3), mesh.name)


def l_prism(name: str = "L") -> TriMesh:
    """L-shaped (non-convex) prism: legs 2 m x 0.5 m, height 1.5 m."""
    outer = np.array([[0, 0], [2, 0], [2, 0.5], [0.5, 0.5], [0.5, 2], [0, 2]], dtype=float)
    return prism(outer, 0.0, 1.5, name=name)


def tetra_volume_check(mesh: TriMesh) -> Tuple[float, np.ndarray]:
    """Volume and centroid by an independent route (trimesh)."""
    import trimesh

    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    return float(tm.volume), np.asarray(tm.center_mass)
