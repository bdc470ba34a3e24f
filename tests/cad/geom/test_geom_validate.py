"""check_solid: valid solids pass untouched, CAD defects are repaired or named."""

import numpy as np
import pytest
from geom_meshes import box, from_manifold, l_prism, prism, to_manifold, unshared

from cad_maths.geometry import validate
from cad_maths.geometry.massprops import mass_properties
from cad_maths.geometry.mesh import TriMesh
from cad_maths.geometry.validate import check_solid
from shared_schema.errors import GeometryError


def volume(mesh):
    return mass_properties(mesh, 1.0, repair=False).volume


def assert_valid(mesh, expected_volume):
    """Valid from scratch (no memory of earlier checks) and nothing left to repair."""
    for repair in (False, True):
        validate._KNOWN.clear()
        again, notes = check_solid(mesh, repair=repair)
        assert again is mesh and notes == []
    assert abs(volume(mesh) - expected_volume) <= 1e-12 * expected_volume


def test_a_mesh_edited_in_place_after_a_check_is_checked_again():
    b = box([0, 0, 0], [1, 1, 1], "edited")
    assert check_solid(b)[0] is b
    assert validate._is_known_valid(b, repair=True)
    b.faces[3] = b.faces[3, ::-1].copy()
    with pytest.raises(GeometryError, match="edited: has inconsistent face orientation"):
        check_solid(b, repair=False)


def test_memory_of_valid_meshes_is_released_with_them():
    import gc

    b = box([0, 0, 0], [1, 1, 1])
    check_solid(b)
    key = id(b)
    assert key in validate._KNOWN
    del b
    gc.collect()
    assert key not in validate._KNOWN


def test_a_mesh_accepted_without_repair_is_still_repaired_when_asked():
    b = box([0, 0, 0], [1, 1, 1], "b")
    stray = TriMesh(np.vstack([b.vertices, [[5.0, 5, 5]]]), b.faces, "b")
    assert check_solid(stray, repair=False) == (stray, [])
    out, notes = check_solid(stray)
    assert out is not stray and notes == ["b: removed 1 unused vertices"]


def test_valid_solid_is_returned_as_is_without_warnings():
    wall = box([0, 0, 0], [0.5, 4, 3], "wall")
    out, notes = check_solid(wall)
    assert out is wall and notes == []


def test_open_box_is_filled_with_a_warning():
    b = box([0, 0, 0], [2, 1, 3], "pier")
    opened = TriMesh(b.vertices, b.faces[2:], "pier")  # bottom face removed
    out, notes = check_solid(opened)
    assert any("pier: filled 1 planar holes (4 boundary edges)" in n for n in notes)
    assert_valid(out, 6.0)


def test_open_box_without_repair_is_an_error_naming_the_mesh():
    b = box([0, 0, 0], [2, 1, 3], "pier")
    with pytest.raises(GeometryError, match=r"^pier: is open: 4 boundary edges"):
        check_solid(TriMesh(b.vertices, b.faces[2:], "pier"), repair=False)


def test_box_missing_two_opposite_faces_is_filled_twice():
    b = box([0, 0, 0], [2, 1, 3], "tube")
    out, notes = check_solid(TriMesh(b.vertices, b.faces[4:], "tube"))  # no top, no bottom
    assert notes == ["tube: filled 2 planar holes (8 boundary edges)"]
    assert_valid(out, 6.0)


def test_box_missing_two_adjacent_faces_cannot_be_filled():
    b = box([0, 0, 0], [2, 1, 3], "pier")
    faces = np.delete(b.faces, [0, 1, 4, 5], axis=0)  # bottom and front: one bent hole
    with pytest.raises(GeometryError, match=r"pier: is open: 6 boundary edges.*not planar"):
        check_solid(TriMesh(b.vertices, faces, "pier"))


