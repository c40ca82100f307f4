"""Hypothesis strategies shared by the tests: rotations, quaternions, bodies."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from tumble import mass

FINITE = {"allow_nan": False, "allow_infinity": False}


@st.composite
def unit_vectors(draw: st.DrawFn) -> np.ndarray:
    """Unit 3-vectors, roughly uniform on the sphere (a normalised box sample)."""
    vector = np.array(draw(st.tuples(*[st.floats(-1.0, 1.0, **FINITE)] * 3)))
    norm = np.linalg.norm(vector)
    if norm < 1e-3:
        return np.array([0.0, 0.0, 1.0])
    return vector / norm


def rotation_vectors(min_angle: float = 0.0, max_angle: float = np.pi) -> st.SearchStrategy:
    """Rotation vectors (rad) with angle in [min_angle, max_angle]."""
    angles = st.floats(min_angle, max_angle, **FINITE)
    return st.builds(lambda n, t: n * t, unit_vectors(), angles)


def small_rotation_vectors() -> st.SearchStrategy:
    """Angles from 0 to 1e-3 on a log scale, down to exactly 0."""
    tiny = st.builds(lambda e: 10.0**e, st.floats(-12.0, -3.0, **FINITE)) | st.just(0.0)
    return st.builds(lambda n, t: n * t, unit_vectors(), tiny)


def near_pi_rotation_vectors() -> st.SearchStrategy:
    """Angles within 1e-4 of π (below it), on a log scale, and π itself."""
    gap = st.builds(lambda e: 10.0**e, st.floats(-14.0, -4.0, **FINITE)) | st.just(0.0)
    return st.builds(lambda n, g: n * (np.pi - g), unit_vectors(), gap)


@st.composite
def unit_quaternions(draw: st.DrawFn) -> np.ndarray:
    """Unit quaternions [w, x, y, z], either sign of w."""
    q = np.array(draw(st.tuples(*[st.floats(-1.0, 1.0, **FINITE)] * 4)))
    norm = np.linalg.norm(q)
    if norm < 1e-3:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return q / norm


def rotation_matrices() -> st.SearchStrategy:
    """Rotation matrices from unit quaternions."""
    from tumble import so3

    return st.builds(so3.matrix_from_quat, unit_quaternions())


def euler_angles_away_from_lock(margin: float = 1e-3) -> st.SearchStrategy:
    """ZYX angles [phi_z, theta_y, psi_x] in the principal ranges, |theta| <= π/2 - margin."""
    half = np.pi / 2 - margin
    return st.builds(
        lambda a, b, c: np.array([a, b, c]),
        st.floats(-np.pi + 1e-9, np.pi, **FINITE),
        st.floats(-half, half, **FINITE),
        st.floats(-np.pi + 1e-9, np.pi, **FINITE),
    )


def points(scale: float = 1.0) -> st.SearchStrategy:
    """Points in the cube [-scale, scale]³ (m)."""
    coordinate = st.floats(-scale, scale, **FINITE)
    return st.builds(lambda x, y, z: np.array([x, y, z]), coordinate, coordinate, coordinate)


@st.composite
def bodies(draw: st.DrawFn) -> mass.MassProperties:
    """Boxes of random size, mass, orientation and position (always physical)."""
    sides = draw(st.tuples(*[st.floats(0.1, 2.0, **FINITE)] * 3))
    body_mass = draw(st.floats(0.1, 10.0, **FINITE))
    rotation = draw(rotation_matrices())
    center = draw(points())
    return mass.box(sides, mass=body_mass, rotation=rotation, center=center)
