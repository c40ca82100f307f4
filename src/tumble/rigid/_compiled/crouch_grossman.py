"""The Crouch–Grossman step (:mod:`tumble.rigid.crouch_grossman`), compiled.

One step, :func:`_step`, bound into the fixed-step template of :mod:`tumble.ode.templates`
(:data:`COMPILED_CG`, one loop for every CG tableau: ``A`` and ``b`` travel in the
:class:`~tumble.rigid._compiled.base.KernelProblem`) and into the batch's parallel loop over
bodies. Each stage turns a copy of ``R_n`` by the stages before it, ``R_i = R_n
exp(h a_i1 ω̂_1) ⋯``, with Rodrigues' formula on the rows (the series of the exp coefficients
below 0.25 rad, as every compiled chart); the loads are the charts' constant ones
(``_loads``). The state ``(z, R_n)``, ``z = (x, p, L)``, is updated in place.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from tumble.ode import templates
from tumble.ode.templates import NON_FINITE, OK, bind
from tumble.rigid._compiled.base import (
    _INLINE,
    _JIT,
    CompiledChart,
    _apply,
    _apply_transpose,
    _copy,
    _copy_matrix,
    _loads,
)
from tumble.rigid._compiled.charts import _batch
from tumble.rigid._compiled.exact_flow import _rotate_axis_angle


@njit(**_INLINE)
def _work(problem, state):
    """The stages' slopes ``K`` (s, 9), body rates ``W`` (s, 3), the stage point ``zs`` and
    the stage rotation ``R_i``."""
    s = problem.b.shape[0]
    return np.empty((s, 9)), np.empty((s, 3)), np.empty(9), np.empty((3, 3))


@njit(**_INLINE)
def _step(problem, state, work, t, t_new, settle):
    """:func:`tumble.rigid.crouch_grossman.cg_step` for constant loads, in place."""
    z, Rn = state
    K, W, zs, Ri = work
    A, b, h = problem.A, problem.b, t_new - t
    s = b.shape[0]
    for i in range(s):
        _copy_matrix(Rn, Ri)
        for j in range(i):
            turn = h * A[i, j]  # the turn's vector scaled first: no overflow in |ω|²
            _rotate_axis_angle(Ri, turn * W[j, 0], turn * W[j, 1], turn * W[j, 2], 1.0)
        for q in range(9):
            acc = 0.0
            for j in range(i):
                acc += A[i, j] * K[j, q]
            zs[q] = z[q] + h * acc
        m0, m1, m2 = _apply_transpose(Ri, zs[6], zs[7], zs[8])
        W[i, 0], W[i, 1], W[i, 2] = _apply(problem.inv_I, m0, m1, m2)
        _loads(0, zs, Ri, 0.0, 0.0, 0.0, 0.0, 0.0, problem, K, i)
    finite = True
    for q in range(9):  # z_new = z + h Σ b_i k_i
        acc = 0.0
        for i in range(s):
            acc += b[i] * K[i, q]
        zs[q] = z[q] + h * acc
        finite = finite and math.isfinite(zs[q])
    for i in range(s):
        for c in range(3):
            finite = finite and math.isfinite(W[i, c])
    if not finite:
        return NON_FINITE
    for j in range(s):
        turn = h * b[j]
        _rotate_axis_angle(Rn, turn * W[j, 0], turn * W[j, 1], turn * W[j, 2], 1.0)
    _copy(zs, 0, z)
    return OK


@njit(**_INLINE)
def _record(problem, state, work, records, i):
    z, Rn = state
    _copy_matrix(Rn, records.R[i])
    _copy(z, 0, records.Y[i])


def _compile() -> CompiledChart:
    loop = templates.loop(templates.fixed_loop, "_cg_loop", WORK=_work, STEP=_step, RECORD=_record)
    batch = njit(parallel=True, **_JIT)(bind(_batch, "_batch_cg", LOOP=loop))
    return CompiledChart(loop, batch)


COMPILED_CG = _compile()
"""The Crouch–Grossman loop for one body and for a batch (every CG tableau)."""
