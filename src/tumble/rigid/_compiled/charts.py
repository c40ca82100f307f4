"""The charts of :mod:`tumble.rigid.charts`, compiled (numba), and their loops.

One loop, :func:`_loop`, runs every fixed-step method for constant loads: a stage loop over
the tableau (``A``, ``b`` as arrays), the chart's vector field, and the chart's map back. A
chart's compiled twin is three functions (field, advance, record), and :func:`_for_chart`
compiles the loop once per chart with that chart's functions inlined (:data:`COMPILED`),
and a parallel loop over bodies for :func:`~tumble.rigid.simulate_batch`. The run's data
travel in one :class:`~.base.KernelProblem`, its samples in one
:class:`~.base.Records`, its grid in the driver's :class:`~tumble.ode.driver.Grid`.

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

import numpy as np
from numba import njit, prange

from tumble.ode import templates
from tumble.ode.templates import NON_FINITE, OK, bind
from tumble.rigid import charts
from tumble.rigid._compiled.base import (
    _INLINE,
    _JIT,
    CompiledChart,
    KernelProblem,
    Records,
    _apply,
    _apply_transpose,
    _copy,
    _copy_matrix,
    _loads,
    _quat_matrix,
    _rotate,
)

SERIES_ANGLE = 0.25
"""Below this angle (rad) the exp and dexp⁻¹ coefficients use their Taylor series; the first
term left out is below 1e-17 relative (θ¹²/13! for sin θ/θ, 8e-19 for dexp⁻¹)."""

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
def _take_new(z, znew, Rn):
    """``z ← z_new``: the map back of the charts that carry the attitude in ``z`` itself
    (``matrix``; ``quat``, whose ``q`` is normalised by :func:`_quat_start`)."""
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


@njit(**_JIT)
def _matrix_record(z, Rn, R_out, q_out, Y_out):
    for r in range(3):
        for c in range(3):
            R_out[r, c] = z[3 * r + c]
    _copy(z, 9, Y_out)


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


def _work(problem, state):
    """The stages ``K``, the stage point ``zs``, a rotation ``R`` and the error ``err``."""
    s, nz = problem.b.shape[0], state[0].shape[0]
    return np.empty((s, nz)), np.empty(nz), np.empty((3, 3)), np.empty(nz)


def _adaptive_work(problem, state):
    return _work(problem[0], state)


def _step(problem, state, work, t, t_new, settle):
    """One explicit Runge–Kutta step of the chart's field (as :func:`tumble.ode.stepper.rk_step`)

    .. math:: k_i = f\\Bigl(z + h \\sum_{j<i} a_{ij} k_j\\Bigr), \\quad
              z_{n+1} = z + h \\sum_i b_i k_i,

    then the chart's map back; ``START`` runs before the step (the ``quat`` chart normalises
    there). ``state = (z, R_n)`` is updated in place unless the new ``z`` is not finite.
    ``STAGES`` (:func:`_stages` with the chart's field), ``START`` and ``ADVANCE`` are the
    chart's, bound by :func:`_for_chart`.
    """
    z, Rn = state
    K, zs, R, _ = work
    b, h = problem.b, t_new - t
    START(z, Rn)  # noqa: F821
    STAGES(problem, problem.A, z, Rn, h, 0, K, zs, R)  # noqa: F821
    finite = True
    for q in range(z.shape[0]):  # z_new = z + h Σ b_i k_i
        acc = 0.0
        for i in range(b.shape[0]):
            acc += b[i] * K[i, q]
        zs[q] = z[q] + h * acc
        finite = finite and math.isfinite(zs[q])
    if not finite:
        return NON_FINITE
    ADVANCE(z, zs, Rn)  # noqa: F821
    return OK


def _try(problem, state, work, t, h, have_first, share):
    """The step of :func:`_step` into ``work`` (``z`` untouched) with its embedded error
    ``h Σ e_i k_i``, and the error's norm per unit step ``share``:
    :func:`tumble.rigid.charts.error_norm` (compiled from it, ``NORM``). ``problem`` is
    ``(KernelProblem, (e, rtol, atol, separatrix))``; with ``have_first`` the first stage is
    the last accepted try's (FSAL)."""
    p, tolerances = problem
    e, rtol, atol, separatrix = tolerances
    z, Rn = state
    K, zs, R, err = work
    b = p.b
    START(z, Rn)  # noqa: F821
    STAGES(p, p.A, z, Rn, h, 1 if have_first else 0, K, zs, R)  # noqa: F821
    for q in range(z.shape[0]):  # z_new = z + h Σ b_i k_i, error h Σ e_i k_i
        acc, acc_e = 0.0, 0.0
        for i in range(b.shape[0]):
            acc += b[i] * K[i, q]
            acc_e += e[i] * K[i, q]
        zs[q] = z[q] + h * acc
        err[q] = h * acc_e
    return NORM(err, z, zs, Rn, rtol, atol, separatrix, share) / share  # noqa: F821


@njit(**_INLINE)
def _finite(problem, state, work):
    zs = work[1]
    for q in range(zs.shape[0]):
        if not math.isfinite(zs[q]):
            return False
    return True


def _accept(problem, state, work, t, t_new, fsal):
    """The tried ``z`` becomes the state (``ADVANCE``); the last stage becomes the next
    try's first where the chart can (``FIRST_SAME_AS_LAST``)."""
    z, Rn = state
    K, zs = work[0], work[1]
    ADVANCE(z, zs, Rn)  # noqa: F821
    return fsal and FIRST_SAME_AS_LAST(K, K.shape[0], zs)  # noqa: F821


def _record(problem, state, work, records, i):
    z, Rn = state
    RECORD(z, Rn, records.R[i], records.q[i], records.Y[i])  # noqa: F821


def _batch(problem, grid, Z, RN, k0, k1, every, step0, records, counts, failed, causes):
    """:data:`LOOP` over steps ``k0 + 1 … k1`` of ``grid`` for every body ``k`` in parallel.

    Body ``k``'s state is ``Z[k]`` (and ``RN[k]``), its data ``problem.inv_I[k]``,
    ``problem.m[k]``, ``problem.F[k]``, ``problem.axes[k]``, ``problem.moments[k]`` and
    ``problem.inertia[k]``; its samples go to ``records.t[k]``, … ; ``counts[k]`` samples,
    the failed step ``failed[k]`` (-1 if none) and its cause ``causes[k]`` come back. A body
    stopped in an earlier block (``failed[k] >= 0`` on entry) is left as it is.
    """
    for k in prange(Z.shape[0]):
        if failed[k] < 0:
            p = problem
            body = KernelProblem(p.correct, p.A, p.b, p.inv_I[k], p.m[k], p.F[k], p.tau,
                                 p.points, p.point_forces, p.axes[k], p.moments[k], p.gravity,
                                 p.inertia[k])  # fmt: skip
            body_records = Records(records.t[k], records.R[k], records.q[k], records.Y[k])
            counts[k], failed[k], causes[k] = LOOP(body, grid, (Z[k], RN[k]), k0, k1, every,  # noqa: F821
                                                   step0, body_records)  # fmt: skip


# The error norm is the Python reference's own function, compiled: the adaptive loop and
# the driver cannot drift apart.
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
    """The chart's functions bound into :mod:`tumble.ode.templates`' loops."""
    stages = njit(**_INLINE)(bind(_stages, f"_stages_{name}", FIELD=field))
    chart = dict(STAGES=stages, ADVANCE=advance, START=start)
    step = njit(**_INLINE)(bind(_step, f"_step_{name}", **chart))
    recorder = njit(**_INLINE)(bind(_record, f"_record_{name}", RECORD=record))
    loop = templates.loop(
        templates.fixed_loop, f"_loop_{name}", WORK=_WORK, STEP=step, RECORD=recorder
    )
    batch = njit(parallel=True, **_JIT)(bind(_batch, f"_batch_{name}", LOOP=loop))
    if not adaptive:  # the error norm is the lie chart's (every adaptive method is one)
        return CompiledChart(loop, batch)
    tried = njit(**_INLINE)(bind(_try, f"_try_{name}", NORM=_ERROR_NORM, **chart))
    accept = njit(**_INLINE)(
        bind(_accept, f"_accept_{name}", ADVANCE=advance, FIRST_SAME_AS_LAST=fsal)
    )
    adaptive_loop = templates.loop(
        templates.adaptive_loop, f"_adaptive_{name}", WORK=_ADAPTIVE_WORK, TRY=tried,
        FINITE=_finite, ACCEPT=accept, RECORD=recorder,
    )  # fmt: skip
    return CompiledChart(loop, batch, adaptive_loop)


_WORK = njit(**_INLINE)(_work)
_ADAPTIVE_WORK = njit(**_INLINE)(bind(_adaptive_work, "_adaptive_work", _work=_WORK))


COMPILED: dict[str, CompiledChart] = {
    "matrix": _for_chart("matrix", _matrix_field, _take_new, _matrix_record),
    "quat": _for_chart("quat", _quat_field, _take_new, _quat_record, _quat_start),
    "lie": _for_chart(
        "lie", _lie_field, _lie_advance, _lie_record, fsal=_lie_first_same_as_last, adaptive=True
    ),  # fmt: skip
}
"""Each chart of :data:`tumble.rigid.charts.CHARTS`, compiled."""

# ---------------------------------------------------------------------------------------
# The ``split`` family (:mod:`tumble.rigid.geometric`): kicks, a free-body flow, compiled.
# The attitude is ``R_p = R P`` (principal frame); a flow turns it in place and returns
# False when its Newton iteration did not converge.
