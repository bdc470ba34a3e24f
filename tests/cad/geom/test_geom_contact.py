"""Contact areas: sections of solids by a plane and faces they share."""

import math

import numpy as np
import pytest
from geom_meshes import (
    box,
    from_manifold,
    l_prism,
    moved,
    prism,
    regular_polygon,
    rotation,
    to_manifold,
)

from cad_maths.geometry.contact import contact_area, find_contact
from cad_maths.geometry.mesh import TriMesh
from shared_schema.errors import InputError

LOWER = box([0, 0, 0], [1, 1, 1], "wall")


def subdivided(mesh, times):
    import trimesh

    v, f = mesh.vertices, mesh.faces
    for _ in range(times):
        v, f = trimesh.remesh.subdivide(v, f)
    return TriMesh(v, f, mesh.name)


def test_stacked_boxes_touch_on_the_overlap_of_their_faces():
    upper = box([0.5, 0, 1], [2, 1, 2], "floor")
    area, c = contact_area(LOWER, upper, [0, 0, 1], [0, 0, 1])
    assert math.isclose(area, 0.5, rel_tol=1e-12)
    assert np.allclose(c, [0.75, 0.5, 1.0], atol=1e-12)
    area, c, n = find_contact(upper, LOWER)
    assert math.isclose(area, 0.5, rel_tol=1e-12)
    assert np.allclose(c, [0.75, 0.5, 1.0], atol=1e-12)
    assert np.allclose(n, [0, 0, -1])  # from the floor down into the wall
    assert np.allclose(find_contact(LOWER, upper)[2], [0, 0, 1])


def test_offset_boxes_touch_on_a_partial_overlap():
    upper = box([0.3, 0.4, 1], [1.3, 1.4, 1.2], "slab")
    area, c = contact_area(LOWER, upper, [5, 5, 1], [0, 0, -3])  # any point, any sign
    assert math.isclose(area, 0.7 * 0.6, rel_tol=1e-12)
    assert np.allclose(c, [0.65, 0.7, 1.0], atol=1e-12)
    area2, c2, _ = find_contact(LOWER, upper)
    assert math.isclose(area2, area, rel_tol=1e-12) and np.allclose(c2, c, atol=1e-12)


def test_side_by_side_boxes_abut_on_a_vertical_face():
    beam = box([1, 0.25, 0.6], [3, 0.75, 0.9], "beam")
    area, c, n = find_contact(beam, LOWER)
    assert math.isclose(area, 0.5 * 0.3, rel_tol=1e-12)
    assert np.allclose(c, [1, 0.5, 0.75], atol=1e-12)
    assert np.allclose(n, [-1, 0, 0])
    assert math.isclose(contact_area(LOWER, beam, [1, 0, 0], [1, 0, 0])[0], 0.15, rel_tol=1e-12)


def test_boxes_not_touching_have_no_contact():
    apart = box([0, 0, 1.01], [1, 1, 2], "apart")
    assert find_contact(LOWER, apart) is None
    area, c = contact_area(LOWER, apart, [0, 0, 1], [0, 0, 1])
    assert area == 0.0 and np.all(np.isnan(c))
    far = box([10, 10, 10], [11, 11, 11])
    assert find_contact(LOWER, far) is None


def test_boxes_touching_only_along_an_edge_have_no_contact():
    assert find_contact(LOWER, box([1, 0, 1], [2, 1, 2])) is None


def test_gap_within_tolerance_still_touches():
    upper = box([0, 0, 1 + 5e-7], [1, 1, 2])
    area, _, _ = find_contact(LOWER, upper, tol=1e-6)
    assert math.isclose(area, 1.0, rel_tol=1e-9)
    assert find_contact(LOWER, upper, tol=1e-7) is None


def test_overlapping_faces_with_the_same_direction_are_not_a_contact():
    # Interpenetrating blocks with coplanar, overlapping tops and bottoms facing the same way.
    twin = box([0.5, 0, 0], [1.5, 1, 1])
    assert find_contact(LOWER, twin) is None
    area, _, n = find_contact(LOWER, box([1, 0, 0], [2, 1, 1]))  # abutting: the x = 1 face
    assert np.allclose(n, [1, 0, 0]) and math.isclose(area, 1.0)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_oblique_contact_is_invariant_under_rigid_motion(seed):
    rng = np.random.default_rng(seed)
    rot = rotation(rng.normal(size=3), rng.uniform(0, 2 * math.pi))
    shift = rng.normal(size=3) * 100.0
    lower = moved(LOWER, rot, shift)
    upper = moved(box([0.3, 0.4, 1], [1.3, 1.4, 1.2]), rot, shift)
    plane_n = rot @ [0, 0, 1]
    area, c = contact_area(lower, upper, rot @ [0.2, 0.2, 1] + shift, plane_n)
    expected_c = rot @ [0.65, 0.7, 1.0] + shift
    assert math.isclose(area, 0.42, rel_tol=1e-9)
    assert np.allclose(c, expected_c, rtol=0, atol=1e-9)
    area2, c2, n = find_contact(lower, upper)
    assert math.isclose(area2, 0.42, rel_tol=1e-9)
    assert np.allclose(c2, expected_c, rtol=0, atol=1e-9) and np.allclose(n, plane_n)


