"""Compiled (numba) fixed-step loops: each chart of :mod:`tumble.rigid.charts`, compiled.

One loop, :func:`_loop`, runs every fixed-step method for constant loads: a stage loop over
the tableau (``A``, ``b`` as arrays), the chart's vector field, and the chart's map back. A
chart's compiled twin is three functions (field, advance, record), and :func:`_for_chart`
compiles the loop once per chart with that chart's functions inlined (:data:`COMPILED`),
and a parallel loop over bodies for :func:`~tumble.rigid.simulate_batch`. The run's data
travel in one :class:`Problem`, its samples in one :class:`Records`, its grid in the
driver's :class:`~tumble.ode.driver.Grid`.

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
import types
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numba import njit, prange

from tumble.ode import control
from tumble.rigid import charts

NON_FINITE, UNCONVERGED = 0, 1
"""Why a loop stopped at a step: its state was not finite, or an implicit flow's Newton
iteration did not converge (``split`` loops)."""

SERIES_ANGLE = 0.25
"""Below this angle (rad) the exp and dexp⁻¹ coefficients use their Taylor series; the first
term left out is below 1e-17 relative (θ¹²/13! for sin θ/θ, 8e-19 for dexp⁻¹)."""

_JIT: dict[str, Any] = dict(cache=True, error_model="numpy")  # no ZeroDivisionError checks
_INLINE: dict[str, Any] = dict(_JIT, inline="always")
_SERIES2 = SERIES_ANGLE * SERIES_ANGLE
_S1, _S2, _S3, _S4, _S5 = -1.0 / 6, 1.0 / 120, -1.0 / 5040, 1.0 / 362880, -1.0 / 39916800
_C1, _C2, _C3, _C4, _C5 = -1.0 / 24, 1.0 / 720, -1.0 / 40320, 1.0 / 3628800, -1.0 / 479001600


@njit(**_JIT)
def _exp_series(x):
    """``(sin θ/θ, (1 − cos θ)/θ²)`` for ``θ² = x`` below :data:`SERIES_ANGLE`: Horner in
    θ² of Σ (−θ²)^k/(2k+1)! and Σ (−θ²)^k/(2k+2)! (also the batch loops' vector form)."""
    a = 1.0 + x * (_S1 + x * (_S2 + x * (_S3 + x * (_S4 + x * _S5))))
    b = 0.5 + x * (_C1 + x * (_C2 + x * (_C3 + x * (_C4 + x * _C5))))
    return a, b


@njit(**_JIT)
def _dexpinv_series(x):
    """dexp⁻¹'s ``α`` for ``θ² = x`` below :data:`SERIES_ANGLE`: the Bernoulli series
    ``1/12 + θ²/720 + …`` to 691/15!."""
    tail = 1 / 1209600 + x * (1 / 47900160 + x * (691 / 1307674368000))
    return 1 / 12 + x * (1 / 720 + x * (1 / 30240 + x * tail))


@njit(**_JIT)
def _exp_coefficients(theta2):
    """``(sin θ/θ, (1 − cos θ)/θ²)`` for ``θ² = theta2``."""
    x = theta2
    if x < _SERIES2:
        return _exp_series(x)
    theta = math.sqrt(x)
    half = math.sin(0.5 * theta) / theta
    return math.sin(theta) / theta, 2.0 * half * half


@njit(**_JIT)
def _dexpinv_coefficient(theta2):
    """``α = (1 − (θ/2) cot(θ/2))/θ²``; Bernoulli series ``1/12 + θ²/720 + …`` when small."""
    x = theta2
    if x < _SERIES2:
        return _dexpinv_series(x)
    theta = math.sqrt(x)
    return 1.0 / x - (1.0 + math.cos(theta)) / (2.0 * theta * math.sin(theta))


@njit(**_JIT)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


# The 3 × 3 helpers are the Python reference's own (tumble.rigid.charts: its error norm
# uses them), compiled: one definition for both paths.
_rotate = njit(**_JIT)(charts._rotate)
_apply = njit(**_JIT)(charts._apply)
_apply_transpose = njit(**_JIT)(charts._transpose_apply)


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
def _loads(off, zs, R, a, b, u0, u1, u2, problem, K, i):
    """``K[i, off:] = (p/m, F + Σ f_k, τ + Σ (R exp(û) r_k) × f_k)``, ``zs[off:] = (x, p, L)``."""
    m, F, tau = problem.m, problem.F, problem.tau
    points, point_forces = problem.points, problem.point_forces
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


@njit(**_INLINE)
def _copy(z, start, out):
    """``out[:] = z[start:]`` as a loop: a slice assignment brings numba's broadcasting code
    into every loop that records (160 kB of cached code to load instead of 20)."""
    for q in range(out.shape[0]):
        out[q] = z[start + q]


@njit(**_INLINE)
def _copy_matrix(M, out):
    """``out[:, :] = M`` for 3×3 arrays, as a loop (see :func:`_copy`)."""
    for r in range(3):
        for c in range(3):
            out[r, c] = M[r, c]


# A chart's compiled twin is three functions: field(problem, zs, Rn, R, K, i) writes
# K[i] = f(zs); advance(z, znew, Rn) sets z (and Rn) to the new state; record(z, Rn, R_out,
# q_out, Y_out) writes one sample. ``problem`` is a :class:`Problem`.


@njit(**_INLINE)
def _lie_field(problem, zs, Rn, R, K, i):
    """``u̇ = dexp⁻¹_{−u}(ω)`` (``ω`` if not ``correct``), ``ω = I⁻¹ exp(−û) R_nᵀ L``."""
    u0, u1, u2 = zs[0], zs[1], zs[2]
    theta2 = u0 * u0 + u1 * u1 + u2 * u2
    a, b = _exp_coefficients(theta2)
    w0, w1, w2 = _apply_transpose(Rn, zs[9], zs[10], zs[11])
    w0, w1, w2 = _apply(problem.inv_I, *_rotate(-a, b, u0, u1, u2, w0, w1, w2))
    half, alpha = (0.5, _dexpinv_coefficient(theta2)) if problem.correct else (0.0, 0.0)
    K[i, 0], K[i, 1], K[i, 2] = _rotate(half, alpha, u0, u1, u2, w0, w1, w2)
    _loads(3, zs, Rn, a, b, u0, u1, u2, problem, K, i)


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


@njit(**_INLINE)
def _lie_first_same_as_last(K, s, znew):
    """``K[0] ← (dexp_{−u}(K[s−1]_u), K[s−1]_y)``: the next step's first stage, at ``u = 0``
    in the new chart, from this step's last (as :func:`tumble.rigid.charts`' reference);
    ``dexp_{−u} v = v − b u×v + c u×(u×v)`` with ``c = (1 − sin θ/θ)/θ²`` (series when
    small)."""
    u0, u1, u2 = znew[0], znew[1], znew[2]
    x = u0 * u0 + u1 * u1 + u2 * u2
    a, b = _exp_coefficients(x)
    c = -(_S1 + x * (_S2 + x * (_S3 + x * (_S4 + x * _S5)))) if x < _SERIES2 else (1.0 - a) / x
    K[0, 0], K[0, 1], K[0, 2] = _rotate(-b, c, u0, u1, u2, K[s - 1, 0], K[s - 1, 1], K[s - 1, 2])
    for q in range(3, K.shape[1]):
        K[0, q] = K[s - 1, q]
    return True


@njit(**_INLINE)
def _no_first_same_as_last(K, s, znew):
    """Charts that do not reuse the last stage (their loops recompute the first)."""
    return False


@njit(**_JIT)
def _lie_record(z, Rn, R_out, q_out, Y_out):
    _copy_matrix(Rn, R_out)
    _copy(z, 3, Y_out)


@njit(**_INLINE)
def _quat_field(problem, zs, Rn, R, K, i):
    """``q̇ = ½ q ⊗ (0, ω)``, ``ω = I⁻¹ Rᵀ L`` with ``R = R(q/|q|)``."""
    q0, q1, q2, q3 = zs[0], zs[1], zs[2], zs[3]
    norm = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    _quat_matrix(q0 / norm, q1 / norm, q2 / norm, q3 / norm, R)
    w0, w1, w2 = _apply(problem.inv_I, *_apply_transpose(R, zs[10], zs[11], zs[12]))
    K[i, 0] = 0.5 * (-q1 * w0 - q2 * w1 - q3 * w2)
    K[i, 1] = 0.5 * (q0 * w0 + q2 * w2 - q3 * w1)
    K[i, 2] = 0.5 * (q0 * w1 + q3 * w0 - q1 * w2)
    K[i, 3] = 0.5 * (q0 * w2 + q1 * w1 - q2 * w0)
    _loads(4, zs, R, 0.0, 0.0, 0.0, 0.0, 0.0, problem, K, i)


@njit(**_INLINE)
def _quat_start(z, Rn):
    """``q ← q/|q|`` at the start of a step: the step ends with the quaternion as the
    tableau left it, so that the record sees ``|q| − 1`` before it is removed."""
    norm = math.sqrt(z[0] ** 2 + z[1] ** 2 + z[2] ** 2 + z[3] ** 2)
    for q in range(4):
        z[q] = z[q] / norm


@njit(**_INLINE)
def _quat_advance(z, znew, Rn):
    """The step's result, ``q`` not yet normalised (:func:`_quat_start` does that)."""
    for q in range(z.shape[0]):
        z[q] = znew[q]


@njit(**_JIT)
def _quat_record(z, Rn, R_out, q_out, Y_out):
    """R of ``q/|q|``; ``q`` as it is (its norm error is the step's)."""
    norm = math.sqrt(z[0] ** 2 + z[1] ** 2 + z[2] ** 2 + z[3] ** 2)
    _quat_matrix(z[0] / norm, z[1] / norm, z[2] / norm, z[3] / norm, R_out)
    _copy(z, 0, q_out)
    _copy(z, 4, Y_out)


@njit(**_INLINE)
def _no_start(z, Rn):
    """Charts that need nothing at the start of a step."""


@njit(**_INLINE)
def _matrix_field(problem, zs, Rn, R, K, i):
    """``Ṙ = R ω̂``, ``ω = I⁻¹ Rᵀ L``, R the first nine numbers of ``zs``."""
    for r in range(3):
        for c in range(3):
            R[r, c] = zs[3 * r + c]
    w0, w1, w2 = _apply(problem.inv_I, *_apply_transpose(R, zs[15], zs[16], zs[17]))
    for r in range(3):
        K[i, 3 * r + 0] = R[r, 1] * w2 - R[r, 2] * w1
        K[i, 3 * r + 1] = R[r, 2] * w0 - R[r, 0] * w2
        K[i, 3 * r + 2] = R[r, 0] * w1 - R[r, 1] * w0
    _loads(9, zs, R, 0.0, 0.0, 0.0, 0.0, 0.0, problem, K, i)


@njit(**_INLINE)
def _matrix_advance(z, znew, Rn):
    for q in range(z.shape[0]):
        z[q] = znew[q]


@njit(**_JIT)
def _matrix_record(z, Rn, R_out, q_out, Y_out):
    for r in range(3):
        for c in range(3):
            R_out[r, c] = z[3 * r + c]
    _copy(z, 9, Y_out)


class Problem(NamedTuple):
    """What the compiled loops need of a run besides its state: method and loads.

    ``correct``: stages corrected by dexp⁻¹ (False only for ``seed-rk4``); ``A``, ``b``: the
    tableau (for a ``split`` method, ``b`` holds the composition weights); ``inv_I`` (3, 3),
    ``m``: the body; ``F`` (3,), ``tau`` (3,): constant force on the centre of mass and
    torque (world); ``points`` (k, 3), ``point_forces`` (k, 3): body points and the constant
    world forces there (magnetic dipoles among them, see
    :func:`~tumble.rigid.forces.compiled_loads`); ``axes`` (3, 3), ``moments`` (3,): the
    principal axes and moments (the ``split`` loops). For the batch loops ``inv_I``, ``m``,
    ``F``, ``axes`` and ``moments`` carry a leading body axis.
    """

    correct: bool
    A: np.ndarray
    b: np.ndarray
    inv_I: np.ndarray
    m: float | np.ndarray
    F: np.ndarray
    tau: np.ndarray
    points: np.ndarray
    point_forces: np.ndarray
    axes: np.ndarray
    moments: np.ndarray


class Records(NamedTuple):
    """Where a loop writes its samples: ``t`` (m,), ``R`` (m, 3, 3), ``q`` (m, 4), ``Y`` (m, 9)
    (with a leading body axis for :func:`run_batch`)."""

    t: np.ndarray
    R: np.ndarray
    q: np.ndarray
    Y: np.ndarray


def _stages(problem, A, z, Rn, h, first, K, zs, R):
    """The stages ``first … s−1`` of one step: ``k_i = f(z + h Σ_{j<i} a_ij k_j)`` into ``K``
    (``zs`` and ``R`` are work arrays; ``first`` = 1 when ``K[0]`` is known, FSAL). ``FIELD``
    is the chart's compiled field, bound by :func:`_for_chart`; inlined into its loops."""
    for i in range(first, A.shape[0]):
        for q in range(z.shape[0]):
            acc = 0.0
            for j in range(i):
                acc += A[i, j] * K[j, q]
            zs[q] = z[q] + h * acc
        FIELD(problem, zs, Rn, R, K, i)  # noqa: F821


def _loop(problem, grid, z, Rn, k0, k1, every, step0, records):
    """Steps ``k0+1 … k1`` of ``grid`` (a :class:`~tumble.ode.driver.Grid`) for one chart.

    Each step is one explicit Runge–Kutta step of the chart's field (as
    :func:`tumble.ode.stepper.rk_step`)

    .. math:: k_i = f\\Bigl(z + h \\sum_{j<i} a_{ij} k_j\\Bigr), \\quad
              z_{n+1} = z + h \\sum_i b_i k_i,

    then the chart's map back (``START`` runs before each step: the ``quat`` chart normalises
    there). ``z`` (and ``Rn``) hold the state and are updated in place.
    Step ``k`` is recorded when ``step0 + k`` is a multiple of ``every``. Returns
    ``(recorded, failed, cause)``: ``failed`` is the step whose result was not finite (the
    state is left at the step before), or -1; ``cause`` is :data:`NON_FINITE` then.
    ``STAGES`` (:func:`_stages` with the chart's field), ``ADVANCE`` and ``RECORD`` are the
    chart's compiled functions, bound by :func:`_for_chart`.
    """
    A, b = problem.A, problem.b
    t_a, t_b, h, n = grid
    s, nz = b.shape[0], z.shape[0]
    K, zs, R = np.empty((s, nz)), np.empty(nz), np.empty((3, 3))
    count, until_record = 0, every - (step0 + k0) % every
    for k in range(k0 + 1, k1 + 1):
        t_old = t_a + (k - 1) * h
        hk = (t_b if k == n else t_a + k * h) - t_old
        START(z, Rn)  # noqa: F821
        STAGES(problem, A, z, Rn, hk, 0, K, zs, R)  # noqa: F821
        finite = True
        for q in range(nz):  # z_new = z + h Σ b_i k_i
            acc = 0.0
            for i in range(s):
                acc += b[i] * K[i, q]
            zs[q] = z[q] + hk * acc
            finite = finite and math.isfinite(zs[q])
        if not finite:
            return count, k, NON_FINITE
        ADVANCE(z, zs, Rn)  # noqa: F821
        until_record -= 1
        if until_record == 0:
            records.t[count] = t_old + hk
            RECORD(z, Rn, records.R[count], records.q[count], records.Y[count])  # noqa: F821
            count += 1
            until_record = every
    return count, -1, NON_FINITE


def _batch(problem, grid, Z, RN, every, records, counts, failed, causes):
    """:data:`LOOP` over all the steps of ``grid`` for every body ``k`` in parallel.

    Body ``k``'s state is ``Z[k]`` (and ``RN[k]``), its data ``problem.inv_I[k]``,
    ``problem.m[k]``, ``problem.F[k]``, ``problem.axes[k]`` and ``problem.moments[k]``; its
    samples go to ``records.t[k]``, … ; ``counts[k]`` samples, the failed step ``failed[k]``
    (-1 if none) and its cause ``causes[k]`` come back.
    """
    for k in prange(Z.shape[0]):
        p = problem
        body = Problem(p.correct, p.A, p.b, p.inv_I[k], p.m[k], p.F[k], p.tau, p.points,
                       p.point_forces, p.axes[k], p.moments[k])  # fmt: skip
        body_records = Records(records.t[k], records.R[k], records.q[k], records.Y[k])
        counts[k], failed[k], causes[k] = LOOP(body, grid, Z[k], RN[k], 0, grid.n, every, 0,  # noqa: F821
                                               body_records)  # fmt: skip


def _adaptive_loop(problem, e, t, t1, h, rtol, atol, separatrix, control, fsal, z, Rn, every,
                   step0, max_steps, records):  # fmt: skip
    """Adaptive steps from ``t`` towards ``t1`` for one chart: the driver's adaptive loop,
    compiled (:func:`tumble.ode.driver.march` with a ``Control``).

    Each try is the step of :func:`_loop` plus the embedded error estimate
    ``h Σ e_i k_i``; its norm is :func:`tumble.rigid.charts.error_norm` (``separatrix``: its
    :func:`~tumble.rigid.charts.separatrix_form`) and the next step
    comes from :func:`tumble.ode.control.step_factor` (both compiled from those very
    functions), tries start from the accepted state, and a step below
    :func:`tumble.ode.control.minimum_step` ends the run, as in the driver. ``control`` is
    ``(safety, min_factor, max_factor, order, horizon)`` (``horizon`` 0: none; see
    :class:`tumble.ode.driver.Control`). With ``fsal`` (a FSAL tableau) an accepted step's
    last stage becomes the next one's first through the chart's ``FIRST_SAME_AS_LAST``
    (:attr:`tumble.rigid.charts.Chart.first_same_as_last`); a call starts with a fresh one.
    Returns at ``t1``, when ``records`` is full
    or after ``max_steps`` accepted steps:
    ``(recorded, t, h_next, accepted, rejected, code, t_failed, norm_finite)`` with ``code`` 0
    (going on), 1 (a non-finite accepted state; the step to ``t_failed``) or 2 (the minimum
    step; ``norm_finite`` says whether the last norm was finite).
    """
    A, b = problem.A, problem.b
    safety, min_factor, max_factor, order, horizon = control
    s, nz = b.shape[0], z.shape[0]
    K, zs, err, R = np.empty((s, nz)), np.empty(nz), np.empty(nz), np.empty((3, 3))
    capacity = records.t.shape[0]
    count, until_record = 0, every - step0 % every
    accepted, rejected, after_rejection, have_first = 0, 0, False, False
    while t < t1 and count < capacity and accepted < max_steps:
        h_min = MINIMUM_STEP(t)  # noqa: F821
        planned = max(h, h_min)
        t_new = min(t + planned, t1)
        hk = t_new - t
        START(z, Rn)  # noqa: F821
        STAGES(problem, A, z, Rn, hk, 1 if have_first else 0, K, zs, R)  # noqa: F821
        for q in range(nz):  # z_new = z + h Σ b_i k_i, error h Σ e_i k_i
            acc, acc_e = 0.0, 0.0
            for i in range(s):
                acc += b[i] * K[i, q]
                acc_e += e[i] * K[i, q]
            zs[q] = z[q] + hk * acc
            err[q] = hk * acc_e
        share = hk / horizon if horizon > 0.0 else 1.0  # error per unit step (Control.horizon)
        norm = NORM(err, z, zs, Rn, rtol, atol, separatrix, share) / share  # noqa: F821
        h = hk * FACTOR(norm, order, safety, min_factor, max_factor, after_rejection)  # noqa: F821
        after_rejection = not norm <= 1.0
        if after_rejection:
            rejected += 1
            if h < h_min:
                return count, t, h, accepted, rejected, 2, t_new, math.isfinite(norm)
            continue
        for q in range(nz):
            if not math.isfinite(zs[q]):
                return count, t, h, accepted, rejected, 1, t_new, True
        if t_new == t1 and t + planned > t1:
            h = planned  # shortened to land on t1 (as the driver)
        ADVANCE(z, zs, Rn)  # noqa: F821
        have_first = fsal and FIRST_SAME_AS_LAST(K, s, zs)  # noqa: F821
        t = t_new
        accepted += 1
        until_record -= 1
        if until_record == 0:
            records.t[count] = t
            RECORD(z, Rn, records.R[count], records.q[count], records.Y[count])  # noqa: F821
            count += 1
            until_record = every
    return count, t, h, accepted, rejected, 0, t, True


def _bind(template, name: str, **functions):
    """``template`` compiled with ``functions`` as its globals, cached under its own name.

    numba's on-disk cache is keyed by a function's qualified name and code, so each chart's
    loop gets a name of its own; a closure over compiled functions would miss the cache.
    """
    bound = types.FunctionType(template.__code__, {**globals(), **functions}, name)
    bound.__qualname__ = name
    bound.__doc__ = template.__doc__
    return bound


@dataclass(frozen=True)
class CompiledChart:
    """A chart's compiled loop for one body (:func:`_loop`), for a batch (:func:`_batch`),
    and its adaptive loop (:func:`_adaptive_loop`)."""

    loop: Callable[..., tuple[int, int, int]]
    batch: Callable[..., None]
    adaptive: Callable[..., tuple] | None = None


# The step controller, the minimum step and the error norm are the Python reference's own
# functions, compiled here: the adaptive loop and the driver cannot drift apart.
_STEP_FACTOR = njit(**_INLINE)(control.step_factor)
_MINIMUM_STEP = njit(**_INLINE)(control.minimum_step)


def _compiled_norm():
    """:func:`tumble.rigid.charts.error_norm` and its helpers compiled, each calling the
    others' compiled twins (one namespace for all)."""
    namespace = dict(vars(charts))
    for name in (*charts.NORM_HELPERS, "error_norm"):
        code = getattr(charts, name).__code__
        namespace[name] = njit(**_INLINE)(types.FunctionType(code, namespace, name))
    return namespace["error_norm"]


_ERROR_NORM = _compiled_norm()


def _for_chart(
    name: str, field, advance, record, start=_no_start, fsal=_no_first_same_as_last,
    adaptive: bool = False,
) -> CompiledChart:  # fmt: skip
    stages = njit(**_INLINE)(_bind(_stages, f"_stages_{name}", FIELD=field))
    chart = dict(STAGES=stages, ADVANCE=advance, RECORD=record, START=start)
    loop = njit(**_JIT)(_bind(_loop, f"_loop_{name}", **chart))
    batch = njit(parallel=True, **_JIT)(_bind(_batch, f"_batch_{name}", LOOP=loop))
    if not adaptive:  # the error norm is the lie chart's (every adaptive method is one)
        return CompiledChart(loop, batch)
    adaptive_loop = njit(**_JIT)(
        _bind(
            _adaptive_loop,
            f"_adaptive_{name}",
            NORM=_ERROR_NORM,
            FACTOR=_STEP_FACTOR,
            MINIMUM_STEP=_MINIMUM_STEP,
            FIRST_SAME_AS_LAST=fsal,
            **chart,
        )
    )
    return CompiledChart(loop, batch, adaptive_loop)


COMPILED: dict[str, CompiledChart] = {
    "matrix": _for_chart("matrix", _matrix_field, _matrix_advance, _matrix_record),
    "quat": _for_chart("quat", _quat_field, _quat_advance, _quat_record, _quat_start),
    "lie": _for_chart(
        "lie", _lie_field, _lie_advance, _lie_record, fsal=_lie_first_same_as_last, adaptive=True
    ),  # fmt: skip
}
"""Each chart of :data:`tumble.rigid.charts.CHARTS`, compiled."""

# ---------------------------------------------------------------------------------------
# The ``split`` family (:mod:`tumble.rigid.geometric`): kicks, a free-body flow, compiled.
# The attitude is ``R_p = R P`` (principal frame); a flow turns it in place and returns
# False when its Newton iteration did not converge.

NEWTON_MAX = 30
"""As :data:`tumble.rigid.geometric.NEWTON_MAX` (a test checks they agree)."""
NEWTON_TOL = 4.0 * 2.220446049250313e-16
"""As :data:`tumble.rigid.geometric.NEWTON_TOL`."""


@njit(**_JIT)
def _solve3(j00, j01, j02, j10, j11, j12, j20, j21, j22, r0, r1, r2):
    """``J⁻¹ r`` for a 3×3 ``J`` by Cramer's rule (the cofactors, once)."""
    c00, c01, c02 = j11 * j22 - j12 * j21, j12 * j20 - j10 * j22, j10 * j21 - j11 * j20
    det = j00 * c00 + j01 * c01 + j02 * c02
    x0 = (c00 * r0 + (j02 * j21 - j01 * j22) * r1 + (j01 * j12 - j02 * j11) * r2) / det
    x1 = (c01 * r0 + (j00 * j22 - j02 * j20) * r1 + (j02 * j10 - j00 * j12) * r2) / det
    x2 = (c02 * r0 + (j01 * j20 - j00 * j21) * r1 + (j00 * j11 - j01 * j10) * r2) / det
    return x0, x1, x2


@njit(**_INLINE)
def _times_matrix(Rp, c00, c01, c02, c10, c11, c12, c20, c21, c22):
    """``R_p ← R_p C`` in place, row by row."""
    for r in range(3):
        a, b, c = Rp[r, 0], Rp[r, 1], Rp[r, 2]
        Rp[r, 0] = a * c00 + b * c10 + c * c20
        Rp[r, 1] = a * c01 + b * c11 + c * c21
        Rp[r, 2] = a * c02 + b * c12 + c * c22


@njit(**_INLINE)
def _turn_columns(Rp, j, k, c, s):
    """Columns ``j, k`` of ``R_p`` turned: ``(c R_j + s R_k, c R_k − s R_j)``."""
    for r in range(3):
        a, b = Rp[r, j], Rp[r, k]
        Rp[r, j] = c * a + s * b
        Rp[r, k] = c * b - s * a


@njit(**_INLINE)
def _turn(Rp, m0, m1, m2, axis, angle):
    """``R_p ← R_p exp(angle ê_axis)`` in place; returns ``exp(−angle ê_axis) m``. ``axis`` is
    a constant at each call, so after inlining every index below is one too."""
    c, s = math.cos(angle), math.sin(angle)
    if axis == 0:
        _turn_columns(Rp, 1, 2, c, s)
        return m0, c * m1 + s * m2, c * m2 - s * m1
    if axis == 1:
        _turn_columns(Rp, 2, 0, c, s)
        return c * m0 - s * m2, m1, c * m2 + s * m0
    _turn_columns(Rp, 0, 1, c, s)
    return c * m0 + s * m1, c * m1 - s * m0, m2


@njit(**_INLINE)
def _axes_flow(Rp, L0, L1, L2, moments, h, work, head, tail):
    """Strang's splitting by axes, ``1, 2, 3, 2, 1`` (each rotation exact). The outer turns
    about axis 1 go by ``head/2`` and ``tail/2`` instead of ``h/2`` (0: left out): axis 1's
    turn leaves ``m₁`` alone, so the last turn of a step and the first of the next are one
    turn by their sum, which the loop takes when nothing happens between them."""
    # the factors h/(2Iᵢ) off the chain of dependent rotations: a product on it, not a division
    a0, a1, a2 = 0.5 / moments[0], 0.5 * h / moments[1], h / moments[2]
    m0, m1, m2 = _apply_transpose(Rp, L0, L1, L2)
    if head != 0.0:
        m0, m1, m2 = _turn(Rp, m0, m1, m2, 0, head * a0 * m0)
    m0, m1, m2 = _turn(Rp, m0, m1, m2, 1, a1 * m1)
    m0, m1, m2 = _turn(Rp, m0, m1, m2, 2, a2 * m2)
    m0, m1, m2 = _turn(Rp, m0, m1, m2, 1, a1 * m1)
    if tail != 0.0:
        _turn(Rp, m0, m1, m2, 0, tail * a0 * m0)
    return True


@njit(**_INLINE)
def _midpoint_flow(Rp, L0, L1, L2, moments, h, work, head, tail):
    """Implicit midpoint on ``ṁ = m × I⁻¹m`` by Newton, then ``R_p ← R_p cay(h I⁻¹m̄)``."""
    m0, m1, m2 = _apply_transpose(Rp, L0, L1, L2)
    i0, i1, i2 = 1.0 / moments[0], 1.0 / moments[1], 1.0 / moments[2]
    w0, w1, w2 = m0, m1, m2
    g = 0.5 * h
    converged = False
    for _ in range(NEWTON_MAX):
        y0, y1, y2 = w0 * i0, w1 * i1, w2 * i2
        c0, c1, c2 = _cross(w0, w1, w2, y0, y1, y2)
        # J = 1 − (h/2)(ŵ diag(i) − ŷ), ŷ the hat of y = I⁻¹w
        d0, d1, d2 = _solve3(
            1.0, -g * (-w2 * i1 + y2), -g * (w1 * i2 - y1),
            -g * (w2 * i0 - y2), 1.0, -g * (-w0 * i2 + y0),
            -g * (-w1 * i0 + y1), -g * (w0 * i1 - y0), 1.0,
            w0 - m0 - g * c0, w1 - m1 - g * c1, w2 - m2 - g * c2,
        )  # fmt: skip
        w0, w1, w2 = w0 - d0, w1 - d1, w2 - d2
        size = w0 * w0 + w1 * w1 + w2 * w2
        if not math.isfinite(size):
            return False
        if d0 * d0 + d1 * d1 + d2 * d2 <= NEWTON_TOL * NEWTON_TOL * size:
            converged = True
            break
    v0, v1, v2 = h * w0 * i0, h * w1 * i1, h * w2 * i2
    f = 4.0 / (4.0 + v0 * v0 + v1 * v1 + v2 * v2)  # cay(v) = 1 + f (v̂ + v̂²/2)
    _times_matrix(
        Rp,
        1.0 - 0.5 * f * (v1 * v1 + v2 * v2), f * (0.5 * v0 * v1 - v2), f * (0.5 * v0 * v2 + v1),
        f * (0.5 * v0 * v1 + v2), 1.0 - 0.5 * f * (v0 * v0 + v2 * v2), f * (0.5 * v1 * v2 - v0),
        f * (0.5 * v0 * v2 - v1), f * (0.5 * v1 * v2 + v0), 1.0 - 0.5 * f * (v0 * v0 + v1 * v1),
    )  # fmt: skip
    return converged


@njit(**_INLINE)
def _dmv_flow(Rp, L0, L1, L2, moments, h, work, head, tail):
    """Moser–Veselov: Newton on ``h m = 2 e₀ I e + 2 (D e) × e`` for Ω's quaternion."""
    m0, m1, m2 = _apply_transpose(Rp, L0, L1, L2)
    I0, I1, I2 = moments[0], moments[1], moments[2]
    half = 0.5 * (I0 + I1 + I2)
    D0, D1, D2 = half - I0, half - I1, half - I2
    e1, e2, e3 = 0.5 * h * m0 / I0, 0.5 * h * m1 / I1, 0.5 * h * m2 / I2
    converged = False
    for _ in range(NEWTON_MAX):
        e0 = math.sqrt(1.0 - (e1 * e1 + e2 * e2 + e3 * e3))
        c0, c1, c2 = _cross(D0 * e1, D1 * e2, D2 * e3, e1, e2, e3)
        a0, a1, a2 = I0 * e1, I1 * e2, I2 * e3
        # J = 2e₀ diag(I) − 2 (I e) eᵀ/e₀ + 2 ((D e)^ − ê diag(D))
        d0, d1, d2 = _solve3(
            2.0 * (e0 * I0 - a0 * e1 / e0),
            2.0 * (-a0 * e2 / e0 - D2 * e3 + e3 * D1),
            2.0 * (-a0 * e3 / e0 + D1 * e2 - e2 * D2),
            2.0 * (-a1 * e1 / e0 + D2 * e3 - e3 * D0),
            2.0 * (e0 * I1 - a1 * e2 / e0),
            2.0 * (-a1 * e3 / e0 - D0 * e1 + e1 * D2),
            2.0 * (-a2 * e1 / e0 - D1 * e2 + e2 * D0),
            2.0 * (-a2 * e2 / e0 + D0 * e1 - e1 * D1),
            2.0 * (e0 * I2 - a2 * e3 / e0),
            2.0 * (e0 * a0 + c0) - h * m0,
            2.0 * (e0 * a1 + c1) - h * m1,
            2.0 * (e0 * a2 + c2) - h * m2,
        )  # fmt: skip
        e1, e2, e3 = e1 - d0, e2 - d1, e3 - d2
        size = e1 * e1 + e2 * e2 + e3 * e3
        if not size < 1.0:  # also NaN
            return False
        if d0 * d0 + d1 * d1 + d2 * d2 <= NEWTON_TOL * NEWTON_TOL * size:
            converged = True
            break
    e0 = math.sqrt(1.0 - (e1 * e1 + e2 * e2 + e3 * e3))
    _times_matrix(
        Rp,
        1 - 2 * (e2 * e2 + e3 * e3), 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2),
        2 * (e1 * e2 + e0 * e3), 1 - 2 * (e1 * e1 + e3 * e3), 2 * (e2 * e3 - e0 * e1),
        2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), 1 - 2 * (e1 * e1 + e2 * e2),
    )  # fmt: skip
    return converged


