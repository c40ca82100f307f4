"""The report card's problems: the bodies, their starts and loads, and their references.

* ``P1``: Hairer–Lubich–Wanner's body I = diag(2, 1, 2/3) kg m², L₀ = (cos 1.1, 0, sin 1.1),
  R₀ = I (exact reference :func:`tumble.exact.free_body_rotation`);
* the T-handle's three spins (:data:`tumble.scenarios.t_handle.SPINS`) and a spin ten
  thousand times nearer its separatrix, ω₀ = (1, 10⁻⁴, 0) rad/s (exact reference);
* ``forced``: P1's body with a magnetic dipole μ = (1, 0.5, 0) A m² in B = (0, 0, 0.5) T
  (:class:`tumble.MagneticDipole`), against a tight scipy DOP853 reference (rtol = atol =
  10⁻¹³).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tumble import exact, mass, so3
from tumble.rigid import MagneticDipole, RigidBody
from tumble.scenarios import convergence, t_handle

SWEEP_T = 10.0
"""T (s) of the order sweeps."""
PROBLEM_T = 50.0
"""T (s) of the T-handle's runs (its flip takes 47 s)."""
P1_INERTIA = np.array(convergence.INERTIA)
P1_L0 = np.array(convergence.L0)
DIPOLE = MagneticDipole(moment=(1.0, 0.5, 0.0), field=(0.0, 0.0, 0.5))
"""The forced body's load: a compass needle, torque (Rμ) × B, potential −(Rμ)·B."""
SEPARATRIX_SPIN = (1.0, 1e-4, 0.0)
"""The T-handle spun about its middle axis x with a 10⁻⁴ wobble: near the separatrix."""
REFERENCE_RTOL = 1e-13
"""rtol = atol of the forced body's scipy DOP853 reference."""


@dataclass(frozen=True)
class CardProblem:
    """One problem of the report card: a body, its start (R₀ = I, ω₀ body frame), T and loads.

    ``dipole`` is None for a free body (exact reference) or the magnetic dipole.
    """

    name: str
    body: RigidBody
    omega0: np.ndarray
    t_end: float
    dipole: MagneticDipole | None = None

    @property
    def forced(self) -> bool:
        return self.dipole is not None

    def forces(self) -> list:
        return [] if self.dipole is None else [self.dipole]


def p1_body() -> RigidBody:
    """Hairer–Lubich–Wanner's body diag(2, 1, 2/3) (it breaks the triangle inequality)."""
    return RigidBody(1.0, P1_INERTIA, allow_unphysical=True)


def problems() -> list[CardProblem]:
    """P1, the T-handle's three spins, the near-separatrix spin and the forced body."""
    p1 = p1_body()
    p1_omega = P1_L0 / P1_INERTIA
    handle = RigidBody.from_mass_properties(mass.t_handle())
    spins = [
        CardProblem(f"T-handle ω₀={tuple(spin)}", handle, np.array(spin, float), PROBLEM_T)
        for spin in t_handle.SPINS
    ]
    return [
        CardProblem("P1", p1, p1_omega, SWEEP_T),
        *spins,
        CardProblem("separatrix", handle, np.array(SEPARATRIX_SPIN), PROBLEM_T),
        CardProblem("forced", p1, p1_omega, SWEEP_T, DIPOLE),
    ]


def rhs(problem: CardProblem) -> Callable[[float, np.ndarray], np.ndarray]:
    """Euler's equations and ``q̇ = ½ q ⊗ (0, ω)`` for ``y = (ω, q)`` (the peers' way), with
    the dipole's body torque ``μ × (Rᵀ B)``."""
    A, B, C = problem.body.inertia.diagonal()
    inertia = np.array([A, B, C])
    dipole = problem.dipole

    def f(t, y):
        w1, w2, w3, q0, q1, q2, q3 = y
        torque = np.zeros(3)
        if dipole is not None:
            R = so3.matrix_from_quat(y[3:])
            torque = np.cross(dipole.moment, R.T @ dipole.field) / inertia
        return np.array(
            [
                (B - C) * w2 * w3 / A + torque[0],
                (C - A) * w3 * w1 / B + torque[1],
                (A - B) * w1 * w2 / C + torque[2],
                0.5 * (-q1 * w1 - q2 * w2 - q3 * w3),
                0.5 * (q0 * w1 + q2 * w3 - q3 * w2),
                0.5 * (q0 * w2 + q3 * w1 - q1 * w3),
                0.5 * (q0 * w3 + q1 * w2 - q2 * w1),
            ]
        )

    return f


def y0(problem: CardProblem) -> np.ndarray:
    """``y₀ = (ω₀, q₀ = 1)`` of :func:`rhs`."""
    return np.concatenate([problem.omega0, [1.0, 0.0, 0.0, 0.0]])


def reference(problem: CardProblem, t_end: float | None = None) -> np.ndarray:
    """R(T): exact for a free body, scipy DOP853 at rtol = atol = 1e-13 for the forced one."""
    from scipy.integrate import solve_ivp

    t_end = problem.t_end if t_end is None else t_end
    if not problem.forced:
        return exact.free_body_rotation(problem.body.inertia, problem.omega0, t_end)
    solution = solve_ivp(rhs(problem), (0.0, t_end), y0(problem), method="DOP853",
                         rtol=REFERENCE_RTOL, atol=REFERENCE_RTOL)  # fmt: skip
    return so3.matrix_from_quat(solution.y[3:].T)[-1]  # as the peers read it: q/|q|


def attitude_error(R: np.ndarray, R_ref: np.ndarray) -> float:
    """``‖R − R_ref‖_F`` (inf when R is not finite)."""
    with np.errstate(over="ignore", invalid="ignore"):
        error = float(np.linalg.norm(R - R_ref))
    return error if math.isfinite(error) else math.inf
