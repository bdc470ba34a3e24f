"""The hand-written ear clipper that ``triangulate_polygon`` used before manifold3d.

Kept only as the benchmark's peer (``benchmarks/geometry_speed.py --triangulation``): holes
joined to the outer boundary by bridge edges, then ear clipping, O(n²) to O(n³).
"""

from typing import List, Sequence, Tuple

import numpy as np

# A triangulation whose area differs from the polygon's by more than this fraction is rejected.
AREA_RTOL = 1e-9


def _area2(p: np.ndarray) -> float:
    """Twice the signed area of a polygon (n, 2), positive counter-clockwise."""
    x, y = p[:, 0], p[:, 1]
    return float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def triangulate_polygon_earclip(
    outer: np.ndarray, holes: Sequence[np.ndarray] = ()
) -> List[Tuple[int, int, int]]:
    """Triangulate a simple polygon with holes by ear clipping.

    Parameters
    ----------
    outer : (n, 2) float
        Outer boundary, either orientation, not repeating the first point.
    holes : sequence of (k, 2) float
        Hole boundaries, inside ``outer`` and disjoint.

    Returns
    -------
    list of (int, int, int)
        Triangles, counter-clockwise, as indices into the concatenation
        ``[outer, holes[0], holes[1], ...]``. Every input vertex is used; collinear
        vertices are kept (they are needed where a neighbouring face has a vertex there).

    Raises
    ------
    ValueError
        The polygon is degenerate or self-intersecting (the triangles would not cover it).

    Notes
    -----
    Each hole is joined to the boundary by a bridge edge from its right-most vertex to the
    nearest visible boundary vertex (holes in decreasing order of x), which gives one weakly
    simple polygon; ears are then clipped. The result is checked: the triangle areas must sum
    to the polygon's area within ``AREA_RTOL``.

    Examples
    --------
    >>> sq = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], float)
    >>> hole = np.array([[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]], float)
    >>> len(triangulate_polygon(sq, [hole]))
    8
    """
    rings_in = [np.asarray(outer, dtype=np.float64)] + [
        np.asarray(h, dtype=np.float64) for h in holes
    ]
    pts = np.vstack(rings_in)
    size = float(np.linalg.norm(pts.max(0) - pts.min(0))) if pts.size else 0.0
    if size == 0.0:
        raise ValueError("the polygon is degenerate (zero size)")
    eps = 1e-12 * size * size  # area tolerance for orientation tests
    rings: List[List[int]] = []
    start = 0
    for k, r in enumerate(rings_in):
        ids = list(range(start, start + r.shape[0]))
        start += r.shape[0]
        a2 = _area2(r) if r.shape[0] >= 3 else 0.0
        if abs(a2) <= eps:
            if k == 0:
                raise ValueError("the outer boundary has zero area")
            continue  # a zero-area hole removes nothing
        if (a2 > 0.0) != (k == 0):
            ids.reverse()  # outer counter-clockwise, holes clockwise
        rings.append(ids)
    target = sum(abs(_area2(pts[r])) * (1 if k == 0 else -1) for k, r in enumerate(rings))
    ring = rings[0]
    holes_sorted = sorted(rings[1:], key=lambda h: -float(pts[h, 0].max()))
    for hole in holes_sorted:
        ring = _bridge(pts, ring, hole, holes_sorted, eps)
    tris = _ear_clip(pts, ring, eps)
    if len(tris) != len(ring) - 2:  # a zero-area triangle was left: T-junction
        raise ValueError("degenerate boundary (zero-width spike or repeated vertex)")
    got = sum(_cross(pts[a], pts[b], pts[c]) for a, b, c in tris)
    if abs(got - target) > AREA_RTOL * max(abs(target), eps) + 8 * eps:
        raise ValueError(
            f"triangulation covers area {got / 2:.6g} instead of {target / 2:.6g} "
            "(self-intersecting boundary or overlapping holes)"
        )
    return tris


