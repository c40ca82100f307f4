"""``solve``'s compiled stepper: its Runge–Kutta steps in numba when ``fun`` is compiled.

When the right-hand side handed to :func:`tumble.solve` is a numba-compiled function (a
``CPUDispatcher``, made by ``@numba.njit``), the stepper :func:`tumble.ode.driver.march` runs
is :class:`CompiledRungeKutta`: :class:`tumble.ode.ivp.RungeKutta` with a compiled part
whose fixed grids (``march_block``, :func:`_fixed_loop`) and adaptive steps
(``march_adaptive``, :func:`_adaptive_loop`) run in numba loops that call ``fun`` from
compiled code, with no Python per step. Everything around the steps is the driver's, as
for every stepper: the record, the status and its message, ``max_steps``, events, dense
output. The loops are the
Python stepper's algorithm and must give its result to round-off
(``tests/ode/test_ode_compiled.py`` compares the two for every tableau of
:data:`~tumble.ode.tableaux.TABLEAUX`):

* each step is :func:`tumble.ode.stepper.rk_step`
  (:math:`k_i = f(t + c_i h, y + h \\sum_{j<i} a_{ij} k_j)`, :math:`y_{n+1} = y + h \\sum_i
  b_i k_i`, error :math:`h \\sum_i (b_i - \\hat b_i) k_i`);
* the error norm is :func:`tumble.ode.control.error_norm`'s formula written as a scalar loop
  (the NumPy one would allocate every step), and the controller's factor, the minimum step
  and the first step are :func:`tumble.ode.control.step_factor`,
  :func:`tumble.ode.control.minimum_step` and :func:`tumble.ode.control.initial_step`
  compiled from those very functions (as the rigid kernels do), so the loop and the driver
  cannot drift apart;
* fixed steps land on :func:`tumble.ode.control.grid_time` (compiled from it);
* with events or dense output (``interpolants=True``) each accepted step also records its
  interpolant's coefficients ``Q`` (:func:`tumble.ode.dense.step_coefficients`' formulas as
  scalar loops: the tableau's own extension with its extra stages, or the cubic Hermite
  one), and each block hands the driver its steps (``Block.steps``, the part's
  ``steps``): the driver locates the events on them with its
  :class:`~tumble.ode.events.EventTracker` (the events may be compiled or not) and keeps
  them as the dense output.

The loops take ``fun`` as an argument, so numba compiles them once per right-hand side and
process (2 to 5 s here, ``benchmarks/bench_cold.py``): numba keys a function that receives
another by that function's identity, so such a loop can never come from the on-disk cache
(``cache=True`` would only add an index entry at each run). What they call is cached. After
the first call a loop is called through its compiled entry point (about 1 µs instead of
numba's 14 µs dispatch of a function argument). The few lines that call ``fun`` (the stages,
the extension's extra stages) are written in each loop: a compiled helper that receives
``fun`` calls it indirectly, which made the loops 1.3 to 2.5 times slower.

References
----------
.. [1] E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*,
   2nd ed., Springer, 1993, §II.4 (step control), §II.6 (dense output).
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable
from functools import cache

import numba
import numpy as np
from numba import njit

from tumble.ode import control
from tumble.ode.contract import FAILURES, MINIMUM_STEP, NON_FINITE, OK
from tumble.ode.dense import StepInterpolant
from tumble.ode.driver import AdaptiveBlock, Block, Compiled, Control, Grid, Steps
from tumble.ode.ivp import RungeKutta
from tumble.ode.tableaux import ButcherTableau
from tumble.ode.templates import GRID_TIME as _GRID_TIME
from tumble.ode.templates import INLINE as _INLINE
from tumble.ode.templates import JIT as _JIT
from tumble.ode.templates import MINIMUM_STEP_OF as _MINIMUM_STEP
from tumble.ode.templates import STEP_FACTOR as _STEP_FACTOR

FIRST_BLOCK, LARGEST_BLOCK = 256, 1 << 16
"""An adaptive block has room for this many steps, doubling at each block up to the second."""

GOING = OK
"""How an adaptive block ended, in the causes every compiled loop shares
(:mod:`tumble.ode.contract`): ``GOING`` (``OK``: at ``t1``, its record full or ``max_steps``
taken), ``NON_FINITE`` (a non-finite accepted state), ``MINIMUM_STEP`` (a step below the
minimum); :data:`~tumble.ode.contract.FAILURES` names them for the
:class:`~tumble.ode.driver.AdaptiveBlock`."""

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


@njit(**_JIT)
def _interpolant(tab, hermite, y, y_new, f_new, h, X, Q):
    """The step's interpolant into ``Q`` (:func:`tumble.ode.dense.step_coefficients`): the
    cubic Hermite one, or the continuous extension ``Xᵀ P`` from ``X``, the stages followed
    by ``f_new = fun(t + h, y_new)`` and the extension's extra stages."""
    if hermite:
        _hermite(y, y_new, X[0], f_new, h, Q)
    else:
        _extension(X, tab[4], Q)


