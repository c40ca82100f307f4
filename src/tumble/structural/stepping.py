"""How a scheme is stepped, twice: a NumPy reference and the one compiled loop.

Every scheme of :data:`tumble.structural.SCHEMES` is a
:class:`~tumble.structural.scheme.Scheme`: constant step matrices, factorised once, and a
step that updates a :class:`BeamState` in place. The state carries the out-of-balance force
``q = f − S x``, updated by ``S Δx`` summed element by element
(:meth:`~tumble.structural.system.LinearSystem.internal_forces`) and never formed as
``f − S x`` from the global matrix: on fine meshes (``κ(S) ∝ N⁴``) that is a difference of
huge numbers, and carrying the small ``q`` rounds it relative to its own size.

Two steppers of the one driver, :func:`tumble.ode.driver.march` (which owns the run), take
any scheme:

- :class:`ReferenceBeamStepper` runs the scheme's NumPy step
  (:meth:`~tumble.structural.scheme.Scheme.step`) with SuperLU
  (:func:`~tumble.structural.factorization.factorize`), one Python call a step;
- :class:`CompiledBeamStepper` runs its compiled twin
  (:attr:`~tumble.structural.scheme.Scheme.kernel`) inside the one time loop
  (:func:`tumble.structural.kernels.time_loop`) with the banded Cholesky of
  :class:`~tumble.structural.factorization.BandedCholesky`, many steps per call.

Both watch the energy (:mod:`tumble.structural.divergence`) every
:data:`~tumble.structural.divergence.CHECK_EVERY` steps; tests check that the two agree to
round-off for every scheme.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, ClassVar

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from tumble._progress import announce_compilation
from tumble.ode.driver import Block, Compiled, Grid, Stepper, non_finite_message
from tumble.structural.divergence import EnergyWatch, mechanical_energy
from tumble.structural.factorization import BandedCholesky, factorize
from tumble.structural.kernels import BeamKernelProblem, BeamRecords, all_finite
from tumble.structural.system import LinearSystem

if TYPE_CHECKING:
    from tumble.structural.scheme import Scheme

Solve = Callable[[NDArray], NDArray]


@dataclass
class BeamState:
    """The stepped state: ``x``, ``y``, ``q = f − S x`` (carried) and ``g``, a product with
    ``S`` that the next step needs (``S y`` for the increment schemes; each scheme says).

    A scheme that carries more (the acceleration, …) subclasses it with more fields;
    :attr:`MODAL` names the fields that make up its state on one mode (the amplification
    matrix acts on them).
    """

    x: NDArray[np.float64]
    y: NDArray[np.float64]
    q: NDArray[np.float64]
    g: NDArray[np.float64]

    MODAL: ClassVar[tuple[str, ...]] = ("x", "y")

    @classmethod
    def start(cls, system: LinearSystem, x: NDArray, y: NDArray) -> BeamState:
        """The state at ``(x, y)``, with ``S x`` and ``S y`` summed element by element."""
        return cls(x, y, system.f - system.internal_forces(x), system.internal_forces(y))

    def vectors(self) -> tuple[NDArray, ...]:
        """Every vector of the state, in field order (the compiled step's ``state``)."""
        return tuple(getattr(self, f.name) for f in fields(self))

    def copy(self) -> BeamState:
        """A deep copy (every vector copied)."""
        return type(self)(*(v.copy() for v in self.vectors()))

    def permuted(self, order: NDArray) -> BeamState:
        """The state with every vector taken in ``order`` (contiguous copies)."""
        return type(self)(*(np.ascontiguousarray(v[order]) for v in self.vectors()))

    def modal(self) -> list[float]:
        """The :attr:`MODAL` fields of a one-DOF state, as numbers."""
        return [float(getattr(self, name)[0]) for name in self.MODAL]


def initial_state(
    scheme: Scheme, system: LinearSystem, state: BeamState, C: sp.spmatrix | None, dt: float
) -> tuple[BeamState, float]:
    """The scheme's stepped state from ``(x₀, y₀)``, and what its start adds to the energy
    the watch allows for.

    A scheme that :attr:`~tumble.structural.scheme.Scheme.carries_acceleration` starts from
    ``a₀ = M⁻¹ r₀`` (``r₀ = q₀ − C y₀``, SuperLU of ``M``), whose ``Δt²`` terms move ``x``
    in the first steps: ``½ Δt² a₀ᵀM a₀`` [J] is added to ``V₀``
    (:mod:`~tumble.structural.divergence`). Otherwise the energy term is 0.
    """
    if not scheme.carries_acceleration:
        return scheme.start(system, state, C, dt, None), 0.0
    r = state.q - (0.0 if C is None else C @ state.y)
    a = factorize(system.M)(r)
    extra = 0.5 * dt * dt * max(float(a @ r), 0.0)
    return scheme.start(system, state, C, dt, (a, r)), extra


class Watched(Stepper):
    """What both structural steppers share: the energy check of
    :mod:`tumble.structural.divergence` (:attr:`watch`, made from the initial state by
    :meth:`start`), whose message ends a run that fails it."""

    system: LinearSystem
    watch: EnergyWatch
    solve: Solve
    """``A⁻¹`` of the first step matrix (``A ≥ M``), for the watch's first bound."""

    def start(self, state: BeamState, acceleration_energy: float = 0.0) -> BeamState:
        """The stepped state: ``state`` itself, and the watch from it (with
        ``acceleration_energy``, :func:`initial_state`'s second result)."""
        self.watch = EnergyWatch.start(
            self.system, state.x, state.y, state.q, self.solve, acceleration_energy
        )
        return state


class ReferenceBeamStepper(Watched):
    """The NumPy reference of any scheme as a stepper of :func:`tumble.ode.driver.march`:
    SuperLU of each step matrix, one :meth:`~tumble.structural.scheme.Scheme.step` a step,
    on a copy of each state (so that a failed step leaves the last good one); the energy
    checked as in the compiled loop, every :data:`~tumble.structural.divergence.CHECK_EVERY`
    steps."""

    def __init__(
        self, system: LinearSystem, scheme: Scheme, C: sp.spmatrix | None, dt: float,
        matrices: list[sp.spmatrix],
    ) -> None:  # fmt: skip
        self.system, self.scheme, self.C, self.dt = system, scheme, C, dt
        self.coefficients = scheme.coefficients(dt)
        self.solves = [factorize(A) for A in matrices]
        self.solve = self.solves[0]

    def step(self, t: float, state: BeamState, h: float) -> tuple[BeamState, None]:
        new = state.copy()
        self.scheme.step(new, self.system, self.solves, self.C, self.coefficients)
        self.step_index = round((t + h) / self.dt)
        return new, None

    def accept(self, t_old: float, old: BeamState, t_new: float, new: BeamState) -> str | None:
        """A state that is not finite is refused, and so is one whose energy fails the
        watch's check (at its steps)."""
        if not all_finite(new.x, new.y):
            return non_finite_message(t_old, t_new)
        if not self.watch.checks(self.step_index):
            return None
        t = self.step_index * self.dt
        energy = mechanical_energy(self.system, new.x, new.y, new.q)
        if self.watch.exceeds(t, energy) and self.watch.confirms(t, energy):
            return self.watch.message(t_old, t_new)
        return None

    def record(self, state: BeamState) -> tuple:
        return state.x[None].copy(), state.y[None].copy()


class CompiledBeamStepper(Watched):
    """Any scheme's compiled step in the one time loop
    (:func:`~tumble.structural.kernels.time_loop`), as a stepper of the driver with a
    compiled part only: blocks of steps compiled, with the banded Cholesky factors of the
    scheme's step matrices.

    Everything is put in the first factor's DOF order (``factor.order``) once, so the loop
    never permutes; :meth:`record` and the blocks' records put it back. A block that meets
    a non-finite state, or fails the energy check, is replayed from its start to the step
    before (the same operations, so the same numbers): the run keeps its last good state at
    no cost per step. A check that fails only the first bound (``P_A``, module
    :mod:`~tumble.structural.divergence`) goes on from where it stopped with the true one.
    """

    def __init__(
        self, system: LinearSystem, scheme: Scheme, C: sp.spmatrix | None, dt: float,
        factors: list[BandedCholesky], block: int,
    ) -> None:  # fmt: skip
        order = factors[0].order
        self.order, self.inverse = order, np.empty_like(order)
        self.inverse[order] = np.arange(order.size)
        b = max(factor.bandwidth for factor in factors)  # the loop is compiled for one
        self.factors = tuple(_kernel_factor(_padded(factor, b)) for factor in factors)
        dof_map, *element_arrays = system.elements.kernel_arrays
        permuted_map = np.where(dof_map >= 0, self.inverse[np.maximum(dof_map, 0)], -1)
        self.frame = (permuted_map.astype(np.int32), *element_arrays)
        self.damping = _csr_arrays(None if C is None else sp.csr_matrix(C)[order][:, order])
        self._block = block
        self.system, self.solve = system, factors[0].solve
        self.kernel, self.what = scheme.kernel, f"the structural time loop ({scheme.name})"
        self.coefficients = scheme.coefficients(dt)
        self.work = tuple(np.zeros(order.size) for _ in range(self.kernel.work))
        self.lag = self.work[self.kernel.lag] if self.kernel.lag >= 0 else np.zeros(0)
        self.energy = np.full(1, -1.0)

    @property
    def compiled(self) -> Compiled:
        """The time loop as the compiled part (made when asked: no reference cycle)."""
        return Compiled(self._march_block, block_steps=self._block)

    def start(self, state: BeamState, acceleration_energy: float = 0.0) -> BeamState:
        """``state`` in the factor's DOF order, and the watch from it."""
        super().start(state, acceleration_energy)
        return state.permuted(self.order)

    def record(self, state: BeamState) -> tuple:
        return state.x[self.inverse][None], state.y[self.inverse][None]

    def _run(self, state: BeamState, grid: Grid, k0: int, k1: int, every: int, step0: int,
             records: BeamRecords) -> tuple[int, int, float]:  # fmt: skip
        """Steps ``k0 + 1 … k1`` in the loop: the rows recorded, the step where it stopped
        (or -1) and ``V`` of a failed check (-1.0: a non-finite state, or none)."""
        loop = self.kernel.loop
        announce_compilation(loop, self.what)
        self.energy[0] = -1.0
        problem = BeamKernelProblem(self.coefficients, self.frame, self.factors, self.damping,
                                    self.work, self.lag, self.checks, self.energy)  # fmt: skip
        rows, failed, _ = loop(problem, grid, state.vectors(), k0, k1, every, step0, records)
        return rows, failed, float(self.energy[0])

    def _march_block(
        self, state: BeamState, grid: Grid, k0: int, k1: int, every: int, step0: int
    ) -> Block:
        first = k0 + 1 + (-(step0 + k0 + 1)) % every  # the first step recorded
        size = max(0, (k1 - first) // every + 1)
        n = self.order.size
        records = BeamRecords(np.empty(size), np.empty((size, n)), np.empty((size, n)))
        start = state.copy()
        self.checks = self.watch.kernel(self.order)
        rows, failed, energy = self._run(state, grid, k0, k1, every, step0, records)
        diverged = False
        while failed >= 0 and not energy < 0:  # a failed energy check (-1.0: non-finite)
            diverged = self.watch.confirms(grid.time(failed), energy)
            if diverged:
                break
            self.checks = self.watch.kernel(self.order)  # the true bound holds: go on
            more, failed, energy = self._run(state, grid, failed, k1, every, step0,
                                             records.after(rows))  # fmt: skip
            rows += more
        message = None
        if failed >= 0:  # replay to the step before, from the block's start
            state = start
            rows, _, _ = self._run(state, grid, k0, failed - 1, every, step0, records)
            if diverged:
                message = self.watch.message(grid.time(failed - 1), grid.time(failed))
        xs, ys = records.x[:rows][:, self.inverse], records.y[:rows][:, self.inverse]
        return Block(records.t[:rows], (xs, ys), state, failed, message=message)


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
