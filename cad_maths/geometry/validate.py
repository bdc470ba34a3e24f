"""Check that a triangle mesh bounds a solid, and repair common CAD defects.

A divergence-theorem volume is only meaningful for a closed, consistently oriented,
outward-facing surface; trimesh (and this package's own integrals) still return a number
for an open mesh. :func:`check_solid` is therefore the gate in front of every mass
property: it returns a mesh that is a valid solid or raises :class:`GeometryError` naming
the object and the defect.

What is detected
----------------
* non-finite coordinates, face indices out of range, no faces;
* open surfaces (edges used by one face), reported as "is open: k boundary edges";
* non-manifold edges (used by more than two faces: touching or interpenetrating parts);
* inconsistent face orientation (an edge traversed twice in the same direction);
* zero volume (flat or collapsed) and inward-facing (inside-out) shells;
* overlapping shells ("is self-intersecting"): a shell nested inside another shell with
  the same orientation (generalised winding number of a point of each shell), and shells
  whose bounding boxes overlap and whose manifold3d union is smaller than the sum of their
  volumes (crossing shells).

What is *not* detected
----------------------
A single connected shell that passes through itself (for example a vertex dragged
through the opposite face). Finding that needs triangle-triangle intersection tests,
which cost far more than the rest of the check; such a mesh gives the signed volume of
its winding-number field. Overlaps between a cavity and other shells are not checked.

Repairs (``repair=True``), each reported in the returned warnings
-----------------------------------------------------------------
* faces with a repeated vertex index are dropped, unused vertices removed;
* duplicate vertices (closer than ``MERGE_RTOL`` × bounding-box diagonal) are merged,
  but only when the mesh is not already closed by its indices;
* duplicated faces are dropped; pairs of coincident faces with opposite orientation
  (internal walls between two joined parts) are both dropped;
* face orientation is made consistent on each shell (breadth-first propagation);
* planar holes are filled (constrained triangulation in the hole plane);
* inside-out shells are flipped.

Notation
--------
``det`` : 6 × signed volume of the tetrahedron (reference point, triangle) [m³]
"""

import weakref
import zlib
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from shared_schema.errors import GeometryError
from shared_schema.extras import require

from .frames import plane_basis
from .mesh import TriMesh
from .topology import (
    MERGE_RTOL,
    edge_defects,
    fix_winding,
    half_edge_keys,
    is_closed_oriented,
    merge_vertices,
    shell_labels,
)

__all__ = ["REPAIRS_KEY", "check_solid", "shell_labels"]

#: Key of ``TriMesh.meta`` under which a reader lists the repairs it made before the check
#: (``cad_maths.scene_base.solid_mesh``); ``check_solid`` reports them with its own.
REPAIRS_KEY = "repairs"
#: |volume| below this × (bounding-box diagonal)³ counts as zero [-].
ZERO_VOLUME_RTOL = 1e-12
#: A hole is filled when its loop deviates from its plane by less than this × its size [-].
HOLE_PLANARITY_RTOL = 1e-6
#: Shells overlapping by more than this × their total volume are rejected [-].
OVERLAP_RTOL = 1e-9
#: Winding-number test points sit this × the shell size off the shell's surface [-].
WINDING_PUSH_RTOL = 1e-6
#: Faces per chunk in vectorised loops (small enough to stay in cache, large enough to
#: amortise numpy's per-call overhead).
CHUNK = 1 << 16


#: Meshes found valid: id -> (weak reference, content fingerprint, valid with repair=True).
#: Lets ``mass_properties`` skip a second check of a mesh ``check_solid`` just returned.
_KNOWN: Dict[int, Tuple[Any, Tuple[int, int, int, int], bool]] = {}


def _fingerprint(mesh: TriMesh) -> Tuple[int, int, int, int]:
    # CRC of the arrays (~15 ms per million triangles): an in-place edit invalidates it.
    v, f = mesh.vertices, mesh.faces
    return zlib.crc32(v.data), zlib.crc32(f.data), v.shape[0], f.shape[0]