@njit(error_model="numpy")
def _fixed_loop(fun, tab, hermite, want_q, grid, k0, k1, y, f, nfev, out):
    """Steps ``k0 + 1 … k1`` of the fixed grid ``(t0, t1, h, n)``: the driver's ``_fixed``
    with :class:`~tumble.ode.ivp.RungeKutta`.

    ``y`` and ``f`` (``fun`` at ``y``) are updated in place; every accepted step is recorded
    in ``out = (t, y, Q, nfev)`` (``Q`` when ``want_q``). Returns ``(count, failed, nfev)``:
    ``failed`` is the grid step whose state was not finite (the block stops before it), or
    -1; ``nfev`` counts on from the ``nfev`` given.
    """
    t0, t1, h, n_grid = grid
    A, b, c, e, _, dense_A, dense_c = tab
    ts, ys, Qs, nfevs = out
    s, n, m = b.shape[0], y.shape[0], dense_c.shape[0]
    X, z, y_new, err = np.empty((s + 1 + m, n)), np.empty(n), np.empty(n), np.empty(n)
    for k in range(k0, k1):
        t = _GRID_TIME(t0, t1, h, k, n_grid)
        t_new = _GRID_TIME(t0, t1, h, k + 1, n_grid)
        hk = t_new - t
        X[0] = f
        for i in range(1, s):  # k_i = f(t + c_i h, y + h Σ_{j<i} a_ij k_j)
            _stage_point(A, i, i, y, hk, X, z)
            X[i, :] = fun(t + c[i] * hk, z)
        nfev += s - 1
        if not _combine(b, e, y, hk, X, y_new, err):
            return k - k0, k + 1, nfev
        f[:] = fun(t_new, y_new)
        nfev += 1
        if want_q:
            X[s] = f
            for j in range(m):  # the continuous extension's extra stages
                _stage_point(dense_A, j, s + 1 + j, y, hk, X, z)
                X[s + 1 + j, :] = fun(t + dense_c[j] * hk, z)
            nfev += m
            _interpolant(tab, hermite, y, y_new, f, hk, X, Qs[k - k0])
        y[:] = y_new
        ts[k - k0], ys[k - k0], nfevs[k - k0] = t_new, y_new, nfev
    return k1 - k0, -1, nfev


