"""Every rigid-body method's measured order, and the seed 002 figures (SPEC §1, §4)."""

import numpy as np
import pytest
from rigid_roundoff import invariant_bound
from roundoff import error_bound

from tumble import exact
from tumble.rigid import METHODS, RigidBody, simulate

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


FIXED = [
    name for name, method in METHODS.items() if not method.adaptive and method.flow != "exact"
]
"""The methods with an order in h on a free body (on the exact flow the error is round-off
without loads: test_rigid_geometric measures strang's and yoshida4's orders with a load)."""


def order_steps(order: int) -> list[int]:
    """Step counts over T = 10 s where a method of ``order`` shows its slope: above round-off
    (1e-15) and past the pre-asymptotic range. Order 8 at h = 0.5 … 0.2: errors 7.7e-10 …
    4.8e-13, slope 8.03 (from h = 1 it reads 8.3–8.5)."""
    if order == 1:
        return [1000, 2000, 4000, 8000]
    if order <= 4:
        return [100, 200, 400, 800]
    return [20, 25, 32, 40, 50]


FINEST_ERROR = {1: 5e-2, 2: 3e-3, 3: 6e-6, 4: 4e-7, 8: 2e-12}
"""Bounds on ‖R − R_exact‖_F at the finest step, about 3× above the largest measured for each
order: euler 1.6e-2, lie-euler 6.5e-3; seed-rk4 6.3e-5, split-axes 3.7e-5, midpoint-lp
4.6e-4, dmv 8.9e-4; cg3 1.9e-6; rk4-matrix 1.2e-8, rk4-quat 1.7e-9, rkmk4 3.6e-10,
split-axes4 1.3e-7, cg4 7.5e-9; rkmk8 4.8e-13."""


# The adaptive method has no fixed h to fit a slope against: its tolerance is tested below.
@pytest.mark.parametrize("method", FIXED)
def test_method_has_its_declared_order_on_asymmetric_body(hairer, reference, method):
    order = METHODS[method].order
    h = T_END / np.array(order_steps(order))
    errors = [
        np.linalg.norm(simulate(hairer, T_END, method=method, h=hi, L0=L0).R[-1] - reference)
        for hi in h
    ]
    slope = exact.observed_order(h, errors)
    assert abs(slope - order) < 0.2, f"{method}: measured order {slope:.3f}, claimed {order}"
    assert errors[-1] < FINEST_ERROR[order], f"{method}: {errors[-1]:.2e} at h = {h[-1]}"


@pytest.mark.parametrize("method", list(METHODS))
def test_method_keeps_what_it_declares_on_a_torque_free_body(hairer, method):
    # T = 20 s at h = 0.1 (rtol 1e-6 for the adaptive one): L is stepped linearly, so with no
    # torque it is constant to round-off for every method; the lie and quat charts and the
    # split family stay on SO(3) to round-off, the matrix chart visibly leaves it at this
    # step (≥ 1e-9); midpoint-lp and dmv keep the energy to round-off.
    spec = METHODS[method]
    step = {"rtol": 1e-6} if spec.adaptive else {"h": 0.1}
    run = simulate(hairer, 20.0, method=method, L0=L0, **step)
    assert "angular_momentum" in spec.conserves
    assert np.abs(run.L_world - L0).max() < 1e-13  # L += h·0 is exact: 0 measured everywhere
    walk = invariant_bound(method, run.n_steps)  # 1.2e-13 … 2.5e-13
    if "orthogonality" in spec.conserves:
        assert run.orthogonality_error.max() < 1e-12  # above the walk (measured ≤ 7.9e-15)
    else:
        assert run.orthogonality_error[-1] > 1e-9
    energy = np.abs(run.energy_error / run.energy[0]).max()
    if "energy" in spec.conserves:
        assert energy < walk  # measured ≤ 2.7e-15
    elif spec.order <= 4:
        assert energy > 1e-12  # the others change it visibly at this step (rkmk8: 3e-15)


