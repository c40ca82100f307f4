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


# Inlined by numba, not left to LLVM: as a call, the KernelProblem's thirteen fields crossed
# it at every stage with their reference counts, 1.6-2.7x the chart loops' time (issue 25).
@njit(**_INLINE)
def _loads(off, zs, R, a, b, u0, u1, u2, problem, K, i):
    """``K[i, off:] = (p/m, F + Σ f_k + Σ F_g, τ + Σ (R exp(û) r_k) × f_k + Σ τ_g)``,
    ``zs[off:] = (x, p, L)``; ``(F_g, τ_g)`` the point masses' (:func:`_gradient`)."""
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
    gravity = problem.gravity
    if gravity.shape[0] == 0:
        return
    I = problem.inertia
    Rt = (R[0, 0], R[0, 1], R[0, 2], R[1, 0], R[1, 1], R[1, 2], R[2, 0], R[2, 1], R[2, 2])
    It = (I[0, 0], I[0, 1], I[0, 2], I[1, 0], I[1, 1], I[1, 2], I[2, 0], I[2, 1], I[2, 2])
    for k in range(gravity.shape[0]):
        f0, f1, f2, t0, t1, t2 = _gradient(
            gravity[k, 0], m, zs[off] - gravity[k, 1], zs[off + 1] - gravity[k, 2],
            zs[off + 2] - gravity[k, 3], Rt, a, b, u0, u1, u2, It,
        )  # fmt: skip
        K[i, off + 3] += f0
        K[i, off + 4] += f1
        K[i, off + 5] += f2
        K[i, off + 6] += t0
        K[i, off + 7] += t1
        K[i, off + 8] += t2


@njit(**_JIT)
def _gradient(mu, m, r0, r1, r2, R, a, b, u0, u1, u2, I):
    """A :class:`~tumble.rigid.forces.GravityGradient`'s ``(F, τ)`` (world, six numbers):
    the point mass ``μ`` seen at ``r = x − c`` by a body of mass ``m`` and inertia ``I``
    (body axes, a 9-tuple row by row) at the attitude ``R exp(û)`` (``R`` a 9-tuple row by
    row; ``a, b`` exp's coefficients of ``u``, zeros for the charts that carry no ``u``):

    .. math:: \\tau = \\frac{3\\mu}{r^5} r \\times I_w r, \\quad
              F = -\\frac{\\mu m}{r^3} r - \\frac{3\\mu}{r^5}\\Bigl[\\bigl(\\tfrac12
              \\operatorname{tr} I - \\tfrac52 \\hat r^T I_w \\hat r\\bigr) r
              + I_w r\\Bigr],

    ``I_w r = R exp(û) I exp(−û) Rᵀ r``, the NumPy reference's formula term for term. One
    function for the one-body loops and the batch's columns (:mod:`tumble.rigid.soa`), so
    both do the same operations."""
    s0 = R[0] * r0 + R[3] * r1 + R[6] * r2
    s1 = R[1] * r0 + R[4] * r1 + R[7] * r2
    s2 = R[2] * r0 + R[5] * r1 + R[8] * r2
    s0, s1, s2 = _rotate(-a, b, u0, u1, u2, s0, s1, s2)  # r in body axes
    y0 = I[0] * s0 + I[1] * s1 + I[2] * s2
    y1 = I[3] * s0 + I[4] * s1 + I[5] * s2
    y2 = I[6] * s0 + I[7] * s1 + I[8] * s2
    v0, v1, v2 = _rotate(a, b, u0, u1, u2, y0, y1, y2)
    w0 = R[0] * v0 + R[1] * v1 + R[2] * v2  # I_w r
    w1 = R[3] * v0 + R[4] * v1 + R[5] * v2
    w2 = R[6] * v0 + R[7] * v1 + R[8] * v2
    rr = r0 * r0 + r1 * r1 + r2 * r2
    distance = math.sqrt(rr)
    k = 3.0 * mu / (rr * rr * distance)
    radial = 0.5 * (I[0] + I[4] + I[8]) - 2.5 * (s0 * y0 + s1 * y1 + s2 * y2) / rr
    g = mu * m / (rr * distance)
    t0, t1, t2 = _cross(r0, r1, r2, w0, w1, w2)
    return (
        -g * r0 - k * (radial * r0 + w0),
        -g * r1 - k * (radial * r1 + w1),
        -g * r2 - k * (radial * r2 + w2),
        k * t0,
        k * t1,
        k * t2,
    )


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
    principal axes and moments (the ``split`` loops); ``gravity`` (g, 4): one row
    ``(μ, c)`` per :class:`~tumble.rigid.forces.GravityGradient`, ``inertia`` (3, 3): the
    body's, which its torque needs. For the batch loops ``inv_I``, ``m``, ``F``, ``axes``,
    ``moments`` and ``inertia`` carry a leading body axis.
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
    gravity: np.ndarray
    inertia: np.ndarray


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
