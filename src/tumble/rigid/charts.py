"""Charts: how each family of methods carries the attitude through one step.

For the duration of one step a chart turns the rigid body into an ODE on a vector
``z = (attitude coordinates, x, p, L)`` that the ODE core's
:func:`~tumble.ode.stepper.rk_step` integrates with the method's tableau; then the chart maps
``z`` back to an attitude. Every method is this one mechanism with other data:

=========  ========================  ==========================  ============================
chart      ``z``                     vector field                map back
=========  ========================  ==========================  ============================
matrix     ``(vec R, x, p, L)``      ``Ṙ = R ω̂``                 ``R`` (leaves SO(3))
quat       ``(q, x, p, L)``          ``q̇ = ½ q ⊗ (0, ω)``        ``q`` (normalised at the next
                                                                step's start)
lie        ``(u, x, p, L)``, u(0)=0  ``u̇ = dexp⁻¹_{−u}(ω)``      ``R ← R_n exp(û)``
=========  ========================  ==========================  ============================

with ``ω = I⁻¹ Rᵀ L``, ``ẋ = p/m``, ``ṗ = F`` and ``L̇ = τ`` (world frame). The ``lie`` chart
is Runge–Kutta–Munthe-Kaas (Munthe-Kaas 1998): the right-trivialised equation keeps
``R_{n+1} = R_n exp(û_{n+1})`` on SO(3) to round-off.

A chart is Python data here (pack, map back, vector field) and a compiled twin in
:mod:`tumble.rigid.kernels` (a numba field, map back and record), which a test checks
against this reference to round-off. Adding a family costs one :class:`Chart`, its Python
field, and its numba field.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tumble import so3
from tumble.rigid.body import RigidBody
from tumble.rigid.forces import State, total_load

Field = Callable[[float, np.ndarray], np.ndarray]


class Dynamics:
    """The right-hand side of a body under its continuous loads."""

    def __init__(self, body: RigidBody, loads):
        self.body, self.loads = body, list(loads)
        self.mass, self.inertia_inverse = body.mass, body.inertia_inverse

    def rates(self, t: float, R: np.ndarray, Y: np.ndarray) -> np.ndarray:
        """``(ẋ, ṗ, L̇) = (p/m, F, τ)`` for ``Y = (x, p, L)``, shape (9,)."""
        x, p, L = Y[:3], Y[3:6], Y[6:]
        F, tau = total_load(self.loads, t, State(x, R, p, L), self.mass)
        return np.concatenate([p / self.mass, F, tau])

    def omega(self, R: np.ndarray, L: np.ndarray) -> np.ndarray:
        """``ω_body = I⁻¹ Rᵀ L``."""
        return self.inertia_inverse @ (R.T @ L)


@dataclass(frozen=True)
class Chart:
    """One family's chart (module docstring).

    Attributes
    ----------
    name : str
        ``"matrix"``, ``"quat"`` or ``"lie"``: a method's ``family``.
    size : int
        How many numbers of ``z`` carry the attitude.
    attitude : callable
        ``attitude(R)``: the attitude the chart carries between steps (R, or q).
    matrix : callable
        ``matrix(attitude)``: back to R.
    pack : callable
        ``pack(attitude, Y) -> (z, R_n)``: ``z`` at the start of a step, and the base point
        (the identity for charts that need none).
    advance : callable
        ``advance(z, R_n) -> (attitude, Y)``: the map back after a step.
    read : callable
        ``read(z, R_n) -> (attitude, Y)``: the state a compiled loop left in ``(z, R_n)``
        (its map back is done already).
    field : callable
        ``field(dynamics, correct, R_n) -> f(t, z)``; ``correct`` is False only for the
        uncorrected Lie stages of ``seed-rk4``.
    first_same_as_last : callable, optional
        ``(K, z_new) -> f`` at the new state in its own chart from the last stage ``K[-1]``
        (``f(t + h, z_new)`` in the old chart) of a FSAL tableau; None where the chart
        cannot reuse it.
    """

    name: str
    size: int
    attitude: Callable[[np.ndarray], np.ndarray]
    matrix: Callable[[np.ndarray], np.ndarray]
    pack: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
    advance: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
    read: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
    field: Callable[[Dynamics, bool, np.ndarray], Field]
    first_same_as_last: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None


def _identity(attitude: np.ndarray) -> np.ndarray:
    return attitude


def _matrix_field(dynamics: Dynamics, correct: bool, Rn: np.ndarray) -> Field:
    def f(t: float, z: np.ndarray) -> np.ndarray:
        R = z[:9].reshape(3, 3)
        Rdot = R @ so3.hat(dynamics.omega(R, z[15:]))
        return np.concatenate([Rdot.ravel(), dynamics.rates(t, R, z[9:])])

    return f


def _quat_field(dynamics: Dynamics, correct: bool, Rn: np.ndarray) -> Field:
    def f(t: float, z: np.ndarray) -> np.ndarray:
        R = so3.matrix_from_quat(z[:4] / np.linalg.norm(z[:4]))
        omega = dynamics.omega(R, z[10:])
        qdot = 0.5 * so3.quat_mul(z[:4], np.concatenate([[0.0], omega]))
        return np.concatenate([qdot, dynamics.rates(t, R, z[4:])])

    return f


def _lie_field(dynamics: Dynamics, correct: bool, Rn: np.ndarray) -> Field:
    def f(t: float, z: np.ndarray) -> np.ndarray:
        u = z[:3]
        R = Rn @ so3.exp(u)
        omega = dynamics.omega(R, z[9:])
        udot = so3.dexpinv_apply(-u, omega) if correct else omega
        return np.concatenate([udot, dynamics.rates(t, R, z[3:])])

    return f


def error_norm(error, size, Y_old, Y_new, rtol, atol):
    """The weighted size of a step's error estimate in a chart: what rtol and atol measure.

    The state has four parts, each measured in its own units, and the norm is the largest of
    their root-mean-square norms, so that parts that carry no error (x and p of a free body,
    L without torque: their estimates are exactly zero) cannot dilute the others:

    .. math::

        \\|e\\| = \\max\\Bigl(\\mathrm{rms}_{i < n_a} \\frac{e_i}{r},\\;
        \\max_{g \\in \\{x, p, L\\}} \\mathrm{rms}_{i \\in g}
        \\frac{e_i}{a_i + r \\max(|y_i|, |y^{new}_i|)}\\Bigr)

    * the first ``size`` numbers are the attitude's chart coordinates: for the ``lie`` chart
      the increment ``u`` in radians, measured against ``rtol`` alone (a rotation's natural
      size is one radian, so ``rtol = 1e-8`` asks each step's rotation to be right to 1e-8
      rad); no ``atol`` applies to them, so it can never swamp ``rtol`` there;
    * ``x`` (m), ``p`` (kg m/s) and ``L`` (kg m²/s) against ``atol + rtol·|y|``, Hairer's
      mixed test, with ``atol`` of shape (9,).

    Plain scalar code: the Python steppers call it and the compiled adaptive loops of
    :mod:`tumble.rigid.kernels` compile this same function. A NaN anywhere gives NaN (the step
    is rejected); an error of exactly zero counts as zero even where the scale is zero.
    """
    acc = 0.0
    for i in range(size):
        acc += (error[i] / rtol) ** 2
    norm = math.sqrt(acc / size)
    if norm != norm:  # NaN: the step is rejected
        return norm
    for group in range(3):
        acc = 0.0
        for c in range(3):
            j = 3 * group + c
            e = error[size + j]
            if e != 0.0:
                scale = atol[j] + rtol * max(abs(Y_old[j]), abs(Y_new[j]))
                acc += (e / scale) ** 2
        part = math.sqrt(acc / 3.0)
        if part != part:
            return part
        norm = max(norm, part)
    return norm


def _lie_first_same_as_last(K: np.ndarray, z_new: np.ndarray) -> np.ndarray:
    """The next step's first stage from this step's last (FSAL, Dormand–Prince).

    ``K[-1]`` is ``(u̇, ẏ)`` at ``z_new`` in this step's chart, ``u̇ = dexp⁻¹_{−u}(ω)``; the
    next chart starts at ``u = 0``, where ``u̇ = ω = dexp_{−u}(K[-1]_u)``. The vector part
    is the same."""
    return np.concatenate([so3.dexp(-z_new[:3]) @ K[-1, :3], K[-1, 3:]])


def _frames(shape: tuple[int, ...]) -> np.ndarray:
    """Identity base points for charts that need none, one per leading index."""
    return np.broadcast_to(np.eye(3), (*shape, 3, 3)).copy()


def _lie_pack(R: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``z = (u = 0, Y)`` in the chart at ``R``, and ``R`` as the base point."""
    z = np.zeros((*np.shape(Y)[:-1], 3 + np.shape(Y)[-1]))
    z[..., 3:] = Y
    return z, np.array(R, dtype=float)


