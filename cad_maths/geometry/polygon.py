"""Triangulation of planar polygons with holes, by index over the input points.

Python 3.9-clean: imported by Rhino 8.
"""

from typing import List, Sequence, Tuple

import numpy as np

__all__ = ["newell", "orient_rings", "triangulate_polygon"]

# A triangulation whose area differs from the polygon's by more than this fraction is rejected.
AREA_RTOL = 1e-9


def newell(pts: np.ndarray) -> np.ndarray:
    """Newell's area vector of a closed polygon.

    Parameters
    ----------
    pts : (n, 3) float
        Vertices in order, not repeating the first.

    Returns
    -------
    (3,) float
        Twice the vector area (normal times twice the area), right-hand rule along ``pts``.

    Examples
    --------
    >>> newell(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])).tolist()
    [0.0, 0.0, 1.0]
    """
    c = pts - pts.mean(axis=0)
    return np.cross(c, np.roll(c, -1, axis=0)).sum(axis=0)


def _area2(p: np.ndarray) -> float:
    """Twice the signed area of a polygon (n, 2), positive counter-clockwise."""
    x, y = p[:, 0], p[:, 1]
    return float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def orient_rings(rings: Sequence[np.ndarray]) -> List[np.ndarray]:
    """Return a polygon's rings with the outer one counter-clockwise and the holes clockwise.

    Parameters
    ----------
    rings : sequence of (n, 2) float
        The outer boundary first, then the holes, each in either orientation.

    Returns
    -------
    list of (n, 2) float
        The same rings (reversed where needed): the material lies on the left of each edge.

    Examples
    --------
    >>> orient_rings([np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]])])[0].tolist()
    [[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]
    """
    return [r if (_area2(r) > 0.0) == (k == 0) else r[::-1] for k, r in enumerate(rings)]


def triangulate_polygon(
    outer: np.ndarray, holes: Sequence[np.ndarray] = ()
) -> List[Tuple[int, int, int]]:
    """Triangulate a simple polygon with holes, keeping every vertex.

    Parameters
    ----------
    outer : (n, 2) float
        Outer boundary, either orientation, not repeating the first point.
    holes : sequence of (k, 2) float
        Hole boundaries, inside ``outer`` and disjoint, either orientation.

    Returns
    -------
    list of (int, int, int)
        Triangles, counter-clockwise, as indices into the concatenation
        ``[outer, holes[0], holes[1], ...]``. Every input vertex is used; collinear
        vertices are kept (they are needed where a neighbouring face has a vertex there,
        else the mesh would have a T-junction).

    Raises
    ------
    ValueError
        The polygon is degenerate or self-intersecting (the triangles would not cover it).

    Notes
    -----
    ``manifold3d.triangulate`` (ear clipping with hole bridging, O(n log n) in practice)
    works on the float64 points as given and returns indices, so no coordinate is rounded:
    the triangles reuse the caller's exact vertices. The rings are first oriented (outer
    counter-clockwise, holes clockwise) and zero-area holes dropped. The result is checked:
    every vertex used, ``n - 2 + 2 h`` triangles (Euler, ``h`` holes), none inverted, and
    their areas summing to the polygon's within ``AREA_RTOL``. manifold3d may join
    collinear vertices of different rings by a zero-area triangle; each such sliver is
    removed by flipping its long edge with the neighbouring triangle (two proper triangles
    replace the pair), so no triangle of the result is degenerate.

    Examples
    --------
    >>> sq = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], float)
    >>> hole = np.array([[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]], float)
    >>> len(triangulate_polygon(sq, [hole]))
    8
    """
    import manifold3d  # compiled; only the Brep tessellation needs it

    rings_in = [np.asarray(outer, dtype=np.float64).reshape(-1, 2)] + [
        np.asarray(h, dtype=np.float64).reshape(-1, 2) for h in holes
    ]
    pts = np.vstack(rings_in)
    size = float(np.linalg.norm(pts.max(0) - pts.min(0))) if pts.size else 0.0
    if not size > 0.0 or not np.all(np.isfinite(pts)):
        raise ValueError("the polygon is degenerate (zero size or non-finite points)")
    # areas about a point of the polygon: no cancellation far from the origin
    lo = pts.min(axis=0)
    pts = pts - lo
    rings_in = [r - lo for r in rings_in]
    eps = 1e-12 * size * size  # area tolerance for orientation tests
    rings: List[np.ndarray] = []
    start = 0
    for k, r in enumerate(rings_in):
        ids = np.arange(start, start + r.shape[0])
        start += r.shape[0]
        a2 = _area2(r) if r.shape[0] >= 3 else 0.0
        if abs(a2) <= eps:
            if k == 0:
                raise ValueError("the outer boundary has zero area")
            continue  # a zero-area hole removes nothing
        if (a2 > 0.0) != (k == 0):
            ids = ids[::-1]  # outer counter-clockwise, holes clockwise
        rings.append(ids)
    target = sum(abs(_area2(pts[r])) * (1 if k == 0 else -1) for k, r in enumerate(rings))
    order = np.concatenate(rings)
    local = np.asarray(
        manifold3d.triangulate([np.ascontiguousarray(pts[r]) for r in rings]), dtype=np.int64
    ).reshape(-1, 3)
    tris = _flip_slivers(pts, order[local], eps)
    if tris.shape[0] != order.size - 2 + 2 * (len(rings) - 1) or np.unique(tris).size != order.size:
        raise ValueError("degenerate boundary (zero-width spike, repeated vertex or crossing)")
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    got = float(area2.sum())
    if np.any(area2 < -eps) or abs(got - target) > AREA_RTOL * max(abs(target), eps) + 8 * eps:
        raise ValueError(
            f"triangulation covers area {got / 2:.6g} instead of {target / 2:.6g} "
            "(self-intersecting boundary or overlapping holes)"
        )
    return [(int(i), int(j), int(k)) for i, j, k in tris.tolist()]