def test_one_flipped_face_is_fixed_with_a_warning():
    b = box([0, 0, 0], [2, 1, 3], "block")
    faces = b.faces.copy()
    faces[5] = faces[5, ::-1]
    bad = TriMesh(b.vertices, faces, "block")
    with pytest.raises(GeometryError, match="block: has inconsistent face orientation: 3 edges"):
        check_solid(bad, repair=False)
    out, notes = check_solid(bad)
    assert notes == ["block: flipped 1 faces to make the orientation consistent"]
    assert_valid(out, 6.0)


def test_majority_of_faces_flipped_keeps_the_solid_outward():
    b = box([0, 0, 0], [2, 1, 3], "block")
    faces = b.faces.copy()
    faces[:9] = faces[:9, ::-1]  # 9 of 12 flipped: fixed by winding, then by inversion
    out, notes = check_solid(TriMesh(b.vertices, faces, "block"))
    assert len(notes) == 2 and "flipped 3 faces" in notes[0] and "inside out" in notes[1]
    assert_valid(out, 6.0)


def test_inward_facing_box_is_flipped():
    b = box([0, 0, 0], [2, 1, 3], "block")
    inside_out = TriMesh(b.vertices, b.faces[:, ::-1], "block")
    with pytest.raises(GeometryError, match="block: is inside out"):
        check_solid(inside_out, repair=False)
    out, notes = check_solid(inside_out)
    assert notes == ["block: faces pointed inward (inside out); all faces flipped"]
    assert_valid(out, 6.0)


def test_flat_closed_mesh_has_zero_volume():
    b = box([0, 0, 0], [2, 1, 3], "slab")
    flat = b.vertices.copy()
    flat[:, 2] = 0.0  # top vertices onto the bottom ones, indices kept: closed but flat
    with pytest.raises(GeometryError, match="slab: has zero volume"):
        check_solid(TriMesh(flat, b.faces, "slab"))


def test_flat_open_patch_has_zero_volume_rather_than_being_filled():
    patch = TriMesh(np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
                    np.array([[0, 1, 2], [0, 2, 3]]), "sheet")  # fmt: skip
    with pytest.raises(GeometryError, match="sheet: has zero volume"):
        check_solid(patch)


def test_duplicate_vertices_are_merged():
    soup = unshared(l_prism("L"))
    with pytest.raises(GeometryError, match="L: is open"):
        check_solid(soup, repair=False)
    out, notes = check_solid(soup)
    assert any("merged" in n and "duplicate vertices" in n for n in notes)
    assert len(out.vertices) == 12  # 6 corners top and bottom
    assert_valid(out, (2 * 0.5 + 1.5 * 0.5) * 1.5)


def test_nearly_coincident_vertices_are_merged_but_distinct_ones_are_not():
    soup = unshared(box([0, 0, 0], [1, 1, 1], "b"))
    jitter = np.random.default_rng(1).uniform(-1e-12, 1e-12, soup.vertices.shape)
    out, _ = check_solid(TriMesh(soup.vertices + jitter, soup.faces, "b"))
    assert len(out.vertices) == 8
    assert abs(volume(out) - 1.0) < 1e-10


def test_degenerate_faces_and_unused_vertices_are_removed():
    b = box([0, 0, 0], [1, 1, 1], "b")
    verts = np.vstack([b.vertices, [[9.0, 9.0, 9.0]]])
    faces = np.vstack([b.faces, [[0, 0, 1]]])
    out, notes = check_solid(TriMesh(verts, faces, "b"))
    assert notes == ["b: removed 1 degenerate faces", "b: removed 1 unused vertices"]
    assert len(out.vertices) == 8 and len(out.faces) == 12
    kept, _ = check_solid(TriMesh(verts, faces, "b"), repair=False)
    assert len(kept.faces) == 13  # checked only


def test_box_with_cavity_is_valid_and_subtracts_it():
    outer = box([0, 0, 0], [3, 3, 3])
    inner = box([1, 1, 1], [2, 2, 2])
    verts = np.vstack([outer.vertices, inner.vertices])
    faces = np.vstack([outer.faces, inner.faces[:, ::-1] + 8])
    hollow = TriMesh(verts, faces, "hollow")
    assert_valid(hollow, 26.0)


