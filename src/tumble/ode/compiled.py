"""``solve``'s compiled path: the whole integration in numba when ``fun`` is compiled.

When the right-hand side handed to :func:`tumble.solve` is a numba-compiled function (a
``CPUDispatcher``, made by ``@numba.njit``), the step loop runs compiled with ``fun`` called
from compiled code: no Python per step. It is the loop of :func:`tumble.ode.driver.march`
with the stepper :class:`tumble.ode.ivp.RungeKutta`, written once more for numba, and must
give the same result to round-off (``tests/ode/test_ode_compiled.py`` compares the two for
every tableau of :data:`~tumble.ode.tableaux.TABLEAUX`):

* each step is :func:`tumble.ode.stepper.rk_step`
  (:math:`k_i = f(t + c_i h, y + h \\sum_{j<i} a_{ij} k_j)`, :math:`y_{n+1} = y + h \\sum_i
  b_i k_i`, error :math:`h \\sum_i (b_i - \\hat b_i) k_i`);
* the error norm is :func:`tumble.ode.control.error_norm`'s formula written as a scalar loop
  (the NumPy one would allocate every step), and the controller's
  factor and the minimum step are :func:`tumble.ode.control.step_factor` and
  :func:`tumble.ode.control.minimum_step` compiled from those very functions (as the rigid
  kernels do), so the loop and the driver cannot drift apart;
* fixed steps land on :func:`tumble.ode.control.grid_time` (compiled from it);
* with dense output or events each accepted step records its interpolant's coefficients
  ``Q`` (:func:`tumble.ode.dense.step_coefficients`' formulas as scalar loops: the tableau's
  own extension with its extra stages, or the cubic Hermite one), and the result's
  :class:`~tumble.ode.dense.DenseOutput` is built from them;
* events are located in Python, after each compiled block, by the same
  :class:`~tumble.ode.events.EventTracker` on those interpolants (the events may be compiled
  or not). The loop runs in blocks of at most :data:`EVENT_BLOCK` steps when there are
  events, so a terminal event wastes at most one block of steps beyond it; the result is cut
  at the event with the counters (``nfev``, ``n_steps``, ``n_rejected``) of that step.

This is the one step loop beside :func:`tumble.ode.driver.march`: the driver runs compiled
blocks only without events and dense output, and here both stay compiled.

The loop, :func:`_loop`, takes ``fun`` as an argument, so numba compiles it once per
right-hand side and process (2 to 5 s here, ``benchmarks/bench_cold.py``): numba keys a
function that receives another by that function's identity, so such a loop can never come
from the on-disk cache (``cache=True`` would only add an index entry at each run). What it
calls is cached. After the first call the loop is called through its compiled entry point
(about 1 µs instead of numba's 14 µs dispatch of a function argument).

References
----------
.. [1] E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*,
   2nd ed., Springer, 1993, §II.4 (step control), §II.6 (dense output).
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache
from typing import Any

import numba
import numpy as np
from numba import njit

from tumble.ode import control
from tumble.ode.dense import DenseOutput, StepInterpolant
from tumble.ode.driver import (
    Status,
    _minimum_step_message,
    check_record_size,
    max_steps_message,
    non_finite_message,
)
from tumble.ode.events import Event, EventTracker
from tumble.ode.tableaux import ButcherTableau

EVENT_BLOCK = 256
"""With events, the compiled loop returns to Python after at most this many steps."""

FIRST_BLOCK, LARGEST_BLOCK = 256, 1 << 16
"""An adaptive run's record starts with room for this many steps, doubling up to the second."""

GOING, NON_FINITE, MINIMUM_STEP, MAX_STEPS = 0, 1, 2, 3
"""How a compiled block ended: at its end or with its record full; a non-finite accepted
state; a step below the minimum; ``max_steps`` accepted steps."""

