"""Tests for tumble.mass: seed figures, closed forms, composition, validation, meshes."""

import numpy as np
import pytest
from hypothesis import given
from roundoff import error_bound
from strategies import bodies, points, rotation_matrices

from tumble import mass, meshes, so3

# Round-off: the closed forms are a few scalar operations in the library and in these tests
# (≤ 10 roundings a side on positive terms: ≤ 2.2e-15 relative; the bounds of 1e-14 and
# 1e-15 cover that, and elementwise IEEE operations give the same bits on every machine).
# Where the library rotates an inertia (R I Rᵀ in the CPU's BLAS kernel) or meshes a body,
# the bound counts the sums of products of entries of that size instead.

# Seed 002 / SPEC §4: the T-handle inertia, printed to 9 significant digits, so the
# reference itself is only good to 5e-13 / 7.2e-5 = 7e-9 relative; SPEC asks for 1e-8.
T_HANDLE_INERTIA = np.array([9.82271303e-05, 7.22671030e-05, 1.57865031e-04])
T_HANDLE_MASS = 0.2525840  # kg, 12π cm³ × 6.7 g/cm³, printed to 7 digits
# SPEC §4: torus R = 1, r = 0.5, rho = 1 (closed forms, printed to 7 digits).
TORUS_VOLUME = 4.934802
TORUS_INERTIA = np.array([3.238464, 3.238464, 5.860078])


def test_t_handle_inertia_matches_seed_002():
    assert np.allclose(mass.t_handle().inertia, np.diag(T_HANDLE_INERTIA), rtol=1e-8, atol=0)


def test_t_handle_mass_matches_seed_002():
    assert mass.t_handle().mass == pytest.approx(T_HANDLE_MASS, rel=5e-7)


def _com_roundoff(*parts) -> float:
    """The centre of mass Σ m_i c_i / M rounds each product, the sum and the quotient: 4
    roundings on Σ |m_i c_i| / M."""
    weights = sum(abs(part.mass * part.com) for part in parts) / sum(p.mass for p in parts)
    return float(error_bound(weights, 4).max())


def test_t_handle_centre_of_mass_is_the_origin():
    # m₁ (−1 cm) + m₂ (2 cm) with m₁ = 2 m₂: zero up to the rounding of each term (7e-19)
    handle = mass.cylinder(0.01, 0.08, density=6700.0, axis="y", center=(-0.01, 0, 0))
    shaft = mass.cylinder(0.01, 0.04, density=6700.0, axis="x", center=(0.02, 0, 0))
    assert np.allclose(mass.t_handle().com, 0.0, rtol=0, atol=_com_roundoff(handle, shaft))


def test_t_handle_equals_two_cylinders_added_by_hand():
    handle = mass.cylinder(0.01, 0.08, density=6700.0, axis="y", center=(-0.01, 0, 0))
    shaft = mass.cylinder(0.01, 0.04, density=6700.0, axis="x", center=(0.02, 0, 0))
    both = handle + shaft
    assert np.allclose(both.inertia, np.diag(T_HANDLE_INERTIA), rtol=1e-8, atol=0)
    assert np.allclose(both.com, 0.0, rtol=0, atol=_com_roundoff(handle, shaft))


def test_t_handle_matches_the_seed_hand_formula():
    # Seed 002, oppg1.py: I_xx = M1 R1²/4 + M1 L1²/12 + M2 R2²/2, and so on (exact here
    # because the offsets 1 cm and 2 cm equal R1 and L2/2).
    m1, m2, R, L1, L2 = 6700 * np.pi * 1e-4 * 0.08, 6700 * np.pi * 1e-4 * 0.04, 0.01, 0.08, 0.04
    expected = [
        m1 * R**2 / 4 + m1 * L1**2 / 12 + m2 * R**2 / 2,
        m1 * R**2 + m2 * L2**2 / 4 + m1 * R**2 / 2 + m2 * R**2 / 4 + m2 * L2**2 / 12,
        m1 * R**2
        + m2 * L2**2 / 4
        + m1 * R**2 / 4
        + m1 * L1**2 / 12
        + m2 * R**2 / 4
        + m2 * L2**2 / 12,
    ]
    assert np.allclose(mass.t_handle().inertia.diagonal(), expected, rtol=1e-14, atol=0)


def test_t_handle_with_other_dimensions_still_has_com_at_origin():
    body = mass.t_handle(handle_length=0.1, shaft_length=0.06)
    assert np.allclose(body.com, 0.0, rtol=0, atol=1e-17)