def test_inside_out_cavity_of_wrong_orientation_is_nested_overlap():
    outer = box([0, 0, 0], [3, 3, 3])
    inner = box([1, 1, 1], [2, 2, 2])
    verts = np.vstack([outer.vertices, inner.vertices])
    nested = TriMesh(verts, np.vstack([outer.faces, inner.faces + 8]), "nested")
    with pytest.raises(GeometryError, match="nested: is self-intersecting"):
        check_solid(nested)


def test_disjoint_shells_are_valid_and_an_inverted_one_is_flipped():
    a, b = box([0, 0, 0], [1, 1, 1]), box([2, 0, 0], [3, 2, 1])
    verts = np.vstack([a.vertices, b.vertices])
    two = TriMesh(verts, np.vstack([a.faces, b.faces + 8]), "pair")
    assert_valid(two, 3.0)
    bad = TriMesh(verts, np.vstack([a.faces, b.faces[:, ::-1] + 8]), "pair")
    with pytest.raises(GeometryError, match="pair: 1 of its 2 shells are inside out"):
        check_solid(bad, repair=False)
    out, notes = check_solid(bad)
    assert notes == ["pair: flipped 1 inside-out shells"]
    assert_valid(out, 3.0)


def test_overlapping_shells_are_self_intersecting():
    a, b = box([0, 0, 0], [2, 2, 2]), box([1, 1, 1], [3, 3, 3])
    both = TriMesh(np.vstack([a.vertices, b.vertices]), np.vstack([a.faces, b.faces + 8]), "x")
    with pytest.raises(GeometryError, match="x: is self-intersecting"):
        check_solid(both)


def test_crossing_bars_are_self_intersecting():
    # A plus sign; no face centre of either bar lies inside the other: manifold3d union.
    a, b = box([-5, 1, 0], [8, 2, 1]), box([1, -5, 0.25], [2, 6, 0.75])
    both = TriMesh(np.vstack([a.vertices, b.vertices]), np.vstack([a.faces, b.faces + 8]), "+")
    with pytest.raises(GeometryError, match=r"\+: is self-intersecting: 2 of its shells overlap"):
        check_solid(both)


def test_nested_box_with_the_same_orientation_is_self_intersecting():
    a, b = box([0, 0, 0], [3, 3, 3]), box([1, 1, 1], [2, 2, 2])
    both = TriMesh(np.vstack([a.vertices, b.vertices]), np.vstack([a.faces, b.faces + 8]), "n")
    with pytest.raises(GeometryError, match="n: is self-intersecting: 1 of its shells lie inside"):
        check_solid(both)


def test_touching_shells_are_not_overlapping():
    a, b = box([0, 0, 0], [1, 1, 1]), box([1, 0.2, 0], [2, 0.8, 1])
    both = TriMesh(np.vstack([a.vertices, b.vertices]), np.vstack([a.faces, b.faces + 8]), "t")
    assert_valid(both, 1.6)


def test_joined_boxes_sharing_a_face_lose_the_internal_wall():
    a, b = box([0, 0, 0], [1, 1, 1]), box([1, 0, 0], [2, 1, 1])
    soup = unshared(
        TriMesh(np.vstack([a.vertices, b.vertices]), np.vstack([a.faces, b.faces + 8]), "j")
    )
    # The shared corners are duplicates: merged, then the two x = 1 faces cancel.
    out, notes = check_solid(soup)
    assert any("coincident opposite faces" in n for n in notes)
    assert_valid(out, 2.0)


def test_separately_indexed_boxes_sharing_a_face_are_two_valid_shells():
    a, b = box([0, 0, 0], [1, 1, 1]), box([1, 0, 0], [2, 1, 1])
    assert_valid(
        TriMesh(np.vstack([a.vertices, b.vertices]), np.vstack([a.faces, b.faces + 8]), "p"), 2.0
    )


