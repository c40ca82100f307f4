"""Structure-of-arrays batch loops: bodies side by side, so the loops over bodies vectorise.

:func:`~tumble.rigid.simulate_batch` runs every body through the one-body loop of
:mod:`tumble.rigid._compiled` (one body at a time per thread: "array of structures"). Here
the ``lie`` and ``quat`` charts (``rkmk4``, ``rkmk8``, ``lie-euler``, ``seed-rk4``,
``rk4-quat``, ``euler-quat``) get a second loop in which the bodies are columns:
:func:`run_batch` takes the batch as it is (``Z`` (N, nz), ``R_n`` (N, 3, 3), the body data
in the :class:`~tumble.rigid._compiled.base.KernelProblem`) and each block of :data:`BLOCK`
bodies copies its columns into contiguous work arrays (``z`` (nz, B), ``R_n`` (9, B),
``I⁻¹`` (9, B), ``m`` (B,), ``F`` (3, B)), marches them over the driver's block of steps
and copies them back; the blocks run in parallel (``prange``), so the transposes do too.
Each stage is a few loops over the bodies of the block whose bodies are plain arithmetic on
contiguous rows, so LLVM turns them into packed (SIMD) instructions
(``tests/rigid/test_rigid_batch.py`` checks the assembly for packed ``vmulpd``). What keeps
them packed: no call and no branch in a loop over bodies (the rare branches run as a
second, scalar loop after it), and few rows written per loop (a loop that also wrote the
nine rows of the loads was judged not worth vectorising). What makes them cheap: a stage
sum keeps up to four terms in a register (:func:`_combine`: one pass over the rows instead
of one per term), the positions, which no field reads, get no stage sum, and the exp and
dexp⁻¹ series take one loop for all bodies.

The arithmetic is the one-body loop's, operation for operation in the same order
(:func:`~tumble.rigid._compiled.charts._lie_field`, ``_quat_field``, ``_loads``, the stage
sums, less the zero terms of a tableau, which change no number: :func:`_terms`): no fastmath, so no
reassociation or fused multiply-add, and every body gets bit for bit the numbers of
:func:`~tumble.rigid.simulate` (the batch tests compare with ``assert_array_equal``).
The two branches of that arithmetic become: the ``exp`` and ``dexp⁻¹`` coefficients from
their series for all bodies (a vector loop), then the few bodies whose angle is at least
:data:`~tumble.rigid._compiled.charts.SERIES_ANGLE` recomputed by the one-body functions (a scalar
loop); a body whose new state is not finite stops alone, as in the one-body loop (its state
is left at the step before; the test ``Σ 0·x == 0`` on its numbers is vectorised,
the bookkeeping of a stop is scalar and rare).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from tumble.rigid._compiled.base import _JIT, _cross, _gradient, _quat_matrix, _rotate
from tumble.rigid._compiled.charts import (
    _SERIES2,
    _dexpinv_coefficient,
    _dexpinv_series,
    _exp_coefficients,
    _exp_series,
)

BLOCK = 256
"""Bodies marched together by one thread (their work arrays stay in the L2 cache)."""


@njit(**_JIT)
def _terms(A, b):
    """The stage sums' terms: ``(w, l, count)`` with ``Σ_{l<i} a_il k_l`` = the sum of
    ``w[i, t] k_{l[i, t]}`` for ``t < count[i]`` (stage ``i < s``; row ``s``: ``b``).

    The zero ``a_il`` are left out when no ``b_i`` is zero, and then it changes no number:
    the one-body sum starts from ``+0.0`` and, rounding to nearest, never becomes ``−0.0``,
    so adding ``0·k_l = ±0`` (``k_l`` finite) leaves it as it is; a ``k_l`` that is not
    finite makes ``z + h Σ b_i k_i`` not finite in both loops (``b_l ≠ 0``), and the body
    stops in that step with nothing of it kept. (``rkmk4``: stages 3 and 4 have one term.)
    """
    s = b.shape[0]
    skip = True
    for i in range(s):
        skip = skip and b[i] != 0.0
    w, terms, count = (
        np.zeros((s + 1, s)),
        np.zeros((s + 1, s), np.int64),
        np.zeros(s + 1, np.int64),
    )
    for i in range(s + 1):
        for l in range(i if i < s else s):
            weight = A[i, l] if i < s else b[l]
            if i == s or not (skip and weight == 0.0):
                w[i, count[i]], terms[i, count[i]] = weight, l
                count[i] += 1
    return w, terms, count


@njit(**_JIT)
def _combine(stage, i, h, z, K, c, out):
    """``out[c] = z[c] + h Σ_t w[i, t] K[terms[i, t], c]`` for every body (``stage`` = ``(w,
    terms, count)`` of :func:`_terms`): the one-body sum, term by term from ``0.0`` in the
    same order; up to four terms stay in registers (one pass over the row)."""
    w, terms, count = stage[0], stage[1], stage[2][i]
    n = out.shape[1]
    if count == 0:
        for j in range(n):
            out[c, j] = z[c, j] + h * 0.0
        return
    w0, l0 = w[i, 0], terms[i, 0]
    if count == 1:
        for j in range(n):
            out[c, j] = z[c, j] + h * (0.0 + w0 * K[l0, c, j])
        return
    w1, l1 = w[i, 1], terms[i, 1]
    if count == 2:
        for j in range(n):
            out[c, j] = z[c, j] + h * ((0.0 + w0 * K[l0, c, j]) + w1 * K[l1, c, j])
        return
    w2, l2 = w[i, 2], terms[i, 2]
    if count == 3:
        for j in range(n):
            acc = (0.0 + w0 * K[l0, c, j]) + w1 * K[l1, c, j]
            out[c, j] = z[c, j] + h * (acc + w2 * K[l2, c, j])
        return
    w3, l3 = w[i, 3], terms[i, 3]
    for j in range(n):
        acc = (0.0 + w0 * K[l0, c, j]) + w1 * K[l1, c, j]
        out[c, j] = (acc + w2 * K[l2, c, j]) + w3 * K[l3, c, j]
    for t in range(4, count):
        wt, lt = w[i, t], terms[i, t]
        for j in range(n):
            out[c, j] += wt * K[lt, c, j]
    for j in range(n):
        out[c, j] = z[c, j] + h * out[c, j]


@njit(**_JIT)
def _stage_state(stage, i, h, z, K, zs, off, positions):
    """``zs = z + h Σ_{l<i} a_il K_l`` (:func:`_combine`, ``stage`` from :func:`_terms`) for
    the numbers the fields read: all but the positions ``x`` (rows ``off … off+2``), which
    no field or load depends on but a point mass's gravity (``positions``)."""
    for c in range(z.shape[0]):
        if positions or c < off or c >= off + 3:
            _combine(stage, i, h, z, K, c, zs)


