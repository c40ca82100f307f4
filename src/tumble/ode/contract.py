"""The driver's contract: what a stepper provides, what a run returns, and how it ended.

:func:`tumble.ode.driver.march` runs any :class:`Stepper`: its Python step, or the blocks of
its optional :class:`Compiled` part (a :class:`Block` of fixed steps on a :class:`Grid`, or
an :class:`AdaptiveBlock`). A run ends with an :class:`Outcome` and a :class:`Status` whose
message names the time; a run of many members (a batch) also with each one's
(:class:`Members`, from its blocks' :class:`Stops`). These types are re-exported by
:mod:`tumble.ode.driver`, where the contract is described in full.
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
    (``Block.steps``, from a part with :attr:`Compiled.steps`).

    Attributes
    ----------
    t : ndarray, shape (m,)
        Where each step ends (the block starts where the run stands).
    states : sequence or ndarray
        The state at each ``t``.
    interpolants : sequence of callable
        ``sol(t)`` on each step (as :meth:`Stepper.interpolant`).
    n_rejected : ndarray of int, shape (m,), optional
        Steps rejected in the block up to each accepted one (adaptive blocks).
    """

    t: np.ndarray
    states: Sequence[Any] | np.ndarray
    interpolants: Sequence[Callable]
    n_rejected: np.ndarray | None = None


@dataclass
class Stops:
    """Where the members of a block stopped (``Block.stops``): a stepper that marches many
    members at once (the bodies of a batch), each of which stops alone.

    Attributes
    ----------
    recorded : ndarray of int, shape (N,)
        The samples each member recorded in the block: all of the block's, unless it stopped
        in it (then those before), or before it (then 0).
    failed : ndarray of int, shape (N,)
        For a member that stopped in this block, the grid step whose result was not finite
        (its state is left at the step before, and no later block marches it); else -1.
    messages : dict of int to str
        Why, for those of them whose reason is not a non-finite state (by default
        :func:`non_finite_message`).
    """

    recorded: np.ndarray
    failed: np.ndarray
    messages: dict[int, str] = field(default_factory=dict)


@dataclass
class Block:
    """What a compiled block of steps returns (:attr:`Compiled.march_block`).

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
        Every accepted step (a part with :attr:`Compiled.steps`).
    message : str, optional
        Why the block stopped at ``failed``, if not a non-finite state (an unconverged
        implicit solve, an energy past its bound).
    stops : Stops, optional
        Where its members stopped, for a stepper of many members (they stop alone:
        ``failed`` stays -1).
    """

    t: np.ndarray
    records: tuple
    state: Any
    failed: int = -1
    steps: Steps | None = None
    message: str | None = None
    stops: Stops | None = None


def finite(state: Any) -> bool:
    """Whether every number of ``state`` (an array, or a tuple of arrays) is finite."""
    parts = state if isinstance(state, tuple) else (state,)
    return all(bool(np.isfinite(part).all()) for part in parts)


class Compiled(NamedTuple):
    """A stepper's compiled part (:attr:`Stepper.compiled`): it marches blocks of steps in
    compiled code, with no Python per step (the driver's module docstring: the contract).

    Attributes
    ----------
    march_block : callable
        ``march_block(state, grid, k0, k1, every, step0) -> Block``: steps ``k0 + 1 … k1``
        of a fixed :class:`Grid`, recording step ``k`` when ``step0 + k`` is a multiple of
        ``every``.
    march_adaptive : callable, optional
        ``march_adaptive(state, t, t1, h, control, every, step0, max_steps) ->
        AdaptiveBlock``: adaptive steps from ``t`` towards ``t1``. None: adaptive runs step
        in Python.
    rewind : callable, optional
        ``rewind(block, index)``: a terminal event ended the run in step ``index`` of
        ``block``; forget what was counted for its later steps. None: nothing to forget.
    steps : bool
        Whether its blocks return their steps (``Block.steps``), so that runs with events,
        dense output or ``t_eval`` march compiled too. Without, they step in Python.
    block_steps : int, optional
        At most this many steps per ``march_block`` call (None: as many as the run allows).
    """

    march_block: Callable[..., Block]
    march_adaptive: Callable[..., AdaptiveBlock] | None = None
    rewind: Callable[[Any, int], None] | None = None
    steps: bool = False
    block_steps: int | None = None

    def takes(self, adaptive: bool, follows: bool) -> bool:
        """Whether it marches a run, adaptive or not, whose steps are followed (events,
        dense output, ``t_eval``) or not: the one question the driver asks."""
        return (self.march_adaptive is not None or not adaptive) and (self.steps or not follows)


