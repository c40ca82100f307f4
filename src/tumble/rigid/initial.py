"""Checking ``simulate``'s arguments and building the initial state."""

from __future__ import annotations

import math

import numpy as np

from tumble import so3
from tumble.rigid.body import RigidBody
from tumble.rigid.methods import Method


def _vector(value, name: str, default=(0.0, 0.0, 0.0)) -> np.ndarray:
    array = np.asarray(default if value is None else value, dtype=float)
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        raise ValueError(f"{name}={value!r} must be 3 finite numbers")
    return array


def check_times(t0: float, t_end: float) -> tuple[float, float]:
    """``t0`` and ``t_end`` finite with ``t_end > t0``."""
    if not (np.isscalar(t0) and math.isfinite(t0)):
        raise ValueError(f"t0={t0!r} must be a finite number (s)")
    if not (np.isscalar(t_end) and math.isfinite(t_end) and t_end > t0):
        raise ValueError(f"t_end={t_end!r} is not allowed: it must be finite and > t0={t0!r}")
    return float(t0), float(t_end)


def check_steps(method: Method, h, rtol, atol) -> tuple[float | None, float, float]:
    """The step for fixed-step methods, the tolerances for the adaptive one."""
    if h is not None and not (np.isscalar(h) and math.isfinite(h) and h > 0):
        raise ValueError(f"h={h!r} is not allowed: the step must be finite and > 0 (s)")
    if not method.adaptive:
        if h is None:
            raise ValueError(
                f"h=None is not allowed for the fixed-step method {method.name!r}: give h > 0 "
                "(s), or use method='rkmk45' with rtol"
            )
        if rtol is not None or atol is not None:
            raise ValueError(
                f"rtol={rtol!r}, atol={atol!r}: tolerances apply only to method='rkmk45'; "
                f"{method.name!r} takes a fixed step h"
            )
        return float(h), 0.0, 0.0
    rtol = 1e-6 if rtol is None else rtol
    atol = 1e-9 if atol is None else atol
    if not (np.isscalar(rtol) and math.isfinite(rtol) and rtol > 0):
        raise ValueError(f"rtol={rtol!r} is not allowed: it must be finite and > 0")
    if not (np.isscalar(atol) and math.isfinite(atol) and atol >= 0):
        raise ValueError(f"atol={atol!r} is not allowed: it must be finite and ≥ 0")
    return (None if h is None else float(h)), float(rtol), float(atol)


def initial_attitude(R0, q0) -> np.ndarray:
    """R0 (checked to be a rotation) or R from q0 (normalised; zero norm refused)."""
    if R0 is not None and q0 is not None:
        raise ValueError("give at most one of R0 and q0 (both describe the initial attitude)")
    if q0 is not None:
        q = np.asarray(q0, dtype=float)
        if q.shape != (4,) or not np.all(np.isfinite(q)) or np.linalg.norm(q) == 0:
            raise ValueError(
                f"q0={q0!r} is not allowed: a quaternion [w, x, y, z] of finite, non-zero norm"
            )
        return so3.matrix_from_quat(q / np.linalg.norm(q))
    if R0 is None:
        return np.eye(3)
    R = np.asarray(R0, dtype=float)
    if R.shape != (3, 3) or not np.all(np.isfinite(R)):
        raise ValueError(f"R0={R0!r} must be a finite 3×3 rotation matrix")
    return so3.validate_rotation(R, name="R0", atol=1e-9)


def initial_state(body: RigidBody, x0, v0, R0, q0, omega0, L0):
    """``(R, Y)`` with ``Y = (x, p, L)``; ``L0 = R0 I ω0`` when ``omega0`` is given."""
    if not isinstance(body, RigidBody):
        raise ValueError(f"body={body!r} must be a tumble.RigidBody")
    if omega0 is not None and L0 is not None:
        raise ValueError(
            "give at most one of omega0 (body-frame angular velocity) and L0 (world angular "
            "momentum); they describe the same thing"
        )
    R = initial_attitude(R0, q0)
    if L0 is not None:
        L = _vector(L0, "L0")
    else:
        L = R @ (body.inertia @ _vector(omega0, "omega0"))
    x, v = _vector(x0, "x0"), _vector(v0, "v0")
    return R, np.concatenate([x, body.mass * v, L])