def test_torus_volume_and_inertia_match_spec():
    body = mass.torus(1.0, 0.5, density=1.0)
    # 7 printed digits: rounding error <= 5e-7 absolute.
    assert body.mass == pytest.approx(TORUS_VOLUME, abs=5e-7)
    assert np.allclose(body.inertia, np.diag(TORUS_INERTIA), rtol=0, atol=5e-7)


def test_torus_matches_the_textbook_formulas_on_another_axis():
    R, r, m = 2.0, 0.3, 7.0
    body = mass.torus(R, r, mass=m, axis="x")
    expected = np.diag([m * (R**2 + 0.75 * r**2), *[m * (R**2 / 2 + 5 * r**2 / 8)] * 2])
    assert np.allclose(body.inertia, expected, rtol=1e-14, atol=0)


def test_cylinder_matches_the_textbook_formulas():
    a, L, rho = 0.2, 1.5, 800.0
    m = rho * np.pi * a**2 * L
    body = mass.cylinder(a, L, density=rho)
    assert body.mass == pytest.approx(m, rel=1e-15)
    perp = m * (3 * a**2 + L**2) / 12
    assert np.allclose(body.inertia, np.diag([perp, perp, m * a**2 / 2]), rtol=1e-14, atol=0)


def test_hex_prism_equals_six_triangular_wedges():
    # Independent route: the hexagon's polar second moment as the sum over its six
    # equilateral triangles (centroid moment a²/12 per area plus the parallel-axis term).
    a, L = 0.3, 0.8
    area = 6 * np.sqrt(3) / 4 * a**2
    polar_per_area = a**2 / 12 + a**2 / 3
    body = mass.hex_prism(a, L, density=1.0)
    assert body.mass == pytest.approx(area * L, rel=1e-15)
    assert body.inertia[2, 2] == pytest.approx(area * L * polar_per_area, rel=1e-14)
    perp = area * L * (polar_per_area / 2 + L**2 / 12)
    assert body.inertia[0, 0] == pytest.approx(perp, rel=1e-14)


def test_sphere_has_isotropic_inertia():
    body = mass.sphere(0.5, mass=3.0)
    assert np.allclose(body.inertia, 0.4 * 3.0 * 0.25 * np.eye(3), rtol=1e-15, atol=0)


def test_box_rotated_has_rotated_inertia():
    R = so3.exp([0.3, -0.2, 0.9])
    body = mass.box([1.0, 2.0, 3.0], mass=12.0, rotation=R, center=(1.0, 2.0, 3.0))
    assert np.allclose(body.inertia, R @ np.diag([13.0, 10.0, 5.0]) @ R.T, rtol=0, atol=1e-13)
    assert np.allclose(body.com, [1.0, 2.0, 3.0], rtol=0, atol=0)


def test_axis_vector_gives_the_same_body_as_the_axis_name():
    by_name = mass.cylinder(1.0, 3.0, mass=1.0, axis="y")
    by_vector = mass.cylinder(1.0, 3.0, mass=1.0, axis=[0.0, 5.0, 0.0])
    assert np.allclose(by_name.inertia, by_vector.inertia, rtol=0, atol=1e-15)


def test_mass_and_density_give_the_same_body():
    by_density = mass.torus(1.0, 0.25, density=2.0)
    by_mass = mass.torus(1.0, 0.25, mass=by_density.mass)
    assert np.allclose(by_density.inertia, by_mass.inertia, rtol=1e-15, atol=0)


@pytest.mark.parametrize(
    ("primitive", "mesh", "rtol"),
    [
        # Exact meshes: integration round-off only.
        (mass.box([0.3, 0.5, 0.7], density=1.0), meshes.box([0.3, 0.5, 0.7]), 1e-12),
        (mass.hex_prism(0.4, 1.1, density=1.0), meshes.hex_prism(0.4, 1.1), 1e-12),
        # Inscribed polygons: relative error ~ (2π/n)²/6 = 1e-4 at n = 256; the torus has
        # two such polygons (around the axis and around the tube), and its inertia errs
        # about 1.6 times its volume (measured: 2.0e-4 and 3.1e-4).
        (mass.cylinder(0.4, 1.1, density=1.0), meshes.cylinder(0.4, 1.1, 256), 2e-4),
        (mass.torus(1.0, 0.3, density=1.0), meshes.torus(1.0, 0.3, 256), 4e-4),
        # Icosphere with 5 subdivisions (10240 faces): volume short by 5e-4.
        (mass.sphere(0.5, density=1.0), meshes.sphere(0.5, 5), 2e-3),
    ],
    ids=["box", "hex_prism", "cylinder", "torus", "sphere"],
)
def test_primitive_matches_its_mesh(primitive, mesh, rtol):
    meshed = meshes.from_mesh(mesh, density=1.0)
    assert meshed.mass == pytest.approx(primitive.mass, rel=rtol)
    scale = np.max(primitive.inertia)
    assert np.allclose(meshed.inertia, primitive.inertia, rtol=0, atol=rtol * scale)


