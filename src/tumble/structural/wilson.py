"""Wilson-θ: linear acceleration over the extended step ``θΔt``, then back to ``Δt``.

Wilson, Farhoomand and Bathe (1973) assume the acceleration linear over
``[t, t + θΔt]``, ``θ ≥ 1``,

.. math::

    a(t + τ) = a_n + \\frac{τ}{θΔt} (a_θ - a_n), \\qquad
    y_θ = y_n + \\frac{θΔt}{2} (a_n + a_θ), \\qquad
    x_θ = x_n + θΔt\\, y_n + \\frac{(θΔt)^2}{6} (a_θ + 2 a_n),

and ask for equilibrium at the end of the extended step, ``M a_θ + C y_θ + S x_θ = f``
(here ``f`` is constant; a varying load is extrapolated linearly to ``t + θΔt``). Then
``τ = Δt`` in the same interpolation gives the step:

.. math::

    a_{n+1} = (1 - 1/θ)\\, a_n + a_θ/θ, \\qquad
    y_{n+1} = y_n + \\frac{Δt}{2} (a_n + a_{n+1}), \\qquad
    x_{n+1} = x_n + Δt\\, y_n + \\frac{Δt^2}{6} (a_{n+1} + 2 a_n).

*In increments.* With ``θΔt = T``, one constant matrix ``A = M + (T/2) C + (T²/6) S`` and

.. math::

    A\\, a_θ = q_n - g_n - C (y_n + \\tfrac{T}{2} a_n), \\qquad
    g = S\\,(T y + \\tfrac{T^2}{3} a), \\qquad q = f - S x,

where ``q`` is carried and updated by ``S Δx``, and the next step's ``g`` is summed with
``S Δx`` in one pass over the elements (as the generalized-α step does): a step costs what
a Newmark step costs. The state carries ``a`` (it is not in equilibrium at ``t_{n+1}``),
started from ``a₀ = M⁻¹(f − S x₀ − C y₀)``.

``θ = 1`` is Newmark's linear acceleration (``β = 1/6``, ``γ = ½``), stable for
``ωΔt < √12``. On one mode, as ``Ω = ωΔt → ∞`` the amplification matrix on
``(x, Δt y, Δt² a)`` tends to

.. math::

    G_∞ = \\begin{pmatrix} 1 - u^3 & 1 - u^2 & (1 - u)/2 \\\\
                           -3u^3 & 1 - 3u^2 & 1 - 3u/2 \\\\
                           -6u^3 & -6u^2 & 1 - 3u \\end{pmatrix},
    \\qquad u = 1/θ,

with ``det(G_∞ + I) = 2(u − 2)(u² + 2u − 2)``: a real eigenvalue passes −1 where
``u² + 2u − 2 = 0``, at ``θ = (1 + √3)/2 ≈ 1.366`` — the "θ ≥ 1.37" of Bathe and Wilson
(1973). From there on the scheme is unconditionally stable (the tests scan ρ over
``Ω = 10⁻³ … 10⁸``); below, :meth:`WilsonTheta.critical_omega` finds the limit from the
spectral radius (``√12`` at ``θ = 1``). ``θ = 1.4``, the usual choice and the default,
damps high frequencies (ρ∞ = 0.778) and is second order, with a larger error than Newmark's
average acceleration (3× on the one-element cantilever at the same step).

*Overshoot* (Hilber & Hughes 1978). From ``G_∞``'s last column, one step from an
acceleration ``a₀`` moves a stiff mode by ``(1 − 1/θ)/2 · Δt² a₀``, ``(1 − 1/θ) Ω²/2``
times its static displacement ``Δt² a₀/Ω²``, before the damping (``ρ∞`` a step) takes it
away. A step load from rest on the 20-element cantilever at 3 periods of mode 1 a step
(``ωΔt`` up to 10⁴) raises the energy to 2·10⁸ times the bound ``(√V₀ + P t)²`` of
:mod:`~tumble.structural.divergence` in the first step; at step 64, where the energy watch
first looks, it is 7·10⁻⁹ of it.

References
----------
.. [1] E. L. Wilson, I. Farhoomand, K. J. Bathe, "Nonlinear dynamic analysis of complex
   structures", *Earthq. Eng. Struct. Dyn.* 1, 241–252, 1973.
.. [2] K. J. Bathe, E. L. Wilson, "Stability and accuracy analysis of direct integration
   methods", *Earthq. Eng. Struct. Dyn.* 1, 283–291, 1973.
.. [3] H. M. Hilber, T. J. R. Hughes, "Collocation, dissipation and 'overshoot' for time
   integration schemes in structural dynamics", *Earthq. Eng. Struct. Dyn.* 6, 99–117,
   1978.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numba
import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from tumble import _checks
from tumble.structural.kernels import StepKernel, assemble_internal_forces_pair, banded_solve
from tumble.structural.scheme import Scheme
from tumble.structural.stepping import BeamState, Solve
from tumble.structural.system import LinearSystem

UNCONDITIONAL_THETA = (1 + math.sqrt(3)) / 2
"""The smallest θ stable at every Δt, ``(1 + √3)/2 ≈ 1.366`` (module docstring)."""


@dataclass
class WilsonState(BeamState):
    """``x, y, q = f − S x``, ``g = S(θΔt y + (θΔt)²/3 a)`` (the next step's product) and
    the carried acceleration ``a``."""

    a: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    MODAL: ClassVar[tuple[str, ...]] = ("x", "y", "a")


def wilson_step(
    state: BeamState, system: LinearSystem, solves: list[Solve], C: sp.spmatrix | None,
    coefficients: tuple[float, ...],
) -> None:  # fmt: skip
    """One Wilson-θ step (module docstring) in NumPy, updating ``state`` in place.

    ``coefficients`` are :meth:`WilsonTheta.coefficients`; ``solves[0]`` applies ``A⁻¹``.
    """
    dt, keep, gain, c_damping, half, sixth, k_y, k_a = coefficients
    a = state.a  # type: ignore[attr-defined]
    r = state.q - state.g
    if C is not None:
        r = r - C @ (state.y + c_damping * a)
    a_new = keep * a + gain * solves[0](r)
    dx = dt * state.y + sixth * (a_new + 2.0 * a)
    state.y += half * (a_new + a)
    state.x += dx
    state.a = a_new  # type: ignore[attr-defined]
    state.q -= system.internal_forces(dx)
    state.g = system.internal_forces(k_y * state.y + k_a * a_new)


@numba.njit(cache=True, nogil=True, inline="always")
def wilson_kernel(coefficients, state, frame, factors, damping, work):  # noqa: ANN001, ANN201
    """:func:`wilson_step` compiled, for :func:`tumble.structural.kernels.time_loop`.

    ``state`` is ``(x, y, q, g, a)`` (:class:`WilsonState`); ``work`` the right-hand side
    (then ``a_θ``), ``Δx``, ``S Δx`` (left for the next step to take from ``q``: the lag)
    and ``θΔt y + (θΔt)²/3 a``.
    """
    dt, keep, gain, c_damping, half, sixth, k_y, k_a = coefficients
    x, y, q, g, a = state
    rhs, dxs, h, combined = work
    factor = factors[0]
    indptr, indices, data = damping
    n = x.size
    for i in range(n):  # r = q − g − C(y + T/2 a), q first taking the last step's S Δx
        q[i] -= h[i]
        r = q[i] - g[i]
        if indptr.size:
            c = 0.0
            for j in range(indptr[i], indptr[i + 1]):
                c += data[j] * (y[indices[j]] + c_damping * a[indices[j]])
            r -= c
        rhs[i] = r
    banded_solve(factor[0], factor[1], factor[2], rhs, factor[3])  # rhs = a_θ
    non_finite = 0
    for i in range(n):
        a_new = keep * a[i] + gain * rhs[i]
        dx = dt * y[i] + sixth * (a_new + 2.0 * a[i])
        y[i] += half * (a_new + a[i])
        x[i] += dx
        a[i] = a_new
        dxs[i] = dx
        combined[i] = k_y * y[i] + k_a * a_new
        non_finite += not (np.isfinite(x[i]) and np.isfinite(y[i]))
    assemble_internal_forces_pair(dxs, combined, *frame, h, g)
    return non_finite


@dataclass(frozen=True)
class WilsonTheta(Scheme):
    """Wilson-θ (Wilson, Farhoomand & Bathe 1973; module docstring).

    Parameters
    ----------
    theta : float
        θ ≥ 1: the step solves equilibrium at ``t + θΔt``. ``θ ≥ (1 + √3)/2 ≈ 1.366`` is
        stable at every Δt (1.4, the default, is the usual choice); ``θ = 1`` is Newmark's
        linear acceleration, stable for ``ωΔt < √12``; in between
        :func:`~tumble.structural.critical_dt` reports the limit.

    Examples
    --------
    >>> from tumble import structural
    >>> beam = structural.cantilever(1.0, 10, E=210e9, rho=7850, width=0.01, height=0.01,
    ...                              tip_load=1.0)
    >>> run = structural.integrate(beam, WilsonTheta(), dt=1e-3, n_steps=500)
    >>> run.success, round(float(run.tip_displacement.max() * 525), 2)  # / (F L³/(3EI))
    (True, 1.99)
    >>> WilsonTheta().critical_omega(), round(WilsonTheta(1.0).critical_omega() ** 2, 9)
    (inf, 12.0)
    """

    theta: float = 1.4
    name: str = field(default="wilson", init=False)
    kernel = StepKernel("wilson", wilson_kernel, work=4, lag=2)

    def __post_init__(self) -> None:
        theta = _checks.finite("theta", self.theta)
        if not theta >= 1:
            raise _checks.fail(
                "theta", self.theta, ">= 1 (1 is Newmark's linear acceleration)",
                remedy=f"θ >= {UNCONDITIONAL_THETA:.4f} is stable at every dt; 1.4 is usual",
            )  # fmt: skip

    @property
    def order(self) -> int:
        """2, for every θ (Bathe & Wilson 1973)."""
        return 2

    @property
    def carries_acceleration(self) -> bool:
        """True: the state holds ``a``, started from ``a₀ = M⁻¹ r₀``."""
        return True

    @property
    def label(self) -> str:
        """``Wilson θ=1.4``."""
        return f"Wilson θ={self.theta:g}"

    def matrices(self, system: LinearSystem, C: sp.spmatrix | None, dt: float) -> list:
        """The step matrix ``M + (θΔt/2) C + ((θΔt)²/6) S``, in a list."""
        T = self.theta * dt
        A = system.M + (T * T / 6) * system.S
        return [A if C is None else A + (T / 2) * C]

    def coefficients(self, dt: float) -> tuple[float, ...]:
        """``(Δt, 1 − 1/θ, 1/θ, T/2, Δt/2, Δt²/6, T, T²/3)`` with ``T = θΔt``."""
        T = self.theta * dt
        return (dt, 1 - 1 / self.theta, 1 / self.theta, T / 2, dt / 2, dt * dt / 6, T,
                T * T / 3)  # fmt: skip

    def start(
        self, system: LinearSystem, state: BeamState, C: sp.spmatrix | None, dt: float,
        acceleration: tuple[NDArray, NDArray] | None,
    ) -> WilsonState:  # fmt: skip
        """The stepped state from ``(x₀, y₀, q₀)`` and ``a₀``: ``g₀ = S(T y₀ + T²/3 a₀)``."""
        assert acceleration is not None, "it carries the acceleration: initial_state gives a₀"
        a = acceleration[0].copy()
        k_y, k_a = self.coefficients(dt)[6:]
        g = system.internal_forces(k_y * state.y + k_a * a)
        return WilsonState(state.x, state.y, state.q, g, a)

    def step(
        self, state: BeamState, system: LinearSystem, solves: list[Solve],
        C: sp.spmatrix | None, coefficients: tuple[float, ...],
    ) -> None:  # fmt: skip
        wilson_step(state, system, solves, C, coefficients)

    def critical_omega(self) -> float:
        """``inf`` for ``θ ≥ (1 + √3)/2``; below, where the spectral radius of the
        amplification matrix first exceeds 1 (:meth:`Scheme.critical_omega`)."""
        if self.theta >= UNCONDITIONAL_THETA:
            return math.inf
        return super().critical_omega()
