"""``solve``: the ODE entry point, shaped like ``scipy.integrate.solve_ivp``."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from tumble.ode.control import StepController, error_norm, initial_step, minimum_step
from tumble.ode.dense import DenseOutput, StepInterpolant, step_coefficients
from tumble.ode.events import Event, EventTracker
from tumble.ode.stepper import rk_step
from tumble.ode.tableaux import TABLEAUX, ButcherTableau

MESSAGES = {
    0: "The solver successfully reached the end of the integration interval.",
    1: "A termination event occurred.",
}


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
    status : int
        0: reached ``t_span[1]``; 1: a terminal event; -1: failed (see ``message``).
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
    status: int
    message: str
    sol: DenseOutput | None

    @property
    def success(self) -> bool:
        """True unless the run failed (``status >= 0``)."""
        return self.status >= 0


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


class _Run:
    """The state of one integration and the record of its accepted steps."""

    def __init__(self, fun, tableau, t0, y0, events, dense_output):
        self.fun, self.tableau = fun, tableau
        self.t, self.y = t0, y0
        self.f = fun(t0, y0)
        self.K = np.empty((tableau.stages, y0.size))
        self.ts, self.ys = [t0], [y0]
        self.tracker = EventTracker(events, t0, y0) if events else None
        self.interpolants: list[StepInterpolant] | None = [] if dense_output else None
        self.n_steps = self.n_rejected = 0
        self.status, self.message = 0, MESSAGES[0]

    def fail(self, message: str) -> None:
        self.status, self.message = -1, message

    def accept(self, t_new: float, y_new: np.ndarray, f_new: np.ndarray) -> bool:
        """Record a step; True when the run must stop (terminal event)."""
        h = t_new - self.t
        sol = None
        if self.tracker is not None or self.interpolants is not None:
            Q = step_coefficients(self.tableau, self.K, self.y, y_new, f_new, h)
            sol = StepInterpolant(self.t, h, self.y, Q)
        if self.tracker is not None:
            t_stop = self.tracker.update(self.t, t_new, y_new, sol)
            if t_stop is not None:
                t_new, y_new = t_stop, sol(t_stop)
                self.status, self.message = 1, MESSAGES[1]
        if self.interpolants is not None:
            self.interpolants.append(sol)
        self.t, self.y, self.f = t_new, y_new, f_new.copy()
        self.ts.append(t_new)
        self.ys.append(y_new)
        self.n_steps += 1
        return self.status == 1

    def result(self) -> OdeResult:
        n = self.y.size
        t_events, y_events = self.tracker.results(n) if self.tracker else ([], [])
        sol = DenseOutput(self.ts, self.interpolants) if self.interpolants else None
        return OdeResult(
            t=np.array(self.ts),
            y=np.array(self.ys).T,
            t_events=t_events,
            y_events=y_events,
            nfev=self.fun.count,
            n_steps=self.n_steps,
            n_rejected=self.n_rejected,
            status=self.status,
            message=self.message,
            sol=sol,
        )


def fixed_step_count(t0: float, t1: float, h: float) -> int:
    """Number of steps of size ``h`` (the last one shortened) that cover ``[t0, t1]``.

    A ratio within round-off of an integer counts as that integer, so ``h = 0.1`` on
    ``[0, 1]`` takes 10 steps, not 11.
    """
    ratio = (t1 - t0) / h
    nearest = round(ratio)
    if nearest >= 1 and abs(ratio - nearest) <= 1e-9 * max(1.0, ratio):
        return int(nearest)
    return max(1, math.ceil(ratio))


def _integrate_fixed(run: _Run, t1: float, h: float, max_steps: int) -> None:
    t0 = run.t
    n = fixed_step_count(t0, t1, h)
    for k in range(1, n + 1):
        if k > max_steps:
            run.fail(f"max_steps={max_steps} reached at t={run.t!r}; increase `max_steps`")
            return
        t_new = t1 if k == n else t0 + k * h
        y_new, _ = rk_step(run.fun, run.t, run.y, run.f, t_new - run.t, run.tableau, run.K)
        if not np.all(np.isfinite(y_new)):
            run.fail(f"the solution became non-finite (nan or inf) at t={t_new!r}")
            return
        f_new = run.fun(t_new, y_new)
        if run.accept(t_new, y_new, f_new):
            return


def _integrate_adaptive(
    run: _Run, t1: float, h: float | None, rtol: float, atol, max_steps: int
) -> None:
    tableau, controller = run.tableau, StepController()
    order = tableau.error_order
    if h is None:
        h = initial_step(run.fun, run.t, run.y, run.f, order, rtol, atol)
    rejected = False
    while run.t < t1:
        if run.n_steps >= max_steps:
            run.fail(f"max_steps={max_steps} reached at t={run.t!r}; increase `max_steps`")
            return
        h_min = minimum_step(run.t)
        t_new = min(run.t + max(h, h_min), t1)
        y_new, error = rk_step(run.fun, run.t, run.y, run.f, t_new - run.t, tableau, run.K)
        norm = error_norm(error, run.y, y_new, rtol, atol)  # nan/inf if y_new is not finite
        finite = math.isfinite(norm)
        accepted, h = controller.propose(t_new - run.t, norm, order, after_rejection=rejected)
        if not accepted:
            run.n_rejected += 1
            rejected = True
            if h < h_min:
                cause = "" if finite else " (the solution became non-finite: nan or inf)"
                run.fail(f"step size fell below the minimum {h_min:.3g} at t={run.t!r}{cause}")
                return
            continue
        rejected = False
        f_new = run.K[-1] if tableau.fsal else run.fun(t_new, y_new)
        if run.accept(t_new, y_new, f_new):
            return


def _lookup(method: str) -> ButcherTableau:
    if method not in TABLEAUX:
        raise ValueError(f"method={method!r} is not known; choose one of {sorted(TABLEAUX)}")
    return TABLEAUX[method]


def _check_span(t_span) -> tuple[float, float]:
    try:
        t0, t1 = (float(t) for t in t_span)
    except (TypeError, ValueError):
        raise ValueError(f"t_span={t_span!r} must be two numbers (t0, t1)") from None
    if not (np.isfinite(t0) and np.isfinite(t1)) or t1 <= t0:
        raise ValueError(
            f"t_span={t_span!r} is not allowed: t0 and t1 must be finite with t1 > t0 "
            "(tumble integrates forward in time)"
        )
    return t0, t1


def _check_y0(y0) -> np.ndarray:
    y = np.array(y0, dtype=float)
    if y.ndim != 1 or y.size == 0 or not np.all(np.isfinite(y)):
        raise ValueError(f"y0={y0!r} must be a non-empty 1-D array of finite numbers")
    return y


def _check_step(h, tableau: ButcherTableau) -> float | None:
    if h is None:
        if not tableau.adaptive:
            raise ValueError(
                f"h=None is not allowed for the fixed-step method {tableau.name!r}: give a step "
                "size h > 0, or choose an adaptive method ('rkf45', 'dopri5')"
            )
        return None
    if not (isinstance(h, int | float | np.floating | np.integer) and np.isfinite(h) and h > 0):
        raise ValueError(f"h={h!r} is not allowed: the step size must be finite and > 0")
    return float(h)


def _check_tolerances(rtol, atol, n: int) -> np.ndarray:
    if not (np.isscalar(rtol) and np.isfinite(rtol) and rtol > 0):
        raise ValueError(f"rtol={rtol!r} is not allowed: it must be finite and > 0")
    if rtol < 100 * np.finfo(float).eps:
        raise ValueError(f"rtol={rtol!r} is below 100 × machine epsilon (2.2e-14); raise it")
    atol_array = np.asarray(atol, dtype=float)
    if (
        atol_array.shape not in ((), (n,))
        or np.any(atol_array < 0)
        or not np.all(np.isfinite(atol_array))
    ):
        raise ValueError(f"atol={atol!r} must be ≥ 0 and finite, a scalar or shape ({n},)")
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
    max_steps: int = 1_000_000,
) -> OdeResult:
    """Integrate ``y' = fun(t, y)`` from ``t_span[0]`` to ``t_span[1]``.

    Parameters
    ----------
    fun : callable
        Right-hand side ``fun(t, y) -> ndarray, shape (n,)``.
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
    max_steps : int
        Stop with ``status = -1`` after this many accepted steps.

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
    if not (isinstance(max_steps, int | np.integer) and max_steps > 0):
        raise ValueError(f"max_steps={max_steps!r} must be a positive integer")
    if events is not None and callable(events):
        events = [events]
    run = _Run(_CountedFunction(fun, y.size), tableau, t0, y, events or [], dense_output)
    # Non-finite values are detected and reported as a status, not as numpy warnings.
    with np.errstate(over="ignore", invalid="ignore"):
        if tableau.adaptive:
            _integrate_adaptive(run, t1, h, float(rtol), atol_array, int(max_steps))
        else:
            _integrate_fixed(run, t1, h, int(max_steps))
    return run.result()
