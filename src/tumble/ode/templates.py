"""The loops that advance time in compiled code: one fixed-step and one adaptive template.

A family of methods (a chart of the rigid body, a splitting, …) does not write a loop. It
contributes numba functions, and :func:`bind` compiles a template with them as its globals:

=============  ===========================================================================
name           what it does
=============  ===========================================================================
``WORK``       ``WORK(problem, state) -> work``: the scratch arrays, made once per call
``STEP``       ``STEP(problem, state, work, t, h, settle) -> cause``: one fixed step in
               place (``settle``: this step's end is recorded or handed back); a cause
               other than :data:`OK` leaves the state at the step before
``TRY``        ``TRY(problem, state, work, t, h, share) -> norm``: one adaptive try into
               ``work`` (the state untouched) and its error norm per unit step ``share``
``FINITE``     ``FINITE(problem, state, work) -> bool``: whether the tried state is finite
``ACCEPT``     ``ACCEPT(problem, state, work, fsal) -> has_first``: the tried state becomes
               the state; returns whether the next try knows its first stage (FSAL)
``RECORD``     ``RECORD(problem, state, records, i)``: sample ``i`` (``records.t[i]`` is
               written by the loop)
=============  ===========================================================================

Both loops land steps on :func:`~tumble.ode.control.grid_time` (fixed) or on ``t1``
(adaptive), record step ``k`` when ``step0 + k`` is a multiple of ``every``, and stop with
one of the causes below, which :func:`tumble.ode.driver.march` turns into a
:class:`~tumble.ode.driver.Status` and a message. The adaptive loop is the driver's adaptive
loop (:func:`~tumble.ode.control.step_factor`, :func:`~tumble.ode.control.minimum_step`,
compiled from those very functions), so the Python and compiled paths cannot drift apart.

numba inlines the bound functions (``inline="always"``), so a family's loop compiles to what
a hand-written loop would; and since :func:`bind` gives each binding a name of its own, each
is cached on disk like any ``cache=True`` function.
"""

from __future__ import annotations

import math
import types
from typing import Any

from numba import njit

from tumble.ode import control
from tumble.ode.contract import MINIMUM_STEP, NON_FINITE, OK, UNCONVERGED

__all__ = [
    "MINIMUM_STEP",
    "NON_FINITE",
    "OK",
    "UNCONVERGED",
    "adaptive_loop",
    "bind",
    "fixed_loop",
]


JIT: dict[str, Any] = dict(cache=True, error_model="numpy")  # no ZeroDivisionError checks
INLINE: dict[str, Any] = dict(JIT, inline="always")

GRID_TIME = njit(**INLINE)(control.grid_time)
STEP_FACTOR = njit(**INLINE)(control.step_factor)
MINIMUM_STEP_OF = njit(**INLINE)(control.minimum_step)


def bind(template, name: str, **functions):
    """``template`` with ``functions`` as its globals, under its own name (not compiled).

    numba's on-disk cache is keyed by a function's qualified name and code, so each family's
    loop gets a name of its own; a closure over compiled functions would miss the cache.
    """
    bound = types.FunctionType(template.__code__, {**template.__globals__, **functions}, name)
    bound.__qualname__ = name
    bound.__doc__ = template.__doc__
    return bound


def fixed_loop(problem, grid, state, k0, k1, every, step0, records):
    """Steps ``k0+1 … k1`` of ``grid`` (a :class:`~tumble.ode.driver.Grid`) by ``STEP``.

    Step ``k`` goes from ``grid_time(k − 1)`` to ``grid_time(k)`` and is recorded (``RECORD``)
    when ``step0 + k`` is a multiple of ``every``. Returns ``(recorded, failed, cause)``:
    ``failed`` is the step whose ``STEP`` returned ``cause`` (the state is left at the step
    before), or −1 with ``cause`` :data:`OK`.
    """
    t_a, t_b, h, n = grid
    work = WORK(problem, state)  # noqa: F821
    count, until_record = 0, every - (step0 + k0) % every
    for k in range(k0 + 1, k1 + 1):
        t_old = GRID_TIME(t_a, t_b, h, k - 1, n)
        hk = GRID_TIME(t_a, t_b, h, k, n) - t_old
        cause = STEP(problem, state, work, t_old, hk, until_record == 1 or k == k1)  # noqa: F821
        if cause != OK:
            return count, k, cause
        until_record -= 1
        if until_record == 0:
            records.t[count] = t_old + hk
            RECORD(problem, state, records, count)  # noqa: F821
            count += 1
            until_record = every
    return count, -1, OK


def adaptive_loop(problem, t, t1, h, settings, fsal, state, every, step0, max_steps, records):
    """Adaptive steps from ``t`` towards ``t1``: :func:`tumble.ode.driver.march` with a
    :class:`~tumble.ode.driver.Control`, compiled.

    Each try (``TRY``) gives its error norm; :func:`~tumble.ode.control.step_factor` gives
    the next step; a rejected try is tried again from the accepted state, and a step below
    :func:`~tumble.ode.control.minimum_step` ends the run, as in the driver. ``settings`` is
    ``(safety, min_factor, max_factor, order, horizon)`` (``horizon`` 0: none, else the norm
    is per unit step ``h/horizon``, :meth:`~tumble.ode.driver.Control.weigh`). With ``fsal``
    the accepted try's last stage is the next one's first (``ACCEPT`` says when); a call
    starts with a fresh one. Returns at ``t1``, when ``records`` is full or after
    ``max_steps`` accepted steps: ``(recorded, t, h_next, accepted, rejected, cause,
    t_failed, norm_finite)`` with ``cause`` :data:`OK`, :data:`NON_FINITE` (the step to
    ``t_failed``) or :data:`MINIMUM_STEP` (``norm_finite``: whether the last norm was
    finite).
    """
    safety, min_factor, max_factor, order, horizon = settings
    work = WORK(problem, state)  # noqa: F821
    capacity = records.t.shape[0]
    count, until_record = 0, every - step0 % every
    accepted, rejected, after_rejection, have_first = 0, 0, False, False
    while t < t1 and count < capacity and accepted < max_steps:
        h_min = MINIMUM_STEP_OF(t)
        planned = max(h, h_min)
        t_new = min(t + planned, t1)
        hk = t_new - t
        share = hk / horizon if horizon > 0.0 else 1.0
        norm = TRY(problem, state, work, t, hk, have_first, share)  # noqa: F821
        h = hk * STEP_FACTOR(norm, order, safety, min_factor, max_factor, after_rejection)
        after_rejection = not norm <= 1.0
        if after_rejection:
            rejected += 1
            if h < h_min:
                return count, t, h, accepted, rejected, MINIMUM_STEP, t_new, math.isfinite(norm)
            continue
        if not FINITE(problem, state, work):  # noqa: F821
            return count, t, h, accepted, rejected, NON_FINITE, t_new, True
        if t_new == t1 and t + planned > t1:
            h = planned  # shortened to land on t1 (as the driver)
        have_first = ACCEPT(problem, state, work, fsal)  # noqa: F821
        t = t_new
        accepted += 1
        until_record -= 1
        if until_record == 0:
            records.t[count] = t
            RECORD(problem, state, records, count)  # noqa: F821
            count += 1
            until_record = every
    return count, t, h, accepted, rejected, OK, t, True