def test_boxes_sharing_only_an_edge_are_not_manifold():
    a, b = box([0, 0, 0], [1, 1, 1]), box([1, 1, 0], [2, 2, 1])
    soup = unshared(
        TriMesh(np.vstack([a.vertices, b.vertices]), np.vstack([a.faces, b.faces + 8]), "e")
    )
    with pytest.raises(GeometryError, match="e: is not manifold: 1 edges"):
        check_solid(soup)


def test_non_finite_and_out_of_range_meshes_are_named():
    b = box([0, 0, 0], [1, 1, 1], "bad")
    verts = b.vertices.copy()
    verts[3, 1] = np.nan
    with pytest.raises(GeometryError, match="bad: has non-finite"):
        check_solid(TriMesh(verts, b.faces, "bad"))
    with pytest.raises(GeometryError, match=r"bad: has face indices outside 0\.\.7"):
        check_solid(TriMesh(b.vertices, b.faces + 1, "bad"))
    with pytest.raises(GeometryError, match="bad: has no faces"):
        check_solid(TriMesh(b.vertices, np.zeros((0, 3)), "bad"))


def test_manifold3d_boolean_output_passes():
    wall = box([0, 0, 0], [4, 0.5, 3])
    window = box([1, -1, 1], [2, 1, 2])
    mesh = from_manifold(to_manifold(wall) - to_manifold(window), "wall with window")
    assert_valid(mesh, 6.0 - 0.5)


def test_genus_one_prism_is_a_single_valid_shell():
    outer = np.array([[0, 0], [3, 0], [3, 2], [0, 2]], dtype=float)
    hole = np.array([[1, 0.5], [1, 1.5], [2, 1.5], [2, 0.5]], dtype=float)
    assert_valid(prism(outer, 0, 1, holes=[hole]), 5.0)


def icosphere(subdivisions, name="sphere"):
    import trimesh

    s = trimesh.creation.icosphere(subdivisions=subdivisions)
    return TriMesh(np.asarray(s.vertices), np.asarray(s.faces), name)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_randomly_flipped_faces_on_a_sphere_are_all_fixed(seed):
    sphere = icosphere(4)
    rng = np.random.default_rng(seed)
    flip = rng.random(len(sphere.faces)) < 0.3
    faces = sphere.faces.copy()
    faces[flip] = faces[flip, ::-1]
    out, notes = check_solid(TriMesh(sphere.vertices, faces, "ball"))
    assert notes == [f"ball: flipped {int(flip.sum())} faces to make the orientation consistent"]
    assert np.array_equal(out.faces, sphere.faces)


def test_numpy_fallback_without_scipy_finds_the_same_shells(monkeypatch):
    import sys

    from cad_maths.geometry.validate import shell_labels

    a, b = box([0, 0, 0], [1, 1, 1]), box([2, 0, 0], [3, 2, 1])
    sphere = icosphere(3)
    verts = np.vstack([a.vertices, b.vertices, sphere.vertices + np.array([5, 5, 5])])
    faces = np.vstack([a.faces, b.faces + 8, sphere.faces + 16])
    with_scipy = shell_labels(faces, len(verts))
    monkeypatch.setitem(sys.modules, "scipy.sparse", None)
    monkeypatch.setitem(sys.modules, "scipy.sparse.csgraph", None)
    without = shell_labels(faces, len(verts))
    assert with_scipy[0] == without[0] == 3
    assert np.array_equal(with_scipy[1], without[1])
    out, _ = check_solid(TriMesh(verts, faces, "three"))
    assert out.n_triangles == len(faces)


def test_non_convex_planar_hole_is_triangulated_in_its_plane():
    solid = l_prism("L")
    top = np.all(solid.vertices[solid.faces][:, :, 2] == 1.5, axis=1)
    out, notes = check_solid(TriMesh(solid.vertices, solid.faces[~top], "L"))
    assert notes == ["L: filled 1 planar holes (6 boundary edges)"]
    assert_valid(out, 1.75 * 1.5)
