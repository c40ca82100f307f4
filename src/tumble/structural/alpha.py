"""Schemes with controllable numerical damping: generalized-α, HHT-α and ρ∞-Bathe.

**Generalized-α** (Chung & Hulbert 1993) keeps the acceleration ``a`` as a state and
satisfies the equation of motion at intermediate points,

.. math::

    M a_{n+1-α_m} + C y_{n+1-α_f} + S x_{n+1-α_f} = f, \\qquad
    z_{n+1-α} = (1 - α) z_{n+1} + α z_n,

    x_{n+1} = x_n + Δt y_n + Δt^2 ((½ - β) a_n + β a_{n+1}), \\qquad
    y_{n+1} = y_n + Δt ((1 - γ) a_n + γ a_{n+1}).

Here ``α_m``, ``α_f`` weigh the **old** values (Chung–Hulbert's convention, and Hughes'
for HHT up to the sign ``α_f = −α``). The other common convention (OpenSees'
``GeneralizedAlpha αM αF`` and ``HHT α``, Jansen–Whiting–Hulbert 2000) weighs the new
values: ``α_M = 1 − α_m``, ``α_F = 1 − α_f`` (so OpenSees' HHT ``α ∈ [⅔, 1]`` is
``1 + α`` here). Second-order accuracy needs ``γ = ½ − α_m + α_f``; unconditional stability
``α_m ≤ α_f ≤ ½`` and ``β ≥ ¼ + ½(α_f − α_m)``. Chung and Hulbert choose the rest so that
the high-frequency spectral radius is ``ρ∞ ∈ [0, 1]`` with the least low-frequency damping:

.. math::

    α_m = \\frac{2ρ_∞ - 1}{ρ_∞ + 1}, \\quad α_f = \\frac{ρ_∞}{ρ_∞ + 1}, \\quad
    γ = ½ - α_m + α_f, \\quad β = ¼ (1 - α_m + α_f)^2.

As ``ωΔt → ∞`` the three eigenvalues of the amplification matrix all tend to ``−ρ∞``
for these values (Chung–Hulbert eqs. 18–25; :func:`tumble.structural.amplification`
measures it). ``ρ∞ = 1`` gives ``α_m = α_f = ½``, ``γ = ½``, ``β = ¼``: the
midpoint/average-acceleration step. **HHT-α** (Hilber, Hughes & Taylor 1977) is the family
with ``α_m = 0``, ``α_f = −α``, ``α ∈ [−⅓, 0]``, ``γ = ½ − α``, ``β = (1 − α)²/4``.

*In increments.* With ``κ = (1 − α_f) γ Δt/(1 − α_m)``, ``c_r = γ/(1 − α_m)``,
``rⁿ = f − S xⁿ − C yⁿ`` and ``mⁿ = M aⁿ`` (carried; equal to ``rⁿ`` only when
``α_m = α_f = 0``), eliminating ``a_{n+1}`` gives one constant matrix:

.. math::

    (M + κ C + κ (β/γ) Δt S)\\, Δy
        = Δt\\, (c_r r^n + (1 - c_r) m^n - S (κ y^n + κ (½ - β/γ) Δt a^n)),

    Δx = Δt y^n + (β/γ) Δt Δy + (½ - β/γ) Δt^2 a^n, \\qquad a^{n+1} = (1 - 1/γ) a^n + Δy/(γΔt),

    (1 - α_m) m^{n+1} = (1 - α_f) r^{n+1} + α_f r^n - α_m m^n

(the last is the equation of motion itself, so no product with ``M``). The product with
``S`` of the next step is summed with ``S Δx`` in one pass over the elements: a step costs
what a Newmark step costs.

**ρ∞-Bathe** (Noh & Bathe 2019) is a composite of two sub-steps, each in equilibrium at
its end: the trapezoidal rule over ``γΔt`` (``γ`` the *splitting ratio*), then

.. math::

    x_{n+1} = x_n + Δt (q_0 y_n + q_1 y_{n+γ} + q_2 y_{n+1}), \\quad
    y_{n+1} = y_n + Δt (q_0 a_n + q_1 a_{n+γ} + q_2 a_{n+1}),

    q_1 = \\frac{ρ_∞ + 1}{2γ(ρ_∞ - 1) + 4}, \\quad q_0 = (γ - 1) q_1 + ½, \\quad
    q_2 = -γ q_1 + ½.

Its matrices are ``M + (γΔt/2) C + (γΔt/2)² S`` and ``M + q_2Δt C + (q_2Δt)² S``; they are
equal, one factorisation, at ``q_2 = γ/2``, i.e. ``γ₀ = 2/(2 + √(2 + 2ρ∞))`` (``2 − √2``
for ``ρ∞ = 0``, the original Bathe method; ``½`` for ``ρ∞ = 1``, two trapezoidal half
steps), the default. In increments the second sub-step is
``A₂ Δy = Δt (d₀ rⁿ + d₁ r^{n+γ} − q₂ Δt S w)``, ``Δx = Δt w + q₂ Δt Δy`` with
``w = d₀ yⁿ + d₁ y^{n+γ}``, ``d₀ = q₀ − γ/2``, ``d₁ = 1 − q₀ − γ/2``.

References
----------
.. [1] J. Chung, G. M. Hulbert, "A time integration algorithm for structural dynamics with
   improved numerical dissipation: the generalized-α method", *J. Appl. Mech.* 60,
   371–375, 1993.
.. [2] H. M. Hilber, T. J. R. Hughes, R. L. Taylor, "Improved numerical dissipation for time
   integration algorithms in structural dynamics", *Earthq. Eng. Struct. Dyn.* 5,
   283–292, 1977.
.. [3] G. Noh, K. J. Bathe, "The Bathe time integration method with controllable spectral
   radius: the ρ∞-Bathe method", *Comput. Struct.* 212, 299–310, 2019.
.. [4] K. E. Jansen, C. H. Whiting, G. M. Hulbert, "A generalized-α method for integrating
   the filtered Navier–Stokes equations", *Comput. Methods Appl. Mech. Eng.* 190,
   305–319, 2000.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from tumble import _checks
from tumble.structural.alpha_kernels import ALPHA, BATHE
from tumble.structural.scheme import Scheme
from tumble.structural.stepping import BeamState, Solve
from tumble.structural.system import LinearSystem


def _unit_interval(name: str, value: float) -> float:
    value = _checks.finite(name, value)
    if not 0.0 <= value <= 1.0:
        raise _checks.fail(name, value, "in [0, 1] for unconditional stability")
    return value


@dataclass(frozen=True)
class AlphaCoefficients:
    """The constants of one generalized-α increment step (module docstring).

    ``values`` is the tuple the compiled loop reads:
    ``(Δt, c_r, k_g = κ, k_sa = κ(½ − β/γ)Δt, k_dy = (β/γ)Δt, k_a = (½ − β/γ)Δt²,
    1 − 1/γ, 1/(γΔt), (1 − α_f)/(1 − α_m), α_f/(1 − α_m), α_m/(1 − α_m))``.
    """

    values: tuple[float, ...]

    @classmethod
    def of(cls, alpha_m: float, alpha_f: float, beta: float, gamma: float, dt: float):
        """The constants for parameters ``α_m, α_f, β, γ`` and step ``Δt`` [s]."""
        kappa = (1 - alpha_f) * gamma * dt / (1 - alpha_m)
        ratio = beta / gamma
        return cls((dt, gamma / (1 - alpha_m), kappa, kappa * (0.5 - ratio) * dt, ratio * dt,
                    (0.5 - ratio) * dt * dt, 1 - 1 / gamma, 1 / (gamma * dt),
                    (1 - alpha_f) / (1 - alpha_m), alpha_f / (1 - alpha_m),
                    alpha_m / (1 - alpha_m)))  # fmt: skip


@dataclass(frozen=True)
class AlphaScheme(Scheme):
    """A member of the generalized-α family, given by ``α_m, α_f, β, γ`` (module docstring).

    Use :class:`GeneralizedAlpha` (by ρ∞) or :class:`HHT` (by α); Newmark is
    ``α_m = α_f = 0``. Its state carries the acceleration (:class:`AlphaState`).
    """

    name: str = field(init=False, default="alpha")
    kernel = ALPHA

    @property
    def parameters(self) -> tuple[float, float, float, float]:
        """``(α_m, α_f, β, γ)``."""
        raise NotImplementedError

    @property
    def order(self) -> int:
        """Order of accuracy: 2 when ``γ = ½ − α_m + α_f`` (Chung–Hulbert eq. 13), else 1."""
        alpha_m, alpha_f, _, gamma = self.parameters
        return 2 if abs(gamma - (0.5 - alpha_m + alpha_f)) < 1e-14 else 1

    @property
    def carries_acceleration(self) -> bool:
        """True: the state holds ``a`` and ``m = M a``."""
        return True

    def matrices(self, system: LinearSystem, C: sp.spmatrix | None, dt: float) -> list:
        """The step matrix ``M + κ C + κ (β/γ) Δt S``, in a list (one factorisation)."""
        alpha_m, alpha_f, beta, gamma = self.parameters
        kappa = (1 - alpha_f) * gamma * dt / (1 - alpha_m)
        A = system.M + (kappa * beta / gamma * dt) * system.S
        return [A if C is None else A + kappa * C]

    def coefficients(self, dt: float) -> tuple[float, ...]:
        """:attr:`AlphaCoefficients.values` for ``dt`` [s]."""
        return AlphaCoefficients.of(*self.parameters, dt).values

    def start(
        self, system: LinearSystem, state: BeamState, C: sp.spmatrix | None, dt: float,
        acceleration: tuple[NDArray, NDArray] | None,
    ) -> AlphaState:  # fmt: skip
        """The stepped state from ``(x, y, q, S y)`` and ``(a₀, m₀ = M a₀)``, with
        ``r₀ = q₀ − C y₀`` and ``p₀ = S(k_g y₀ + k_sa a₀)``."""
        assert acceleration is not None, "it carries the acceleration: initial_state gives a₀"
        a, m = acceleration
        r = state.q - (0.0 if C is None else C @ state.y)
        _, _, k_g, k_sa, *_ = self.coefficients(dt)
        p = system.internal_forces(k_g * state.y + k_sa * a)
        return AlphaState(state.x, state.y, state.q, p, a, m.copy(), r)

    def step(
        self, state: BeamState, system: LinearSystem, solves: list[Solve],
        C: sp.spmatrix | None, coefficients: tuple[float, ...],
    ) -> None:  # fmt: skip
        alpha_step(state, coefficients, system, solves[0], C)  # type: ignore[arg-type]

    def critical_omega(self) -> float:
        """``inf``: parameters that are not unconditionally stable are refused."""
        return math.inf


@dataclass(frozen=True)
class GeneralizedAlpha(AlphaScheme):
    """Chung–Hulbert generalized-α by its high-frequency spectral radius ``ρ∞ ∈ [0, 1]``.

    ``α_m = (2ρ∞ − 1)/(ρ∞ + 1)``, ``α_f = ρ∞/(ρ∞ + 1)``, ``γ = ½ − α_m + α_f``,
    ``β = ¼(1 − α_m + α_f)²`` (module docstring, with the conventions). ρ∞ = 1 keeps
    energy (the midpoint step), ρ∞ = 0 annihilates the highest modes in one step.
    """

    rho_inf: float = 0.8
    name: str = field(init=False, default="generalized-alpha")

    def __post_init__(self) -> None:
        _unit_interval("rho_inf", self.rho_inf)

    @property
    def parameters(self) -> tuple[float, float, float, float]:
        rho = self.rho_inf
        alpha_m, alpha_f = (2 * rho - 1) / (rho + 1), rho / (rho + 1)
        return alpha_m, alpha_f, 0.25 * (1 - alpha_m + alpha_f) ** 2, 0.5 - alpha_m + alpha_f


@dataclass(frozen=True)
class HHT(AlphaScheme):
    """Hilber–Hughes–Taylor α: ``M aⁿ⁺¹ + (1 + α)(C yⁿ⁺¹ + S xⁿ⁺¹) − α (C yⁿ + S xⁿ) = f``.

    ``α ∈ [−⅓, 0]`` (Hughes' sign; OpenSees' ``HHT`` takes ``1 + α``), with
    ``γ = ½ − α`` and ``β = (1 − α)²/4`` unless given; ``γ < ½`` or ``β < (γ + ½)²/4``
    lose unconditional stability and are refused. ``α = 0`` is Newmark's average
    acceleration. ``ρ∞ = (1 + α)/(1 − α)``.
    """

    alpha: float = -0.05
    beta: float | None = None
    gamma: float | None = None
    name: str = field(init=False, default="hht")

    def __post_init__(self) -> None:
        alpha = _checks.finite("alpha", self.alpha)
        if not -1 / 3 <= alpha <= 0:
            raise _checks.fail(
                "alpha", self.alpha, "in [-1/3, 0] for unconditional stability",
                remedy="Hughes' sign: OpenSees' HHT alpha a is a - 1 here",
            )  # fmt: skip
        gamma = 0.5 - alpha if self.gamma is None else _checks.finite("gamma", self.gamma)
        if gamma < 0.5:
            raise _checks.fail("gamma", self.gamma, ">= 1/2 for unconditional stability")
        if self.beta is not None:
            beta = _checks.finite("beta", self.beta)
            if beta < (gamma + 0.5) ** 2 / 4:
                bound = (gamma + 0.5) ** 2 / 4
                raise _checks.fail(
                    "beta", self.beta, f">= (gamma + 1/2)²/4 = {bound!r} for unconditional "
                    "stability",
                )  # fmt: skip

    @property
    def parameters(self) -> tuple[float, float, float, float]:
        gamma = 0.5 - self.alpha if self.gamma is None else self.gamma
        beta = (1 - self.alpha) ** 2 / 4 if self.beta is None else self.beta
        return 0.0, -self.alpha, beta, gamma


@dataclass
class AlphaState(BeamState):
    """``x, y, q = f − S x`` and ``g = p = S(k_g y + k_sa a)`` (the next step's product),
    the acceleration ``a``, ``m = M a`` and ``r = q − C y``, all carried."""

    a: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    m: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    r: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    MODAL: ClassVar[tuple[str, ...]] = ("x", "y", "a")


def alpha_step(state: AlphaState, values: tuple, system: LinearSystem, solve, C) -> None:
    """One generalized-α increment step (module docstring) in NumPy, in place."""
    dt, c_r, k_g, k_sa, k_dy, k_a, a_keep, a_gain, m_new, m_old, m_prev = values
    dy = solve(dt * (c_r * state.r + (1.0 - c_r) * state.m - state.g))  # g holds p
    dx = dt * state.y + k_dy * dy + k_a * state.a
    state.x += dx
    state.y += dy
    state.a = a_keep * state.a + a_gain * dy
    sdx = system.internal_forces(dx)
    state.g = system.internal_forces(k_g * state.y + k_sa * state.a)
    state.q -= sdx
    r_new = state.q - (0.0 if C is None else C @ state.y)
    state.m = m_new * r_new + m_old * state.r - m_prev * state.m
    state.r = r_new


@dataclass(frozen=True)
class Bathe(Scheme):
    """The ρ∞-Bathe composite method (Noh & Bathe 2019; module docstring).

    Parameters
    ----------
    rho_inf : float
        High-frequency spectral radius ρ∞ ∈ [0, 1]; 0 (default) is the original Bathe method.
    gamma : float, optional
        Splitting ratio γ ∈ (0, 1): the first (trapezoidal) sub-step covers ``γΔt``. By
        default ``γ₀ = 2/(2 + √(2 + 2ρ∞))``, for which both sub-steps share one matrix.
    """

    rho_inf: float = 0.0
    gamma: float | None = None
    name: str = field(init=False, default="bathe")
    kernel = BATHE

    def __post_init__(self) -> None:
        _unit_interval("rho_inf", self.rho_inf)
        if self.gamma is not None:
            gamma = _checks.finite("gamma", self.gamma)
            if not 0 < gamma < 1:
                raise _checks.fail("gamma", self.gamma, "in (0, 1): the splitting ratio")

    @property
    def order(self) -> int:
        """2, for every ρ∞ and γ (Noh & Bathe 2019, §2)."""
        return 2

    @property
    def splitting(self) -> float:
        """The splitting ratio γ."""
        if self.gamma is not None:
            return self.gamma
        return 2 / (2 + math.sqrt(2 + 2 * self.rho_inf))

    @property
    def weights(self) -> tuple[float, float, float]:
        """``(q₀, q₁, q₂)`` of the second sub-step."""
        rho, gamma = self.rho_inf, self.splitting
        q1 = (rho + 1) / (2 * gamma * (rho - 1) + 4)
        return (gamma - 1) * q1 + 0.5, q1, -gamma * q1 + 0.5

    def coefficients(self, dt: float) -> tuple[float, ...]:
        """``(Δt, τ = γΔt, d₀, d₁, q₂)`` (module docstring) for ``dt`` [s]."""
        gamma = self.splitting
        q0, _, q2 = self.weights
        return dt, gamma * dt, q0 - gamma / 2, 1 - q0 - gamma / 2, q2

    def matrices(self, system: LinearSystem, C: sp.spmatrix | None, dt: float) -> list:
        """The two sub-steps' matrices ``M + c C + c² S``, ``c = γΔt/2`` and ``q₂Δt``."""
        out = []
        for c in (self.splitting * dt / 2, self.weights[2] * dt):
            A = system.M + (c * c) * system.S
            out.append(A if C is None else A + c * C)
        return out

    def step(
        self, state: BeamState, system: LinearSystem, solves: list[Solve],
        C: sp.spmatrix | None, coefficients: tuple[float, ...],
    ) -> None:  # fmt: skip
        bathe_step(state, coefficients, system, solves, C)

    def critical_omega(self) -> float:
        """``inf``: ρ∞ ∈ [0, 1] and γ ∈ (0, 1) are unconditionally stable."""
        return math.inf


def bathe_step(state: BeamState, values: tuple, system: LinearSystem, solves, C) -> None:
    """One ρ∞-Bathe step (two sub-steps, module docstring) in NumPy, in place."""
    dt, tau, d0, d1, q2 = values
    r_old = state.q - (0.0 if C is None else C @ state.y)
    y_old, g_old = state.y.copy(), state.g
    dy = solves[0](tau * (r_old - 0.5 * tau * state.g))
    dx = tau * state.y + 0.5 * tau * dy
    state.x += dx
    state.y += dy
    state.q -= system.internal_forces(dx)
    state.g = system.internal_forces(state.y)
    r_mid = state.q - (0.0 if C is None else C @ state.y)
    dy = solves[1](dt * (d0 * r_old + d1 * r_mid - q2 * dt * (d0 * g_old + d1 * state.g)))
    dx = dt * (d0 * y_old + d1 * state.y) + q2 * dt * dy
    state.x += dx
    state.y += dy
    state.q -= system.internal_forces(dx)
    state.g = system.internal_forces(state.y)