def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _segments_cross(
    p1: np.ndarray, p2: np.ndarray, q1: np.ndarray, q2: np.ndarray, eps: float
) -> bool:
    """Whether segments p1p2 and q1q2 intersect (touching included, shared ends excluded)."""
    d1 = _cross(q1, q2, p1)
    d2 = _cross(q1, q2, p2)
    d3 = _cross(p1, p2, q1)
    d4 = _cross(p1, p2, q2)
    if ((d1 > eps and d2 < -eps) or (d1 < -eps and d2 > eps)) and (
        (d3 > eps and d4 < -eps) or (d3 < -eps and d4 > eps)
    ):
        return True

    def on(a: np.ndarray, b: np.ndarray, p: np.ndarray, d: float) -> bool:
        return (
            abs(d) <= eps
            and min(a[0], b[0]) <= p[0] <= max(a[0], b[0])
            and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])
        )

    return on(q1, q2, p1, d1) or on(q1, q2, p2, d2) or on(p1, p2, q1, d3) or on(p1, p2, q2, d4)


def _locally_inside(
    pts: np.ndarray, prev: int, cur: int, nxt: int, p: np.ndarray, eps: float
) -> bool:
    """Whether direction cur->p starts into the interior (left side) at vertex cur."""
    c = pts[cur]
    a, b = pts[nxt], pts[prev]
    if _cross(b, c, a) >= 0.0:  # convex corner (interior angle <= 180 deg)
        return _cross(c, a, p) > eps and _cross(c, p, b) > eps
    return not (_cross(c, b, p) >= -eps and _cross(c, p, a) >= -eps)


def _bridge(
    pts: np.ndarray, ring: List[int], hole: List[int], holes: List[List[int]], eps: float
) -> List[int]:
    """Splice a hole into the ring through a bridge edge to a visible ring vertex."""
    hm = max(range(len(hole)), key=lambda i: (pts[hole[i], 0], -pts[hole[i], 1]))
    m = hole[hm]
    pm = pts[m]
    edges = [(ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring))]
    for h in holes:
        edges.extend((h[i], h[(i + 1) % len(h)]) for i in range(len(h)))
    hprev, hnext = hole[hm - 1], hole[(hm + 1) % len(hole)]
    cands = sorted(range(len(ring)), key=lambda i: float(np.sum((pts[ring[i]] - pm) ** 2)))
    for i in cands:
        p = ring[i]
        pp = pts[p]
        if np.array_equal(pp, pm):
            continue
        if not _locally_inside(pts, ring[i - 1], p, ring[(i + 1) % len(ring)], pm, eps):
            continue
        if not _locally_inside(pts, hprev, m, hnext, pp, eps):
            continue
        blocked = False
        for a, b in edges:
            if a in (p, m) or b in (p, m):
                continue
            if np.array_equal(pts[a], pp) or np.array_equal(pts[b], pp):
                continue
            if _segments_cross(pm, pp, pts[a], pts[b], eps):
                blocked = True
                break
        if not blocked:
            k = hm
            loop = hole[k:] + hole[:k] + [m]
            return ring[: i + 1] + loop + ring[i:]
    raise ValueError("a hole cannot be joined to the boundary (does it lie outside it?)")


def _ear_clip(pts: np.ndarray, ring: List[int], eps: float) -> List[Tuple[int, int, int]]:
    tris: List[Tuple[int, int, int]] = []
    ring = list(ring)
    strict = True
    i = 0
    stall = 0
    while len(ring) > 3:
        n = len(ring)
        a, b, c = ring[(i - 1) % n], ring[i % n], ring[(i + 1) % n]
        if _is_ear(pts, ring, a, b, c, eps, strict):
            tris.append((a, b, c))
            del ring[i % n]
            i = (i - 1) % len(ring)
            stall = 0
            strict = True
            continue
        i = (i + 1) % n
        stall += 1
        if stall > n:
            if not strict:
                raise ValueError("no ear found (self-intersecting boundary?)")
            strict = False
            stall = 0
    if len(ring) == 3:
        a, b, c = ring
        if _cross(pts[a], pts[b], pts[c]) > eps:
            tris.append((a, b, c))
    return tris


def _is_ear(
    pts: np.ndarray, ring: List[int], a: int, b: int, c: int, eps: float, strict: bool
) -> bool:
    pa, pb, pc = pts[a], pts[b], pts[c]
    if _cross(pa, pb, pc) <= eps:
        return False
    # a bridge revisits the same point: only points elsewhere can block the ear
    for k in ring:
        if k in (a, b, c):
            continue
        p = pts[k]
        if np.array_equal(p, pa) or np.array_equal(p, pb) or np.array_equal(p, pc):
            continue
        lim = -eps if strict else eps
        if _cross(pa, pb, p) >= lim and _cross(pb, pc, p) >= lim and _cross(pc, pa, p) >= lim:
            return False
    return True
