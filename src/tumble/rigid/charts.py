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
:mod:`tumble.rigid._compiled` (a numba field, map back and record), which a test checks
against this reference to round-off. Adding a chart family costs one :class:`Chart`, its
Python field, its numba field, and its :class:`~tumble.rigid.families.ChartFamily` in
:data:`tumble.rigid.methods.FAMILIES`.
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
        ``"matrix"``, ``"quat"`` or ``"lie"``: the name of the family that steps in it
        (:data:`tumble.rigid.methods.FAMILIES`).
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
    quaternion : bool
        Whether the attitude carried is a quaternion, kept as the run's ``q`` record
        (:attr:`Trajectory.q_raw <tumble.rigid.trajectory.Trajectory.q_raw>`, ``|q| − 1``
        before normalising).
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
    quaternion: bool = False


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


SEPARATRIX_SHARE = 0.1
"""The share of ``rtol |Δ|`` by which one step may (by its error estimate) change the distance
to the separatrix ``Δ`` (:func:`error_norm`). Per step, not per unit time as the other
parts: the embedded estimate of a change of ``Δ`` overstates the accepted solution's by
about ``1/(h λ)`` (it falls as h⁵, the accepted change of Δ as h⁶; measured 20–400× near a
flip), so held per unit time it would cost the T-handle's flipping spin 2.7× the steps for
no gain. A tenth, per step, keeps attitudes and flip times near the separatrix within 10× of
scipy RK45 at equal rtol, or of the problem's round-off floor, from 1e-3 to 1e-8 off the
middle axis (all but ``rkmk45``'s flips at 1e-3, rtol 1e-8: 15×), at 1.2–1.9× the steps on
the T-handle's flipping spin (docs/rigid-body.md)."""

ROUNDING = 2.220446049250313e-16
"""One ulp at 1 (``np.finfo(float).eps``): ``Δ = m·D m`` is not known better than
``ROUNDING |m| |D m|``, and no step is asked to keep it better than that."""


def separatrix_form(inertia: np.ndarray) -> np.ndarray:
    """``D = 1 − I₂ I⁻¹``, shape (3, 3), body frame, with ``I₂`` the middle principal moment.

    ``Δ = m·D m = |m|² − 2 E I₂`` for the body momentum ``m = Rᵀ L`` is the signed distance
    of the motion from the separatrix, where a spin about the middle axis turns over
    (``Δ = 0``); the free body keeps it constant. Built in the principal frame, so that the
    middle axis' entry is an exact zero and ``Δ`` near that axis keeps the relative accuracy
    of the small components.

    Examples
    --------
    >>> separatrix_form(np.diag([3.0, 2.0, 1.5])).diagonal().round(4)
    array([ 0.3333,  0.    , -0.3333])
    """
    moments, axes = np.linalg.eigh(np.asarray(inertia, dtype=float))
    return (axes * (1.0 - moments[1] / moments)) @ axes.T


