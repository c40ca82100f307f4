"""The one stepping driver: :func:`march` takes any stepper over a span.

Every time loop in tumble is this one: ``solve`` (a Runge–Kutta tableau on a vector),
``simulate`` (a rigid-body chart, in Python or in compiled blocks), ``simulate_batch`` (many
bodies at once, in compiled blocks) and the structural schemes (one factorised solve a step). What
differs is the *stepper*; what the run does around the steps is written once, here.

The stepper's contract
----------------------
A stepper (:class:`Stepper` gives the defaults) is four methods and the record of a state:

``step(t, state, h) -> (new_state, error)``
    One step from ``state`` at ``t``. ``error`` is the local error estimate (an array that
    :meth:`~Stepper.norm` weighs) or None; an adaptive run needs it. It must not change
    ``state``: the driver may need it again (events, a rejected step).
``accept(t_old, old, t_new, new) -> None or str``
    The driver accepts the step to ``(t_new, new)``: the stepper takes it (first-same-as-last
    data, counters), or refuses it with the reason, and the run fails there with that
    message and the state ``old``. By default a state that is not finite is refused
    (:func:`non_finite_message`); an implicit stepper names its unconverged solve, a
    structural one the energy that outgrew its bound (:mod:`tumble.structural.divergence`).
``interpolant(t_old, old, t_new, new) -> sol``
    ``sol(t)`` for ``t`` in ``[t_old, t_new]``: the state between the two (the dense output
    that events are located on). Called only after ``accept``.
``norm(error, old, new, control) -> float``
    The weighted size of a step's error estimate (by default Hairer's RMS norm,
    :func:`~tumble.ode.control.error_norm`); a step is accepted when it is at most 1. A
    stepper whose state has parts of different kinds (an attitude and vectors) says here
    what the tolerances measure. ``error_order`` is the estimate's order ``q`` (the
    controller's exponent is ``1/(q + 1)``).
``record(state) -> tuple of ndarray``
    One sample: each array with a time axis of length 1 at ``time_axis`` (by default
    ``(state[None],)`` and 0).

The compiled part
-----------------
``Stepper.compiled`` is None, or a :class:`Compiled`: blocks of steps in compiled code, so a
kernel runs thousands of steps per call with no Python per step. The driver asks it one
question, :meth:`Compiled.takes`: does it march this run (adaptive or not, its steps followed
by events, dense output or ``t_eval`` or not)? If so, the run marches in its blocks, else in
Python steps. What the part gives:

``march_block(state, grid, k0, k1, every, step0) -> Block``
    Steps ``k0 + 1 … k1`` of a fixed grid at once, recording every step ``k`` with
    ``step0 + k`` a multiple of ``every``. ``Block.failed`` is the step that failed (as
    ``accept`` would have refused it), the block's state the one before, ``Block.message``
    why if not a non-finite state. A block ends on a recorded step wherever one lies within
    it (or at the grid's end), so that a loop which settles its state only where it records
    or returns (the axes flow's merged half turns) gives the numbers of one block, as every
    part must (the rigid ones go on from their loop's arrays, not packing again the state
    they handed back).
``march_adaptive(state, t, t1, h, control, every, step0, max_steps) -> AdaptiveBlock``
    (optional) Adaptive steps from ``t`` towards ``t1``, with the same controller, norm and
    minimum step as the driver; it returns at ``t1``, at a failure, after ``max_steps``
    steps, or when its record is full (then the driver calls it again). ``h = 0`` asks it to
    choose the first step (``march(h=None)``).
``steps``, ``rewind(block, index)`` (optional)
    With ``steps``, each block also returns its accepted steps, ``Block.steps``
    (:class:`Steps`: every step's end, state and interpolant), so that runs with events,
    dense output or ``t_eval`` march in blocks too. The driver follows each block's steps
    after it returns, as it follows one Python step (events located on the interpolants by
    the same :class:`~tumble.ode.events.EventTracker`, the interpolants kept, ``t_eval``
    sampled); with events a block takes at most :data:`EVENT_BLOCK` steps, so a terminal
    event costs at most one block of steps beyond it. A terminal event in step ``i`` of a
    block cuts the record there and ends the run at the event with the counters of that
    step, and ``rewind(block, i)`` lets the part forget what it counted for the later steps.
``block_steps`` (optional)
    At most this many steps per ``march_block`` call (memory, or Ctrl-C between blocks).

Many members
------------
A stepper may march many independent members at once (the bodies of
:func:`~tumble.rigid.simulate_batch`): its state and records carry the members first
(``time_axis = 1``), and its blocks say in ``Block.stops`` (:class:`Stops`) which members
stopped in them, at which step and why; such a member stops alone, its state left at its
last finite one, which no later block marches. The driver keeps each member's account over
the blocks and ends the run with ``Outcome.members`` (:class:`Members`): per member its
status and message (its step named), its steps, its valid samples and their last time. In
the record, a stopped member's last finite state follows its recorded samples (unless the
last of them is that state) and its later rows are NaN. A block ends on a recorded step, so
a batch gives the same numbers bit for bit in one block or in many.

What :func:`march` guarantees
-----------------------------
* Steps land exactly on ``t1`` and on every jump time (a fixed grid restarts at each).
* ``h`` is the step of a fixed-step run; for an adaptive run (``control`` given) the first
  step, then the :class:`~tumble.ode.control.StepController` proposes each next one from the
  weighted norm (:meth:`Stepper.norm`, weighed by :meth:`Control.weigh`); a rejected step is
  retried from the accepted state. A step shortened to land on an end (``t1`` or a jump)
  hands on the step it was planned as, not the proposal from its own, shorter, error. A step
  below :func:`~tumble.ode.control.minimum_step` ends the run.
* The record holds the initial state, every ``record_every``-th accepted step (counted over
  the whole run) and the final state; after a jump the state at the jump's time replaces the
  sample taken just before it.
* A non-finite state, or a step the stepper refuses, ends the run with
  :attr:`Status.FAILED` and a message naming the step; the record and the final state are
  the last finite ones.
* ``max_steps`` accepted steps end the run with :attr:`Status.FAILED`.
* Events ``g(t, state)`` are located by :class:`~tumble.ode.events.EventTracker` on the
  stepper's interpolant; a terminal event ends the run there with
  :attr:`Status.TERMINAL_EVENT`.
* With ``t_eval``, the record holds the state at exactly those times (each step's
  interpolant between the steps) instead of every ``record_every``-th step.
* A compiled part gives the run that Python steps would: the same steps, record, status,
  message, counters, events and interpolants.
* ``progress(t)`` is called as the run goes (per block, per jump segment, every
  :data:`PROGRESS_EVERY` Python steps).

References
----------
.. [1] E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*,
   2nd ed., Springer, 1993, §II.4 (step control), §II.6 (dense output).
.. [2] scipy's ``OdeSolver`` (a written contract for steppers) and diffrax's ``RESULTS``
   (a status type whose values carry their messages).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from tumble import _checks
from tumble.ode.contract import (
    AdaptiveBlock,
    Block,
    Compiled,
    Control,
    Grid,
    Jump,
    Members,
    Outcome,
    Status,
    Stepper,
    Steps,
    Stops,
    max_steps_message,
    non_finite_message,
)
from tumble.ode.control import (
    fixed_step_count,
    minimum_step,
)
from tumble.ode.events import Event, EventTracker

__all__ = [
    "AdaptiveBlock",
    "Block",
    "Compiled",
    "Control",
    "Grid",
    "Jump",
    "Members",
    "Outcome",
    "Status",
    "Stepper",
    "Steps",
    "Stops",
    "check_record_size",
    "march",
    "max_steps_message",
    "non_finite_message",
]

PROGRESS_EVERY = 256
"""A Python-stepped run reports its progress every this many steps."""

PROGRESS_BLOCKS = 50
"""A compiled run with a progress bar marches in about this many blocks (at most one per
recorded sample: each block a whole number of them)."""

EVENT_BLOCK = 256
"""With events, a compiled block takes at most this many steps (a terminal event found after
the block costs at most these steps beyond it)."""

RECORD_MEMORY_SHARE = 0.5
"""A fixed-step run is refused up front when its record would need more than this share of the
machine's memory."""


