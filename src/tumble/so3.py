"""Rotations: pure functions on arrays, batched over leading axes.

Conventions (SPEC §2): a rotation matrix ``R`` maps body to world, ``r_world = R r_body``.
Quaternions are scalar-first ``[w, x, y, z]`` with the Hamilton product; scipy's
``Rotation.from_quat`` is scalar-last by default, so convert explicitly. Rotation vectors
``w`` have angle ``|w|`` (rad) about ``w / |w|``. ZYX Euler angles are ``[phi_z, theta_y,
psi_x]`` with ``R = Rz(phi) Ry(theta) Rx(psi)``, the same numbers as scipy's
``as_euler("ZYX")``.

The derivative of the exponential (``dexp``, ``dexpinv``) is in the *left-trivialised*
form of Iserles, Munthe-Kaas, Nørsett & Zanna (2000): ``d/dt exp(u) = hat(dexp(u) u') exp(u)``.
For the body-frame equation ``X' = X hat(Omega)`` write ``X = X0 exp(u)`` and integrate
``u' = dexpinv(-u) Omega``; see :func:`dexp` and ``docs/rotations.md``.

Every function checks the shape of its arguments (a ValueError names the argument) and
takes a ``scipy.spatial.transform.Rotation`` wherever it takes rotation matrices. Like
NumPy's own functions they do not check the entries: a NaN or inf gives NaN, and so does a
rotation vector past ~1e154 rad (its angle has no digit left modulo 2π). The functions that
must divide by a norm (:func:`quat_normalize` and those that normalise first, :func:`log`)
refuse a quaternion or matrix they cannot normalise.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tumble import _checks

SMALL_ANGLE = 1e-3
"""Below this angle (rad) sin(x)/x is replaced by its Taylor series (error < x**6/5040)."""
SERIES_ANGLE = 0.1
"""Below this angle (rad) the dexp/dexpinv coefficients use their Taylor series."""
GIMBAL_LOCK_TOL = 1e-10
"""cos(theta_y) below which ZYX angles are gimbal-locked (psi_x := 0, error <= this)."""

Array = NDArray[np.float64]


def hat(w: ArrayLike) -> Array:
    """Skew-symmetric matrix of a vector: ``hat(w) @ v == cross(w, v)``.

    Parameters
    ----------
    w : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``[[0, -w3, w2], [w3, 0, -w1], [-w2, w1, 0]]``.

    Examples
    --------
    >>> hat([1.0, 2.0, 3.0]) @ [0.0, 0.0, 1.0]
    array([ 2., -1.,  0.])
    """
    w = _vectors("w", w)
    x, y, z = w[..., 0], w[..., 1], w[..., 2]
    zero = np.zeros_like(x)
    rows = [np.stack(r, axis=-1) for r in ((zero, -z, y), (z, zero, -x), (-y, x, zero))]
    return np.stack(rows, axis=-2)


def vee(W: ArrayLike) -> Array:
    """Vector of the skew-symmetric part of a matrix, the inverse of :func:`hat`.

    Parameters
    ----------
    W : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3)
        ``w`` with ``hat(w) = (W - W^T) / 2``.

    Examples
    --------
    >>> vee(hat([1.0, 2.0, 3.0]))
    array([1., 2., 3.])
    """
    W = _matrices("W", W)
    return 0.5 * np.stack(
        [W[..., 2, 1] - W[..., 1, 2], W[..., 0, 2] - W[..., 2, 0], W[..., 1, 0] - W[..., 0, 1]],
        axis=-1,
    )


def _sinc(x: Array) -> Array:
    """sin(x)/x with the series 1 - x²/6 + x⁴/120 for |x| < SMALL_ANGLE."""
    small = np.abs(x) < SMALL_ANGLE
    safe = np.where(small, 1.0, x)
    return np.where(small, 1.0 - x**2 / 6.0 + x**4 / 120.0, np.sin(safe) / safe)


def exp(w: ArrayLike) -> Array:
    """Rotation matrix of a rotation vector (Rodrigues' formula).

    ``exp(w) = I + (sin t / t) hat(w) + ((1 - cos t) / t²) hat(w)²`` with ``t = |w|``; the
    second coefficient is evaluated as ``(sin(t/2) / t)² · 2`` and both use their Taylor
    series for ``t < SMALL_ANGLE``, so ``exp`` is accurate to round-off at and near 0.

    Parameters
    ----------
    w : array_like, shape (..., 3)
        Rotation vector (rad).

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Examples
    --------
    >>> np.round(exp([0.0, 0.0, np.pi / 2]) @ [1.0, 0.0, 0.0], 12) + 0.0  # x turns to y
    array([0., 1., 0.])
    """
    w = _vectors("w", w)
    t = np.linalg.norm(w, axis=-1)
    a = _sinc(t)[..., None, None]
    b = (0.5 * _sinc(0.5 * t) ** 2)[..., None, None]
    K = hat(w)
    return np.eye(3) + a * K + b * (K @ K)


def log(R: ArrayLike) -> Array:
    """Rotation vector of a rotation matrix, angle in [0, π].

    Computed through the quaternion (Shepperd's method, then ``2 atan2(|v|, w)``), which is
    accurate to round-off near 0 and near π, where ``arccos((tr R - 1) / 2)`` is not. At
    exactly π the sign of the returned vector is arbitrary (both represent ``R``).

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3)
        ``w`` with ``exp(w) == R`` and ``|w| <= π``.

    Examples
    --------
    >>> np.round(log(exp([0.1, -0.2, 0.3])), 12)
    array([ 0.1, -0.2,  0.3])
    """
    R = _matrices("R", R)
    with np.errstate(all="ignore"):
        q = quat_from_matrix(R)
    bad = np.isfinite(q).sum(axis=-1) != 4
    if np.any(bad):  # a NaN or inf in R, or entries past ~1e154 (its trace overflows)
        index = _first(bad)
        raise _checks.fail(_label("R", index), R[index].tolist(), "a rotation matrix, finite")
    return rotvec_from_quat(q)


def _coefficient_b(t: Array) -> Array:
    return 0.5 * _sinc(0.5 * t) ** 2  # (1 - cos t) / t²


def _coefficient_c(t: Array) -> Array:
    """(t - sin t) / t³, series below SERIES_ANGLE (truncation < t¹⁰/6e9)."""
    small = t < SERIES_ANGLE
    safe = np.where(small, 1.0, t)
    t2 = t * t
    series = 1 / 6 - t2 / 120 + t2**2 / 5040 - t2**3 / 362880 + t2**4 / 39916800
    return np.where(small, series, (safe - np.sin(safe)) / safe**3)


def _coefficient_d(t: Array) -> Array:
    """(1 - (t/2) cot(t/2)) / t², series below SERIES_ANGLE (Bernoulli numbers)."""
    small = t < SERIES_ANGLE
    safe = np.where(small, 1.0, t)
    t2 = t * t
    series = 1 / 12 + t2 / 720 + t2**2 / 30240 + t2**3 / 1209600 + t2**4 / 47900160
    direct = 1.0 / safe**2 - (1.0 + np.cos(safe)) / (2.0 * safe * np.sin(safe))
    return np.where(small, series, direct)


def dexp(u: ArrayLike) -> Array:
    """Derivative of the exponential, left-trivialised, as a 3×3 matrix.

    ``dexp(u) = I + ((1 - cos t) / t²) hat(u) + ((t - sin t) / t³) hat(u)²``, ``t = |u|``,
    i.e. ``sum_k ad_u^k / (k+1)!``. For a curve ``u(t)``::

        d/dt exp(u) = hat(dexp(u) @ u') @ exp(u)          (left / spatial)
        exp(u)^T @ d/dt exp(u) = hat(dexp(-u) @ u')       (right / body)

    ``dexp(-u) == dexp(u).T``. Series near ``t = 0``.

    Parameters
    ----------
    u : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Examples
    --------
    >>> np.allclose(dexp([0.3, 0.1, -0.2]) @ dexpinv([0.3, 0.1, -0.2]), np.eye(3))
    True
    """
    u = _vectors("u", u)
    t = np.linalg.norm(u, axis=-1)
    K = hat(u)
    return (
        np.eye(3)
        + _coefficient_b(t)[..., None, None] * K
        + _coefficient_c(t)[..., None, None] * (K @ K)
    )


def dexpinv(u: ArrayLike) -> Array:
    """Inverse of :func:`dexp`, closed form.

    ``dexpinv(u) = I - hat(u) / 2 + ((1 - (t/2) cot(t/2)) / t²) hat(u)²``, ``t = |u|``, i.e.
    ``sum_k B_k ad_u^k / k!`` (Bernoulli numbers). Series near ``t = 0`` (where the last
    coefficient is ``1/12 + t²/720 + ...``); **singular at t = 2π k, k >= 1**, so keep
    ``|u| < 2π`` (RKMK stages have ``|u| ~ h |Omega|``).

    Use in RKMK: for ``X' = hat(Omega) X`` (world), ``X = exp(u) X0`` and
    ``u' = dexpinv(u) @ Omega``; for ``X' = X hat(Omega)`` (body), ``X = X0 exp(u)`` and
    ``u' = dexpinv(-u) @ Omega``.

    Parameters
    ----------
    u : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Examples
    --------
    >>> np.allclose(dexpinv([0.0, 0.0, 0.0]), np.eye(3))
    True
    """
    u = _vectors("u", u)
    K = hat(u)
    return (
        np.eye(3) - 0.5 * K + _coefficient_d(np.linalg.norm(u, axis=-1))[..., None, None] * (K @ K)
    )


def dexpinv_apply(u: ArrayLike, v: ArrayLike) -> Array:
    """``dexpinv(u) @ v`` by cross products: ``v - u×v / 2 + d(t) u×(u×v)``.

    Parameters
    ----------
    u, v : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> u, v = np.array([0.2, -0.1, 0.4]), np.array([1.0, 2.0, 3.0])
    >>> np.allclose(dexpinv_apply(u, v), dexpinv(u) @ v)
    True
    """
    u, v = _pair("u", u, "v", v, (3,), "3-vectors")
    uv = np.cross(u, v)
    return v - 0.5 * uv + _coefficient_d(np.linalg.norm(u, axis=-1))[..., None] * np.cross(u, uv)


def quat_mul(p: ArrayLike, q: ArrayLike) -> Array:
    """Hamilton product ``p ⊗ q`` of scalar-first quaternions.

    ``(p_w q_w - p_v·q_v, p_w q_v + q_w p_v + p_v × q_v)``; then
    ``matrix_from_quat(p ⊗ q) == matrix_from_quat(p) @ matrix_from_quat(q)``.

    Parameters
    ----------
    p, q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 4)

    Examples
    --------
    >>> quat_mul([0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0])  # i j = k
    array([0., 0., 0., 1.])
    """
    p, q = _pair("p", p, "q", q, (4,), "quaternions [w, x, y, z]")
    pw, pv, qw, qv = p[..., :1], p[..., 1:], q[..., :1], q[..., 1:]
    w = pw * qw - np.sum(pv * qv, axis=-1, keepdims=True)
    return np.concatenate([w, pw * qv + qw * pv + np.cross(pv, qv)], axis=-1)


def quat_conj(q: ArrayLike) -> Array:
    """Conjugate ``[w, -x, -y, -z]``, the inverse of a unit quaternion.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 4)

    Examples
    --------
    >>> quat_conj([1.0, 2.0, 3.0, 4.0])
    array([ 1., -2., -3., -4.])
    """
    return _quaternions("q", q) * np.array([1.0, -1.0, -1.0, -1.0])


def quat_normalize(q: ArrayLike, *, name: str = "q") -> Array:
    """Unit quaternion ``q / |q|``.

    Parameters
    ----------
    q : array_like, shape (..., 4)
    name : str
        Argument name used in the error message.

    Returns
    -------
    ndarray, shape (..., 4)

    Raises
    ------
    ValueError
        If any ``q`` has zero or non-finite norm.

    Examples
    --------
    >>> quat_normalize([2.0, 0.0, 0.0, 0.0])
    array([1., 0., 0., 0.])
    """
    q = _quaternions(name, q)
    with np.errstate(over="ignore", invalid="ignore"):
        norm = np.linalg.norm(q, axis=-1, keepdims=True)
    bad = ~np.isfinite(norm[..., 0]) | (norm[..., 0] == 0.0)
    if np.any(bad):  # |q|² past 1.8e308 overflows: the norm again, of q scaled to 1
        with np.errstate(all="ignore"):
            largest = np.max(np.abs(q), axis=-1, keepdims=True)
            norm = np.linalg.norm(q / largest, axis=-1, keepdims=True) * largest
        bad = ~np.isfinite(norm[..., 0]) | (norm[..., 0] == 0.0)
    if np.any(bad):
        index = _first(bad)
        raise _checks.fail(
            _label(name, index),
            q[index].tolist(),
            "a finite quaternion [w, x, y, z] of nonzero norm",
        )
    return q / norm


def matrix_from_quat(q: ArrayLike) -> Array:
    """Rotation matrix of a quaternion ``[w, x, y, z]`` (normalised first).

    ``R = (w² - v·v) I + 2 v vᵀ + 2 w hat(v)``.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Examples
    --------
    >>> np.allclose(matrix_from_quat([np.sqrt(0.5), 0, 0, np.sqrt(0.5)]), exp([0, 0, np.pi / 2]))
    True
    """
    q = quat_normalize(q)
    w, v = q[..., 0, None, None], q[..., 1:]
    outer = v[..., :, None] * v[..., None, :]
    scale = (w * w - np.sum(v * v, axis=-1)[..., None, None]) * np.eye(3)
    return scale + 2.0 * outer + 2.0 * w * hat(v)


def quat_from_matrix(R: ArrayLike) -> Array:
    """Unit quaternion ``[w, x, y, z]`` of a rotation matrix, with ``w >= 0``.

    Shepperd's method: of ``4w², 4x², 4y², 4z²`` (from the trace and the diagonal) pick the
    largest and get the other components from off-diagonal sums and differences, so no
    component is divided by a small number.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 4)

    Examples
    --------
    >>> np.round(quat_from_matrix(np.diag([1.0, -1.0, -1.0])), 12) + 0.0
    array([0., 1., 0., 0.])
    """
    m = np.moveaxis(_matrices("R", R), (-2, -1), (0, 1))  # m[i, j] is R[..., i, j]
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    s01, s02, s12 = m[1, 0] + m[0, 1], m[0, 2] + m[2, 0], m[2, 1] + m[1, 2]
    a21, a02, a10 = m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]
    candidates = np.stack(  # rows are 4w, 4x, 4y, 4z times q
        [
            np.stack([1.0 + trace, a21, a02, a10], axis=-1),
            np.stack([a21, 1.0 + 2 * m[0, 0] - trace, s01, s02], axis=-1),
            np.stack([a02, s01, 1.0 + 2 * m[1, 1] - trace, s12], axis=-1),
            np.stack([a10, s02, s12, 1.0 + 2 * m[2, 2] - trace], axis=-1),
        ],
        axis=-2,
    )
    choice = np.argmax(np.stack([trace, m[0, 0], m[1, 1], m[2, 2]], axis=-1), axis=-1)
    q = np.take_along_axis(candidates, choice[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0.0, -q, q)


def quat_from_rotvec(w: ArrayLike) -> Array:
    """Unit quaternion ``[cos(t/2), sin(t/2) w/t]`` of a rotation vector, ``t = |w|``.

    Parameters
    ----------
    w : array_like, shape (..., 3)
        Rotation vector (rad).

    Returns
    -------
    ndarray, shape (..., 4)

    Examples
    --------
    >>> np.round(quat_from_rotvec([np.pi, 0.0, 0.0]), 12) + 0.0
    array([0., 1., 0., 0.])
    """
    w = _vectors("w", w)
    half = 0.5 * np.linalg.norm(w, axis=-1)
    return np.concatenate([np.cos(half)[..., None], (0.5 * _sinc(half))[..., None] * w], -1)


def rotvec_from_quat(q: ArrayLike) -> Array:
    """Rotation vector of a quaternion, angle ``t = 2 atan2(|v|, |w|)`` in [0, π].

    The sign of ``q`` is chosen so that ``w >= 0``; then ``w_vec = v t / sin(t/2)``.

    Parameters
    ----------
    q : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> np.round(rotvec_from_quat([0.0, 0.0, 1.0, 0.0]), 12)
    array([0.        , 3.14159265, 0.        ])
    """
    q = quat_normalize(q)
    q = np.where(q[..., :1] < 0.0, -q, q)
    v = q[..., 1:]
    t = 2.0 * np.arctan2(np.linalg.norm(v, axis=-1), q[..., 0])
    return (2.0 / _sinc(0.5 * t))[..., None] * v


def matrix_from_euler_zyx(angles: ArrayLike) -> Array:
    """Rotation matrix ``R = Rz(phi) Ry(theta) Rx(psi)`` of ZYX Euler angles.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        ``[phi_z, theta_y, psi_x]`` (rad), as scipy's ``Rotation.from_euler("ZYX", ...)``.

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Examples
    --------
    >>> np.allclose(matrix_from_euler_zyx([0.3, 0.0, 0.0]), exp([0.0, 0.0, 0.3]))
    True
    """
    angles = _vectors("angles", angles, "ZYX angles [phi_z, theta_y, psi_x]")
    e = np.eye(3)
    return (
        exp(angles[..., 0, None] * e[2])
        @ exp(angles[..., 1, None] * e[1])
        @ exp(angles[..., 2, None] * e[0])
    )


def euler_zyx_from_matrix(R: ArrayLike) -> Array:
    """ZYX Euler angles ``[phi_z, theta_y, psi_x]`` with ``R = Rz(phi) Ry(theta) Rx(psi)``.

    Ranges: ``phi, psi`` in [-π, π], ``theta`` in [-π/2, π/2]. ``theta = atan2(-R20,
    hypot(R00, R10))``. Away from gimbal lock ``phi = atan2(R10, R00)``; ``psi`` is then read
    from ``Rz(phi)ᵀ R = Ry(theta) Rx(psi)``, so an error in ``phi`` is compensated and the
    angles reproduce ``R`` to round-off. **Gimbal lock** (``cos theta < GIMBAL_LOCK_TOL``,
    ``theta = ±π/2``): only ``phi ∓ psi`` is defined; we set ``psi = 0`` and
    ``phi = atan2(-R01, R11)``, as scipy's ``as_euler("ZYX")`` does; the angles then
    reproduce ``R`` to within ``cos theta < GIMBAL_LOCK_TOL``.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> np.round(euler_zyx_from_matrix(matrix_from_euler_zyx([0.3, -0.2, 0.1])), 12)
    array([ 0.3, -0.2,  0.1])
    """
    R = _matrices("R", R)
    cos_theta = np.hypot(R[..., 0, 0], R[..., 1, 0])
    locked = cos_theta < GIMBAL_LOCK_TOL
    phi = np.where(
        locked,
        np.arctan2(-R[..., 0, 1], R[..., 1, 1]),
        np.arctan2(R[..., 1, 0], R[..., 0, 0]),
    )
    theta = np.arctan2(-R[..., 2, 0], cos_theta)
    c, s = np.cos(phi), np.sin(phi)
    psi = np.arctan2(s * R[..., 0, 2] - c * R[..., 1, 2], c * R[..., 1, 1] - s * R[..., 0, 1])
    return np.stack([phi, theta, np.where(locked, 0.0, psi)], axis=-1)


def random_rotation(
    rng: np.random.Generator | int | None = None, size: int | tuple[int, ...] = ()
) -> Array:
    """Rotation matrices drawn uniformly (Haar measure) from SO(3).

    A 4-vector of independent standard normals, normalised, is uniform on the unit sphere
    S³, and its rotation is Haar-distributed (Shoemake 1992).

    Parameters
    ----------
    rng : numpy.random.Generator or int or None
        Generator, or seed for ``numpy.random.default_rng``.
    size : int or tuple of int
        Leading shape of the batch; ``()`` for a single matrix.

    Returns
    -------
    ndarray, shape ``(*size, 3, 3)``

    Examples
    --------
    >>> R = random_rotation(np.random.default_rng(0), size=2)
    >>> R.shape, np.allclose(R @ R.swapaxes(-1, -2), np.eye(3))
    ((2, 3, 3), True)
    """
    if not (rng is None or isinstance(rng, np.random.Generator)):
        rng = _checks.count("rng", rng, 0, remedy="a seed, a numpy.random.Generator or None")
    shape = _size(size)
    return matrix_from_quat(np.random.default_rng(rng).standard_normal(shape + (4,)))


def _size(size: object) -> tuple[int, ...]:
    """``size`` of :func:`random_rotation` as a shape: an int or a tuple of ints >= 0, of at
    most :data:`MAX_DRAWS` rotations."""
    allowed = "an int or a tuple of ints >= 0 (the batch's shape)"
    if isinstance(size, bool) or not isinstance(size, int | np.integer | tuple | list):
        raise _checks.fail("size", size, allowed)
    shape = (size,) if isinstance(size, int | np.integer) else tuple(size)
    if not all(isinstance(n, int | np.integer) and not isinstance(n, bool) and n >= 0
               for n in shape):  # fmt: skip
        raise _checks.fail("size", size, allowed)
    if math.prod(shape) > MAX_DRAWS:
        raise _checks.fail("size", size, f"at most {MAX_DRAWS:.3g} rotations in all",
                           remedy="draw them in batches")  # fmt: skip
    return tuple(int(n) for n in shape)


MAX_DRAWS = 10**8
"""The most rotations :func:`random_rotation` draws in one call (7.2 GB of matrices)."""


def validate_rotation(R: ArrayLike, *, name: str = "R", atol: float = 1e-9) -> Array:
    """Check that ``R`` is a rotation matrix and return it as a float array.

    Accepted when ``max |RᵀR - I| <= atol`` and ``det R > 0``.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
    name : str
        Argument name used in the error message.
    atol : float
        Tolerance on the orthogonality defect.

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    ValueError
        Naming ``name``, the defect found and what is allowed.

    Examples
    --------
    >>> validate_rotation(np.eye(3)).shape
    (3, 3)
    """
    R = from_scipy(R, name)
    atol = _checks.non_negative("atol", atol)
    R = _checks.trailing(name, R, (3, 3), "rotation matrices")
    if R.ndim < 2:
        raise _checks.fail(name, R, "of shape (..., 3, 3)", remedy=f"it has shape {R.shape}")
    with np.errstate(all="ignore"):  # NaN or huge entries: refused below, by name
        defect = np.max(np.abs(R.swapaxes(-1, -2) @ R - np.eye(3)), axis=(-2, -1))
        det = np.linalg.det(R)
    bad = ~(defect <= atol) | ~(det > 0.0)  # NaN is bad too
    if np.any(bad):
        index = _first(bad)
        raise _checks.fail(
            _label(name, index),
            R[index].tolist(),
            f"a rotation matrix (R^T R = I within {atol:g}, det R = +1)",
            remedy=f"it has max|R^T R - I| = {defect[index]:.3g}, det R = {det[index]:.6g}; "
            f"re-orthonormalise, e.g. tumble.so3.exp(tumble.so3.log({name}))",
        )
    return R.copy()


def from_scipy(value: Any, name: str, *, quaternion: bool = False, single: bool = False) -> Any:
    """``value`` as an array if it is a ``scipy.spatial.transform.Rotation`` (its matrices,
    or with ``quaternion`` its scalar-first quaternions ``[w, x, y, z]``); anything else as
    it is. ``single``: a Rotation of several rotations is refused, naming ``name``.

    Examples
    --------
    >>> from scipy.spatial.transform import Rotation
    >>> from_scipy(Rotation.from_rotvec([0.0, 0.0, np.pi]), "R0", quaternion=True).round(12)
    array([0., 0., 0., 1.])
    """
    if type(value).__name__ != "Rotation" or not hasattr(value, "as_matrix"):
        return value
    if single and not value.single:
        raise _checks.fail(name, f"<Rotation of {len(value)}>", "a single rotation")
    if quaternion:
        return value.as_quat()[..., [3, 0, 1, 2]]  # scipy's is scalar last
    return value.as_matrix()


def _vectors(name: str, value: ArrayLike, what: str = "3-vectors") -> Array:
    return _checks.trailing(name, value, (3,), what)


def _matrices(name: str, value: ArrayLike) -> Array:
    return _checks.trailing(name, from_scipy(value, name), (3, 3), "3×3 matrices")


def _quaternions(name: str, value: ArrayLike) -> Array:
    return _checks.trailing(name, value, (4,), "quaternions [w, x, y, z]")


def _pair(first: str, a: ArrayLike, second: str, b: ArrayLike, shape: tuple[int, ...],
          what: str) -> tuple[Array, Array]:  # fmt: skip
    """Two arrays of items of ``shape`` whose leading axes broadcast together."""
    a, b = _checks.trailing(first, a, shape, what), _checks.trailing(second, b, shape, what)
    if a.shape[:-1] != b.shape[:-1]:
        try:
            np.broadcast_shapes(a.shape[:-1], b.shape[:-1])
        except ValueError:
            raise _checks.fail(second, b.tolist(), f"{what} whose batch shape broadcasts with "
                               f"{first}'s, {a.shape[:-1]}", remedy=f"it has {b.shape[:-1]}"
                               ) from None  # fmt: skip
    return a, b


def _first(bad: NDArray[np.bool_]) -> tuple[int, ...]:
    """Index of the first True in ``bad`` (``()`` for a 0-d array)."""
    return tuple(int(i) for i in np.argwhere(bad)[0])


def _label(name: str, index: tuple[int, ...]) -> str:
    """``name`` or ``name[i, j]``: which item of a batch an error is about."""
    return f"{name}[{', '.join(map(str, index))}]" if index else name