@njit(error_model="numpy")
def _adaptive_loop(fun, tab, flags, t, t1, h, rtol, atol, settings, y, f, nfev, max_steps,
                   out):  # fmt: skip
    """Adaptive steps from ``(t, y)`` towards ``t1``: the driver's ``_adaptive`` with
    :class:`~tumble.ode.ivp.RungeKutta`, at most ``max_steps`` accepted ones.

    ``h <= 0`` asks for the first step (:func:`tumble.ode.control.initial_step`, compiled
    from it). ``flags = (fsal, hermite, want_q)``; ``settings = (safety, min_factor,
    max_factor, order, horizon)`` (``horizon`` 0: none, else :meth:`Control.weigh
    <tumble.ode.driver.Control.weigh>`). ``y`` and ``f`` are updated in place; every accepted
    step is recorded in ``out = (t, y, Q, nfev, rejected)``. Returns ``(count, t, h_next,
    rejected, code, t_failed, norm_finite, nfev)``: ``code`` is :data:`GOING` (at ``t1``,
    the record full or ``max_steps`` taken), :data:`NON_FINITE` (the step to ``t_failed``) or
    :data:`MINIMUM_STEP` (``norm_finite``: whether its last norm was finite).
    """
    fsal, hermite, want_q = flags
    safety, min_factor, max_factor, order, horizon = settings
    ts, ys, Qs, nfevs, rejects = out
    A, b, c, e, _, dense_A, dense_c = tab
    s, n, m = b.shape[0], y.shape[0], dense_c.shape[0]
    if h <= 0.0:  # the first step, chosen as solve's Python path does
        h = _INITIAL_STEP(fun, t, y, f, order, rtol, atol)
        nfev += 1
    X, z, y_new, err = np.empty((s + 1 + m, n)), np.empty(n), np.empty(n), np.empty(n)
    count, rejected, after_rejection = 0, 0, False
    while t < t1 and count < ts.shape[0] and count < max_steps:
        h_min = _MINIMUM_STEP(t)
        planned = max(h, h_min)
        t_new = min(t + planned, t1)
        hk = t_new - t
        X[0] = f
        for i in range(1, s):  # the stages, as in _fixed_loop
            _stage_point(A, i, i, y, hk, X, z)
            X[i, :] = fun(t + c[i] * hk, z)
        finite = _combine(b, e, y, hk, X, y_new, err)
        nfev += s - 1
        norm = _norm(err, y, y_new, rtol, atol)
        if horizon > 0.0:
            norm *= horizon / hk
        h = hk * _STEP_FACTOR(norm, order, safety, min_factor, max_factor, after_rejection)
        after_rejection = not norm <= 1.0
        if after_rejection:
            rejected += 1
            if h < h_min:
                return count, t, h, rejected, MINIMUM_STEP, t_new, math.isfinite(norm), nfev
            continue
        if t_new == t1 and t + planned > t1:
            h = planned  # shortened to land on t1 (as the driver)
        if not finite:
            return count, t, h, rejected, NON_FINITE, t_new, True, nfev
        if fsal:  # f at the new point: first same as last, or one evaluation
            f[:] = X[s - 1]
        else:
            f[:] = fun(t_new, y_new)
            nfev += 1
        if want_q:  # the interpolant, as in _fixed_loop
            X[s] = f
            for j in range(m):
                _stage_point(dense_A, j, s + 1 + j, y, hk, X, z)
                X[s + 1 + j, :] = fun(t + dense_c[j] * hk, z)
            nfev += m
            _interpolant(tab, hermite, y, y_new, f, hk, X, Qs[count])
        y[:] = y_new
        t = t_new
        ts[count], ys[count] = t, y
        nfevs[count], rejects[count] = nfev, rejected
        count += 1
    return count, t, h, rejected, GOING, t, True, nfev


_ENTRIES: dict[int, tuple[weakref.ref, dict]] = {}
"""``id(fun) -> (weak reference to fun, {loop: entry point})`` (a plain dict: a
``WeakKeyDictionary`` lookup makes a weak reference every call, 0.5 µs of a short run)."""


def _call(loop, args: tuple) -> tuple:
    """``loop(*args)`` through its compiled entry point once it is compiled for ``args[0]``.

    numba's dispatch of a function argument costs ~14 µs a call (it types the function each
    time); the entry point of the compiled overload costs ~1 µs. Every call of a loop passes
    arguments of the same types, so one overload per loop and ``fun`` is enough.
    """
    fun = args[0]
    known = _ENTRIES.get(id(fun))
    if known is None or known[0]() is not fun:
        key = id(fun)
        known = (weakref.ref(fun, lambda _: _ENTRIES.pop(key, None)), {})
        _ENTRIES[key] = known
    entry = known[1].get(loop)
    if entry is None:
        result = loop(*args)
        overload = loop.overloads.get(tuple(numba.typeof(a) for a in args))
        if overload is not None:
            known[1][loop] = overload.entry_point
        return result
    return entry(*args)