def _remember(mesh: TriMesh, clean: bool) -> None:
    key = id(mesh)

    def forget(_ref: Any, key: int = key) -> None:
        _KNOWN.pop(key, None)

    _KNOWN[key] = (weakref.ref(mesh, forget), _fingerprint(mesh), clean)


def _is_known_valid(mesh: TriMesh, repair: bool) -> bool:
    entry = _KNOWN.get(id(mesh))
    if entry is None or entry[0]() is not mesh or (repair and not entry[2]):
        return False
    return entry[1] == _fingerprint(mesh)


# --------------------------------------------------------------------------- kernels


def face_dets(local: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Six times the signed volume of the tetrahedra (origin, triangle).

    Parameters
    ----------
    local : (n, 3) float
        Vertex coordinates relative to a reference point near the mesh [m].
    faces : (m, 3) int
        Triangles.

    Returns
    -------
    (m,) float
        ``a · (b × c)`` for each triangle (a, b, c) [m³].
    """
    x, y, z = np.ascontiguousarray(local.T)
    out = np.empty(len(faces))
    for start in range(0, len(faces), CHUNK):
        i, j, k = faces[start : start + CHUNK].T
        xa, ya, za, xb, yb, zb = x[i], y[i], z[i], x[j], y[j], z[j]
        xc, yc, zc = x[k], y[k], z[k]
        out[start : start + CHUNK] = (
            xa * (yb * zc - zb * yc) + ya * (zb * xc - xb * zc) + za * (xb * yc - yb * xc)
        )
    return out


def _bbox_diag(points: np.ndarray) -> float:
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


# --------------------------------------------------------------------------- repairs


def _drop_duplicate_faces(faces: np.ndarray) -> Tuple[np.ndarray, int, int]:
    """Drop repeated faces; drop both faces of a coincident, oppositely oriented pair."""
    srt = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(srt, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    if not np.any(counts > 1):
        return faces, 0, 0
    # Orientation of a face relative to its sorted vertex triple: even or odd permutation.
    parity = _cyclic_parity(faces, srt)
    plus = np.bincount(inverse, weights=parity, minlength=len(counts))
    minus = counts - plus
    keep = np.ones(len(faces), dtype=bool)
    n_dup = n_pairs = 0
    for g in np.nonzero(counts > 1)[0]:
        members = np.nonzero(inverse == g)[0]
        p, m = int(plus[g]), int(minus[g])
        pairs = min(p, m)
        n_pairs += pairs
        survivors = abs(p - m)
        n_dup += counts[g] - 2 * pairs - min(survivors, 1)
        keep[members] = False
        if survivors:
            sign = 1 if p > m else 0
            keep[members[parity[members] == sign][0]] = True
    return faces[keep], int(n_dup), n_pairs


def _cyclic_parity(faces: np.ndarray, srt: np.ndarray) -> np.ndarray:
    """1 where the face is a cyclic rotation of its sorted triple, else 0."""
    rot1 = faces[:, [1, 2, 0]]
    rot2 = faces[:, [2, 0, 1]]
    return (
        np.all(faces == srt, axis=1) | np.all(rot1 == srt, axis=1) | np.all(rot2 == srt, axis=1)
    ).astype(np.int64)


def _boundary_loops(faces: np.ndarray, n_vertices: int) -> Optional[List[List[int]]]:
    """Vertex loops of the boundary, in the direction of their half-edges (None if pinched)."""
    keys = half_edge_keys(faces, n_vertices)
    canon = keys >> 1
    _, inverse, counts = np.unique(canon, return_inverse=True, return_counts=True)
    single = counts[inverse] == 1
    a = faces.ravel()[single]
    b = faces[:, [1, 2, 0]].ravel()[single]
    if len(np.unique(a)) != len(a):
        return None
    succ = dict(zip(a.tolist(), b.tolist()))
    loops: List[List[int]] = []
    while succ:
        start, nxt = succ.popitem()
        loop = [start]
        while nxt != start:
            loop.append(nxt)
            if nxt not in succ:
                return None
            nxt = succ.pop(nxt)
        loops.append(loop)
    return loops


def _fill_holes(vertices: np.ndarray, faces: np.ndarray) -> Tuple[np.ndarray, int, int]:
    """Close planar boundary loops with a constrained triangulation in their plane.

    Returns the faces, the number of holes filled and the number left open.
    """
    manifold3d = require("manifold3d", "geometry", "to close holes in meshes")
    shapely = require("shapely", "geometry", "to close holes in meshes")

    loops = _boundary_loops(faces, len(vertices))
    if loops is None:
        return faces, 0, -1
    new: List[np.ndarray] = []
    n_open = 0
    for loop in loops:
        ring = np.asarray(loop[::-1], dtype=np.int64)  # the fill runs against the hole
        if len(ring) == 3:
            new.append(ring[None, :])
            continue
        pts = vertices[ring]
        centre = pts.mean(axis=0)
        rel = pts - centre
        newell = np.cross(rel, np.roll(rel, -1, axis=0)).sum(axis=0)
        size = _bbox_diag(pts)
        if len(ring) < 3 or not np.linalg.norm(newell) > 0.0 or size == 0.0:
            n_open += 1
            continue
        u, v, n = plane_basis(newell)
        if np.max(np.abs(rel @ n)) > HOLE_PLANARITY_RTOL * size:
            n_open += 1
            continue
        xy = np.ascontiguousarray(np.stack([rel @ u, rel @ v], axis=1))
        if not shapely.Polygon(xy).is_valid:
            n_open += 1
            continue
        tris = np.asarray(manifold3d.triangulate([xy]), dtype=np.int64)
        new.append(ring[tris])
    if new:
        faces = np.vstack([faces, *new])
    return faces, len(new), n_open


# --------------------------------------------------------------------------- checks


def _topology_message(name: str, keys: np.ndarray) -> str:
    n_boundary, n_nonmanifold, n_misoriented = edge_defects(keys)
    parts = []
    if n_boundary:
        parts.append(f"is open: {n_boundary} boundary edges")
    if n_nonmanifold:
        parts.append(
            f"is not manifold: {n_nonmanifold} edges are shared by more than two faces "
            "(touching or self-intersecting parts)"
        )
    if n_misoriented:
        parts.append(f"has inconsistent face orientation: {n_misoriented} edges")
    return f"{name}: " + "; ".join(parts or ["has an invalid edge structure"])


def _winding_number(point: np.ndarray, tris: np.ndarray) -> float:
    """Generalised winding number of a point w.r.t. triangles (k, 3, 3) [-].

    Van Oosterom & Strackee (1983) solid angle of each triangle, summed, over 4π.
    """
    total = 0.0
    for start in range(0, len(tris), CHUNK):
        t = tris[start : start + CHUNK] - point
        a, b, c = t[:, 0], t[:, 1], t[:, 2]
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        num = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = (
            la * lb * lc
            + np.einsum("ij,ij->i", a, b) * lc
            + np.einsum("ij,ij->i", b, c) * la
            + np.einsum("ij,ij->i", c, a) * lb
        )
        total += float(np.sum(np.arctan2(num, den)))
    return total / (2.0 * np.pi)


def _shell_boxes(tri: np.ndarray, label: np.ndarray, k: int) -> Tuple[np.ndarray, np.ndarray]:
    """Bounding boxes (k, 3) of the shells from the triangles' corners (m, 3, 3)."""
    lo = np.full((k, 3), np.inf)
    hi = np.full((k, 3), -np.inf)
    np.minimum.at(lo, label, tri.min(axis=1))
    np.maximum.at(hi, label, tri.max(axis=1))
    return lo, hi


def _shell_depths(
    tri: np.ndarray, label: np.ndarray, vol: np.ndarray, lo: np.ndarray, hi: np.ndarray
) -> np.ndarray:
    """How many other shells contain each shell (-1 where the test is ambiguous).

    The test point of a shell sits just off the centre of one of its largest faces; its
    generalised winding number with respect to each other shell, made outward, counts 1
    if that shell contains it.
    """
    k = len(vol)
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    areas = np.linalg.norm(normals, axis=1)
    depth = np.full(k, -1)
    by_shell = np.argsort(label, kind="stable")
    starts = np.searchsorted(label[by_shell], np.arange(k + 1))
    for s in range(k):
        members = by_shell[starts[s] : starts[s + 1]]
        push = WINDING_PUSH_RTOL * float(np.linalg.norm(hi[s] - lo[s]))
        for f in members[np.argsort(-areas[members])[:3]]:
            p = tri[f].mean(axis=0) - push * normals[f] / areas[f]
            inside = np.all((lo <= p) & (p <= hi), axis=1)
            inside[s] = False
            w = 0.0
            for j in np.nonzero(inside)[0]:
                shell_j = tri[by_shell[starts[j] : starts[j + 1]]]
                w += np.sign(vol[j]) * _winding_number(p, shell_j)
            if abs(w - round(w)) < 0.25:
                depth[s] = round(w)
                break
    return depth


def _check_overlaps(
    name: str,
    local: np.ndarray,
    faces: np.ndarray,
    label: np.ndarray,
    vol: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
) -> None:
    """Reject positive shells whose union is smaller than the sum of their volumes."""
    pos = np.nonzero(vol > 0)[0]
    span = np.minimum(hi[pos, None], hi[None, pos]) - np.maximum(lo[pos, None], lo[None, pos])
    overlap = np.all(span > 0, axis=2)
    np.fill_diagonal(overlap, False)
    involved = pos[np.any(overlap, axis=1)]
    if len(involved) < 2:
        return
    manifold3d = require("manifold3d", "geometry", "to check solids for overlaps")

    solids = []
    for s in involved:
        f = faces[label == s]
        used, inv = np.unique(f, return_inverse=True)
        mesh = manifold3d.Mesh64(
            vert_properties=np.ascontiguousarray(local[used]),
            tri_verts=inv.reshape(-1, 3).astype(np.uint64),
        )
        solid = manifold3d.Manifold(mesh)
        if solid.status() != manifold3d.Error.NoError:
            raise GeometryError(f"{name}: manifold3d rejects shell {s}: {solid.status()}")
        solids.append(solid)
    union = manifold3d.Manifold.batch_boolean(solids, manifold3d.OpType.Add).volume()
    total = float(sum(vol[involved]))
    if total - union > OVERLAP_RTOL * total:
        raise GeometryError(
            f"{name}: is self-intersecting: {len(involved)} of its shells overlap by "
            f"{total - union:.6g} m³ (the overlap would be counted twice)"
        )


def _check_shells(
    name: str, vertices: np.ndarray, faces: np.ndarray, repair: bool, notes: List[str]
) -> np.ndarray:
    """Volume sign and nesting of the shells; returns (possibly flipped/filtered) faces."""
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.ravel()] = True
    lo, hi = vertices[used].min(axis=0), vertices[used].max(axis=0)
    local = vertices - 0.5 * (lo + hi)
    det = face_dets(local, faces)
    k, label = shell_labels(faces, len(vertices))
    vol = np.bincount(label, weights=det, minlength=k) / 6.0
    if k == 1:
        diag = float(np.linalg.norm(hi - lo))
        if not abs(vol[0]) > ZERO_VOLUME_RTOL * diag**3:
            raise GeometryError(f"{name}: has zero volume (it is flat or collapsed)")
        if vol[0] < 0:
            if not repair:
                raise GeometryError(
                    f"{name}: is inside out: its faces point inward (volume {vol[0]:.6g} m³)"
                )
            notes.append(f"{name}: faces pointed inward (inside out); all faces flipped")
            return faces[:, ::-1]
        return faces

    # Several shells: drop flat ones, then check orientation against nesting depth.
    tri = local[faces]
    box_lo, box_hi = _shell_boxes(tri, label, k)
    diag = np.linalg.norm(box_hi - box_lo, axis=1)
    flat = ~(np.abs(vol) > ZERO_VOLUME_RTOL * diag**3)
    if flat.all():
        raise GeometryError(f"{name}: has zero volume (it is flat or collapsed)")
    if flat.any():
        if not repair:
            raise GeometryError(f"{name}: {int(flat.sum())} of its {k} shells have zero volume")
        notes.append(f"{name}: removed {int(flat.sum())} zero-volume shells")
        faces = faces[~flat[label]]
        return _check_shells(name, vertices, faces, repair, notes)
    depth = _shell_depths(tri, label, vol, box_lo, box_hi)
    if np.any(depth < 0):
        raise GeometryError(f"{name}: is self-intersecting: its shells cross each other")
    nested = (depth % 2 == 1) & (vol > 0)
    if nested.any():
        raise GeometryError(
            f"{name}: is self-intersecting: {int(nested.sum())} of its shells lie inside "
            "another shell with the same orientation (overlapping parts)"
        )
    inverted = (depth % 2 == 0) & (vol < 0)
    if inverted.any():
        if not repair:
            raise GeometryError(
                f"{name}: {int(inverted.sum())} of its {k} shells are inside out "
                "(faces point inward)"
            )
        notes.append(f"{name}: flipped {int(inverted.sum())} inside-out shells")
        faces = faces.copy()
        sel = inverted[label]
        faces[sel] = faces[sel][:, ::-1]
        vol = np.where(inverted, -vol, vol)
    _check_overlaps(name, local, faces, label, vol, box_lo, box_hi)
    return faces


