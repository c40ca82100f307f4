"""Checking ``simulate``'s arguments and building the initial state."""

from __future__ import annotations

import numpy as np

from tumble import _checks, so3
from tumble.rigid.body import RigidBody
from tumble.rigid.methods import Method


def _vector(value, name: str, unit: str) -> np.ndarray:
    """A 3-vector argument [unit], zero when not given."""
    return np.zeros(3) if value is None else _checks.array(name, value, shape=(3,), unit=unit)


def check_times(t0: float, t_end: float) -> tuple[float, float]:
    """``t0`` and ``t_end`` finite with ``t_end > t0``."""
    t0 = _checks.finite("t0", t0, "s")
    if _checks.finite("t_end", t_end, "s") <= t0:
        raise _checks.fail("t_end", t_end, f"> t0={t0!r}", "s")
    return t0, float(t_end)


def check_steps(method: Method, h, rtol, atol) -> tuple[float | None, float, float]:
    """The step for fixed-step methods, the tolerances for the adaptive one."""
    if h is not None:
        h = _checks.positive("h", h, "s")
    if not method.adaptive:
        if h is None:
            raise _checks.fail(
                "h",
                None,
                f"a step > 0 for the fixed-step method {method.name!r}",
                "s",
                "or use method='rkmk45' with rtol",
            )
        if rtol is not None or atol is not None:
            name, value = ("rtol", rtol) if rtol is not None else ("atol", atol)
            raise _checks.fail(
                name,
                value,
                f"None for the fixed-step method {method.name!r}",
                remedy="tolerances apply only to method='rkmk45'; "
                f"{method.name!r} takes a fixed step h",
            )
        return h, 0.0, 0.0
    rtol = _checks.positive("rtol", 1e-6 if rtol is None else rtol)
    atol = _checks.non_negative("atol", 1e-9 if atol is None else atol)
    return h, rtol, atol


def initial_attitude(R0, q0) -> np.ndarray:
    """R0 (checked to be a rotation; a single ``scipy.spatial.transform.Rotation`` is taken
    as its matrix) or R from q0 (normalised; zero norm refused)."""
    if R0 is not None and type(R0).__name__ == "Rotation" and hasattr(R0, "as_matrix"):
        if not R0.single:
            raise _checks.fail("R0", f"<Rotation of {len(R0)}>", "a single rotation")
        R0 = R0.as_matrix()
    if R0 is not None and q0 is not None:
        raise _checks.fail(
            "q0",
            q0,
            "None when R0 is given",
            remedy="give at most one of R0 and q0 (both describe the initial attitude)",
        )
    if q0 is not None:
        q = _checks.array("q0", q0, shape=(4,))
        return so3.matrix_from_quat(so3.quat_normalize(q, name="q0"))
    if R0 is None:
        return np.eye(3)
    R = _checks.array("R0", R0, shape=(3, 3))
    return so3.validate_rotation(R, name="R0", atol=1e-9)


def initial_state(body: RigidBody, x0, v0, R0, q0, omega0, L0):
    """``(R, Y)`` with ``Y = (x, p, L)``; ``L0 = R0 I ω0`` when ``omega0`` is given."""
    if not isinstance(body, RigidBody):
        raise _checks.fail("body", body, "a tumble.RigidBody")
    if omega0 is not None and L0 is not None:
        raise _checks.fail(
            "L0",
            L0,
            "None when omega0 is given",
            remedy="give at most one of omega0 (body-frame angular velocity) and L0 (world "
            "angular momentum); they describe the same thing",
        )
    R = initial_attitude(R0, q0)
    if L0 is not None:
        L = _vector(L0, "L0", "kg m²/s")
    else:
        L = R @ (body.inertia @ _vector(omega0, "omega0", "rad/s"))
    x, v = _vector(x0, "x0", "m"), _vector(v0, "v0", "m/s")
    return R, np.concatenate([x, body.mass * v, L])