class _Run:
    """One run's current state, counters, record and events."""

    def __init__(
        self,
        stepper: Stepper,
        t0: float,
        state: Any,
        events: list[Event],
        record_every: int,
        max_steps: float,
        dense: bool,
        progress: Callable[[float], None] | None,
        t_eval: np.ndarray | None = None,
    ):
        self.stepper, self.t, self.state = stepper, t0, state
        self.every, self.max_steps, self.progress = record_every, max_steps, progress
        self.n_steps = self.n_rejected = 0
        self.status, self.message = Status.SUCCESS, Status.SUCCESS.message
        self.tracker = EventTracker(events, t0, state) if events else None
        self.step_times: list[float] | None = [t0] if dense else None
        self.interpolants: list[Callable] | None = [] if dense else None
        self.times: list[np.ndarray] = []
        self.samples: list[tuple] = []
        self.members: _Members | None = None
        self.t_eval, self.next_eval = t_eval, 0
        if t_eval is None or t_eval[0] == t0:
            self.record()
            self.next_eval = 1

    def fail(self, message: str) -> None:
        self.status, self.message = Status.FAILED, message

    def max_steps_message(self) -> str:
        return max_steps_message(self.max_steps, self.t)

    def record(self) -> None:
        """Sample the current state (replacing a sample at the same time: before a jump)."""
        if self.times and self.times[-1][-1] == self.t:
            axis = self.stepper.time_axis
            self.times[-1] = self.times[-1][:-1]
            self.samples[-1] = tuple(np.delete(a, -1, axis=axis) for a in self.samples[-1])
        self.times.append(np.array([self.t]))
        self.samples.append(self.stepper.record(self.state))

    def sample(self, t_new: float, new: Any, sol: Callable) -> None:
        """Record the requested times in ``(t, t_new]`` from the step's interpolant."""
        t_eval, k = self.t_eval, self.next_eval
        assert t_eval is not None
        while k < len(t_eval) and t_eval[k] <= t_new:
            state = new if t_eval[k] == t_new else sol(float(t_eval[k]))
            self.times.append(t_eval[k : k + 1].copy())
            self.samples.append(self.stepper.record(state))
            k += 1
        self.next_eval = k

    def extend(self, block: Block | AdaptiveBlock) -> None:
        if len(block.t):
            self.times.append(block.t)
            self.samples.append(block.records)

    @property
    def follows(self) -> bool:
        """Whether each step's interpolant is needed (events, dense output, ``t_eval``)."""
        return self.tracker is not None or self.interpolants is not None or self.t_eval is not None

    def follow(self, t_old: float, t_new: float, new: Any, sol: Callable) -> tuple[float, Any]:
        """Events, dense output and ``t_eval`` on one accepted step's interpolant ``sol``;
        the step's end, moved to a terminal event if one fired (the status then says so)."""
        if self.tracker is not None:
            t_stop = self.tracker.update(t_old, t_new, new, sol)
            if t_stop is not None:
                t_new, new = t_stop, sol(t_stop)
                self.status = Status.TERMINAL_EVENT
                self.message = Status.TERMINAL_EVENT.message
        if self.interpolants is not None and self.step_times is not None:
            self.interpolants.append(sol)
            self.step_times.append(t_new)
        if self.t_eval is not None:
            self.sample(t_new, new, sol)
        return t_new, new

    def accept(self, t_old: float, old: Any, t_new: float, new: Any) -> bool:
        """Take a step the stepper accepted; True when the run must stop (a terminal event)."""
        if self.tracker is not None or self.interpolants is not None or self.t_eval is not None:
            sol = self.stepper.interpolant(t_old, old, t_new, new)
            t_new, new = self.follow(t_old, t_new, new, sol)
        self.t, self.state = t_new, new
        self.n_steps += 1
        if self.t_eval is None and self.n_steps % self.every == 0:
            self.record()
        if self.progress is not None and self.n_steps % PROGRESS_EVERY == 0:
            self.progress(t_new)
        return self.status == Status.TERMINAL_EVENT

    def stops(self, stops: Stops, grid: Grid, k0: int) -> None:
        """Where members stopped in a block from grid step ``k0`` (the record and the
        counters still at the block's start)."""
        if self.members is None:
            self.members = _Members(len(stops.failed), sum(len(t) for t in self.times))
        self.members.stop(stops, grid, self.n_steps - k0)

    def outcome(self) -> Outcome:
        if self.t_eval is None and self.times[-1][-1] != self.t:
            self.record()
        if not self.samples:  # t_eval asked for no time the run reached
            empty = self.stepper.record(self.state)
            axis = self.stepper.time_axis
            self.times.append(np.empty(0))
            self.samples.append(tuple(np.delete(a, 0, axis=axis) for a in empty))
        axis = self.stepper.time_axis
        records = tuple(
            np.concatenate(parts, axis=axis) for parts in zip(*self.samples, strict=True)
        )
        t = np.concatenate(self.times)
        members = None
        if self.members is not None:
            last = self.stepper.record(self.state)
            members = self.members.outcome(self, t, records, last)
        tracker = self.tracker
        return Outcome(
            t=t,
            records=records,
            state=self.state,
            status=self.status,
            message=self.message,
            n_steps=self.n_steps,
            n_rejected=self.n_rejected,
            t_events=tracker.t_events if tracker else [],
            y_events=tracker.y_events if tracker else [],
            step_times=self.step_times,
            interpolants=self.interpolants,
            members=members,
        )


