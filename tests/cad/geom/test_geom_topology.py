"""Welding and outward winding shared by the scene readers (no rhino3dm needed)."""

import numpy as np
import pytest
from geom_meshes import box, unshared

from cad_maths.geometry.topology import orient_outward, weld


def signed_volume(v: np.ndarray, f: np.ndarray) -> float:
    return float(np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6)


def test_weld_merges_near_duplicates_keeps_first_coordinates_and_drops_degenerates() -> None:
    cube = unshared(box([0, 0, 0], [2, 1, 1]))  # every triangle with its own 3 vertices
    v = cube.vertices.copy()
    v[1::3] += 1e-10  # well inside 1e-9 x diagonal (2.45e-9)
    f = np.vstack([cube.faces, [[0, 0, 1]]])  # plus a degenerate triangle
    out_v, out_f = weld(v, f)
    assert out_v.shape == (8, 3) and out_f.shape == (12, 3)
    # the first occurrence of each corner is kept, unmoved
    first = {tuple(np.round(p, 6)): p for p in v[::-1]}
    for p in out_v:
        np.testing.assert_array_equal(p, first[tuple(np.round(p, 6))])
    assert signed_volume(out_v, out_f) == pytest.approx(2.0, rel=1e-12)


def test_weld_keeps_vertices_farther_apart_than_the_tolerance() -> None:
    cube = unshared(box([0, 0, 0], [1, 1, 1]))
    v = cube.vertices.copy()
    v[1] += 1e-6
    out_v, _ = weld(v, cube.faces)
    assert out_v.shape == (9, 3)


def test_orient_outward_fixes_flipped_faces_and_inverted_shells() -> None:
    a, b = box([0, 0, 0], [1, 1, 1]), box([3, 0, 0], [5, 2, 1])
    v = np.vstack([a.vertices, b.vertices])
    f = np.vstack([a.faces, b.faces + 8])
    want = f.copy()
    f = f.copy()
    f[[0, 5]] = f[[0, 5], ::-1]  # two faces of shell a disagree with the rest
    f[12:] = f[12:, ::-1]  # shell b inside out
    out, closed, n_bad = orient_outward(v, f)
    assert closed and n_bad == 0
    np.testing.assert_array_equal(out, want)
    assert signed_volume(v, out[:12]) == pytest.approx(1.0, rel=1e-12)
    assert signed_volume(v, out[12:]) == pytest.approx(4.0, rel=1e-12)


def test_orient_outward_reports_open_edges_and_leaves_faces() -> None:
    cube = box([0, 0, 0], [1, 1, 1])
    f = cube.faces[:-1]
    out, closed, n_bad = orient_outward(cube.vertices, f)
    assert not closed and n_bad == 3
    np.testing.assert_array_equal(out, f)


@pytest.mark.parametrize("high", [2**20, 2**50])
def test_packed_sort_orders_like_a_stable_argsort(high: int) -> None:
    # 2**50 keys with 3e4 indices need more than 63 bits: the argsort fallback
    from cad_maths.geometry.topology import _argsort_keys

    keys = np.random.default_rng(3).integers(0, high, 30_000)
    keys[::7] = keys[0]  # ties are ordered by index
    order, sorted_keys = _argsort_keys(keys)
    np.testing.assert_array_equal(order, np.argsort(keys, kind="stable"))
    np.testing.assert_array_equal(sorted_keys, np.sort(keys))
