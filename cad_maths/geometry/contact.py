"""Contact areas between solids: plane sections, their overlap, and touching faces.

A solid's section by a plane is the closed set solid ∩ plane: the polygons where the plane
cuts through it plus the faces lying in the plane (within ``tol``). Two solids resting on
each other touch exactly along such faces, so a contact plane is usually also a face
plane of both; the section below is built to be exact in that case.

Notation
--------
n : unit plane normal; (u, v, n) right-handed (``frames.plane_basis``)
d : signed distance of a vertex from the plane [m]; |d| <= tol counts as on the plane
"""

from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from shared_schema.errors import GeometryError, InputError
from shared_schema.extras import require

from .frames import plane_basis
from .mesh import TriMesh

__all__ = ["ContactPlane", "contact_area", "contact_region", "find_contact", "section_polygon"]

#: Face normals closer than this (per component) are grouped as one plane [-].
NORMAL_GAP = 1e-5
#: An overlap narrower than tol (area below tol × its length) is not a contact.
MIN_WIDTH_FACTOR = 1.0


def _as_plane(point: Any, normal: Any) -> Tuple[np.ndarray, np.ndarray]:
    p = np.asarray(point, dtype=np.float64).reshape(-1)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise InputError(f"must be a finite 3-vector, got {point!r}", "plane_point")
    n = np.asarray(normal, dtype=np.float64).reshape(-1)
    if n.shape != (3,) or not np.all(np.isfinite(n)) or not np.linalg.norm(n) > 0.0:
        raise InputError(f"must be a finite non-zero 3-vector, got {normal!r}", "plane_normal")
    return p, n


def _outline_rings(faces: np.ndarray) -> Optional[List[List[int]]]:
    """Boundary loops (vertex ids) of a patch of consistently oriented triangles.

    Edges used once in the patch are its boundary; they are chained into closed walks.
    Returns None if the patch is not an oriented 2-manifold with boundary (then the
    caller falls back to a polygon union).
    """
    a = faces.ravel()
    b = np.roll(faces, -1, axis=1).ravel()
    n = int(faces.max()) + 1
    key = np.minimum(a, b) * n + np.maximum(a, b)
    _, inverse, counts = np.unique(key, return_inverse=True, return_counts=True)
    count = counts[inverse]
    if np.any(count > 2):
        return None
    pair_dir = np.bincount(inverse, weights=(a > b), minlength=len(counts))
    if np.any((counts == 2) & (pair_dir != 1)):
        return None
    boundary = count == 1
    succ: Dict[int, List[int]] = {}
    for s, e in zip(a[boundary].tolist(), b[boundary].tolist()):
        succ.setdefault(s, []).append(e)
    rings: List[List[int]] = []
    while succ:
        start = next(iter(succ))
        ring, cur = [start], start
        while True:
            options = succ.get(cur)
            if not options:
                return None
            nxt = options.pop()
            if not options:
                del succ[cur]
            if nxt == start:
                break
            ring.append(nxt)
            cur = nxt
        rings.append(ring)
    return rings


def _patch_region(faces: np.ndarray, xy: np.ndarray) -> Any:
    """Region covered by a patch of triangles lying in the plane, (u, v) coordinates.

    Parameters
    ----------
    faces : (k, 3) int
        Triangles (vertex ids) of a valid mesh, all lying in the plane.
    xy : (n, 2) float
        Plane coordinates of the vertices [m].
    """
    shapely = require("shapely", "geometry", "for contact polygons")

    tri = xy[faces]
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    up = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] >= 0.0
    parts = []
    # Faces seen from either side of the plane are outlined separately (a thin slab can
    # have both its faces within tol).
    for side in (up, ~up):
        if not side.any():
            continue
        rings = _outline_rings(faces[side])
        if rings is None:
            parts.append(_triangles_union(tri[side]))
        else:
            parts.append(_rings_xor([xy[r] for r in rings]))
    if not parts:
        return shapely.Polygon()
    return shapely.union_all(parts) if len(parts) > 1 else parts[0]


