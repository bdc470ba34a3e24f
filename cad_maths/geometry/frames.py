"""Orthonormal frames: bounding boxes in a frame and the 2D frame of a plane.

Notation
--------
origin : (3,) point of the frame [m]
x_axis, y_axis : (3,) unit axes; z = x × y (right-handed)
u, v, n : in-plane axes and unit normal of a plane, with u × v = n
"""

from typing import Tuple

import numpy as np

from shared_schema.errors import GeometryError, InputError

from .mesh import TriMesh

__all__ = ["bounding_box_in_frame", "frame_axes", "plane_basis", "to_frame"]

#: Two axes count as perpendicular when |cos| of their angle is below this.
ORTHO_TOL = 1e-9


def _unit(vector: np.ndarray, field: str) -> np.ndarray:
    vec = np.asarray(vector, dtype=np.float64).reshape(-1)
    if vec.shape != (3,) or not np.all(np.isfinite(vec)):
        raise InputError(f"must be a finite 3-vector, got {vector!r}", field)
    norm = float(np.linalg.norm(vec))
    if norm == 0.0:
        raise InputError("must be a non-zero vector", field)
    return vec / norm


def plane_basis(normal: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Right-handed orthonormal basis (u, v, n) of a plane with the given normal.

    Parameters
    ----------
    normal : (3,) float
        Plane normal; its length does not matter.

    Returns
    -------
    u, v, n : (3,) float
        In-plane unit axes and the unit normal, with u × v = n.

    Examples
    --------
    >>> u, v, n = plane_basis([0.0, 0.0, 2.0])
    >>> bool(np.allclose(np.cross(u, v), n)) and n.tolist() == [0.0, 0.0, 1.0]
    True
    """
    n = _unit(normal, "normal")
    # The coordinate axis least aligned with n keeps u well conditioned.
    helper = np.zeros(3)
    helper[int(np.argmin(np.abs(n)))] = 1.0
    u = helper - np.dot(helper, n) * n
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    return u, v, n


def frame_axes(x_axis: np.ndarray, y_axis: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the unit axes (x, y, z = x × y) of a frame given two perpendicular directions.

    Parameters
    ----------
    x_axis, y_axis : (3,) float
        Perpendicular directions; their lengths do not matter.

    Returns
    -------
    x, y, z : (3,) float
        Unit axes of the right-handed frame.

    Raises
    ------
    InputError
        If an axis is zero or not finite, or the axes are not perpendicular.
    """
    x = _unit(x_axis, "x_axis")
    y = _unit(y_axis, "y_axis")
    cos = float(np.dot(x, y))
    if abs(cos) > ORTHO_TOL:
        raise InputError(f"must be perpendicular to x_axis (cos = {cos:.3g})", "y_axis")
    return x, y, np.cross(x, y)


def to_frame(
    points: np.ndarray, origin: np.ndarray, x_axis: np.ndarray, y_axis: np.ndarray
) -> np.ndarray:
    """Coordinates of points in the frame (origin, x, y, z = x × y).

    Parameters
    ----------
    points : (k, 3) float
        Points in world coordinates [m].
    origin : (3,) float
        Frame origin [m].
    x_axis, y_axis : (3,) float
        Perpendicular frame directions (normalised here).

    Returns
    -------
    (k, 3) float
        Frame coordinates [m].
    """
    x, y, z = frame_axes(x_axis, y_axis)
    o = np.asarray(origin, dtype=np.float64).reshape(3)
    return (np.asarray(points, dtype=np.float64) - o) @ np.stack([x, y, z], axis=1)


def bounding_box_in_frame(
    mesh: TriMesh, origin: np.ndarray, x_axis: np.ndarray, y_axis: np.ndarray
) -> Tuple[np.ndarray, np.ndarray]:
    """Axis-aligned bounding box of a mesh in the frame (origin, x, y, z = x × y).

    Only vertices used by a face count, so stray vertices do not inflate the box.

    Parameters
    ----------
    mesh : TriMesh
        The mesh [m].
    origin : (3,) float
        Frame origin [m].
    x_axis, y_axis : (3,) float
        Perpendicular frame directions; their lengths do not matter.

    Returns
    -------
    lo, hi : (3,) float
        Minimum and maximum frame coordinates [m].

    Raises
    ------
    InputError
        If the axes are degenerate or not perpendicular.
    GeometryError
        If the mesh has no faces.

    Examples
    --------
    >>> box = TriMesh(np.array([[0.0, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 3]]),
    ...               np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]))
    >>> lo, hi = bounding_box_in_frame(box, [0, 0, 0], [0, 1, 0], [0, 0, 1])
    >>> lo.tolist(), hi.tolist()
    ([0.0, 0.0, 0.0], [1.0, 3.0, 2.0])
    """
    used = np.zeros(len(mesh.vertices), dtype=bool)
    used[mesh.faces.ravel()] = True
    if not used.any():
        raise GeometryError(f"{mesh.name}: has no faces")
    local = to_frame(mesh.vertices[used], origin, x_axis, y_axis)
    return local.min(axis=0), local.max(axis=0)
