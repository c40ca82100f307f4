"""When a structural run has diverged: more energy than its start and its loads can supply.

For ``M ẍ + C ẋ + S x = f`` (``M`` positive definite, ``S`` and ``C`` positive
semi-definite) the mechanical energy ``V = ½ yᵀM y + ½ xᵀS x`` changes at the rate

.. math::

    \\dot V = f^T y - y^T C y \\le |f|_{M^{-1}}\\, |y|_M \\le |f|_{M^{-1}} \\sqrt{2 V}

(Cauchy–Schwarz in the ``M`` inner product, ``|y|_M² = yᵀMy ≤ 2V``). So
``d√V/dt ≤ P = |f|_{M⁻¹}/√2`` and

.. math::

    V(t) \\le B(t) = \\bigl(\\sqrt{V_0} + P\\, t\\bigr)^2 .

Nothing in it asks ``S`` to be invertible (a mechanism that the load accelerates grows as
``t²``, within ``B``), and it holds for any load with ``|f(t)|_{M⁻¹} ≤ |f|``: resonance,
the most a bounded load can do, makes the amplitude ``√V`` grow linearly in ``t``, which is
the growth ``B`` allows. ``P`` is the rate at which the loads can raise ``√V``.

A scheme is a linear map of its state. When it is stable, the powers of its amplification
matrix are bounded, and the discrete motion obeys the bound times the scheme's transient
constant. An unstable scheme multiplies its unstable modes by ``ρ > 1`` at every step:
exponential growth passes any polynomial bound. So a run ends
:attr:`~tumble.ode.driver.Status.FAILED` at the first check where
``V > GROWTH_LIMIT · B(t)``; the compiled loops check after every :data:`CHECK_EVERY`-th
step and after the run's last (a check costs about a tenth of a step: the loops then cost
0.2 % more).

Two things make the transient constants of stable schemes large, and both are met here:

* *The start of a scheme that carries the acceleration* (Newmark with ``2β ≠ γ``, the
  generalized-α family): its state includes ``a₀ = M⁻¹(f − S x₀ − C y₀)``, and its first
  steps move ``x`` by ``Δt² a₀`` terms. ``V₀`` counts ``½ Δt² a₀ᵀM a₀`` for them (the size
  of ``a₀`` in energy; Newmark's algorithmic energy carries it with weight ``β − γ/2``).
  A velocity in a stiff, heavily damped mode has a huge ``a₀`` (``C y₀``), and so has a
  displacement in a stiff mode (``S x₀``).
* *Overshoot*: HHT and generalized-α, started with energy in a mode of large ``Ω = ωΔt``,
  raise it by ``∝ Ω²`` within their first steps, then damp it (by ``ρ∞`` a step); measured
  on the 40-element steel cantilever at ``Δt = T₁``, 1.4e10 ``V₀`` at step 10, 2.1e3 at
  step 64. So the first check comes after step :data:`CHECK_EVERY` = 64, and a run shorter
  than that is not checked.

Measured, with those two (``tests/structural/test_structural_divergence.py``): every mode of
every scheme, ``Ω`` from 1e-2 to 1e6 (up to 0.999 of a critical ``Ω``), damping ratio 0 to
0.99, started from a displacement, a velocity or a step load, stepped by its own
amplification matrix: ``V/B`` at the checks is at most 1.0 for the unconditionally stable
schemes, and at 0.999 of their limit 993 for the semi-implicit scheme (its modified energy,
``(1 + z/2)/(1 − z/2)`` with ``z = ω_max Δt``: it passes 1e6 only within 2·10⁻⁶ of the
limit) and 497 for central difference and linear acceleration. With heavily damped modes
too (``ξ`` up to 1e5, ``Ω`` up to 1e8) no check fires, except for Newmark with
``β = 0.3025, γ = 0.6`` from ``Ω ≈ 1e7``: its computed step amplifies round-off by 1.24 a
step where the exact one damps by 0.82 (in 60-digit arithmetic ``V/B`` stays below 8.3 at
the checks), so the run really does blow up, and the check says so.
Linear systems with Rayleigh damping decouple into such modes, and ``B`` of a system bounds
the sum of its modes' (Minkowski), so the modal numbers hold for any such system.

``P`` needs a solve with ``M``. Most runs never need it: with the step matrix ``A ≥ M``
already factorised, ``P_A = √(fᵀA⁻¹f/2) ≤ P`` costs one substitution, and the loops check
against ``B`` with ``P_A``, never larger than the true bound. Only when that check fails is
``P`` computed (:meth:`EnergyWatch.confirms`), and the run goes on if the true bound holds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from tumble.structural.factorization import factorize
from tumble.structural.system import LinearSystem

GROWTH_LIMIT = 1e6
"""A run fails when its energy passes this many times what its start and its loads can
supply (module docstring)."""

CHECK_EVERY = 64
"""The loops check the energy at every multiple of this many steps, and at a run's last
step when it has at least that many (module docstring: why not sooner)."""


def mechanical_energy(system: LinearSystem, x: NDArray, y: NDArray, q: NDArray) -> float:
    """``V = ½ yᵀM y + ½ xᵀS x`` [J], with ``S x = f − q`` from the carried ``q``."""
    return 0.5 * float(y @ (system.M @ y)) + 0.5 * float(x @ (system.f - q))


def load_power(system: LinearSystem, solve: Callable[[NDArray], NDArray] | None = None) -> float:
    """``P = √(fᵀ K⁻¹ f / 2)`` [√J/s] with ``solve`` applying ``K⁻¹`` (by default ``M``'s)."""
    f = system.f
    if not f.any():
        return 0.0
    solve = factorize(system.M) if solve is None else solve
    return math.sqrt(max(float(f @ solve(f)), 0.0) / 2)


def lower_band(M: sp.spmatrix, order: NDArray[np.intp]) -> NDArray[np.float64]:
    """``band[p, j] = M[p, p − j]`` in the DOF ``order`` (0 where ``p < j``), shape
    (n, b + 1): what :func:`~tumble.structural.kernels.energy_exceeds` reads."""
    permuted = sp.csr_matrix(M)[order][:, order]
    lower = sp.tril(permuted).tocoo()
    band = np.zeros((order.size, int(np.max(lower.row - lower.col, initial=0)) + 1))
    band[lower.row, lower.row - lower.col] = lower.data
    return band


def diagonal_bound(M: sp.spmatrix) -> float:
    """``c`` with ``yᵀM y ≤ c yᵀD y``, ``D = diag M``: Gershgorin's bound on the largest
    eigenvalue of ``D^{-½} M D^{-½}``, its largest absolute row sum (2.78 for the consistent
    mass of the beams here, at any element count)."""
    scale = sp.diags(1.0 / np.sqrt(M.diagonal()))
    return float(abs(scale @ M @ scale).sum(axis=1).max())


@dataclass
class EnergyWatch:
    """A run's bound ``B(t) = (√V₀ + P t)²`` and what the loops need to check it.

    Attributes
    ----------
    system : LinearSystem
    initial : float
        ``V₀`` [J], with ``½ Δt² a₀ᵀM a₀`` for a scheme that carries the acceleration.
    power : float
        The ``P`` the loops check with [√J/s]: ``P_A`` until :meth:`confirms` has computed
        the true one.
    exact : bool
        Whether ``power`` is the true ``P``.
    every : int
        Steps between checks (:data:`CHECK_EVERY` when the watch was made).
    final : int
        The run's last step, checked too when it is at least ``every`` (-1: unknown).
    energy : float
        The energy at the check that failed [J] (NaN until one has).
    """

    system: LinearSystem
    initial: float
    power: float
    exact: bool
    every: int = CHECK_EVERY
    final: int = -1
    energy: float = math.nan
    _arrays: tuple | None = field(default=None, repr=False)

    @classmethod
    def start(
        cls, system: LinearSystem, x: NDArray, y: NDArray, q: NDArray, solve,
        acceleration: float = 0.0,
    ) -> EnergyWatch:  # fmt: skip
        """The watch from the initial state; ``solve`` applies ``A⁻¹`` (``A ≥ M``);
        ``acceleration`` is ``½ Δt² a₀ᵀM a₀`` [J] for a scheme that carries ``a``."""
        initial = max(mechanical_energy(system, x, y, q), 0.0) + acceleration
        exact = not system.f.any()
        power = 0.0 if exact else load_power(system, solve)
        return cls(system, initial, power, exact, CHECK_EVERY)

    def checks(self, step: int) -> bool:
        """Whether the loops check after ``step``."""
        return step % self.every == 0 or (step == self.final and step >= self.every)

    def bound(self, t: float) -> float:
        """``B(t)`` [J] with the current ``power``."""
        return (math.sqrt(self.initial) + self.power * t) ** 2

    def exceeds(self, t: float, energy: float) -> bool:
        """Whether ``energy`` at ``t`` passes :data:`GROWTH_LIMIT` times the bound."""
        return not energy <= GROWTH_LIMIT * self.bound(t)

    def confirms(self, t: float, energy: float) -> bool:
        """A loop found ``energy`` past the bound at ``t``: True if the true bound is passed
        too (the run has diverged), after computing the true ``P`` if not yet done."""
        if not self.exact:
            self.power, self.exact = load_power(self.system), True
        if self.exceeds(t, energy):
            self.energy = energy
            return True
        return False

    def kernel(self, order: NDArray[np.intp]) -> tuple:
        """``(every, final, √V₀, P, GROWTH_LIMIT, mass, f, c)`` as the compiled loops read
        it: ``mass`` is :func:`lower_band` of ``M``, ``f`` the loads, in the DOF ``order``,
        and ``c`` :func:`diagonal_bound` (the three made at the first call: a run asks again
        at every block, with only ``P`` changed by :meth:`confirms`)."""
        if self._arrays is None:
            M, f = self.system.M, self.system.f
            self._arrays = (lower_band(M, order), np.ascontiguousarray(f[order]),
                            diagonal_bound(M))  # fmt: skip
        final = self.final if self.final >= self.every else -1
        return (
            self.every,
            final,
            math.sqrt(self.initial),
            self.power,
            GROWTH_LIMIT,
            *self._arrays,
        )

    def message(self, t_old: float, t_new: float) -> str:
        """What a run whose check failed at ``t_new`` says (before its likely cause); it
        ends at ``t_old``, the step before."""
        bound = self.bound(t_new)
        growth = self.energy / bound if bound > 0 else math.inf
        return (
            f"at t={t_new!r} s the energy ½yᵀMy + ½xᵀSx = {self.energy:.3g} J had grown "
            f"{growth:.2g}× beyond what the initial state and the loads can supply "
            f"((√V₀ + P t)² = {bound:.3g} J with V₀ = {self.initial:.3g} J and "
            f"P = |f|_M⁻¹/√2 = {self.power:.3g} √J/s); the run ends with the state of the step "
            f"before, t={t_old!r}"
        )


def likely_cause(system: LinearSystem, scheme, dt: float) -> str:
    """Why a run of ``scheme`` at ``dt`` probably diverged: its step against the critical
    one (:func:`~tumble.structural.critical_dt`), with the numbers."""
    from tumble.structural.stability import critical_dt, highest_mode

    critical = critical_dt(system, scheme)
    name = describe(scheme)
    if critical.dt == 0.0:
        return (
            f"{name} is unstable at every dt (every mode grows at every step, the highest "
            "fastest); use 'semi-implicit' below its critical step, or an implicit scheme"
        )
    if math.isinf(critical.dt):
        omega = highest_mode(system)[0]
        return (
            f"{name} is stable at every dt in exact arithmetic, but at ω_max Δt = "
            f"{omega * dt:.3g} its computed step can amplify round-off (Newmark with γ = 0.6 "
            "did from about 1e7), and a system too ill-conditioned for double precision "
            "(IllConditionedWarning) or a state near overflow can make the numbers grow; "
            "try a smaller dt, or 'newmark', 'midpoint' or 'bathe'"
        )
    ratio = dt / critical.dt
    where = f"set by the highest mode, {critical.mode}, ω_max = {critical.omega:.4g} rad/s"
    if ratio < 1:
        return (
            f"dt = {dt:.3g} s is {ratio:.6g}× the scheme's critical step {critical.dt:.3g} s "
            f"({name}; {where}): {'at the limit itself' if ratio > 0.99 else 'below it'}; "
            "take dt clearly below it, or look for a state or load too large for double "
            "precision"
        )
    return (
        f"dt = {dt:.3g} s is {ratio:.3g}× the scheme's critical step {critical.dt:.3g} s "
        f"({name}; {where}); take dt below {critical.dt:.3g} s, or an unconditionally stable "
        "scheme ('newmark', 'midpoint', 'hht', 'generalized-alpha', 'bathe')"
    )


def describe(scheme) -> str:
    """A scheme by its ``label`` (:class:`~tumble.structural.scheme.Scheme`: ``the
    implicit scheme``, or with its parameters, ``Newmark β=1/6, γ=1/2``)."""
    return scheme.label