# The exact flow: Carlson's symmetric integrals, Jacobi's functions by the AGM or their
# hyperbolic series, and the closed form of tumble._elliptic (which this mirrors line by
# line, one time at a time).

_EPS = 2.220446049250313e-16
_RF_Q = (3.0 * _EPS) ** (-1.0 / 6.0)
_RJ_Q = (0.25 * _EPS) ** (-1.0 / 6.0)
SYMMETRY_RTOL, SEPARATRIX_RTOL, M1_MIN, M1_SERIES = 1e-12, 2.0 * _EPS, 1e-300, 1.0 / 9.0
NU_SPLIT = 1.0
"""As :mod:`tumble._elliptic`, which derives them (a test checks they agree)."""
AGM_MAX_STEPS = 64
WORK_SIZE = AGM_MAX_STEPS
"""A flow's work array: the AGM's ratios."""


@njit(**_JIT)
def _carlson_rf(x, y, z):
    """``R_F(x, y, z)`` by duplication (Carlson 1995, Algorithm 1; DLMF 19.36.1)."""
    a0 = (x + y + z) / 3.0
    a, scale = a0, 1.0
    q = _RF_Q * max(abs(a0 - x), abs(a0 - y), abs(a0 - z))
    x0, y0 = x, y
    while scale * q >= abs(a):
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * sy + sx * sz + sy * sz
        x, y, z, a = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam), 0.25 * (a + lam)
        scale *= 0.25
    X, Y = (a0 - x0) * scale / a, (a0 - y0) * scale / a
    Z = -X - Y
    e2, e3 = X * Y - Z * Z, X * Y * Z
    return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / math.sqrt(a)


