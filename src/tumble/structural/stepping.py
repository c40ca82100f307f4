"""How one step is computed, twice: a readable NumPy reference and the compiled loop.

Every scheme of :mod:`tumble.structural.schemes` is the same increment step with four
constants (:class:`Increments`). With ``r = q − C y``, ``q = f − S x`` and, for Newmark with
``2β ≠ γ``, ``a = M⁻¹ r``:

.. math::

    A\\, Δy = Δt\\,(r - k_{sa}\\, S a - k_g\\, S y), \\qquad
    Δx = Δt\\, y + k_{dy}\\, Δy + k_a\\, a,

then ``x += Δx``, ``y += Δy`` and ``q −= S Δx``. Every product with ``S`` is summed
element by element (:meth:`~tumble.structural.system.LinearSystem.internal_forces`), and the
out-of-balance force ``q`` is carried along, never formed as ``f − S x`` from the global
matrix: on fine meshes (``κ(S) ∝ N⁴``) that is a difference of huge numbers, and carrying
the small ``q`` rounds it relative to its own size. ``S y`` is summed afresh each step
(carrying it too made the midpoint energy drift 10× faster, measured). A step costs one
solve with the constant ``A`` and one pass over the elements for ``S Δx`` and ``S y``
(plus a mass solve and ``S a`` for Newmark with ``2β ≠ γ``).

:class:`ReferenceStepper` runs it in Python with SuperLU (:func:`~tumble.structural.
factorization.factorize`); :class:`CompiledStepper` runs the same operations in the same
order in :func:`tumble.structural.kernels.run_steps`, with the banded Cholesky of
:class:`~tumble.structural.factorization.BandedCholesky`, many steps per call. Both are
steppers of the one driver, :func:`tumble.ode.driver.march`, which owns the time loop.
Tests check that the two agree to round-off.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from tumble._progress import announce_compilation
from tumble.ode.driver import Block, Grid, Stepper, non_finite_message
from tumble.structural.divergence import EnergyWatch, mechanical_energy
from tumble.structural.factorization import BandedCholesky, factorize
from tumble.structural.kernels import all_finite, run_steps
from tumble.structural.system import LinearSystem


@dataclass(frozen=True)
class Increments:
    """The constants of one increment step (module docstring), for a scheme and a Δt.

    Attributes
    ----------
    dt : float
        Time step Δt [s].
    k_g : float
        [s]: ``θ_x Δt`` for a θ-scheme, ``γ Δt`` for Newmark.
    k_dy : float
        [s]: ``θ_y Δt``, or ``(β/γ) Δt``.
    k_sa : float
        [s²]: ``(γ/2 − β) Δt²`` for Newmark, else 0.
    k_a : float
        [s²]: ``(½ − β/γ) Δt²`` for Newmark, else 0.
    """

    dt: float
    k_g: float
    k_dy: float
    k_sa: float = 0.0
    k_a: float = 0.0

    @property
    def mass_solve(self) -> bool:
        """Whether a step needs ``a = M⁻¹ r`` (Newmark with ``2β ≠ γ``)."""
        return self.k_sa != 0.0 or self.k_a != 0.0


@dataclass
class State:
    """The stepped state: ``x``, ``y``, ``q = f − S x`` (carried) and ``g = S y`` (summed)."""

    x: NDArray[np.float64]
    y: NDArray[np.float64]
    q: NDArray[np.float64]
    g: NDArray[np.float64]

    @classmethod
    def start(cls, system: LinearSystem, x: NDArray, y: NDArray) -> State:
        """The state at ``(x, y)``, with ``S x`` and ``S y`` summed element by element."""
        return cls(x, y, system.f - system.internal_forces(x), system.internal_forces(y))

    def vectors(self) -> tuple[NDArray, ...]:
        """Every vector of the state, in field order (a subclass may carry more)."""
        return tuple(getattr(self, f.name) for f in fields(self))

    def copy(self) -> State:
        """A deep copy (every vector copied)."""
        return type(self)(*(v.copy() for v in self.vectors()))

    def permuted(self, order: NDArray) -> State:
        """The state with every vector taken in ``order`` (contiguous copies)."""
        return type(self)(*(np.ascontiguousarray(v[order]) for v in self.vectors()))


Solve = Callable[[NDArray], NDArray]


def reference_step(
    state: State,
    k: Increments,
    system: LinearSystem,
    solve: Solve,
    solve_mass: Solve | None,
    C: sp.spmatrix | None,
) -> None:
    """One increment step (module docstring) in NumPy, updating ``state`` in place."""
    forces = system.internal_forces
    r = state.q.copy()
    if C is not None:
        r -= C @ state.y
    rhs = r
    if solve_mass is not None:
        a = solve_mass(r)
        rhs = r - k.k_sa * forces(a)
    dy = solve(k.dt * (rhs - k.k_g * state.g))
    dx = k.dt * state.y + k.k_dy * dy
    if solve_mass is not None:
        dx += k.k_a * a
    state.x += dx
    state.y += dy
    state.q -= forces(dx)
    if k.k_g:
        state.g = forces(state.y)


class Watched(Stepper):
    """What every structural stepper shares: the energy check of
    :mod:`tumble.structural.divergence` (:attr:`watch`, made from the initial state by
    :meth:`start`) and the message of a run that failed it."""

    system: LinearSystem
    watch: EnergyWatch
    solve: Solve
    """``A⁻¹`` of the step matrix (``A ≥ M``), for the watch's first bound."""
    failed_check = False

    def start(self, state: State) -> State:
        """The stepped state: ``state`` itself, and the watch from it."""
        self.watch = EnergyWatch.start(
            self.system, state.x, state.y, state.q, self.solve, self.acceleration_energy(state)
        )
        return state

    def acceleration_energy(self, state: State) -> float:
        """``½ Δt² a₀ᵀM a₀`` [J] of a scheme that carries the acceleration, else 0
        (:mod:`~tumble.structural.divergence`: part of what its start supplies)."""
        return 0.0

    def failure(self, t_old: float, t_new: float) -> str:
        if self.failed_check:
            return self.watch.message(t_old, t_new)
        return non_finite_message(t_old, t_new)


