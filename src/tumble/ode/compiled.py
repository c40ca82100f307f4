"""``solve``'s compiled stepper: its Runge–Kutta steps in numba when ``fun`` is compiled.

When the right-hand side handed to :func:`tumble.solve` is a numba-compiled function (a
``CPUDispatcher``, made by ``@numba.njit``), the stepper :func:`tumble.ode.driver.march` runs
is :class:`CompiledRungeKutta`: :class:`tumble.ode.ivp.RungeKutta` with a compiled part
whose fixed grids (``march_block``, :data:`_FIXED`) and adaptive steps (``march_adaptive``,
:data:`_ADAPTIVE`) run in the loop templates of :mod:`tumble.ode.templates`, bound to the
steps below, which call ``fun`` from compiled code, with no Python per step. Everything
around the steps is the driver's, as for every stepper: the record, the status and its
message, ``max_steps``, events, dense output. The loops are the
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

The loops receive ``fun`` in their :class:`SolveProblem`, so numba compiles them once per
right-hand side and process (2 to 5 s here, ``benchmarks/bench_cold.py``): numba keys a
function that receives another by that function's identity, so such a loop can never come
from the on-disk cache (``cache=False``; ``cache=True`` would only add an index entry at
each run). What they call is cached. After the first call a loop is called through its
compiled entry point (about 1 µs instead of numba's 14 µs dispatch of a function argument).
The functions that call ``fun`` (:func:`_stages`, :func:`_extend`, the steps) are inlined
into the loop, where ``fun`` is the problem's field, so each call is direct: a compiled
helper not inlined, that received ``fun``, called it indirectly, which made the loops 1.3 to
2.5 times slower; bound and inlined they take the hand-written loops' time
(``benchmarks/bench_renovation.py``) and give their numbers bit for bit. The evaluations of
``fun`` are counted from what the loops return: each part of a step makes a known number
(:meth:`CompiledRungeKutta._count`).

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
from typing import NamedTuple

import numba
import numpy as np
from numba import njit, types
from numba.extending import overload

from tumble.ode import control, templates
from tumble.ode.callback import Callback, PythonRightHandSide, call_address
from tumble.ode.contract import FAILURES, NON_FINITE, OK
from tumble.ode.dense import StepInterpolant
from tumble.ode.driver import AdaptiveBlock, Block, Compiled, Control, Grid, Steps
from tumble.ode.ivp import RungeKutta
from tumble.ode.tableaux import ButcherTableau
from tumble.ode.templates import INLINE as _INLINE
from tumble.ode.templates import JIT as _JIT

FIRST_BLOCK, LARGEST_BLOCK = 256, 1 << 16
"""An adaptive block has room for this many steps, doubling at each block up to the second."""

_INITIAL_STEP = njit(**_INLINE)(control.initial_step)


def _is_callback(fun) -> bool:
    """Whether the numba type ``fun`` is a :class:`~tumble.ode.callback.Callback` (a Python
    right-hand side), not a compiled function."""
    return isinstance(fun, types.BaseNamedTuple) and fun.instance_class is Callback


def _evaluate(fun, t, z, X, i):
    """``X[i] = fun(t, z)``: a compiled ``fun`` called directly, a Python one through its
    :class:`~tumble.ode.callback.Callback` (``z`` into its ``z``, the call, its ``out`` into
    ``X[i]``; NaN when ``fun`` raised)."""


def _evaluate_into(fun, t, z, f):
    """``f[:] = fun(t, z)``: :func:`_evaluate` into a vector."""


def _initial(fun, t, y, f, order, rtol, atol):
    """:func:`tumble.ode.control.initial_step` for a compiled ``fun``; a Python one has its
    first step chosen by ``solve`` in Python (NaN here, never asked)."""


@overload(_evaluate, inline="always", jit_options=_JIT)
def _evaluate_overload(fun, t, z, X, i):
    if _is_callback(fun):

        def through_callback(fun, t, z, X, i):
            shared = fun.z
            for q in range(z.shape[0]):
                shared[q] = z[q]
            if call_address(fun.address, t) == 0:
                X[i, :] = fun.out
            else:
                X[i, :] = np.nan

        return through_callback

    def direct(fun, t, z, X, i):
        X[i, :] = fun(t, z)

    return direct


@overload(_evaluate_into, inline="always", jit_options=_JIT)
def _evaluate_into_overload(fun, t, z, f):
    if _is_callback(fun):

        def through_callback(fun, t, z, f):
            shared = fun.z
            for q in range(z.shape[0]):
                shared[q] = z[q]
            if call_address(fun.address, t) == 0:
                f[:] = fun.out
            else:
                f[:] = np.nan

        return through_callback

    def direct(fun, t, z, f):
        f[:] = fun(t, z)

    return direct


@overload(_initial, inline="always", jit_options=_JIT)
def _initial_overload(fun, t, y, f, order, rtol, atol):
    if _is_callback(fun):

        def unasked(fun, t, y, f, order, rtol, atol):
            return np.nan

        return unasked

    def initial(fun, t, y, f, order, rtol, atol):
        return _INITIAL_STEP(fun, t, y, f, order, rtol, atol)

    return initial


class Tableau:
    """A :class:`~tumble.ode.tableaux.ButcherTableau` as the compiled loops read it.

    ``arrays = (A, b, c, e, P, dense_A, dense_c)``, writable float64 copies: ``e`` is zero
    for a fixed-step method; ``P`` (s + 1 + m, q) is the continuous extension with a row
    for ``f(t + h, y_{n+1})`` and the ``m`` extra stages (zero rows where the tableau has
    none), or empty for the cubic Hermite interpolant (``hermite``).
    """

    def __init__(self, tableau: ButcherTableau):
        s, m = tableau.stages, tableau.extra_stages
        self.stages, self.extra_stages, self.fsal = s, m, tableau.fsal
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
def _slopes(y, y_new, h, delta):
    """``delta = (y_new − y)/h``: the secant slope the cubic Hermite interpolant takes."""
    for q in range(y.shape[0]):
        delta[q] = (y_new[q] - y[q]) / h


@njit(**_JIT)
def _hermite(delta, f, f_new, Q):
    """:func:`tumble.ode.dense.hermite_coefficients` into ``Q`` (n, 3), from the slope
    ``delta`` (:func:`_slopes`)."""
    for q in range(delta.shape[0]):
        Q[q, 0] = f[q]
        Q[q, 1] = 3 * delta[q] - 2 * f[q] - f_new[q]
        Q[q, 2] = f[q] + f_new[q] - 2 * delta[q]


@njit(**_JIT)
def _extension(X, P, Q):
    """``Q = Xᵀ P``: a continuous extension's coefficients from its stages."""
    for q in range(X.shape[1]):
        for col in range(P.shape[1]):
            acc = 0.0
            for r in range(P.shape[0]):
                acc += X[r, q] * P[r, col]
            Q[q, col] = acc