def error_norm(error, z, z_new, Rn, rtol, atol, separatrix, share):
    """The weighted size of a ``lie``-chart step's error: what rtol and atol measure.

    ``z = (0, x, p, L)`` and ``z_new = (u, x, p, L)`` are the step's start and end in the chart
    at ``R_n`` (``R = R_n exp(û)``), ``error`` the tableau's estimate of ``z_new``'s error, and
    ``share`` the step's share ``h/T`` of the run (1 without :attr:`Control.horizon
    <tumble.ode.driver.Control.horizon>`), by which the caller divides the norm (error per
    unit step). The norm is the largest of four parts (each a root mean square, so that a
    part without error cannot dilute another):

    * the increment ``u`` in radians against ``rtol`` alone (a rotation's natural size is one
      radian): the attitude, its phase about ``L`` included;
    * ``x`` (m) and ``p`` (kg m/s) against ``atol + rtol |y|``, component by component;
    * the body momentum ``m = Rᵀ L`` (kg m²/s) against ``atol[6:] + rtol |m|``, component by
      component in the body frame, with ``δm = m × e + Rᵀ e_L`` and ``e = dexp_{−u}(e_u)`` the
      attitude's error in the body frame: the small components of a spin near a principal
      axis are held to their own size, and ``atol`` bounds each in kg m²/s;
    * on a step without torque (``L`` unchanged), the distance to the separatrix
      ``Δ = m·D m`` (:func:`separatrix_form`), which the free body keeps: the estimated change
      ``δΔ = 2 (D m)·δm`` against :data:`SEPARATRIX_SHARE` ``· rtol |Δ|`` per step, or
      ``Δ``'s own rounding (:data:`ROUNDING`). Near the separatrix ``Δ`` is tiny beside
      ``|m|²``; its relative error sets the flip times, and through them the attitude.

    Plain scalar code: the Python stepper calls it and the compiled adaptive loop of
    :mod:`tumble.rigid._compiled` compiles this same function and its helpers
    (:data:`NORM_HELPERS`). A NaN anywhere gives NaN (the step is rejected); an error of
    exactly zero counts as zero.
    """
    e0, e1, e2 = error[0], error[1], error[2]
    norm = math.sqrt((e0 * e0 + e1 * e1 + e2 * e2) / 3.0) / rtol
    for j in (3, 6):  # x, p
        acc = _mixed(error[j], atol[j - 3], rtol, z[j], z_new[j])
        acc += _mixed(error[j + 1], atol[j - 2], rtol, z[j + 1], z_new[j + 1])
        acc += _mixed(error[j + 2], atol[j - 1], rtol, z[j + 2], z_new[j + 2])
        norm = _largest(norm, math.sqrt(acc / 3.0))
    u0, u1, u2 = z_new[0], z_new[1], z_new[2]
    a, b, c = _exp_coefficients(u0 * u0 + u1 * u1 + u2 * u2)
    m0, m1, m2 = _transpose_apply(Rn, z[9], z[10], z[11])
    n0, n1, n2 = _transpose_apply(Rn, z_new[9], z_new[10], z_new[11])
    n0, n1, n2 = _rotate(-a, b, u0, u1, u2, n0, n1, n2)  # m_new = exp(−û) R_nᵀ L_new
    f0, f1, f2 = _rotate(-b, c, u0, u1, u2, e0, e1, e2)  # e = dexp_{−u}(e_u)
    g0, g1, g2 = _transpose_apply(Rn, error[9], error[10], error[11])
    g0, g1, g2 = _rotate(-a, b, u0, u1, u2, g0, g1, g2)  # R_newᵀ e_L
    d0, d1, d2 = n1 * f2 - n2 * f1 + g0, n2 * f0 - n0 * f2 + g1, n0 * f1 - n1 * f0 + g2
    acc = _mixed(d0, atol[6], rtol, m0, n0) + _mixed(d1, atol[7], rtol, m1, n1)
    norm = _largest(norm, math.sqrt((acc + _mixed(d2, atol[8], rtol, m2, n2)) / 3.0))
    if z[9] == z_new[9] and z[10] == z_new[10] and z[11] == z_new[11]:  # no torque
        drift = _separatrix_drift(separatrix, m0, m1, m2, n0, n1, n2, d0, d1, d2, rtol)
        norm = _largest(norm, share * drift)
    return norm


def _separatrix_drift(D, m0, m1, m2, n0, n1, n2, d0, d1, d2, rtol):
    """One free step's estimated change of ``Δ = m·D m``, ``2 (D m_new)·δm``, against
    ``SEPARATRIX_SHARE · rtol |Δ|`` or ``Δ``'s rounding (:func:`error_norm`)."""
    k0, k1, k2 = _apply(D, n0, n1, n2)
    change = 2.0 * (k0 * d0 + k1 * d1 + k2 * d2)
    if change == 0.0:
        return 0.0
    s0, s1, s2 = _apply(D, m0, m1, m2)
    delta = max(abs(m0 * s0 + m1 * s1 + m2 * s2), abs(n0 * k0 + n1 * k1 + n2 * k2))
    rounding = math.sqrt((n0 * n0 + n1 * n1 + n2 * n2) * (k0 * k0 + k1 * k1 + k2 * k2))
    return abs(change) / (SEPARATRIX_SHARE * rtol * delta + ROUNDING * rounding)


