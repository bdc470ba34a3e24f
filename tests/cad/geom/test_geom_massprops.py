"""Mass properties against hand formulas, composites and rigid-motion invariants."""

import math

import numpy as np
import pytest
from geom_meshes import box, convex, moved, prism, regular_polygon, rotation
from hypothesis import given, settings
from hypothesis import strategies as st

from cad_maths.geometry.massprops import MassProps, _integrals, combine, mass_properties
from shared_schema.errors import GeometryError, InputError

RTOL = 1e-12  # exact polyhedral integrals: rounding only


def rel(a, b):
    return abs(a - b) / abs(b)


# ---------------------------------------------------------------- hand formulas


def test_box_volume_mass_com_and_inertia_tensor_are_exact():
    b, length, h, rho = 0.6, 4.0, 3.0, 1900.0  # x, y, z extents [m], [kg/m³]
    lo = np.array([2.0, -1.0, 0.5])
    p = mass_properties(box(lo, lo + np.array([b, length, h]), "wall"), rho)
    mass = rho * b * length * h
    assert rel(p.volume, b * length * h) < RTOL
    assert rel(p.mass, mass) < RTOL
    assert np.allclose(p.com, lo + np.array([b, length, h]) / 2, rtol=0, atol=RTOL * 4.0)
    expected = mass / 12 * np.diag([length**2 + h**2, b**2 + h**2, b**2 + length**2])
    assert np.max(np.abs(p.inertia_com - expected)) < RTOL * np.max(expected)
    assert p.density == rho and p.name == "wall" and p.warnings == ()


def test_box_inertia_about_base_edge_is_m_b2_plus_h2_over_3():
    b, length, h, rho = 0.6, 4.0, 3.0, 1900.0
    p = mass_properties(box([0, 0, 0], [b, length, h]), rho)
    # Rocking axis along y through the bottom edge x = b, z = 0 (theory §2.1, I_O = 4/3 M R²).
    i_o = p.inertia_about_axis([b, 0.0, 0.0], [0.0, 1.0, 0.0])
    assert rel(i_o, p.mass * (b**2 + h**2) / 3) < RTOL
    assert rel(i_o, 4 / 3 * p.mass * (b**2 + h**2) / 4) < RTOL


def test_wedge_matches_triangular_prism_formulas():
    b, h, ln, rho = 0.8, 2.0, 3.0, 2200.0  # legs along x and z, length along y
    tri = np.array([[0.0, 0.0], [b, 0.0], [0.0, h]])
    # Extrude along z, then rotate +90° about x: (x, y, z) -> (x, -z, y).
    wedge = moved(prism(tri, 0.0, ln), rotation([1, 0, 0], math.pi / 2), [0, 0, 0], "wedge")
    p = mass_properties(wedge, rho)
    area = b * h / 2
    mass = rho * area * ln
    assert rel(p.mass, mass) < RTOL
    assert np.allclose(p.com, [b / 3, -ln / 2, h / 3], rtol=0, atol=1e-14 * ln)
    cxx, cyy, czz = ln * b**3 * h / 36, area * ln**3 / 12, ln * b * h**3 / 36
    cxz = -ln * b**2 * h**2 / 72
    expected = rho * np.array(
        [[cyy + czz, 0.0, -cxz], [0.0, cxx + czz, 0.0], [-cxz, 0.0, cxx + cyy]]
    )
    assert np.max(np.abs(p.inertia_com - expected)) < RTOL * np.max(expected)
    # Rocking about the right-angle edge (the y axis): ρ ln ∫(x² + z²) dA.
    toe = p.inertia_about_axis([0, 0, 0], [0, 1, 0])
    assert rel(toe, rho * ln * (b**3 * h / 12 + b * h**3 / 12)) < RTOL


@pytest.mark.parametrize("n", [64, 256])
def test_cylinder_matches_inscribed_polygon_prism_exactly_and_circle_within_tessellation(n):
    r, height, rho = 0.4, 2.5, 2500.0
    p = mass_properties(prism(regular_polygon(n, r), 0.0, height, name="column"), rho)
    theta = 2 * math.pi / n
    area = n * r**2 * math.sin(theta) / 2
    polar = n * r**4 * math.sin(theta) * (2 + math.cos(theta)) / 12  # ∫ρ² dA of the n-gon
    assert rel(p.volume, area * height) < RTOL
    assert np.allclose(p.com, [0, 0, height / 2], rtol=0, atol=1e-14)
    expected = rho * np.diag([height * polar / 2 + area * height**3 / 12] * 2 + [height * polar])
    assert np.max(np.abs(p.inertia_com - expected)) < RTOL * np.max(expected)
    # Smooth cylinder: area error θ²/6 and polar-moment error θ²/3 to leading order.
    v_smooth, izz_smooth = math.pi * r**2 * height, rho * math.pi * r**4 * height / 2
    assert 0 < 1 - p.volume / v_smooth <= theta**2 / 6 * 1.001
    assert 0 < 1 - p.inertia_com[2, 2] / izz_smooth <= theta**2 / 3 * 1.001


