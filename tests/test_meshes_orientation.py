"""Tests for the orientation of each part of a mesh: cavities kept, inside-out parts refused.

A closed mesh may have several connected parts. Each must be wound so that the surface bounds
a solid: outward at even nesting depth (a part, an island inside a cavity), inward at odd
depth (a cavity). Closed forms are those of :mod:`tumble.mass` (boxes are exact as meshes).
"""

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from strategies import points, rotation_matrices

from tumble import _parts, mass, meshes

DENSITY = 2.0


def _join(*parts):
    return trimesh.util.concatenate(list(parts))


def _inverted(mesh):
    mesh.invert()
    return mesh


def _same(body, expected):
    # the same mesh integrals over faces taken in another order or orientation: sums of a few
    # dozen signed tetrahedra of the body's size, without much cancellation (the hollow box:
    # 8 − 1), so 48 u · 9/7 = 7e-15 relative at most
    assert body.mass == pytest.approx(expected.mass, rel=1e-13)
    assert np.allclose(body.com, expected.com, rtol=0, atol=1e-13)
    assert np.allclose(body.inertia, expected.inertia, rtol=1e-12, atol=1e-13)


def _scaled(mesh, factor):
    return trimesh.Trimesh(mesh.vertices * factor, mesh.faces, process=False)


def _minus(outer, inner):
    """Mass properties of ``outer`` with the solid ``inner`` taken away (both at the origin)."""
    return mass.MassProperties(outer.mass - inner.mass, outer.com, outer.inertia - inner.inertia)


def test_a_separate_inside_out_part_is_refused_naming_it():
    # Issue 18, item 1: two disjoint boxes, the small one reversed, not inside the other;
    # its volume was subtracted (15.75 kg instead of 16.25 kg) without a word.
    mesh = _join(
        meshes.box([2.0, 2.0, 2.0]), _inverted(meshes.box([0.5, 0.5, 0.5], center=(1.5, 0, 0)))
    )
    with pytest.raises(
        ValueError,
        match=r"must be outward-oriented.*part 2 of 2 \(12 faces from face 12, volume -0.125 m³, "
        r"centred at \[1.5, 0, 0\] m\) is inside-out and lies inside no other part.*"
        r"fix_inside_out=True",
    ):
        meshes.from_mesh(mesh, density=DENSITY)


def test_fix_inside_out_flips_only_the_inverted_part_with_a_warning():
    big = meshes.box([2.0, 2.0, 2.0])
    mesh = _join(big, _inverted(meshes.box([0.5, 0.5, 0.5], center=(1.5, 0, 0))))
    with pytest.warns(UserWarning, match=r"part 2 of 2 .* is inside-out.*flipped"):
        body = meshes.from_mesh(mesh, density=DENSITY, fix_inside_out=True)
    expected = mass.box([2.0, 2.0, 2.0], density=DENSITY) + mass.box(
        [0.5, 0.5, 0.5], density=DENSITY, center=(1.5, 0, 0)
    )
    _same(body, expected)  # 16.25 kg; it was 15.75 (16 - 0.25)


def test_a_cavity_wound_inward_is_subtracted_without_a_word():
    mesh = _join(meshes.box([2.0, 2.0, 2.0]), _inverted(meshes.box([1.0, 1.0, 1.0])))
    body = meshes.from_mesh(mesh, density=DENSITY)  # filterwarnings=error: no warning either
    expected = _minus(
        mass.box([2.0, 2.0, 2.0], density=DENSITY), mass.box([1.0, 1.0, 1.0], density=DENSITY)
    )
    _same(body, expected)
    assert body.mass == pytest.approx(14.0, rel=1e-14)  # the hollow box: (8 - 1) m³ × 2 kg/m³


def test_an_island_inside_a_cavity_is_a_solid_again():
    outer, hole, island = (meshes.box([s, s, s]) for s in (4.0, 3.0, 1.0))
    body = meshes.from_mesh(_join(outer, _inverted(hole), island), density=1.0)
    assert body.mass == pytest.approx(64.0 - 27.0 + 1.0, rel=1e-14)


def test_a_cavity_wound_outward_is_refused_as_overlapping_solid():
    mesh = _join(meshes.box([2.0, 2.0, 2.0]), meshes.box([1.0, 1.0, 1.0]))
    with pytest.raises(
        ValueError, match=r"part 2 of 2 .* lies inside part 1 but is wound outward.*cavity"
    ):
        meshes.from_mesh(mesh, density=DENSITY)
    with pytest.warns(UserWarning, match=r"part 2 of 2 .*flipped"):
        body = meshes.from_mesh(mesh, density=DENSITY, fix_inside_out=True)
    assert body.mass == pytest.approx(14.0, rel=1e-14)


