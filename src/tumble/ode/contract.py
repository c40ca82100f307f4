"""The driver's contract: what a stepper provides, what a run returns, and how it ended.

:func:`tumble.ode.driver.march` runs any :class:`Stepper`; a compiled one hands it a
:class:`Block` (fixed steps on a :class:`Grid`) or an :class:`AdaptiveBlock` at a time. A run
ends with an :class:`Outcome` and a :class:`Status` whose message names the time. These types
are re-exported by :mod:`tumble.ode.driver`, where the contract is described in full.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any, NamedTuple

import numpy as np

from tumble.ode.control import StepController, error_norm, grid_time

OK, NON_FINITE, UNCONVERGED, MINIMUM_STEP = 0, 1, 2, 3
"""Why a compiled loop stopped, one set for every family (:mod:`tumble.ode.templates`): it
did not (``OK``: at the end, or with the record full, or after ``max_steps``); a state was
not finite; an implicit step's Newton iteration did not converge; an adaptive step fell
below the minimum step."""

FAILURES = {OK: None, NON_FINITE: "non-finite", MINIMUM_STEP: "minimum-step"}
"""The :attr:`AdaptiveBlock.failure` of each cause an adaptive loop can stop with."""


class Status(IntEnum):
    """How a run ended; the codes of ``scipy.integrate.solve_ivp``.

    Every result type (:class:`~tumble.ode.OdeResult`, :class:`~tumble.Trajectory`,
    :class:`~tumble.BatchTrajectory`, :class:`~tumble.structural.Response`) carries one,
    with a ``message`` that says the time. Compare with the members or the integers.

    Examples
    --------
    >>> Status.FAILED == -1, Status.TERMINAL_EVENT.success, Status.SUCCESS.message
    (True, True, 'The run reached the end of the interval.')
    """

    SUCCESS = 0
    TERMINAL_EVENT = 1
    FAILED = -1

    @property
    def success(self) -> bool:
        """True unless the run failed."""
        return self >= 0

    @property
    def message(self) -> str:
        """The generic message (a failure's own message names its cause and time)."""
        return _MESSAGES[self]


_MESSAGES = {
    Status.SUCCESS: "The run reached the end of the interval.",
    Status.TERMINAL_EVENT: "A terminal event occurred.",
    Status.FAILED: "The run failed.",
}


def max_steps_message(max_steps: float, t: float) -> str:
    """The message of a run stopped by ``max_steps`` (the one wording everywhere)."""
    return f"max_steps={max_steps} reached at t={t!r}; increase `max_steps`"


def non_finite_message(t_old: float, t_new: float) -> str:
    """The message of a run stopped by a non-finite state (the one wording everywhere)."""
    return (
        f"the state became non-finite (nan or inf) in the step from t={t_old!r} to "
        f"t={t_new!r}; the run ends with the last finite state"
    )


class Grid(NamedTuple):
    """A fixed-step grid: ``n`` steps from ``t0``, step ``k`` ending at ``t0 + k h`` and the
    last exactly at ``t1``."""

    t0: float
    t1: float
    h: float
    n: int

    def time(self, k: int) -> float:
        """Where step ``k`` ends."""
        return grid_time(self.t0, self.t1, self.h, k, self.n)


@dataclass
class Steps:
    """A compiled block's accepted steps, for events, dense output and ``t_eval``
    (``Block.steps``, from a stepper with ``block_interpolants``).

    Attributes
    ----------
    t : ndarray, shape (m,)
        Where each step ends (the block starts where the run stands).
    states : sequence
        The state at each ``t``.
    interpolants : sequence of callable
        ``sol(t)`` on each step (:meth:`Stepper.interpolant`).
    n_rejected : ndarray of int, shape (m,), optional
        Steps rejected in the block up to each accepted one (adaptive blocks).
    """

    t: np.ndarray
    states: Sequence[Any]
    interpolants: Sequence[Callable]
    n_rejected: np.ndarray | None = None


@dataclass
class Block:
    """What a compiled block of steps returns.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Times of the samples it recorded.
    records : tuple of ndarray
        The samples, as :meth:`Stepper.record` lays them out, ``m`` along the time axis.
    state : object
        The state after the block (the last finite one if it stopped).
    failed : int
        The grid step whose result was not finite (the block stopped before it), or -1.
    steps : Steps, optional
        Every accepted step (a stepper with ``block_interpolants``).
    """

    t: np.ndarray
    records: tuple
    state: Any
    failed: int = -1
    steps: Steps | None = None


class Stepper:
    """Defaults of the stepper contract (module docstring); subclasses override ``step``."""

    adaptive: bool = False
    error_order: int = 1
    blocks: bool = False
    """Whether :meth:`march_block` runs a fixed grid compiled."""
    time_axis: int = 0
    """The axis of :meth:`record`'s arrays along which samples are stacked."""
    block_steps: int | None = None
    """At most this many steps per :meth:`march_block` call (None: the whole grid)."""
    block_interpolants: bool = False
    """Whether its blocks return their steps (``Block.steps``) for events and dense output."""

    def start(self, state: Any) -> Any:
        """The stepped state for a caller's initial state (by default the same object)."""
        return state

    def step(self, t: float, state: Any, h: float) -> tuple[Any, np.ndarray | None]:
        raise NotImplementedError

    def accept(self, t: float, state: Any) -> None:
        """A step to ``(t, state)`` was accepted."""

    def interpolant(self, t_old: float, old: Any, t_new: float, new: Any) -> Callable:
        """The state between two accepted ones; by default a step from ``old`` to ``t``."""

        def sol(t: float) -> Any:
            return old if t == t_old else self.step(t_old, old, t - t_old)[0]

        return sol

    def finite(self, state: Any) -> bool:
        parts = state if isinstance(state, tuple) else (state,)
        return all(bool(np.isfinite(part).all()) for part in parts)

    def scale(self, state: Any) -> np.ndarray:
        return np.abs(state)

    adaptive_blocks: bool = False
    """Whether :meth:`march_adaptive` runs adaptive steps compiled."""

    def norm(self, error: np.ndarray, old: Any, new: Any, control: Control) -> float:
        """The weighted norm of ``error`` (Hairer's RMS over :meth:`scale`)."""
        return error_norm(error, self.scale(old), self.scale(new), control.rtol, control.atol)

    def march_adaptive(
        self, state: Any, t: float, t1: float, h: float, control: Control, every: int,
        step0: int, max_steps: float,
    ) -> AdaptiveBlock:  # fmt: skip
        raise NotImplementedError

    def failure(self, t_old: float, t_new: float) -> str:
        """Why the step from ``t_old`` to ``t_new`` gave a state that is not finite."""
        return non_finite_message(t_old, t_new)

    def record(self, state: Any) -> tuple:
        return (np.asarray(state)[None],)

    def rewind(self, block: Block | AdaptiveBlock, index: int) -> None:
        """A terminal event ended the run in step ``index`` of ``block``: forget the later
        steps (their counters)."""

    def march_block(
        self, state: Any, grid: Grid, k0: int, k1: int, every: int, step0: int
    ) -> Block:
        raise NotImplementedError


@dataclass
class AdaptiveBlock:
    """What a compiled adaptive block returns (:meth:`Stepper.march_adaptive`).

    Attributes
    ----------
    t, records, state : as in :class:`Block`
        The samples it recorded, and the state at ``t_end`` (the last accepted one).
    t_end : float
        Where it stopped.
    h : float
        The step the controller proposes next.
    n_steps, n_rejected : int
        Accepted and rejected steps in the block.
    failure : str or None
        None when it reached ``t1`` or filled its record; else why the run fails there
        (``"non-finite"`` with ``t_failed`` the end of the failed step, ``"minimum-step"``
        with ``finite`` whether its last error norm was finite).
    steps : Steps, optional
        Every accepted step (a stepper with ``block_interpolants``).
    """

    t: np.ndarray
    records: tuple
    state: Any
    t_end: float
    h: float
    n_steps: int
    n_rejected: int
    failure: str | None = None
    t_failed: float = math.nan
    finite: bool = True
    steps: Steps | None = None


@dataclass(frozen=True)
class Control:
    """Adaptive step control: tolerances and the controller (diffrax's split: the stepper
    never picks a step, the controller never sees a tableau)."""

    rtol: float
    atol: np.ndarray | float
    controller: StepController = field(default_factory=StepController)
    horizon: float | None = None
    """With the run's length ``T`` here, each step's error is held to its share ``h/T`` of
    the tolerance (error per unit step, Hairer–Nørsett–Wanner I §II.4): the local errors then
    add up to at most the tolerance over the run, so that rtol bounds the global error
    (before the dynamics amplify it) instead of each step's. None: per step, as scipy."""

    def weigh(self, norm: float, h: float) -> float:
        """The step's norm as the controller judges it (per unit step with a horizon)."""
        return norm if self.horizon is None else norm * (self.horizon / h)


Jump = tuple[float, Callable[[Any], Any]]
"""``(time, apply)``: at ``time`` the state becomes ``apply(state)`` (an impulse)."""


@dataclass
class Outcome:
    """What :func:`march` returns; the callers turn it into their result types.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Times of the recorded samples.
    records : tuple of ndarray
        The samples, stacked along the stepper's time axis.
    state : object
        The final state, at ``t[-1]``.
    status, message : Status, str
        How the run ended.
    n_steps, n_rejected : int
        Accepted and rejected steps.
    t_events, y_events : list
        Per event, the times and states where it fired.
    step_times, interpolants : list or None
        Every accepted step's end and its interpolant, with ``dense_output=True``.
    """

    t: np.ndarray
    records: tuple
    state: Any
    status: Status
    message: str
    n_steps: int
    n_rejected: int
    t_events: list[list[float]]
    y_events: list[list[Any]]
    step_times: list[float] | None
    interpolants: list[Callable] | None