class _Members:
    """Each member's account over a run's blocks (many members: module docstring)."""

    def __init__(self, n: int, recorded: int):
        self.recorded = np.full(n, recorded, dtype=np.int64)  # samples so far
        self.n_steps = np.full(n, -1, dtype=np.int64)  # steps of a stopped member; -1: going
        self.t_last = np.full(n, math.nan)  # the time of its last finite state
        self.messages: dict[int, str] = {}

    def stop(self, stops: Stops, grid: Grid, step0: int) -> None:
        """A block's :class:`Stops`, on ``grid`` whose step ``k`` is the run's ``step0 + k``."""
        self.recorded += stops.recorded
        for k in np.flatnonzero(stops.failed >= 0).tolist():
            step = int(stops.failed[k])
            t_old, t_new = grid.time(step - 1), grid.time(step)
            self.n_steps[k], self.t_last[k] = step0 + step - 1, t_old
            self.messages[k] = stops.messages.get(k) or non_finite_message(t_old, t_new)

    def outcome(self, run: _Run, t: np.ndarray, records: tuple, last: tuple) -> Members:
        """The members' outcome; each stopped one's record ended in place: its last finite
        state (``last``, a record of the run's state, which holds it) after its samples
        unless the last of them is that state, NaN after."""
        stopped = self.n_steps >= 0
        n_recorded = np.where(stopped, self.recorded, len(t))
        for k in np.flatnonzero(stopped).tolist():
            row = int(n_recorded[k])
            if t[row - 1] != self.t_last[k]:
                for array, sample in zip(records, last, strict=True):
                    array[k, row] = sample[k, 0]
                n_recorded[k] += 1
            for array in records:
                array[k, n_recorded[k] :] = np.nan
        return Members(
            status=np.where(stopped, int(Status.FAILED), int(run.status)),
            messages=[self.messages.get(k, run.message) for k in range(len(stopped))],
            n_steps=np.where(stopped, self.n_steps, run.n_steps),
            n_recorded=n_recorded,
            t_last=np.where(stopped, self.t_last, run.t),
        )


