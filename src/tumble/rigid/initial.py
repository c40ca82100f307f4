"""Checking ``simulate``'s arguments and building the initial state."""

from __future__ import annotations

import warnings

import numpy as np

from tumble import _checks, so3
from tumble.ode.control import relative_tolerance
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


def check_steps(method: Method, h, rtol, atol) -> tuple[float | None, float, np.ndarray | None]:
    """The step for fixed-step methods, the tolerances for the adaptive ones (``atol`` None
    when not given: :func:`tolerances` derives it from the body)."""
    if h is not None:
        h = _checks.positive("h", h, "s")
    if not method.adaptive:
        if h is None:
            raise _checks.fail(
                "h",
                None,
                f"a step > 0 for the fixed-step method {method.name!r}",
                "s",
                f"or an adaptive method ({adaptive_names()}) with rtol",
            )
        if rtol is not None or atol is not None:
            name, value = ("rtol", rtol) if rtol is not None else ("atol", atol)
            raise _checks.fail(
                name,
                value,
                f"None for the fixed-step method {method.name!r}",
                remedy=f"tolerances apply only to the adaptive methods ({adaptive_names()}); "
                f"{method.name!r} takes a fixed step h",
            )
        return h, 0.0, None
    rtol = relative_tolerance(DEFAULT_RTOL if rtol is None else rtol)
    if atol is None:
        return h, rtol, None
    checked = _checks.array("atol", atol)
    if checked.shape not in ((), (9,)) or np.any(checked < 0):
        raise _checks.fail(
            "atol", atol, ">= 0 and finite: a scalar, or shape (9,) for (x, p, L)",
            "m, kg m/s, kg m²/s",
            remedy="atol applies to x, p and L (L's components in the body frame); the "
            "attitude is measured against rtol alone",
        )  # fmt: skip
    return h, rtol, np.broadcast_to(checked, (9,)).copy()


DEFAULT_RTOL = 1e-6
"""``rtol`` of the adaptive methods when none is given."""


def adaptive_names() -> str:
    """The adaptive methods, for messages."""
    from tumble.rigid.methods import METHODS

    return ", ".join(repr(name) for name, m in METHODS.items() if m.adaptive)


def sizes(body: RigidBody, Y: np.ndarray, span: float) -> np.ndarray:
    """Characteristic sizes of ``(x, p, L)``, shape (9,): each part's initial size, and at
    least one radius of gyration ``ℓ = √(tr I / m)`` for x, ``m ℓ / T`` for p and ``m ℓ² / T``
    for L (a gyration radius, or a radian, over the run's length ``T``). ``|L|`` is the same
    in the world and the body frame, where the error norm measures L's components."""
    m = body.mass
    ell = float(np.sqrt(np.trace(body.inertia) / m))
    floors = (ell, m * ell / span, m * ell * ell / span)
    parts = [max(float(np.abs(Y[3 * g : 3 * g + 3]).max()), floors[g]) for g in range(3)]
    return np.repeat(parts, 3)


def tolerances(body: RigidBody, Y: np.ndarray, span: float, rtol: float, atol) -> np.ndarray:
    """``atol`` for ``(x, p, L)``, shape (9,): by default ``rtol`` times their characteristic
    sizes (:func:`sizes`), so that a tighter ``rtol`` tightens every part. A given ``atol``
    larger than that for every part makes ``rtol`` meaningless for them: a UserWarning says so.
    """
    scale = sizes(body, Y, span)
    if atol is None:
        return rtol * scale
    if np.all(atol > rtol * scale):
        warnings.warn(
            f"atol={atol.max():.3g} exceeds rtol={rtol:.3g} times the sizes of x, p and L "
            f"({scale[0]:.3g} m, {scale[3]:.3g} kg m/s, {scale[6]:.3g} kg m²/s): atol, not rtol, "
            "sets their accuracy; leave atol unset to scale it with rtol",
            UserWarning,
            stacklevel=3,
        )
    return atol


_IDENTITY = np.eye(3)


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
        return _IDENTITY.copy()  # a third of np.eye(3)'s cost
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
