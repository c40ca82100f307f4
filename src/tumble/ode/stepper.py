"""One explicit Runge–Kutta step for every tableau."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from tumble.ode.tableaux import ButcherTableau

RHS = Callable[[float, np.ndarray], np.ndarray]


def rk_step(
    fun: RHS,
    t: float,
    y: np.ndarray,
    f: np.ndarray,
    h: float,
    tableau: ButcherTableau,
    K: np.ndarray,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Take one explicit Runge–Kutta step.

    .. math::

        k_1 = f(t, y), \\quad
        k_i = f\\Bigl(t + c_i h, y + h \\sum_{j<i} a_{ij} k_j\\Bigr), \\quad
        y_{n+1} = y + h \\sum_i b_i k_i.

    Parameters
    ----------
    fun : callable
        Right-hand side ``fun(t, y) -> ndarray, shape (n,)``.
    t : float
        Time at the start of the step.
    y : ndarray, shape (n,)
        State at ``t``.
    f : ndarray, shape (n,)
        ``fun(t, y)``, already known (the first stage is never recomputed).
    h : float
        Step size.
    tableau : ButcherTableau
        The method.
    K : ndarray, shape (s, n)
        Work array, overwritten with the stages ``k_i``.

    Returns
    -------
    y_new : ndarray, shape (n,)
        The propagated solution at ``t + h``.
    error : ndarray, shape (n,) or None
        The local error estimate ``h Σ (b_i − b̂_i) k_i`` for an embedded pair, else None.
        For a FSAL tableau ``K[-1]`` then holds ``fun(t + h, y_new)``.
    """
    K[0] = f
    for i, (row, c) in enumerate(tableau.rows, start=1):
        K[i] = fun(t + c * h, y + h * (row @ K[:i]))
    y_new = y + h * (tableau.b @ K)
    error = None if tableau.e is None else h * (tableau.e @ K)
    return y_new, error
