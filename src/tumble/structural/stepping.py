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

:func:`reference_loop` runs it in Python with SuperLU (:func:`~tumble.structural.
factorization.factorize`); :func:`compiled_loop` runs the same operations in the same
order in :func:`tumble.structural.kernels.run_steps`, with the banded Cholesky of
:class:`~tumble.structural.factorization.BandedCholesky`, many steps per call. Tests check
that the two agree to round-off.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

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


Solve = Callable[[NDArray], NDArray]
Records = tuple[NDArray, NDArray, int, int]
"""``(xs, ys, rows, diverged)``: records, rows filled, the step of divergence or -1."""


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


def reference_loop(
    system: LinearSystem,
    k: Increments,
    A: sp.spmatrix,
    C: sp.spmatrix | None,
    state: State,
    record_steps: NDArray[np.int64],
    advance: Callable[[int], None],
    block: int,
) -> Records:
    """Step in Python with SuperLU; record at ``record_steps``; ``advance`` every ``block``."""
    solve = factorize(A)
    solve_mass = factorize(system.M) if k.mass_solve else None
    xs, ys = _records(record_steps.size, state)
    row = 1
    for step in range(1, int(record_steps[-1]) + 1):
        reference_step(state, k, system, solve, solve_mass, C)
        finite = all_finite(state.x, state.y)
        if not finite or step == record_steps[row]:
            xs[row], ys[row], row = state.x, state.y, row + 1
            if not finite:
                return xs, ys, row, step
        if step % block == 0:
            advance(block)
    return xs, ys, row, -1


def compiled_loop(
    system: LinearSystem,
    k: Increments,
    factor: BandedCholesky,
    C: sp.spmatrix | None,
    state: State,
    record_steps: NDArray[np.int64],
    advance: Callable[[int], None],
    block: int,
) -> Records:
    """Step in :func:`~tumble.structural.kernels.run_steps`, ``block`` steps per call.

    Everything is first put in the factor's DOF order (``factor.order``), so the loop
    never permutes; the records are put back at the end.
    """
    order = factor.order
    inverse = np.empty_like(order)
    inverse[order] = np.arange(order.size)
    mass = BandedCholesky.from_matrix(system.M, order) if k.mass_solve else factor
    b = max(factor.bandwidth, mass.bandwidth)  # the loop is compiled for one bandwidth
    factor, mass = _padded(factor, b), _padded(mass, b)
    dof_map, *element_arrays = system.elements.kernel_arrays
    permuted_map = np.where(dof_map >= 0, inverse[np.maximum(dof_map, 0)], -1).astype(np.int32)
    frame = (permuted_map, *element_arrays)
    permuted = [np.ascontiguousarray(v[order]) for v in (state.x, state.y, state.q, state.g)]
    damping = _csr_arrays(None if C is None else sp.csr_matrix(C)[order][:, order])
    n = order.size
    work = tuple(np.zeros(n) for _ in range(4))
    xs, ys = _records(record_steps.size, State(*permuted))
    row, diverged, last = 1, -1, int(record_steps[-1])
    coefficients = (k.dt, k.k_g, k.k_dy, k.k_sa, k.k_a)
    for first in range(0, last, block):
        row, diverged = run_steps(
            first,
            min(first + block, last),
            record_steps,
            row,
            coefficients,
            tuple(permuted),
            frame,
            _kernel_factor(factor),
            _kernel_factor(mass),
            damping,
            work,
            xs,
            ys,
        )
        if diverged >= 0:
            break
        advance(min(block, last - first))
    if np.array_equal(order, np.arange(order.size)):
        return xs, ys, row, diverged
    return xs[:, inverse], ys[:, inverse], row, diverged


def _records(n_records: int, state: State) -> tuple[NDArray, NDArray]:
    xs, ys = np.empty((n_records, state.x.size)), np.empty((n_records, state.y.size))
    xs[0], ys[0] = state.x, state.y
    return xs, ys


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


def block_size(n_steps: int, updates: int) -> int:
    """Steps per call so that a run advances its progress bar about ``updates`` times."""
    return max(1, math.ceil(n_steps / updates))