@njit(**_JIT)
def _new_state(stage, h, z, K, zn, bad):
    """``zn = z + h Σ b_i K_i`` (:func:`_combine`, the last row of ``stage``); ``bad[j]``:
    body j's new state has a non-finite number (``Σ 0·zn`` is 0 exactly when every number
    is finite, NaN otherwise)."""
    s, (nz, n) = stage[2].shape[0] - 1, z.shape
    for j in range(n):
        bad[j] = 0.0
    for c in range(nz):
        _combine(stage, s, h, z, K, c, zn)
        for j in range(n):
            bad[j] += 0.0 * zn[c, j]
    any_bad = False
    for j in range(n):
        any_bad = any_bad or bad[j] != 0.0
    return any_bad


@njit(**_JIT)
def _loads_soa(off, zs, m, F, tau, K, i):
    """:func:`~tumble.rigid._compiled.base._loads` but the points' for every body: ``ẋ = p/m``,
    ``ṗ = F``, ``L̇ = τ`` (rows ``off …`` of ``K[i]``; ``zs[off:]`` = ``(x, p, L)``)."""
    t0, t1, t2 = tau[0], tau[1], tau[2]
    for j in range(m.shape[0]):
        K[i, off, j] = zs[off + 3, j] / m[j]
        K[i, off + 1, j] = zs[off + 4, j] / m[j]
        K[i, off + 2, j] = zs[off + 5, j] / m[j]
        K[i, off + 3, j], K[i, off + 4, j], K[i, off + 5, j] = F[0, j], F[1, j], F[2, j]
        K[i, off + 6, j], K[i, off + 7, j], K[i, off + 8, j] = t0, t1, t2