def _fixed(run: _Run, t1: float, h: float) -> bool:
    """Step in Python over the grid from ``run.t`` to ``t1``; False when the run ended."""
    stepper, grid = run.stepper, Grid(run.t, t1, h, fixed_step_count(run.t, t1, h))
    for k in range(1, grid.n + 1):
        if run.n_steps >= run.max_steps:
            run.fail(run.max_steps_message())
            return False
        t_old, old, t_new = run.t, run.state, grid.time(k)
        new, _ = stepper.step(t_old, old, t_new - t_old)
        refused = stepper.accept(t_old, old, t_new, new)
        if refused is not None:
            run.fail(refused)
            return False
        if run.accept(t_old, old, t_new, new):
            return False
    return True


def _adaptive(run: _Run, t1: float, h: float, control: Control) -> tuple[bool, float]:
    """Step with the controller from ``run.t`` to ``t1``; (going on, the next step)."""
    stepper, order = run.stepper, run.stepper.error_order
    rejected = False
    while run.t < t1:
        if run.n_steps >= run.max_steps:
            run.fail(run.max_steps_message())
            return False, h
        t_old, old = run.t, run.state
        h_min = minimum_step(t_old)
        planned = max(h, h_min)
        t_new = min(t_old + planned, t1)
        new, error = stepper.step(t_old, old, t_new - t_old)
        if error is None:
            raise TypeError(f"{type(stepper).__name__}.step returned no error estimate")
        norm = control.weigh(stepper.norm(error, old, new, control), t_new - t_old)
        accepted, h = control.controller.propose(
            t_new - t_old, norm, order, after_rejection=rejected
        )
        if accepted and t_new == t1 < t_old + planned:
            h = planned  # shortened to land on t1: its (round-off-level) norm does not count
        rejected = not accepted
        if not accepted:
            run.n_rejected += 1
            if h < h_min:
                run.fail(_minimum_step_message(t_old, h_min, math.isfinite(norm)))
                return False, h
            continue
        refused = stepper.accept(t_old, old, t_new, new)
        if refused is not None:
            run.fail(refused)
            return False, h
        if run.accept(t_old, old, t_new, new):
            return False, h
    return True, h


