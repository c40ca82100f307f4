"""Every tableau satisfies its construction checks and the order conditions it claims."""

import math
from functools import cache

import numpy as np
import pytest
from roundoff import error_bound

from tumble.ode import TABLEAUX, ButcherTableau

ALL = sorted(TABLEAUX.values(), key=lambda tableau: tableau.name)


def _grown(tree):
    """Every rooted tree made by adding one leaf to ``tree`` (a tree is the sorted tuple of
    its root's subtrees)."""
    yield tuple(sorted((*tree, ())))
    for k, child in enumerate(tree):
        for grown in _grown(child):
            yield tuple(sorted((*tree[:k], grown, *tree[k + 1 :])))


@cache
def _trees(order):
    """The rooted trees with ``order`` nodes: 1, 1, 2, 4, 9, 20, 48, 115, 286 of them."""
    if order == 1:
        return ((),)
    return tuple(sorted({grown for tree in _trees(order - 1) for grown in _grown(tree)}))


def _size(tree):
    return 1 + sum(_size(child) for child in tree)


def _density(tree):
    """``γ(t) = |t| Π γ(children)``."""
    return _size(tree) * math.prod(_density(child) for child in tree)


def _stage_weights(A, tree):
    """``Φ_i(t) = Π_children (A Φ(child))_i``: 1 at a leaf, so ``A Φ(leaf) = c``."""
    phi = np.ones(A.shape[0])
    for child in tree:
        phi = phi * (A @ _stage_weights(A, child))
    return phi


def _order_residuals(A, b, order):
    """``|b·Φ(t) − 1/γ(t)|`` over every rooted tree of ``order`` nodes (Butcher 1963)."""
    return [abs(b @ _stage_weights(A, tree) - 1 / _density(tree)) for tree in _trees(order)]


def _order_roundoff(A, b, order):
    """The round-off bound of each residual of :func:`_order_residuals`: a term of ``b·Φ(t)``
    is a product of ``order`` coefficients, each rounded to a double, and passes through at
    most ``order`` sums of ``s`` terms (``A @ Φ`` in the order of the CPU's BLAS kernel) and
    products of children, on terms ``|b|·Φ_|A|(t)``; ``1/γ(t)`` rounds once."""
    chain = order * (len(b) + 2)
    return [
        error_bound(np.abs(b) @ _stage_weights(np.abs(A), tree) + 1 / _density(tree), chain)
        for tree in _trees(order)
    ]


def _worst_order_condition(A, b, order) -> float:
    """The largest order-``order`` residual in units of its round-off bound."""
    return max(
        residual / roundoff
        for residual, roundoff in zip(
            _order_residuals(A, b, order), _order_roundoff(A, b, order), strict=True
        )
    )


def _sum_roundoff(terms):
    """The round-off bound of ``terms.sum(axis=-1)`` against the exact sum of the exact
    coefficients: each rounded to a double once, then n − 1 sums."""
    return error_bound(np.abs(terms).sum(axis=-1), terms.shape[-1])


@pytest.mark.parametrize("tableau", ALL, ids=lambda t: t.name)
def test_rows_of_a_sum_to_c(tableau):
    roundoff = _sum_roundoff(tableau.A) + error_bound(tableau.c, 1)
    assert np.all(np.abs(tableau.A.sum(axis=1) - tableau.c) <= roundoff)


@pytest.mark.parametrize("tableau", ALL, ids=lambda t: t.name)
def test_weights_sum_to_one(tableau):
    assert abs(tableau.b.sum() - 1.0) <= _sum_roundoff(tableau.b)


@pytest.mark.parametrize("tableau", [t for t in ALL if t.adaptive], ids=lambda t: t.name)
def test_error_weights_sum_to_zero(tableau):
    # e = b − b̂: each e_i carries the rounding of b_i and b̂_i as well as its own
    roundoff = (
        _sum_roundoff(tableau.e) + error_bound(np.abs(tableau.b) + np.abs(tableau.b_hat), 2).sum()
    )
    assert abs(tableau.e.sum()) <= roundoff


@pytest.mark.parametrize("tableau", ALL, ids=lambda t: t.name)
def test_propagated_weights_meet_every_order_condition_up_to_claimed_order(tableau):
    # All 200 trees up to order 8 for rk8; its 30-digit coefficients rounded to double leave
    # residuals of at most 1e-15, within the round-off of the terms of each condition.
    for order in range(1, tableau.order + 1):
        worst = _worst_order_condition(tableau.A, tableau.b, order)
        assert worst <= 1, f"order-{order} condition off by {worst:.2f} times its round-off"


@pytest.mark.parametrize("tableau", ALL, ids=lambda t: t.name)
def test_order_is_not_higher_than_claimed(tableau):
    worst = max(_order_residuals(tableau.A, tableau.b, tableau.order + 1))
    assert worst > 1e-6, f"every order-{tableau.order + 1} condition holds ({worst:.1e})"


@pytest.mark.parametrize("tableau", [t for t in ALL if t.adaptive], ids=lambda t: t.name)
def test_embedded_weights_meet_order_conditions(tableau):
    for order in range(1, tableau.order_hat + 1):
        worst = _worst_order_condition(tableau.A, tableau.b_hat, order)
        assert worst <= 1, f"order-{order} condition off by {worst:.2f} times its round-off"


def test_rooted_tree_counts_are_butchers():
    assert [len(_trees(order)) for order in range(1, 10)] == [1, 1, 2, 4, 9, 20, 48, 115, 286]


def test_dopri5_dense_output_matches_step_at_theta_one():
    tableau = TABLEAUX["dopri5"]
    roundoff = _sum_roundoff(tableau.dense) + error_bound(tableau.b, 1)
    assert np.all(np.abs(tableau.dense.sum(axis=1) - tableau.b) <= roundoff)


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


def test_continuous_extension_without_its_order_is_refused():
    with pytest.raises(ValueError, match="dense_order"):
        ButcherTableau(name="bad", c=[0.0], A=[[0.0]], b=[1.0], order=1, dense=[[1.0]])


def test_continuous_extension_that_misses_the_step_at_theta_one_is_refused():
    with pytest.raises(ValueError, match="equal b at θ = 1"):
        ButcherTableau(
            name="bad", c=[0.0], A=[[0.0]], b=[1.0], order=1, dense=[[0.9]], dense_order=1
        )


def test_extra_dense_stages_of_the_wrong_shape_are_refused():
    with pytest.raises(ValueError, match="dense_A must be"):
        ButcherTableau(
            name="bad", c=[0.0], A=[[0.0]], b=[1.0], order=1, dense=[[1.0], [0.0], [0.0]],
            dense_c=[0.5], dense_A=[[0.5]], dense_order=1,
        )  # fmt: skip