@njit(**_JIT)
def _rc_one(e):
    """``R_C(1, 1 + e)``: ``atan(√e)/√e``, ``atanh(√−e)/√−e``, or its series near 0."""
    if abs(e) < 1e-4:
        return 1.0 - e / 3.0 + e * e / 5.0 - e * e * e / 7.0 + e * e * e * e / 9.0
    if e > 0.0:
        root = math.sqrt(e)
        return math.atan(root) / root
    root = math.sqrt(-e)
    return math.atanh(root) / root


@njit(**_JIT)
def _carlson_rj(x, y, z, p):
    """``R_J(x, y, z, p)`` for ``p > 0`` by duplication (Carlson 1995, Algorithm 3)."""
    a0 = (x + y + z + 2.0 * p) / 5.0
    a, scale, total = a0, 1.0, 0.0
    delta = (p - x) * (p - y) * (p - z)
    q = _RJ_Q * max(abs(a0 - x), abs(a0 - y), abs(a0 - z), abs(a0 - p))
    x0, y0, z0 = x, y, z
    while scale * q >= abs(a):
        sx, sy, sz, sp = math.sqrt(x), math.sqrt(y), math.sqrt(z), math.sqrt(p)
        lam = sx * sy + sx * sz + sy * sz
        d = (sp + sx) * (sp + sy) * (sp + sz)
        total += scale / d * _rc_one(scale * scale * scale * delta / (d * d))
        x, y, z = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)
        p, a = 0.25 * (p + lam), 0.25 * (a + lam)
        scale *= 0.25
    X, Y, Z = (a0 - x0) * scale / a, (a0 - y0) * scale / a, (a0 - z0) * scale / a
    P = -0.5 * (X + Y + Z)
    e2 = X * Y + X * Z + Y * Z - 3.0 * P * P
    e3 = X * Y * Z + 2.0 * e2 * P + 4.0 * P * P * P
    e4 = (2.0 * X * Y * Z + e2 * P + 3.0 * P * P * P) * P
    e5 = X * Y * Z * P * P
    series = (1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0
              - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0)  # fmt: skip
    return scale * series / (a * math.sqrt(a)) + 6.0 * total