def test_rkmk4_halving_h_divides_error_by_16(hairer, reference):
    # SPEC §1: on this body halving h divides the RKMK4 error by 16, not 4 (seed 002's RK4).
    errors = [
        np.linalg.norm(simulate(hairer, T_END, h=h, L0=L0).R[-1] - reference) for h in (0.02, 0.01)
    ]
    assert 13 < errors[0] / errors[1] < 19


def test_rkmk8_reaches_round_off_level_errors_in_50_steps(hairer, reference):
    # h = 0.2 over 10 s: measured 4.8e-13; bound with a 4x margin. rkmk4 at this h: 2.3e-5.
    run = simulate(hairer, T_END, method="rkmk8", h=0.2, L0=L0)
    assert np.linalg.norm(run.R[-1] - reference) < 2e-12  # truncation, far above round-off
    assert run.orthogonality_error.max() < invariant_bound("rkmk8", 50)  # measured 1.8e-15


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
    # the walk of 10 steps' roundings, and the closed form's (measured 1.1e-16)
    bound = 2 * invariant_bound("lie-euler", 10) + error_bound(3.0, 10)
    np.testing.assert_allclose(run.R, exact.sphere(run.t), atol=bound)
    assert len(run.t) == 11


def test_rkmk4_long_run_stays_on_so3_and_conserves(hairer):
    # h = 0.01, T = 100: ‖RᵀR − I‖ within the walk of 10⁴ steps' round-off (1.1e-12; measured
    # 1.2e-14), energy to 1e-6, L_world to 1e-12 (L += h·0 is exact).
    run = simulate(hairer, 100.0, h=0.01, L0=L0)
    assert run.orthogonality_error.max() < invariant_bound("rkmk4", run.n_steps)
    energy = run.energy
    assert np.abs(energy / energy[0] - 1).max() < 1e-6
    assert np.abs(run.L_world - L0).max() < 1e-12


def test_rkmk45_reaches_reference_in_far_fewer_steps(hairer):
    reference = exact.free_body_rotation(INERTIA, L0 / INERTIA, 100.0)
    # rtol bounds the run's attitude error (error per unit step): 1e-6 asked, < 1e-6 got
    run = simulate(hairer, 100.0, method="rkmk45", rtol=1e-6, L0=L0)
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


@pytest.mark.parametrize("compiled", [False, True])
def test_quaternion_norm_error_is_what_the_renormalisation_removes(hairer, compiled):
    # Issue 18: |q| − 1 was recorded after q ← q/|q| and always read 1e-16. It is now the
    # step's own departure: one RK4 step from a unit q, by hand, gives the first one.
    run = simulate(hairer, 10.0, method="rk4-quat", h=0.1, L0=L0, compiled=compiled)
    from tumble import so3
    from tumble.ode.stepper import rk_step
    from tumble.ode.tableaux import RK4

    def f(t, q):
        omega = (so3.matrix_from_quat(q).T @ L0) / INERTIA
        return 0.5 * so3.quat_mul(q, np.concatenate([[0.0], omega]))

    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    q1, _ = rk_step(f, 0.0, q0, f(0.0, q0), 0.1, RK4, np.empty((4, 4)))
    assert run.quaternion_norm_error[0] == 0.0
    assert run.quaternion_norm_error[1] == pytest.approx(np.linalg.norm(q1) - 1, rel=1e-9)
    assert 1e-9 < np.abs(run.quaternion_norm_error[1:]).max() < 1e-5
    # q/|q| (|q| through BLAS on the reference path): 6 roundings from a unit vector, and 6
    # more for the norm taken here. R is made from that q at every record, so RᵀR − I does
    # not accumulate: 2 ||q|² − 1| and the rounding of R's and RᵀR's 3-term sums of products.
    np.testing.assert_allclose(np.linalg.norm(run.q, axis=1), 1.0, atol=error_bound(1.0, 12))
    assert run.orthogonality_error.max() < 2 * error_bound(1.0, 24) + error_bound(3.0, 8)