class SolveProblem(NamedTuple):
    """What ``solve``'s fixed-step loop needs besides the state: the compiled right-hand
    side ``fun``, the tableau (:attr:`Tableau.arrays`), whether its interpolant is the cubic
    Hermite one and whether the steps' interpolants are wanted (``want_q``)."""

    fun: Callable
    tab: tuple
    hermite: bool
    want_q: bool


class AdaptiveSolveProblem(NamedTuple):
    """:class:`SolveProblem` and what the adaptive loop needs more: the tolerances (``atol``
    of shape (n,)), the order of the error estimate (for the first step) and the
    controller's horizon (0: none)."""

    fun: Callable
    tab: tuple
    hermite: bool
    want_q: bool
    rtol: float
    atol: np.ndarray
    order: int
    horizon: float


class SolveRecords(NamedTuple):
    """Every accepted step of a block: its end ``t`` (m,), ``y`` (m, n), its interpolant's
    ``Q`` (m, n, q) (none without ``want_q``), and in an adaptive block the tries rejected
    in the block so far ``rejected`` (m,)."""

    t: np.ndarray
    y: np.ndarray
    Q: np.ndarray
    rejected: np.ndarray


# The loops are the templates of tumble.ode.templates bound to the functions below. The
# state is (y, f): y and f = fun(t, y) of shape (n,); the work (X, z, y_new, err), and
# (…, tally) in the adaptive loop: the stages X (s + 1 + m, n) (then f_new and the
# extension's extra stages), a stage point z (then the Hermite slope), the new y and its
# error, and the tries rejected with whether the last try was finite. Each part of a step
# makes a known number of evaluations of fun, so the stepper counts them from what the
# loops return (CompiledRungeKutta._count).


