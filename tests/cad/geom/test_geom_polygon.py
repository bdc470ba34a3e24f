"""Planar polygon triangulation by index (manifold3d): every vertex kept, exact areas."""

from typing import List, Sequence

import numpy as np
import pytest

from cad_maths.geometry.polygon import triangulate_polygon


def shoelace(p: np.ndarray) -> float:
    x, y = (p - p.mean(axis=0)).T
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)))


def check(outer: np.ndarray, holes: Sequence[np.ndarray], rel: float = 1e-12) -> np.ndarray:
    tris = np.asarray(triangulate_polygon(outer, holes))
    pts = np.vstack([outer, *holes])
    pts = pts - pts.mean(axis=0)
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    a2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert np.all(a2 > 0.0), "every triangle counter-clockwise, none of zero area"
    assert np.array_equal(np.unique(tris), np.arange(len(pts))), "every vertex used"
    exact = shoelace(outer) - sum(shoelace(h) for h in holes)
    assert 0.5 * a2.sum() == pytest.approx(exact, rel=rel)
    return tris


def sides(corners: np.ndarray, per_side: int) -> np.ndarray:
    """A polygon with ``per_side - 1`` collinear points inserted on every side."""
    out: List[np.ndarray] = []
    for k in range(len(corners)):
        p, q = corners[k], corners[(k + 1) % len(corners)]
        t = np.arange(per_side)[:, None] / per_side
        out.append(p + t * (q - p))
    return np.vstack(out)


def test_collinear_vertices_on_every_side_are_all_kept() -> None:
    # A wall face whose neighbours are split into many faces: dropping any of these
    # points would leave a T-junction (an open edge) in the solid.
    outer = sides(np.array([[0.0, 0], [3, 0], [3, 2], [0, 2]]), 25)
    hole = sides(np.array([[1.0, 0.5], [1, 1.5], [2, 1.5], [2, 0.5]]), 7)  # clockwise
    tris = check(outer, [hole])
    assert len(tris) == len(outer) + len(hole)  # n - 2 + 2 h


def test_holes_with_vertices_collinear_with_others_give_no_slivers() -> None:
    # vertices of the boundary and of three of the holes on the line x = 3: manifold3d 3.5 joins
    # such collinear points by a zero-area triangle, which must be flipped away
    outer = np.array([[0, 0], [6, 0], [6, 3], [3, 4], [0, 3]], float)
    holes = [
        np.array([[0.5, 0.5], [1.5, 0.5], [1.5, 2.5], [0.5, 2.5]], float),
        np.array([[2, 1], [2.5, 2], [3, 1]], float),
        np.array(
            [[4, 0.5], [5.5, 0.5], [5.5, 2.5], [5, 2.5], [5, 1], [4.5, 1], [4.5, 2.5], [4, 2.5]]
        ),
        np.array([[3, 2.5], [3.5, 2.5], [3.5, 3.2], [3, 3.2]], float),
    ]
    check(outer, holes)


def test_coordinates_are_not_rounded_to_float32() -> None:
    # a 1 mm comb at 100 km from the origin: float32 spacing there is 7.8 mm, so any
    # single-precision step would collapse it
    comb = np.array([[0, 0], [3, 0], [3, 3], [2, 3], [2, 1], [1, 1], [1, 3], [0, 3]], float)
    tris = check(1e5 + 1e-3 * comb, [], rel=1e-9)
    assert len(tris) == 6


def test_large_face_with_holes_is_covered_exactly() -> None:
    n = 1500
    t = 2 * np.pi * np.arange(n) / n
    r = 10 + np.sin(9 * t)
    outer = np.column_stack([r * np.cos(t), r * np.sin(t)])
    holes = []
    for k in range(5):
        c = 5.5 * np.array([np.cos(2 * np.pi * k / 5), np.sin(2 * np.pi * k / 5)])
        s = 2 * np.pi * np.arange(150) / 150
        holes.append(c + 1.2 * np.column_stack([np.cos(s), -np.sin(s)]))
    check(outer, holes)


def test_bowtie_and_zero_area_outer_boundary_are_refused() -> None:
    with pytest.raises(ValueError, match="zero area"):
        triangulate_polygon(np.array([[0, 0], [1, 1], [1, 0], [0, 1]], float))
    with pytest.raises(ValueError, match="zero area"):
        triangulate_polygon(np.array([[0, 0], [1, 0], [2, 0]], float))


def test_crossing_boundary_is_refused() -> None:
    # a self-intersecting pentagram-like outline with non-zero signed area
    star = np.array([[np.cos(a), np.sin(a)] for a in 2 * np.pi * np.arange(5) * 2 / 5 + 0.3])
    with pytest.raises(ValueError):
        triangulate_polygon(star)
