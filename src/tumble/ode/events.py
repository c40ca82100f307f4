"""Events: zero crossings of ``g(t, y)`` located on the dense output of each step.

An event is a callable ``g(t, y) -> float`` with the optional attributes of
``scipy.integrate.solve_ivp``'s events:

* ``terminal`` — ``True`` (stop at the first occurrence), or a positive int ``k`` (stop at the
  ``k``-th), default ``False``;
* ``direction`` — ``+1`` (only rising crossings, ``g`` from negative to non-negative),
  ``-1`` (only falling), ``0`` (both; default).

A crossing counts when ``g`` leaves a strictly non-zero sign: a ``g`` that starts at exactly 0
(the projectile on the ground at ``t0``) does not fire until it comes back.

**What is found.** ``g`` is sampled on the step's dense output at ``SAMPLES_PER_STEP`` equal
sub-intervals, and every sub-interval whose ends differ in sign is searched with Brent's method
to ``4 ε`` in ``t``. So all crossings of ``g`` along the dense output are found when
consecutive ones are more than ``h / SAMPLES_PER_STEP`` apart (an oscillation of ``g`` faster
than that can hide two crossings in one sub-interval, as it hides them in a step in scipy's
``solve_ivp``). The cost is ``SAMPLES_PER_STEP - 1`` evaluations of the interpolant and of every
``g`` per accepted step, and none of the right-hand side.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

Event = Callable[[float, np.ndarray], float]
_XTOL = 4 * np.finfo(float).eps
SAMPLES_PER_STEP = 4
"""Sub-intervals of each step on which the signs of the events are compared."""


def event_attributes(event: Event, index: int) -> tuple[int, float]:
    """Read ``(terminal_count, direction)`` from an event; 0 means non-terminal."""
    terminal = getattr(event, "terminal", False)
    direction = float(getattr(event, "direction", 0.0))
    if isinstance(terminal, bool | np.bool_):
        count = int(bool(terminal))
    elif isinstance(terminal, int | np.integer) and terminal > 0:
        count = int(terminal)
    else:
        raise ValueError(
            f"events[{index}].terminal={terminal!r} is not allowed: use True, False, "
            "or a positive int (stop at that occurrence)"
        )
    if direction not in (-1.0, 0.0, 1.0):
        raise ValueError(f"events[{index}].direction={direction!r} must be -1, 0 or +1")
    return count, direction


class EventTracker:
    """Watches the events over a run and records where they fire."""

    def __init__(self, events: Sequence[Event], t0: float, y0: Any):
        for index, event in enumerate(events):
            if not callable(event):
                raise ValueError(f"events[{index}]={event!r} is not callable g(t, y) -> float")
        self.events = list(events)
        attributes = [event_attributes(event, i) for i, event in enumerate(self.events)]
        self.terminal = np.array([count for count, _ in attributes], dtype=int)
        self.direction = np.array([direction for _, direction in attributes])
        self.g = self._values(t0, y0)
        self.counts = np.zeros(len(self.events), dtype=int)
        self.t_events: list[list[float]] = [[] for _ in self.events]
        self.y_events: list[list[np.ndarray]] = [[] for _ in self.events]

    def _values(self, t: float, y: np.ndarray) -> np.ndarray:
        return np.array([float(event(t, y)) for event in self.events])

    def _crossed(self, g_old: np.ndarray, g_new: np.ndarray) -> np.ndarray:
        up = (g_old < 0) & (g_new >= 0)
        down = (g_old > 0) & (g_new <= 0)
        wanted_up = up & (self.direction >= 0)
        wanted_down = down & (self.direction <= 0)
        return np.flatnonzero(wanted_up | wanted_down)

    def _root(self, i: int, t_a: float, t_b: float, g_a: float, g_b: float, sol) -> float:
        from scipy.optimize import brentq  # 0.4 s to import: only when an event fires

        def g(t: float) -> float:
            if t == t_a:
                return g_a
            if t == t_b:
                return g_b
            return float(self.events[i](t, sol(t)))

        return float(brentq(g, t_a, t_b, xtol=_XTOL, rtol=_XTOL))

    def _crossings(
        self, t_old: float, t_new: float, g_new: np.ndarray, sol: Callable[[float], Any]
    ) -> list[tuple[float, int]]:
        """Every wanted crossing in ``[t_old, t_new]``, sub-interval by sub-interval."""
        theta = np.arange(1, SAMPLES_PER_STEP) / SAMPLES_PER_STEP
        times = [*(t_old + theta * (t_new - t_old)), t_new]
        found = []
        t_a, g_a = t_old, self.g
        for t_b in times:
            g_b = g_new if t_b == t_new else self._values(t_b, sol(t_b))
            for i in self._crossed(g_a, g_b):
                found.append((self._root(i, t_a, t_b, g_a[i], g_b[i], sol), int(i)))
            t_a, g_a = t_b, g_b
        return sorted(found)

    def update(
        self, t_old: float, t_new: float, y_new: Any, sol: Callable[[float], Any]
    ) -> float | None:
        """Locate the crossings in ``[t_old, t_new]``; return a terminal event's time or None."""
        g_new = self._values(t_new, y_new)
        found = self._crossings(t_old, t_new, g_new, sol)
        self.g = g_new
        for t_root, i in found:
            self.t_events[i].append(t_root)
            self.y_events[i].append(sol(t_root))
            self.counts[i] += 1
            if self.terminal[i] and self.counts[i] >= self.terminal[i]:
                return t_root
        return None
