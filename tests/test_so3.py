"""Tests for tumble.so3: conventions, round trips, scipy agreement, dexp."""

import numpy as np
import pytest
from hypothesis import given
from roundoff import error_bound
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation
from strategies import (
    euler_angles_away_from_lock,
    near_pi_rotation_vectors,
    rotation_matrices,
    rotation_vectors,
    small_rotation_vectors,
    unit_quaternions,
)

from tumble import so3

# Round-off tolerance: a few hundred ulps of quantities of size ~1. Each check compares two
# chains of at most ~50 roundings (numpy's SIMD sin and cos to 4 ulps, norms, 3-term products
# in the CPU's BLAS kernel, a composition) on terms of size ≤ 3: 2 · 50 u · 3 = 3.3e-14.
ROUNDOFF = 1e-13


def to_scipy(q):
    """Scalar-first [w, x, y, z] -> scipy's scalar-last [x, y, z, w]."""
    return np.roll(q, -1, axis=-1)


def from_scipy(q):
    """scipy's scalar-last [x, y, z, w] -> scalar-first [w, x, y, z]."""
    return np.roll(q, 1, axis=-1)


def same_rotation_vector(a, b, atol=ROUNDOFF):
    """Equal, or both of angle π and opposite (w and -w are the same rotation at π)."""
    return np.allclose(a, b, rtol=0, atol=atol) or (
        abs(np.linalg.norm(a) - np.pi) < 1e-6 and np.allclose(a, -b, rtol=0, atol=atol)
    )


def test_hat_is_the_cross_product():
    w, v = np.array([0.3, -1.2, 2.0]), np.array([1.5, 0.4, -0.7])
    assert np.allclose(so3.hat(w) @ v, np.cross(w, v), rtol=0, atol=ROUNDOFF)


def test_vee_inverts_hat_over_a_batch():
    w = np.arange(24.0).reshape(2, 4, 3)
    assert np.array_equal(so3.vee(so3.hat(w)), w)


def test_exp_of_quarter_turn_about_z_maps_x_to_y():
    # R maps body to world: the body x axis ends up along world y.
    R = so3.exp([0.0, 0.0, np.pi / 2])
    assert np.allclose(R @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], rtol=0, atol=ROUNDOFF)


@given(rotation_vectors())
def test_exp_matches_scipy_from_rotvec(w):
    expected = Rotation.from_rotvec(w).as_matrix()
    assert np.allclose(so3.exp(w), expected, rtol=0, atol=ROUNDOFF)


@given(rotation_vectors(max_angle=np.pi - 1e-6))
def test_log_inverts_exp(w):
    assert np.allclose(so3.log(so3.exp(w)), w, rtol=0, atol=ROUNDOFF)


@given(small_rotation_vectors())
def test_log_inverts_exp_near_zero_to_relative_precision(w):
    # Relative: at angle 1e-12 an absolute check would pass for log = 0. The series and the
    # quaternion are accurate to a few u relative: ≤ 20 roundings, 4.4e-15 < 1e-14.
    scale = max(np.linalg.norm(w), 1e-300)
    assert np.linalg.norm(so3.log(so3.exp(w)) - w) <= 1e-14 * scale


@given(near_pi_rotation_vectors())
def test_log_inverts_exp_near_pi(w):
    # arccos((tr R - 1)/2) would lose half the digits here (error ~ sqrt(eps) = 1e-8).
    assert same_rotation_vector(so3.log(so3.exp(w)), w, atol=1e-12)


@given(rotation_matrices())
def test_log_matches_scipy_as_rotvec(R):
    assert same_rotation_vector(so3.log(R), Rotation.from_matrix(R).as_rotvec())


def test_exp_and_log_work_on_batches():
    w = np.random.default_rng(0).normal(size=(5, 2, 3))
    R = so3.exp(w)
    assert R.shape == (5, 2, 3, 3)
    assert np.allclose(so3.exp(so3.log(R)), R, rtol=0, atol=ROUNDOFF)


@given(unit_quaternions())
def test_matrix_from_quat_matches_scipy_scalar_last(q):
    expected = Rotation.from_quat(to_scipy(q)).as_matrix()
    assert np.allclose(so3.matrix_from_quat(q), expected, rtol=0, atol=ROUNDOFF)


@given(rotation_matrices())
def test_quat_from_matrix_matches_scipy_up_to_sign(R):
    q = so3.quat_from_matrix(R)
    expected = from_scipy(Rotation.from_matrix(R).as_quat())
    assert np.allclose(q, expected, atol=ROUNDOFF) or np.allclose(q, -expected, atol=ROUNDOFF)