@njit(**_JIT)
def _jacobi(u, m, m1, work):
    """``(sn, cn, dn, am)`` of ``u`` by the AGM (``tumble._elliptic.jacobi``); ``work`` holds
    the ratios ``c_n/a_n``."""
    a, b, c = 1.0, math.sqrt(m1), math.sqrt(m)
    n = 0
    while c > _EPS * a and n < AGM_MAX_STEPS:
        a, b, c = 0.5 * (a + b), math.sqrt(a * b), 0.5 * (a - b)
        work[n] = c / a
        n += 1
    phi = 2.0**n * a * u
    for k in range(n - 1, -1, -1):
        phi = 0.5 * (phi + math.asin(work[k] * math.sin(phi)))
    sn, cn = math.sin(phi), math.cos(phi)
    return sn, cn, math.sqrt(cn * cn + m1 * sn * sn), phi


@njit(**_JIT)
def _jacobi_series(w, m, quarter, co_quarter):
    """``(sn, cn)`` of ``0 ≤ w ≤ K/2`` by their hyperbolic series
    (``tumble._elliptic.jacobi_series``)."""
    c = 0.5 * math.pi / co_quarter
    sech, tanh, twice = 1.0 / math.cosh(c * w), math.tanh(c * w), math.sinh(2.0 * c * w)
    cn, sn = sech, tanh
    for n in range(1, AGM_MAX_STEPS):
        near, far = math.cosh(c * (2 * n * quarter - w)), math.cosh(c * (2 * n * quarter + w))
        sign = -1.0 if n % 2 else 1.0
        cn += sign * (1.0 / near + 1.0 / far)
        sn += sign * twice / (near * far)
        if 1.0 / near <= 0.25 * _EPS * sech:
            break
    return c / math.sqrt(m) * sn, c / math.sqrt(m) * cn