class CompiledRungeKutta(RungeKutta):
    """:class:`~tumble.ode.ivp.RungeKutta` whose steps run in numba: the stepper of
    :func:`tumble.solve` for a compiled ``fun``. Its compiled part
    (:class:`~tumble.ode.driver.Compiled`) marches fixed grids in :func:`_fixed_loop` and,
    for an adaptive tableau, adaptive steps in :func:`_adaptive_loop`.

    Parameters
    ----------
    fun : callable
        The right-hand side as Python calls it (``solve`` counts those calls): ``f(t0, y0)``
        here, and :meth:`step` if a run is ever stepped in Python.
    compiled : numba dispatcher
        The same right-hand side, called from the loops.
    tableau : ButcherTableau
        The method.
    t0, y0 : float, ndarray of shape (n,)
        The initial point.
    interpolants : bool
        Whether the blocks return their steps with their interpolants (the part's
        ``steps``): for events and dense output, which then stay compiled.
    """

    def __init__(self, fun: Callable, compiled: Callable, tableau: ButcherTableau, t0: float,
                 y0: np.ndarray, *, interpolants: bool):  # fmt: skip
        super().__init__(fun, tableau, t0, y0)
        self.jitted, self.tab = compiled, _tableau(tableau)
        self.interpolants = interpolants
        self._flags = (tableau.fsal, self.tab.hermite, interpolants)  # _adaptive_loop's
        self.f = np.array(self.f, dtype=float)  # updated in place by the loops
        self.size = FIRST_BLOCK
        self._nfev: np.ndarray | None = None  # after each step of the last block
        self._control: tuple = (None, None, None)  # (control, atol, settings)

    @property
    def compiled(self) -> Compiled:
        """The loops as the compiled part (made when asked: no reference cycle)."""
        adaptive = self._march_adaptive if self.tableau.adaptive else None
        return Compiled(self._march_block, adaptive, self._rewind, self.interpolants)

    def _march_block(
        self, state: np.ndarray, grid: Grid, k0: int, k1: int, every: int, step0: int
    ) -> Block:
        y = np.array(state, dtype=float)
        out = _arrays(k1 - k0, y.size, self.tab.q, self.interpolants, adaptive=False)
        grid_tuple = (float(grid.t0), float(grid.t1), float(grid.h), int(grid.n))
        count, failed, self.compiled_evaluations = _call(_fixed_loop, (
            self.jitted, self.tab.arrays, self.tab.hermite, self.interpolants,
            grid_tuple, k0, k1, y, self.f, self.compiled_evaluations, out))  # fmt: skip
        self._nfev = out[3]
        every_th = slice((-(step0 + k0) - 1) % every, count, every)
        steps = self._steps(grid.time(k0), state, out, count)
        return Block(out[0][every_th], (out[1][every_th],), y, failed, steps)

    def _march_adaptive(
        self, state: np.ndarray, t: float, t1: float, h: float, control: Control, every: int,
        step0: int, max_steps: float,
    ) -> AdaptiveBlock:  # fmt: skip
        y = np.array(state, dtype=float)
        size = max(1, int(min(self.size, max_steps)))
        self.size = min(2 * self.size, LARGEST_BLOCK)
        out = _arrays(size, y.size, self.tab.q, self.interpolants, adaptive=True)
        atol, settings = self._settings(control, y.size)
        count, t_end, h_next, rejected, code, t_failed, finite, nfev = _call(_adaptive_loop, (
            self.jitted, self.tab.arrays, self._flags, float(t), float(t1), float(h),
            float(control.rtol), atol, settings, y, self.f, self.compiled_evaluations,
            float(max_steps), out))  # fmt: skip
        self.compiled_evaluations, self._nfev = nfev, out[3]
        every_th = slice((-step0 - 1) % every, count, every)
        steps = self._steps(t, state, out, count)
        return AdaptiveBlock(out[0][every_th], (out[1][every_th],), y, t_end, h_next, count,
                             rejected, FAILURES[code], t_failed, finite, steps)  # fmt: skip

    def _rewind(self, block: Block | AdaptiveBlock, index: int) -> None:
        """A terminal event in step ``index``: the evaluations counted stop with that step."""
        assert self._nfev is not None
        self.compiled_evaluations = int(self._nfev[index])

    def _steps(self, t: float, state: np.ndarray, out: tuple, count: int) -> Steps | None:
        """The block's steps and their interpolants, with ``interpolants``."""
        if not self.interpolants:
            return None
        ts, ys, Qs = out[0][:count], out[1][:count], out[2]
        interpolants = []
        t_old, y_old = float(t), state
        for i in range(count):
            t_new = float(ts[i])
            interpolants.append(StepInterpolant(t_old, t_new - t_old, y_old, Qs[i]))
            t_old, y_old = t_new, ys[i]
        return Steps(ts, ys, interpolants, out[4][:count] if len(out) == 5 else None)

    def _settings(self, control: Control, n: int) -> tuple:
        """``atol`` as an (n,) array and the controller's settings, kept for the run."""
        if self._control[0] is not control:
            atol = np.array(control.atol, dtype=float)  # a number, or shape () or (n,)
            atol = np.full(n, atol) if atol.ndim == 0 else atol
            rule = control.controller
            settings = (float(rule.safety), float(rule.min_factor), float(rule.max_factor),
                        int(self.error_order), float(control.horizon or 0.0))  # fmt: skip
            self._control = (control, atol, settings)
        return self._control[1], self._control[2]


def _arrays(size: int, n: int, q: int, want_q: bool, *, adaptive: bool) -> tuple:
    """A block's record: ``(t, y, Q, nfev)``, and the rejections for an adaptive one."""
    arrays = (np.empty(size), np.empty((size, n)), np.empty((size if want_q else 0, n, q)),
              np.empty(size, dtype=np.int64))  # fmt: skip
    return (*arrays, np.empty(size, dtype=np.int64)) if adaptive else arrays
