"""The loops that advance time in compiled code: one fixed-step and one adaptive template.

A family of methods (a chart of the rigid body, a splitting, a structural scheme, ``solve``'s
Runge–Kutta steps) does not write a loop. It contributes numba functions, and :func:`loop`
compiles a template with them as its globals:

==============  ==========================================================================
name            what it does
==============  ==========================================================================
``WORK``        ``WORK(problem, state) -> work``: the scratch arrays, made once per call
``STEP``        ``STEP(problem, state, work, t, t_new, settle) -> cause``: one fixed step
                from ``t`` to ``t_new`` in place (``settle``: this step's end is recorded
                or handed back); what a cause other than :data:`OK` leaves in ``state`` is
                the family's to say
``CHECK``       ``CHECK(problem, state, work, k) -> cause``: after step ``k`` and its
                record, whether the run goes on (default: :data:`OK`)
``FINISH``      ``FINISH(problem, state, work)``: before a fixed block hands its state
                back, at its end or at a failure (default: nothing)
``FIRST_STEP``  ``FIRST_STEP(problem, state, work, t) -> h``: the adaptive loop's first
                step when it is called with ``h <= 0``
``TRY``         ``TRY(problem, state, work, t, h, have_first, share) -> norm``: one
                adaptive try into ``work`` (the state untouched) and its error norm per
                unit step ``share``
``FINITE``      ``FINITE(problem, state, work) -> bool``: whether the tried state is finite
``ACCEPT``      ``ACCEPT(problem, state, work, t, t_new, fsal) -> has_first``: the state
                tried from ``t`` becomes the state at ``t_new``; returns whether the next
                try knows its first stage (FSAL)
``RECORD``      ``RECORD(problem, state, work, records, i)``: sample ``i`` (``records.t[i]``
                is written by the loop)
==============  ==========================================================================

Both loops land steps on :func:`~tumble.ode.control.grid_time` (fixed) or on ``t1``
(adaptive), record step ``k`` when ``step0 + k`` is a multiple of ``every``, and stop with
one of the causes below, which :func:`tumble.ode.driver.march` turns into a
:class:`~tumble.ode.driver.Status` and a message. The adaptive loop is the driver's adaptive
loop (:func:`~tumble.ode.control.step_factor`, :func:`~tumble.ode.control.minimum_step`,
compiled from those very functions), so the Python and compiled paths cannot drift apart.

numba inlines the bound functions (``inline="always"``), so a family's loop compiles to what
a hand-written loop would, with one exception that :class:`LoopCompiler` removes: inlining
binds each argument of a bound function, and each array a tuple argument holds, to a new
variable, and numba counts a reference to every array so bound, at each step (an atomic
update each, which its pruning pass cannot remove across a step body of loops and
branches). Measured: the split-axes flow's 0.085 µs step took 0.15 µs bound without it
(``benchmarks/bench_renovation.py``). And since :func:`bind` gives each binding a name of
its own, each is cached on disk like any ``cache=True`` function.
"""

from __future__ import annotations

import math
import types
from typing import Any

from numba import njit
from numba.core import ir, ir_utils
from numba.core import types as nbtypes
from numba.core.compiler import CompilerBase, DefaultPassBuilder
from numba.core.compiler_machinery import FunctionPass, register_pass
from numba.core.typed_passes import NopythonTypeInference

from tumble.ode import control
from tumble.ode.contract import MINIMUM_STEP, NON_FINITE, OK, UNCONVERGED

__all__ = [
    "MINIMUM_STEP",
    "NON_FINITE",
    "OK",
    "UNCONVERGED",
    "LoopCompiler",
    "adaptive_loop",
    "bind",
    "fixed_loop",
    "loop",
]


JIT: dict[str, Any] = dict(cache=True, error_model="numpy")  # no ZeroDivisionError checks
INLINE: dict[str, Any] = dict(JIT, inline="always")

GRID_TIME = njit(**INLINE)(control.grid_time)
STEP_FACTOR = njit(**INLINE)(control.step_factor)
MINIMUM_STEP_OF = njit(**INLINE)(control.minimum_step)

_PURE_READS = ("static_getitem", "getattr", "exhaust_iter")
"""The reads of a tuple that :class:`LoopCompiler` moves to where the tuple is made."""


def _definitions(blocks: dict) -> tuple[dict[str, int], dict[str, int]]:
    """How many times each variable is assigned, and the block of its (last) assignment."""
    count: dict[str, int] = {}
    where: dict[str, int] = {}
    for label, block in blocks.items():
        for stmt in block.body:
            if isinstance(stmt, ir.Assign):
                count[stmt.target.name] = count.get(stmt.target.name, 0) + 1
                where[stmt.target.name] = label
    return count, where


