"""Compiled (numba) fixed-step loops: the same algorithm as :mod:`tumble.rigid.steppers`.

One kernel runs every fixed-step method for constant loads: a stage loop over the tableau
(``A``, ``b``, ``c`` as arrays), the family's vector field in a chart, and the family's map
back (``R_n exp(û)``, quaternion renormalisation, or nothing). No allocation happens inside
the step loop; every work array is made once per call. ``tests/rigid`` checks that kernel and
reference agree to round-off.

Families: 0 = matrix (``z = (vec R, x, p, L)``), 1 = quat (``z = (q, x, p, L)``),
2 = lie (``z = (u, x, p, L)`` with ``R = R_n exp(û)``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from tumble.ode.solve import fixed_step_count

FAMILY_CODES = {"matrix": 0, "quat": 1, "lie": 2}
_ATTITUDE_SIZE = (9, 4, 3)
_SERIES_ANGLE = 1e-4


@njit(cache=True)
def _exp(u0, u1, u2, out):
    """Rodrigues: ``out = exp(û) = I + sin θ/θ û + (1 − cos θ)/θ² û²``."""
    theta2 = u0 * u0 + u1 * u1 + u2 * u2
    theta = math.sqrt(theta2)
    if theta < _SERIES_ANGLE:
        a = 1.0 - theta2 / 6.0
        b = 0.5 - theta2 / 24.0
    else:
        a = math.sin(theta) / theta
        b = (1.0 - math.cos(theta)) / theta2
    out[0, 0] = 1.0 - b * (u1 * u1 + u2 * u2)
    out[1, 1] = 1.0 - b * (u0 * u0 + u2 * u2)
    out[2, 2] = 1.0 - b * (u0 * u0 + u1 * u1)
    out[0, 1] = -a * u2 + b * u0 * u1
    out[1, 0] = a * u2 + b * u0 * u1
    out[0, 2] = a * u1 + b * u0 * u2
    out[2, 0] = -a * u1 + b * u0 * u2
    out[1, 2] = -a * u0 + b * u1 * u2
    out[2, 1] = a * u0 + b * u1 * u2


@njit(cache=True)
def _matmul3(A, B, out):
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]


@njit(cache=True)
def _quat_matrix(q0, q1, q2, q3, out):
    """Rotation matrix of the unit quaternion ``(q0, q1, q2, q3)`` (scalar first)."""
    out[0, 0] = 1 - 2 * (q2 * q2 + q3 * q3)
    out[0, 1] = 2 * (q1 * q2 - q0 * q3)
    out[0, 2] = 2 * (q1 * q3 + q0 * q2)
    out[1, 0] = 2 * (q1 * q2 + q0 * q3)
    out[1, 1] = 1 - 2 * (q1 * q1 + q3 * q3)
    out[1, 2] = 2 * (q2 * q3 - q0 * q1)
    out[2, 0] = 2 * (q1 * q3 - q0 * q2)
    out[2, 1] = 2 * (q2 * q3 + q0 * q1)
    out[2, 2] = 1 - 2 * (q1 * q1 + q2 * q2)


@njit(cache=True)
def _omega(R, inv_I, L, out):
    """``out = I⁻¹ Rᵀ L``."""
    b0 = R[0, 0] * L[0] + R[1, 0] * L[1] + R[2, 0] * L[2]
    b1 = R[0, 1] * L[0] + R[1, 1] * L[1] + R[2, 1] * L[2]
    b2 = R[0, 2] * L[0] + R[1, 2] * L[1] + R[2, 2] * L[2]
    for i in range(3):
        out[i] = inv_I[i, 0] * b0 + inv_I[i, 1] * b1 + inv_I[i, 2] * b2


@njit(cache=True)
def _rates(z, off, R, m, F, tau, points, point_forces, out):
    """``out[off:off+9] = (p/m, F, τ)`` for ``z[off:off+9] = (x, p, L)`` at attitude R."""
    for i in range(3):
        out[off + i] = z[off + 3 + i] / m
        out[off + 3 + i] = F[i]
        out[off + 6 + i] = tau[i]
    for k in range(points.shape[0]):
        r0 = R[0, 0] * points[k, 0] + R[0, 1] * points[k, 1] + R[0, 2] * points[k, 2]
        r1 = R[1, 0] * points[k, 0] + R[1, 1] * points[k, 1] + R[1, 2] * points[k, 2]
        r2 = R[2, 0] * points[k, 0] + R[2, 1] * points[k, 1] + R[2, 2] * points[k, 2]
        f0, f1, f2 = point_forces[k, 0], point_forces[k, 1], point_forces[k, 2]
        out[off + 3] += f0
        out[off + 4] += f1
        out[off + 5] += f2
        out[off + 6] += r1 * f2 - r2 * f1
        out[off + 7] += r2 * f0 - r0 * f2
        out[off + 8] += r0 * f1 - r1 * f0


@njit(cache=True)
def _dexpinv_neg(u, w, out):
    """``out[:3] = dexp⁻¹_{−u}(w) = w + ½ u×w + α u×(u×w)``, α = (1 − (θ/2)cot(θ/2))/θ²."""
    theta2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2]
    if theta2 < _SERIES_ANGLE * _SERIES_ANGLE:
        alpha = 1.0 / 12.0 + theta2 / 720.0
    else:
        half = 0.5 * math.sqrt(theta2)
        alpha = (1.0 - half * math.cos(half) / math.sin(half)) / theta2
    c0 = u[1] * w[2] - u[2] * w[1]
    c1 = u[2] * w[0] - u[0] * w[2]
    c2 = u[0] * w[1] - u[1] * w[0]
    out[0] = w[0] + 0.5 * c0 + alpha * (u[1] * c2 - u[2] * c1)
    out[1] = w[1] + 0.5 * c1 + alpha * (u[2] * c0 - u[0] * c2)
    out[2] = w[2] + 0.5 * c2 + alpha * (u[0] * c1 - u[1] * c0)


@njit(cache=True)
def _field(family, correct, zs, Rn, inv_I, m, F, tau, points, point_forces, out, R, E, w):
    """The family's vector field at the stage value ``zs``; writes ``out``."""
    if family == 0:
        for i in range(3):
            for j in range(3):
                R[i, j] = zs[3 * i + j]
        _omega(R, inv_I, zs[15:18], w)
        for i in range(3):  # Ṙ = R ω̂
            out[3 * i + 0] = R[i, 1] * w[2] - R[i, 2] * w[1]
            out[3 * i + 1] = R[i, 2] * w[0] - R[i, 0] * w[2]
            out[3 * i + 2] = R[i, 0] * w[1] - R[i, 1] * w[0]
        _rates(zs, 9, R, m, F, tau, points, point_forces, out)
    elif family == 1:
        norm = math.sqrt(zs[0] ** 2 + zs[1] ** 2 + zs[2] ** 2 + zs[3] ** 2)
        _quat_matrix(zs[0] / norm, zs[1] / norm, zs[2] / norm, zs[3] / norm, R)
        _omega(R, inv_I, zs[10:13], w)
        out[0] = 0.5 * (-zs[1] * w[0] - zs[2] * w[1] - zs[3] * w[2])  # ½ q ⊗ (0, ω)
        out[1] = 0.5 * (zs[0] * w[0] + zs[2] * w[2] - zs[3] * w[1])
        out[2] = 0.5 * (zs[0] * w[1] + zs[3] * w[0] - zs[1] * w[2])
        out[3] = 0.5 * (zs[0] * w[2] + zs[1] * w[1] - zs[2] * w[0])
        _rates(zs, 4, R, m, F, tau, points, point_forces, out)
    else:
        _exp(zs[0], zs[1], zs[2], E)
        _matmul3(Rn, E, R)
        _omega(R, inv_I, zs[9:12], w)
        if correct:
            _dexpinv_neg(zs, w, out)
        else:
            out[0], out[1], out[2] = w[0], w[1], w[2]
        _rates(zs, 3, R, m, F, tau, points, point_forces, out)


