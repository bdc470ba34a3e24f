"""Edge topology of triangle meshes: welding, shells, consistent and outward winding.

One implementation shared by the scene readers (``solid_mesh``) and the solid check
(:mod:`cad_maths.geometry.validate`). Everything here is vectorised numpy (scipy's
connected components where available), so a scan of a million triangles costs a few sorts
of its 3m half-edges.

Notation
--------
half-edge key : ``2 × (undirected edge id) + (1 if it runs from the higher to the lower
vertex index)``, one int64 per (face, corner).

Python 3.9-clean: imported by Rhino 8.
"""

from typing import Tuple

import numpy as np

from shared_schema.errors import GeometryError

__all__ = [
    "MERGE_RTOL",
    "components",
    "edge_defects",
    "fix_winding",
    "half_edge_keys",
    "is_closed_oriented",
    "merge_vertices",
    "orient_outward",
    "shell_labels",
    "weld",
]

#: Vertices closer than this × the bounding-box diagonal are merged [-].
MERGE_RTOL = 1e-9


def half_edge_keys(faces: np.ndarray, n_vertices: int) -> np.ndarray:
    """One int64 per half-edge: 2 × (undirected edge id) + (1 if it runs high → low).

    Parameters
    ----------
    faces : (m, 3) int
        Triangles.
    n_vertices : int
        Number of vertices (bounds the indices).

    Returns
    -------
    (3m,) int64
        Keys in face order: half-edge ``3 i + c`` runs from corner ``c`` of face ``i``
        to corner ``c + 1``.
    """
    if n_vertices >= 1 << 31:
        raise GeometryError(f"too many vertices ({n_vertices}) for the edge check")
    a = faces.ravel()
    b = np.roll(faces, -1, axis=1).ravel()
    key = np.minimum(a, b)
    key *= n_vertices
    key += np.maximum(a, b)
    key <<= 1
    key |= a > b
    return key


def is_closed_oriented(keys: np.ndarray) -> bool:
    """Every undirected edge has exactly two half-edges, in opposite directions.

    Sorts ``keys`` in place (their order carries no information).
    """
    if len(keys) % 2:
        return False
    keys.sort()
    first, second = keys[0::2], keys[1::2]
    if not (np.all(second - first == 1) and np.all(first % 2 == 0)):
        return False
    return bool(np.all((first[1:] >> 1) != (second[:-1] >> 1)))


def edge_defects(keys: np.ndarray) -> Tuple[int, int, int]:
    """Numbers of boundary, non-manifold and misoriented edges."""
    canon = keys >> 1
    _, inverse, counts = np.unique(canon, return_inverse=True, return_counts=True)
    downs = np.bincount(inverse, weights=keys & 1, minlength=len(counts))
    n_boundary = int(np.count_nonzero(counts == 1))
    n_nonmanifold = int(np.count_nonzero(counts > 2))
    n_misoriented = int(np.count_nonzero((counts == 2) & (downs != 1)))
    return n_boundary, n_nonmanifold, n_misoriented


def components(n_nodes: int, u: np.ndarray, w: np.ndarray) -> Tuple[int, np.ndarray]:
    """Label the connected components of a graph given by its edges (u, w): 0..k-1."""
    try:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components
    except ImportError:  # Rhino's Python may lack scipy: hook-and-jump in numpy
        label = np.arange(n_nodes)
        while True:
            lu, lw = label[u], label[w]
            lo, hi = np.minimum(lu, lw), np.maximum(lu, lw)
            differ = lo != hi
            if not differ.any():
                break
            np.minimum.at(label, hi[differ], lo[differ])
            while True:
                jumped = label[label]
                if np.array_equal(jumped, label):
                    break
                label = jumped
        roots, compact = np.unique(label, return_inverse=True)
        return len(roots), compact.reshape(-1)
    graph = coo_matrix((np.ones(len(u), dtype=np.int8), (u, w)), shape=(n_nodes, n_nodes))
    k, labels = connected_components(graph, directed=False)
    return int(k), labels


def shell_labels(faces: np.ndarray, n_vertices: int) -> Tuple[int, np.ndarray]:
    """Label the faces of a mesh by connected shell (faces sharing a vertex).

    Parameters
    ----------
    faces : (m, 3) int
        Triangles.
    n_vertices : int
        Number of vertices.

    Returns
    -------
    k : int
        Number of shells.
    labels : (m,) int
        Shell index of each face, in 0..k-1.
    """
    u = np.concatenate([faces[:, 0], faces[:, 1]])
    w = np.concatenate([faces[:, 1], faces[:, 2]])
    _, vlabel = components(n_vertices, u, w)
    roots, flabel = np.unique(vlabel[faces[:, 0]], return_inverse=True)
    return len(roots), flabel.reshape(-1)