@njit(**_JIT)
def _point_loads(off, R, u, a, b, points, point_forces, K, i):
    """The point loads of :func:`~tumble.rigid._compiled.base._loads` for every body:
    ``ṗ += f_k``, ``L̇ += (R exp(û) r_k) × f_k`` (``R`` (9, B) row-major; ``u`` (3, B))."""
    n = K.shape[2]
    for k in range(points.shape[0]):
        v0, v1, v2 = points[k, 0], points[k, 1], points[k, 2]
        f0, f1, f2 = point_forces[k, 0], point_forces[k, 1], point_forces[k, 2]
        for j in range(n):
            r0, r1, r2 = _rotate(a[j], b[j], u[0, j], u[1, j], u[2, j], v0, v1, v2)
            s0 = R[0, j] * r0 + R[1, j] * r1 + R[2, j] * r2
            s1 = R[3, j] * r0 + R[4, j] * r1 + R[5, j] * r2
            s2 = R[6, j] * r0 + R[7, j] * r1 + R[8, j] * r2
            t0, t1, t2 = _cross(s0, s1, s2, f0, f1, f2)
            K[i, off + 3, j] += f0
            K[i, off + 4, j] += f1
            K[i, off + 5, j] += f2
            K[i, off + 6, j] += t0
            K[i, off + 7, j] += t1
            K[i, off + 8, j] += t2


@njit(**_JIT)
def _gravity_loads(off, zs, R, u, a, b, m, inertia, gravity, K, i):
    """The point masses' loads of :func:`~tumble.rigid._compiled.base._loads` for every body
    (:func:`~tumble.rigid._compiled.base._gradient`, the same function: the same numbers);
    ``R``, ``inertia`` (9, B) row-major, ``u`` (3, B), positions in rows ``off …`` of ``zs``.
    A scalar loop (a call per body): the point masses are rare, their arithmetic long."""
    for k in range(gravity.shape[0]):
        mu, c0, c1, c2 = gravity[k, 0], gravity[k, 1], gravity[k, 2], gravity[k, 3]
        for j in range(K.shape[2]):
            Rt = (R[0, j], R[1, j], R[2, j], R[3, j], R[4, j], R[5, j], R[6, j], R[7, j],
                  R[8, j])  # fmt: skip
            It = (inertia[0, j], inertia[1, j], inertia[2, j], inertia[3, j], inertia[4, j],
                  inertia[5, j], inertia[6, j], inertia[7, j], inertia[8, j])  # fmt: skip
            f0, f1, f2, t0, t1, t2 = _gradient(
                mu, m[j], zs[off, j] - c0, zs[off + 1, j] - c1, zs[off + 2, j] - c2, Rt, a[j],
                b[j], u[0, j], u[1, j], u[2, j], It,
            )  # fmt: skip
            K[i, off + 3, j] += f0
            K[i, off + 4, j] += f1
            K[i, off + 5, j] += f2
            K[i, off + 6, j] += t0
            K[i, off + 7, j] += t1
            K[i, off + 8, j] += t2


@njit(**_JIT)
def _coefficients(u, coefficients, dexpinv):
    """Per body: exp's ``(a, b)`` for ``θ²`` of ``u`` (rows 0 … 2 of ``u``) and, if
    ``dexpinv``, dexp⁻¹'s ``α`` into the rows of ``coefficients`` (3, B): the series for all
    bodies in one vector loop, then the exact forms (:func:`~tumble.rigid._compiled.charts.
    _exp_coefficients`, ``_dexpinv_coefficient``) for the few bodies whose angle is not
    small."""
    n = u.shape[1]
    large = 0
    for j in range(n):
        x = u[0, j] * u[0, j] + u[1, j] * u[1, j] + u[2, j] * u[2, j]
        large += x >= _SERIES2
        coefficients[0, j], coefficients[1, j] = _exp_series(x)
        coefficients[2, j] = _dexpinv_series(x) if dexpinv else 0.0
    if large == 0:
        return
    for j in range(n):
        x = u[0, j] * u[0, j] + u[1, j] * u[1, j] + u[2, j] * u[2, j]
        if x >= _SERIES2:
            coefficients[0, j], coefficients[1, j] = _exp_coefficients(x)
            coefficients[2, j] = _dexpinv_coefficient(x) if dexpinv else 0.0