class Reference(Watched):
    """A NumPy reference stepper: ``advance(state)`` in place, on a copy of each state, so
    that a failed step leaves the last good one; the energy checked as in the compiled
    loops, every :data:`~tumble.structural.divergence.CHECK_EVERY` steps of ``dt``."""

    dt: float

    def advance(self, state: State) -> None:
        raise NotImplementedError

    def step(self, t: float, state: State, h: float) -> tuple[State, None]:
        new = state.copy()
        self.advance(new)
        self.step_index = round((t + h) / self.dt)
        return new, None

    def finite(self, state: State) -> bool:
        if not all_finite(state.x, state.y):
            return False
        if not self.watch.checks(self.step_index):
            return True
        t = self.step_index * self.dt
        energy = mechanical_energy(self.system, state.x, state.y, state.q)
        self.failed_check = self.watch.exceeds(t, energy) and self.watch.confirms(t, energy)
        return not self.failed_check

    def record(self, state: State) -> tuple:
        return state.x[None].copy(), state.y[None].copy()


class ReferenceStepper(Reference):
    """The NumPy reference as a stepper of :func:`tumble.ode.driver.march`: SuperLU, one
    :func:`reference_step` a step."""

    def __init__(self, system: LinearSystem, k: Increments, A: sp.spmatrix, C):
        self.system, self.k, self.C, self.dt = system, k, C, k.dt
        self.solve = factorize(A)
        self.solve_mass = factorize(system.M) if k.mass_solve else None

    def advance(self, state: State) -> None:
        reference_step(state, self.k, self.system, self.solve, self.solve_mass, self.C)

    def acceleration_energy(self, state: State) -> float:
        return _acceleration_energy(self.system, state, self.C, self.solve_mass, self.dt)