@njit(**_INLINE)
def _work(problem, state):
    b, dense_c = problem.tab[1], problem.tab[6]
    s, n, m = b.shape[0], state[0].shape[0], dense_c.shape[0]
    return np.empty((s + 1 + m, n)), np.empty(n), np.empty(n), np.empty(n)


@njit(**_INLINE)
def _adaptive_work(problem, state):
    return (*_work(problem, state), np.zeros(2, dtype=np.int64))


@njit(**_INLINE)
def _stages(problem, y, f, X, z, t, h):
    """``k_0 = f`` and ``k_i = fun(t + c_i h, y + h Σ_{j<i} a_ij k_j)`` into ``X``; ``fun``
    is called here, inlined into the loop, so that the call is direct."""
    fun, A, c = problem.fun, problem.tab[0], problem.tab[2]
    X[0] = f
    for i in range(1, A.shape[0]):
        _stage_point(A, i, i, y, h, X, z)
        _evaluate(fun, t + c[i] * h, z, X, i)


@njit(**_INLINE)
def _extend(problem, y, y_new, f_new, X, z, t, h):
    """With ``want_q``, what the step's interpolant needs: ``X[s] = f_new``, then the
    continuous extension's extra stages, or the Hermite slope into ``z``."""
    if not problem.want_q:
        return
    fun, dense_A, dense_c = problem.fun, problem.tab[5], problem.tab[6]
    s = problem.tab[1].shape[0]
    X[s] = f_new
    for j in range(dense_c.shape[0]):
        _stage_point(dense_A, j, s + 1 + j, y, h, X, z)
        _evaluate(fun, t + dense_c[j] * h, z, X, s + 1 + j)
    if problem.hermite:
        _slopes(y, y_new, h, z)


@njit(**_INLINE)
def _adaptive_record(problem, state, work, records, i):
    """:func:`_record` and the tries rejected so far."""
    records.rejected[i] = work[4][0]
    _record(problem, state, work, records, i)


@njit(**_INLINE)
def _record(problem, state, work, records, i):
    """``y`` and, with ``want_q``, the interpolant's ``Q``
    (:func:`tumble.ode.dense.step_coefficients`: the cubic Hermite one from ``f``, ``f_new``
    and the slope, or the extension ``Xᵀ P`` of the stages)."""
    y, f = state[0], state[1]
    X, z = work[0], work[1]
    records.y[i] = y
    if problem.want_q:
        if problem.hermite:
            _hermite(z, X[0], f, records.Q[i])
        else:
            _extension(X, problem.tab[4], records.Q[i])


@njit(**_INLINE)
def _fixed_step(problem, state, work, t, t_new, settle):
    """One step of :func:`tumble.ode.stepper.rk_step` from ``t`` to ``t_new``, then ``f =
    fun(t_new, y_new)`` and what the interpolant needs (:func:`_extend`); a non-finite
    ``y_new`` leaves the state as it was (after s − 1 evaluations; s + m a step else)."""
    b, e = problem.tab[1], problem.tab[3]
    y, f = state
    X, z, y_new, err = work
    h = t_new - t
    _stages(problem, y, f, X, z, t, h)
    if not _combine(b, e, y, h, X, y_new, err):
        return NON_FINITE
    _evaluate_into(problem.fun, t_new, y_new, f)
    _extend(problem, y, y_new, f, X, z, t, h)
    y[:] = y_new
    return OK


@njit(**_INLINE)
def _try(problem, state, work, t, h, have_first, share):
    """The step of :func:`_fixed_step` into ``y_new`` (the state untouched), its error norm
    (:func:`tumble.ode.control.error_norm`, per unit step ``h/horizon`` with a horizon),
    and the rejections counted in ``tally``."""
    b, e = problem.tab[1], problem.tab[3]
    y, f = state
    X, z, y_new, err, tally = work
    _stages(problem, y, f, X, z, t, h)
    tally[1] = _combine(b, e, y, h, X, y_new, err)
    norm = _norm(err, y, y_new, problem.rtol, problem.atol)
    if problem.horizon > 0.0:
        norm *= problem.horizon / h
    if not norm <= 1.0:
        tally[0] += 1
    return norm


@njit(**_INLINE)
def _finite(problem, state, work):
    return work[4][1] != 0