# pack and read take one state or a stack of them (leading axes: simulate_batch's bodies),
# hence the ``...`` indexing; advance is the Python reference's, one state at a time.
MATRIX = Chart(
    name="matrix",
    size=9,
    attitude=_identity,
    matrix=_identity,
    pack=lambda R, Y: (
        np.concatenate([np.reshape(R, (*np.shape(R)[:-2], 9)), Y], axis=-1),
        _frames(np.shape(R)[:-2]),
    ),
    advance=lambda z, Rn: (z[:9].reshape(3, 3).copy(), z[9:].copy()),
    read=lambda z, Rn: (z[..., :9].reshape((*z.shape[:-1], 3, 3)).copy(), z[..., 9:].copy()),
    field=_matrix_field,
)
# quat: the step starts from q/|q| and ends with q as the tableau left it, so the record
# keeps |q| − 1 before normalising (matrix_from_quat normalises).
QUAT = Chart(
    name="quat",
    size=4,
    attitude=so3.quat_from_matrix,
    matrix=so3.matrix_from_quat,
    pack=lambda q, Y: (
        np.concatenate([q / np.linalg.norm(q, axis=-1, keepdims=True), Y], axis=-1),
        _frames(np.shape(q)[:-1]),
    ),
    advance=lambda z, Rn: (z[:4].copy(), z[4:].copy()),
    read=lambda z, Rn: (z[..., :4].copy(), z[..., 4:].copy()),
    field=_quat_field,
)
LIE = Chart(
    name="lie",
    size=3,
    attitude=_identity,
    matrix=_identity,
    pack=_lie_pack,
    advance=lambda z, Rn: (Rn @ so3.exp(z[:3]), z[3:].copy()),
    read=lambda z, Rn: (Rn.copy(), z[..., 3:].copy()),
    field=_lie_field,
    first_same_as_last=_lie_first_same_as_last,
)

CHARTS: dict[str, Chart] = {chart.name: chart for chart in (MATRIX, QUAT, LIE)}
"""Every chart by name: a method's ``family`` names one."""
