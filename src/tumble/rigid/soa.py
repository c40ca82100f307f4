"""Structure-of-arrays batch loops: bodies side by side, so the loops over bodies vectorise.

:func:`~tumble.rigid.simulate_batch` runs every body through the one-body loop of
:mod:`tumble.rigid.kernels` (one body at a time per thread: "array of structures"). Here the
``lie`` and ``quat`` charts (``rkmk4``, ``rkmk8``, ``lie-euler``, ``seed-rk4``, ``rk4-quat``,
``euler-quat``) get a second loop for batches in which the bodies are the columns: the state
is ``Z`` (nz, N) and ``R_n`` (9, N), the body data ``I⁻¹`` (9, N), ``m`` (N,), ``F`` (3, N).
A block of :data:`BLOCK` bodies is copied into contiguous work arrays and marched over the
whole grid; each stage is a few loops over the bodies of the block whose bodies are plain
arithmetic on contiguous rows, so LLVM turns them into packed (SIMD) instructions
(``tests/rigid/test_rigid_batch.py`` checks the assembly for packed ``vmulpd``/``vaddpd``).
The blocks run in parallel (``prange``).

The arithmetic is the one-body loop's, operation for operation in the same order
(:func:`~tumble.rigid.kernels._lie_field`, ``_quat_field``, ``_loads``, the stage sums): no
fastmath, so no reassociation or fused multiply-add, and every body gets bit for bit the
numbers of :func:`~tumble.rigid.simulate` (the batch tests compare with ``assert_array_equal``).
The two branches of that arithmetic become: the ``exp`` and ``dexp⁻¹`` coefficients from
their series for all bodies (a vector loop), then the few bodies whose angle is at least
:data:`~tumble.rigid.kernels.SERIES_ANGLE` recomputed by the one-body functions (a scalar
loop); a body whose new state is not finite stops alone, as in the one-body loop (its state
is left at the step before; the test ``x − x == 0`` on the sum of its numbers is vectorised,
the bookkeeping of a stop is scalar and rare).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from tumble.rigid.kernels import (
    _C1,
    _C2,
    _C3,
    _C4,
    _C5,
    _JIT,
    _S1,
    _S2,
    _S3,
    _S4,
    _S5,
    _SERIES2,
    _dexpinv_coefficient,
    _exp_coefficients,
    _quat_matrix,
)

BLOCK = 256
"""Bodies marched together by one thread (their work arrays stay in the L2 cache)."""


@njit(**_JIT)
def _series(u, theta2, a, b, alpha, dexpinv):
    """Per body: ``θ²`` of ``u`` (3, B), exp's ``(a, b)`` and, if ``dexpinv``, dexp⁻¹'s ``α``
    (:func:`~tumble.rigid.kernels._exp_coefficients` and ``_dexpinv_coefficient``): the series
    for all bodies (vectorised), then the exact forms where the angle is not small."""
    n = theta2.shape[0]
    for j in range(n):
        x = u[0, j] * u[0, j] + u[1, j] * u[1, j] + u[2, j] * u[2, j]
        theta2[j] = x
        a[j] = 1.0 + x * (_S1 + x * (_S2 + x * (_S3 + x * (_S4 + x * _S5))))
        b[j] = 0.5 + x * (_C1 + x * (_C2 + x * (_C3 + x * (_C4 + x * _C5))))
    if dexpinv:
        for j in range(n):
            x = theta2[j]
            tail = 1 / 1209600 + x * (1 / 47900160 + x * (691 / 1307674368000))
            alpha[j] = 1 / 12 + x * (1 / 720 + x * (1 / 30240 + x * tail))
    for j in range(n):
        if theta2[j] >= _SERIES2:
            a[j], b[j] = _exp_coefficients(theta2[j])
            if dexpinv:
                alpha[j] = _dexpinv_coefficient(theta2[j])


@njit(**_JIT)
def _stage_state(A, i, h, z, K, zs, acc):
    """``zs = z + h Σ_{l<i} a_il K_l`` for every number of every body: the one-body sums,
    term by term in the same order, with the loop over bodies innermost (``acc`` (B,))."""
    nz, n = z.shape
    for c in range(nz):
        for j in range(n):
            acc[j] = 0.0
        for l in range(i):
            a = A[i, l]
            for j in range(n):
                acc[j] += a * K[l, c, j]
        for j in range(n):
            zs[c, j] = z[c, j] + h * acc[j]


@njit(**_JIT)
def _new_state(b, h, z, K, zn, bad, acc):
    """``zn = z + h Σ b_i K_i`` (as :func:`_stage_state`); ``bad[j]``: body j's new state has
    a non-finite number (``Σ 0·zn`` is 0 exactly when every number is finite, NaN otherwise)."""
    nz, n = z.shape
    for j in range(n):
        bad[j] = 0.0
    for c in range(nz):
        for j in range(n):
            acc[j] = 0.0
        for i in range(b.shape[0]):
            w = b[i]
            for j in range(n):
                acc[j] += w * K[i, c, j]
        for j in range(n):
            zn[c, j] = z[c, j] + h * acc[j]
            bad[j] += 0.0 * zn[c, j]
    any_bad = False
    for j in range(n):
        any_bad = any_bad or bad[j] != 0.0
    return any_bad


@njit(**_JIT)
def _loads_soa(off, zs, R, u, a, b, m, F, tau, points, point_forces, K, i):
    """:func:`~tumble.rigid.kernels._loads` for every body: ``ẋ = p/m``, ``ṗ = F + Σ f_k``,
    ``L̇ = τ + Σ (R exp(û) r_k) × f_k`` (``R`` (9, B) row-major; ``u`` (3, B) or None)."""
    n = m.shape[0]
    for c in range(3):
        for j in range(n):
            K[i, off + c, j] = zs[off + 3 + c, j] / m[j]
            K[i, off + 3 + c, j] = F[c, j]
            K[i, off + 6 + c, j] = tau[c]
    for k in range(points.shape[0]):
        v0, v1, v2 = points[k, 0], points[k, 1], points[k, 2]
        f0, f1, f2 = point_forces[k, 0], point_forces[k, 1], point_forces[k, 2]
        for j in range(n):
            u0, u1, u2 = u[0, j], u[1, j], u[2, j]
            c0, c1, c2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
            d0, d1, d2 = u1 * c2 - u2 * c1, u2 * c0 - u0 * c2, u0 * c1 - u1 * c0
            r0 = v0 + a[j] * c0 + b[j] * d0
            r1 = v1 + a[j] * c1 + b[j] * d1
            r2 = v2 + a[j] * c2 + b[j] * d2
            s0 = R[0, j] * r0 + R[1, j] * r1 + R[2, j] * r2
            s1 = R[3, j] * r0 + R[4, j] * r1 + R[5, j] * r2
            s2 = R[6, j] * r0 + R[7, j] * r1 + R[8, j] * r2
            K[i, off + 3, j] += f0
            K[i, off + 4, j] += f1
            K[i, off + 5, j] += f2
            K[i, off + 6, j] += s1 * f2 - s2 * f1
            K[i, off + 7, j] += s2 * f0 - s0 * f2
            K[i, off + 8, j] += s0 * f1 - s1 * f0


@njit(**_JIT)
def _lie_field_soa(correct, zs, Rn, inv_I, coefficients, K, i):
    """:func:`~tumble.rigid.kernels._lie_field` for every body: ``u̇ = dexp⁻¹_{−u}(ω)``,
    ``ω = I⁻¹ exp(−û) R_nᵀ L``; ``coefficients`` = ``(θ², a, b, α)`` work rows (4, B)."""
    n = zs.shape[1]
    theta2, a, b, alpha = coefficients[0], coefficients[1], coefficients[2], coefficients[3]
    _series(zs[0:3], theta2, a, b, alpha, correct)
    half = 0.5 if correct else 0.0
    for j in range(n):
        u0, u1, u2 = zs[0, j], zs[1, j], zs[2, j]
        L0, L1, L2 = zs[9, j], zs[10, j], zs[11, j]
        v0 = Rn[0, j] * L0 + Rn[3, j] * L1 + Rn[6, j] * L2
        v1 = Rn[1, j] * L0 + Rn[4, j] * L1 + Rn[7, j] * L2
        v2 = Rn[2, j] * L0 + Rn[5, j] * L1 + Rn[8, j] * L2
        ma = -a[j]
        c0, c1, c2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
        d0, d1, d2 = u1 * c2 - u2 * c1, u2 * c0 - u0 * c2, u0 * c1 - u1 * c0
        e0, e1, e2 = v0 + ma * c0 + b[j] * d0, v1 + ma * c1 + b[j] * d1, v2 + ma * c2 + b[j] * d2
        w0 = inv_I[0, j] * e0 + inv_I[1, j] * e1 + inv_I[2, j] * e2
        w1 = inv_I[3, j] * e0 + inv_I[4, j] * e1 + inv_I[5, j] * e2
        w2 = inv_I[6, j] * e0 + inv_I[7, j] * e1 + inv_I[8, j] * e2
        al = alpha[j] if correct else 0.0
        c0, c1, c2 = u1 * w2 - u2 * w1, u2 * w0 - u0 * w2, u0 * w1 - u1 * w0
        d0, d1, d2 = u1 * c2 - u2 * c1, u2 * c0 - u0 * c2, u0 * c1 - u1 * c0
        K[i, 0, j] = w0 + half * c0 + al * d0
        K[i, 1, j] = w1 + half * c1 + al * d1
        K[i, 2, j] = w2 + half * c2 + al * d2


@njit(**_JIT)
def _lie_advance_soa(zn, z, Rn, coefficients, alive):
    """:func:`~tumble.rigid.kernels._lie_advance` for the living bodies: ``R_n ← R_n
    exp(û)``, ``u ← 0``, ``(x, p, L)`` from ``zn``."""
    n = z.shape[1]
    theta2, a, b = coefficients[0], coefficients[1], coefficients[2]
    _series(zn[0:3], theta2, a, b, coefficients[3], False)
    for r in range(3):
        for j in range(n):
            u0, u1, u2 = zn[0, j], zn[1, j], zn[2, j]
            v0, v1, v2 = Rn[3 * r, j], Rn[3 * r + 1, j], Rn[3 * r + 2, j]
            ma = -a[j]
            c0, c1, c2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
            d0, d1, d2 = u1 * c2 - u2 * c1, u2 * c0 - u0 * c2, u0 * c1 - u1 * c0
            keep = alive[j]
            Rn[3 * r, j] = v0 + ma * c0 + b[j] * d0 if keep else v0
            Rn[3 * r + 1, j] = v1 + ma * c1 + b[j] * d1 if keep else v1
            Rn[3 * r + 2, j] = v2 + ma * c2 + b[j] * d2 if keep else v2
    for c in range(z.shape[0]):
        for j in range(n):
            new = (0.0 if c < 3 else zn[c, j]) if alive[j] else z[c, j]
            z[c, j] = new


@njit(**_JIT)
def _quat_field_soa(zs, R, inv_I, K, i):
    """:func:`~tumble.rigid.kernels._quat_field` for every body: ``q̇ = ½ q ⊗ (0, ω)``,
    ``ω = I⁻¹ Rᵀ L`` with ``R = R(q/|q|)`` written to ``R`` (9, B) (two loops: each
    vectorises)."""
    n = zs.shape[1]
    for j in range(n):
        q0, q1, q2, q3 = zs[0, j], zs[1, j], zs[2, j], zs[3, j]
        norm = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
        p0, p1, p2, p3 = q0 / norm, q1 / norm, q2 / norm, q3 / norm
        R[0, j], R[1, j] = 1 - 2 * (p2 * p2 + p3 * p3), 2 * (p1 * p2 - p0 * p3)
        R[2, j], R[3, j] = 2 * (p1 * p3 + p0 * p2), 2 * (p1 * p2 + p0 * p3)
        R[4, j], R[5, j] = 1 - 2 * (p1 * p1 + p3 * p3), 2 * (p2 * p3 - p0 * p1)
        R[6, j], R[7, j] = 2 * (p1 * p3 - p0 * p2), 2 * (p2 * p3 + p0 * p1)
        R[8, j] = 1 - 2 * (p1 * p1 + p2 * p2)
    for j in range(n):
        q0, q1, q2, q3 = zs[0, j], zs[1, j], zs[2, j], zs[3, j]
        L0, L1, L2 = zs[10, j], zs[11, j], zs[12, j]
        v0 = R[0, j] * L0 + R[3, j] * L1 + R[6, j] * L2
        v1 = R[1, j] * L0 + R[4, j] * L1 + R[7, j] * L2
        v2 = R[2, j] * L0 + R[5, j] * L1 + R[8, j] * L2
        w0 = inv_I[0, j] * v0 + inv_I[1, j] * v1 + inv_I[2, j] * v2
        w1 = inv_I[3, j] * v0 + inv_I[4, j] * v1 + inv_I[5, j] * v2
        w2 = inv_I[6, j] * v0 + inv_I[7, j] * v1 + inv_I[8, j] * v2
        K[i, 0, j] = 0.5 * (-q1 * w0 - q2 * w1 - q3 * w2)
        K[i, 1, j] = 0.5 * (q0 * w0 + q2 * w2 - q3 * w1)
        K[i, 2, j] = 0.5 * (q0 * w1 + q3 * w0 - q1 * w2)
        K[i, 3, j] = 0.5 * (q0 * w2 + q1 * w1 - q2 * w0)


@njit(**_JIT)
def _quat_start_soa(z):
    """:func:`~tumble.rigid.kernels._quat_start`: ``q ← q/|q|`` for every body."""
    for j in range(z.shape[1]):
        norm = math.sqrt(z[0, j] ** 2 + z[1, j] ** 2 + z[2, j] ** 2 + z[3, j] ** 2)
        for c in range(4):
            z[c, j] = z[c, j] / norm


@njit(**_JIT)
def _record(quat, z, Rn, j, R_out, q_out, Y_out):
    """One body's sample, as the chart's record function writes it."""
    if quat:
        norm = math.sqrt(z[0, j] ** 2 + z[1, j] ** 2 + z[2, j] ** 2 + z[3, j] ** 2)
        _quat_matrix(z[0, j] / norm, z[1, j] / norm, z[2, j] / norm, z[3, j] / norm, R_out)
        for c in range(4):
            q_out[c] = z[c, j]
        for c in range(9):
            Y_out[c] = z[4 + c, j]
    else:
        for c in range(9):
            R_out[c // 3, c % 3] = Rn[c, j]
            Y_out[c] = z[3 + c, j]


@njit(**_JIT)
def _block(quat, problem, grid, z, Rn, inv_I, m, F, every, j0, records, counts, failed):
    """March the bodies ``j0 …`` of one block (their columns ``z``, ``Rn``, ``inv_I``, ``m``,
    ``F``, contiguous) over the whole grid; the one-body loop's steps, body by body."""
    A, b, correct = problem.A, problem.b, problem.correct
    tau, points, point_forces = problem.tau, problem.points, problem.point_forces
    t_a, t_b, h, n_steps = grid
    s, (nz, n) = b.shape[0], z.shape
    K, zs, zn = np.empty((s, nz, n)), np.empty((nz, n)), np.empty((nz, n))
    R, coefficients, bad, acc = np.empty((9, n)), np.empty((4, n)), np.empty(n), np.empty(n)
    alive, zero = np.ones(n, dtype=np.bool_), np.zeros((4, n))
    count, until_record = 0, every
    for k in range(1, n_steps + 1):
        t_old = t_a + (k - 1) * h
        hk = (t_b if k == n_steps else t_a + k * h) - t_old
        if quat:
            _quat_start_soa(z)
        for i in range(s):
            _stage_state(A, i, hk, z, K, zs, acc)
            if quat:  # R(q/|q|) turns the points: no exp(û) (u = 0, a = b = 0)
                _quat_field_soa(zs, R, inv_I, K, i)
                _loads_soa(4, zs, R, zero[0:3], zero[3], zero[3], m, F, tau, points,
                           point_forces, K, i)  # fmt: skip
            else:
                _lie_field_soa(correct, zs, Rn, inv_I, coefficients, K, i)
                _loads_soa(3, zs, Rn, zs[0:3], coefficients[1], coefficients[2], m, F, tau,
                           points, point_forces, K, i)  # fmt: skip
        if _new_state(b, hk, z, K, zn, bad, acc):
            for j in range(n):
                if not bad[j] == 0.0 and alive[j]:
                    alive[j] = False
                    failed[j0 + j], counts[j0 + j] = k, count
        if quat:
            for c in range(nz):
                for j in range(n):
                    z[c, j] = zn[c, j] if alive[j] else z[c, j]
        else:
            _lie_advance_soa(zn, z, Rn, coefficients, alive)
        until_record -= 1
        if until_record == 0:
            for j in range(n):
                if alive[j]:
                    records.t[j0 + j, count] = t_old + hk
                    _record(quat, z, Rn, j, records.R[j0 + j, count], records.q[j0 + j, count],
                            records.Y[j0 + j, count])  # fmt: skip
            count += 1
            until_record = every
    for j in range(n):
        if alive[j]:
            counts[j0 + j], failed[j0 + j] = count, -1