_JIT: dict[str, Any] = dict(cache=True, error_model="numpy")
_INLINE: dict[str, Any] = dict(_JIT, inline="always")
_STEP_FACTOR = njit(**_INLINE)(control.step_factor)
_MINIMUM_STEP = njit(**_INLINE)(control.minimum_step)
_GRID_TIME = njit(**_INLINE)(control.grid_time)
_INITIAL_STEP = njit(**_INLINE)(control.initial_step)


class Tableau:
    """A :class:`~tumble.ode.tableaux.ButcherTableau` as the compiled loops read it.

    ``arrays = (A, b, c, e, P, dense_A, dense_c)``, writable float64 copies: ``e`` is zero
    for a fixed-step method; ``P`` (s + 1 + m, q) is the continuous extension with a row
    for ``f(t + h, y_{n+1})`` and the ``m`` extra stages (zero rows where the tableau has
    none), or empty for the cubic Hermite interpolant (``hermite``).
    """

    def __init__(self, tableau: ButcherTableau):
        s, m = tableau.stages, tableau.extra_stages
        dense = tableau.dense
        self.hermite = dense is None
        self.q = 3 if dense is None else dense.shape[1]
        P = np.zeros((s + 1 + m, self.q))
        if dense is not None:
            P[: dense.shape[0]] = dense
        dense_A = np.zeros((m, s + 1 + m)) if tableau.dense_A is None else tableau.dense_A
        dense_c = np.zeros(m) if tableau.dense_c is None else tableau.dense_c
        e = np.zeros(s) if tableau.e is None else tableau.e
        self.arrays = tuple(
            np.array(a, dtype=float)
            for a in (tableau.A, tableau.b, tableau.c, e, P, dense_A, dense_c)
        )


@cache
def _tableau(tableau: ButcherTableau) -> Tableau:
    return Tableau(tableau)


@njit(**_JIT)
def _stage_point(A, row, i, y, h, K, z):
    """``z = y + h Σ_{j<i} a_{row,j} k_j``: where a stage evaluates ``fun``."""
    for q in range(y.shape[0]):
        acc = 0.0
        for j in range(i):
            acc += A[row, j] * K[j, q]
        z[q] = y[q] + h * acc


@njit(**_JIT)
def _combine(b, e, y, h, K, y_new, err):
    """``y_new = y + h Σ b_i k_i`` and the error ``h Σ e_i k_i``; whether y_new is finite."""
    finite = True
    for q in range(y.shape[0]):
        acc, acc_e = 0.0, 0.0
        for i in range(b.shape[0]):
            acc += b[i] * K[i, q]
            acc_e += e[i] * K[i, q]
        y_new[q] = y[q] + h * acc
        err[q] = h * acc_e
        finite = finite and math.isfinite(y_new[q])
    return finite


@njit(**_JIT)
def _norm(err, y, y_new, rtol, atol):
    """:func:`tumble.ode.control.error_norm`: Hairer's weighted RMS norm."""
    acc = 0.0
    for q in range(err.shape[0]):
        scaled = err[q] / (atol[q] + rtol * max(abs(y[q]), abs(y_new[q])))
        acc += scaled * scaled
    return math.sqrt(acc / err.shape[0])


@njit(**_JIT)
def _hermite(y, y_new, f, f_new, h, Q):
    """:func:`tumble.ode.dense.hermite_coefficients` into ``Q`` (n, 3)."""
    for q in range(y.shape[0]):
        delta = (y_new[q] - y[q]) / h
        Q[q, 0] = f[q]
        Q[q, 1] = 3 * delta - 2 * f[q] - f_new[q]
        Q[q, 2] = f[q] + f_new[q] - 2 * delta


@njit(**_JIT)
def _extension(X, P, Q):
    """``Q = Xᵀ P``: a continuous extension's coefficients from its stages."""
    for q in range(X.shape[1]):
        for col in range(P.shape[1]):
            acc = 0.0
            for r in range(P.shape[0]):
                acc += X[r, q] * P[r, col]
            Q[q, col] = acc