def _flip_slivers(pts: np.ndarray, tris: np.ndarray, eps: float) -> np.ndarray:
    """Replace each zero-area triangle and its neighbour across its long edge by two.

    A sliver (a, b, c) with b on the segment ca shares the edge c→a with a neighbour
    (a, c, d); the pair becomes (a, b, d) and (b, c, d), both counter-clockwise when d is
    left of a→c. Repeats until no sliver is left (each flip removes one).
    """
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    bad = np.flatnonzero(np.abs(area2) <= eps)
    if bad.size == 0:
        return tris
    out = tris.copy()
    owner = {}
    for t, (i, j, k) in enumerate(out.tolist()):
        owner[(i, j)], owner[(j, k)], owner[(k, i)] = t, t, t
    todo = [int(t) for t in bad]
    for _ in range(4 * len(todo) + 8):
        if not todo:
            return out
        t = todo.pop()
        tri = out[t].tolist()
        p = pts[tri]
        # the middle vertex of a collinear triple is opposite the longest edge
        lengths = [float(np.sum((p[(m + 2) % 3] - p[(m + 1) % 3]) ** 2)) for m in range(3)]
        m = int(np.argmax(lengths))
        vb, vc, va = tri[m], tri[(m + 1) % 3], tri[(m + 2) % 3]
        nb = owner.get((va, vc))
        if nb is None:
            raise ValueError("degenerate boundary (a zero-area triangle on the boundary)")
        vd = next(v for v in out[nb].tolist() if v not in (va, vc))
        out[t], out[nb] = (va, vb, vd), (vb, vc, vd)
        for u, w in ((va, vb), (vb, vd), (vd, va)):
            owner[(u, w)] = t
        for u, w in ((vb, vc), (vc, vd), (vd, vb)):
            owner[(u, w)] = nb
        owner.pop((vc, va), None)
        owner.pop((va, vc), None)
        for s_ in (t, nb):
            q = pts[out[s_]]
            if abs(_cross(q[0], q[1], q[2])) <= eps and s_ not in todo:
                todo.append(s_)
    raise ValueError("degenerate boundary (zero-area triangles cannot be removed)")


def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))
