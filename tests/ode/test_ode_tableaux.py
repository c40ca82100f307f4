"""Every tableau satisfies its construction checks and the order conditions it claims."""

import numpy as np
import pytest

from tumble.ode import TABLEAUX, ButcherTableau

ALL = sorted(TABLEAUX.values(), key=lambda tableau: tableau.name)


def _order_conditions(A, b, c):
    """Butcher's order conditions up to order 4, as (order, lhs, rhs)."""
    return [
        (1, b.sum(), 1.0),
        (2, b @ c, 1 / 2),
        (3, b @ c**2, 1 / 3),
        (3, b @ A @ c, 1 / 6),
        (4, b @ c**3, 1 / 4),
        (4, b @ (c * (A @ c)), 1 / 8),
        (4, b @ A @ c**2, 1 / 12),
        (4, b @ A @ A @ c, 1 / 24),
    ]


@pytest.mark.parametrize("tableau", ALL, ids=lambda t: t.name)
def test_rows_of_a_sum_to_c(tableau):
    np.testing.assert_allclose(tableau.A.sum(axis=1), tableau.c, atol=1e-15)


@pytest.mark.parametrize("tableau", ALL, ids=lambda t: t.name)
def test_weights_sum_to_one(tableau):
    assert tableau.b.sum() == pytest.approx(1.0, abs=1e-15)


@pytest.mark.parametrize("tableau", [t for t in ALL if t.adaptive], ids=lambda t: t.name)
def test_error_weights_sum_to_zero(tableau):
    assert tableau.e.sum() == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("tableau", ALL, ids=lambda t: t.name)
def test_propagated_weights_meet_order_conditions_up_to_claimed_order(tableau):
    for order, lhs, rhs in _order_conditions(tableau.A, tableau.b, tableau.c):
        if order <= tableau.order:
            assert lhs == pytest.approx(rhs, abs=1e-14), f"order-{order} condition"


@pytest.mark.parametrize("tableau", ALL, ids=lambda t: t.name)
def test_order_is_not_higher_than_claimed_below_five(tableau):
    failing = [
        order
        for order, lhs, rhs in _order_conditions(tableau.A, tableau.b, tableau.c)
        if abs(lhs - rhs) > 1e-12
    ]
    if tableau.order < 4:
        assert min(failing) == tableau.order + 1


@pytest.mark.parametrize("tableau", [t for t in ALL if t.adaptive], ids=lambda t: t.name)
def test_embedded_weights_meet_order_conditions(tableau):
    for order, lhs, rhs in _order_conditions(tableau.A, tableau.b_hat, tableau.c):
        if order <= min(tableau.order_hat, 4):
            assert lhs == pytest.approx(rhs, abs=1e-14), f"order-{order} condition"


def test_dopri5_dense_output_matches_step_at_theta_one():
    tableau = TABLEAUX["dopri5"]
    np.testing.assert_allclose(tableau.dense.sum(axis=1), tableau.b, atol=1e-14)


def test_tableau_whose_rows_do_not_sum_to_c_is_refused():
    with pytest.raises(ValueError, match="rows of A must sum to c"):
        ButcherTableau(name="bad", c=[0, 0.4], A=[[0, 0], [0.5, 0]], b=[0.5, 0.5], order=2)


def test_tableau_whose_weights_do_not_sum_to_one_is_refused():
    with pytest.raises(ValueError, match="must sum to 1"):
        ButcherTableau(name="bad", c=[0, 1], A=[[0, 0], [1, 0]], b=[0.5, 0.6], order=2)


def test_tableau_whose_error_weights_do_not_sum_to_zero_is_refused():
    with pytest.raises(ValueError, match="sum to 0"):
        ButcherTableau(
            name="bad", c=[0, 1], A=[[0, 0], [1, 0]], b=[0.5, 0.5], order=2, b_hat=[1.0, 0.1]
        )


def test_implicit_tableau_is_refused():
    with pytest.raises(ValueError, match="lower-triangular"):
        ButcherTableau(name="bad", c=[0.5], A=[[0.5]], b=[1.0], order=2)


def test_tableau_coefficients_are_read_only():
    with pytest.raises(ValueError, match="read-only"):
        TABLEAUX["rk4"].b[0] = 1.0
