"""What every compiled rigid-body loop shares: the run's data, its records, the 3-vector
helpers and the way a loop template is bound to a family's functions.

The run's data travel in one :class:`KernelProblem`, its samples in one :class:`Records`,
its grid in the driver's :class:`~tumble.ode.driver.Grid`. The 3 × 3 helpers are the Python
reference's own (:mod:`tumble.rigid.charts`: its error norm uses them), compiled: one
definition for both paths.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from tumble.ode.templates import INLINE as _INLINE
from tumble.ode.templates import JIT as _JIT
from tumble.rigid import charts


@njit(**_JIT)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


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


class KernelProblem(NamedTuple):
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


@dataclass(frozen=True)
class CompiledChart:
    """A chart's compiled loop for one body (:func:`_loop`), for a batch (:func:`_batch`),
    and its adaptive loop (:func:`_adaptive_loop`)."""

    loop: Callable[..., tuple[int, int, int]]
    batch: Callable[..., None]
    adaptive: Callable[..., tuple] | None = None