class Stepper:
    """A stepper of :func:`~tumble.ode.driver.march`: one step in Python, and an optional
    compiled part (the driver's module docstring: the contract). Subclasses override
    :meth:`step`; the rest are defaults."""

    error_order: int = 1
    """The order ``q`` of :meth:`step`'s error estimate (the controller's exponent is
    ``1/(q + 1)``)."""
    time_axis: int = 0
    """The axis of :meth:`record`'s arrays along which samples are stacked (1 for a stepper
    of many members, whose records put the members first)."""

    @property
    def compiled(self) -> Compiled | None:
        """The compiled part, or None: every run steps in Python. A stepper that has one
        makes it when asked (a property): a part kept on the stepper would hold its bound
        methods, and so the stepper, in a reference cycle that only the garbage collector
        frees, with the run's arrays (measured: short compiled calls 10–20 % slower)."""
        return None

    def step(self, t: float, state: Any, h: float) -> tuple[Any, np.ndarray | None]:
        """One step of ``h`` from ``(t, state)``: the new state and its error estimate (or
        None); ``state`` is left unchanged."""
        raise NotImplementedError

    def accept(self, t_old: float, old: Any, t_new: float, new: Any) -> str | None:
        """Take the accepted step to ``(t_new, new)``, or refuse it: why (the run then fails
        there, with ``old``). By default a state that is not finite is refused."""
        return None if finite(new) else non_finite_message(t_old, t_new)

    def interpolant(self, t_old: float, old: Any, t_new: float, new: Any) -> Callable:
        """The state between two accepted ones; by default a step from ``old`` to ``t``."""

        def sol(t: float) -> Any:
            return old if t == t_old else self.step(t_old, old, t - t_old)[0]

        return sol

    def norm(self, error: np.ndarray, old: Any, new: Any, control: Control) -> float:
        """The weighted norm of ``error`` (Hairer's RMS relative to ``|old|`` and ``|new|``,
        :func:`~tumble.ode.control.error_norm`)."""
        return error_norm(error, old, new, control.rtol, control.atol)

    def record(self, state: Any) -> tuple:
        """One sample: arrays with a time axis of length 1 at :attr:`time_axis`."""
        return (np.asarray(state)[None],)


@dataclass
class AdaptiveBlock:
    """What a compiled adaptive block returns (:attr:`Compiled.march_adaptive`).

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
        Every accepted step (a part with :attr:`Compiled.steps`).
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
class Members:
    """Per member of a run of many members (``Outcome.members``), as the driver made it
    from its blocks' :class:`Stops`.

    Attributes
    ----------
    status : ndarray of int, shape (N,)
        :class:`Status` codes: ``FAILED`` for a member that stopped, else the run's.
    messages : list of str
        Why each stopped (its step named), else the run's message.
    n_steps : ndarray of int, shape (N,)
        Accepted steps each took.
    n_recorded : ndarray of int, shape (N,)
        Its valid samples, the first ones of the record (the rows after are NaN); the last
        is its last finite state.
    t_last : ndarray, shape (N,)
        The time of that last valid sample: for a member that stopped, the time of its last
        finite state, between two recorded times when ``record_every > 1``.
    """

    status: np.ndarray
    messages: list[str]
    n_steps: np.ndarray
    n_recorded: np.ndarray
    t_last: np.ndarray


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
    members : Members or None
        Per member, for a stepper of many members (its blocks report :class:`Stops`).
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
    members: Members | None = None