@njit(**_INLINE)
def _accept(problem, state, work, t, t_new, fsal):
    """``y_new`` becomes ``y``, with ``f`` at it (the last stage if FSAL, else one
    evaluation) and what the interpolant needs; each try computes its first stage."""
    y, f = state
    X, z, y_new = work[0], work[1], work[2]
    s = problem.tab[1].shape[0]
    if fsal:
        f[:] = X[s - 1]
    else:
        _evaluate_into(problem.fun, t_new, y_new, f)
    _extend(problem, y, y_new, f, X, z, t, t_new - t)
    y[:] = y_new
    return False


@njit(**_INLINE)
def _first_step(problem, state, work, t):
    """:func:`tumble.ode.control.initial_step` (one evaluation), as solve's Python path."""
    y, f = state
    return _initial(problem.fun, t, y, f, problem.order, problem.rtol, problem.atol)


_FIXED = templates.loop(
    templates.fixed_loop, "_solve_fixed", cache=False, WORK=_work, STEP=_fixed_step,
    RECORD=_record,
)  # fmt: skip
"""``solve``'s fixed grids: :func:`tumble.ode.templates.fixed_loop` with the steps above
(compiled per right-hand side, ``cache=False``: module docstring)."""

_ADAPTIVE = templates.loop(
    templates.adaptive_loop, "_solve_adaptive", cache=False, WORK=_adaptive_work, TRY=_try,
    FINITE=_finite, ACCEPT=_accept, FIRST_STEP=_first_step, RECORD=_adaptive_record,
)  # fmt: skip
"""``solve``'s adaptive steps: :func:`tumble.ode.templates.adaptive_loop` with the tries
above."""

_PYTHON_FIXED = templates.loop(
    templates.fixed_loop, "_solve_python_fixed", WORK=_work, STEP=_fixed_step, RECORD=_record,
)  # fmt: skip
""":data:`_FIXED` for a Python right-hand side (a :class:`~tumble.ode.callback.Callback` in
the problem: no function in the types, so one compilation, cached on disk, serves every
Python ``fun``)."""

_PYTHON_ADAPTIVE = templates.loop(
    templates.adaptive_loop, "_solve_python_adaptive", WORK=_adaptive_work, TRY=_try,
    FINITE=_finite, ACCEPT=_accept, FIRST_STEP=_first_step, RECORD=_adaptive_record,
)  # fmt: skip
""":data:`_ADAPTIVE` for a Python right-hand side."""


_ENTRIES: dict[int, tuple[weakref.ref, dict]] = {}
"""``id(fun) -> (weak reference to fun, {loop: entry point})`` (a plain dict: a
``WeakKeyDictionary`` lookup makes a weak reference every call, 0.5 µs of a short run)."""