@given(unit_quaternions())
def test_quat_matrix_round_trip_up_to_sign(q):
    back = so3.quat_from_matrix(so3.matrix_from_quat(q))
    assert np.allclose(back, q, atol=ROUNDOFF) or np.allclose(back, -q, atol=ROUNDOFF)


@given(rotation_matrices())
def test_quat_from_matrix_has_nonnegative_scalar_part(R):
    assert so3.quat_from_matrix(R)[0] >= 0.0


@given(unit_quaternions(), unit_quaternions())
def test_quaternion_product_composes_rotations(p, q):
    product = so3.matrix_from_quat(so3.quat_mul(p, q))
    composed = so3.matrix_from_quat(p) @ so3.matrix_from_quat(q)
    assert np.allclose(product, composed, rtol=0, atol=ROUNDOFF)


@given(unit_quaternions(), unit_quaternions())
def test_quat_mul_matches_scipy_composition(p, q):
    expected = (Rotation.from_quat(to_scipy(p)) * Rotation.from_quat(to_scipy(q))).as_quat()
    product = so3.quat_mul(p, q)
    # Both are exact Hamilton products, so the sign agrees too.
    assert np.allclose(product, from_scipy(expected), rtol=0, atol=ROUNDOFF)


@given(unit_quaternions())
def test_quat_conj_is_the_inverse(q):
    identity = so3.quat_mul(q, so3.quat_conj(q))
    assert np.allclose(identity, [1.0, 0.0, 0.0, 0.0], rtol=0, atol=ROUNDOFF)


@given(rotation_vectors())
def test_quat_from_rotvec_matches_scipy_up_to_sign(w):
    q = so3.quat_from_rotvec(w)
    expected = from_scipy(Rotation.from_rotvec(w).as_quat())
    assert np.allclose(q, expected, atol=ROUNDOFF) or np.allclose(q, -expected, atol=ROUNDOFF)


@given(small_rotation_vectors())
def test_rotvec_quat_round_trip_near_zero_is_relatively_exact(w):
    scale = max(np.linalg.norm(w), 1e-300)
    assert np.linalg.norm(so3.rotvec_from_quat(so3.quat_from_rotvec(w)) - w) <= 1e-14 * scale


def test_quat_normalize_refuses_zero_norm_naming_the_argument():
    with pytest.raises(
        ValueError, match=r"q0=\[0\.0, 0\.0, 0\.0, 0\.0\] is not allowed: must be .* nonzero norm"
    ):
        so3.quat_normalize(np.zeros(4), name="q0")


def test_quat_normalize_refuses_wrong_shape():
    with pytest.raises(
        ValueError,
        match=r"q=.* must be quaternions \[w, x, y, z\] of shape \(\.\.\., 4\).*\(3,\)",
    ):
        so3.quat_normalize([1.0, 0.0, 0.0])


def test_euler_zyx_is_rz_ry_rx():
    phi, theta, psi = 0.4, -0.3, 1.1
    e = np.eye(3)
    expected = so3.exp(phi * e[2]) @ so3.exp(theta * e[1]) @ so3.exp(psi * e[0])
    assert np.allclose(so3.matrix_from_euler_zyx([phi, theta, psi]), expected, atol=ROUNDOFF)


@given(euler_angles_away_from_lock())
def test_euler_zyx_round_trip_away_from_gimbal_lock(angles):
    R = so3.matrix_from_euler_zyx(angles)
    back = so3.euler_zyx_from_matrix(R)
    # Angle errors grow like eps / cos(theta): 1e-13 / 1e-3 margin; ±π compared on the circle.
    assert np.allclose(np.angle(np.exp(1j * (back - angles))), 0.0, rtol=0, atol=1e-10)


@given(euler_angles_away_from_lock())
def test_euler_zyx_matches_scipy_intrinsic_zyx(angles):
    R = so3.matrix_from_euler_zyx(angles)
    expected = Rotation.from_matrix(R).as_euler("ZYX")
    # ±π name the same angle: compare on the circle (seen: ψ = π here, −π from scipy).
    difference = np.angle(np.exp(1j * (so3.euler_zyx_from_matrix(R) - expected)))
    assert np.allclose(difference, 0.0, rtol=0, atol=1e-10)


@pytest.mark.parametrize("theta", [np.pi / 2, -np.pi / 2])
def test_euler_zyx_at_gimbal_lock_sets_psi_to_zero_and_keeps_the_rotation(theta):
    R = so3.matrix_from_euler_zyx([0.7, theta, -0.4])
    angles = so3.euler_zyx_from_matrix(R)
    assert angles[2] == 0.0
    assert angles[1] == pytest.approx(theta, abs=1e-7)
    assert np.allclose(so3.matrix_from_euler_zyx(angles), R, rtol=0, atol=ROUNDOFF)


