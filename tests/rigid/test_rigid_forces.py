"""Loads: exact momentum changes, the parabola, torques, events."""

import numpy as np
import pytest
from roundoff import error_bound

from tumble.rigid import Force, Gravity, Impulse, RigidBody, Torque, simulate

BODY = RigidBody(2.0, [1.0, 2.0, 2.5])


def test_impulse_changes_velocity_by_j_over_m_exactly():
    J, point = np.array([0.3, -0.2, 1.0]), np.array([0.5, 0.1, -0.2])
    run = simulate(BODY, 1.0, h=0.1, forces=[Impulse(point, J, time=0.0)])
    # J / m and r × J (a b − c d) from zero, with no torque after: the same IEEE operations
    # here and in the kernel, so the same bits on any machine
    np.testing.assert_array_equal(run.v[0], J / BODY.mass)
    np.testing.assert_array_equal(run.L_world[-1], np.cross(point, J))


def test_impulse_mid_run_lands_a_step_on_its_time():
    J = np.array([1.0, 0.0, 0.0])
    run = simulate(BODY, 1.0, h=0.1, x0=(0, 0, 0), forces=[Impulse((0, 1, 0), J, time=0.35)])
    assert 0.35 in run.t
    before = run.t < 0.35
    np.testing.assert_array_equal(run.v[before], 0.0)
    np.testing.assert_allclose(run.v[~before], np.broadcast_to(J / BODY.mass, (8, 3)), atol=0)
    np.testing.assert_allclose(run.L_world[-1], np.cross([0, 1, 0], J), atol=0)


def test_impulse_arm_is_measured_from_the_current_centre_of_mass():
    J = np.array([0.0, 0.0, 1.0])
    run = simulate(BODY, 2.0, h=0.1, v0=(1, 0, 0), forces=[Impulse((1.0, 1.0, 0.0), J, time=1.0)])
    # At t = 1 the centre of mass is at (1, 0, 0): the arm is (0, 1, 0), up to x's ten steps
    # of two roundings at |x| ≤ 1 and the arm's own.
    np.testing.assert_allclose(run.L_world[-1], np.cross([0.0, 1.0, 0.0], J),
                               atol=error_bound(1.0, 22))  # fmt: skip


@pytest.mark.parametrize("method", ["rkmk4", "rk4-quat", "euler"])
def test_gravity_centre_of_mass_follows_the_parabola(method):
    g = np.array([0.0, 0.0, -9.81])
    x0, v0 = np.array([1.0, 2.0, 3.0]), np.array([3.0, 0.0, 4.0])
    run = simulate(BODY, 2.0, method=method, h=0.01, x0=x0, v0=v0, forces=[Gravity(g)])
    expected = x0 + np.outer(run.t, v0) + 0.5 * np.outer(run.t**2, g)
    # Euler's position lags by h/2 · g t (first order); RK4 is exact for a parabola.
    tol = 0.1 if method == "euler" else 1e-11
    np.testing.assert_allclose(run.x, expected, atol=tol)


def test_constant_torque_grows_angular_momentum_linearly():
    tau = np.array([0.1, -0.2, 0.3])
    run = simulate(BODY, 1.0, h=0.01, L0=(1, 0, 0), forces=[Torque(tau)])
    # L += h τ: 100 steps of two roundings at |L| ≤ 1.1, and t τ + L0's own two
    bound = error_bound(1.1, 2 * 100) + error_bound(1.1, 2)
    np.testing.assert_allclose(run.L_world, [1, 0, 0] + np.outer(run.t, tau), atol=bound)


def test_force_at_a_body_point_gives_torque_r_cross_f():
    F, point = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0])
    run = simulate(BODY, 1e-3, h=1e-3, forces=[Force(F, point=point)])
    # Over one tiny step from rest, ΔL ≈ (R r × F) h with R = I.
    np.testing.assert_allclose(run.L_world[-1] / 1e-3, np.cross(point, F), rtol=1e-6)
    np.testing.assert_allclose(run.v[-1] * BODY.mass / 1e-3, F, rtol=1e-12)


def test_terminal_event_finds_the_ground():
    def ground(t, state):
        return state.x[2]

    ground.terminal, ground.direction = True, -1
    run = simulate(BODY, 10.0, h=0.05, x0=(0, 0, 10), forces=[Gravity()], events=[ground])
    assert run.status == 1
    assert run.t[-1] == pytest.approx(np.sqrt(2 * 10 / 9.81), abs=1e-9)
    assert run.t_events[0][0] == pytest.approx(np.sqrt(2 * 10 / 9.81), abs=1e-9)
    assert run.x[-1, 2] == pytest.approx(0.0, abs=1e-9)


def test_nan_from_a_user_force_stops_with_the_time():
    def force(t, state):
        return (np.nan, 0.0, 0.0) if t >= 0.5 else (1.0, 0.0, 0.0)

    run = simulate(BODY, 1.0, h=0.1, forces=[Force(force)])
    assert run.status == -1 and not run.success
    assert "non-finite" in run.message and "t=0.5" in run.message
    assert np.all(np.isfinite(run.x))
    assert run.t[-1] == pytest.approx(0.4)


def test_exceptions_from_a_user_force_come_through_unchanged():
    def force(t, state):
        raise KeyError("user bug")

    with pytest.raises(KeyError, match="user bug"):
        simulate(BODY, 1.0, h=0.1, forces=[Force(force)])
