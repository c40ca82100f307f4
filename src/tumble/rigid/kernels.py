"""Compiled (numba) fixed-step loops: the same algorithm as :mod:`tumble.rigid.steppers`.

One loop, :func:`run_fixed`, runs every fixed-step method for constant loads: a stage loop
over the tableau (``A``, ``b`` as arrays), the family's vector field in a chart, and the
family's map back. A family is three compiled functions (field, advance, record), and
:func:`_compile_loop` compiles the loop once per family with that family's functions inlined
(the other families' branches are dropped at compile time):

=========  ==========================  ==========================  ===========================
family     ``z``                       vector field                map back
=========  ==========================  ==========================  ===========================
matrix     ``(vec R, x, p, L)``        ``Ṙ = R ω̂``                 nothing
quat       ``(q, x, p, L)``            ``q̇ = ½ q ⊗ (0, ω)``        ``q ← q/|q|``
lie        ``(u, x, p, L)``            ``u̇ = dexp⁻¹_{−u}(ω)``      ``R_n ← R_n exp(û)``, u ← 0
=========  ==========================  ==========================  ===========================

with ``ω = I⁻¹ Rᵀ L``, ``ẋ = p/m``, ``ṗ = F``, ``L̇ = τ + Σ (R r_k) × f_k``.

Why it is fast: the fields work on scalar locals; nothing is allocated inside the step loop
(the work arrays are made once per call); the ``lie`` field never forms ``R = R_n exp(û)``, it
needs only ``Rᵀ L = exp(−û) (R_nᵀ L)`` (Rodrigues' formula on one vector); and no array is
passed into inlined code under a runtime branch, which costs numba an atomic reference-count
update per array per stage (most of the time of the earlier version, which branched on the
family inside one loop). The
``exp`` and ``dexp⁻¹`` coefficients come from their Taylor series below :data:`SERIES_ANGLE`
(accurate to round-off there, and free of the cancellation in ``1 − cos θ``). No fastmath:
``tests/rigid`` checks that kernel and NumPy reference agree to round-off.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from tumble.ode.solve import fixed_step_count

SERIES_ANGLE = 0.25
"""Below this angle (rad) the exp and dexp⁻¹ coefficients use their Taylor series; the first
term left out is below 1e-17 relative (θ¹²/13! for sin θ/θ, 8e-19 for dexp⁻¹)."""

_JIT = dict(cache=True, error_model="numpy")  # numpy error model: no ZeroDivisionError checks
_INLINE = dict(_JIT, inline="always")
_SERIES2 = SERIES_ANGLE * SERIES_ANGLE
_S1, _S2, _S3, _S4, _S5 = -1.0 / 6, 1.0 / 120, -1.0 / 5040, 1.0 / 362880, -1.0 / 39916800
_C1, _C2, _C3, _C4, _C5 = -1.0 / 24, 1.0 / 720, -1.0 / 40320, 1.0 / 3628800, -1.0 / 479001600


@njit(**_JIT)
def _exp_coefficients(theta2):
    """``(sin θ/θ, (1 − cos θ)/θ²)`` for ``θ² = theta2``."""
    x = theta2
    if x < _SERIES2:  # Horner in θ²: Σ (−θ²)^k/(2k+1)! and Σ (−θ²)^k/(2k+2)!
        a = 1.0 + x * (_S1 + x * (_S2 + x * (_S3 + x * (_S4 + x * _S5))))
        b = 0.5 + x * (_C1 + x * (_C2 + x * (_C3 + x * (_C4 + x * _C5))))
        return a, b
    theta = math.sqrt(x)
    half = math.sin(0.5 * theta) / theta
    return math.sin(theta) / theta, 2.0 * half * half


@njit(**_JIT)
def _dexpinv_coefficient(theta2):
    """``α = (1 − (θ/2) cot(θ/2))/θ²``; Bernoulli series ``1/12 + θ²/720 + …`` when small."""
    x = theta2
    if x < _SERIES2:
        tail = 1 / 1209600 + x * (1 / 47900160 + x * (691 / 1307674368000))  # 691/15!
        return 1 / 12 + x * (1 / 720 + x * (1 / 30240 + x * tail))
    theta = math.sqrt(x)
    return 1.0 / x - (1.0 + math.cos(theta)) / (2.0 * theta * math.sin(theta))


@njit(**_JIT)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(**_JIT)
def _rotate(a, b, u0, u1, u2, v0, v1, v2):
    """``v + a u×v + b u×(u×v)``: ``exp(û) v`` for exp's ``(a, b)``, ``exp(−û) v`` for
    ``(−a, b)``, ``dexp⁻¹_{−u} v`` for ``(½, α)``."""
    c0, c1, c2 = _cross(u0, u1, u2, v0, v1, v2)
    d0, d1, d2 = _cross(u0, u1, u2, c0, c1, c2)
    return v0 + a * c0 + b * d0, v1 + a * c1 + b * d1, v2 + a * c2 + b * d2


@njit(**_JIT)
def _apply(M, v0, v1, v2):
    """``M v`` for a 3×3 ``M``."""
    return (
        M[0, 0] * v0 + M[0, 1] * v1 + M[0, 2] * v2,
        M[1, 0] * v0 + M[1, 1] * v1 + M[1, 2] * v2,
        M[2, 0] * v0 + M[2, 1] * v1 + M[2, 2] * v2,
    )


@njit(**_JIT)
def _apply_transpose(M, v0, v1, v2):
    """``Mᵀ v`` for a 3×3 ``M``."""
    return (
        M[0, 0] * v0 + M[1, 0] * v1 + M[2, 0] * v2,
        M[0, 1] * v0 + M[1, 1] * v1 + M[2, 1] * v2,
        M[0, 2] * v0 + M[1, 2] * v1 + M[2, 2] * v2,
    )


@njit(**_JIT)
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


@njit(**_JIT)
def _loads(off, zs, R, a, b, u0, u1, u2, m, F, tau, points, point_forces, K, i):
    """``K[i, off:] = (p/m, F + Σ f_k, τ + Σ (R exp(û) r_k) × f_k)``, ``zs[off:] = (x, p, L)``."""
    for c in range(3):
        K[i, off + c] = zs[off + 3 + c] / m
        K[i, off + 3 + c] = F[c]
        K[i, off + 6 + c] = tau[c]
    for k in range(points.shape[0]):
        r0, r1, r2 = _rotate(a, b, u0, u1, u2, points[k, 0], points[k, 1], points[k, 2])
        r0, r1, r2 = _apply(R, r0, r1, r2)
        f0, f1, f2 = point_forces[k, 0], point_forces[k, 1], point_forces[k, 2]
        t0, t1, t2 = _cross(r0, r1, r2, f0, f1, f2)
        K[i, off + 3] += f0
        K[i, off + 4] += f1
        K[i, off + 5] += f2
        K[i, off + 6] += t0
        K[i, off + 7] += t1
        K[i, off + 8] += t2


# A family is three functions: field(correct, zs, Rn, R, inv_I, m, F, tau, points,
# point_forces, K, i) writes K[i] = f(zs); advance(z, znew, Rn) sets z (and Rn) to the new
# state; record(z, Rn, R_out, q_out, Y_out) writes one sample.


@njit(**_INLINE)
def _lie_field(correct, zs, Rn, R, inv_I, m, F, tau, points, point_forces, K, i):
    """``u̇ = dexp⁻¹_{−u}(ω)`` (``ω`` if not ``correct``), ``ω = I⁻¹ exp(−û) R_nᵀ L``."""
    u0, u1, u2 = zs[0], zs[1], zs[2]
    theta2 = u0 * u0 + u1 * u1 + u2 * u2
    a, b = _exp_coefficients(theta2)
    w0, w1, w2 = _apply_transpose(Rn, zs[9], zs[10], zs[11])
    w0, w1, w2 = _apply(inv_I, *_rotate(-a, b, u0, u1, u2, w0, w1, w2))
    half, alpha = (0.5, _dexpinv_coefficient(theta2)) if correct else (0.0, 0.0)
    K[i, 0], K[i, 1], K[i, 2] = _rotate(half, alpha, u0, u1, u2, w0, w1, w2)
    _loads(3, zs, Rn, a, b, u0, u1, u2, m, F, tau, points, point_forces, K, i)


@njit(**_INLINE)
def _lie_advance(z, znew, Rn):
    """``R_n ← R_n exp(û)`` (row r of the product is ``exp(−û)`` of row r), ``u ← 0``."""
    u0, u1, u2 = znew[0], znew[1], znew[2]
    a, b = _exp_coefficients(u0 * u0 + u1 * u1 + u2 * u2)
    for r in range(3):
        Rn[r, 0], Rn[r, 1], Rn[r, 2] = _rotate(-a, b, u0, u1, u2, Rn[r, 0], Rn[r, 1], Rn[r, 2])
    z[0] = z[1] = z[2] = 0.0
    for q in range(3, z.shape[0]):
        z[q] = znew[q]


@njit(**_JIT)
def _lie_record(z, Rn, R_out, q_out, Y_out):
    R_out[:, :] = Rn
    Y_out[:] = z[3:]


@njit(**_INLINE)
def _quat_field(correct, zs, Rn, R, inv_I, m, F, tau, points, point_forces, K, i):
    """``q̇ = ½ q ⊗ (0, ω)``, ``ω = I⁻¹ Rᵀ L`` with ``R = R(q/|q|)``."""
    q0, q1, q2, q3 = zs[0], zs[1], zs[2], zs[3]
    norm = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    _quat_matrix(q0 / norm, q1 / norm, q2 / norm, q3 / norm, R)
    w0, w1, w2 = _apply(inv_I, *_apply_transpose(R, zs[10], zs[11], zs[12]))
    K[i, 0] = 0.5 * (-q1 * w0 - q2 * w1 - q3 * w2)
    K[i, 1] = 0.5 * (q0 * w0 + q2 * w2 - q3 * w1)
    K[i, 2] = 0.5 * (q0 * w1 + q3 * w0 - q1 * w2)
    K[i, 3] = 0.5 * (q0 * w2 + q1 * w1 - q2 * w0)
    _loads(4, zs, R, 0.0, 0.0, 0.0, 0.0, 0.0, m, F, tau, points, point_forces, K, i)


@njit(**_INLINE)
def _quat_advance(z, znew, Rn):
    """``q ← q/|q|``."""
    norm = math.sqrt(znew[0] ** 2 + znew[1] ** 2 + znew[2] ** 2 + znew[3] ** 2)
    for q in range(4):
        z[q] = znew[q] / norm
    for q in range(4, z.shape[0]):
        z[q] = znew[q]


@njit(**_JIT)
def _quat_record(z, Rn, R_out, q_out, Y_out):
    _quat_matrix(z[0], z[1], z[2], z[3], R_out)
    q_out[:] = z[:4]
    Y_out[:] = z[4:]


@njit(**_INLINE)
def _matrix_field(correct, zs, Rn, R, inv_I, m, F, tau, points, point_forces, K, i):
    """``Ṙ = R ω̂``, ``ω = I⁻¹ Rᵀ L``, R the first nine numbers of ``zs``."""
    for r in range(3):
        for c in range(3):
            R[r, c] = zs[3 * r + c]
    w0, w1, w2 = _apply(inv_I, *_apply_transpose(R, zs[15], zs[16], zs[17]))
    for r in range(3):
        K[i, 3 * r + 0] = R[r, 1] * w2 - R[r, 2] * w1
        K[i, 3 * r + 1] = R[r, 2] * w0 - R[r, 0] * w2
        K[i, 3 * r + 2] = R[r, 0] * w1 - R[r, 1] * w0
    _loads(9, zs, R, 0.0, 0.0, 0.0, 0.0, 0.0, m, F, tau, points, point_forces, K, i)


@njit(**_INLINE)
def _matrix_advance(z, znew, Rn):
    for q in range(z.shape[0]):
        z[q] = znew[q]


@njit(**_JIT)
def _matrix_record(z, Rn, R_out, q_out, Y_out):
    for r in range(3):
        for c in range(3):
            R_out[r, c] = z[3 * r + c]
    Y_out[:] = z[9:]


def _compile_loop(family: int):
    """The step loop of one family, compiled with that family's field and map back inlined.

    ``family`` is a constant of the closure, so numba drops the other families' branches and
    caches one loop per family (the cache is keyed by the closure's value).
    """

    @njit(**_JIT)
    def loop(correct, A, b, z, Rn, t_a, h, k0, k1, n, t_b, inv_I, m, F, tau, points,
             point_forces, every, step0, rec_t, rec_R, rec_q, rec_Y):  # fmt: skip
        s, nz = b.shape[0], z.shape[0]
        K, zs, R = np.empty((s, nz)), np.empty(nz), np.empty((3, 3))
        count, until_record = 0, every - (step0 + k0) % every
        for k in range(k0 + 1, k1 + 1):
            t_old = t_a + (k - 1) * h
            hk = (t_b if k == n else t_a + k * h) - t_old
            for i in range(s):  # k_i = f(z + h Σ_{j<i} a_ij k_j)
                for q in range(nz):
                    acc = 0.0
                    for j in range(i):
                        acc += A[i, j] * K[j, q]
                    zs[q] = z[q] + hk * acc
                if family == 2:
                    _lie_field(correct, zs, Rn, R, inv_I, m, F, tau, points, point_forces, K, i)
                elif family == 1:
                    _quat_field(correct, zs, Rn, R, inv_I, m, F, tau, points, point_forces, K, i)
                else:
                    _matrix_field(correct, zs, Rn, R, inv_I, m, F, tau, points, point_forces, K, i)
            finite = True
            for q in range(nz):  # z_new = z + h Σ b_i k_i
                acc = 0.0
                for i in range(s):
                    acc += b[i] * K[i, q]
                zs[q] = z[q] + hk * acc
                finite = finite and math.isfinite(zs[q])
            if not finite:
                return count, k
            if family == 2:
                _lie_advance(z, zs, Rn)
            elif family == 1:
                _quat_advance(z, zs, Rn)
            else:
                _matrix_advance(z, zs, Rn)
            until_record -= 1
            if until_record == 0:
                rec_t[count] = t_old + hk
                if family == 2:
                    _lie_record(z, Rn, rec_R[count], rec_q[count], rec_Y[count])
                elif family == 1:
                    _quat_record(z, Rn, rec_R[count], rec_q[count], rec_Y[count])
                else:
                    _matrix_record(z, Rn, rec_R[count], rec_q[count], rec_Y[count])
                count += 1
                until_record = every
        return count, -1

    return loop


FAMILY_CODES = {"matrix": 0, "quat": 1, "lie": 2}
ATTITUDE_SIZE = {"matrix": 9, "quat": 4, "lie": 3}
_MATRIX_LOOP, _QUAT_LOOP, _LIE_LOOP = (_compile_loop(code) for code in range(3))
LOOPS = {"matrix": _MATRIX_LOOP, "quat": _QUAT_LOOP, "lie": _LIE_LOOP}


def run_fixed(family: str, *args):
    """Steps ``k0+1 … k1`` of the grid ``t_a + k h`` (step ``n`` lands on ``t_b``).

    ``args = (correct, A, b, z, Rn, t_a, h, k0, k1, n, t_b, inv_I, m, F, tau, points,
    point_forces, every, step0, rec_t, rec_R, rec_q, rec_Y)``. Each step is one explicit
    Runge–Kutta step of the family's chart (as :func:`tumble.ode.stepper.rk_step`)

    .. math:: k_i = f\\Bigl(z + h \\sum_{j<i} a_{ij} k_j\\Bigr), \\quad
              z_{n+1} = z + h \\sum_i b_i k_i,

    then the family's map back. ``z`` (and ``Rn`` for the lie family) hold the state and are
    updated in place. A step is recorded in ``rec_*`` when ``step0 + k`` is a multiple of
    ``every``. Returns ``(recorded, failed)`` with ``failed`` the step whose result was not
    finite, or -1.
    """
    return LOOPS[family](*args)


@njit(**_JIT)
def _run_body(family, correct, A, b, z, Rn, t_a, h, n, t_b, inv_I, m, F, tau, points,
              point_forces, every, rec_t, rec_R, rec_q, rec_Y):  # fmt: skip
    """All ``n`` steps of one body with the loop of ``family`` (a code of FAMILY_CODES)."""
    args = (correct, A, b, z, Rn, t_a, h, 0, n, n, t_b, inv_I, m, F, tau, points,
            point_forces, every, 0, rec_t, rec_R, rec_q, rec_Y)  # fmt: skip
    if family == 2:
        return _LIE_LOOP(*args)
    if family == 1:
        return _QUAT_LOOP(*args)
    return _MATRIX_LOOP(*args)


@njit(cache=True, error_model="numpy", parallel=True)
def run_batch(family, correct, A, b, Z, RN, t_a, h, n, t_b, inv_I, m, F, tau, points,
              point_forces, every, rec_t, rec_R, rec_q, rec_Y, counts, failed):  # fmt: skip
    """:func:`run_fixed` over steps ``1 … n`` for every body ``k`` in parallel (``prange``).

    ``family`` is a code of :data:`FAMILY_CODES`. Body ``k``'s state is ``Z[k]`` (and
    ``RN[k]``), its inverse inertia ``inv_I[k]``, mass ``m[k]`` and centre-of-mass force
    ``F[k]``; ``tau``, ``points`` and ``point_forces`` are shared. Its samples go to
    ``rec_t[k]``, ``rec_R[k]``, …; ``counts[k]`` samples and the failed step ``failed[k]``
    (-1 if none) come back.
    """
    for k in prange(Z.shape[0]):
        counts[k], failed[k] = _run_body(
            family, correct, A, b, Z[k], RN[k], t_a, h, n, t_b, inv_I[k], m[k], F[k], tau,
            points, point_forces, every, rec_t[k], rec_R[k], rec_q[k], rec_Y[k],
        )  # fmt: skip


def pack(family: str, attitude: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The kernel's ``(z, Rn)`` for a family's attitude (R or q) and ``Y = (x, p, L)``."""
    if family == "lie":
        return np.concatenate([np.zeros(3), Y]), np.array(attitude, dtype=float)
    return np.concatenate([np.ravel(attitude), Y]), np.eye(3)