@njit(**_JIT)
def _jacobi_reduced(r, m, m1, quarter, co_quarter, work):
    """``(sn, cn, dn)`` of ``|r| ≤ K``, each to a few ε relative and together on both
    identities (``tumble._elliptic.jacobi_reduced``: beyond K/2 by the reflection about K)."""
    w = abs(r)
    reflect = w > 0.5 * quarter
    if reflect:
        w = quarter - w
    if m1 >= M1_SERIES:
        s, c, _, _ = _jacobi(w, m, m1, work)
    else:
        s, c = _jacobi_series(w, m, quarter, co_quarter)
    size = math.hypot(s, c)
    s, c = s / size, c / size
    d = math.sqrt(c * c + m1 * s * s)
    if reflect:
        root = math.sqrt(m1)
        s, c, d = c / d, root * s / d, root / d
    return math.copysign(s, r), c, d


@njit(**_JIT)
def _legendre_integrals(s, c2, d2, nu, m):
    """``(F(φ|m), P)`` from ``s, cn², dn²``: ``Π(−ν; φ|m) = F + P`` for ``ν < 1``, ``= P``
    from 1 up (``tumble._elliptic.legendre_integrals``)."""
    r2 = s * s + c2
    first = s * _carlson_rf(c2, d2, r2)
    if nu < NU_SPLIT:
        return first, -nu / 3.0 * s * s * s * _carlson_rj(c2, d2, r2, r2 + nu * s * s)
    n = m / nu
    g = math.sqrt((1.0 + nu) * (1.0 + n))
    turn = math.atan2(g * s * math.sqrt(r2), math.sqrt(c2 * d2)) / g
    return first, n / 3.0 * s * s * s * _carlson_rj(c2, d2, r2, r2 + n * s * s) + turn