def _forward_copies(blocks: dict, typemap: dict) -> None:
    """``a = b`` with ``a`` and ``b`` each assigned once and of one type: every use of ``a``
    becomes ``b`` and the copy goes (what inlining writes for each argument)."""
    count, _ = _definitions(blocks)
    rename = {}
    for block in blocks.values():
        kept = []
        for stmt in block.body:
            if (
                isinstance(stmt, ir.Assign)
                and isinstance(stmt.value, ir.Var)
                and count.get(stmt.target.name) == 1
                and count.get(stmt.value.name) == 1
                and typemap[stmt.target.name] == typemap[stmt.value.name]
            ):
                rename[stmt.target.name] = stmt.value.name
            else:
                kept.append(stmt)
        block.body = kept
    ir_utils.replace_var_names(blocks, rename)


def _fold_built_tuples(blocks: dict, typemap: dict) -> None:
    """An item of a tuple built in place (``a, b, c, d = w[0], w[1], w[2], w[3]`` builds one
    and unpacks it) becomes the variable it was built from."""
    built = {}
    for block in blocks.values():
        for stmt in block.body:
            if isinstance(stmt, ir.Assign) and isinstance(stmt.value, ir.Expr):
                if stmt.value.op == "build_tuple":
                    built[stmt.target.name] = stmt.value.items
                elif stmt.value.op == "exhaust_iter" and stmt.value.value.name in built:
                    built[stmt.target.name] = built[stmt.value.value.name]
    for block in blocks.values():
        for stmt in block.body:
            value = stmt.value if isinstance(stmt, ir.Assign) else None
            if (
                isinstance(value, ir.Expr)
                and value.op == "static_getitem"
                and value.value.name in built
                and isinstance(value.index, int)
            ):
                item = built[value.value.name][value.index]
                if typemap[item.name] == typemap[stmt.target.name]:
                    stmt.value = item


def _drop_unused(blocks: dict) -> None:
    """Copies, built tuples and reads of tuples whose results nothing uses (left by the
    folds above): numba would still count their references."""
    pure = ("build_tuple", *_PURE_READS)

    def read(stmt) -> list:
        if not isinstance(stmt, ir.Assign):
            return stmt.list_vars()
        value = stmt.value
        return [value] if isinstance(value, ir.Var) else value.list_vars() if isinstance(
            value, ir.Expr) else []  # fmt: skip

    dropped = True
    while dropped:
        used = {v.name for block in blocks.values() for stmt in block.body for v in read(stmt)}
        dropped = False
        for block in blocks.values():
            kept = [
                stmt for stmt in block.body
                if not (
                    isinstance(stmt, ir.Assign) and stmt.target.name not in used
                    and (isinstance(stmt.value, ir.Var)
                         or isinstance(stmt.value, ir.Expr) and stmt.value.op in pure)
                )
            ]  # fmt: skip
            dropped = dropped or len(kept) < len(block.body)
            block.body = kept


def _hoist_tuple_reads(blocks: dict, typemap: dict) -> None:
    """Each read of a tuple (an item, a field, its unpacking) placed just after the tuple's
    one assignment: read once per call, not once per step."""
    moved = True
    while moved:  # a read of a read follows it on the next round
        moved = False
        count, where = _definitions(blocks)
        for label, block in blocks.items():
            for stmt in list(block.body):
                value = stmt.value if isinstance(stmt, ir.Assign) else None
                if not (isinstance(value, ir.Expr) and value.op in _PURE_READS):
                    continue
                source = value.value.name
                if (
                    count.get(source) != 1
                    or count.get(stmt.target.name) != 1
                    or where[source] == label
                    or not isinstance(typemap[source], nbtypes.BaseTuple)
                ):
                    continue
                home = blocks[where[source]].body
                at = next(
                    i for i, s in enumerate(home)
                    if isinstance(s, ir.Assign) and s.target.name == source
                )  # fmt: skip
                if isinstance(home[at].value, ir.Expr) and home[at].value.op == "phi":
                    continue  # phis stay first in their block
                block.body.remove(stmt)
                home.insert(at + 1, stmt)
                where[stmt.target.name] = where[source]
                moved = True


@register_pass(mutates_CFG=False, analysis_only=False)
class _ForwardInvariants(FunctionPass):
    """Typed IR in SSA form (after type inference, before the phis are stripped): forward
    the copies inlining makes and hoist the tuples' reads (:class:`LoopCompiler`)."""

    _name = "tumble_forward_invariants"

    def __init__(self) -> None:
        FunctionPass.__init__(self)

    def run_pass(self, state) -> bool:
        blocks = state.func_ir.blocks
        if any(isinstance(s, ir.Del) for b in blocks.values() for s in b.body):
            return False  # a numba that places its dels before lowering: leave it alone
        _forward_copies(blocks, state.typemap)
        _fold_built_tuples(blocks, state.typemap)
        _forward_copies(blocks, state.typemap)
        _drop_unused(blocks)
        _hoist_tuple_reads(blocks, state.typemap)
        state.func_ir._definitions = ir_utils.build_definitions(blocks)
        return True


