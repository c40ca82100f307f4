"""Exact reference solutions: projectile, isotropic sphere, torque-free body; order measurement.

Every order and work–precision study in tumble (the convergence scenario, ``work_precision``,
the report card and its structural rows) runs through one harness, :func:`study` (warm up,
best of N, error against the reference), and fits through one policy, :func:`fit_order`
(which errors enter the fit), which calls :func:`observed_order`.

Conventions (SPEC §2): SI units; R maps body to world; ω_body = Rᵀ ω_world; inertia about the
centre of mass in body axes; Euler's equations I ω̇ = (I ω) × ω; L = R I ω_body is constant.

Bad input is refused by name. A spin so large that its angle or energy overflows (past about
1e154 rad/s) is not bad input but beyond doubles: :func:`sphere`, :func:`free_body` and
:func:`free_body_rotation` give NaN there (no warning), so that a run compared with them
reports its own failure; :class:`Projectile` refuses a time at which its position overflows.

References
----------
.. [1] L. D. Landau, E. M. Lifshitz, Mechanics, 3rd ed., Pergamon 1976, §33, §35, §37.
.. [2] E. Hairer, C. Lubich, G. Wanner, Geometric Numerical Integration, 2nd ed., Springer 2006,
   §IV.1 and §VII.5 (the free rigid body; the test body diag(2, 1, 2/3)).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, SupportsFloat, TypeVar

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks, so3
from tumble._elliptic import (
    body_omega,
    body_period,
    body_rotation,
    check_rotation,
    principal_axes,
    rodrigues,
)

__all__ = [
    "OrderFit",
    "Projectile",
    "Trial",
    "fit_order",
    "free_body",
    "free_body_period",
    "free_body_rotation",
    "measure_order",
    "observed_order",
    "projectile",
    "sphere",
    "study",
]


@dataclass(frozen=True)
class Projectile:
    """Drag-free projectile launched from (x0, y0) at speed v0 (m/s), angle (rad), gravity g.

    x(t) = x0 + v0 cos α t,  y(t) = y0 + v0 sin α t − g t²/2; the ground is y = 0. The
    formulas continue past `flight_time` (below ground). Built and checked by `projectile`.
    """

    v0: float
    angle: float
    g: float = 9.81
    x0: float = 0.0
    y0: float = 0.0

    def __post_init__(self) -> None:
        _checks.non_negative("v0", self.v0, "m/s")
        if abs(_checks.finite("angle", self.angle, "rad")) > np.pi / 2:
            raise _checks.fail("angle", self.angle, "in [-pi/2, pi/2]", "rad")
        _checks.positive("g", self.g, "m/s²")
        _checks.finite("x0", self.x0, "m")
        _checks.non_negative("y0", self.y0, "m", "the ground is y = 0")
        with np.errstate(all="ignore"):
            flight = (self.flight_time, self.range, self.max_height, self.x0 + self.range)
        if not all(math.isfinite(value) for value in flight):
            sizes = {"v0": self.v0, "g": self.g, "y0": self.y0}
            name = max(sizes, key=lambda key: abs(math.log10(sizes[key])) if sizes[key] else 0)
            raise _checks.fail(
                name, sizes[name], "such that the flight time, range and height are finite",
                remedy=f"with v0={self.v0!r} m/s, g={self.g!r} m/s² and y0={self.y0!r} m they "
                "overflow past 1.8e308; give the launch in other units",
            )  # fmt: skip

    @property
    def flight_time(self) -> float:
        """Time of impact with y = 0, s: (v0 sin α + √(v0² sin²α + 2 g y0)) / g."""
        vy = self.v0 * np.sin(self.angle)
        return float((vy + np.sqrt(vy * vy + 2.0 * self.g * self.y0)) / self.g)

    @property
    def range(self) -> float:
        """Horizontal distance from launch to impact, m: v0 cos α · flight_time."""
        return float(self.v0 * np.cos(self.angle) * self.flight_time)

    @property
    def max_height(self) -> float:
        """Highest y reached, m: y0 + (v0 sin α)² / (2g) when launched upwards, else y0."""
        vy = max(self.v0 * np.sin(self.angle), 0.0)
        return float(self.y0 + vy * vy / (2.0 * self.g))

    def position(self, t: ArrayLike) -> np.ndarray:
        """(x, y) in m at times t (s); shape (2,) for scalar t, (n, 2) for t of shape (n,)."""
        t, scalar = _times(t)
        with np.errstate(over="ignore", invalid="ignore"):
            x = self.x0 + self.v0 * np.cos(self.angle) * t
            y = self.y0 + self.v0 * np.sin(self.angle) * t - 0.5 * self.g * t * t
        position = np.stack([x, y], axis=-1)
        return _shaped(_finite(position, "t", t, "g t²/2 or v0 t overflows"), scalar)

    def velocity(self, t: ArrayLike) -> np.ndarray:
        """(vx, vy) in m/s at times t (s); shape (2,) or (n, 2) like `position`."""
        t, scalar = _times(t)
        vx = np.full_like(t, self.v0 * np.cos(self.angle))
        with np.errstate(over="ignore"):
            vy = self.v0 * np.sin(self.angle) - self.g * t
        velocity = np.stack([vx, vy], axis=-1)
        return _shaped(_finite(velocity, "t", t, "g t overflows"), scalar)


def projectile(
    v0: float, angle: float, g: float = 9.81, x0: float = 0.0, y0: float = 0.0
) -> Projectile:
    """Exact drag-free projectile launched at speed `v0` (m/s) and `angle` (radians).

    Parameters
    ----------
    v0 : float
        Launch speed, m/s, ≥ 0.
    angle : float
        Elevation above the horizontal in **radians**, in [−π/2, π/2] (launch towards +x).
    g : float
        Gravitational acceleration, m/s², > 0.
    x0, y0 : float
        Launch point, m; y0 ≥ 0 is the height above the ground y = 0.

    Returns
    -------
    Projectile
        With ``flight_time`` = (v0 sin α + √(v0² sin²α + 2 g y0))/g, ``range``, ``max_height``,
        ``position(t)`` and ``velocity(t)``.

    References
    ----------
    SPEC §4: v0 = 500 m/s at 45°, g = 9.81: impact at 72.080202 s, range 25484.1998 m.

    Examples
    --------
    >>> shot = projectile(500.0, np.pi / 4)
    >>> round(shot.flight_time, 6), round(shot.range, 4)
    (72.080202, 25484.1998)
    """
    return Projectile(v0, angle, g, x0, y0)


def sphere(t: ArrayLike, omega0: ArrayLike = (1.0, 0.0, 0.0)) -> np.ndarray:
    """Attitude of a torque-free isotropic body (I = c Id) starting at R(0) = Id.

    With I proportional to the identity ω is constant and R(t) = exp(t ω̃0): a rotation about
    ω0 by the angle ‖ω0‖ t, by Rodrigues' formula
    exp(θ k̃) = Id + sin θ k̃ + (1 − cos θ) k̃² with k = ω0/‖ω0‖, θ = ‖ω0‖ t.

    Parameters
    ----------
    t : float or ndarray, shape (n,)
        Times, s.
    omega0 : array_like, shape (3,)
        Angular velocity, rad/s (body and world frames agree up to R).

    Returns
    -------
    ndarray, shape (3, 3) for scalar t, (n, 3, 3) otherwise
        R(t), body to world.

    References
    ----------
    Seed 002 (the sphere, I = Id, L = (1, 0, 0)); Hairer–Lubich–Wanner [2] §IV.1.

    Examples
    --------
    >>> np.round(sphere(np.pi / 2), 12) + 0.0
    array([[ 1.,  0.,  0.],
           [ 0.,  0., -1.],
           [ 0.,  1.,  0.]])
    """
    t, scalar = _times(t)
    omega0 = _vector("omega0", omega0)
    with np.errstate(over="ignore", invalid="ignore"):
        R = rodrigues(omega0, t)
    return _shaped(_past_overflow(R), scalar)


def free_body(inertia: ArrayLike, omega0: ArrayLike, t: ArrayLike) -> np.ndarray:
    """Body angular velocity ω(t) of the torque-free rigid body, exactly.

    Solves I ω̇ = (I ω) × ω, ω(0) = ω0. In the principal frame with A < B < C and the energy
    2E = ω·Iω, the momentum ‖L‖² = ‖Iω‖² and Δ = ‖L‖² − 2EB (Landau & Lifshitz §37):

    * Δ > 0 (spin nearer the largest axis C): ω_A = a_A cn u, ω_B = σ a_B sn u,
      ω_C = σ a_C dn u, with a_A² = (2EC − L²)/(A(C − A)), a_B² = (2EC − L²)/(B(C − B)),
      a_C² = (L² − 2EA)/(C(C − A)), λ² = (C − B)(L² − 2EA)/(ABC),
      m = (B − A)(2EC − L²)/((C − B)(L² − 2EA)).
    * Δ < 0 (nearer the smallest axis A): the same with A and C exchanged,
      ω_A = σ a_A dn u, ω_C = a_C cn u, a_B² = (L² − 2EA)/(B(B − A)).

    Here u = u0 + λt, σ = sign of the dn component at t = 0, and u0 = F(am u0 | m) with
    (cn u0, sn u0) read off ω0. A symmetric body (two equal moments, about axis e_s)
    precesses: ω(t) = exp(−Ωt ẽ_s) ω0, Ω = (I⊥ − I_s) ω_s / I⊥. A sphere, or a spin about a
    principal axis, keeps ω constant.

    Parameters
    ----------
    inertia : array_like, shape (3,) or (3, 3)
        Principal moments in body axes (any order), or a symmetric positive definite tensor
        about the centre of mass, kg m². A full tensor is diagonalised, solved in its principal
        axes and rotated back. The triangle inequality is not required (e.g. diag(2, 1, 2/3)).
    omega0 : array_like, shape (3,)
        Initial body angular velocity, rad/s.
    t : float or ndarray, shape (n,)
        Times, s.

    Returns
    -------
    ndarray, shape (3,) for scalar t, (n, 3) otherwise
        ω_body(t), rad/s.

    Raises
    ------
    ValueError
        On bad input, or ω0 on the separatrix ‖L‖² = 2EB and not a steady spin: the motion
        takes infinite time to leave the middle axis (m = 1). On it means within the round-off
        of ω0's own terms: ``|x − y| ≤ 2ε (x + y)`` for ``Δ = x² − y²`` (docs/exact.md).

    References
    ----------
    Landau & Lifshitz [1] §37; Hairer–Lubich–Wanner [2] §VII.5; Carlson forms: DLMF §19.25.

    Examples
    --------
    >>> w = free_body([2.0, 1.0, 2.0 / 3.0], [0.2, 0.0, 1.3], [0.0, 1.0])
    >>> w.shape, bool(np.allclose(w[0], [0.2, 0.0, 1.3]))
    ((2, 3), True)
    """
    t, scalar = _times(t)
    moments, axes = principal_axes(_inertia(inertia))
    omega0 = _vector("omega0", omega0)
    with np.errstate(over="ignore", invalid="ignore"):
        omega = body_omega(moments, axes, omega0, t)
    return _shaped(_past_overflow(omega), scalar)


def free_body_period(inertia: ArrayLike, omega0: ArrayLike) -> float:
    """Period of ω_body(t) of the torque-free body, s.

    4K(m)/λ for an asymmetric body (m, λ as in `free_body`), 2π/abs(Ω) for a symmetric one. On
    the separatrix it is ``inf`` (the motion never returns; no error, test ``math.isinf``).
    Where ω is constant it is the limit of nearby periods: 2π/λ (small oscillations) for a
    spin about the largest or smallest axis, ``inf`` for a spin about the middle axis, a
    transverse spin of a symmetric body, a sphere or ω0 = 0.

    Parameters
    ----------
    inertia : array_like, shape (3,) or (3, 3)
        As in `free_body`, kg m².
    omega0 : array_like, shape (3,)
        Initial body angular velocity, rad/s.

    Returns
    -------
    float
        The period, s (``inf`` as described).

    References
    ----------
    Landau & Lifshitz [1] §37 (the period 4K/λ).

    Examples
    --------
    >>> round(free_body_period([1.0, 1.0, 2.0], [0.3, 0.0, 1.0]), 12) == round(2 * np.pi, 12)
    True
    """
    moments, axes = principal_axes(_inertia(inertia))
    omega0 = _vector("omega0", omega0)
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        period = body_period(moments, axes, omega0)
    if math.isnan(period):  # |ω0|² under- or overflows: no digit of the energy is left
        raise _checks.fail("omega0", omega0.tolist(), "a spin whose energy ½ ω·Iω is a normal "
                           "float", "rad/s", remedy="give it in other units")  # fmt: skip
    return period


def free_body_rotation(
    inertia: ArrayLike, omega0: ArrayLike, t: ArrayLike, R0: ArrayLike | None = None
) -> np.ndarray:
    """Attitude R(t) (body to world) of the torque-free body, exactly.

    L = R0 I ω0 is constant. In the pole frame (q, r, p), p the axis the spin stays near,
    R(t) = W Rz(φ) M(l) Pᵀ: l = Iω/‖L‖, M(l) = Rx(θ) Rz(ψ) the rotation with last row lᵀ
    (Landau's Euler angles), P the pole axes in body coordinates, W = R0 P M(l(0))ᵀ, and
    φ̇ = ‖L‖ (I_q ω_q² + I_r ω_r²)/(L_q² + L_r²) integrated in closed form,
    φ = ‖L‖ t / I_p ± ‖L‖ (C − A)/(A C λ) [Π(−ν; am u | m)]₀ᵗ (docs/exact.md). A symmetric
    body: R(t) = exp(t L̃/I⊥) R0 exp(Ωt ẽ_s); a constant ω: R(t) = R0 exp(t ω̃0).

    Parameters
    ----------
    inertia : array_like, shape (3,) or (3, 3)
        As in `free_body`, kg m².
    omega0 : array_like, shape (3,)
        Initial body angular velocity, rad/s.
    t : float or ndarray, shape (n,)
        Times, s.
    R0 : array_like, shape (3, 3), optional
        Initial attitude, a rotation matrix; identity by default.

    Returns
    -------
    ndarray, shape (3, 3) for scalar t, (n, 3, 3) otherwise
        R(t).

    Raises
    ------
    ValueError
        As `free_body` (bad input, separatrix), or R0 not a rotation.

    References
    ----------
    Landau & Lifshitz [1] §35 (Euler angles), §37; Hairer–Lubich–Wanner [2] §VII.5;
    Carlson forms of Π: DLMF 19.25.14.

    Examples
    --------
    >>> R = free_body_rotation([2.0, 1.0, 2.0 / 3.0], [0.2, 0.0, 1.3], 5.0)
    >>> bool(np.allclose(R.T @ R, np.eye(3)))
    True
    """
    t, scalar = _times(t)
    moments, axes = principal_axes(_inertia(inertia))
    R0 = None if R0 is None else _checks.array("R0", so3.from_scipy(R0, "R0", single=True),
                                               shape=(3, 3))  # fmt: skip
    omega0, R0 = _vector("omega0", omega0), check_rotation("R0", R0)
    with np.errstate(over="ignore", invalid="ignore"):
        R = body_rotation(moments, axes, omega0, R0, t)
    return _shaped(_past_overflow(R), scalar)


def observed_order(step_sizes: ArrayLike, errors: ArrayLike) -> float:
    """Observed order p of a method: the least-squares slope of log(error) against log(h).

    Fits log e = p log h + c with ``np.polyfit``; e ∝ h^p gives exactly p.

    Parameters
    ----------
    step_sizes : array_like, shape (k,)
        At least two distinct positive step sizes.
    errors : array_like, shape (k,)
        The positive errors measured with them.

    Returns
    -------
    float
        The slope p.

    Examples
    --------
    >>> round(observed_order([0.1, 0.05, 0.025], [1e-4, 6.25e-6, 3.90625e-7]), 12)
    4.0
    """
    h = _checks.values("step_sizes", step_sizes, minimum=2, unit="s", positive=True)
    e = _checks.values(
        "errors", errors, minimum=2, positive=True, remedy="an exact method has no observed order"
    )
    if e.shape != h.shape:
        raise _checks.fail("errors", errors, f"one value per step size ({h.size})")
    if np.unique(h).size < 2:
        raise _checks.fail("step_sizes", step_sizes, "at least two distinct values", "s")
    return float(np.polyfit(np.log(h), np.log(e), 1)[0])


def measure_order(
    run: Callable[[float], float], step_sizes: Sequence[float] | np.ndarray
) -> tuple[float, np.ndarray]:
    """Run a method at each step size and fit its observed order.

    Parameters
    ----------
    run : callable
        ``run(h) -> error``: integrates with step h (s) and returns a positive error
        (e.g. the distance to an exact reference at the final time).
    step_sizes : sequence of float, shape (k,)
        At least two distinct positive step sizes.

    Returns
    -------
    order : float
        `observed_order` of the errors.
    errors : ndarray, shape (k,)
        ``run(h)`` for each h.

    Examples
    --------
    >>> order, errors = measure_order(lambda h: 3.0 * h**2, [0.1, 0.05, 0.025])
    >>> round(order, 12)
    2.0
    """
    run = _checks.function("run", run, "a callable run(h) -> error")
    h = _checks.values("step_sizes", step_sizes, minimum=2, unit="s", positive=True)
    errors = np.array([trial.error for trial in study(run, h, error=float)])
    return observed_order(h, errors), errors


R = TypeVar("R")


@dataclass(frozen=True)
class Trial(Generic[R]):
    """One setting of a :func:`study`: its error, its time and the run itself.

    Attributes
    ----------
    setting : float
        The step h (s) or the tolerance the run was given.
    error : float
        The run's error against the reference; ``inf`` when it is not finite (a failed run),
        NaN when the study measured none.
    seconds : float
        The best time of the study's ``repeat`` runs (s).
    result : object
        What the fastest run returned.
    """

    setting: float
    error: float
    seconds: float
    result: R


def study(
    run: Callable[[float], R],
    settings: ArrayLike,
    error: Callable[[R], SupportsFloat] | None = None,
    *,
    repeat: int = 1,
    warm_up: Callable[[], object] | None = None,
    seconds: Callable[[R], float] | None = None,
    until: Callable[[list[Trial[R]]], bool] | None = None,
) -> list[Trial[R]]:
    """Run a method at each setting, timed, and measure each run's error: the one harness.

    The work–precision diagrams, the order studies and the report card all measure this way:
    ``warm_up()`` once (numba's compilation and the first call's imports are not timed), then
    for each setting the best time of ``repeat`` calls ``run(setting)`` (the least disturbed
    by other work) and ``error`` of the fastest; a non-finite error (a run that blew up or
    stopped) is ``inf``. Its runs take coarse steps on purpose: a
    :class:`~tumble._checks.LargeStepWarning` is not shown for them (each error says it).

    Parameters
    ----------
    run : callable
        ``run(setting) -> result``: one integration with that step (s) or tolerance.
    settings : sequence of float, shape (k,)
        The settings, in the order they are run.
    error : callable, optional
        ``error(result) -> float``: the run's distance to the reference; None only times the
        runs (each error NaN).
    repeat : int
        Timed calls per setting, >= 1.
    warm_up : callable, optional
        Called once before the first timed call.
    seconds : callable, optional
        ``seconds(result)``: the run's own time, when it times only the integration; default
        the wall time of the call (``time.perf_counter``).
    until : callable, optional
        ``until(trials) -> bool``, asked after each setting: True stops the study (finer
        settings would add nothing, e.g. once two errors are at round-off).

    Returns
    -------
    list of Trial
        One per setting run, in order.

    Examples
    --------
    >>> trials = study(lambda h: 3.0 * h**2, [0.1, 0.05], error=lambda e: e)
    >>> [round(trial.error, 6) for trial in trials]
    [0.03, 0.0075]
    """
    run = _checks.function("run", run, "a callable run(setting) -> result")
    given = _checks.array("settings", settings)
    if given.ndim != 1:
        raise _checks.fail("settings", settings, "a 1-D sequence of numbers (steps or "
                           "tolerances)")  # fmt: skip
    for name, value in (("error", error), ("warm_up", warm_up), ("seconds", seconds),
                        ("until", until)):  # fmt: skip
        if value is not None:
            _checks.function(name, value, "None or a callable")
    repeat = _checks.count("repeat", repeat)
    with warnings.catch_warnings():  # coarse steps on purpose: the errors say how coarse
        warnings.simplefilter("ignore", _checks.LargeStepWarning)
        return _trials(run, given.tolist(), error, repeat, warm_up, seconds, until)


def _trials(run, settings: list[float], error, repeat: int, warm_up, seconds,
            until) -> list[Trial]:  # fmt: skip
    """:func:`study`'s runs, its arguments checked."""
    if warm_up is not None:
        warm_up()
    trials: list[Trial] = []
    for setting in settings:
        best, fastest = math.inf, None
        for _ in range(repeat):
            start = time.perf_counter()
            result = run(setting)
            took = time.perf_counter() - start if seconds is None else seconds(result)
            if fastest is None or took < best:
                best, fastest = took, result
        assert fastest is not None
        value = math.nan if error is None else float(error(fastest))
        if error is not None and not math.isfinite(value):
            value = math.inf
        trials.append(Trial(setting, value, best, fastest))
        if until is not None and until(trials):
            break
    return trials


@dataclass(frozen=True)
class OrderFit:
    """An observed order and the runs it was fitted through (:func:`fit_order`).

    Attributes
    ----------
    order : float
        The least-squares slope of log e against log h.
    step_sizes : ndarray, shape (m,)
        The fitted step sizes (s).
    errors : ndarray, shape (m,)
        Their errors.
    used : ndarray of bool, shape (k,)
        Which of the given runs were fitted.
    """

    order: float
    step_sizes: np.ndarray
    errors: np.ndarray
    used: np.ndarray

    @property
    def points(self) -> int:
        """How many runs were fitted."""
        return int(self.step_sizes.size)

    @property
    def h_min(self) -> float:
        """The finest fitted step (s)."""
        return float(self.step_sizes.min())

    @property
    def h_max(self) -> float:
        """The coarsest fitted step (s)."""
        return float(self.step_sizes.max())


def fit_order(
    step_sizes: ArrayLike,
    errors: ArrayLike,
    *,
    window: tuple[float, float] = (0.0, math.inf),
    finest: int | None = None,
    minimum: int = 2,
) -> OrderFit | None:
    """The observed order through the errors that measure truncation: the one fit policy.

    An error enters the fit when it is finite and inside the open ``window`` = (floor,
    ceiling): above the floor it is truncation, not round-off or the reference's own error;
    below the ceiling the run is in the asymptotic range. Of those, the ``finest`` runs with
    the smallest steps (all when None) are fitted by :func:`observed_order`: the nearest to
    the asymptotic regime. Each caller names its window, from where its round-off and its
    reference's accuracy lie.

    Parameters
    ----------
    step_sizes : array_like, shape (k,)
        The steps h (s), or mean steps of adaptive runs.
    errors : array_like, shape (k,)
        Their errors (``inf`` or NaN for a failed run).
    window : (float, float)
        The open interval of errors that enter the fit.
    finest : int, optional
        Fit at most this many, those with the smallest steps.
    minimum : int
        The fewest distinct step sizes a fit needs (at least 2).

    Returns
    -------
    OrderFit or None
        None when fewer than ``minimum`` distinct steps are left.

    Examples
    --------
    >>> fit = fit_order([0.1, 0.05, 0.025, 0.0125], [1e-4, 6.25e-6, 3.90625e-7, 1e-16],
    ...                 window=(1e-13, 1.0))
    >>> round(fit.order, 12), fit.points
    (4.0, 3)
    """
    h = _checks.values("step_sizes", step_sizes, minimum=1, unit="s", positive=True)
    e = _checks.array("errors", errors, finite=False)  # inf or NaN: a failed run
    if e.shape != h.shape:
        raise _checks.fail("errors", errors, f"one value per step size ({h.size})")
    minimum = _checks.count("minimum", minimum, 2, remedy="a slope needs two steps")
    if finest is not None:
        finest = _checks.count("finest", finest)
    floor, ceiling = _window(window)
    with np.errstate(invalid="ignore"):
        inside = np.isfinite(e) & (e > floor) & (e < ceiling)
    by_step = np.argsort(h, kind="stable")
    chosen = by_step[inside[by_step]][:finest]
    if np.unique(h[chosen]).size < minimum:
        return None
    used = np.zeros(h.shape, dtype=bool)
    used[chosen] = True
    order = observed_order(h[used], e[used])
    return OrderFit(order, h[used], e[used], used)


def _times(t: ArrayLike) -> tuple[np.ndarray, bool]:
    """Times as a 1-D float array, and whether a scalar was given."""
    arr = _checks.array("t", t, unit="s")
    if arr.ndim > 1:
        raise _checks.fail("t", t, "a number or a 1-D array of times", "s")
    return arr.reshape(-1), arr.ndim == 0


def _shaped(out: np.ndarray, scalar: bool) -> np.ndarray:
    return out[0] if scalar else out


def _vector(name: str, value: ArrayLike) -> np.ndarray:
    return _checks.array(name, value, shape=(3,), unit="rad/s")


def _inertia(value: ArrayLike) -> np.ndarray:
    """``inertia`` as numbers (its shape and values are checked by ``principal_axes``)."""
    return _checks.array("inertia", value, unit="kg m²")


def _finite(result: np.ndarray, name: str, value: np.ndarray, cause: str) -> np.ndarray:
    """``result``, or the ValueError naming ``name`` when an entry is not finite (an input
    so large that the closed form overflows)."""
    if np.count_nonzero(np.isfinite(result)) != result.size:
        raise _checks.fail(name, value.tolist(), "small enough that the result is finite",
                           remedy=f"{cause} past 1.8e308; give it in other units")  # fmt: skip
    return result


def _past_overflow(result: np.ndarray) -> np.ndarray:
    """A reference past the range of doubles (a spin whose angle or energy overflows) as NaN,
    without NumPy's warnings: a run compared with it is then said to have failed, by its
    status, not by an exception from the reference."""
    result[~np.isfinite(result)] = np.nan
    return result


def _window(window: Any) -> tuple[float, float]:
    """``(floor, ceiling)`` of :func:`fit_order`: numbers, ``0 <= floor < ceiling``."""
    allowed = "a pair (floor, ceiling) of errors, 0 <= floor < ceiling (ceiling may be inf)"
    try:
        if isinstance(window, str | bytes):
            raise TypeError
        floor, ceiling = (float(x) for x in window)
    except (TypeError, ValueError):
        raise _checks.fail("window", window, allowed) from None
    if not (0 <= floor < ceiling and math.isfinite(floor)):
        raise _checks.fail("window", window, allowed)
    return floor, ceiling