@njit(**_JIT)
def _complete_part(nu, m, m_1):
    """P of the complete ``Π(−ν|m)`` (``tumble._elliptic.complete_part``)."""
    if nu < NU_SPLIT:
        return -nu / 3.0 * _carlson_rj(0.0, m_1, 1.0, 1.0 + nu)
    n = m / nu
    g = math.sqrt((1.0 + nu) * (1.0 + n))
    return n / 3.0 * _carlson_rj(0.0, m_1, 1.0, 1.0 + n) + 0.5 * math.pi / g


@njit(**_JIT)
def _elliptic_step(wb, other_w, pole_w, amplitudes, rate, m, m_1, nu, h, work):
    """The elliptic motion from ω over ``h``: ``(ω_other, ω_B, ω_pole)`` at ``h`` and the
    difference over the step of the precession integral's part P (``Π(−ν; am u) = F + P``
    for ``ν < 1``, ``= P`` from 1 up; ``tumble._elliptic``'s ``elliptic_motion``,
    ``start_phase``, ``EllipticMotion.omega`` and ``precession``)."""
    amp_other, amp_b, amp_pole = amplitudes
    sign = 1.0 if pole_w > 0.0 else -1.0
    cn0 = other_w / amp_other if amp_other > 0.0 else 1.0
    sn0 = sign * wb / amp_b if amp_b > 0.0 else 0.0
    quarter = _carlson_rf(0.0, m_1, 1.0)
    full = 2.0 * _complete_part(nu, m, m_1)  # P of 2Π(−ν|m)
    half = 0.0 if cn0 >= 0.0 else (1.0 if sn0 >= 0.0 else -1.0)
    s, c = (sn0, cn0) if cn0 >= 0.0 else (-sn0, -cn0)
    u0, start = _legendre_integrals(s, c * c, c * c + m_1 * s * s, nu, m)
    u0, start = u0 + 2.0 * half * quarter, start + half * full
    co_quarter = _carlson_rf(0.0, m, 1.0) if m_1 < M1_SERIES else math.inf
    u = u0 + rate * h
    j = math.floor((u + quarter) / (2.0 * quarter))
    sn, cn, dn = _jacobi_reduced(u - 2.0 * quarter * j, m, m_1, quarter, co_quarter, work)
    flip = 1.0 - 2.0 * (j - 2.0 * math.floor(0.5 * j))
    part = _legendre_integrals(sn, cn * cn, dn * dn, nu, m)[1] + j * full
    return amp_other * flip * cn, sign * amp_b * flip * sn, sign * amp_pole * dn, part - start


@njit(**_JIT)
def _separatrix_step(wa, wb, wc, amp_a, amp_b, amp_c, rate, nu, h):
    """The motion at ``m = 1`` over ``h`` (``tumble._elliptic.SeparatrixMotion``):
    ``(ω_A, ω_B, ω_C)`` at ``h`` and ``∫ du/(1 + ν tanh²u)`` over the step."""
    sign, side = (1.0 if wc >= 0.0 else -1.0), (1.0 if wa >= 0.0 else -1.0)
    cn0 = abs(wa) / amp_a if amp_a > 0.0 else 0.0
    dn0 = abs(wc) / amp_c if amp_c > 0.0 else 0.0
    tanh0 = side * sign * wb / amp_b if amp_b > 0.0 else 0.0
    sech0 = math.sqrt(0.5 * (cn0 * cn0 + dn0 * dn0))
    u0 = math.asinh(tanh0 / sech0) if sech0 > 0.0 else math.copysign(math.inf, tanh0)
    u = u0 + rate * h
    sech, tanh, root = 1.0 / math.cosh(u), math.tanh(u), math.sqrt(nu)
    turn = root * (math.atan(root * tanh) - math.atan(root * math.tanh(u0)))
    return (side * amp_a * sech, side * sign * amp_b * tanh, sign * amp_c * sech,
            (rate * h + turn) / (1.0 + nu))  # fmt: skip


