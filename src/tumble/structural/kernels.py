"""Compiled kernels: internal forces ``S x`` element by element, banded solves, the time loop.

:func:`assemble_internal_forces` is :func:`tumble.structural.elements.element_forces` (the
readable NumPy reference, which a test checks this against to round-off) fused with the
scatter into the free-DOF vector, so that one call does no allocation and no Python work
per element. It takes each element's ``1/h``, ``EA/h`` and ``EI/h`` precomputed
(:attr:`tumble.structural.system.FrameElements.kernel_arrays`): without the four divisions
an element costs 3.4 ns instead of 4.7 ns (measured at 10⁴ elements).
:func:`banded_solve` is the substitution with a banded Cholesky factor.

**The time loop** is the fixed-step template of :mod:`tumble.ode.templates`, which
:func:`time_loop` binds once per step function, with the step inlined, under a name of its
own (so numba's on-disk cache keeps each): the scheme's compiled step (a
``@numba.njit(inline="always")`` function, the twin of its NumPy reference step) is its
``STEP``, the energy watch (:func:`energy_exceeds`, every
:data:`~tumble.structural.divergence.CHECK_EVERY` steps and at the last) its ``CHECK``; it
records the requested steps and stops at a non-finite state or a failed check. A step
function reads

``step(coefficients, state, frame, factors, damping, work) -> non_finite``

with the scheme's constants, its state vectors (``x, y, q = f − S x`` first, then what it
carries), the element arrays of :func:`assemble_internal_forces`, the banded factors of its
step matrices, ``C`` as CSR and its scratch vectors; it updates the state in place and
returns how many entries of ``x`` and ``y`` stopped being finite.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from tumble.ode import templates
from tumble.ode.templates import NON_FINITE, OK


@numba.njit(cache=True, nogil=True)
def assemble_internal_forces(
    x: NDArray[np.float64],
    dof_map: NDArray[np.int64],
    inverse_length: NDArray[np.float64],
    cos: NDArray[np.float64],
    sin: NDArray[np.float64],
    EA_per_length: NDArray[np.float64],
    EI_per_length: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None:
    """Write ``out = S x`` computed from each element's natural deformations.

    Per element, with ``Δu = u_j − u_i``, ``Δv = v_j − v_i``:
    ``ψ = (c Δv − s Δu)/h``, ``a = θ_i − ψ``, ``b = θ_j − ψ``, ``N = EA/h (c Δu + s Δv)``,
    ``M_i = EI/h (4a + 2b)``, ``M_j = EI/h (2a + 4b)``, ``V = (M_i + M_j)/h``; the end
    forces ``(−cN − sV, −sN + cV, M_i, cN + sV, sN − cV, M_j)`` are added into ``out``.

    Parameters
    ----------
    x : ndarray, shape (n_dofs,)
        Free-DOF vector (displacements [m, rad], or velocities, or increments).
    dof_map : ndarray of int32, shape (n_elements, 6)
        Free-DOF index of each element DOF, ``-1`` where the DOF is fixed (value 0).
    inverse_length, cos, sin, EA_per_length, EI_per_length : ndarray, shape (n_elements,)
        ``1/h`` [1/m], direction cosines, ``EA/h`` [N/m] and ``EI/h`` [N m].
    out : ndarray, shape (n_dofs,)
        Overwritten with the internal forces [N, N m].
    """
    out[:] = 0.0
    for e in range(dof_map.shape[0]):
        forces = _element_forces(
            e, x, dof_map, inverse_length, cos, sin, EA_per_length, EI_per_length
        )
        for k in range(6):
            index = dof_map[e, k]
            if index >= 0:
                out[index] += forces[k]


@numba.njit(cache=True, nogil=True)
def assemble_internal_forces_pair(
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    dof_map: NDArray[np.int64],
    inverse_length: NDArray[np.float64],
    cos: NDArray[np.float64],
    sin: NDArray[np.float64],
    EA_per_length: NDArray[np.float64],
    EI_per_length: NDArray[np.float64],
    out_x: NDArray[np.float64],
    out_y: NDArray[np.float64],
) -> None:
    """``out_x = S x`` and ``out_y = S y`` in one pass over the elements.

    The same numbers as two calls of :func:`assemble_internal_forces`, reading the element
    data once.
    """
    out_x[:] = 0.0
    out_y[:] = 0.0
    for e in range(dof_map.shape[0]):
        fx = _element_forces(e, x, dof_map, inverse_length, cos, sin, EA_per_length, EI_per_length)
        fy = _element_forces(e, y, dof_map, inverse_length, cos, sin, EA_per_length, EI_per_length)
        for k in range(6):
            index = dof_map[e, k]
            if index >= 0:
                out_x[index] += fx[k]
                out_y[index] += fy[k]


@numba.njit(cache=True, nogil=True)
def _element_forces(e, x, dof_map, inverse_length, cos, sin, EA_per_length, EI_per_length):  # noqa: ANN001, ANN202
    """Element ``e``'s six end forces for the free-DOF values ``x`` (a tuple: registers)."""
    i0, i1, i2 = dof_map[e, 0], dof_map[e, 1], dof_map[e, 2]
    i3, i4, i5 = dof_map[e, 3], dof_map[e, 4], dof_map[e, 5]
    u_i = x[i0] if i0 >= 0 else 0.0
    v_i = x[i1] if i1 >= 0 else 0.0
    theta_i = x[i2] if i2 >= 0 else 0.0
    u_j = x[i3] if i3 >= 0 else 0.0
    v_j = x[i4] if i4 >= 0 else 0.0
    theta_j = x[i5] if i5 >= 0 else 0.0
    g, c, s = inverse_length[e], cos[e], sin[e]
    du = u_j - u_i
    dv = v_j - v_i
    psi = (c * dv - s * du) * g
    a = theta_i - psi
    b = theta_j - psi
    axial = EA_per_length[e] * (c * du + s * dv)
    moment_i = EI_per_length[e] * (4.0 * a + 2.0 * b)
    moment_j = EI_per_length[e] * (2.0 * a + 4.0 * b)
    shear = (moment_i + moment_j) * g
    f_x = -c * axial - s * shear
    f_y = -s * axial + c * shear
    return f_x, f_y, moment_i, -f_x, -f_y, moment_j