@pytest.mark.parametrize("gap", [1e-6, 1e-9])
def test_euler_zyx_near_gimbal_lock_still_reproduces_the_rotation(gap):
    # cos(theta) = gap: phi is ill-determined but psi compensates, so R comes back to
    # round-off; treating this as gimbal lock (psi = 0) would cost an error of size gap.
    # Each entry: up to three sin or cos (≤ 4 ulps in numpy's SIMD loops), three products and
    # a sum, on terms ≤ 2; both sides: 2 · 16 u · 2 = 7e-15 < 1e-14.
    R = so3.matrix_from_euler_zyx([0.7, np.pi / 2 - gap, -0.4])
    angles = so3.euler_zyx_from_matrix(R)
    assert np.allclose(so3.matrix_from_euler_zyx(angles), R, rtol=0, atol=1e-14)


@given(rotation_matrices())
def test_euler_zyx_reproduces_any_rotation(R):
    # Including near gimbal lock, where phi alone is ill-determined (1e-9: eps / cos θ).
    angles = so3.euler_zyx_from_matrix(R)
    assert np.allclose(so3.matrix_from_euler_zyx(angles), R, rtol=0, atol=1e-9)


def test_random_rotation_is_a_batch_of_rotations():
    R = so3.random_rotation(np.random.default_rng(1), size=(4, 5))
    assert R.shape == (4, 5, 3, 3)
    assert np.allclose(R @ R.swapaxes(-1, -2), np.eye(3), rtol=0, atol=ROUNDOFF)
    assert np.allclose(np.linalg.det(R), 1.0, rtol=0, atol=ROUNDOFF)


def test_random_rotation_is_haar_uniform():
    # Under Haar measure, E[R] = 0 and E[tr R] = 0; with 20000 draws each mean entry has
    # standard deviation 1/sqrt(3 * 20000) = 0.004, so 0.02 is five sigma.
    R = so3.random_rotation(np.random.default_rng(2), size=20000)
    assert np.max(np.abs(R.mean(axis=0))) < 0.02
    # The angle density is (1 - cos t)/π on [0, π]: P(t < π/2) = (π/2 - 1)/π = 0.1817.
    angles = np.linalg.norm(so3.log(R), axis=-1)
    assert np.mean(angles < np.pi / 2) == pytest.approx((np.pi / 2 - 1) / np.pi, abs=0.015)


@given(rotation_vectors(max_angle=3.0))
def test_dexp_times_dexpinv_is_identity(u):
    assert np.allclose(so3.dexp(u) @ so3.dexpinv(u), np.eye(3), rtol=0, atol=1e-12)


@given(small_rotation_vectors())
def test_dexp_times_dexpinv_is_identity_near_zero(u):
    assert np.allclose(so3.dexp(u) @ so3.dexpinv(u), np.eye(3), rtol=0, atol=ROUNDOFF)


@pytest.mark.parametrize("angle", [0.05, 0.0999999, 0.1, 0.1000001, 0.2])
def test_dexp_times_dexpinv_is_identity_to_round_off_at_the_series_switch(angle):
    # so3 switches to Taylor series below 0.1 rad; a missing series term or a cancelling
    # closed form would leave > 1e-12 here (e.g. the t^4 term of dexpinv: 1e-4/30240 * t^2).
    u = angle * np.array([0.6, 0.0, 0.8])
    # each entry of dexp = I + a K + b K² and of dexp⁻¹ within a few u of their terms (size
    # ‖·‖∞ ≈ 1 here), then 3-term products: ≤ 10 roundings on ‖dexp‖∞ ‖dexp⁻¹‖∞ (measured 2 u)
    A, B = so3.dexp(u), so3.dexpinv(u)
    roundoff = error_bound(np.abs(A).sum(axis=1).max() * np.abs(B).sum(axis=1).max(), 10)
    assert np.abs(A @ B - np.eye(3)).max() <= roundoff


@given(rotation_vectors(max_angle=3.0), rotation_vectors(max_angle=1.0))
def test_dexp_is_the_left_trivialised_derivative_of_exp(u, v):
    # d/de exp(u + e v) at e = 0 equals hat(dexp(u) v) exp(u); central difference error
    # is O(eps^2) ~ 1e-10 plus round-off / eps ~ 1e-11.
    eps = 1e-5
    derivative = (so3.exp(u + eps * v) - so3.exp(u - eps * v)) / (2 * eps)
    assert np.allclose(derivative, so3.hat(so3.dexp(u) @ v) @ so3.exp(u), rtol=0, atol=1e-8)