def merge_vertices(
    vertices: np.ndarray,
    faces: np.ndarray,
    tol: float,
    shifts: Tuple[float, ...] = (0.0, 0.5),
) -> Tuple[np.ndarray, int]:
    """Re-index faces so that vertices within ``tol`` share one index (two grid passes).

    Parameters
    ----------
    vertices : (n, 3) float
        Coordinates [m].
    faces : (m, 3) int
        Triangles.
    tol : float
        Grid cell size [m] (> 0).
    shifts : tuple of float
        Grid offsets, in cells, of the passes (one pass per offset).

    Returns
    -------
    faces : (m, 3) int
        Re-indexed triangles; each cluster is represented by its lowest vertex index.
    n_merged : int
        Number of vertices that lost their identity.

    Notes
    -----
    Coordinates are not moved. Two vertices in one grid cell merge; with two passes, a pair
    straddling a cell boundary in one grid usually shares a cell in the other, shifted by
    half a cell.
    """
    n = len(vertices)
    target = np.arange(n)
    lo = vertices.min(axis=0)
    for shift in shifts:
        q = np.floor((vertices - lo) / tol + shift).astype(np.int64)
        order = np.lexsort((q[:, 2], q[:, 1], q[:, 0]))
        qs = q[order]
        new_group = np.ones(n, dtype=bool)
        new_group[1:] = np.any(qs[1:] != qs[:-1], axis=1)
        group = np.cumsum(new_group) - 1
        first = order[new_group]
        rep = np.empty(n, dtype=np.int64)
        rep[order] = first[group]
        target = rep[target]
    # distinct representatives by counting, not np.unique (a hash/sort of n values)
    merged = int(n - np.count_nonzero(np.bincount(target, minlength=n)))
    return target[faces], merged


def weld(
    vertices: np.ndarray, faces: np.ndarray, rtol: float = MERGE_RTOL
) -> Tuple[np.ndarray, np.ndarray]:
    """Merge close vertices, drop degenerate triangles and unused vertices.

    Parameters
    ----------
    vertices : (n, 3) float
        Coordinates [any length unit].
    faces : (m, 3) int
        Triangles.
    rtol : float
        Merge distance as a fraction of the bounding-box diagonal of ``vertices`` [-].

    Returns
    -------
    vertices : (k, 3) float
        The kept vertices, each at its first occurrence's coordinates, in first-occurrence
        order.
    faces : (m', 3) int64
        The triangles with three distinct vertices, in their original order.

    Examples
    --------
    >>> v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0]])
    >>> weld(v, np.array([[0, 1, 2], [0, 3, 1]]))[1].tolist()
    [[0, 1, 2]]
    """
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    if v.shape[0] == 0 or f.shape[0] == 0:
        return v[:0], f[:0]
    size = float(np.linalg.norm(v.max(0) - v.min(0)))
    # one pass, cells centred on the grid points (rounding): CAD and scan files repeat
    # vertices exactly; the solid check's repair makes a second, shifted pass if needed
    f, _ = merge_vertices(v, f, rtol * size if size > 0.0 else 1.0, shifts=(0.5,))
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])]
    used = np.zeros(v.shape[0], dtype=bool)
    used[f.ravel()] = True
    new = np.cumsum(used) - 1
    return v[used], new[f]


