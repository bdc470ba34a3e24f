"""Smoke test at CAD scale: a 1.3M-triangle solid through validation and mass properties.

Not timed here (benchmarks time things); it must simply complete with the right answer.
"""

import math

import numpy as np
import pytest

from cad_maths.geometry.massprops import mass_properties
from cad_maths.geometry.mesh import TriMesh
from cad_maths.geometry.validate import check_solid


@pytest.mark.slow
def test_million_triangle_sphere_is_checked_and_integrated():
    import trimesh

    s = trimesh.creation.icosphere(subdivisions=8, radius=2.0)  # 1,310,720 triangles
    shift = np.array([1e5, -2e5, 30.0])
    ball = TriMesh(np.asarray(s.vertices) + shift, np.asarray(s.faces), "dome")
    assert ball.n_triangles > 1_000_000
    out, notes = check_solid(ball)
    assert out is ball and notes == []
    p = mass_properties(ball, 2000.0)
    # Inscribed polyhedron: a little under the sphere (edge ~ 4 mm on r = 2 m).
    v_sphere = 4 / 3 * math.pi * 8.0
    assert 0 < 1 - p.volume / v_sphere < 1e-5
    assert np.allclose(p.com, shift, rtol=0, atol=1e-9)
    i_sphere = 0.4 * p.mass * 4.0
    assert np.allclose(p.inertia_com, i_sphere * np.eye(3), rtol=0, atol=1e-5 * i_sphere)