def test_hex_prism_mesh_matches_on_a_slanted_axis():
    axis, center = [1.0, -2.0, 0.5], [0.1, 0.2, -0.3]
    primitive = mass.hex_prism(0.4, 1.1, density=3.0, axis=axis, center=center)
    meshed = meshes.from_mesh(meshes.hex_prism(0.4, 1.1, axis=axis, center=center), density=3.0)
    assert np.allclose(meshed.inertia, primitive.inertia, rtol=0, atol=1e-12)
    assert np.allclose(meshed.com, center, rtol=0, atol=1e-12)


def test_t_handle_mesh_converges_to_the_primitive():
    meshed = meshes.from_mesh(meshes.t_handle(256), density=6700.0)
    # Polygon error (2π/256)²/6 = 1e-4 relative (measured 1.0e-4 to 1.2e-4).
    scale = T_HANDLE_INERTIA.max()
    assert np.allclose(meshed.inertia, np.diag(T_HANDLE_INERTIA), rtol=0, atol=2e-4 * scale)


@given(bodies(), bodies(), points())
def test_sum_obeys_the_parallel_axis_theorem_about_any_point(a, b, point):
    total = a + b
    expected = a.inertia_about(point) + b.inertia_about(point)
    assert np.allclose(total.inertia_about(point), expected, rtol=1e-12, atol=1e-12)
    assert total.mass == pytest.approx(a.mass + b.mass, rel=1e-15)


def test_sum_of_a_list_uses_builtin_sum():
    parts = [mass.sphere(1.0, mass=1.0, center=(x, 0.0, 0.0)) for x in (-1.0, 0.0, 1.0)]
    total = sum(parts)
    assert total.mass == 3.0
    assert total.inertia[1, 1] == pytest.approx(3 * 0.4 + 2.0, rel=1e-15)


@given(bodies(), points())
def test_translation_keeps_the_inertia_about_the_com(body, offset):
    moved = body.translated(offset)
    assert np.array_equal(moved.inertia, body.inertia)
    assert np.allclose(moved.com, body.com + offset, rtol=0, atol=1e-15)


@given(bodies(), rotation_matrices())
def test_rotation_keeps_the_principal_moments(body, R):
    moments, _ = body.rotated(R).principal()
    assert np.allclose(moments, body.principal()[0], rtol=1e-12, atol=0)


@given(bodies())
def test_principal_axes_are_right_handed_and_diagonalise(body):
    moments, axes = body.principal()
    assert np.linalg.det(axes) == pytest.approx(1.0, abs=1e-12)
    scale = moments[-1]
    assert np.allclose(axes @ np.diag(moments) @ axes.T, body.inertia, rtol=0, atol=1e-12 * scale)
    assert np.all(np.diff(moments) >= 0)


def test_mass_properties_arrays_are_read_only_copies():
    com = np.array([1.0, 2.0, 3.0])
    body = mass.MassProperties(1.0, com, np.eye(3))
    com[0] = 99.0
    assert body.com[0] == 1.0
    with pytest.raises(ValueError, match="read-only"):
        body.inertia[0, 0] = 5.0


def test_mass_properties_is_frozen():
    body = mass.MassProperties(1.0, [0.0, 0.0, 0.0], np.eye(3))
    with pytest.raises(AttributeError):
        body.mass = 2.0


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf"), "heavy"])
def test_mass_properties_refuses_bad_mass(bad):
    with pytest.raises(ValueError, match=r"mass=.* is not allowed: must be finite and > 0"):
        mass.MassProperties(bad, [0.0, 0.0, 0.0], np.eye(3))