def _repair_topology(
    name: str, vertices: np.ndarray, faces: np.ndarray, notes: List[str]
) -> np.ndarray:
    """Merge, deduplicate, re-orient and fill until closed and oriented, or raise."""
    n = len(vertices)
    keys = half_edge_keys(faces, n)
    pts = vertices[np.unique(faces)]
    diag = _bbox_diag(pts)
    centred = pts - pts.mean(axis=0)
    # Smallest principal second moment ~ (mean squared distance to the best plane) × count.
    smallest = np.linalg.eigvalsh(centred.T @ centred)[0]
    if not smallest > ZERO_VOLUME_RTOL * diag**2 * len(pts):
        raise GeometryError(f"{name}: has zero volume (all its vertices lie in one plane)")

    faces, merged = merge_vertices(vertices, faces, max(MERGE_RTOL * diag, 1e-300))
    if merged:
        notes.append(f"{name}: merged {merged} duplicate vertices")
        good = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
        good &= faces[:, 2] != faces[:, 0]
        if not good.all():
            notes.append(f"{name}: removed {int((~good).sum())} faces collapsed by the merge")
            faces = faces[good]
        keys = half_edge_keys(faces, n)
        if is_closed_oriented(keys):
            return faces

    n_boundary, n_nonmanifold, n_misoriented = edge_defects(keys)
    if n_nonmanifold:
        faces, n_dup, n_pairs = _drop_duplicate_faces(faces)
        if n_dup:
            notes.append(f"{name}: removed {n_dup} duplicated faces")
        if n_pairs:
            notes.append(
                f"{name}: removed {n_pairs} pairs of coincident opposite faces (internal walls)"
            )
        keys = half_edge_keys(faces, n)
        n_boundary, n_nonmanifold, n_misoriented = edge_defects(keys)
        if n_nonmanifold:
            raise GeometryError(_topology_message(name, keys))
    if n_misoriented:
        faces, n_flipped, _ = fix_winding(faces, n)
        keys = half_edge_keys(faces, n)
        if edge_defects(keys)[2]:
            raise GeometryError(
                f"{name}: has inconsistent face orientation that cannot be fixed "
                "(non-orientable surface)"
            )
        notes.append(f"{name}: flipped {n_flipped} faces to make the orientation consistent")
    if n_boundary:
        faces, n_filled, n_open = _fill_holes(vertices, faces)
        keys = half_edge_keys(faces, n)
        if n_open or not is_closed_oriented(keys):
            msg = _topology_message(name, keys)
            if n_open < 0:
                msg += " (its boundary is pinched; holes were not filled)"
            elif n_open:
                msg += f" ({n_open} holes are not planar or not simple and were not filled)"
            raise GeometryError(msg)
        notes.append(f"{name}: filled {n_filled} planar holes ({n_boundary} boundary edges)")
    if not is_closed_oriented(keys):
        raise GeometryError(_topology_message(name, keys))
    return faces


