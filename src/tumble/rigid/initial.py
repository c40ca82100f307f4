"""Checking ``simulate``'s arguments and building the initial state."""

from __future__ import annotations

import math
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
    if not rtol < 1:
        raise _checks.fail("rtol", rtol, "< 1", remedy="a relative tolerance of 100 % or more "
                           "bounds nothing (the attitude's error is in radians)")  # fmt: skip
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

MAX_TURN = 1.0
"""The rotation per step ``h |ω|`` (rad) above which :func:`warn_large_step` warns."""
LargeStepWarning = _checks.LargeStepWarning
"""The category of :func:`warn_large_step`'s warning (a UserWarning)."""
MAX_RECORD_EVERY = 2**62
"""``record_every`` is held to this (the compiled loops count steps in int64): larger keeps
only the first and the last record, as this does."""


def check_record_every(value: object) -> int:
    """``record_every`` checked (an integer >= 1), and held to :data:`MAX_RECORD_EVERY`."""
    return min(_checks.count("record_every", value), MAX_RECORD_EVERY)


def warn_large_step(method: Method, h, span: float, inertia_inverse, R, L) -> None:
    """A UserWarning when a fixed step turns a body by more than :data:`MAX_TURN` radians.

    ``h |ω|`` with ``ω = I⁻¹ Rᵀ L`` at the start (shapes (3, 3), (3,) for one body; a leading
    body axis for a batch, whose fastest body counts), the step at most the run's ``span``.
    The charts, splittings and Crouch–Grossman methods resolve a turn of well under a radian
    a step: past one their error is of the order of the motion itself (``rkmk4`` at 10 rad a
    step: 35 % of the energy), with no NaN to stop the run. The adaptive methods choose their
    own steps, and the exact flow (``exact``, ``strang``, ``yoshida4``) turns the free body
    exactly whatever the step: no warning for them.
    """
    if h is None or method.adaptive or method.flow == "exact":
        return
    step = min(h, span)
    if L.ndim == 1:  # one body: |ω| <= tr(I⁻¹) |L| (R a rotation), a 1 µs screen
        inverse = inertia_inverse
        bound = (inverse.item(0) + inverse.item(4) + inverse.item(8)) * math.hypot(*L.tolist())
        if step * bound <= MAX_TURN:
            return
    with np.errstate(over="ignore", invalid="ignore"):
        omega = inertia_inverse @ (np.swapaxes(R, -1, -2) @ L[..., None])
        spin = float(np.max(np.sqrt(np.sum(omega * omega, axis=(-2, -1)))))
    if not step * spin > MAX_TURN or not np.isfinite(spin):  # inf: the overflow check says
        return
    warnings.warn(
        f"h={h!r} s turns the body by h|ω| = {step * spin:.3g} rad a step (|ω| = {spin:.3g} "
        f"rad/s at the start), more than the {MAX_TURN:g} rad that method={method.name!r} "
        f"resolves: the result is not accurate, though it may look fine; take "
        f"h <= {MAX_TURN / spin:.3g} s, or an adaptive method ({adaptive_names()})",
        LargeStepWarning,
        stacklevel=3,
    )


def finite_event(event, index: int):
    """The user's event ``g(t, state)``, its value checked at each call: a real number, not
    NaN (a NaN never changes sign, so the event would silently never fire). ``terminal`` and
    ``direction`` are kept."""

    def g(t: float, state) -> float:
        value = event(t, state)
        try:
            number = float(value)
        except (TypeError, ValueError):
            number = None
        if number is None or number != number:
            raise _checks.fail(
                f"events[{index}]", event, "a function g(t, state) returning a real number",
                remedy=f"it returned {value!r} at t={t!r}: an event fires where g changes sign, "
                "and a NaN never does",
            )  # fmt: skip
        return number

    g.terminal = getattr(event, "terminal", False)  # type: ignore[attr-defined]
    g.direction = getattr(event, "direction", 0)  # type: ignore[attr-defined]
    return g


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
    """R0 (checked to be a rotation) or R from q0 (normalised; zero norm refused); a single
    ``scipy.spatial.transform.Rotation`` is taken for either."""
    R0 = so3.from_scipy(R0, "R0", single=True)
    q0 = so3.from_scipy(q0, "q0", quaternion=True, single=True)
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
    L = None if L0 is None else _vector(L0, "L0", "kg m²/s")
    omega = _vector(omega0, "omega0", "rad/s") if L0 is None else None
    x, v = _vector(x0, "x0", "m"), _vector(v0, "v0", "m/s")
    with np.errstate(over="ignore", invalid="ignore"):  # too large a spin: a status, later
        if L is None:
            L = R @ (body.inertia @ omega)
        return R, np.concatenate([x, body.mass * v, L])