def test_non_convex_prism_with_hole_subtracts_the_hole():
    outer = np.array([[0, 0], [3, 0], [3, 2], [0, 2]], dtype=float)
    hole = np.array([[1, 0.5], [1, 1.5], [2, 1.5], [2, 0.5]], dtype=float)  # CW
    p = mass_properties(prism(outer, 0, 2.5, holes=[hole], name="wall with window"), 1000.0)
    assert rel(p.volume, (6 - 1) * 2.5) < RTOL
    assert np.allclose(p.com, [1.5, 1.0, 1.25], rtol=0, atol=1e-14)


# ---------------------------------------------------------------- composites


def test_two_density_column_and_statue_equal_the_sum_of_their_parts():
    column = box([0, 0, 0], [0.5, 0.5, 3.0], "column")
    statue = box([0.1, 0.1, 3.0], [0.4, 0.4, 3.8], "statue")
    parts = [mass_properties(column, 2400.0), mass_properties(statue, 8800.0)]
    both = combine(parts, name="column+statue")
    m1, m2 = 2400.0 * 0.75, 8800.0 * 0.3 * 0.3 * 0.8
    assert rel(both.mass, m1 + m2) < RTOL
    assert rel(both.volume, 0.75 + 0.072) < RTOL
    zc = (m1 * 1.5 + m2 * 3.4) / (m1 + m2)
    assert np.allclose(both.com, [0.25, 0.25, zc], rtol=0, atol=1e-14)
    # Base edge x = 0.5, z = 0 along y: box inertia + parallel axis, part by part.
    i1 = m1 * ((0.5**2 + 3.0**2) / 12 + 0.25**2 + 1.5**2)
    i2 = m2 * ((0.3**2 + 0.8**2) / 12 + 0.25**2 + 3.4**2)
    assert rel(both.inertia_about_axis([0.5, 0, 0], [0, 1, 0]), i1 + i2) < RTOL
    assert math.isnan(both.density) and both.name == "column+statue"


def test_combining_the_two_halves_of_a_cut_box_gives_the_whole_box():
    from cad_maths.geometry.cut import split_by_plane

    whole = box([0, 0, 0], [1.2, 0.7, 2.0], "block")
    upper, lower = split_by_plane(whole, [0.3, 0.2, 0.9], [0.3, -0.5, 1.0])
    both = combine([mass_properties(upper, 2000.0), mass_properties(lower, 2000.0)])
    ref = mass_properties(whole, 2000.0)
    assert rel(both.mass, ref.mass) < 1e-12
    assert np.allclose(both.com, ref.com, rtol=0, atol=1e-12)
    assert np.max(np.abs(both.inertia_com - ref.inertia_com)) < 1e-11 * np.max(ref.inertia_com)


def test_combine_needs_parts():
    with pytest.raises(InputError, match="parts"):
        combine([])


# ---------------------------------------------------------------- inputs and robustness


@pytest.mark.parametrize("density", [0.0, -2400.0, float("nan"), float("inf"), "heavy"])
def test_bad_density_is_an_input_error_naming_field_and_object(density):
    with pytest.raises(InputError) as err:
        mass_properties(box([0, 0, 0], [1, 1, 1], "pier 3"), density)
    assert err.value.field == "density" and "pier 3" in str(err.value)


def test_open_mesh_never_yields_a_volume():
    b = box([0, 0, 0], [1, 1, 1], "open box")
    opened = type(b)(b.vertices, b.faces[2:], "open box")
    with pytest.raises(GeometryError, match="open box: is open"):
        mass_properties(opened, 2000.0, repair=False)
    fixed = mass_properties(opened, 2000.0)  # repaired: the missing face is planar
    assert rel(fixed.volume, 1.0) < RTOL and any("filled" in w for w in fixed.warnings)