def _adaptive_blocks(
    run: _Run, part: Compiled, t1: float, h: float, control: Control
) -> tuple[bool, float]:
    """:func:`_adaptive` in the compiled ``part``'s blocks; (going on, the next step)."""
    assert part.march_adaptive is not None
    while run.t < t1:
        allowed = run.max_steps - run.n_steps
        if run.tracker is not None:
            allowed = min(allowed, EVENT_BLOCK)
        block = part.march_adaptive(
            run.state, run.t, t1, h, control, run.every, run.n_steps, allowed
        )
        if not _take(run, part, block):
            return False, block.h
        run.n_steps += block.n_steps
        run.n_rejected += block.n_rejected
        run.t, run.state, h = block.t_end, block.state, block.h
        if block.failure == "non-finite":
            run.fail(non_finite_message(run.t, block.t_failed))
            return False, h
        if block.failure == "minimum-step":
            run.fail(_minimum_step_message(run.t, minimum_step(run.t), block.finite))
            return False, h
        if run.n_steps >= run.max_steps and run.t < t1:
            run.fail(run.max_steps_message())
            return False, h
        if run.progress is not None:
            run.progress(run.t)
    return True, h


def _take(run: _Run, part: Compiled, block: Block | AdaptiveBlock) -> bool:
    """Keep a block's record and, if the run follows its steps (events, dense output,
    ``t_eval``), follow them: False when a terminal event ended the run in the block (the
    record is then cut there, the run stands at the event, with that step's counters)."""
    if not run.follows:
        run.extend(block)
        return True
    steps = block.steps
    if steps is None:
        raise TypeError(f"{type(run.stepper).__name__}'s blocks returned no steps")
    t_old = run.t
    for i, sol in enumerate(steps.interpolants):
        t_new, new = run.follow(t_old, float(steps.t[i]), steps.states[i], sol)
        if run.status == Status.TERMINAL_EVENT:
            kept = block.t < steps.t[i]
            axis = run.stepper.time_axis
            cut = tuple(np.compress(kept, array, axis=axis) for array in block.records)
            if run.t_eval is None:
                run.extend(Block(block.t[kept], cut, new))
            run.n_steps += i + 1
            run.n_rejected += 0 if steps.n_rejected is None else int(steps.n_rejected[i])
            run.t, run.state = t_new, new
            if part.rewind is not None:
                part.rewind(block, i)
            return False
        t_old = t_new
    if run.t_eval is None:
        run.extend(block)
    return True


