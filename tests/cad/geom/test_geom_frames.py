"""Bounding boxes in a frame and plane bases."""

import math

import numpy as np
import pytest
from geom_meshes import box, moved, rotation

from cad_maths.geometry.frames import bounding_box_in_frame, plane_basis
from cad_maths.geometry.mesh import TriMesh
from shared_schema.errors import InputError


def test_rotated_box_has_its_extents_in_its_own_frame():
    rot = rotation([1, -2, 0.5], 0.9)
    origin = np.array([1e5, 3.0, -2.0])
    b = moved(box([0.5, -1.0, 0.0], [1.1, 3.0, 3.0]), rot, origin)
    lo, hi = bounding_box_in_frame(b, origin, rot[:, 0], 2.0 * rot[:, 1])
    assert np.allclose(lo, [0.5, -1.0, 0.0], atol=1e-9)
    assert np.allclose(hi, [1.1, 3.0, 3.0], atol=1e-9)


def test_frame_z_is_x_cross_y():
    b = box([0, 0, 0], [1, 2, 3])
    lo, hi = bounding_box_in_frame(b, [0, 0, 0], [0, 1, 0], [1, 0, 0])  # z = -world z
    assert lo.tolist() == [0.0, 0.0, -3.0] and hi.tolist() == [2.0, 1.0, 0.0]


def test_unused_vertices_do_not_count():
    b = box([0, 0, 0], [1, 1, 1])
    stray = TriMesh(np.vstack([b.vertices, [[50.0, 0, 0]]]), b.faces)
    assert bounding_box_in_frame(stray, [0, 0, 0], [1, 0, 0], [0, 1, 0])[1][0] == 1.0


@pytest.mark.parametrize(
    ("x", "y", "field"),
    [([0, 0, 0], [0, 1, 0], "x_axis"), ([1, 0, 0], [1, 1e-3, 0], "y_axis"),
     ([1, 0, 0], [0, math.nan, 1], "y_axis")],
)  # fmt: skip
def test_degenerate_frames_are_input_errors(x, y, field):
    with pytest.raises(InputError) as err:
        bounding_box_in_frame(box([0, 0, 0], [1, 1, 1]), [0, 0, 0], x, y)
    assert err.value.field == field


@pytest.mark.parametrize("normal", [[0, 0, 1], [0, 0, -2], [1, 1, 1], [1e-9, 1, 0], [-3, 0.1, 0]])
def test_plane_basis_is_right_handed_and_orthonormal(normal):
    u, v, n = plane_basis(normal)
    m = np.stack([u, v, n])
    assert np.allclose(m @ m.T, np.eye(3), atol=1e-15)
    assert np.allclose(np.cross(u, v), n, atol=1e-15)
    assert np.allclose(n, np.asarray(normal) / np.linalg.norm(normal))