def test_a_whole_mesh_inside_out_with_a_cavity_is_one_fix():
    mesh = _join(_inverted(meshes.box([2.0, 2.0, 2.0])), meshes.box([1.0, 1.0, 1.0]))
    with pytest.raises(ValueError, match=r"part 1 of 2 .* is inside-out"):
        meshes.from_mesh(mesh, density=DENSITY)
    with pytest.warns(UserWarning, match="inside-out"):
        body = meshes.from_mesh(mesh, density=DENSITY, fix_inside_out=True)
    assert body.mass == pytest.approx(14.0, rel=1e-14)


def test_parts_that_touch_without_nesting_are_both_solids():
    # The T-handle's two cylinders touch along a line: neither is inside the other.
    body = meshes.from_mesh(meshes.t_handle(32), density=6700.0)
    expected = meshes.from_mesh(meshes.cylinder(0.01, 0.08, 32), density=6700.0).mass
    assert body.mass == pytest.approx(1.5 * expected, rel=1e-12)  # 8 cm + 4 cm of rod


def test_a_closed_mesh_of_zero_volume_is_refused_as_such():
    # Issue 18, item 11: a flat closed surface was blamed on the inertia matrix.
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]])
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    flat = trimesh.Trimesh(vertices, faces, process=False)
    with pytest.raises(ValueError, match=r"encloses no volume \(0 m³"):
        meshes.from_mesh(flat, density=1.0)


@pytest.mark.parametrize("scale", [1e-30, 1e30])
def test_orientation_is_judged_at_any_scale(scale):
    mesh = _join(meshes.box([2 * scale] * 3), _inverted(meshes.box([scale] * 3)))
    body = meshes.from_mesh(mesh, density=1.0)
    assert body.mass == pytest.approx(7 * scale**3, rel=1e-13)


def test_mass_properties_that_overflow_are_refused_with_the_cause():
    with pytest.raises(
        ValueError, match=r"mass properties are finite.*coordinates up to 1e\+150 m"
    ):
        meshes.from_mesh(_scaled(meshes.box([2.0, 2.0, 2.0]), 1e150), density=1.0)


@pytest.mark.parametrize(("point", "expected"), [((0.1, 0.2, -0.3), 1.0), ((0.0, 0.0, 2.0), 0.0)])
def test_winding_number_is_one_inside_and_zero_outside_and_flips_with_the_winding(point, expected):
    triangles = np.array(meshes.sphere(1.0, 2).triangles)
    assert _parts.winding_number(np.array(point), triangles) == pytest.approx(expected, abs=1e-12)
    reversed_ = triangles[:, ::-1]
    assert _parts.winding_number(np.array(point), reversed_) == pytest.approx(-expected, abs=1e-12)


@settings(max_examples=25)
@given(
    rotation=rotation_matrices(),
    offset=points(scale=100.0),
    scale=st.floats(1e-3, 1e3),
    gap=st.floats(0.01, 10.0),
)
def test_parts_are_judged_the_same_wherever_the_mesh_is_placed(rotation, offset, scale, gap):
    """A hollow box keeps its cavity, and a separate inside-out box is refused, after any
    rotation, translation and scaling; the masses are the closed forms."""
    place = np.eye(4)
    place[:3, :3], place[:3, 3] = scale * rotation, offset
    outer, hole = meshes.box([2.0, 2.0, 2.0]), _inverted(meshes.box([1.0, 1.0, 1.0]))
    apart = _inverted(meshes.box([0.5, 0.5, 0.5], center=(1.25 + gap, 0.0, 0.0)))
    hollow = _join(outer, hole).apply_transform(place)
    assert meshes.from_mesh(hollow, density=1.0).mass == pytest.approx(7 * scale**3, rel=1e-9)
    with pytest.raises(ValueError, match=r"part 2 of 2 .* is inside-out and lies inside no"):
        meshes.from_mesh(
            _join(meshes.box([2.0, 2.0, 2.0]), apart).apply_transform(place), density=1.0
        )


def test_a_part_in_the_hole_of_a_torus_is_beside_it_not_inside_it():
    # Its bounding box is inside the torus's, but the torus's winding number there is 0.
    ring, plug = meshes.torus(2.0, 0.5, 32), meshes.box([0.5, 0.5, 0.5])
    body = meshes.from_mesh(_join(ring, plug), density=1.0)
    expected = meshes.from_mesh(ring, density=1.0).mass + 0.125
    assert body.mass == pytest.approx(expected, rel=1e-13)
    with pytest.raises(ValueError, match=r"part 2 of 2 .* is inside-out and lies inside no other"):
        meshes.from_mesh(_join(ring, _inverted(plug)), density=1.0)
