"""Dense output: a polynomial per step, and the piecewise solution they make together.

Every step's interpolant has the form

.. math::

    y(t_n + \\theta h) = y_n + h \\sum_{j=1}^{q} Q_j \\theta^j, \\qquad 0 \\le \\theta \\le 1,

where ``Q`` comes from the tableau's own continuous extension (``Q = Kᵀ P``; DOP853's order-7
one adds three stages) or, for tableaux without one, from the cubic Hermite interpolant through
``(y_n, f_n)`` and ``(y_{n+1}, f_{n+1})``. :attr:`ButcherTableau.interpolant_order
<tumble.ode.tableaux.ButcherTableau.interpolant_order>` states each one's order.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from tumble.ode.tableaux import ButcherTableau


def hermite_coefficients(
    y0: np.ndarray, y1: np.ndarray, f0: np.ndarray, f1: np.ndarray, h: float
) -> np.ndarray:
    """Coefficients ``Q``, shape (n, 3), of the cubic Hermite interpolant on one step.

    .. math::

        Q_1 = f_0,\\quad Q_2 = 3\\Delta - 2 f_0 - f_1,\\quad Q_3 = f_0 + f_1 - 2\\Delta,
        \\qquad \\Delta = (y_1 - y_0)/h.
    """
    delta = (y1 - y0) / h
    return np.stack([f0, 3 * delta - 2 * f0 - f1, f0 + f1 - 2 * delta], axis=1)


def step_coefficients(
    tableau: ButcherTableau,
    K: np.ndarray,
    y0: np.ndarray,
    y1: np.ndarray,
    f1: np.ndarray,
    h: float,
    fun: Callable[[float, np.ndarray], np.ndarray] | None = None,
    t0: float = 0.0,
) -> np.ndarray:
    """The interpolant's coefficients ``Q`` for one step ``[t0, t0 + h]``, shape (n, q).

    A tableau with extra dense-output stages (DOP853's three) evaluates ``fun`` for them here,
    so only a run that asks for dense output or events pays for them.
    """
    if tableau.dense is None:
        return hermite_coefficients(y0, y1, K[0], f1, h)
    if tableau.dense_A is None or tableau.dense_c is None:
        if tableau.dense.shape[0] == tableau.stages + 1:  # the stages and f(t + h, y_{n+1})
            return K.T @ tableau.dense[:-1] + np.outer(f1, tableau.dense[-1])
        return K.T @ tableau.dense
    if fun is None:
        raise ValueError(f"{tableau.name}'s dense output needs the right-hand side fun")
    s = tableau.stages
    extended = np.empty((s + 1 + tableau.extra_stages, y0.size))
    extended[:s], extended[s] = K[:s], f1
    for j, (row, c) in enumerate(zip(tableau.dense_A, tableau.dense_c, strict=True)):
        i = s + 1 + j
        extended[i] = fun(t0 + c * h, y0 + h * (row[:i] @ extended[:i]))
    return extended.T @ tableau.dense


class StepInterpolant:
    """The solution on one step ``[t_old, t_old + h]`` as a polynomial in ``θ``."""

    def __init__(self, t_old: float, h: float, y_old: np.ndarray, Q: np.ndarray):
        self.t_old, self.h, self.y_old, self.Q = t_old, h, y_old, Q

    def __call__(self, t: float | np.ndarray) -> np.ndarray:
        """Evaluate at ``t`` (scalar → (n,), array of m times → (n, m))."""
        theta = (np.asarray(t, dtype=float) - self.t_old) / self.h
        powers = theta[..., None] ** np.arange(1, self.Q.shape[1] + 1)
        if theta.ndim == 0:
            return self.y_old + self.h * (self.Q @ powers)
        return self.y_old[:, None] + self.h * (self.Q @ powers.T)


class DenseOutput:
    """The continuous solution over the whole run, like scipy's ``OdeSolution``.

    Parameters
    ----------
    ts : ndarray, shape (m + 1,)
        Step boundaries, increasing.
    interpolants : list of StepInterpolant
        One per step.

    Examples
    --------
    >>> import numpy as np
    >>> from tumble import solve
    >>> result = solve(lambda t, y: -y, (0.0, 1.0), [1.0], method="dopri5", dense_output=True)
    >>> bool(abs(result.sol(0.5)[0] - np.exp(-0.5)) < 1e-6)
    True
    """

    def __init__(self, ts: Sequence[float] | np.ndarray, interpolants: Sequence[Callable]):
        self.ts = np.asarray(ts, dtype=float)
        self.interpolants = list(interpolants)
        self.t_min, self.t_max = float(self.ts[0]), float(self.ts[-1])

    def steps(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(t, index)``: the times as an array, and the step whose interpolant holds each.

        Raises
        ------
        ValueError
            For a time outside the solved interval.
        """
        t_array = np.asarray(t, dtype=float)
        if np.any(t_array < self.t_min) or np.any(t_array > self.t_max):
            raise ValueError(
                f"t={t!r} is outside the solved interval [{self.t_min}, {self.t_max}]"
            )
        index = np.clip(np.searchsorted(self.ts, t_array, side="right") - 1, 0, len(self) - 1)
        return t_array, index

    def __call__(self, t: float | np.ndarray) -> np.ndarray:
        """Evaluate the solution at ``t``: scalar → (n,), array of m times → (n, m)."""
        t_array, index = self.steps(t)
        if t_array.ndim == 0:
            return self.interpolants[int(index)](float(t_array))
        columns = [
            self.interpolants[i](float(s))
            for i, s in zip(index.ravel(), t_array.ravel(), strict=True)
        ]
        return np.stack(columns, axis=-1).reshape((-1, *t_array.shape))

    def __len__(self) -> int:
        return len(self.interpolants)