@njit(parallel=True, **_JIT)
def run_batch(quat, problem, grid, Z, RN, inv_I, m, F, every, records, counts, failed):
    """Every body of a batch, :data:`BLOCK` at a time in parallel: ``Z`` (nz, N), ``RN``
    (9, N), ``inv_I`` (9, N), ``m`` (N,), ``F`` (3, N) (the columns are the bodies; ``Z``,
    ``RN`` end as the last states); ``problem`` holds the tableau and the shared loads
    (:class:`~tumble.rigid.kernels.Problem`). ``records``, ``counts``, ``failed`` as for
    :func:`~tumble.rigid.kernels._batch` (the cause of a stop is always ``NON_FINITE``)."""
    n_bodies = Z.shape[1]
    for block in prange((n_bodies + BLOCK - 1) // BLOCK):
        j0 = block * BLOCK
        j1 = min(j0 + BLOCK, n_bodies)
        z, Rn = np.ascontiguousarray(Z[:, j0:j1]), np.ascontiguousarray(RN[:, j0:j1])
        _block(quat, problem, grid, z, Rn, np.ascontiguousarray(inv_I[:, j0:j1]),
               np.ascontiguousarray(m[j0:j1]), np.ascontiguousarray(F[:, j0:j1]), every, j0,
               records, counts, failed)  # fmt: skip
        Z[:, j0:j1] = z
        RN[:, j0:j1] = Rn