class LoopCompiler(CompilerBase):
    """numba's nopython pipeline with one pass more, after type inference, for the bound
    loops (:func:`loop`).

    Inlining a function binds its parameters to the caller's values by copies (``param =
    arg``), and numba counts a reference to every array a copy holds (each array in a tuple
    too) when it is made and when it dies: inside the step loop that is one atomic
    increment and one decrement per array per step, which numba's pruning pass removes
    only when no other release lies between them, never across a step body of loops and
    branches. The pass forwards those copies (each is assigned once, in SSA form) and moves
    every read of a tuple (an item, a field, its unpacking: pure, a tuple never changes) to
    just after the tuple is made, so that a step binds no array at all. The numbers do not
    change; only where references are counted.
    """

    def define_pipelines(self) -> list:
        pm = DefaultPassBuilder.define_nopython_pipeline(self.state)
        pm.add_pass_after(_ForwardInvariants, NopythonTypeInference)
        pm.finalize()
        return [pm]


def bind(template, name: str, **functions):
    """``template`` with ``functions`` as its globals, under its own name (not compiled).

    numba's on-disk cache is keyed by a function's qualified name and code, so each family's
    loop gets a name of its own; a closure over compiled functions would miss the cache.
    """
    bound = types.FunctionType(template.__code__, {**template.__globals__, **functions}, name)
    bound.__qualname__ = name
    bound.__doc__ = template.__doc__
    return bound


def loop(template, name: str, *, cache: bool = True, nogil: bool = False, **functions):
    """``template`` (:func:`fixed_loop` or :func:`adaptive_loop`) bound to a family's
    ``functions`` (:func:`bind`) and compiled by :class:`LoopCompiler`. ``cache=False`` for
    a loop whose types hold a function (``solve``'s right-hand side: one compilation per
    function, which numba cannot take from its cache); ``nogil`` releases the GIL."""
    options = dict(JIT, cache=cache, nogil=nogil, pipeline_class=LoopCompiler)
    return njit(**options)(bind(template, name, **functions))


@njit(**INLINE)
def CHECK(problem, state, work, k):  # noqa: N802
    """The default ``CHECK``: every step goes on."""
    return OK


@njit(**INLINE)
def FINISH(problem, state, work):  # noqa: N802
    """The default ``FINISH``: nothing to hand back."""


@njit(**INLINE)
def FIRST_STEP(problem, state, work, t):  # noqa: N802
    """The default ``FIRST_STEP``, for families that always give one: none (0)."""
    return 0.0


def fixed_loop(problem, grid, state, k0, k1, every, step0, records):
    """Steps ``k0+1 … k1`` of ``grid`` (a :class:`~tumble.ode.driver.Grid`) by ``STEP``.

    Step ``k`` goes from ``grid_time(k − 1)`` to ``grid_time(k)``, is recorded (``RECORD``)
    when ``step0 + k`` is a multiple of ``every`` and then checked (``CHECK``). Returns
    ``(recorded, failed, cause)``: ``failed`` is the step whose ``STEP`` or ``CHECK``
    returned ``cause``, or −1 with ``cause`` :data:`OK`. ``FINISH`` runs before each return.
    """
    t_a, t_b, h, n = grid
    work = WORK(problem, state)  # noqa: F821
    count, until_record = 0, every - (step0 + k0) % every
    for k in range(k0 + 1, k1 + 1):
        t_old = GRID_TIME(t_a, t_b, h, k - 1, n)
        t_new = GRID_TIME(t_a, t_b, h, k, n)
        cause = STEP(problem, state, work, t_old, t_new, until_record == 1 or k == k1)  # noqa: F821
        if cause == OK:
            until_record -= 1
            if until_record == 0:
                records.t[count] = t_new
                RECORD(problem, state, work, records, count)  # noqa: F821
                count += 1
                until_record = every
            cause = CHECK(problem, state, work, k)
        if cause != OK:
            FINISH(problem, state, work)
            return count, k, cause
    FINISH(problem, state, work)
    return count, -1, OK


def adaptive_loop(problem, t, t1, h, settings, fsal, state, every, step0, max_steps, records):
    """Adaptive steps from ``t`` towards ``t1``: :func:`tumble.ode.driver.march` with a
    :class:`~tumble.ode.driver.Control`, compiled.

    ``h <= 0`` asks ``FIRST_STEP`` for the first step. Each try (``TRY``) gives its error
    norm; :func:`~tumble.ode.control.step_factor` gives the next step; a rejected try is
    tried again from the accepted state, and a step below
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
    if h <= 0.0:
        h = FIRST_STEP(problem, state, work, t)
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
        have_first = ACCEPT(problem, state, work, t, t_new, fsal)  # noqa: F821
        t = t_new
        accepted += 1
        until_record -= 1
        if until_record == 0:
            records.t[count] = t
            RECORD(problem, state, work, records, count)  # noqa: F821
            count += 1
            until_record = every
    return count, t, h, accepted, rejected, OK, t, True