def _mixed(e, atol, rtol, old, new):
    """``(e / (atol + rtol max(|old|, |new|)))²``, zero for an error of exactly zero."""
    if e == 0.0:
        return 0.0
    return (e / (atol + rtol * max(abs(old), abs(new)))) ** 2


def _largest(norm, part):
    """``max(norm, part)``, NaN if either is (a NaN part rejects the step)."""
    if part != part or norm != norm:
        return math.nan
    return max(norm, part)


def _exp_coefficients(theta2):
    """``(sin θ/θ, (1 − cos θ)/θ², (1 − sin θ/θ)/θ²)`` for ``θ² = theta2``: ``exp(û)`` and
    ``dexp_u`` by cross products. Below 0.25 rad (a step's usual turn) their Taylor series to
    θ⁸, whose first term left out is below 3e-14 relative: the norm only weighs errors, and
    each coefficient's error times θ² stays within an ulp of the vector it turns."""
    x = theta2
    if x < 0.0625:
        a = 1.0 + x * (-1.0 / 6 + x * (1.0 / 120 + x * (-1.0 / 5040 + x / 362880)))
        b = 0.5 + x * (-1.0 / 24 + x * (1.0 / 720 + x * (-1.0 / 40320 + x / 3628800)))
        c = 1.0 / 6 + x * (-1.0 / 120 + x * (1.0 / 5040 + x * (-1.0 / 362880 + x / 39916800)))
        return a, b, c
    theta = math.sqrt(x)
    a = math.sin(theta) / theta
    half = math.sin(0.5 * theta) / theta
    return a, 2.0 * half * half, (1.0 - a) / x


def _apply(M, v0, v1, v2):
    """``M v`` for a 3×3 ``M``."""
    return (
        M[0, 0] * v0 + M[0, 1] * v1 + M[0, 2] * v2,
        M[1, 0] * v0 + M[1, 1] * v1 + M[1, 2] * v2,
        M[2, 0] * v0 + M[2, 1] * v1 + M[2, 2] * v2,
    )


def _transpose_apply(M, v0, v1, v2):
    """``Mᵀ v`` for a 3×3 ``M``."""
    return (
        M[0, 0] * v0 + M[1, 0] * v1 + M[2, 0] * v2,
        M[0, 1] * v0 + M[1, 1] * v1 + M[2, 1] * v2,
        M[0, 2] * v0 + M[1, 2] * v1 + M[2, 2] * v2,
    )


def _rotate(a, b, u0, u1, u2, v0, v1, v2):
    """``v + a u×v + b u×(u×v)``: ``exp(±û) v`` for ``(±sin θ/θ, (1 − cos θ)/θ²)``,
    ``dexp_{−u} v`` for ``(−(1 − cos θ)/θ², (1 − sin θ/θ)/θ²)``, ``dexp⁻¹_{−u} v`` for
    ``(½, α)`` (:mod:`tumble.rigid._compiled` compiles this one for its loops too)."""
    c0, c1, c2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
    d0, d1, d2 = u1 * c2 - u2 * c1, u2 * c0 - u0 * c2, u0 * c1 - u1 * c0
    return v0 + a * c0 + b * d0, v1 + a * c1 + b * d1, v2 + a * c2 + b * d2


NORM_HELPERS = (
    "_separatrix_drift", "_mixed", "_largest", "_exp_coefficients", "_apply",
    "_transpose_apply", "_rotate",
)  # fmt: skip
"""The functions :func:`error_norm` calls, compiled beside it by :mod:`tumble.rigid._compiled`."""


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
    quaternion=True,
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
"""Every chart by name (each is a family of :data:`tumble.rigid.methods.FAMILIES`)."""
