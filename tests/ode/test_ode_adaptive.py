"""Adaptive steppers: accuracy and cost against scipy on Van der Pol, step control."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tumble import solve
from tumble.ode import StepController

MU = 2.0


def van_der_pol(t, y):
    return np.array([y[1], MU * (1 - y[0] ** 2) * y[1] - y[0]])


@pytest.fixture(scope="module")
def reference():
    return solve_ivp(
        van_der_pol, (0, 10), [2, 0], method="DOP853", rtol=1e-13, atol=1e-13, dense_output=True
    )


@pytest.fixture(scope="module")
def scipy_rk45():
    return solve_ivp(van_der_pol, (0, 10), [2, 0], method="RK45", rtol=1e-8, atol=1e-8)


@pytest.fixture(scope="module", params=["rkf45", "dopri5"])
def tumble_run(request):
    return solve(
        van_der_pol, (0, 10), [2, 0], method=request.param, rtol=1e-8, atol=1e-8, dense_output=True
    )


def test_final_error_on_van_der_pol_is_below_1e5(tumble_run, reference):
    assert np.abs(tumble_run.y[:, -1] - reference.y[:, -1]).max() < 1e-5


def test_cost_is_at_most_three_times_scipy_rk45(tumble_run, scipy_rk45):
    assert tumble_run.nfev <= 3 * scipy_rk45.nfev


def test_dense_output_at_midpoint_is_as_accurate(tumble_run, reference):
    assert np.abs(tumble_run.sol(5.0) - reference.sol(5.0)).max() < 1e-5


def test_dopri5_takes_the_same_steps_as_scipy_rk45(scipy_rk45):
    # Same tableau, controller constants and first-step rule: the same steps, up to round-off
    # in the first-step estimate (seen: 2e-9 relative).
    result = solve(van_der_pol, (0, 10), [2, 0], method="dopri5", rtol=1e-8, atol=1e-8)
    assert result.nfev == scipy_rk45.nfev
    np.testing.assert_allclose(result.t, scipy_rk45.t, rtol=1e-7)


def test_adaptive_run_ends_exactly_on_t_end(tumble_run):
    assert tumble_run.t[-1] == 10.0


def test_rejected_step_restarts_from_accepted_state():
    # A huge first step is rejected; the accepted trajectory must still start at y0 and be
    # accurate, which it would not be if the retry began from the rejected result.
    result = solve(lambda t, y: -50 * y, (0, 1), [1.0], method="rkf45", h=0.9, rtol=1e-8)
    assert result.n_rejected >= 1
    assert result.y[0, 0] == 1.0
    assert abs(result.y[0, -1] - np.exp(-50)) < 1e-9


def test_controller_rejects_and_shrinks_on_large_error():
    accepted, h_next = StepController().propose(0.1, 10.0, 4)
    assert not accepted
    assert 0.02 <= h_next < 0.1


def test_controller_growth_is_bounded():
    accepted, h_next = StepController().propose(0.1, 1e-30, 4)
    assert accepted
    assert h_next == pytest.approx(1.0)


def test_controller_does_not_grow_right_after_a_rejection():
    _, h_next = StepController().propose(0.1, 1e-6, 4, after_rejection=True)
    assert h_next == pytest.approx(0.1)


def test_controller_treats_nan_error_as_rejection():
    accepted, h_next = StepController().propose(0.1, float("nan"), 4)
    assert not accepted and h_next == pytest.approx(0.02)


def test_blow_up_stops_with_status_minus_one_naming_t():
    # y' = y², y(0) = 1 blows up at t = 1: the step underflows there, the run must stop.
    result = solve(lambda t, y: y**2, (0, 2), [1.0], method="dopri5")
    assert result.status == -1
    assert "t=0.99" in result.message or "t=1.0" in result.message
    assert 0.99 < result.t[-1] < 1.001  # the last accepted step may straddle the pole


def test_max_steps_stops_adaptive_run():
    result = solve(van_der_pol, (0, 10), [2, 0], method="dopri5", rtol=1e-10, max_steps=5)
    assert result.status == -1
    assert "max_steps=5" in result.message
    assert result.n_steps == 5