def test_validate_inertia_refuses_asymmetric():
    inertia = np.array([[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(
        ValueError, match=r"I_body=\[\[1\.0, 0\.1.* is not allowed: must be symmetric"
    ):
        mass.validate_inertia(inertia, name="I_body")


def test_validate_inertia_refuses_indefinite():
    with pytest.raises(
        ValueError, match=r"inertia=.* is not allowed: must be positive definite.*-1\.0"
    ):
        mass.validate_inertia(np.diag([1.0, 2.0, -1.0]))


def test_validate_inertia_refuses_triangle_violation_with_the_remedy():
    with pytest.raises(ValueError, match=r"triangle inequality.*allow_unphysical=True"):
        mass.validate_inertia(np.diag([2.0, 1.0, 2 / 3]))


def test_validate_inertia_accepts_unphysical_when_asked():
    value = mass.validate_inertia(np.diag([2.0, 1.0, 2 / 3]), allow_unphysical=True)
    assert np.array_equal(value, np.diag([2.0, 1.0, 2 / 3]))


def test_validate_inertia_accepts_a_thin_plate_at_the_triangle_bound():
    # A plate has I_z = I_x + I_y exactly; round-off must not reject it.
    plate = mass.box([1.0, 2.0, 1e-9], mass=1.0).rotated(so3.exp([0.1, 0.2, 0.3]))
    assert plate.principal()[0][2] == pytest.approx(5 / 12, rel=1e-12)


def test_mass_properties_refuses_unphysical_unless_asked():
    with pytest.raises(ValueError, match="allow_unphysical"):
        mass.MassProperties(1.0, [0.0, 0.0, 0.0], np.diag([2.0, 1.0, 2 / 3]))
    body = mass.MassProperties(
        1.0, [0.0, 0.0, 0.0], np.diag([2.0, 1.0, 2 / 3]), allow_unphysical=True
    )
    assert body.allow_unphysical


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (
            lambda: mass.cylinder(-0.1, 1.0, density=1.0),
            r"radius=-0\.1 is not allowed: must be .*> 0",
        ),
        (
            lambda: mass.cylinder(0.1, 0.0, density=1.0),
            r"length=0\.0 is not allowed: must be .*> 0",
        ),
        (lambda: mass.sphere(float("nan"), mass=1.0), r"radius=nan is not allowed: must be .*> 0"),
        (
            lambda: mass.hex_prism(-2.0, 1.0, mass=1.0),
            r"circumradius=-2\.0 is not allowed: must be .*> 0",
        ),
        (
            lambda: mass.box([1.0, -1.0, 1.0], mass=1.0),
            r"extents\[1\]=-1\.0 is not allowed: must be .*> 0",
        ),
        (
            lambda: mass.torus(-1.0, 0.5, mass=1.0),
            r"major_radius=-1\.0 is not allowed: must be .*> 0",
        ),
        (
            lambda: mass.torus(1.0, 1.0, mass=1.0),
            r"minor_radius=1\.0 is not allowed: must be less than major_rad",
        ),
        (
            lambda: mass.torus(1.0, 2.0, mass=1.0),
            r"minor_radius=2\.0 is not allowed: .*major_radius=1\.0",
        ),
        (
            lambda: mass.cylinder(1.0, 1.0, density=-5.0),
            r"density=-5\.0 is not allowed: must be .*> 0",
        ),
        (lambda: mass.cylinder(1.0, 1.0, mass=0.0), r"mass=0\.0 is not allowed: must be .*> 0"),
        (lambda: mass.cylinder(1.0, 1.0), r"exactly one of density= .* or mass="),
        (lambda: mass.cylinder(1.0, 1.0, mass=1.0, density=1.0), r"exactly one of density="),
        (
            lambda: mass.cylinder(1.0, 1.0, mass=1.0, axis="w"),
            r'axis=\'w\' is not allowed: must be "x"',
        ),
        (
            lambda: mass.cylinder(1.0, 1.0, mass=1.0, axis=[0, 0, 0]),
            r"axis=\[0, 0, 0\] is not allowed: must be .*nonzero",
        ),
        (
            lambda: mass.sphere(1.0, mass=1.0, center=[0, 1]),
            r"center=\[0, 1\] is not allowed: must be of shape \(3,\)",
        ),
        (lambda: mass.t_handle(density=0.0), r"density=0\.0 is not allowed: must be .*> 0"),
    ],
    ids=[
        "negative-radius",
        "zero-length",
        "nan-radius",
        "negative-circumradius",
        "negative-extent",
        "negative-major-radius",
        "minor-equals-major",
        "minor-above-major",
        "negative-density",
        "zero-mass",
        "neither-mass-nor-density",
        "both-mass-and-density",
        "unknown-axis-name",
        "zero-axis-vector",
        "two-component-center",
        "t-handle-zero-density",
    ],
)
def test_primitives_refuse_bad_input_naming_argument_value_and_rule(build, message):
    with pytest.raises(ValueError, match=message):
        build()


def test_rotated_refuses_a_non_rotation():
    body = mass.sphere(1.0, mass=1.0)
    with pytest.raises(ValueError, match=r"rotation=.* is not allowed: must be a rotation matrix"):
        body.rotated(2.0 * np.eye(3))


def test_from_mesh_reads_a_file(tmp_path):
    path = meshes.save(meshes.box([1.0, 2.0, 3.0]), tmp_path / "box.stl")
    body = meshes.from_mesh(path, density=2.0)
    assert body.mass == pytest.approx(12.0, rel=1e-12)
    assert np.allclose(body.inertia, np.diag([13.0, 10.0, 5.0]), rtol=1e-12, atol=0)


def test_from_mesh_refuses_an_open_mesh():
    mesh = meshes.box([1.0, 1.0, 1.0])
    mesh.update_faces(np.arange(len(mesh.faces) - 1))
    with pytest.raises(
        ValueError, match=r"mesh_or_path=.* is not allowed: must be a closed \(watertight\)"
    ):
        meshes.from_mesh(mesh, density=1.0)


def test_from_mesh_refuses_an_inside_out_mesh_with_the_remedy():
    mesh = meshes.torus(1.0, 0.5, 16)
    mesh.invert()
    with pytest.raises(ValueError, match=r"outward-oriented.*volume -4\.68.*fix_inside_out=True"):
        meshes.from_mesh(mesh, density=1.0)


def test_from_mesh_flips_an_inside_out_mesh_with_a_warning_when_asked():
    mesh = meshes.torus(1.0, 0.5, 16)
    expected = meshes.from_mesh(mesh, density=1.0)
    mesh.invert()
    with pytest.warns(UserWarning, match="inside-out"):
        body = meshes.from_mesh(mesh, density=1.0, fix_inside_out=True)
    assert np.allclose(body.inertia, expected.inertia, rtol=1e-14, atol=0)
    assert mesh.volume < 0  # the caller's mesh is left as it was


def test_from_mesh_refuses_inconsistent_winding():
    mesh = meshes.box([1.0, 1.0, 1.0])
    faces = mesh.faces.copy()
    faces[0] = faces[0][::-1]
    mesh.faces = faces
    with pytest.raises(
        ValueError, match=r"mesh_or_path=.* is not allowed: must be a mesh with consistently wound"
    ):
        meshes.from_mesh(mesh, density=1.0)


def test_from_mesh_refuses_an_unreadable_file(tmp_path):
    path = tmp_path / "broken.stl"
    path.write_bytes(b"not an stl file")
    with pytest.raises(ValueError, match=r"path=.*broken.* is not allowed: must be an STL file"):
        meshes.from_mesh(path, density=1.0)


def test_from_mesh_refuses_a_non_mesh():
    with pytest.raises(
        ValueError, match=r"mesh_or_path=42 is not allowed: must be a trimesh.Trimesh"
    ):
        meshes.from_mesh(42, density=1.0)


def test_from_mesh_refuses_bad_density():
    with pytest.raises(ValueError, match=r"density=-1 is not allowed: must be finite and > 0"):
        meshes.from_mesh(meshes.box([1.0, 1.0, 1.0]), density=-1)


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (
            lambda: mass.sphere(1e200, density=1e200),
            r"radius=1e\+200 is not allowed: must be such that the mass and the moments of "
            r"inertia are finite and > 0 \(m\); with density=1e\+200 kg/m³",
        ),
        (lambda: mass.cylinder(1e200, 1.0, density=1.0), r"radius=1e\+200 is not allowed"),
        (lambda: mass.torus(1e200, 1.0, mass=1.0), r"major_radius=1e\+200 .*and mass=1\.0 kg"),
        (lambda: mass.hex_prism(1.0, 1e300, density=1e10), r"length=1e\+300 is not allowed"),
        (lambda: mass.box([1e200, 1.0, 1.0], density=1.0), r"extents\[0\]=1e\+200 is not all"),
        (lambda: mass.sphere(1e-200, density=1.0), r"radius=1e-200 .*the mass is 0 kg"),
        (lambda: mass.sphere(1e-170, mass=1.0), r"radius=1e-170 .*a moment of inertia is 0 kg m²"),
    ],
    ids=["sphere", "cylinder", "torus", "hex_prism", "box", "tiny-sphere", "tiny-inertia"],
)
def test_sizes_whose_mass_or_inertia_overflow_are_refused_by_name(build, message):
    # Issue 18, item 11: mass.sphere(1e200, density=1e200) raised a raw OverflowError; other
    # sizes gave numpy warnings and an inertia "not positive definite".
    with pytest.raises(ValueError, match=message):
        build()