@given(rotation_vectors(max_angle=3.0), rotation_vectors(max_angle=1.0))
def test_dexp_of_minus_u_is_the_right_trivialised_derivative(u, v):
    eps = 1e-5
    derivative = (so3.exp(u + eps * v) - so3.exp(u - eps * v)) / (2 * eps)
    body = so3.exp(u).T @ derivative
    assert np.allclose(body, so3.hat(so3.dexp(-u) @ v), rtol=0, atol=1e-8)


def test_dexpinv_of_minus_u_integrates_body_frame_kinematics():
    # X' = X hat(Omega(t)) integrated directly, against X = X0 exp(u), u' = dexpinv(-u) Omega.
    # Both by solve_ivp at rtol 1e-12; agreement to 1e-9 pins the sign convention (the
    # other sign, dexpinv(u), is off by O(1) here).
    def omega(t):
        return np.array([1.0 + np.sin(2 * t), 0.5 * np.cos(3 * t), -0.8 + t])

    X0 = so3.exp([0.2, -0.4, 0.1])

    def matrix_rhs(t, x):
        return (x.reshape(3, 3) @ so3.hat(omega(t))).ravel()

    def algebra_rhs(t, u):
        return so3.dexpinv(-u) @ omega(t)

    options = {"rtol": 1e-12, "atol": 1e-12, "method": "DOP853"}
    X = solve_ivp(matrix_rhs, (0, 1.2), X0.ravel(), **options).y[:, -1].reshape(3, 3)
    u = solve_ivp(algebra_rhs, (0, 1.2), np.zeros(3), **options).y[:, -1]
    assert np.allclose(X0 @ so3.exp(u), X, rtol=0, atol=1e-9)


def test_dexpinv_of_plus_u_integrates_world_frame_kinematics():
    # X' = hat(omega(t)) X with X = exp(u) X0 and u' = dexpinv(u) omega.
    def omega(t):
        return np.array([0.3 - t, 1.0 + np.cos(t), 0.7 * np.sin(4 * t)])

    X0 = so3.exp([-0.5, 0.3, 0.9])
    options = {"rtol": 1e-12, "atol": 1e-12, "method": "DOP853"}
    X = solve_ivp(
        lambda t, x: (so3.hat(omega(t)) @ x.reshape(3, 3)).ravel(), (0, 1.2), X0.ravel(), **options
    ).y[:, -1]
    u = solve_ivp(lambda t, u: so3.dexpinv(u) @ omega(t), (0, 1.2), np.zeros(3), **options).y[
        :, -1
    ]
    assert np.allclose(so3.exp(u) @ X0, X.reshape(3, 3), rtol=0, atol=1e-9)


@given(rotation_vectors(max_angle=3.0), rotation_vectors(max_angle=2.0))
def test_dexpinv_apply_equals_the_matrix_product(u, v):
    assert np.allclose(so3.dexpinv_apply(u, v), so3.dexpinv(u) @ v, rtol=0, atol=1e-12)


def test_dexpinv_series_starts_with_the_bernoulli_terms():
    # dexpinv(u) v = v - [u, v]/2 + [u, [u, v]]/12 + O(|u|^4): the RKMK4 truncation.
    u, v = 1e-3 * np.array([0.3, -0.5, 0.8]), np.array([1.0, 2.0, -1.0])
    truncated = v - np.cross(u, v) / 2 + np.cross(u, np.cross(u, v)) / 12
    assert np.allclose(so3.dexpinv(u) @ v, truncated, rtol=0, atol=1e-12)


def test_dexp_and_dexpinv_work_on_batches():
    u = np.random.default_rng(3).normal(size=(6, 3))
    products = so3.dexp(u) @ so3.dexpinv(u)
    assert products.shape == (6, 3, 3)
    assert np.allclose(products, np.eye(3), rtol=0, atol=1e-12)


def test_validate_rotation_refuses_a_reflection():
    with pytest.raises(
        ValueError, match=r"R0=.* is not allowed: must be a rotation matrix.*det R = -1"
    ):
        so3.validate_rotation(np.diag([1.0, 1.0, -1.0]), name="R0")


def test_validate_rotation_refuses_a_scaled_matrix():
    with pytest.raises(
        ValueError, match=r"R0=.* is not allowed: must be a rotation.*max\|R\^T R - I\| = 0\.21"
    ):
        so3.validate_rotation(1.1 * np.eye(3), name="R0")