def test_zero_direction_is_an_input_error():
    p = mass_properties(box([0, 0, 0], [1, 1, 1]), 1000.0)
    with pytest.raises(InputError, match="direction"):
        p.inertia_about_axis([0, 0, 0], [0, 0, 0])


def test_properties_are_read_only():
    p = mass_properties(box([0, 0, 0], [1, 1, 1]), 1000.0)
    with pytest.raises(ValueError):
        p.com[0] = 5.0


def test_translation_by_1e5_m_changes_nothing_beyond_1e_9():
    b = box([0, 0, 0], [0.6, 4.0, 3.0])
    shift = np.array([1e5, -1e5, 1e5])
    p0 = mass_properties(b, 1800.0)
    p1 = mass_properties(moved(b, np.eye(3), shift), 1800.0)
    assert rel(p1.volume, p0.volume) < 1e-9
    assert np.max(np.abs(p1.com - shift - p0.com)) < 1e-9 * 4.0
    assert np.max(np.abs(p1.inertia_com - p0.inertia_com)) < 1e-9 * np.max(p0.inertia_com)


# ---------------------------------------------------------------- properties


def random_solid(seed: int):
    rng = np.random.default_rng(seed)
    if seed % 3 == 0:
        lo = rng.uniform(-2, 2, 3)
        return box(lo, lo + rng.uniform(0.1, 3.0, 3), "random box")
    pts = rng.normal(size=(40, 3)) * rng.uniform(0.2, 3.0, 3) + rng.uniform(-2, 2, 3)
    return convex(pts, "random hull")


def random_rotation(rng):
    return rotation(rng.normal(size=3), rng.uniform(0, 2 * math.pi))


seeds = st.integers(0, 2**31 - 1)


@settings(max_examples=40, deadline=None)
@given(seeds, seeds)
def test_parallel_axis_theorem_matches_direct_integration_about_random_axes(seed, axis_seed):
    mesh = random_solid(seed)
    rho = 1000.0 + seed % 7000
    p = mass_properties(mesh, rho)
    rng = np.random.default_rng(axis_seed)
    point = rng.uniform(-5, 5, 3)
    u = rng.normal(size=3)
    u /= np.linalg.norm(u)
    # Direct: second moments about the axis point, no centre of mass involved.
    _, _, second = _integrals(mesh.vertices - point, mesh.faces)
    c_p = rho * second
    direct = u @ (np.trace(c_p) * np.eye(3) - c_p) @ u
    got = p.inertia_about_axis(point, 3.7 * u)
    assert got >= 0.0
    assert abs(got - direct) <= 1e-10 * direct


@settings(max_examples=40, deadline=None)
@given(seeds, seeds, st.sampled_from([0.0, 10.0, 1e5]))
def test_mass_properties_are_invariant_under_rigid_motion(seed, motion_seed, distance):
    mesh = random_solid(seed)
    rng = np.random.default_rng(motion_seed)
    rot = random_rotation(rng)
    shift = rng.normal(size=3)
    shift *= distance / max(np.linalg.norm(shift), 1e-300)
    p0 = mass_properties(mesh, 2400.0)
    p1 = mass_properties(moved(mesh, rot, shift), 2400.0)
    size = float(np.linalg.norm(np.ptp(mesh.vertices, axis=0)))
    assert abs(p1.volume - p0.volume) <= 1e-9 * p0.volume
    assert np.max(np.abs(p1.com - (rot @ p0.com + shift))) <= 1e-9 * size
    scale = np.max(np.abs(p0.inertia_com))
    assert np.max(np.abs(p1.inertia_com - rot @ p0.inertia_com @ rot.T)) <= 1e-9 * scale


@settings(max_examples=30, deadline=None)
@given(seeds, seeds)
def test_inertia_about_any_axis_is_positive(seed, axis_seed):
    p = mass_properties(random_solid(seed), 2000.0)
    rng = np.random.default_rng(axis_seed)
    assert p.inertia_about_axis(rng.uniform(-3, 3, 3), rng.normal(size=3)) > 0.0
    # Through the centre of mass it is bounded by the principal moments.
    eig = np.linalg.eigvalsh(p.inertia_com)
    i_g = p.inertia_about_axis(p.com, rng.normal(size=3))
    assert eig[0] * (1 - 1e-12) <= i_g <= eig[-1] * (1 + 1e-12)


def test_massprops_is_a_frozen_dataclass():
    p = MassProps(1.0, 2.0, [0, 0, 0], np.eye(3), 2.0)
    with pytest.raises(AttributeError):
        p.mass = 3.0  # type: ignore[misc]