@njit(cache=True)
def _record(family, z, Rn, R, count, t, rec_t, rec_R, rec_q, rec_Y):
    rec_t[count] = t
    if family == 0:
        for i in range(3):
            for j in range(3):
                rec_R[count, i, j] = z[3 * i + j]
    elif family == 1:
        _quat_matrix(z[0], z[1], z[2], z[3], R)
        rec_R[count] = R
        rec_q[count] = z[:4]
    else:
        rec_R[count] = Rn
    off = _offset(family)
    rec_Y[count] = z[off : off + 9]


@njit(cache=True)
def _offset(family):
    return 9 if family == 0 else (4 if family == 1 else 3)


@njit(cache=True)
def _step_to(family, z, Rn, znew, E, Rtmp):
    """Map the chart's new value back: ``R_n ← R_n exp(û)``, or ``q ← q/|q|``; then z ← znew."""
    if family == 2:
        _exp(znew[0], znew[1], znew[2], E)
        _matmul3(Rn, E, Rtmp)
        Rn[:, :] = Rtmp
        znew[0] = znew[1] = znew[2] = 0.0
    elif family == 1:
        norm = math.sqrt(znew[0] ** 2 + znew[1] ** 2 + znew[2] ** 2 + znew[3] ** 2)
        for i in range(4):
            znew[i] /= norm
    z[:] = znew