@njit(error_model="numpy")
def _loop(fun, tab, flags, grid, k, t, t1, h, rtol, atol, settings, y, f, steps, max_steps,
          nfev, rejected, out):  # fmt: skip
    """Steps of :func:`tumble.solve` from ``(t, y)`` towards ``t1``: the driver's
    ``_adaptive`` (``flags[0]``) or ``_fixed`` on ``grid = (t0, t1, h, n)`` from its step
    ``k``.

    ``h <= 0`` asks for the first step (:func:`tumble.ode.control.initial_step`, compiled
    from it). ``y`` and ``f`` (``fun`` at ``y``) are updated in place; every accepted step is
    recorded in ``out = (t, y, Q, nfev, rejected)`` (``Q`` when ``flags[3]``: the step's
    interpolant, :func:`tumble.ode.dense.step_coefficients`). ``settings`` is ``(safety,
    min_factor, max_factor, order)``. Returns ``(recorded, t, h_next, k, rejected, code,
    t_failed, norm_finite, nfev)``: ``code`` is :data:`GOING` (at ``t1`` or the record
    full), :data:`NON_FINITE` (the step to ``t_failed``), :data:`MINIMUM_STEP`
    (``norm_finite``: whether its last norm was finite) or :data:`MAX_STEPS`.
    """
    adaptive, fsal, hermite, want_q = flags
    A, b, c, e, P, dense_A, dense_c = tab
    safety, min_factor, max_factor, order = settings
    t0_grid, t1_grid, h_grid, n_grid = grid
    ts, ys, Qs, nfevs, rejects = out
    s, n, m = b.shape[0], y.shape[0], dense_c.shape[0]
    if adaptive and h <= 0.0:  # the first step, chosen as solve's Python path does
        h = _INITIAL_STEP(fun, t, y, f, order, rtol, atol)
        nfev += 1
    K, z, y_new, err = np.empty((s, n)), np.empty(n), np.empty(n), np.empty(n)
    X = np.empty((P.shape[0], n))
    count, after_rejection = 0, False
    while count < ts.shape[0] and (t < t1 if adaptive else k < n_grid):
        if steps + count >= max_steps:
            return count, t, h, k, rejected, MAX_STEPS, t, True, nfev
        if adaptive:
            h_min = _MINIMUM_STEP(t)
            planned = max(h, h_min)
            t_new = min(t + planned, t1)
        else:
            t = _GRID_TIME(t0_grid, t1_grid, h_grid, k, n_grid)
            t_new = _GRID_TIME(t0_grid, t1_grid, h_grid, k + 1, n_grid)
        hk = t_new - t
        K[0, :] = f
        for i in range(1, s):  # k_i = f(t + c_i h, y + h Σ_{j<i} a_ij k_j)
            _stage_point(A, i, i, y, hk, K, z)
            K[i, :] = fun(t + c[i] * hk, z)
        nfev += s - 1
        finite = _combine(b, e, y, hk, K, y_new, err)
        if adaptive:
            norm = _norm(err, y, y_new, rtol, atol)
            h = hk * _STEP_FACTOR(norm, order, safety, min_factor, max_factor, after_rejection)
            after_rejection = not norm <= 1.0
            if after_rejection:
                rejected += 1
                if h < h_min:
                    return count, t, h, k, rejected, MINIMUM_STEP, t_new, math.isfinite(norm), nfev
                continue
            if t_new == t1 and t + planned > t1:
                h = planned  # shortened to land on t1 (as the driver)
        if not finite:
            return count, t, h, k, rejected, NON_FINITE, t_new, True, nfev
        if fsal:  # f at the new point: first same as last, or one evaluation
            f[:] = K[s - 1]
        else:
            f[:] = fun(t_new, y_new)
            nfev += 1
        if want_q:
            if hermite:
                _hermite(y, y_new, K[0], f, hk, Qs[count])
            else:
                X[:s] = K
                X[s] = f
                for j in range(m):  # the continuous extension's extra stages
                    _stage_point(dense_A, j, s + 1 + j, y, hk, X, z)
                    X[s + 1 + j, :] = fun(t + dense_c[j] * hk, z)
                nfev += m
                _extension(X, P, Qs[count])
        y[:] = y_new
        t, k = t_new, k + 1
        ts[count], ys[count] = t, y
        nfevs[count], rejects[count] = nfev, rejected
        count += 1
    return count, t, h, k, rejected, GOING, t, True, nfev