class CompiledStepper(Watched):
    """:func:`~tumble.structural.kernels.run_steps` as a stepper of the driver: blocks of
    steps compiled, with the banded Cholesky of :class:`~tumble.structural.factorization.
    BandedCholesky`.

    Everything is put in the factor's DOF order (``factor.order``) once, so the loop never
    permutes; :meth:`record` and the blocks' records put it back. A block that meets a
    non-finite state, or fails the energy check, is replayed from its start to the step
    before (the same operations, so the same numbers): the run keeps its last good state at
    no cost per step. A check that fails only the first bound (``P_A``, module
    :mod:`~tumble.structural.divergence`) goes on from where it stopped with the true one.
    """

    blocks = True
    solve_mass: Solve | None = None

    def __init__(self, system: LinearSystem, k: Increments, factor: BandedCholesky, C, block):
        mass = BandedCholesky.from_matrix(system.M, factor.order) if k.mass_solve else factor
        self.prepare(system, (factor, mass), C, block)
        self.C, self.solve_mass = C, mass.solve if k.mass_solve else None
        self.coefficients = (k.dt, k.k_g, k.k_dy, k.k_sa, k.k_a)
        self.work = tuple(np.zeros(self.order.size) for _ in range(4))

    def prepare(self, system: LinearSystem, factors: tuple[BandedCholesky, ...], C, block) -> None:
        """What every compiled loop reads, in the first factor's DOF order: the factors
        (padded to one bandwidth, for which the loop is compiled), the element arrays, the
        damping matrix as CSR; and the number of steps per block."""
        order = factors[0].order
        self.order, self.inverse = order, np.empty_like(order)
        self.inverse[order] = np.arange(order.size)
        b = max(factor.bandwidth for factor in factors)
        self.factors = tuple(_kernel_factor(_padded(factor, b)) for factor in factors)
        dof_map, *element_arrays = system.elements.kernel_arrays
        permuted_map = np.where(dof_map >= 0, self.inverse[np.maximum(dof_map, 0)], -1)
        self.frame = (permuted_map.astype(np.int32), *element_arrays)
        self.damping = _csr_arrays(None if C is None else sp.csr_matrix(C)[order][:, order])
        self.block_steps = block
        self.system, self.solve = system, factors[0].solve

    def start(self, state: State) -> State:
        """``state`` in the factor's DOF order, and the watch from it."""
        super().start(state)
        return state.permuted(self.order)

    def record(self, state: State) -> tuple:
        return state.x[self.inverse][None], state.y[self.inverse][None]

    def acceleration_energy(self, state: State) -> float:
        if self.solve_mass is None:
            return 0.0
        dt = self.coefficients[0]
        return _acceleration_energy(self.system, state, self.C, self.solve_mass, dt)

    def _run(self, state: State, k0: int, k1: int, steps: NDArray[np.int64], row: int, xs, ys):
        vectors = (state.x, state.y, state.q, state.g)
        announce_compilation(run_steps, "the structural time loop")
        factor, mass = self.factors
        return run_steps(k0, k1, steps, row, self.coefficients, vectors, self.frame, factor,
                         mass, self.damping, self.work, self.checks, xs, ys)  # fmt: skip

    def march_block(
        self, state: State, grid: Grid, k0: int, k1: int, every: int, step0: int
    ) -> Block:
        k = np.arange(k0 + 1, k1 + 1)
        steps = k[(step0 + k) % every == 0]
        n = self.order.size
        xs, ys = np.empty((steps.size + 1, n)), np.empty((steps.size + 1, n))
        start = state.copy()
        steps_padded = np.append(steps, -1)  # the kernel reads one entry past its last record
        self.checks = self.watch.kernel(self.order)
        rows, failed, energy = self._run(state, k0, k1, steps_padded, 0, xs, ys)
        while failed >= 0 and not energy < 0:  # a failed energy check (-1.0: non-finite)
            self.failed_check = self.watch.confirms(grid.time(failed), energy)
            if self.failed_check:
                break
            self.checks = self.watch.kernel(self.order)  # the true bound holds: go on
            rows, failed, energy = self._run(state, failed, k1, steps_padded, rows, xs, ys)
        if failed >= 0:  # replay to the step before, from the block's start
            state, rows = start, int(np.searchsorted(steps, failed))
            self._run(state, k0, failed - 1, steps_padded, 0, xs, ys)
        times = np.array([grid.time(int(step)) for step in steps[:rows]])
        return Block(
            times, (xs[:rows][:, self.inverse], ys[:rows][:, self.inverse]), state, failed
        )


def _acceleration_energy(system: LinearSystem, state: State, C, solve_mass, dt: float) -> float:
    """``½ Δt² a₀ᵀM a₀`` with ``M a₀ = q − C y`` for Newmark with ``2β ≠ γ`` (which carries
    ``a``); 0 without a mass solve."""
    if solve_mass is None:
        return 0.0
    r = state.q - (0.0 if C is None else C @ state.y)
    return 0.5 * dt * dt * max(float(solve_mass(r) @ r), 0.0)


def _kernel_factor(factor: BandedCholesky) -> tuple:
    return factor.forward, factor.backward, factor.inverse_diagonal, factor.window


def _padded(factor: BandedCholesky, b: int) -> BandedCholesky:
    """The same factor with zero coefficients added so that its bandwidth is ``b``."""
    if factor.bandwidth == b:
        return factor
    extra = np.zeros((factor.order.size, b - factor.bandwidth))
    return BandedCholesky(
        factor.order,
        np.hstack([extra, factor.forward]),
        np.hstack([extra, factor.backward]),
        factor.inverse_diagonal,
    )


def _csr_arrays(C: sp.csr_matrix | None) -> tuple[NDArray, NDArray, NDArray]:
    if C is None:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0)
    return C.indptr.astype(np.int64), C.indices.astype(np.int64), C.data.astype(float)