@njit(**_JIT)
def _lie_field_soa(correct, zs, Rn, inv_I, m, F, tau, coefficients, K, i):
    """:func:`~tumble.rigid._compiled.charts._lie_field` and the loads but the points'
    (:func:`~tumble.rigid._compiled.base._loads`) for every body: ``u̇ = dexp⁻¹_{−u}(ω)``,
    ``ω = I⁻¹ exp(−û) R_nᵀ L``; ``coefficients`` (3, B) gets exp's ``(a, b)`` and dexp⁻¹'s
    ``α`` (:func:`_coefficients`), then a vector loop does the field, :func:`_loads_soa` the
    loads."""
    n = zs.shape[1]
    _coefficients(zs, coefficients, correct)
    half = 0.5 if correct else 0.0
    for j in range(n):
        u0, u1, u2 = zs[0, j], zs[1, j], zs[2, j]
        L0, L1, L2 = zs[9, j], zs[10, j], zs[11, j]
        v0 = Rn[0, j] * L0 + Rn[3, j] * L1 + Rn[6, j] * L2
        v1 = Rn[1, j] * L0 + Rn[4, j] * L1 + Rn[7, j] * L2
        v2 = Rn[2, j] * L0 + Rn[5, j] * L1 + Rn[8, j] * L2
        e0, e1, e2 = _rotate(-coefficients[0, j], coefficients[1, j], u0, u1, u2, v0, v1, v2)
        w0 = inv_I[0, j] * e0 + inv_I[1, j] * e1 + inv_I[2, j] * e2
        w1 = inv_I[3, j] * e0 + inv_I[4, j] * e1 + inv_I[5, j] * e2
        w2 = inv_I[6, j] * e0 + inv_I[7, j] * e1 + inv_I[8, j] * e2
        K[i, 0, j], K[i, 1, j], K[i, 2, j] = _rotate(
            half, coefficients[2, j], u0, u1, u2, w0, w1, w2
        )
    _loads_soa(3, zs, m, F, tau, K, i)


@njit(**_JIT)
def _lie_turn_soa(zn, Rn, coefficients, alive):
    """``R_n ← R_n exp(û)`` for the living bodies (row r of the product is ``exp(−û)`` of
    row r), ``u`` from ``zn``: :func:`~tumble.rigid._compiled.charts._lie_advance` but ``z``."""
    _coefficients(zn, coefficients, False)
    for j in range(Rn.shape[1]):
        u0, u1, u2 = zn[0, j], zn[1, j], zn[2, j]
        ma, b, keep = -coefficients[0, j], coefficients[1, j], alive[j]
        for r in range(3):
            v0, v1, v2 = Rn[3 * r, j], Rn[3 * r + 1, j], Rn[3 * r + 2, j]
            w0, w1, w2 = _rotate(ma, b, u0, u1, u2, v0, v1, v2)
            Rn[3 * r, j] = w0 if keep else v0
            Rn[3 * r + 1, j] = w1 if keep else v1
            Rn[3 * r + 2, j] = w2 if keep else v2


@njit(**_JIT)
def _quat_field_soa(zs, R, inv_I, m, F, tau, K, i):
    """:func:`~tumble.rigid._compiled.charts._quat_field` and the loads but the points' for every
    body: ``q̇ = ½ q ⊗ (0, ω)``, ``ω = I⁻¹ Rᵀ L`` with ``R = R(q/|q|)`` written to ``R``
    (9, B) (two loops: each vectorises)."""
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
    _loads_soa(4, zs, m, F, tau, K, i)