@numba.njit(cache=True, nogil=True)
def all_finite(x: NDArray[np.float64], y: NDArray[np.float64]) -> bool:
    """True if every entry of ``x`` and ``y`` is finite (a loop: no BLAS threads, no copy)."""
    for i in range(x.size):
        if not (np.isfinite(x[i]) and np.isfinite(y[i])):
            return False
    return True


@numba.njit(cache=True, nogil=True)
def energy_exceeds(
    t: float, x: NDArray[np.float64], y: NDArray[np.float64], q: NDArray[np.float64],
    lag: NDArray[np.float64], watch: tuple,
) -> tuple[bool, float]:  # fmt: skip
    """Whether ``V = ½ yᵀM y + ½ xᵀ(f − q + lag)`` passes ``growth (√V₀ + P t)²``; and ``V``
    when it does.

    The check of :mod:`tumble.structural.divergence`; ``watch`` is
    :meth:`~tumble.structural.divergence.EnergyWatch.kernel`'s ``(every, final, √V₀, P,
    growth, mass, f, c)``: ``mass[p, j] = M[p, p − j]``, the lower band of ``M`` row by row
    (0 where ``p < j``), and ``c ≥ λ_max(D^{-½} M D^{-½})`` with ``D = diag M``. ``lag`` is
    the ``S Δx`` not yet taken from ``q`` (empty: none). First the bound
    ``V ≤ ½ c yᵀD y + ½ xᵀS x`` (a pass as cheap as two dot products); only when that
    passes the limit, ``yᵀM y`` itself from the band (the check then costs about a step).
    A NaN ``V`` passes.
    """
    root, power, growth, mass, f, c = watch[2], watch[3], watch[4], watch[5], watch[6], watch[7]
    n = x.size
    strain = 0.0
    diagonal = 0.0
    if lag.size:
        for p in range(n):
            strain += x[p] * (f[p] - q[p] + lag[p])
            diagonal += mass[p, 0] * y[p] * y[p]
    else:
        for p in range(n):
            strain += x[p] * (f[p] - q[p])
            diagonal += mass[p, 0] * y[p] * y[p]
    bound = root + power * t
    limit = growth * bound * bound
    if 0.5 * (c * diagonal + strain) <= limit:
        return False, -1.0
    b = mass.shape[1] - 1
    kinetic = 0.0
    for p in range(n):
        acc = 0.0
        for j in range(1, min(p, b) + 1):
            acc += mass[p, j] * y[p - j]
        kinetic += y[p] * (mass[p, 0] * y[p] + 2.0 * acc)
    energy = 0.5 * (kinetic + strain)
    return not energy <= limit, energy


