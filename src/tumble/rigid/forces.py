"""Forces and torques on a rigid body, in the world frame.

Continuous loads (:class:`Gravity`, :class:`Force`, :class:`Torque`, :class:`MagneticDipole`,
:class:`GravityGradient`) give a force ``F`` on the centre of mass and a torque ``τ`` about it
at every instant; :class:`Impulse` is a kick at one instant. A load that is a constant (not a
callable) can run in the compiled kernels; a callable runs in Python.

Each load's ``__call__(t, state, mass)`` returns ``(F, τ)``; ``state`` is a :class:`State`.
A load that derives from a potential also has ``potential(x, R, mass) -> V`` (vectorised over
samples: ``x`` (n, 3), ``R`` (n, 3, 3)), with ``F = −∂V/∂x`` and ``τ`` the matching torque;
a :class:`~tumble.Trajectory` reports ``potential_energy`` and the total ``energy`` from it.
:class:`GravityGradient` also needs the body's inertia: :func:`for_body` gives it the body's,
which ``simulate`` and ``simulate_batch`` do before they run.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks


class State(NamedTuple):
    """The rigid-body state at one instant, as user callables receive it.

    Attributes
    ----------
    x : ndarray, shape (3,)
        Centre of mass (m, world).
    R : ndarray, shape (3, 3)
        Attitude, body to world.
    p : ndarray, shape (3,)
        Linear momentum (kg m/s, world).
    L : ndarray, shape (3,)
        Angular momentum about the centre of mass (kg m²/s, world).
    omega : ndarray, shape (3,), optional
        Body-frame angular velocity ``I⁻¹ Rᵀ L`` (rad/s): given to events and
        ``Trajectory.sol``, None for loads.
    q : ndarray, shape (4,), optional
        The attitude as a unit quaternion ``[w, x, y, z]``: given to events and
        ``Trajectory.sol``, None for loads.
    """

    x: np.ndarray
    R: np.ndarray
    p: np.ndarray
    L: np.ndarray
    omega: np.ndarray | None = None
    q: np.ndarray | None = None


Vector = Any
"""array_like, shape (3,), when a load is made; a read-only float ndarray (3,) once it is
(``__post_init__`` converts and checks it)."""

VectorOrCallable = Any
"""A :data:`Vector`, or a callable ``f(t, state) -> array_like (3,)`` (kept as it is)."""
_ZERO = np.zeros(3)


def _vector(value: ArrayLike, name: str, unit: str) -> np.ndarray:
    return _checks.array(name, value, shape=(3,), unit=unit)


def _vector_or_callable(value: VectorOrCallable, name: str, unit: str):
    return value if callable(value) else _vector(value, name, unit)


def _evaluate(value, t: float, state: State, name: str) -> np.ndarray:
    if not callable(value):
        return value
    result = np.asarray(value(t, state), dtype=float)
    if result.shape != (3,):
        raise _checks.fail(f"{name}(t, state)", result, "of shape (3,)")
    return result


@dataclass(frozen=True)
class Gravity:
    """Uniform gravity: ``F = m g`` on the centre of mass, no torque.

    Parameters
    ----------
    g : array_like, shape (3,)
        Gravitational acceleration (m/s², world); default ``(0, 0, -9.81)``.
    """

    g: Vector = (0.0, 0.0, -9.81)

    def __post_init__(self) -> None:
        object.__setattr__(self, "g", _vector(self.g, "g", "m/s²"))

    compiled = True
    conservative = True

    def __call__(self, t: float, state: State, mass: float) -> tuple[np.ndarray, np.ndarray]:
        return mass * self.g, _ZERO

    def potential(self, x: np.ndarray, R: np.ndarray, mass: float) -> np.ndarray:
        """``V = −m g·x`` (J)."""
        return -mass * (x @ self.g)


@dataclass(frozen=True)
class Force:
    """A force, constant or ``force(t, state)``, at a point fixed on the body.

    Parameters
    ----------
    force : array_like, shape (3,), or callable
        The force in N, world frame.
    point : array_like, shape (3,), optional
        Where it acts, in body coordinates relative to the centre of mass (m); it turns with
        the body. Omitted: at the centre of mass (no torque). The torque is
        ``τ = (R point) × F``.
    """

    force: VectorOrCallable
    point: Vector | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "force", _vector_or_callable(self.force, "force", "N"))
        if self.point is not None:
            object.__setattr__(self, "point", _vector(self.point, "point", "m"))

    @property
    def compiled(self) -> bool:
        return not callable(self.force)

    def __call__(self, t: float, state: State, mass: float) -> tuple[np.ndarray, np.ndarray]:
        F = _evaluate(self.force, t, state, "force")
        if self.point is None:
            return F, _ZERO
        return F, np.cross(state.R @ self.point, F)

    @property
    def conservative(self) -> bool:
        """A constant force has the potential ``V = −F·(x + R r)``; a callable has none."""
        return not callable(self.force)

    def potential(self, x: np.ndarray, R: np.ndarray, mass: float) -> np.ndarray:
        """``V = −F·(x + R r)`` (J), ``r`` the point (0 at the centre of mass)."""
        where = x if self.point is None else x + R @ self.point
        return -(where @ self.force)


@dataclass(frozen=True)
class Torque:
    """A pure torque about the centre of mass, constant or ``torque(t, state)`` (N m, world)."""

    torque: VectorOrCallable

    def __post_init__(self) -> None:
        object.__setattr__(self, "torque", _vector_or_callable(self.torque, "torque", "N m"))

    @property
    def compiled(self) -> bool:
        return not callable(self.torque)

    conservative = False
    """A torque has no potential on SO(3) in general (a constant one neither)."""

    def __call__(self, t: float, state: State, mass: float) -> tuple[np.ndarray, np.ndarray]:
        return _ZERO, _evaluate(self.torque, t, state, "torque")


@dataclass(frozen=True)
class MagneticDipole:
    """A body-fixed magnetic dipole in a uniform field: a compass needle, a magnetorquer.

    The torque is ``τ = (R μ) × B`` and the potential ``V = −(R μ)·B``; a uniform field
    exerts no force. The load derives from a potential, so the splitting methods
    (``split-axes``, ``split-axes4``, …) keep the total energy ``T + V`` bounded.

    Parameters
    ----------
    moment : array_like, shape (3,)
        The magnetic moment ``μ`` in body axes (A m²).
    field : array_like, shape (3,)
        The flux density ``B`` in world axes (T).

    Examples
    --------
    >>> import numpy as np
    >>> needle = MagneticDipole(moment=(1.0, 0.0, 0.0), field=(0.0, 2.0, 0.0))
    >>> R = np.eye(3)
    >>> needle(0.0, State(np.zeros(3), R, np.zeros(3), np.zeros(3)), 1.0)[1]
    array([0., 0., 2.])
    """

    moment: Vector
    field: Vector

    def __post_init__(self) -> None:
        object.__setattr__(self, "moment", _vector(self.moment, "moment", "A m²"))
        object.__setattr__(self, "field", _vector(self.field, "field", "T"))

    compiled = True
    conservative = True

    def __call__(self, t: float, state: State, mass: float) -> tuple[np.ndarray, np.ndarray]:
        return _ZERO, np.cross(state.R @ self.moment, self.field)

    def potential(self, x: np.ndarray, R: np.ndarray, mass: float) -> np.ndarray:
        """``V = −(R μ)·B`` (J)."""
        return -((R @ self.moment) @ self.field)


GM_EARTH = 3.986004418e14
"""The Earth's gravitational parameter ``μ = GM`` (m³/s²), atmosphere included: WGS 84
(NIMA TR8350.2, 3rd ed., 2000) and the IERS Conventions (2010)."""


@dataclass(frozen=True)
class GravityGradient:
    """The gravity of a point mass on an extended body: Kepler's force on the centre of mass,
    the gravity-gradient torque, and the potential of both, to second order in the body's
    size over its distance.

    With ``r = x − c`` from the attracting centre ``c`` to the centre of mass (``r = |r|``,
    ``r̂ = r/r``), ``μ = GM``, the body's mass ``m`` and its inertia in world axes
    ``I_w = R I Rᵀ``, the potential is MacCullagh's formula, the expansion of
    ``−μ ∫ dm/|r + ρ|`` to second order in ``ρ/r`` (the first-order term vanishes about the
    centre of mass),

    .. math::

        V = -\\frac{\\mu m}{r}
            - \\frac{\\mu}{2 r^3}\\bigl(\\operatorname{tr} I - 3\\,\\hat r^T I_w \\hat r\\bigr),

    and the load is its gradient, so that ``F = −∂V/∂x`` and ``τ`` is minus V's derivative
    along a rotation, exactly:

    .. math::

        \\tau = \\frac{3\\mu}{r^5}\\, r \\times I_w r, \\qquad
        F = -\\frac{\\mu m}{r^3} r - \\frac{3\\mu}{r^5}
            \\Bigl[\\bigl(\\tfrac12 \\operatorname{tr} I
            - \\tfrac52\\,\\hat r^T I_w \\hat r\\bigr) r + I_w r\\Bigr].

    The force's second term (of relative size ``I/(m r²)``, 1e-15 for a cubesat in low Earth
    orbit) is the gradient of V's second-order term: with it F and τ come from the same V,
    so the splitting methods (``strang``, ``yoshida4``, ``split-axes``, …), whose kicks are
    then exact flows of V, keep ``T + V`` bounded, and :attr:`Trajectory.energy
    <tumble.rigid.trajectory.Trajectory.energy>` includes V. Terms of third order in
    ``ρ/r`` (the body's octupole) are left out, in V, F and τ alike.

    Parameters
    ----------
    mu : float
        The attracting body's ``GM`` (m³/s², > 0); default the Earth's, :data:`GM_EARTH`.
    centre : array_like, shape (3,)
        Where the point mass is (m, world); default the origin.
    inertia : array_like, shape (3, 3) or (3,), optional
        The inertia of the body the load acts on (kg m², body axes, about the centre of
        mass; a (3,) array is the diagonal). None (the default): ``simulate`` and
        ``simulate_batch`` give it the body's (:func:`for_body`); one given must be that.

    References
    ----------
    .. [1] P. C. Hughes, *Spacecraft Attitude Dynamics*, Wiley 1986 (Dover 2004), ch. 8: the
       gravitational potential, force and torque of a body expanded in its size over its
       distance.
    .. [2] H. Schaub, J. L. Junkins, *Analytical Mechanics of Space Systems*, 4th ed., AIAA
       2018, ch. 4: the gravity-gradient torque and the net gravitational force on a
       spacecraft to first order beyond the point mass.

    Examples
    --------
    A dumbbell-like body along world x, its centre of mass on the x axis: no torque (it
    points at the centre), and the force is Kepler's (-0.25) and the gradient term (-0.1875):

    >>> import numpy as np
    >>> load = GravityGradient(mu=1.0, inertia=(0.0001, 1.0, 1.0))
    >>> F, tau = load(0.0, State(np.array([2.0, 0.0, 0.0]), np.eye(3), np.zeros(3),
    ...                           np.zeros(3)), 1.0)
    >>> tau.tolist(), round(float(F[0]), 6)
    ([0.0, 0.0, 0.0], -0.437481)
    """

    mu: float = GM_EARTH
    centre: Vector = (0.0, 0.0, 0.0)
    inertia: Vector | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "mu", _checks.positive("mu", self.mu, "m³/s²"))
        object.__setattr__(self, "centre", _vector(self.centre, "centre", "m"))
        if self.inertia is not None:
            object.__setattr__(self, "inertia", _inertia(self.inertia))

    compiled = True
    conservative = True

    def _body_inertia(self) -> np.ndarray:
        if self.inertia is None:
            raise _checks.fail(
                "GravityGradient.inertia", None, "the body's inertia here",
                remedy="simulate and simulate_batch fill it in; to evaluate the load "
                "yourself, give GravityGradient(inertia=body.inertia)",
            )  # fmt: skip
        return self.inertia

    def __call__(self, t: float, state: State, mass: float) -> tuple[np.ndarray, np.ndarray]:
        inertia = self._body_inertia()
        r = state.x - self.centre
        s = state.R.T @ r  # r in body axes
        y = inertia @ s
        w = state.R @ y  # I_w r
        r2 = r @ r
        distance = np.sqrt(r2)
        k = 3.0 * self.mu / (r2 * r2 * distance)  # 3μ/r⁵
        radial = 0.5 * np.trace(inertia) - 2.5 * (s @ y) / r2
        F = -(self.mu * mass / (r2 * distance)) * r - k * (radial * r + w)
        torque = [r[1] * w[2] - r[2] * w[1], r[2] * w[0] - r[0] * w[2], r[0] * w[1] - r[1] * w[0]]
        return F, k * np.array(torque)  # r × I_w r (np.cross costs 5 µs)

    def potential(self, x: np.ndarray, R: np.ndarray, mass: float) -> np.ndarray:
        """MacCullagh's ``V`` (J; class docstring) at samples ``x`` (..., 3), ``R``
        (..., 3, 3)."""
        I = self._body_inertia()
        r = [x[..., c] - self.centre[c] for c in range(3)]
        # written out term by term (no reductions): the same bits for one body and for a
        # batch's stacked inertias, whatever the broadcast
        s = [R[..., 0, c] * r[0] + R[..., 1, c] * r[1] + R[..., 2, c] * r[2] for c in range(3)]
        y = [I[..., c, 0] * s[0] + I[..., c, 1] * s[1] + I[..., c, 2] * s[2] for c in range(3)]
        sIs = s[0] * y[0] + s[1] * y[1] + s[2] * y[2]
        r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
        distance = np.sqrt(r2)
        trace = I[..., 0, 0] + I[..., 1, 1] + I[..., 2, 2]
        return -self.mu * mass / distance - self.mu / (2.0 * r2 * distance) * (
            trace - 3.0 * sIs / r2
        )


def _inertia(value) -> np.ndarray:
    """A load's inertia (3, 3) from (3, 3) or its diagonal (3,): symmetric, positive definite."""
    from tumble.mass import validate_inertia

    inertia = np.asarray(value, dtype=float) if np.ndim(value) == 1 else value
    if np.shape(inertia) == (3,):
        inertia = np.diag(inertia)
    checked = validate_inertia(inertia, name="inertia", allow_unphysical=True)
    checked.setflags(write=False)
    return checked


def for_body(loads, inertia: np.ndarray) -> list:
    """``loads`` as they act on a body of inertia ``inertia`` (3, 3): each
    :class:`GravityGradient` without one gets it; the other loads are as they are.

    ``inertia`` may carry leading axes that broadcast against the samples' (a batch's
    bodies, for :func:`potential_energy`), as ``mass`` does there.

    Raises
    ------
    ValueError
        For a GravityGradient given another inertia than the body's.
    """
    bound = []
    for load in loads:
        if isinstance(load, GravityGradient):
            if load.inertia is None:
                load = dataclasses.replace(load)
                object.__setattr__(load, "inertia", inertia)
            elif not np.all(load.inertia == inertia):
                raise _checks.fail(
                    "GravityGradient.inertia", load.inertia.tolist(),
                    "None or the inertia of the body it acts on", "kg m²",
                    remedy="leave it out: simulate gives the load the body's",
                )  # fmt: skip
        bound.append(load)
    return bound


@dataclass(frozen=True)
class Impulse:
    """An instantaneous kick ``J`` (N s) at a world point, applied exactly at ``time``.

    ``Δp = J`` and ``ΔL = (point − x_cm) × J``, with the full impulse (seed 001 projected it
    for display; tumble does not). Seed 001's hit from ``f0`` to the vertex ``f1`` over ``Δt``
    is ``Impulse(point=f1, impulse=(f1 − f0)·Δt)``.

    Parameters
    ----------
    point : array_like, shape (3,)
        Where the impulse acts, world coordinates at ``time`` (m).
    impulse : array_like, shape (3,)
        ``J = F Δt`` in N s, world frame.
    time : float
        When (s); the integration lands a step on it.
    """

    point: Vector
    impulse: Vector
    time: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _vector(self.point, "point", "m"))
        object.__setattr__(self, "impulse", _vector(self.impulse, "impulse", "N s"))
        _checks.finite("time", self.time, "s")

    def kick(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(Δp, ΔL)`` for a body whose centre of mass is at ``x``."""
        return self.impulse.copy(), np.cross(self.point - x, self.impulse)


Load = Gravity | Force | Torque | MagneticDipole | GravityGradient


def split_loads(forces) -> tuple[list[Load], list[Impulse]]:
    """Separate continuous loads from impulses, checking each item's type."""
    loads, impulses = [], []
    for index, item in enumerate(forces):
        if isinstance(item, Impulse):
            impulses.append(item)
        elif isinstance(item, Gravity | Force | Torque | MagneticDipole | GravityGradient):
            loads.append(item)
        else:
            raise _checks.fail(
                f"forces[{index}]",
                item,
                "a load: tumble.Gravity, tumble.Force, tumble.Torque, tumble.MagneticDipole, "
                "tumble.GravityGradient or tumble.Impulse",
            )
    return loads, impulses


def total_load(loads, t: float, state: State, mass: float) -> tuple[np.ndarray, np.ndarray]:
    """Sum of the continuous loads: ``(F, τ)`` in the world frame."""
    F, tau = np.zeros(3), np.zeros(3)
    for load in loads:
        dF, dtau = load(t, state, mass)
        F = F + dF
        tau = tau + dtau
    return F, tau


def potential_energy(loads, x: np.ndarray, R: np.ndarray, mass: float | np.ndarray) -> np.ndarray:
    """``V`` of the loads that have a potential, summed, at samples ``x`` (..., 3), ``R``
    (..., 3, 3); shape (...), J. Loads without one (:class:`Torque`, callables) add nothing.
    ``mass`` may be an array that broadcasts against the leading axes (a batch's bodies).
    A state that blew up gives inf or nan without a warning: the run's status reports it."""
    V = np.zeros(np.shape(x)[:-1])
    conservative = [load for load in loads if load.conservative]
    if conservative:  # numpy's error state only when there is work (a short run's µs)
        with np.errstate(over="ignore", invalid="ignore"):
            for load in conservative:
                V = V + load.potential(x, R, mass)
    return V


def compiled_loads(loads, mass: float):
    """Constant loads as arrays for the kernels, or None if any load is a callable.

    A magnetic dipole ``μ`` in the field ``B`` has the torque ``(R μ) × B`` of a force ``B``
    at the body point ``μ``: it is listed among the points, with ``B`` taken off the force
    on the centre of mass (a uniform field exerts none). The kernels' load loop stays one
    loop. A :class:`GravityGradient` is a row ``(μ, c)`` of ``gravity``; the kernels take
    the body's inertia from their problem.

    Returns
    -------
    (F, tau, points, point_forces, gravity) : tuple of ndarray
        Constant force on the centre of mass (3,), constant torque (3,), body points (k, 3)
        and the constant world forces acting there (k, 3), and one row ``(μ, c₀, c₁, c₂)``
        per point mass (g, 4).
    """
    if not loads:
        return _NO_LOADS
    if not all(load.compiled for load in loads):
        return None
    F, tau, points, point_forces, gravity = np.zeros(3), np.zeros(3), [], [], []
    for load in loads:
        if isinstance(load, Gravity):
            F += mass * load.g
        elif isinstance(load, Torque):
            tau += load.torque
        elif isinstance(load, MagneticDipole):
            points.append(load.moment)
            point_forces.append(load.field)
            F -= load.field
        elif isinstance(load, GravityGradient):
            gravity.append([load.mu, *load.centre])
        elif load.point is None:
            F += load.force
        else:
            points.append(load.point)
            point_forces.append(load.force)
    shape = (len(points), 3)
    return (F, tau, np.array(points).reshape(shape), np.array(point_forces).reshape(shape),
            np.array(gravity).reshape(len(gravity), 4))  # fmt: skip


_NO_LOADS = (np.zeros(3), np.zeros(3), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 4)))
"""A free body's :func:`compiled_loads`, built once (the kernels only read them; writable, so
that numba types them as every other run's arrays)."""
