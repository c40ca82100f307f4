"""Compiled kernels: internal forces ``S x`` element by element, banded solves, the time loop.

:func:`assemble_internal_forces` is :func:`tumble.structural.elements.element_forces` (the
readable NumPy reference, which a test checks this against to round-off) fused with the
scatter into the free-DOF vector, so that one call does no allocation and no Python work
per element. It takes each element's ``1/h``, ``EA/h`` and ``EI/h`` precomputed
(:attr:`tumble.structural.system.FrameElements.kernel_arrays`): without the four divisions
an element costs 3.4 ns instead of 4.7 ns (measured at 10⁴ elements).
:func:`banded_solve` is the substitution with a banded Cholesky factor, and
:func:`run_steps` the time loop of :mod:`tumble.structural.stepping`.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray


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


@numba.njit(cache=True, nogil=True, inline="always")
def watch_step(
    k: int, until_check: int, non_finite: int, t: float, x: NDArray[np.float64],
    y: NDArray[np.float64], q: NDArray[np.float64], lag: NDArray[np.float64], watch: tuple,
) -> tuple[bool, float, int]:  # fmt: skip
    """The energy check's cadence in every structural loop, after step ``k`` at ``t``: count
    down ``until_check`` and, at zero or at the run's last step ``watch[1]``, ask
    :func:`energy_exceeds` (not after a non-finite step, which stops the loop anyway).
    Returns whether the run has diverged, ``V`` if so (else -1.0), and the next countdown."""
    until_check -= 1
    grown, energy = False, -1.0
    if (until_check == 0 or k == watch[1]) and not non_finite:
        grown, value = energy_exceeds(t, x, y, q, lag, watch)
        if grown:
            energy = value
    if until_check == 0:
        until_check = watch[0]
    return grown, energy, until_check


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


@numba.njit(cache=True, nogil=True)
def run_steps(
    first: int,
    last: int,
    record_steps: NDArray[np.int64],
    row: int,
    coefficients: tuple[float, float, float, float, float],
    state: tuple,
    frame: tuple,
    factor: tuple,
    mass_factor: tuple,
    damping: tuple,
    work: tuple,
    watch: tuple,
    xs: NDArray[np.float64],
    ys: NDArray[np.float64],
) -> tuple[int, int, float]:
    """Steps ``first + 1 … last`` of :func:`tumble.structural.stepping.reference_step`.

    The same operations in the same order, with the NumPy reference's sparse LU solve
    replaced by :func:`banded_solve`, and no allocation: a pass for the right-hand side
    (which also subtracts the previous step's ``S Δx`` from ``q``), the banded solve, a pass
    for the update of ``x`` and ``y``, and one pass over the elements for ``S Δx`` and
    ``S y`` together (:func:`assemble_internal_forces_pair`). Fusing the passes into the
    two sweeps of the solve made a step 3–15 % slower (measured), so they stay apart.

    Parameters
    ----------
    first, last : int
        Steps already taken, and the step to stop after.
    record_steps : ndarray of int64, shape (n_records,)
        The steps to record; ``row`` is the next row of ``xs``, ``ys`` to fill.
    coefficients : tuple of 5 floats
        ``(Δt, k_g, k_dy, k_sa, k_a)`` from :class:`~tumble.structural.stepping.Increments`;
        ``k_sa != 0`` or ``k_a != 0`` switches on the mass solve.
    state : tuple of 4 ndarrays, shape (n,)
        ``(x, y, q, g)``: displacement, velocity, ``q = f − S x`` (carried) and ``S y``
        (recomputed when ``k_g != 0``), updated in place.
    frame : tuple
        ``(dof_map, 1/h, cos, sin, EA/h, EI/h)`` as in :func:`assemble_internal_forces`.
    factor, mass_factor : tuple
        ``(forward, backward, inverse_diagonal, window)`` of the step matrix and of ``M``
        (any factor of the same bandwidth when there is no mass solve).
    damping : tuple of 3 ndarrays
        ``C`` as CSR ``(indptr, indices, data)``; ``indptr`` empty when undamped.
    work : tuple of 4 ndarrays, shape (n,)
        Scratch: right-hand side, then ``Δy``, then ``Δx``; ``S Δx``; ``a``; ``S a``.
    watch : tuple
        The energy check (:func:`energy_exceeds`), made after every step that is a multiple
        of ``watch[0]`` and after step ``watch[1]`` (the run's last).
    xs, ys : ndarray, shape (n_records, n)
        Records, filled from ``row``.

    Returns
    -------
    row : int
        The next row to fill.
    diverged : int
        The step at which the state became non-finite (recorded) or failed the energy check,
        where the loop stopped; or -1.
    energy : float
        ``V`` at the failed check, or -1.0 (none failed: a non-finite state, or no stop).
    """
    # The type: ignore[call-arg] below: numba's stubs count a *tuple into a Dispatcher wrongly.
    dt, k_g, k_dy, k_sa, k_a = coefficients
    use_mass = k_sa != 0.0 or k_a != 0.0
    x, y, q, g = state
    rhs, h, a, sa = work
    indptr, indices, data = damping
    n = x.size
    h[:] = 0.0
    diverged, energy = -1, -1.0
    until_check = watch[0] - first % watch[0]
    for k in range(first + 1, last + 1):
        for i in range(n):  # r = q − C y, q = f − S x first taking the last step's S Δx
            q[i] -= h[i]
            r = q[i]
            if indptr.size:
                cy = 0.0
                for j in range(indptr[i], indptr[i + 1]):
                    cy += data[j] * y[indices[j]]
                r -= cy
            rhs[i] = r
        if use_mass:  # a = M⁻¹ r
            a[:] = rhs
            banded_solve(mass_factor[0], mass_factor[1], mass_factor[2], a, mass_factor[3])
            assemble_internal_forces(a, *frame, sa)  # type: ignore[call-arg]
            for i in range(n):
                rhs[i] -= k_sa * sa[i]
        for i in range(n):
            rhs[i] = dt * (rhs[i] - k_g * g[i])
        banded_solve(factor[0], factor[1], factor[2], rhs, factor[3])  # rhs = Δy
        non_finite = 0
        for i in range(n):
            dx = dt * y[i] + k_dy * rhs[i]
            if use_mass:
                dx += k_a * a[i]
            x[i] += dx
            y[i] += rhs[i]
            rhs[i] = dx
            non_finite += not (np.isfinite(x[i]) and np.isfinite(y[i]))
        if k_g != 0.0:
            # h = S Δx, g = S y
            assemble_internal_forces_pair(rhs, y, *frame, h, g)  # type: ignore[call-arg]
        else:
            assemble_internal_forces(rhs, *frame, h)  # type: ignore[call-arg]
        grown, energy, until_check = watch_step(k, until_check, non_finite, k * dt, x, y, q, h,
                                                watch)  # fmt: skip
        if non_finite or k == record_steps[row]:
            xs[row] = x
            ys[row] = y
            row += 1
        if non_finite or grown:
            diverged = k
            break
    for i in range(n):
        q[i] -= h[i]
    return row, diverged, energy