def _minimum_step_message(t: float, h_min: float, finite: bool) -> str:
    """Why an adaptive run stopped at the minimum step: accuracy, or a non-finite state."""
    if finite:
        return f"step size fell below the minimum {h_min:.3g} at t={t!r}"
    return (
        f"the state became non-finite (nan or inf) in every step tried from t={t!r}, down to "
        f"the minimum step {h_min:.3g}: something the run evaluates (a load, the right-hand "
        "side) is not finite just after that time; the run ends with the last finite state"
    )


def _block_end(k0: int, size: int, last: int, step0: int, every: int) -> int:
    """Where a block from grid step ``k0`` ends: ``size`` steps on, at most at ``last``, and
    back to the last recorded step within it (``step0 + k`` a multiple of ``every``) if there
    is one, so that a loop which settles its state only where it records or returns (the
    axes flow's merged half turns) gives the same numbers whatever the blocks."""
    k1 = min(k0 + size, last)
    recorded = k1 - (step0 + k1) % every
    return recorded if k1 < last and recorded > k0 else k1


def _blocks(run: _Run, part: Compiled, t1: float, h: float) -> bool:
    """March the grid from ``run.t`` to ``t1`` in the compiled ``part``'s blocks; False
    when the run ended."""
    grid = Grid(run.t, t1, h, fixed_step_count(run.t, t1, h))
    last = grid.n if run.max_steps - run.n_steps >= grid.n else int(run.max_steps) - run.n_steps
    size = grid.n
    if run.progress is not None:  # whole recorded samples: blocks may end on recorded steps
        size = min(size, -(-max(1, grid.n // PROGRESS_BLOCKS) // run.every) * run.every)
    size = min(size, part.block_steps or size)
    if run.tracker is not None:
        size = min(size, EVENT_BLOCK)
    k0 = 0
    while k0 < last:
        step0 = run.n_steps - k0
        k1 = _block_end(k0, size, last, step0, run.every)
        block = part.march_block(run.state, grid, k0, k1, run.every, step0)
        if block.stops is not None:
            run.stops(block.stops, grid, k0)
        if not _take(run, part, block):
            return False
        done = k1 if block.failed < 0 else block.failed - 1
        run.n_steps += done - k0
        run.t, run.state = grid.time(done), block.state
        if block.failed >= 0:
            run.fail(block.message or non_finite_message(run.t, grid.time(block.failed)))
            return False
        if run.progress is not None:
            run.progress(run.t)
        k0 = k1
    if last < grid.n:
        run.fail(run.max_steps_message())
        return False
    return True


def check_record_size(
    span: float, h: float, every: int, max_steps: float, sample: tuple, n_jumps: int = 0
) -> None:
    """Refuse a fixed-step run whose record would not fit in memory, before it starts.

    ``sample`` is one recorded state (:meth:`Stepper.record`); the record holds about
    ``min(span / h, max_steps) / every + 1`` of them, plus one per jump, and their times.

    Raises
    ------
    ValueError
        Naming ``h``, the number of samples, the memory they need and what allows; the remedy
        is ``record_every``, a larger ``h`` or a shorter run.
    """
    steps = min(float(span) / float(h), max_steps)  # Python floats: inf, no warning
    samples = steps / every + 1 + n_jumps
    per_sample = 8 + sum(np.asarray(part).nbytes for part in sample)
    need, allowed = samples * per_sample, RECORD_MEMORY_SHARE * _memory()
    if need <= allowed:
        return
    message = (
        f"h={h!r} over {span!r} s would record {samples:.3g} samples of {per_sample} bytes "
        f"({_checks._byte_size(need)}), more than the {_checks._byte_size(allowed)} (half of "
        "this machine's memory) that a record may take"
    )
    if steps > 1e13:  # a week of steps at 0.1 µs each: the step, not the record, is wrong
        raise ValueError(f"{message}; {steps:.3g} steps would never finish: raise h")
    smallest = math.ceil(steps * per_sample / allowed)
    raise ValueError(
        f"{message}; record fewer samples with record_every >= {smallest}, or raise h, or "
        "shorten the run"
    )


_memory = _checks.memory  # this machine's memory (bytes); a module name tests can set


def _segments(t0: float, t1: float, jumps: Sequence[Jump]) -> list[tuple[float, list]]:
    """``[(end, jumps applied at the end), ...]``: the span cut at the jumps' times."""
    if not jumps:
        return [(t1, [])]
    times = sorted({time for time, _ in jumps if t0 <= time <= t1} | {t1})
    return [(b, [apply for time, apply in jumps if time == b]) for b in times]


def march(
    stepper: Stepper,
    t_span: tuple[float, float],
    state: Any,
    *,
    h: float | None,
    control: Control | None = None,
    events: Sequence[Event] = (),
    jumps: Sequence[Jump] = (),
    record_every: int = 1,
    max_steps: int | None = None,
    dense_output: bool = False,
    progress: Callable[[float], None] | None = None,
    t_eval: np.ndarray | None = None,
) -> Outcome:
    """March ``stepper`` from ``state`` at ``t_span[0]`` to ``t_span[1]``.

    Parameters
    ----------
    stepper : Stepper
        What makes one step (module docstring: the contract).
    t_span : (float, float)
        ``(t0, t1)``, ``t1 > t0``: checked by the caller.
    state : object
        The state at ``t0``, of the stepper's type.
    h : float or None
        The fixed step, or an adaptive run's first step (None: the first block of the
        stepper's compiled part chooses it; only with its ``march_adaptive``).
    control : Control, optional
        Tolerances and controller: the run is adaptive. None: fixed steps of ``h``.
    events : sequence of callables
        ``g(t, state)``, with ``terminal`` and ``direction`` as in ``solve_ivp``.
    jumps : sequence of (float, callable)
        Maps applied to the state at given times (a step lands on each).
    record_every : int
        Record every this many accepted steps (and the first and last state).
    max_steps : int, optional
        Accepted steps allowed; no limit by default.
    dense_output : bool
        Keep every step's interpolant.
    progress : callable, optional
        ``progress(t)``, called as the run advances.
    t_eval : ndarray, shape (k,), optional
        Record the state at these times only (sorted, within ``t_span``; checked by the
        caller), from each step's interpolant.

    Returns
    -------
    Outcome
        The record, the final state, the status and message, the counters and events.

    Examples
    --------
    Explicit Euler on ``y' = −y`` as a stepper of two lines:

    >>> class Euler(Stepper):
    ...     def step(self, t, y, h):
    ...         return y - h * y, None
    >>> out = march(Euler(), (0.0, 1.0), np.array([1.0]), h=0.25, record_every=2)
    >>> out.t.tolist(), out.records[0][:, 0].tolist(), out.status
    ([0.0, 0.5, 1.0], [1.0, 0.5625, 0.31640625], <Status.SUCCESS: 0>)
    """
    t0, t1 = t_span
    follows = bool(events) or dense_output or t_eval is not None
    part = stepper.compiled
    if part is not None and not part.takes(control is not None, follows):
        part = None  # the run steps in Python
    if h is None and (control is None or part is None):  # the caller chooses it, checks it
        raise TypeError("march needs h: the fixed step, or an adaptive run's first step")
    step = 0.0 if h is None else float(h)  # 0: the first compiled block chooses it
    limit = math.inf if max_steps is None else max_steps
    run = _Run(stepper, t0, state, list(events), record_every, limit, dense_output, progress,
               t_eval)  # fmt: skip
    if control is None and t_eval is None:
        check_record_size(t1 - t0, step, record_every, limit, run.samples[0], len(jumps))
    going = True
    for end, applied in _segments(t0, t1, jumps):
        if run.t < end:
            if control is None:
                going = _fixed(run, end, step) if part is None else _blocks(run, part, end, step)
            elif part is None:
                going, step = _adaptive(run, end, step, control)
            else:
                going, step = _adaptive_blocks(run, part, end, step, control)
        if not going:
            break
        for apply in applied:
            run.state = apply(run.state)
        if applied and (t_eval is None or run.t in t_eval):
            run.record()
        if progress is not None:
            progress(run.t)
    return run.outcome()