def test_contact_does_not_depend_on_tessellation():
    upper = subdivided(box([0.5, 0, 1], [2, 1, 2], "fine"), 3)
    area, c, _ = find_contact(upper, subdivided(LOWER, 2))
    assert math.isclose(area, 0.5, rel_tol=1e-12)
    assert np.allclose(c, [0.75, 0.5, 1.0], atol=1e-12)


def test_plane_through_two_interpenetrating_solids_intersects_their_sections():
    a = box([0, 0, 0], [2, 2, 2])
    b = box([1, 1, 1], [3, 3, 3])
    for z in (1.0, 1.5, 2.0):  # b's bottom face, mid-depth, a's top face
        area, c = contact_area(a, b, [0, 0, z], [0, 0, 1])
        assert math.isclose(area, 1.0, rel_tol=1e-12)
        assert np.allclose(c, [1.5, 1.5, z], atol=1e-12)


def test_section_with_a_hole_and_a_non_convex_outline():
    wall = box([0, 0, 0], [4, 0.5, 3])
    window = box([1, -1, 1], [2, 1, 2])
    pierced = from_manifold(to_manifold(wall) - to_manifold(window), "pierced wall")
    slab = box([-1, -1, 1.5], [5, 2, 1.6], "probe")  # cut through the window
    area, c = contact_area(pierced, slab, [0, 0, 1.5], [0, 0, 1])
    assert math.isclose(area, (4 - 1) * 0.5, rel_tol=1e-12)
    # Vertical plane along the wall through the window: 4 x 3 minus 1 x 1.
    area, c = contact_area(pierced, pierced, [0, 0.25, 0], [0, 1, 0])
    assert math.isclose(area, 11.0, rel_tol=1e-12)
    x = (4 * 3 * 2 - 1 * 1.5) / 11
    z = (4 * 3 * 1.5 - 1 * 1.5) / 11
    assert np.allclose(c, [x, 0.25, z], atol=1e-12)
    # The L prism: a non-convex section.
    area, c = contact_area(l_prism(), l_prism(), [0, 0, 0.7], [0, 0, 1])
    assert math.isclose(area, 1.75, rel_tol=1e-12)


def test_oblique_section_of_a_column_is_an_ellipse_like_polygon():
    n = 64
    column = prism(regular_polygon(n, 0.5), 0, 4, name="column")
    tilt = math.radians(30)
    normal = [math.sin(tilt), 0, math.cos(tilt)]
    area, c = contact_area(column, column, [0, 0, 2], normal)
    polygon = n * 0.25 * math.sin(2 * math.pi / n) / 2
    assert math.isclose(area, polygon / math.cos(tilt), rel_tol=1e-12)
    assert np.allclose(c, [0, 0, 2], atol=1e-12)


def test_bad_plane_is_an_input_error():
    with pytest.raises(InputError, match="plane_normal"):
        contact_area(LOWER, LOWER, [0, 0, 1], [0, 0, 0])


def test_patch_outline_matches_the_union_of_its_triangles_and_falls_back_when_not_manifold():
    import shapely

    from cad_maths.geometry.contact import _outline_rings, _patch_region, _triangles_union

    outer = np.array([[0, 0], [3, 0], [3, 2], [0, 2]], dtype=float)
    hole = np.array([[1, 0.5], [1, 1.5], [2, 1.5], [2, 0.5]], dtype=float)
    slab = subdivided(prism(outer, 0, 1, holes=[hole]), 2)
    top = np.all(slab.vertices[slab.faces][:, :, 2] == 1.0, axis=1)
    faces, xy = slab.faces[top], slab.vertices[:, :2]
    region = _patch_region(faces, xy)
    assert math.isclose(region.area, 5.0, rel_tol=1e-14)
    assert shapely.equals(region, _triangles_union(xy[faces]))
    doubled = np.vstack([faces, faces[:1]])  # an overlapping copy: not a manifold patch
    assert _outline_rings(doubled) is None
    assert math.isclose(_patch_region(doubled, xy).area, 5.0, rel_tol=1e-14)


def test_floor_on_a_finely_tessellated_wall():
    import manifold3d

    wall = from_manifold(manifold3d.Manifold.cube([0.6, 8.0, 6.0]).refine(40), "wall")
    floor = box([0.3, 3.0, 6.0], [3.3, 5.0, 6.2], "floor")
    area, c, n = find_contact(floor, wall)
    assert math.isclose(area, 0.3 * 2.0, rel_tol=1e-12)
    assert np.allclose(c, [0.45, 4.0, 6.0], atol=1e-12) and np.allclose(n, [0, 0, -1])
    area, c = contact_area(wall, floor, [0, 0, 6], [0, 0, 1])
    assert math.isclose(area, 0.6, rel_tol=1e-12)
