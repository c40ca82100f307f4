"""Fixed-step runs: where the steps land, dense output, failure as status."""

import numpy as np
import pytest
from roundoff import sum_bound

from tumble import solve
from tumble.ode.control import fixed_step_count


def test_step_that_divides_the_span_gives_that_many_steps():
    result = solve(lambda t, y: y, (0, 1), [1.0], h=0.1)
    assert len(result.t) == 11
    assert result.t[-1] == 1.0


def test_last_step_is_shortened_to_land_on_t_end():
    result = solve(lambda t, y: y, (0, 1), [1.0], h=0.3)
    np.testing.assert_allclose(result.t, [0, 0.3, 0.6, 0.9, 1.0], atol=1e-15)
    assert result.t[-1] == 1.0


@pytest.mark.parametrize(
    ("span", "h", "count"),
    [((0, 1), 0.1, 10), ((0, 1), 0.3, 4), ((0, 100), 0.01, 10000), ((0, 1), 2.0, 1)],
)
def test_fixed_step_count(span, h, count):
    assert fixed_step_count(*span, h) == count


def test_nfev_counts_four_per_rk4_step_plus_the_start():
    result = solve(lambda t, y: -y, (0, 1), [1.0], h=0.1)
    assert result.nfev == 10 * 4 + 1


def test_hermite_dense_output_interpolates_the_steps_exactly():
    h = 0.25
    result = solve(lambda t, y: np.cos(t) * y, (0, 2), [1.0], h=h, dense_output=True)
    # Every node but the last is a step's θ = 0, where y_0 + h Σ_j Q_j 0^j adds an exact zero.
    np.testing.assert_array_equal(result.sol(result.t[:-1]), result.y[:, :-1])
    # The last is θ = 1 of the last step: y_0 + h (Q_1 + Q_2 + Q_3), whose terms are
    # f_0, 3Δ − 2 f_0 − f_1 and f_0 + f_1 − 2Δ (|f| = |cos t y| ≤ |y|, Δ = (y_1 − y_0) / h),
    # 4|f_0| + 2|f_1| + 5|Δ| in all, rounded in chains of 3 (each Q_j), 3 (their sum) and 3
    # (h·, y_0 +, and Δ's own).
    terms = np.abs(result.y).max() * (2 + 11 * h)
    assert abs(result.sol(result.t[-1])[0] - result.y[0, -1]) <= sum_bound(terms, 9)


def test_hermite_dense_output_between_steps_is_fourth_order_accurate():
    # Cubic Hermite interpolation of an O(h^4) solution: error O(h^4) between the nodes.
    exact = np.exp(np.sin(0.3))
    errors = []
    for h in (0.1, 0.05):
        result = solve(lambda t, y: np.cos(t) * y, (0, 1), [1.0], h=h, dense_output=True)
        errors.append(abs(result.sol(0.3 + h / 2)[0] - np.exp(np.sin(0.3 + h / 2))))
    assert errors[1] < errors[0] / 10
    assert errors[1] < 1e-7 * exact


def test_dense_output_outside_the_run_is_refused():
    result = solve(lambda t, y: -y, (0, 1), [1.0], h=0.1, dense_output=True)
    with pytest.raises(ValueError, match="outside the solved interval"):
        result.sol(1.5)


def test_nan_from_right_hand_side_stops_fixed_run_with_time():
    def fun(t, y):
        return np.array([np.nan]) if t > 0.5 else -y

    result = solve(fun, (0, 1), [1.0], h=0.1)
    assert result.status == -1
    assert not result.success
    assert "non-finite" in result.message and "t=0.6" in result.message
    assert np.all(np.isfinite(result.y))
    assert result.t[-1] == pytest.approx(0.5)


def test_nan_from_right_hand_side_stops_adaptive_run_with_time():
    def fun(t, y):
        return np.array([np.inf]) if t > 0.5 else -y

    result = solve(fun, (0, 1), [1.0], method="dopri5")
    assert result.status == -1
    assert "non-finite" in result.message
    assert 0.4 < result.t[-1] <= 0.5


def test_max_steps_stops_fixed_run():
    result = solve(lambda t, y: -y, (0, 1), [1.0], h=0.01, max_steps=10)
    assert result.status == -1 and "max_steps=10" in result.message
    assert result.t[-1] == pytest.approx(0.1)


def test_wrong_shape_from_right_hand_side_is_an_error():
    with pytest.raises(ValueError, match="expected \\(2,\\)"):
        solve(lambda t, y: [1.0], (0, 1), [1.0, 2.0], h=0.1)


def test_exceptions_from_the_users_function_come_through_unchanged():
    def fun(t, y):
        raise KeyError("mine")

    with pytest.raises(KeyError, match="mine"):
        solve(fun, (0, 1), [1.0], h=0.1)