_ENTRIES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _call(loop, args: tuple) -> tuple:
    """``loop(*args)`` through its compiled entry point once it is compiled for ``args[0]``.

    numba's dispatch of a function argument costs ~14 µs a call (it types the function each
    time); the entry point of the compiled overload costs ~1 µs.
    """
    entries = _ENTRIES.setdefault(args[0], {})
    entry = entries.get(loop)
    if entry is None:
        result = loop(*args)
        key = tuple(numba.typeof(a) for a in args)
        overload = loop.overloads.get(key)
        if overload is not None:
            entries[loop] = overload.entry_point
        return result
    return entry(*args)


@dataclass
class _Record:
    """A run's accepted steps, block by block."""

    t: list[np.ndarray]
    y: list[np.ndarray]
    Q: list[np.ndarray]
    nfev: list[np.ndarray]
    rejected: list[np.ndarray]
    terminal_h: float | None = None
    """The full length of the step a terminal event cut (its interpolant spans all of it)."""


def _blocks(n: int, q: int, want_q: bool, size: int) -> tuple:
    Q = np.empty((size if want_q else 0, n, q))
    return (np.empty(size), np.empty((size, n)), Q, np.empty(size, dtype=np.int64),
            np.empty(size, dtype=np.int64))  # fmt: skip


@dataclass
class CompiledOutcome:
    """What :func:`march` returns to :func:`tumble.solve` (the fields of its result)."""

    t: np.ndarray
    y: np.ndarray
    t_events: list[list[float]]
    y_events: list[list[np.ndarray]]
    nfev: int
    n_steps: int
    n_rejected: int
    status: Status
    message: str
    sol: DenseOutput | None


def march(
    fun: Callable,
    tableau: ButcherTableau,
    t_span: tuple[float, float],
    y0: np.ndarray,
    f0: np.ndarray,
    *,
    h: float | None,
    nfev: int,
    rtol: float,
    atol: np.ndarray,
    events: Sequence[Event],
    dense_output: bool,
    max_steps: int,
) -> CompiledOutcome:
    """Run :func:`tumble.solve` compiled: ``fun`` a numba function, ``f0 = fun(t0, y0)``.

    ``h`` is the fixed step, or an adaptive run's first step (None: chosen in the compiled
    loop, as :func:`~tumble.ode.control.initial_step` does); ``nfev`` the evaluations made so
    far (``f0``). Returns what :func:`tumble.ode.driver.march`
    would have, for :func:`tumble.solve` to wrap.
    """
    t0, t1 = t_span
    tab = _tableau(tableau)
    n = y0.size
    want_q = dense_output or bool(events)
    flags = (tableau.adaptive, bool(tableau.adaptive and tableau.fsal), tab.hermite, want_q)
    y, f = y0.astype(float, copy=True), np.array(f0, dtype=float)
    tracker = EventTracker(events, t0, y0) if events else None
    record = _Record([np.array([t0])], [y0[None].copy()], [], [], [])
    status, message = Status.SUCCESS, Status.SUCCESS.message
    steps = rejected = k = 0
    t = t0
    atol_n = np.full(n, float(atol)) if np.ndim(atol) == 0 else np.array(atol, dtype=float)
    settings = (control.SAFETY, control.MIN_FACTOR, control.MAX_FACTOR, tableau.error_order)
    if tableau.adaptive:
        h = 0.0 if h is None else h
        grid = (t0, t1, h, 0)
        size = EVENT_BLOCK if events else FIRST_BLOCK
    else:
        assert h is not None
        grid = (t0, t1, h, control.fixed_step_count(t0, t1, h))
        check_record_size(t1 - t0, h, 1, max_steps, (y0,))
        size = min(grid[3], max_steps) + 1
        size = min(size, EVENT_BLOCK) if events else size
    while True:
        out = _blocks(n, tab.q, want_q, size)
        count, t, h, k, rejected, code, t_failed, finite, nfev = _call(
            _loop,
            (fun, tab.arrays, flags, grid, k, t, t1, h, rtol, atol_n, settings, y, f, steps,
             max_steps, nfev, rejected, out),
        )  # fmt: skip
        t_before = record.t[-1][-1]
        _keep(record, out, count)
        if tracker is not None:
            stop = _locate(tracker, record, count, t_before)
            if stop is not None:
                steps += stop
                nfev, rejected = int(record.nfev[-1][-1]), int(record.rejected[-1][-1])
                status, message = Status.TERMINAL_EVENT, Status.TERMINAL_EVENT.message
                break
        steps += count
        if code == NON_FINITE:
            status, message = Status.FAILED, non_finite_message(t, t_failed)
        elif code == MINIMUM_STEP:
            status = Status.FAILED
            message = _minimum_step_message(t, control.minimum_step(t), finite)
        elif code == MAX_STEPS:
            status = Status.FAILED
            message = max_steps_message(max_steps, t)
        if code != GOING or t >= t1:
            break
        size = size if events else min(2 * size, LARGEST_BLOCK)
    return _outcome(record, tracker, dense_output, nfev, steps, rejected, status, message)