@njit(**_JIT)
def _pole_frame_product(l0, l1, l2, phi, k0, k1, k2):
    """``M(l)ᵀ Rz(φ) M(k)`` (``tumble._elliptic.pole_frames``: M has rows ``(r, −q, 0)/ρ``,
    ``(pq, pr, −ρ²)/ρ``, ``l``), as nine numbers."""
    rho = math.hypot(l0, l1)
    a00, a01, a02 = l1 / rho, -l0 / rho, 0.0
    a10, a11, a12 = l2 * l0 / rho, l2 * l1 / rho, -rho
    sigma = math.hypot(k0, k1)
    b00, b01, b02 = k1 / sigma, -k0 / sigma, 0.0
    b10, b11, b12 = k2 * k0 / sigma, k2 * k1 / sigma, -sigma
    c, s = math.cos(phi), math.sin(phi)
    # Rz(φ) M(k): rows c b0 − s b1, s b0 + c b1, k
    r00, r01, r02 = c * b00 - s * b10, c * b01 - s * b11, c * b02 - s * b12
    r10, r11, r12 = s * b00 + c * b10, s * b01 + c * b11, s * b02 + c * b12
    # M(l)ᵀ (…): column j of the product is Σ_i M(l)[i, :] (…)[i, j]
    return (
        a00 * r00 + a10 * r10 + l0 * k0, a00 * r01 + a10 * r11 + l0 * k1,
        a00 * r02 + a10 * r12 + l0 * k2,
        a01 * r00 + a11 * r10 + l1 * k0, a01 * r01 + a11 * r11 + l1 * k1,
        a01 * r02 + a11 * r12 + l1 * k2,
        a02 * r00 + a12 * r10 + l2 * k0, a02 * r01 + a12 * r11 + l2 * k1,
        a02 * r02 + a12 * r12 + l2 * k2,
    )  # fmt: skip


@njit(**_JIT)
def _times_permuted(Rp, pole, x00, x01, x02, x10, x11, x12, x20, x21, x22):
    """``R_p ← R_p P X Pᵀ`` with ``P`` the pole frame's axes (identity when ``pole = 2``,
    the cyclic ``(1, 2, 0)`` when ``pole = 0``): ``(P X Pᵀ)[o_i, o_j] = X[i, j]``."""
    if pole == 2:
        _times_matrix(Rp, x00, x01, x02, x10, x11, x12, x20, x21, x22)
    else:  # order (1, 2, 0): entry [o_i, o_j] = X[i, j]
        _times_matrix(Rp, x22, x20, x21, x02, x00, x01, x12, x10, x11)


@njit(**_JIT)
def _rotate_axis_angle(Rp, w0, w1, w2, h):
    """``R_p ← R_p exp(h ŵ)`` (Rodrigues)."""
    a, b = _exp_coefficients(h * h * (w0 * w0 + w1 * w1 + w2 * w2))
    for r in range(3):
        Rp[r, 0], Rp[r, 1], Rp[r, 2] = _rotate(-h * a, h * h * b, w0, w1, w2,
                                               Rp[r, 0], Rp[r, 1], Rp[r, 2])  # fmt: skip


@njit(**_JIT)
def _orthonormalise(Rp):
    """``R ← R (3 − RᵀR)/2``: one Newton step to the polar factor, removing the O(ε)
    departure from SO(3) a step leaves (without it the exact flow's R grows by 1.6e-16 a
    step, and its energy with it)."""
    S = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            S[i, j] = -0.5 * (Rp[0, i] * Rp[0, j] + Rp[1, i] * Rp[1, j] + Rp[2, i] * Rp[2, j])
        S[i, i] += 1.5
    _times_matrix(Rp, S[0, 0], S[0, 1], S[0, 2], S[1, 0], S[1, 1], S[1, 2], S[2, 0], S[2, 1],
                  S[2, 2])  # fmt: skip


@njit(**_INLINE)
def _exact_flow(Rp, L0, L1, L2, moments, h, work, head, tail):
    """The exact free-body flow over ``h`` (``tumble.rigid.geometric.exact_flow``)."""
    A, B, C = moments[0], moments[1], moments[2]
    m0, m1, m2 = _apply_transpose(Rp, L0, L1, L2)
    wa, wb, wc = m0 / A, m1 / B, m2 / C
    low, high = B - A <= SYMMETRY_RTOL * C, C - B <= SYMMETRY_RTOL * C
    nonzero = (wa != 0.0) + (wb != 0.0) + (wc != 0.0)
    if (low and high) or (not (low or high) and nonzero <= 1):
        _rotate_axis_angle(Rp, wa, wb, wc, h)  # ω constant: R exp(h ω̂)
        return True
    if low or high:  # symmetric: R(h) = exp(h L̂/I⊥) R exp(Ω h ê_s)
        s = 0 if high else 2
        transverse = 0.5 * (B + (C if high else A))
        ws = wa if s == 0 else wc
        rate = (transverse - moments[s]) * ws / transverse
        n0, n1, n2 = L0 / transverse, L1 / transverse, L2 / transverse
        a, b = _exp_coefficients(h * h * (n0 * n0 + n1 * n1 + n2 * n2))
        for c in range(3):  # column c of exp(h n̂) R
            Rp[0, c], Rp[1, c], Rp[2, c] = _rotate(h * a, h * h * b, n0, n1, n2,
                                                   Rp[0, c], Rp[1, c], Rp[2, c])  # fmt: skip
        _turn(Rp, 0.0, 0.0, 0.0, s, rate * h)
        return True
    # the asymmetric body (tumble._elliptic.elliptic_motion; SEPARATRIX_RTOL says the test)
    s_p = math.hypot(math.sqrt(A * (C - A)) * wa, math.sqrt(B * (C - B)) * wb)
    s_q = math.hypot(math.sqrt(B * (B - A)) * wb, math.sqrt(C * (C - A)) * wc)
    x, y = math.sqrt(C * (C - B)) * abs(wc), math.sqrt(A * (B - A)) * abs(wa)
    amp_a, amp_c = s_p / math.sqrt(A * (C - A)), s_q / math.sqrt(C * (C - A))
    separatrix = abs(x - y) <= SEPARATRIX_RTOL * (x + y)
    if x > y or separatrix:
        pole, amp_b = 2, s_p / math.sqrt(B * (C - B))
        rate = s_q * math.sqrt((C - B) / (A * B * C))
        m = (B - A) / (C - B) * (s_p / s_q) ** 2
        m_1 = (C - A) / (C - B) * ((x - y) / s_q) * ((x + y) / s_q)
    else:
        pole, amp_b = 0, s_q / math.sqrt(B * (B - A))
        rate = s_p * math.sqrt((B - A) / (A * B * C))
        m = (C - B) / (B - A) * (s_q / s_p) ** 2
        m_1 = (C - A) / (B - A) * ((y - x) / s_p) * ((y + x) / s_p)
    if not (separatrix or m_1 >= M1_MIN):  # m = 1 in double precision: regime C's limit
        separatrix, pole, amp_b = True, 2, s_p / math.sqrt(B * (C - B))
        rate = s_q * math.sqrt((C - B) / (A * B * C))
    if pole == 2:
        nu, weight = C * (B - A) / (A * (C - B)), 1.0
    else:
        nu, weight = A * (C - B) / (C * (B - A)), -1.0
    if separatrix:  # tumble._elliptic.SeparatrixMotion (regime C at m = 1)
        e0, e1, e2, integral = _separatrix_step(wa, wb, wc, amp_a, amp_b, amp_c, rate, nu, h)
    elif pole == 2:
        e0, e1, e2, integral = _elliptic_step(
            wb, wa, wc, (amp_a, amp_b, amp_c), rate, m, m_1, nu, h, work
        )
    else:
        e2, e1, e0, integral = _elliptic_step(
            wb, wc, wa, (amp_c, amp_b, amp_a), rate, m, m_1, nu, h, work
        )
    norm = math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    scale = weight * norm * (C - A) / (A * C * rate)
    if separatrix:
        phi = norm * h / moments[pole] + scale * integral
    elif nu < NU_SPLIT:  # Π = F + P, F's part λh: |L|/I_pole ± |L|(C − A)/(AC) = |L|/I_other
        phi = norm * h / moments[2 - pole] + scale * integral
    else:  # Π = P
        phi = norm * h / moments[pole] + scale * integral
    # l = I ω / |L| in the pole frame's order (q, r, p)
    if pole == 2:
        i0, i1, i2 = 0, 1, 2
    else:
        i0, i1, i2 = 1, 2, 0
    e = (e0, e1, e2)  # ω at h
    p0, p1, p2 = (m0, m1, m2)[i0], (m0, m1, m2)[i1], (m0, m1, m2)[i2]  # the state's own m
    q0, q1, q2 = moments[i0] * e[i0], moments[i1] * e[i1], moments[i2] * e[i2]
    size_p = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)  # unit l: M(l) orthogonal to round-off
    size_q = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2)
    _times_permuted(
        Rp, pole,
        *_pole_frame_product(p0 / size_p, p1 / size_p, p2 / size_p, phi,
                             q0 / size_q, q1 / size_q, q2 / size_q),
    )  # fmt: skip
    _orthonormalise(Rp)
    return True