def _triangles_union(tri2d: np.ndarray) -> Any:
    """Union of 2D triangles (k, 3, 2) as a shapely geometry (degenerate ones skipped)."""
    shapely = require("shapely", "geometry", "for contact polygons")

    e1 = tri2d[:, 1] - tri2d[:, 0]
    e2 = tri2d[:, 2] - tri2d[:, 0]
    area2 = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    scale = np.maximum(np.sum(e1 * e1, axis=1), np.sum(e2 * e2, axis=1))
    tri2d = tri2d[np.abs(area2) > 1e-12 * scale]
    if len(tri2d) == 0:
        return shapely.Polygon()
    rings = np.concatenate([tri2d, tri2d[:, :1]], axis=1)
    return shapely.union_all(shapely.polygons(rings))


def _rings_xor(rings: List[np.ndarray]) -> Any:
    """Even-odd composition of closed 2D rings (outer boundaries and holes alike)."""
    shapely = require("shapely", "geometry", "for contact polygons")

    result = shapely.Polygon()
    for ring in rings:
        poly = shapely.Polygon(ring)
        if not poly.is_valid:
            poly = shapely.make_valid(poly)
        if poly.area > 0.0:
            result = shapely.symmetric_difference(result, poly)
    return result


def section_polygon(
    mesh: TriMesh,
    origin: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    n: np.ndarray,
    *,
    tol: float = 1e-6,
) -> Any:
    """Section of a closed, oriented solid by a plane, in the plane's 2D frame.

    Parameters
    ----------
    mesh : TriMesh
        A valid solid (see ``check_solid``) [m].
    origin : (3,) float
        A point of the plane; the 2D origin [m].
    u, v, n : (3,) float
        Orthonormal in-plane axes and unit normal, u × v = n.
    tol : float, optional
        Vertices within this distance of the plane count as on it [m].

    Returns
    -------
    shapely geometry
        Polygon(s) in (u, v) coordinates [m]; empty if the plane misses the solid.

    Raises
    ------
    GeometryError
        If the cut edges do not close into loops (the mesh is not a closed solid).

    Notes
    -----
    Vertices on the plane are snapped to it and treated as lying on its negative side,
    which gives the section just above the plane; faces lying in the plane are added, so
    the result is solid ∩ plane whichever side the solid is on. Each cut triangle gives one
    segment, from its positive→negative edge to its negative→positive edge; segments are
    chained through shared mesh edges (no coordinate matching) and the loops combined by
    the even-odd rule.
    """
    shapely = require("shapely", "geometry", "for contact polygons")

    rel = mesh.vertices - origin
    d = rel @ n
    xy = np.stack([rel @ u, rel @ v], axis=1)
    on = np.abs(d) <= tol
    d = np.where(on, 0.0, d)
    f = mesh.faces
    flat = on[f].all(axis=1)
    parts = []
    if flat.any():
        parts.append(_patch_region(f[flat], xy))

    pos = (d > 0.0)[f]
    npos = pos.sum(axis=1)
    cut = (npos == 1) | (npos == 2)
    if cut.any():
        fc, pc = f[cut], pos[cut]
        nxt = [1, 2, 0]
        up = ~pc & pc[:, nxt]
        k_up = np.argmax(up, axis=1)
        k_down = np.argmax(pc & ~pc[:, nxt], axis=1)
        rows = np.arange(len(fc))
        n_v = len(mesh.vertices)

        def edge(k: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
            i, j = fc[rows, k], fc[rows, (k + 1) % 3]
            t = d[i] / (d[i] - d[j])
            point = xy[i] + t[:, None] * (xy[j] - xy[i])
            return np.minimum(i, j) * n_v + np.maximum(i, j), point

        start_key, start_pt = edge(k_down)
        end_key, _ = edge(k_up)
        order = np.argsort(start_key)
        pos_in_sorted = np.searchsorted(start_key[order], end_key)
        pos_in_sorted = np.minimum(pos_in_sorted, len(order) - 1)
        succ = order[pos_in_sorted]
        if not np.array_equal(start_key[succ], end_key) or len(np.unique(succ)) != len(succ):
            raise GeometryError(
                f"{mesh.name}: its section by the plane does not close (not a closed, "
                "consistently oriented solid)"
            )
        seen = np.zeros(len(fc), dtype=bool)
        rings = []
        succ_list = succ.tolist()
        for s0 in range(len(fc)):
            if seen[s0]:
                continue
            loop = []
            s = s0
            while not seen[s]:
                seen[s] = True
                loop.append(s)
                s = succ_list[s]
            pts = start_pt[loop]
            keep = np.ones(len(pts), dtype=bool)
            keep[1:] = np.any(pts[1:] != pts[:-1], axis=1)
            pts = pts[keep]
            if len(pts) > 1 and np.all(pts[-1] == pts[0]):
                pts = pts[:-1]
            if len(pts) >= 3:
                rings.append(pts)
        parts.append(_rings_xor(rings))
    if not parts:
        return shapely.Polygon()
    return shapely.union_all(parts) if len(parts) > 1 else parts[0]


def _to_world(
    geom: Any, origin: np.ndarray, u: np.ndarray, v: np.ndarray
) -> Tuple[float, np.ndarray]:
    area = float(geom.area)
    if not area > 0.0:
        return 0.0, np.full(3, np.nan)
    c = geom.centroid
    return area, origin + c.x * u + c.y * v


def contact_area(
    a: TriMesh,
    b: TriMesh,
    plane_point: np.ndarray,
    plane_normal: np.ndarray,
    *,
    tol: float = 1e-6,
) -> Tuple[float, np.ndarray]:
    """Area and centroid of the overlap of two solids' sections by a plane.

    Parameters
    ----------
    a, b : TriMesh
        Valid solids (see ``check_solid``) [m].
    plane_point : (3,) float
        A point of the plane [m].
    plane_normal : (3,) float
        Plane normal, any orientation; its length does not matter.
    tol : float, optional
        Vertices within this distance of the plane count as on it [m].

    Returns
    -------
    area : float
        Overlap area [m²]; 0 if the sections do not overlap.
    centroid : (3,) float
        Centroid of the overlap, in the plane [m]; NaN where ``area`` is 0.

    Raises
    ------
    InputError
        If the plane is invalid.
    GeometryError
        If a mesh's section does not close.

    Notes
    -----
    Sections by ``section_polygon`` in the plane's (u, v) frame, intersected with
    shapely. For two blocks resting on each other, pass their interface plane: each
    block's face in it is part of its section.

    Examples
    --------
    >>> import trimesh
    >>> lo = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    >>> hi = trimesh.creation.box(bounds=[[0.5, 0, 1], [2, 1, 2]])
    >>> area, c = contact_area(TriMesh(lo.vertices, lo.faces), TriMesh(hi.vertices, hi.faces),
    ...                        [0, 0, 1], [0, 0, 1])
    >>> round(area, 12), c.round(12).tolist()
    (0.5, [0.75, 0.5, 1.0])
    """
    if not tol >= 0.0:
        raise InputError(f"must be >= 0 [m], got {tol!r}", "tol")
    p, normal = _as_plane(plane_point, plane_normal)
    u, v, n = plane_basis(normal)
    sa = section_polygon(a, p, u, v, n, tol=tol)
    if sa.is_empty:
        return 0.0, np.full(3, np.nan)
    sb = section_polygon(b, p, u, v, n, tol=tol)
    return _to_world(sa.intersection(sb), p, u, v)


def _single_linkage(columns: List[np.ndarray], gaps: List[float]) -> np.ndarray:
    """Group rows whose values chain within ``gap`` in each column, column after column."""
    label = np.zeros(len(columns[0]), dtype=np.int64)
    for col, gap in zip(columns, gaps):
        order = np.lexsort((col, label))
        ls, cs = label[order], col[order]
        new = np.ones(len(order), dtype=bool)
        new[1:] = (ls[1:] != ls[:-1]) | (np.diff(cs) > gap)
        label = np.empty_like(label)
        label[order] = np.cumsum(new) - 1
    return label


def contact_region(
    a: TriMesh, b: TriMesh, *, tol: float = 1e-6
) -> Optional[Tuple[float, np.ndarray, np.ndarray, "ContactPlane"]]:
    """Largest planar contact between two solids, with its region in the contact plane.

    Faces of ``a`` and ``b`` that are coplanar within ``tol``, with opposite normals,
    are grouped by plane; in each plane the union of a's faces is intersected with the
    union of b's faces.

    Parameters
    ----------
    a, b : TriMesh
        Valid, outward-facing solids (see ``check_solid``) [m].
    tol : float, optional
        Distance within which faces count as coplanar (a gap up to ``tol`` is still a
        contact) [m].

    Returns
    -------
    (area, centroid, normal, region) or None
        Area [m²], centroid (3,) [m] and unit normal (3,) pointing from ``a`` into ``b``
        of the largest contact, and its region (``ContactPlane``: rings in the plane's
        coordinates); None if the solids share no face area (an overlap narrower than
        ``tol`` does not count).

    Notes
    -----
    Used to tell a floor bearing on a wall top (vertical normal) from one abutting its
    face (horizontal normal), docs/theory.md §2.2. Solids that interpenetrate without sharing a
    face plane are not in contact in this sense; see :func:`contact_area` for a section.

    """
    if not tol >= 0.0:
        raise InputError(f"must be >= 0 [m], got {tol!r}", "tol")
    lo_a, hi_a = a.vertices.min(axis=0) - tol, a.vertices.max(axis=0) + tol
    lo_b, hi_b = b.vertices.min(axis=0) - tol, b.vertices.max(axis=0) + tol
    lo, hi = np.maximum(lo_a, lo_b), np.minimum(hi_a, hi_b)
    if np.any(lo > hi):
        return None
    ref = 0.5 * (lo + hi)

    def candidates(mesh: TriMesh) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Faces near the common box: ids, corners (k, 3, 3), unit normals, areas."""
        # Outcodes: a face is far if all its corners lie beyond the same side of the box.
        v = mesh.vertices
        bits = np.array([1, 2, 4], dtype=np.uint8)
        code = ((v < lo) * bits).sum(axis=1, dtype=np.uint8)
        code |= ((v > hi) * (bits << 3)).sum(axis=1, dtype=np.uint8)
        fc = code[mesh.faces]
        ids = np.nonzero((fc[:, 0] & fc[:, 1] & fc[:, 2]) == 0)[0]
        tri = v[mesh.faces[ids]] - ref
        cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        area2 = np.linalg.norm(cross, axis=1)
        ok = area2 > 0.0
        return ids[ok], tri[ok], cross[ok] / area2[ok, None], area2[ok]

    ids_a, tri_a, n_a, ar_a = candidates(a)
    ids_b, tri_b, n_b, _ = candidates(b)
    if len(tri_a) == 0 or len(tri_b) == 0:
        return None
    # b's faces enter with reversed planes, so opposite coplanar faces share a group.
    normals = np.vstack([n_a, -n_b])
    offsets = np.concatenate(
        [
            np.einsum("ij,ij->i", n_a, tri_a.mean(axis=1)),
            np.einsum("ij,ij->i", -n_b, tri_b.mean(axis=1)),
        ]
    )
    label = _single_linkage(
        [normals[:, 0], normals[:, 1], normals[:, 2], offsets], [NORMAL_GAP] * 3 + [tol]
    )
    la, lb = label[: len(tri_a)], label[len(tri_a) :]
    best: Optional[Tuple[float, np.ndarray, np.ndarray, ContactPlane]] = None
    for g in np.intersect1d(la, lb):
        in_a = np.nonzero(la == g)[0]
        seed = in_a[np.argmax(ar_a[in_a])]
        p0 = tri_a[seed].mean(axis=0)
        u, v, n = plane_basis(n_a[seed])
        sel_a = in_a[np.all(np.abs((tri_a[in_a] - p0) @ n) <= tol, axis=1)]
        in_b = np.nonzero(lb == g)[0]
        sel_b = in_b[np.all(np.abs((tri_b[in_b] - p0) @ n) <= tol, axis=1)]
        if len(sel_a) == 0 or len(sel_b) == 0:
            continue
        basis = np.stack([u, v], axis=1)
        regions = []
        for mesh, sel in ((a, ids_a[sel_a]), (b, ids_b[sel_b])):
            faces = mesh.faces[sel]
            used = np.unique(faces)
            xy = np.zeros((len(mesh.vertices), 2))
            xy[used] = (mesh.vertices[used] - ref - p0) @ basis
            regions.append(_patch_region(faces, xy))
        inter = regions[0].intersection(regions[1])
        area = float(inter.area)
        if area <= 0.0:
            continue
        x0, y0, x1, y1 = inter.bounds
        if area <= MIN_WIDTH_FACTOR * tol * max(x1 - x0, y1 - y0):
            continue
        if best is None or area > best[0]:
            c = inter.centroid
            best = (
                area,
                ref + p0 + c.x * u + c.y * v,
                n,
                ContactPlane(ref + p0, u, v, n, _region_rings(inter)),
            )
    return best


def find_contact(
    a: TriMesh, b: TriMesh, *, tol: float = 1e-6
) -> Optional[Tuple[float, np.ndarray, np.ndarray]]:
    """Largest planar contact between two solids touching along faces.

    Faces of ``a`` and ``b`` that are coplanar within ``tol``, with opposite normals,
    are grouped by plane; in each plane the union of a's faces is intersected with the
    union of b's faces (``contact_region``).

    Parameters
    ----------
    a, b : TriMesh
        Valid, outward-facing solids (see ``check_solid``) [m].
    tol : float, optional
        Distance within which faces count as coplanar (a gap up to ``tol`` is still a
        contact) [m].

    Returns
    -------
    (area, centroid, normal) or None
        Area [m²], centroid (3,) [m] and unit normal (3,) pointing from ``a`` into ``b``
        of the largest contact; None if the solids share no face area (an overlap narrower
        than ``tol`` does not count).

    Notes
    -----
    Used to tell a floor bearing on a wall top (vertical normal) from one abutting its
    face (horizontal normal), docs/theory.md §2.2. Solids that interpenetrate without sharing a
    face plane are not in contact in this sense; see :func:`contact_area` for a section.

    Examples
    --------
    >>> import trimesh
    >>> lo = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    >>> hi = trimesh.creation.box(bounds=[[0.5, 0, 1], [2, 1, 2]])
    >>> area, c, n = find_contact(TriMesh(lo.vertices, lo.faces), TriMesh(hi.vertices, hi.faces))
    >>> round(area, 12), c.round(12).tolist(), n.tolist()
    (0.5, [0.75, 0.5, 1.0], [0.0, 0.0, 1.0])
    """
    found = contact_region(a, b, tol=tol)
    return None if found is None else found[:3]


@dataclass(frozen=True)
class ContactPlane:
    """A contact's region: rings in the plane through ``origin`` spanned by ``u``, ``v``.

    Attributes
    ----------
    origin, u, v, normal : (3,) float
        The plane: a point [m], two orthonormal in-plane directions and the unit normal.
    rings : list of (k, 2) float
        The region's outer boundaries (counter-clockwise) and holes (clockwise), in
        ``(u, v)`` coordinates [m].
    """

    origin: np.ndarray
    u: np.ndarray
    v: np.ndarray
    normal: np.ndarray
    rings: List[np.ndarray]


def _region_rings(region: Any) -> List[np.ndarray]:
    """Rings of a shapely (multi)polygon: exteriors counter-clockwise, holes clockwise."""
    shapely = require("shapely", "geometry", "for contact polygons")

    polys = list(region.geoms) if hasattr(region, "geoms") else [region]
    rings: List[np.ndarray] = []
    for poly in polys:
        if poly.is_empty or poly.geom_type != "Polygon":
            continue
        poly = shapely.geometry.polygon.orient(poly, sign=1.0)
        rings.append(np.asarray(poly.exterior.coords, dtype=float)[:-1])
        rings.extend(np.asarray(h.coords, dtype=float)[:-1] for h in poly.interiors)
    return rings
