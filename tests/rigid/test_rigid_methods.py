"""Every rigid-body method's measured order, and the seed 002 figures (SPEC §1, §4)."""

import numpy as np
import pytest

from tumble import exact
from tumble.rigid import RigidBody, simulate

# Hairer, Lubich & Wanner's free body (GNI §VII.5): violates the triangle inequality on purpose.
INERTIA = np.array([2.0, 1.0, 2.0 / 3.0])
L0 = np.array([np.cos(1.1), 0.0, np.sin(1.1)])
T_END = 10.0


@pytest.fixture(scope="module")
def hairer():
    return RigidBody(1.0, INERTIA, allow_unphysical=True)


@pytest.fixture(scope="module")
def reference():
    return exact.free_body_rotation(INERTIA, L0 / INERTIA, T_END)


@pytest.mark.parametrize(
    ("method", "order", "steps"),
    [
        ("euler", 1, [1000, 2000, 4000, 8000]),
        ("lie-euler", 1, [1000, 2000, 4000, 8000]),
        ("rk4-matrix", 4, [100, 200, 400, 800]),
        ("rk4-quat", 4, [100, 200, 400, 800]),
        ("seed-rk4", 2, [100, 200, 400, 800]),
        ("rkmk4", 4, [100, 200, 400, 800]),
        # h = 0.5 … 0.2: errors 7.7e-10 … 4.8e-13 (round-off is 1e-15), slope 8.03; coarser
        # steps are pre-asymptotic (8.3–8.5 from h = 1).
        ("rkmk8", 8, [20, 25, 32, 40, 50]),
    ],
)
def test_method_has_its_order_on_asymmetric_body(hairer, reference, method, order, steps):
    h = T_END / np.array(steps)
    errors = [
        np.linalg.norm(simulate(hairer, T_END, method=method, h=hi, L0=L0).R[-1] - reference)
        for hi in h
    ]
    slope = exact.observed_order(h, errors)
    assert abs(slope - order) < 0.25, f"{method}: measured order {slope:.3f}, claimed {order}"


def test_rkmk4_halving_h_divides_error_by_16(hairer, reference):
    # SPEC §1: on this body halving h divides the RKMK4 error by 16, not 4 (seed 002's RK4).
    errors = [
        np.linalg.norm(simulate(hairer, T_END, h=h, L0=L0).R[-1] - reference) for h in (0.02, 0.01)
    ]
    assert 13 < errors[0] / errors[1] < 19


def test_rkmk8_reaches_round_off_level_errors_in_50_steps(hairer, reference):
    # h = 0.2 over 10 s: measured 4.8e-13; bound with a 4x margin. rkmk4 at this h: 2.3e-5.
    run = simulate(hairer, T_END, method="rkmk8", h=0.2, L0=L0)
    assert np.linalg.norm(run.R[-1] - reference) < 2e-12
    assert run.orthogonality_error.max() < 1e-14


def test_seed_rk4_halving_h_divides_error_by_4_only(hairer, reference):
    errors = [
        np.linalg.norm(simulate(hairer, T_END, method="seed-rk4", h=h, L0=L0).R[-1] - reference)
        for h in (0.02, 0.01)
    ]
    assert 3.2 < errors[0] / errors[1] < 4.8


def test_sphere_euler_reproduces_seed_table():
    # SPEC §4: eq. 24 on the sphere, h = 0.1, t = 1 (seed 002's table, 8 digits).
    run = simulate(RigidBody(1.0, np.eye(3)), 1.0, method="euler", h=0.1, omega0=(1, 0, 0))
    expected = [[1, 0, 0], [0, 0.57079045, -0.88250801], [0, 0.88250801, 0.57079045]]
    np.testing.assert_allclose(run.R[-1], expected, atol=5e-9)
    assert len(run.t) == 11


def test_sphere_lie_euler_is_exact_to_round_off():
    run = simulate(RigidBody(1.0, np.eye(3)), 1.0, method="lie-euler", h=0.1, omega0=(1, 0, 0))
    np.testing.assert_allclose(run.R, exact.sphere(run.t), atol=1e-14)
    assert len(run.t) == 11


def test_rkmk4_long_run_stays_on_so3_and_conserves(hairer):
    # h = 0.01, T = 100: ‖RᵀR − I‖ < 1e-12 throughout, energy to 1e-6, L_world to 1e-12.
    run = simulate(hairer, 100.0, h=0.01, L0=L0)
    assert run.orthogonality_error.max() < 1e-12
    energy = run.energy
    assert np.abs(energy / energy[0] - 1).max() < 1e-6
    assert np.abs(run.L_world - L0).max() < 1e-12


def test_rkmk45_reaches_reference_in_far_fewer_steps(hairer):
    reference = exact.free_body_rotation(INERTIA, L0 / INERTIA, 100.0)
    run = simulate(hairer, 100.0, method="rkmk45", rtol=1e-9, L0=L0)
    assert np.linalg.norm(run.R[-1] - reference) < 1e-6
    assert run.n_steps < 10_000 / 10  # rkmk4 at h = 0.01 takes 10 000
    assert run.orthogonality_error.max() < 1e-12


def test_rkmk45_is_more_accurate_at_tighter_tolerance(hairer, reference):
    errors = [
        np.linalg.norm(
            simulate(hairer, T_END, method="rkmk45", rtol=rtol, L0=L0).R[-1] - reference
        )
        for rtol in (1e-5, 1e-9)
    ]
    assert errors[1] < errors[0] / 100


def test_rk4_matrix_drifts_off_so3_where_rkmk4_does_not(hairer):
    matrix = simulate(hairer, 100.0, method="rk4-matrix", h=0.1, L0=L0)
    lie = simulate(hairer, 100.0, method="rkmk4", h=0.1, L0=L0)
    assert matrix.orthogonality_error[-1] > 1e-6
    assert lie.orthogonality_error.max() < 1e-12


def test_rk4_quat_keeps_unit_norm(hairer):
    run = simulate(hairer, 10.0, method="rk4-quat", h=0.1, L0=L0)
    assert np.abs(run.quaternion_norm_error).max() < 1e-15