def _keep(record: _Record, out: tuple, count: int) -> None:
    ts, ys, Qs, nfevs, rejects = out
    record.t.append(ts[:count])
    record.y.append(ys[:count])
    record.Q.append(Qs[:count])
    record.nfev.append(nfevs[:count])
    record.rejected.append(rejects[:count])


def _locate(tracker: EventTracker, record: _Record, count: int, t_old: float) -> int | None:
    """Events over the block just kept; the steps up to a terminal event (the block then
    ends there, at the event, with that step's counters), or None."""
    ts, ys, Qs = record.t[-1], record.y[-1], record.Q[-1]
    y_old = record.y[-2][-1]
    for i in range(count):
        sol = StepInterpolant(t_old, ts[i] - t_old, y_old, Qs[i])
        t_stop = tracker.update(t_old, float(ts[i]), ys[i], sol)
        if t_stop is not None:
            record.terminal_h = float(ts[i]) - t_old
            record.t[-1] = np.append(ts[:i], t_stop)
            record.y[-1] = np.vstack([ys[:i], sol(t_stop)[None]])
            for name in ("Q", "nfev", "rejected"):
                getattr(record, name)[-1] = getattr(record, name)[-1][: i + 1]
            return i + 1
        t_old, y_old = float(ts[i]), ys[i]
    return None


def _outcome(
    record: _Record, tracker: EventTracker | None, dense_output: bool, nfev: int, steps: int,
    rejected: int, status: Status, message: str,
) -> CompiledOutcome:  # fmt: skip
    t = np.concatenate(record.t)
    y = np.concatenate(record.y)
    sol = None
    if dense_output and len(t) > 1:
        Q = np.concatenate(record.Q)
        lengths = np.diff(t)
        if record.terminal_h is not None:
            lengths[-1] = record.terminal_h
        interpolants = [
            StepInterpolant(float(t[i]), float(lengths[i]), y[i], Q[i]) for i in range(len(Q))
        ]
        sol = DenseOutput(t, interpolants)
    return CompiledOutcome(
        t=t,
        y=y,
        t_events=tracker.t_events if tracker else [],
        y_events=tracker.y_events if tracker else [],
        nfev=nfev,
        n_steps=steps,
        n_rejected=rejected,
        status=status,
        message=message,
        sol=sol,
    )