def unpack(family: str, z: np.ndarray, Rn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`pack`."""
    if family == "lie":
        return Rn.copy(), z[3:].copy()
    size = ATTITUDE_SIZE[family]
    attitude = z[:size].reshape(3, 3) if family == "matrix" else z[:size]
    return attitude.copy(), z[size:].copy()


def _chunks(n: int, progress: bool) -> list[tuple[int, int]]:
    size = max(1, n // 50) if progress else n
    return [(k0, min(k0 + size, n)) for k0 in range(0, n, size)]


def run_segment(run, b: float, h: float, loads, advance) -> bool:
    """Integrate ``run`` from ``run.t`` to ``b`` with the kernel; False if it stopped."""
    F, tau, points, point_forces = loads
    family, method = run.method.family, run.method
    A, weights = method.tableau.A, method.tableau.b
    inv_I, every, a = run.dynamics.inertia_inverse, run.record_every, run.t
    n = fixed_step_count(a, b, h)
    z, Rn = pack(family, run.attitude, run.Y)
    for k0, k1 in _chunks(n, advance is not None):
        size = (k1 - k0) // every + 1
        rec_t, rec_R = np.empty(size), np.empty((size, 3, 3))
        rec_q, rec_Y = np.empty((size, 4)), np.empty((size, 9))
        count, failed = run_fixed(family, method.dexpinv, A, weights, z, Rn, a, h,
                                  k0, k1, n, b, inv_I, run.dynamics.mass, F, tau, points,
                                  point_forces, every, run.n_steps - k0, rec_t, rec_R, rec_q,
                                  rec_Y)  # fmt: skip
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
