"""Compiled steps of the generalized-α family and of the ρ∞-Bathe method.

The same operations in the same order as the NumPy references
:func:`tumble.structural.alpha.alpha_step` and :func:`tumble.structural.alpha.bathe_step`
(tests check they agree to round-off), with the sparse LU solve replaced by the banded
:func:`~tumble.structural.kernels.banded_solve` and no allocation, each inlined into the one
time loop (:func:`~tumble.structural.kernels.time_loop`). Like the increment step they carry
``q = f − S x`` and subtract ``S Δx`` summed element by element; each step (each sub-step
for Bathe) is one banded solve and one pass over the elements for two products.
"""

from __future__ import annotations

import numba
import numpy as np

from tumble.structural.kernels import StepKernel, assemble_internal_forces_pair, banded_solve


@numba.njit(cache=True, nogil=True, inline="always")
def alpha_kernel(coefficients, state, frame, factors, damping, work):  # noqa: ANN001, ANN201
    """One step of :func:`tumble.structural.alpha.alpha_step`.

    ``coefficients`` are :attr:`tumble.structural.alpha.AlphaCoefficients.values`;
    ``state`` is ``(x, y, q, p, a, m, r)`` (:class:`~tumble.structural.alpha.AlphaState`),
    ``work`` two scratch vectors (``Δx``, then ``k_g y + k_sa a``) and ``S Δx``.
    """
    dt, c_r, k_g, k_sa, k_dy, k_a, a_keep, a_gain, m_new, m_old, m_prev = coefficients
    x, y, q, p, a, m, r = state
    rhs, combined, sdx = work
    factor = factors[0]
    indptr, indices, data = damping
    n = x.size
    damped = indptr.size > 0
    for i in range(n):
        rhs[i] = dt * (c_r * r[i] + (1.0 - c_r) * m[i] - p[i])
    banded_solve(factor[0], factor[1], factor[2], rhs, factor[3])  # rhs = Δy
    non_finite = 0
    for i in range(n):
        dy = rhs[i]
        dx = dt * y[i] + k_dy * dy + k_a * a[i]
        x[i] += dx
        y[i] += dy
        a[i] = a_keep * a[i] + a_gain * dy
        rhs[i] = dx
        combined[i] = k_g * y[i] + k_sa * a[i]
        non_finite += not (np.isfinite(x[i]) and np.isfinite(y[i]))
    assemble_internal_forces_pair(rhs, combined, *frame, sdx, p)
    for i in range(n):
        q[i] -= sdx[i]
    for i in range(n):  # r = q − C y, then m from the equation of motion
        r_new = q[i]
        if damped:
            for j in range(indptr[i], indptr[i + 1]):
                r_new -= data[j] * y[indices[j]]
        m[i] = m_new * r_new + m_old * r[i] - m_prev * m[i]
        r[i] = r_new
    return non_finite


@numba.njit(cache=True, nogil=True, inline="always")
def bathe_kernel(coefficients, state, frame, factors, damping, work):  # noqa: ANN001, ANN201
    """One step of :func:`tumble.structural.alpha.bathe_step`.

    ``coefficients`` are ``(Δt, τ = γΔt, d₀, d₁, q₂)``; ``state`` is ``(x, y, q, g = S y)``;
    ``factors`` those of the two sub-steps' matrices (the same one at the optimal splitting
    ratio); ``work`` holds the right-hand side, ``Δx``, ``S Δx``, ``rⁿ``, ``yⁿ`` (then
    ``w = d₀yⁿ + d₁y^m``) and ``S yⁿ``.
    """
    dt, tau, d0, d1, q2 = coefficients
    x, y, q, g = state
    rhs, dxs, sdx, r_old, y_old, g_old = work
    factor, second_factor = factors[0], factors[-1]
    indptr, indices, data = damping
    n = x.size
    damped = indptr.size > 0
    for i in range(n):  # trapezoidal sub-step over τ; r = q − C y
        r_old[i] = q[i]
        if damped:
            for j in range(indptr[i], indptr[i + 1]):
                r_old[i] -= data[j] * y[indices[j]]
        y_old[i] = y[i]
        g_old[i] = g[i]
        rhs[i] = tau * (r_old[i] - 0.5 * tau * g[i])
    banded_solve(factor[0], factor[1], factor[2], rhs, factor[3])
    for i in range(n):
        dx = tau * y[i] + 0.5 * tau * rhs[i]
        x[i] += dx
        y[i] += rhs[i]
        dxs[i] = dx
    assemble_internal_forces_pair(dxs, y, *frame, sdx, g)
    for i in range(n):
        q[i] -= sdx[i]
    for i in range(n):  # the second sub-step, to t + Δt
        r_mid = q[i]
        if damped:
            for j in range(indptr[i], indptr[i + 1]):
                r_mid -= data[j] * y[indices[j]]
        rhs[i] = dt * (d0 * r_old[i] + d1 * r_mid - q2 * dt * (d0 * g_old[i] + d1 * g[i]))
        y_old[i] = d0 * y_old[i] + d1 * y[i]
    banded_solve(second_factor[0], second_factor[1], second_factor[2], rhs, second_factor[3])
    non_finite = 0
    for i in range(n):
        dx = dt * y_old[i] + q2 * dt * rhs[i]
        x[i] += dx
        y[i] += rhs[i]
        dxs[i] = dx
        non_finite += not (np.isfinite(x[i]) and np.isfinite(y[i]))
    assemble_internal_forces_pair(dxs, y, *frame, sdx, g)
    for i in range(n):
        q[i] -= sdx[i]
    return non_finite


ALPHA = StepKernel("alpha", alpha_kernel, work=3)
"""The compiled step of :class:`~tumble.structural.alpha.GeneralizedAlpha` and
:class:`~tumble.structural.alpha.HHT`."""

BATHE = StepKernel("bathe", bathe_kernel, work=6)
"""The compiled step of :class:`~tumble.structural.alpha.Bathe`."""
