"""The ``split`` family (:mod:`tumble.rigid.geometric`), compiled: kicks and a free-body
flow. The attitude is ``R_p = R P`` (principal frame); a flow turns it in place and returns
False when its Newton iteration did not converge. Each flow's step (:func:`_split_step`) is
bound into the fixed-step template of :mod:`tumble.ode.templates` (:data:`COMPILED_FLOWS`);
the template's :class:`~tumble.ode.templates.LoopCompiler` keeps it as fast as the loop the
flows had of their own (a 0.085 µs axes step took 0.15 µs bound without it).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from tumble.ode import templates
from tumble.ode.templates import NON_FINITE, OK, UNCONVERGED, bind
from tumble.rigid._compiled.base import (
    _INLINE,
    _JIT,
    CompiledChart,
    _apply,
    _apply_transpose,
    _copy,
    _copy_matrix,
    _cross,
    _gradient,
    _times_matrix,
    _turn,
)
from tumble.rigid._compiled.charts import _batch
from tumble.rigid._compiled.exact_flow import WORK_SIZE, _exact_flow

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


@njit(**_INLINE)
def _kick(problem, z, Rp, s):
    """``(p, L) += s (F, τ)`` at the state ``(z, R_p)``; body vectors ``r`` are turned by
    ``R r = R_p (Pᵀ r)``, and a point mass's gravity gradient (:func:`~.base._gradient`)
    takes the inertia in the principal frame, ``R I Rᵀ = R_p diag(I₁, I₂, I₃) R_pᵀ``."""
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
    gravity, M = problem.gravity, problem.moments
    if gravity.shape[0] == 0:
        return
    Rt = (Rp[0, 0], Rp[0, 1], Rp[0, 2], Rp[1, 0], Rp[1, 1], Rp[1, 2], Rp[2, 0], Rp[2, 1],
          Rp[2, 2])  # fmt: skip
    It = (M[0], 0.0, 0.0, 0.0, M[1], 0.0, 0.0, 0.0, M[2])
    for k in range(gravity.shape[0]):
        f0, f1, f2, t0, t1, t2 = _gradient(
            gravity[k, 0], problem.m, z[0] - gravity[k, 1], z[1] - gravity[k, 2],
            z[2] - gravity[k, 3], Rt, 0.0, 0.0, 0.0, 0.0, 0.0, It,
        )  # fmt: skip
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


def _split_work(problem, state):
    """A saved state (``z``, ``R_p``), the flow's work array, the half turn owed by a merged
    sub-step, and whether there are loads (else the kicks are skipped) and the outer half
    turns merge (``MERGES``, the axes flow, and no loads)."""
    loaded = problem.points.shape[0] > 0 or problem.gravity.shape[0] > 0
    for c in range(3):
        loaded = loaded or problem.F[c] != 0.0 or problem.tau[c] != 0.0
    merge = MERGES and not loaded  # noqa: F821
    return np.empty(9), np.empty((3, 3)), np.empty(WORK_SIZE), np.zeros(1), loaded, merge


def _split_step(problem, state, work, t, t_new, settle):
    """One step of a ``split`` method (``FLOW``, bound): :func:`tumble.rigid.geometric.split_step`.

    For each composition weight ``w`` (``problem.b``), with ``s = w h``,

    .. math:: (p, L) \\mathrel{+}= \\tfrac{s}{2}(F, \\tau),\\quad x \\mathrel{+}= s\\,p/m,
              \\quad R_p \\leftarrow \\Phi_s(R_p; L),\\quad
              (p, L) \\mathrel{+}= \\tfrac{s}{2}(F, \\tau).

    ``state = (z, R_p)``, ``z = (x, p, L)``, is updated in place; a step that fails
    (:data:`~tumble.ode.templates.NON_FINITE`, or ``UNCONVERGED`` for an implicit flow) leaves
    it at the step before. Where the outer half turns merge, the last half turn of one
    sub-step and the first of the next are done as one turn, settled (``settle``) before
    every recorded step, at the block's end and on failure.
    """
    z, Rn = state
    saved, R_saved, flow_work, owing, loaded, merge = work
    weights, mass, h = problem.b, problem.m, t_new - t
    last = weights.shape[0] - 1
    _copy(z, 0, saved)
    _copy_matrix(Rn, R_saved)
    owed = owing[0]  # a sub-step whose last half turn about axis 1 is still to do (merged)
    owed_before = owed
    converged = True
    for index in range(last + 1):
        s = weights[index] * h
        if loaded:
            _kick(problem, z, Rn, 0.5 * s)
        for c in range(3):
            z[c] += s * z[3 + c] / mass
        head, tail = owed + s, s
        owed = 0.0
        if merge and not (settle and index == last):
            tail, owed = 0.0, s
        step_ok = FLOW(Rn, z[6], z[7], z[8], problem.moments, s, flow_work, head, tail)  # noqa: F821
        converged = converged and step_ok
        if loaded:
            _kick(problem, z, Rn, 0.5 * s)
    owing[0] = owed
    finite = True
    for q in range(9):
        finite = finite and math.isfinite(z[q])
    for r in range(3):
        for c in range(3):
            finite = finite and math.isfinite(Rn[r, c])
    if finite and converged:
        return OK
    _copy(saved, 0, z)
    _copy_matrix(R_saved, Rn)
    owing[0] = 0.0
    if owed_before != 0.0:  # the state before: finish its last half turn
        FLOW(Rn, z[6], z[7], z[8], problem.moments, 0.0, flow_work, 0.0, owed_before)  # noqa: F821
    return NON_FINITE if not finite else UNCONVERGED


@njit(**_INLINE)
def _split_recorder(problem, state, work, records, i):
    _split_record(state[0], state[1], problem.axes, records.R[i], records.Y[i])


def _for_flow(name: str, flow) -> CompiledChart:
    merges = name == "axes"  # the only flow with separable outer turns
    work = njit(**_INLINE)(bind(_split_work, f"_split_work_{name}", MERGES=merges))
    step = njit(**_INLINE)(bind(_split_step, f"_split_step_{name}", FLOW=flow))
    loop = templates.loop(
        templates.fixed_loop, f"_split_loop_{name}", WORK=work, STEP=step, RECORD=_split_recorder
    )
    batch = njit(parallel=True, **_JIT)(bind(_batch, f"_batch_split_{name}", LOOP=loop))
    return CompiledChart(loop, batch)


COMPILED_FLOWS: dict[str, CompiledChart] = {
    "axes": _for_flow("axes", _axes_flow),
    "midpoint": _for_flow("midpoint", _midpoint_flow),
    "dmv": _for_flow("dmv", _dmv_flow),
    "exact": _for_flow("exact", _exact_flow),
}
"""Each flow of :data:`tumble.rigid.geometric.FLOWS`, compiled in a ``split`` loop."""
