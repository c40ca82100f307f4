"""``solve``: the ODE entry point, shaped like ``scipy.integrate.solve_ivp``."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np

from tumble import _checks
from tumble.ode.control import StepController, initial_step, relative_tolerance
from tumble.ode.dense import DenseOutput, StepInterpolant, step_coefficients
from tumble.ode.driver import Control, Status, Stepper, march
from tumble.ode.events import Event
from tumble.ode.stepper import rk_step
from tumble.ode.tableaux import TABLEAUX, ButcherTableau


@dataclass
class OdeResult:
    """What :func:`solve` returns (the fields of scipy's ``OdeResult``).

    Attributes
    ----------
    t : ndarray, shape (m,)
        Times of the accepted steps, ``t[0] = t_span[0]``.
    y : ndarray, shape (n, m)
        The solution at ``t``.
    t_events, y_events : list of ndarray
        For each event, the times (k,) and states (k, n) where it fired.
    nfev : int
        Number of right-hand-side evaluations.
    n_steps, n_rejected : int
        Accepted and rejected steps.
    status : Status
        ``Status.SUCCESS`` (0): reached ``t_span[1]``; ``Status.TERMINAL_EVENT`` (1);
        ``Status.FAILED`` (-1): see ``message``.
    message : str
        What happened, in words.
    sol : DenseOutput or None
        The continuous solution, if ``dense_output=True``.
    """

    t: np.ndarray
    y: np.ndarray
    t_events: list[np.ndarray]
    y_events: list[np.ndarray]
    nfev: int
    n_steps: int
    n_rejected: int
    status: Status
    message: str
    sol: DenseOutput | None

    @property
    def success(self) -> bool:
        """True unless the run failed (``status >= 0``)."""
        return self.status.success


class _CountedFunction:
    """The user's right-hand side, counted; its first result's shape is checked."""

    def __init__(self, fun: Callable, n: int):
        self.fun, self.n, self.count = fun, n, 0

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        self.count += 1
        f = np.asarray(self.fun(t, y), dtype=float)
        if self.count == 1 and f.shape != (self.n,):
            raise ValueError(f"fun(t, y) returned shape {f.shape}; expected ({self.n},)")
        return f


class RungeKutta(Stepper):
    """An explicit Runge–Kutta tableau on ``y' = f(t, y)``: the stepper of :func:`solve`.

    Keeps ``f`` at the last accepted point (first same as last: ``K[-1]`` for an FSAL pair,
    else one evaluation after acceptance) and builds each step's interpolant from its stages
    (:func:`~tumble.ode.dense.step_coefficients`).
    """

    compiled_evaluations = 0
    """Evaluations of ``fun`` made in compiled code, unseen by a Python counter."""

    def __init__(self, fun: Callable, tableau: ButcherTableau, t0: float, y0: np.ndarray):
        self.fun, self.tableau = fun, tableau
        self.error_order = tableau.error_order
        self._fsal = tableau.adaptive and tableau.fsal
        self.f = fun(t0, y0)
        self.f_old = self.f
        self.K = np.empty((tableau.stages, y0.size))

    def step(self, t: float, y: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray | None]:
        return rk_step(self.fun, t, y, self.f, h, self.tableau, self.K)

    def accept(self, t_old: float, old: np.ndarray, t: float, y: np.ndarray) -> str | None:
        """Keep ``f`` at the accepted point (``K[-1]`` for an FSAL pair, else one evaluation),
        unless the state is not finite (refused, by default)."""
        refused = super().accept(t_old, old, t, y)
        if refused is None:
            self.f_old = self.f
            self.f = self.K[-1].copy() if self._fsal else self.fun(t, y)
        return refused

    def interpolant(self, t_old, old, t_new, new) -> StepInterpolant:
        h = t_new - t_old
        Q = step_coefficients(self.tableau, self.K, old, new, self.f, h, self.fun, t_old)
        return StepInterpolant(t_old, h, old, Q)


def is_compiled(fun: object) -> bool:
    """Whether ``fun`` is a numba-compiled function (``@numba.njit``), without importing
    numba: then :func:`solve` runs compiled (:mod:`tumble.ode.compiled`)."""
    kind = type(fun)
    return kind.__name__ == "CPUDispatcher" and kind.__module__.startswith("numba")


def _stepper(
    counted: _CountedFunction, tableau: ButcherTableau, t0: float, y: np.ndarray,
    interpolants: bool, compiled: bool,
) -> RungeKutta:  # fmt: skip
    """:func:`solve`'s stepper: :class:`RungeKutta` with ``compiled=False``, else its
    compiled twin (:class:`tumble.ode.compiled.CompiledRungeKutta`), which calls a compiled
    ``fun`` directly and a Python one back (:mod:`tumble.ode.callback`); each evaluates
    ``f(t0, y0)`` through ``counted``, which checks its shape."""
    if not compiled:
        return RungeKutta(counted, tableau, t0, y)
    jitted = counted.fun if is_compiled(counted.fun) else None
    return _compiled_stepper()(counted, jitted, tableau, t0, y, interpolants=interpolants)


@cache
def _compiled_stepper() -> Callable[..., RungeKutta]:
    """:class:`tumble.ode.compiled.CompiledRungeKutta`, imported once (it imports numba)."""
    from tumble.ode.compiled import CompiledRungeKutta

    return CompiledRungeKutta


_CONTROLLER = StepController()
""":func:`solve`'s step controller (the defaults: one instance for every run)."""


def _lookup(method: str) -> ButcherTableau:
    return TABLEAUX[_checks.choice("method", method, TABLEAUX, remedy="see tumble.ode.TABLEAUX")]


def _check_span(t_span) -> tuple[float, float]:
    allowed = "two finite numbers (t0, t1) with t1 > t0"
    remedy = "tumble integrates forward in time"
    try:
        t0, t1 = (float(t) for t in t_span)
    except (TypeError, ValueError):
        raise _checks.fail("t_span", t_span, allowed, remedy=remedy) from None
    if not (math.isfinite(t0) and math.isfinite(t1)) or t1 <= t0:
        raise _checks.fail("t_span", t_span, allowed, remedy=remedy)
    return t0, t1


def _check_y0(y0) -> np.ndarray:
    y = _checks.array("y0", y0)
    if y.ndim != 1 or y.size == 0:
        raise _checks.fail("y0", y0, "a non-empty 1-D array of finite numbers")
    return y


def _check_step(h, tableau: ButcherTableau) -> float | None:
    if h is None:
        if not tableau.adaptive:
            raise _checks.fail(
                "h", h, "a step size > 0 for the fixed-step method " + repr(tableau.name),
                remedy="or choose an adaptive method ('rkf45', 'dopri5')",
            )  # fmt: skip
        return None
    return _checks.positive("h", h)


def _check_tolerances(rtol, atol, n: int) -> np.ndarray | float:
    relative_tolerance(rtol)
    if isinstance(atol, float | int) and not isinstance(atol, bool) and atol >= 0:
        return _checks.non_negative("atol", atol)  # a number: no array to check
    atol_array = _checks.array("atol", atol)
    if atol_array.shape not in ((), (n,)) or np.any(atol_array < 0):
        raise _checks.fail("atol", atol, f">= 0 and finite, a scalar or of shape ({n},)")
    return atol_array


def solve(
    fun: Callable[[float, np.ndarray], np.ndarray],
    t_span: tuple[float, float],
    y0: Sequence[float] | np.ndarray,
    *,
    method: str = "rk4",
    h: float | None = None,
    rtol: float = 1e-6,
    atol: float | Sequence[float] = 1e-9,
    events: Event | Sequence[Event] | None = None,
    dense_output: bool = False,
    t_eval: Sequence[float] | np.ndarray | None = None,
    max_steps: int = 1_000_000,
    compiled: bool = True,
) -> OdeResult:
    """Integrate ``y' = fun(t, y)`` from ``t_span[0]`` to ``t_span[1]``.

    Parameters
    ----------
    fun : callable
        Right-hand side ``fun(t, y)`` returning ``n`` numbers (an array, a list or a tuple).
        The steps run compiled (:mod:`tumble.ode.compiled`: the driver marches them in
        blocks, events and dense output included), with the result of Python steps to
        round-off: a numba-compiled ``fun`` (``@numba.njit``, returning a float array) is
        called from the compiled loop directly, a Python one through a callback
        (:mod:`tumble.ode.callback`; it is then handed the same array ``y`` at every call,
        overwritten afterwards: copy it to keep it).
    t_span : (float, float)
        ``(t0, t1)`` with ``t1 > t0``. The last step lands exactly on ``t1``.
    y0 : array_like, shape (n,)
        Initial state.
    method : str
        ``"euler"``, ``"heun"``, ``"midpoint"``, ``"rk4"``, ``"rk8"`` (DOP853's order-8
        weights) (fixed step; ``h`` required), ``"rkf45"`` (Fehlberg 4(5)) or ``"dopri5"``
        (Dormand–Prince 5(4)) (adaptive).
    h : float, optional
        The step size for fixed-step methods; the first step for adaptive ones (chosen
        automatically when omitted).
    rtol, atol : float
        Tolerances of the adaptive methods: the weighted RMS norm of the local error estimate,
        scaled by ``atol + rtol·|y|``, is kept at most 1.
    events : callable or list of callables, optional
        ``g(t, y)``; crossings of zero are located on the dense output. ``g.terminal`` and
        ``g.direction`` as in ``scipy.integrate.solve_ivp``.
    dense_output : bool
        Return the continuous solution as ``result.sol``.
    t_eval : array_like, shape (k,), optional
        Record the solution at these times only (increasing, within ``t_span``), from each
        step's interpolant, instead of at every accepted step.
    max_steps : int
        Stop with ``status = -1`` after this many accepted steps.
    compiled : bool
        False: every step in Python (:class:`RungeKutta`, NumPy per stage), as
        ``solve_ivp`` does; the same steps and numbers to round-off, several times slower.

    Returns
    -------
    OdeResult
        ``t``, ``y``, ``t_events``, ``y_events``, ``nfev``, ``status``, ``message``, ``sol``.

    Raises
    ------
    ValueError
        For an unknown method, a bad step, tolerance, span or initial state.

    Notes
    -----
    Numerical failure is a status, not an exception: a step size underflow, a non-finite
    solution or ``max_steps`` ends the run with ``status = -1`` and a message naming ``t``.

    Examples
    --------
    The projectile of seed 000, stopped by a terminal event at the ground:

    >>> import numpy as np
    >>> from tumble import solve
    >>> def ground(t, y):
    ...     return y[1]
    >>> ground.terminal, ground.direction = True, -1
    >>> v = 500 / np.sqrt(2)
    >>> fall = lambda t, y: [y[2], y[3], 0.0, -9.81]
    >>> result = solve(fall, (0, 100), [0, 0, v, v], h=0.01, events=ground)
    >>> round(float(result.t_events[0][0]), 6), round(float(result.y_events[0][0, 0]), 4)
    (72.080202, 25484.1998)
    """
    tableau = _lookup(method)
    t0, t1 = _check_span(t_span)
    y = _check_y0(y0)
    h = _check_step(h, tableau)
    atol_array = _check_tolerances(rtol, atol, y.size)
    max_steps = _checks.count("max_steps", max_steps)
    events = _checks.callables("events", events)
    dense_output = _checks.flag("dense_output", dense_output)
    times = None if t_eval is None else _checks.sample_times("t_eval", t_eval, t0, t1)
    compiled = _checks.flag("compiled", compiled)
    counted = _CountedFunction(fun, y.size)
    follows = bool(events) or dense_output or times is not None
    stepper = _stepper(counted, tableau, t0, y, follows, compiled)
    control = None
    if tableau.adaptive:
        control = Control(float(rtol), atol_array, _CONTROLLER)
        if h is None and not (compiled and is_compiled(fun)):  # else the compiled loop does
            h = initial_step(counted, t0, y, stepper.f, tableau.error_order, rtol, atol_array)
    # Non-finite values are detected and reported as a status, not as numpy warnings.
    with np.errstate(over="ignore", invalid="ignore"):
        out = march(stepper, (t0, t1), y, h=h, control=control, events=events or [],
                    max_steps=int(max_steps), dense_output=dense_output,
                    t_eval=times)  # fmt: skip
    t_events = [np.array(ts, dtype=float) for ts in out.t_events]
    y_events = [np.array(ys, dtype=float).reshape(-1, y.size) for ys in out.y_events]
    sol = None
    if out.step_times is not None and out.interpolants:
        sol = DenseOutput(out.step_times, out.interpolants)
    return OdeResult(
        t=out.t,
        y=out.records[0].T,
        t_events=t_events,
        y_events=y_events,
        nfev=counted.count + stepper.compiled_evaluations,
        n_steps=out.n_steps,
        n_rejected=out.n_rejected,
        status=out.status,
        message=out.message,
        sol=sol,
    )