@njit(**_JIT)
def _quat_start_soa(z):
    """:func:`~tumble.rigid._compiled.charts._quat_start`: ``q ← q/|q|`` for every body."""
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
def _block(quat, problem, grid, z, Rn, inv_I, m, F, k0, k1, every, step0, j0, records, counts,
           failed):  # fmt: skip
    """March the bodies ``j0 …`` of one block (their columns ``z``, ``Rn``, ``inv_I``, ``m``,
    ``F``, contiguous) over steps ``k0 + 1 … k1`` of the grid; the one-body loop's steps,
    body by body (a body stopped before, ``failed[j] >= 0``, stays as it is)."""
    A, b, correct = problem.A, problem.b, problem.correct
    tau, points, point_forces = problem.tau, problem.points, problem.point_forces
    gravity = problem.gravity
    positions = gravity.shape[0] > 0
    inertia = _columns(problem.inertia, j0, j0 + z.shape[1]) if positions else np.empty((9, 0))
    t_a, t_b, h, n_steps = grid
    s, (nz, n) = b.shape[0], z.shape
    off = 4 if quat else 3
    K, zs, zn = np.empty((s, nz, n)), np.empty((nz, n)), np.empty((nz, n))
    R, coefficients, bad = np.empty((9, n)), np.empty((3, n)), np.empty(n)
    alive, zero = np.ones(n, dtype=np.bool_), np.zeros((4, n))
    stage, state, swapped, dead = _terms(A, b), z, False, 0
    for j in range(n):
        if failed[j0 + j] >= 0:
            alive[j], dead = False, dead + 1
    count, until_record = 0, every - (step0 + k0) % every
    for k in range(k0 + 1, k1 + 1):
        t_old = t_a + (k - 1) * h
        hk = (t_b if k == n_steps else t_a + k * h) - t_old
        if quat:
            _quat_start_soa(z)
        for i in range(s):
            _stage_state(stage, i, hk, z, K, zs, off, positions)
            if quat:  # R(q/|q|) turns the points: no exp(û) (u = 0, a = b = 0)
                _quat_field_soa(zs, R, inv_I, m, F, tau, K, i)
                if points.shape[0]:
                    _point_loads(off, R, zero[0:3], zero[3], zero[3], points, point_forces, K, i)
                if positions:
                    _gravity_loads(off, zs, R, zero[0:3], zero[3], zero[3], m, inertia, gravity,
                                   K, i)  # fmt: skip
            else:
                _lie_field_soa(correct, zs, Rn, inv_I, m, F, tau, coefficients, K, i)
                if points.shape[0]:
                    _point_loads(off, Rn, zs[0:3], coefficients[0], coefficients[1], points,
                                 point_forces, K, i)  # fmt: skip
                if positions:
                    _gravity_loads(off, zs, Rn, zs[0:3], coefficients[0], coefficients[1], m,
                                   inertia, gravity, K, i)  # fmt: skip
        if _new_state(stage, hk, z, K, zn, bad):
            for j in range(n):
                if not bad[j] == 0.0 and alive[j]:
                    alive[j], dead = False, dead + 1
                    failed[j0 + j], counts[j0 + j] = k, count
        if not quat:
            _lie_turn_soa(zn, Rn, coefficients, alive)
        if dead == 0:  # every body takes its new state: the arrays change places
            z, zn, swapped = zn, z, not swapped
        else:
            for c in range(nz):
                for j in range(n):
                    z[c, j] = zn[c, j] if alive[j] else z[c, j]
        if not quat:  # u ← 0 (a stopped body's u is 0 already)
            for c in range(3):
                for j in range(n):
                    z[c, j] = 0.0
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
    if swapped:
        state[:, :] = z


@njit(**_JIT)
def _columns(rows, j0, j1):
    """``rows[j0:j1].T`` (bodies as rows, flattened) as a contiguous (…, j1 − j0) array."""
    flat = rows.reshape(rows.shape[0], -1)
    out = np.empty((flat.shape[1], j1 - j0))
    for j in range(j1 - j0):
        for c in range(flat.shape[1]):
            out[c, j] = flat[j0 + j, c]
    return out


@njit(parallel=True, **_JIT)
def run_batch(quat, problem, grid, Z, RN, k0, k1, every, step0, records, counts, failed):
    """Steps ``k0 + 1 … k1`` of the grid for every body of a batch, :data:`BLOCK` at a time
    in parallel: ``Z`` (N, nz), ``RN`` (N, 3, 3) (end as the last states), body ``k``'s data
    ``problem.inv_I[k]`` (3, 3), ``problem.m[k]``, ``problem.F[k]`` (3,) and the shared loads
    (:class:`~tumble.rigid._compiled.base.KernelProblem`); each block works on its bodies as
    columns (copied in and out). ``records``, ``counts``, ``failed`` as for
    :func:`~tumble.rigid._compiled.charts._batch` (the cause of a stop is always
    ``NON_FINITE``)."""
    n_bodies = Z.shape[0]
    for block in prange((n_bodies + BLOCK - 1) // BLOCK):
        j0 = block * BLOCK
        j1 = min(j0 + BLOCK, n_bodies)
        z, Rn = _columns(Z, j0, j1), _columns(RN, j0, j1)
        m = np.ascontiguousarray(problem.m[j0:j1])
        _block(quat, problem, grid, z, Rn, _columns(problem.inv_I, j0, j1), m,
               _columns(problem.F, j0, j1), k0, k1, every, step0, j0, records, counts,
               failed)  # fmt: skip
        for j in range(j1 - j0):
            for c in range(z.shape[0]):
                Z[j0 + j, c] = z[c, j]
            for c in range(9):
                RN[j0 + j, c // 3, c % 3] = Rn[c, j]
