"""Events: zero crossings of ``g(t, y)`` located on the dense output of each step.

An event is a callable ``g(t, y) -> float`` with the optional attributes of
``scipy.integrate.solve_ivp``'s events:

* ``terminal`` — ``True`` (stop at the first occurrence), or a positive int ``k`` (stop at the
  ``k``-th), default ``False``;
* ``direction`` — ``+1`` (only rising crossings, ``g`` from negative to non-negative),
  ``-1`` (only falling), ``0`` (both; default).

A crossing counts when ``g`` leaves a strictly non-zero sign: a ``g`` that starts at exactly 0
(the projectile on the ground at ``t0``) does not fire until it comes back.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

Event = Callable[[float, np.ndarray], float]
_XTOL = 4 * np.finfo(float).eps


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

    def _crossed(self, g_new: np.ndarray) -> np.ndarray:
        up = (self.g < 0) & (g_new >= 0)
        down = (self.g > 0) & (g_new <= 0)
        wanted_up = up & (self.direction >= 0)
        wanted_down = down & (self.direction <= 0)
        return np.flatnonzero(wanted_up | wanted_down)

    def _root(self, i: int, t_old: float, t_new: float, g_new: float, sol) -> float:
        from scipy.optimize import brentq  # 0.4 s to import: only when an event fires

        g_old = self.g[i]

        def g(t: float) -> float:
            if t == t_old:
                return g_old
            if t == t_new:
                return g_new
            return float(self.events[i](t, sol(t)))

        return float(brentq(g, t_old, t_new, xtol=_XTOL, rtol=_XTOL))

    def update(
        self, t_old: float, t_new: float, y_new: Any, sol: Callable[[float], Any]
    ) -> float | None:
        """Locate the crossings in ``[t_old, t_new]``; return a terminal event's time or None."""
        g_new = self._values(t_new, y_new)
        found = sorted(
            (self._root(i, t_old, t_new, g_new[i], sol), i) for i in self._crossed(g_new)
        )
        self.g = g_new
        for t_root, i in found:
            self.t_events[i].append(t_root)
            self.y_events[i].append(sol(t_root))
            self.counts[i] += 1
            if self.terminal[i] and self.counts[i] >= self.terminal[i]:
                return t_root
        return None