def check_solid(mesh: TriMesh, *, repair: bool = True) -> Tuple[TriMesh, List[str]]:
    """Return a closed, consistently oriented, outward-facing solid, or raise.

    Parameters
    ----------
    mesh : TriMesh
        Candidate solid [m].
    repair : bool, optional
        Repair what can be repaired safely (see the module notes) and report it. With
        ``False`` the mesh is only checked: it is returned unchanged if valid (faces with
        a repeated vertex index are tolerated; they bound no volume) and any defect raises.

    Returns
    -------
    mesh : TriMesh
        The valid solid: the input object itself when nothing was changed.
    warnings : list of str
        One human-readable line per repair, each starting with the mesh name: those the
        scene reader made (listed in ``mesh.meta[REPAIRS_KEY]``) first, then this check's.

    Raises
    ------
    GeometryError
        If the mesh is not, and cannot safely be made, a valid solid. The message names
        ``mesh.name`` and the defect ("is open: 12 boundary edges", "has inconsistent
        face orientation", "has zero volume", "is self-intersecting", ...).

    Notes
    -----
    Closed and oriented means every edge is used by exactly two faces, in opposite
    directions; outward means a positive divergence-theorem volume (docs/theory.md §2.1 uses
    it for M and I_O). Cost is dominated by one sort of the 3m half-edges, O(m log m).
    A mesh this function returned (or accepted) is remembered, with a CRC of its arrays, so
    checking it again (as ``mass_properties`` does) costs only the CRC.

    Examples
    --------
    >>> import numpy as np
    >>> tet = TriMesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]),
    ...               np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]), "tet")
    >>> out, notes = check_solid(tet)
    >>> out is tet, notes
    (True, [])
    """
    if _is_known_valid(mesh, repair):
        return mesh, []
    name = mesh.name
    vertices, faces = mesh.vertices, mesh.faces
    n = len(vertices)
    if len(faces) == 0:
        raise GeometryError(f"{name}: has no faces")
    if not np.all(np.isfinite(vertices)):
        raise GeometryError(f"{name}: has non-finite vertex coordinates")
    if faces.min() < 0 or faces.max() >= n:
        raise GeometryError(f"{name}: has face indices outside 0..{n - 1}")
    # repairs the scene reader already made (welding, winding, inward shells: solid_mesh)
    meta = dict(mesh.meta)
    notes: List[str] = list(meta.pop(REPAIRS_KEY, ()))
    changed = bool(notes)

    good = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
    good &= faces[:, 2] != faces[:, 0]
    work = faces
    if not good.all():
        work = faces[good]
        if len(work) == 0:
            raise GeometryError(f"{name}: has zero volume (all its faces are degenerate)")
        if repair:
            notes.append(f"{name}: removed {int((~good).sum())} degenerate faces")
            changed = True

    keys = half_edge_keys(work, n)
    if not is_closed_oriented(keys):
        if not repair:
            raise GeometryError(_topology_message(name, keys))
        work = _repair_topology(name, vertices, work, notes)
        changed = True

    checked = _check_shells(name, vertices, work, repair, notes)
    changed = changed or checked is not work
    if not repair:
        _remember(mesh, clean=False)
        return mesh, notes

    used = np.zeros(n, dtype=bool)
    used[checked.ravel()] = True
    n_unused = int(n - np.count_nonzero(used))
    if n_unused:
        remap = np.cumsum(used) - 1
        vertices, checked = vertices[used], remap[checked]
        notes.append(f"{name}: removed {n_unused} unused vertices")
        changed = True
    out = mesh if not changed else TriMesh(vertices, checked, name, meta)
    _remember(out, clean=True)
    return out, notes