@numba.njit(cache=True, nogil=True, fastmath={"contract"})
def banded_solve(
    forward: NDArray[np.float64],
    backward: NDArray[np.float64],
    inverse_diagonal: NDArray[np.float64],
    x: NDArray[np.float64],
    window: tuple[float, ...],
) -> None:
    """Overwrite ``x`` with ``(L Lᵀ)⁻¹ x``, ``L`` a banded Cholesky factor.

    ``z_p = x_p / L_pp − Σ_j forward[p, j] z_{p−b+j}``, then
    ``x_p = z_p / L_pp − Σ_j backward[p, j] x_{p+b−j}``; see
    :class:`tumble.structural.factorization.BandedCholesky` for the arrays.

    The last ``b`` results ride along in the tuple ``window`` (``b`` zeros on entry), so they
    stay in registers: the chain from one row to the next is then one multiply–add instead
    of a store and a reload, which made the solve 2.8× faster than a loop over the band.
    The tuple's length is part of the type, so numba compiles one loop per bandwidth, with
    the inner sums unrolled.
    """
    n = x.size
    z = window
    for p in range(n):
        acc = inverse_diagonal[p] * x[p]
        for j in range(len(z)):
            acc -= forward[p, j] * z[j]
        x[p] = acc
        z = z[1:] + (acc,)
    z = window
    for p in range(n - 1, -1, -1):
        acc = inverse_diagonal[p] * x[p]
        for j in range(len(z)):
            acc -= backward[p, j] * z[j]
        x[p] = acc
        z = z[1:] + (acc,)


class BeamKernelProblem(NamedTuple):
    """What a scheme's loop needs of a run besides its state (module docstring).

    ``coefficients``: the scheme's constants
    (:meth:`tumble.structural.scheme.Scheme.coefficients`), ``Δt`` first; ``frame``:
    ``(dof_map, 1/h, cos, sin, EA/h, EI/h)`` as in :func:`assemble_internal_forces`;
    ``factors``: ``(forward, backward, inverse_diagonal, window)`` of each step matrix, one
    bandwidth; ``damping``: ``C`` as CSR ``(indptr, indices, data)``, ``indptr`` empty when
    undamped; ``work``: the step's scratch vectors; ``lag``: the ``S Δx`` a step leaves for
    the next to take from ``q`` (one of ``work``), or empty; ``watch``: the energy check
    (:func:`energy_exceeds`), made after every step that is a multiple of ``watch[0]`` and
    after step ``watch[1]`` (the run's last); ``energy`` (1,): where a failed check leaves
    its ``V`` (-1.0 before).
    """

    coefficients: tuple
    frame: tuple
    factors: tuple
    damping: tuple
    work: tuple
    lag: NDArray[np.float64]
    watch: tuple
    energy: NDArray[np.float64]


class BeamRecords(NamedTuple):
    """Where a scheme's loop writes its samples: ``t`` (m,), ``x`` and ``y`` (m, n)."""

    t: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]

    def after(self, rows: int) -> BeamRecords:
        """The rows from ``rows`` on (a view), for a loop that goes on from there."""
        return BeamRecords(self.t[rows:], self.x[rows:], self.y[rows:])