@njit(**_INLINE)
def _kick(problem, z, Rp, s):
    """``(p, L) += s (F, τ)`` at the state ``(z, R_p)``; body vectors ``r`` are turned by
    ``R r = R_p (Pᵀ r)``."""
    P = problem.axes
    for c in range(3):
        z[3 + c] += s * problem.F[c]
        z[6 + c] += s * problem.tau[c]
    points, point_forces = problem.points, problem.point_forces
    for k in range(points.shape[0]):
        r0, r1, r2 = _apply(Rp, *_apply_transpose(P, points[k, 0], points[k, 1], points[k, 2]))
        f0, f1, f2 = point_forces[k, 0], point_forces[k, 1], point_forces[k, 2]
        t0, t1, t2 = _cross(r0, r1, r2, f0, f1, f2)
        z[3] += s * f0
        z[4] += s * f1
        z[5] += s * f2
        z[6] += s * t0
        z[7] += s * t1
        z[8] += s * t2


@njit(**_JIT)
def _split_record(z, Rp, P, R_out, Y_out):
    """``R = R_p Pᵀ`` and ``Y = z``."""
    for r in range(3):
        for c in range(3):
            R_out[r, c] = Rp[r, 0] * P[c, 0] + Rp[r, 1] * P[c, 1] + Rp[r, 2] * P[c, 2]
    _copy(z, 0, Y_out)


def _split_loop(problem, grid, z, Rn, k0, k1, every, step0, records):
    """Steps ``k0+1 … k1`` of ``grid`` for one ``split`` method (``FLOW``, bound).

    Each step is :func:`tumble.rigid.geometric.split_step`: for each composition weight
    ``w`` (``problem.b``), with ``s = w h``,

    .. math:: (p, L) \\mathrel{+}= \\tfrac{s}{2}(F, \\tau),\\quad x \\mathrel{+}= s\\,p/m,
              \\quad R_p \\leftarrow \\Phi_s(R_p; L),\\quad
              (p, L) \\mathrel{+}= \\tfrac{s}{2}(F, \\tau).

    ``z = (x, p, L)`` and ``Rn = R_p`` hold the state and are updated in place. Returns
    ``(recorded, failed, cause)`` as :func:`_loop`; a failed step leaves the state at the
    step before. Without loads the kicks are skipped, and where ``MERGES`` (the axes flow)
    the last half turn of one sub-step and the first of the next are done as one turn,
    settled before every recorded step, at the block's end and on failure.
    """
    t_a, t_b, h, n = grid
    weights, mass = problem.b, problem.m
    saved, R_saved, work = np.empty(9), np.empty((3, 3)), np.empty(WORK_SIZE)
    loaded = problem.points.shape[0] > 0
    for c in range(3):
        loaded = loaded or problem.F[c] != 0.0 or problem.tau[c] != 0.0
    merge = MERGES and not loaded  # noqa: F821
    owed = 0.0  # a sub-step whose last half turn about axis 1 is still to do (merged)
    last = weights.shape[0] - 1
    count, until_record = 0, every - (step0 + k0) % every
    for k in range(k0 + 1, k1 + 1):
        t_old = t_a + (k - 1) * h
        hk = (t_b if k == n else t_a + k * h) - t_old
        _copy(z, 0, saved)
        _copy_matrix(Rn, R_saved)
        owed_before = owed
        settle = until_record == 1 or k == k1  # this step's end is recorded or handed back
        converged = True
        for index in range(last + 1):
            s = weights[index] * hk
            if loaded:
                _kick(problem, z, Rn, 0.5 * s)
            for c in range(3):
                z[c] += s * z[3 + c] / mass
            head, tail = owed + s, s
            owed = 0.0
            if merge and not (settle and index == last):
                tail, owed = 0.0, s
            step_ok = FLOW(Rn, z[6], z[7], z[8], problem.moments, s, work, head, tail)  # noqa: F821
            converged = converged and step_ok
            if loaded:
                _kick(problem, z, Rn, 0.5 * s)
        finite = True
        for q in range(9):
            finite = finite and math.isfinite(z[q])
        for r in range(3):
            for c in range(3):
                finite = finite and math.isfinite(Rn[r, c])
        if not (finite and converged):
            _copy(saved, 0, z)
            _copy_matrix(R_saved, Rn)
            if owed_before != 0.0:  # the state before: finish its last half turn
                FLOW(Rn, z[6], z[7], z[8], problem.moments, 0.0, work, 0.0, owed_before)  # noqa: F821
            return count, k, NON_FINITE if not finite else UNCONVERGED
        until_record -= 1
        if until_record == 0:
            records.t[count] = t_old + hk
            _split_record(z, Rn, problem.axes, records.R[count], records.Y[count])
            count += 1
            until_record = every
    return count, -1, NON_FINITE


def _for_flow(name: str, flow) -> CompiledChart:
    merges = name == "axes"  # the only flow with separable outer turns
    loop = njit(**_JIT)(_bind(_split_loop, f"_split_loop_{name}", FLOW=flow, MERGES=merges))
    batch = njit(parallel=True, **_JIT)(_bind(_batch, f"_batch_split_{name}", LOOP=loop))
    return CompiledChart(loop, batch)


COMPILED_FLOWS: dict[str, CompiledChart] = {
    "axes": _for_flow("axes", _axes_flow),
    "midpoint": _for_flow("midpoint", _midpoint_flow),
    "dmv": _for_flow("dmv", _dmv_flow),
    "exact": _for_flow("exact", _exact_flow),
}
"""Each flow of :data:`tumble.rigid.geometric.FLOWS`, compiled in a ``split`` loop."""