def fix_winding(faces: np.ndarray, n_vertices: int) -> Tuple[np.ndarray, int, np.ndarray]:
    """Flip faces so that each shell is consistently oriented (breadth-first, by levels).

    Parameters
    ----------
    faces : (m, 3) int
        Triangles; every edge shared by at most two of them.
    n_vertices : int
        Number of vertices.

    Returns
    -------
    faces : (m, 3) int
        Re-oriented triangles; each edge-connected shell keeps the orientation of the
        majority of its faces. A non-orientable shell stays inconsistent somewhere.
    n_flipped : int
        Number of faces reversed.
    shell : (m,) int
        Edge-connected shell of each face, 0..k-1.
    """
    m = len(faces)
    keys = half_edge_keys(faces, n_vertices)
    canon = keys >> 1
    order = np.argsort(canon, kind="stable")
    cs = canon[order]
    idx = np.nonzero(cs[1:] == cs[:-1])[0]
    h1, h2 = order[idx], order[idx + 1]
    f1, f2 = h1 // 3, h2 // 3
    # Same direction on both faces: one of them must be flipped relative to the other.
    rel = ((keys[h1] & 1) == (keys[h2] & 1)).astype(np.int8)
    nbr = np.full((m, 3), -1, dtype=np.int64)
    nrel = np.zeros((m, 3), dtype=np.int8)
    nbr[f1, h1 % 3], nrel[f1, h1 % 3] = f2, rel
    nbr[f2, h2 % 3], nrel[f2, h2 % 3] = f1, rel
    flip = np.full(m, -1, dtype=np.int8)
    root = np.full(m, -1, dtype=np.int64)
    _, vshell = shell_labels(faces, n_vertices)
    front = np.unique(vshell, return_index=True)[1]
    while True:
        flip[front], root[front] = 0, front
        while len(front):
            cand = nbr[front]
            par = flip[front][:, None] ^ nrel[front]
            src = np.broadcast_to(root[front][:, None], cand.shape)
            ok = cand >= 0
            ok[ok] = flip[cand[ok]] < 0
            cand, par, src = cand[ok], par[ok], src[ok]
            flip[cand], root[cand] = par, src
            front = np.unique(cand)
        # Shells joined only at a vertex need one more seed each.
        left = np.nonzero(flip < 0)[0]
        if len(left) == 0:
            break
        front = left[:1]
    # Keep each shell's majority orientation.
    _, shell = np.unique(root, return_inverse=True)
    shell = shell.reshape(-1)
    n_flip = np.bincount(shell, weights=flip)
    n_all = np.bincount(shell)
    invert = (2 * n_flip > n_all)[shell]
    do_flip = (flip == 1) ^ invert
    out = faces.copy()
    out[do_flip] = out[do_flip][:, ::-1]
    return out, int(np.count_nonzero(do_flip)), shell


def _argsort_keys(keys: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Return ``(order, keys[order])`` for non-negative int64 keys.

    Packs each key with its index into one int64 and sorts values, which numpy does several
    times faster than ``argsort`` (vectorised sort); falls back to ``argsort`` when the key
    and the index need more than 63 bits together. Equal keys come in index order either way.
    """
    n = keys.size
    if n == 0:
        return np.zeros(0, dtype=np.int64), keys
    index_bits = max(int(n - 1).bit_length(), 1)
    if int(keys.max()).bit_length() + index_bits > 63:
        order = np.argsort(keys, kind="stable")
        return order, keys[order]
    packed = keys << index_bits
    packed |= np.arange(n, dtype=np.int64)
    packed.sort()
    order = packed & ((1 << index_bits) - 1)
    packed >>= index_bits
    return order, packed


def orient_outward(vertices: np.ndarray, faces: np.ndarray) -> Tuple[np.ndarray, bool, int]:
    """Make the winding consistent and the volume of each closed shell positive.

    Parameters
    ----------
    vertices : (n, 3) float
        Coordinates [m].
    faces : (m, 3) int
        Triangles (non-empty).

    Returns
    -------
    faces : (m, 3) int
        Re-oriented triangles (unchanged if the surface is not closed).
    closed : bool
        Every edge is shared by exactly two triangles, and the surface is orientable.
    n_bad : int
        Number of edges not shared by exactly two triangles.

    Notes
    -----
    Shells are edge-connected sets of triangles; each is made positive on its own, so a
    cavity (an inner shell) comes out as a second solid, which the solid check then rejects
    as overlapping rather than subtracting silently.
    """
    n = len(vertices)
    m = faces.shape[0]
    keys = half_edge_keys(faces, n)
    order, cs = _argsort_keys(keys >> 1)
    starts = np.flatnonzero(np.concatenate([[True], cs[1:] != cs[:-1]]))
    counts = np.diff(np.concatenate([starts, [cs.size]]))
    n_bad = int(np.count_nonzero(counts != 2))
    if n_bad:
        return faces, False, n_bad
    h1, h2 = order[0::2], order[1::2]
    fa, fb = h1 // 3, h2 // 3
    # both uses of an edge running the same way means the two triangles disagree
    if np.any((keys[h1] & 1) == (keys[h2] & 1)):
        fixed, _, _ = fix_winding(faces, n)
        if not is_closed_oriented(half_edge_keys(fixed, n)):
            return faces, False, 0  # non-orientable (Moebius-like)
        faces = fixed
    _, comp = components(m, fa, fb)
    c = vertices.mean(axis=0)
    a, b, cc = vertices[faces[:, 0]] - c, vertices[faces[:, 1]] - c, vertices[faces[:, 2]] - c
    vol6 = np.einsum("ij,ij->i", a, np.cross(b, cc))
    negative = np.bincount(comp, weights=vol6) < 0.0
    if negative.any():
        faces = np.where(negative[comp][:, None], faces[:, ::-1], faces)
    return faces, True, 0