@njit(cache=True)
def run_fixed(family, correct, A, b, z, Rn, t_a, h, k0, k1, n, t_b, inv_I, m, F, tau,
              points, point_forces, record_every, step0, rec_t, rec_R, rec_q, rec_Y):  # fmt: skip
    """Steps ``k0+1 … k1`` of the grid ``t_a + k h`` (step ``n`` lands on ``t_b``).

    ``z`` (and ``Rn`` for the lie family) hold the state and are updated in place. A step is
    recorded when ``step0 + k`` is a multiple of ``record_every``. Returns ``(recorded,
    failed)`` with ``failed`` the step whose result was not finite, or -1.
    """
    s, nz = b.shape[0], z.shape[0]
    K, zs, znew = np.empty((s, nz)), np.empty(nz), np.empty(nz)
    R, E, Rtmp, w = np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)), np.empty(3)
    count = 0
    for k in range(k0 + 1, k1 + 1):
        t_old = t_a + (k - 1) * h
        hk = (t_b if k == n else t_a + k * h) - t_old
        for i in range(s):
            for q in range(nz):
                acc = 0.0
                for j in range(i):
                    acc += A[i, j] * K[j, q]
                zs[q] = z[q] + hk * acc
            _field(family, correct, zs, Rn, inv_I, m, F, tau, points, point_forces, K[i], R, E, w)
        finite = True
        for q in range(nz):
            acc = 0.0
            for i in range(s):
                acc += b[i] * K[i, q]
            znew[q] = z[q] + hk * acc
            finite = finite and math.isfinite(znew[q])
        if not finite:
            return count, k
        _step_to(family, z, Rn, znew, E, Rtmp)
        if (step0 + k) % record_every == 0:
            _record(family, z, Rn, R, count, t_old + hk, rec_t, rec_R, rec_q, rec_Y)
            count += 1
    return count, -1


def pack(family: str, attitude: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The kernel's ``(z, Rn)`` for a family's attitude (R or q) and ``Y = (x, p, L)``."""
    if family == "lie":
        return np.concatenate([np.zeros(3), Y]), np.array(attitude, dtype=float)
    return np.concatenate([np.ravel(attitude), Y]), np.eye(3)


def unpack(family: str, z: np.ndarray, Rn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`pack`."""
    if family == "lie":
        return Rn.copy(), z[3:].copy()
    size = _ATTITUDE_SIZE[FAMILY_CODES[family]]
    attitude = z[:size].reshape(3, 3) if family == "matrix" else z[:size]
    return attitude.copy(), z[size:].copy()


def _chunks(n: int, progress: bool) -> list[tuple[int, int]]:
    size = max(1, n // 50) if progress else n
    return [(k0, min(k0 + size, n)) for k0 in range(0, n, size)]


def run_segment(run, b: float, h: float, loads, advance) -> bool:
    """Integrate ``run`` from ``run.t`` to ``b`` with the kernel; False if it stopped."""
    F, tau, points, point_forces = loads
    family, method = run.method.family, run.method
    code, A, weights = FAMILY_CODES[family], method.tableau.A, method.tableau.b
    inv_I, every, a = run.dynamics.inertia_inverse, run.record_every, run.t
    n = fixed_step_count(a, b, h)
    z, Rn = pack(family, run.attitude, run.Y)
    for k0, k1 in _chunks(n, advance is not None):
        size = (k1 - k0) // every + 1
        rec_t, rec_R = np.empty(size), np.empty((size, 3, 3))
        rec_q, rec_Y = np.empty((size, 4)), np.empty((size, 9))
        count, failed = run_fixed(code, method.dexpinv, A, weights, z, Rn, a, h, k0, k1, n, b,
                                  inv_I, run.dynamics.mass, F, tau, points, point_forces, every,
                                  run.n_steps - k0, rec_t, rec_R, rec_q, rec_Y)  # fmt: skip
        q_block = rec_q[:count] if family == "quat" else None
        run.extend(rec_t[:count], rec_R[:count], rec_Y[:count], q_block)
        attitude, Y = unpack(family, z, Rn)
        done = k1 if failed < 0 else failed - 1
        t_done = b if done == n else a + done * h
        run.n_steps += done - k0
        run.t, run.attitude, run.Y = t_done, attitude, Y
        if failed >= 0:
            run.fail_non_finite(t_done, b if failed == n else a + failed * h)
            return False
        if advance is not None:
            advance(run.t)
    return True