def _call(loop, fun: Callable, args: tuple) -> tuple:
    """``loop(*args)`` through its compiled entry point once it is compiled for ``fun`` (in
    ``args[0]``, the :class:`SolveProblem`).

    numba's dispatch of a function argument costs ~14 µs a call (it types the function each
    time); the entry point of the compiled overload costs ~1 µs. Every call of a loop passes
    arguments of the same types, so one overload per loop and ``fun`` is enough.
    """
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

    def __init__(self, fun: Callable, compiled: Callable | None, tableau: ButcherTableau,
                 t0: float, y0: np.ndarray, *, interpolants: bool):  # fmt: skip
        super().__init__(fun, tableau, t0, y0)
        self.python: PythonRightHandSide | None = None
        if compiled is None:  # a Python right-hand side, called back from the loops
            self.python = PythonRightHandSide(getattr(fun, "fun", fun), y0.size)
            self.jitted: Callable | Callback = self.python.callback
            self._loops, self._key = (_PYTHON_FIXED, _PYTHON_ADAPTIVE), Callback
        else:
            self.jitted, self._loops, self._key = compiled, (_FIXED, _ADAPTIVE), compiled
        self.tab = _tableau(tableau)
        self.interpolants = interpolants
        self._problem: SolveProblem | None = None  # the fixed loop's, at its first block
        self.f = np.array(self.f, dtype=float)  # updated in place by the loops
        self.size = FIRST_BLOCK
        self.compiled_evaluations = 0
        self._counts: tuple = (0, 0, 0, _NONE)  # the last block's: _count
        self._control: tuple = (None, None, None)  # (control, problem, settings)

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
        if self._problem is None:
            self._problem = _new(SolveProblem, (self.jitted, self.tab.arrays, self.tab.hermite,
                                                self.interpolants))  # fmt: skip
        count, failed, _ = _call(self._loops[0], self._key, (
            self._problem, grid_tuple, (y, self.f), k0, k1, 1, 0, out))  # fmt: skip
        if self.python is not None:
            self.python.reraise()
        tab, start = self.tab, self.compiled_evaluations
        per_step = tab.stages + (tab.extra_stages if self.interpolants else 0)
        self._counts = (start, per_step, 0, _NONE)  # _count
        self.compiled_evaluations = start + count * per_step + (tab.stages - 1) * (failed >= 0)
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
        problem, settings = self._settings(control, y.size)
        tab = self.tab
        args = (problem, float(t), float(t1), float(h), settings, tab.fsal, (y, self.f), 1, 0,
                float(max_steps), out)  # fmt: skip
        count, t_end, h_next, _, rejected, code, t_failed, finite = _call(
            self._loops[1], self._key, args
        )
        if self.python is not None:
            self.python.reraise()
        accept = (0 if tab.fsal else 1) + (tab.extra_stages if self.interpolants else 0)
        first = self.compiled_evaluations + (h <= 0.0)  # the first step's choice: one
        self._counts = (first, accept, tab.stages - 1, out.rejected)
        tries = count + rejected + (code == NON_FINITE)  # a non-finite try is no rejection
        self.compiled_evaluations = first + count * accept + tries * (tab.stages - 1)
        every_th = slice((-step0 - 1) % every, count, every)
        steps = self._steps(t, state, out, count)
        return AdaptiveBlock(out[0][every_th], (out[1][every_th],), y, t_end, h_next, count,
                             rejected, FAILURES[code], t_failed, finite, steps)  # fmt: skip

    def _rewind(self, block: Block | AdaptiveBlock, index: int) -> None:
        """A terminal event in step ``index``: the evaluations counted stop with that step."""
        self.compiled_evaluations = self._count(index + 1)

    def _rejected(self, accepted: int) -> int:
        """The tries of the last block rejected before its ``accepted``-th step."""
        rejected = self._counts[3]
        return int(rejected[accepted - 1]) if accepted and rejected.size else 0

    def _count(self, accepted: int) -> int:
        """The evaluations of ``fun`` after the last block's ``accepted``-th step: a known
        number per accepted step (``s + m`` a fixed step, with ``m`` the extension's extra
        stages when its interpolants are wanted; ``m`` and one for ``f`` unless FSAL an
        adaptive one) and ``s − 1`` per try (rejected ones too), from the count at the
        block's start (with one for the first step's choice)."""
        start, per_step, per_try, _ = self._counts
        return start + accepted * per_step + (accepted + self._rejected(accepted)) * per_try

    def _steps(self, t: float, state: np.ndarray, out: SolveRecords, count: int) -> Steps | None:
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
        return Steps(ts, ys, interpolants, out.rejected[:count] if out.rejected.size else None)

    def _settings(self, control: Control, n: int) -> tuple:
        """The adaptive loop's :class:`SolveProblem` (``atol`` as an (n,) array) and the
        controller's settings, kept for the run."""
        if self._control[0] is not control:
            atol = np.array(control.atol, dtype=float)  # a number, or shape () or (n,)
            atol = np.full(n, atol) if atol.ndim == 0 else atol
            rule = control.controller
            settings = (float(rule.safety), float(rule.min_factor), float(rule.max_factor),
                        int(self.error_order), float(control.horizon or 0.0))  # fmt: skip
            tab = self.tab
            problem = _new(AdaptiveSolveProblem, (self.jitted, tab.arrays, tab.hermite,
                                                  self.interpolants, float(control.rtol),
                                                  atol, settings[3], settings[4]))  # fmt: skip
            self._control = (control, problem, settings)
        return self._control[1], self._control[2]


_new = tuple.__new__
"""A named tuple from a tuple without its ``__new__`` in Python (0.3 µs of a short call)."""
_NONE = np.empty(0, dtype=np.int64)
"""The rejections of a fixed block's record: none (never written)."""


def _arrays(size: int, n: int, q: int, want_q: bool, *, adaptive: bool) -> SolveRecords:
    """A block's :class:`SolveRecords` (the rejections for an adaptive one only)."""
    rejected = np.empty(size, dtype=np.int64) if adaptive else _NONE
    return _new(SolveRecords, (np.empty(size), np.empty((size, n)),
                               np.empty((size if want_q else 0, n, q)), rejected))  # fmt: skip
