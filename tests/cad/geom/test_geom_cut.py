"""Plane cuts: watertight halves that conserve volume, in double precision."""

import math

import numpy as np
import pytest
from geom_meshes import box, convex, l_prism, moved, rotation
from hypothesis import given, settings
from hypothesis import strategies as st

from cad_maths.geometry.cut import cut_by_plane, split_by_plane
from cad_maths.geometry.massprops import mass_properties
from cad_maths.geometry.validate import check_solid
from shared_schema.errors import GeometryError, InputError


def volume(mesh):
    return mass_properties(mesh, 1.0, repair=False).volume


def halves_conserve_volume(mesh, point, normal, rtol=1e-10):
    pos, neg = split_by_plane(mesh, point, normal)
    for part in (pos, neg):
        out, notes = check_solid(part, repair=False)  # closed, outward, no repair needed
        assert out is part and notes == []
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    tol = 1e-9 * np.ptp(mesh.vertices, axis=0).max()
    assert np.all((pos.vertices - point) @ n >= -tol)
    assert np.all((neg.vertices - point) @ n <= tol)
    total = volume(mesh)
    assert abs(volume(pos) + volume(neg) - total) <= rtol * total
    return volume(pos), volume(neg)


OBLIQUE = [[0.3, -0.5, 1.0], [1.0, 1.0, 1.0], [-0.2, 0.9, 0.1], [0.0, 0.0, 1.0]]


@pytest.mark.parametrize("normal", OBLIQUE)
def test_box_cut_through_its_centre_gives_two_equal_halves(normal):
    b = box([0, 0, 0], [0.6, 4.0, 3.0], "wall")
    # Point symmetry about the centre: any plane through it halves the volume exactly.
    vp, vn = halves_conserve_volume(b, [0.3, 2.0, 1.5], normal)
    assert abs(vp - 3.6) < 1e-12 * 7.2 and abs(vn - 3.6) < 1e-12 * 7.2


@pytest.mark.parametrize("normal", OBLIQUE)
def test_l_prism_cut_conserves_volume(normal):
    halves_conserve_volume(l_prism(), [0.4, 0.7, 0.8], normal)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_random_convex_polyhedron_cut_conserves_volume(seed):
    rng = np.random.default_rng(seed)
    hull = convex(rng.normal(size=(60, 3)) * rng.uniform(0.3, 3, 3))
    centre = hull.vertices.mean(axis=0)
    halves_conserve_volume(hull, centre + 0.2 * rng.normal(size=3), rng.normal(size=3))


def test_cut_far_from_the_origin_conserves_volume_and_is_double_precision():
    shift = np.array([1e5, 2e5, -1e5])
    b = moved(box([0, 0, 0], [0.6, 4.0, 3.0]), rotation([1, 2, 3], 0.7), shift)
    halves_conserve_volume(b, shift + np.array([0.1, 1.3, 0.9]), [0.2, 0.1, 1.0], rtol=1e-10)


def test_horizontal_cut_keeps_exact_coordinates():
    # float32 would return 0.149999857 (ECOSYSTEM: manifold3d.Mesh, trimesh booleans).
    top = cut_by_plane(box([0, 0, 0], [1, 1, 1]), [0, 0, 0.15], [0, 0, 1])
    assert abs(top.vertices[:, 2].min() - 0.15) < 1e-15
    bottom = cut_by_plane(box([0, 0, 0], [1, 1, 1]), [0, 0, 0.15], [0, 0, 1], keep="negative")
    assert abs(volume(bottom) - 0.15) < 1e-14 and abs(volume(top) - 0.85) < 1e-14


def test_kept_side_follows_the_normal():
    b = box([0, 0, 0], [2, 1, 1], "block")
    pos = cut_by_plane(b, [0.5, 0, 0], [1, 0, 0])
    neg = cut_by_plane(b, [0.5, 0, 0], [1, 0, 0], keep="negative")
    assert math.isclose(volume(pos), 1.5) and math.isclose(volume(neg), 0.5)
    assert pos.name == "block" and pos.meta["cut_side"] == "positive"


@pytest.mark.parametrize("offset", [1.0, 5.0, -0.0001])
def test_plane_missing_the_body_is_an_error_naming_it(offset):
    b = box([0, 0, 0], [1, 1, 1], "pier 7")
    with pytest.raises(GeometryError, match=r"pier 7: the cut plane .* misses the body"):
        cut_by_plane(b, [0, 0, offset], [0, 0, 1])


def test_bad_arguments_are_input_errors():
    b = box([0, 0, 0], [1, 1, 1])
    with pytest.raises(InputError, match="keep"):
        cut_by_plane(b, [0, 0, 0.5], [0, 0, 1], keep="above")
    with pytest.raises(InputError, match="normal"):
        cut_by_plane(b, [0, 0, 0.5], [0, 0, 0])


def test_open_mesh_is_refused():
    b = box([0, 0, 0], [1, 1, 1], "shell")
    with pytest.raises(GeometryError, match="shell: is open"):
        cut_by_plane(type(b)(b.vertices, b.faces[2:], "shell"), [0, 0, 0.5], [0, 0, 1])
