"""The readable NumPy reference of every rigid-body method: one RK step in a local chart.

Each family turns the rigid body into an ODE on a vector ``z`` for the duration of one step
and hands it to the ODE core's :func:`~tumble.ode.stepper.rk_step`, so every method is the
same mechanism with other data:

* ``matrix``: ``z = (vec R, x, p, L)`` with ``Ṙ = R ω̃_body``;
* ``quat``: ``z = (q, x, p, L)`` with ``q̇ = ½ q ⊗ (0, ω_body)``, then ``q ← q/|q|``;
* ``lie`` (Runge–Kutta–Munthe-Kaas, Munthe-Kaas 1998): ``R = R_n exp(û)``,
  ``z = (u, x, p, L)`` with ``u(0) = 0`` and the right-trivialised equation

  .. math:: \\dot u = \\operatorname{dexp}^{-1}_{-u}(\\omega_{body}),

  so ``R_{n+1} = R_n exp(û_{n+1})`` lies on SO(3) to round-off.

Everywhere ``ω_body = I⁻¹ Rᵀ L``, ``ẋ = p/m``, ``ṗ = F`` and ``L̇ = τ`` (world frame).
The compiled kernels in :mod:`tumble.rigid.kernels` run the same algorithm.
"""

from __future__ import annotations

import numpy as np

from tumble import so3
from tumble.ode.stepper import rk_step
from tumble.rigid.body import RigidBody
from tumble.rigid.forces import State, total_load
from tumble.rigid.methods import Method


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


def _matrix_step(dynamics: Dynamics, method: Method, t, R, Y, h):
    def f(t, z):
        R = z[:9].reshape(3, 3)
        Rdot = R @ so3.hat(dynamics.omega(R, z[15:]))
        return np.concatenate([Rdot.ravel(), dynamics.rates(t, R, z[9:])])

    z = np.concatenate([R.ravel(), Y])
    K = np.empty((method.tableau.stages, z.size))
    z_new, error = rk_step(f, t, z, f(t, z), h, method.tableau, K)
    return z_new[:9].reshape(3, 3), z_new[9:], error


def _quat_step(dynamics: Dynamics, method: Method, t, q, Y, h):
    def f(t, z):
        R = so3.matrix_from_quat(z[:4] / np.linalg.norm(z[:4]))
        omega = dynamics.omega(R, z[10:])
        qdot = 0.5 * so3.quat_mul(z[:4], np.concatenate([[0.0], omega]))
        return np.concatenate([qdot, dynamics.rates(t, R, z[4:])])

    z = np.concatenate([q, Y])
    K = np.empty((method.tableau.stages, z.size))
    z_new, error = rk_step(f, t, z, f(t, z), h, method.tableau, K)
    return z_new[:4] / np.linalg.norm(z_new[:4]), z_new[4:], error


def _lie_step(dynamics: Dynamics, method: Method, t, R_n, Y, h):
    def f(t, z):
        u = z[:3]
        R = R_n @ so3.exp(u)
        omega = dynamics.omega(R, z[9:])
        udot = so3.dexpinv_apply(-u, omega) if method.dexpinv else omega
        return np.concatenate([udot, dynamics.rates(t, R, z[3:])])

    z = np.concatenate([np.zeros(3), Y])
    K = np.empty((method.tableau.stages, z.size))
    z_new, error = rk_step(f, t, z, f(t, z), h, method.tableau, K)
    return R_n @ so3.exp(z_new[:3]), z_new[3:], error


_FAMILIES = {"matrix": _matrix_step, "quat": _quat_step, "lie": _lie_step}


def step(dynamics: Dynamics, method: Method, t: float, attitude, Y: np.ndarray, h: float):
    """One step of ``method`` from ``(attitude, Y)`` at ``t``.

    Parameters
    ----------
    dynamics : Dynamics
        The body and its loads.
    method : Method
        Which family and tableau.
    t : float
        Time (s).
    attitude : ndarray, shape (3, 3) or (4,)
        R for the ``matrix`` and ``lie`` families, the unit quaternion for ``quat``.
    Y : ndarray, shape (9,)
        ``(x, p, L)``.
    h : float
        Step (s).

    Returns
    -------
    attitude_new, Y_new : ndarray
        The state at ``t + h``.
    error : ndarray or None
        The embedded error estimate in the chart's coordinates (adaptive tableaux only).
    """
    return _FAMILIES[method.family](dynamics, method, t, attitude, Y, h)