@numba.njit(cache=True, nogil=True, inline="always")
def _work(problem, state):  # noqa: ANN001, ANN202
    """The step's scratch vectors; the lag starts at zero."""
    lag = problem.lag
    for i in range(lag.size):
        lag[i] = 0.0
    return problem.work


def _step(problem, state, work, t, t_new, settle):  # noqa: ANN001, ANN202
    """``KERNEL`` (the scheme's step, bound by :func:`time_loop`); :data:`NON_FINITE` when it
    leaves ``x`` or ``y`` non-finite (the stepper replays the block to the step before)."""
    p = problem
    if KERNEL(p.coefficients, state, p.frame, p.factors, p.damping, work):  # noqa: F821
        return NON_FINITE
    return OK


@numba.njit(cache=True, nogil=True, inline="always")
def _check(problem, state, work, k):  # noqa: ANN001, ANN202
    """The energy watch after step ``k`` (every ``watch[0]`` steps and at ``watch[1]``, the
    run's last): :func:`energy_exceeds` at ``t = k Δt``; a failed check leaves its ``V`` in
    ``problem.energy`` and stops the loop as a divergence (:data:`NON_FINITE`, told from a
    non-finite state by that ``V``)."""
    watch = problem.watch
    if k % watch[0] != 0 and k != watch[1]:
        return OK
    x, y, q = state[0], state[1], state[2]
    grown, energy = energy_exceeds(k * problem.coefficients[0], x, y, q, problem.lag, watch)
    if not grown:
        return OK
    problem.energy[0] = energy
    return NON_FINITE


@numba.njit(cache=True, nogil=True, inline="always")
def _finish(problem, state, work):  # noqa: ANN001, ANN202
    """The lag taken from ``q``: the state handed back is whole."""
    q, lag = state[2], problem.lag
    for i in range(lag.size):
        q[i] -= lag[i]


@numba.njit(cache=True, nogil=True, inline="always")
def _record(problem, state, work, records, i):  # noqa: ANN001, ANN202
    records.x[i] = state[0]
    records.y[i] = state[1]


def time_loop(name: str, step: Callable[..., int]) -> Callable[..., tuple[int, int, int]]:
    """The fixed-step template (:func:`tumble.ode.templates.fixed_loop`) bound to ``step``
    and the watch, cached by numba under ``_beam_loop_<name>``.

    It is called as ``loop(problem, grid, state, k0, k1, every, step0, records)`` with a
    :class:`BeamKernelProblem`, the driver's :class:`~tumble.ode.driver.Grid`, the state's
    vectors ``(x, y, q, …)`` and :class:`BeamRecords`, and returns ``(recorded, failed,
    cause)``. The loop compiles on its first call (once per bandwidth of the factors, whose
    ``window`` tuple is part of the type).
    """
    bound = numba.njit(cache=True, nogil=True, inline="always")(
        templates.bind(_step, f"_beam_step_{name}", KERNEL=step)
    )
    return templates.loop(
        templates.fixed_loop, f"_beam_loop_{name}", nogil=True, WORK=_work, STEP=bound,
        CHECK=_check, FINISH=_finish, RECORD=_record,
    )  # fmt: skip


@dataclass(frozen=True)
class StepKernel:
    """A scheme's compiled step, bound into the one time loop (module docstring).

    Attributes
    ----------
    name : str
        Names the loop in numba's cache (``_beam_loop_<name>``) and in the notice of its
        first compilation.
    step : callable
        ``step(coefficients, state, frame, factors, damping, work) -> non_finite``, a
        ``@numba.njit(inline="always")`` function.
    work : int
        How many scratch vectors of the DOF count the step uses.
    lag : int
        The index in ``work`` of the ``S Δx`` the step leaves for the next one to take from
        ``q``, or -1 (it takes it itself).
    """

    name: str
    step: Callable[..., int]
    work: int
    lag: int = -1
    loop: Any = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "loop", time_loop(self.name, self.step))
