"""The loop templates (tumble.ode.templates): every family's compiled loop is one of them,
and a bound step holds no reference count per step (LoopCompiler)."""

import re
from typing import NamedTuple

import numpy as np
import pytest

from tumble.ode import templates
from tumble.ode.templates import OK, LoopCompiler


def family_loops() -> dict[str, object]:
    """Every compiled loop a family hands to its stepper."""
    from tumble.ode import compiled
    from tumble.rigid._compiled.charts import COMPILED
    from tumble.rigid._compiled.crouch_grossman import COMPILED_CG
    from tumble.rigid._compiled.flows import COMPILED_FLOWS
    from tumble.structural.schemes import SCHEMES

    loops = {"solve fixed": compiled._FIXED, "solve adaptive": compiled._ADAPTIVE,
             "crouch-grossman": COMPILED_CG.loop}  # fmt: skip
    for name, chart in COMPILED.items():
        loops[f"chart {name}"] = chart.loop
        if chart.adaptive is not None:
            loops[f"chart {name} adaptive"] = chart.adaptive
    for name, flow in COMPILED_FLOWS.items():
        loops[f"flow {name}"] = flow.loop
    for name, scheme in SCHEMES.items():
        loops[f"scheme {name}"] = scheme.kernel.loop
    return loops


@pytest.mark.parametrize("name", family_loops())
def test_every_family_loop_is_a_template_compiled_by_the_loop_compiler(name):
    loop = family_loops()[name]
    code = {templates.fixed_loop.__code__, templates.adaptive_loop.__code__}
    assert loop.py_func.__code__ in code
    assert loop._compiler.pipeline_class is LoopCompiler


# A small family whose step has what makes numba count references: a problem and a state of
# several arrays in tuples, unpacked in an inlined step with loops and a branch.


class _Problem(NamedTuple):
    rate: np.ndarray
    scale: np.ndarray
    limit: np.ndarray


class _Records(NamedTuple):
    t: np.ndarray
    y: np.ndarray


def _work(problem, state):
    return np.empty(state[0].size), np.empty(state[0].size), np.empty(1), np.empty(2)


def _fill(v, value):
    for i in range(v.size):
        v[i] = value


def _step(problem, state, work, t, t_new, settle):
    """Explicit Euler on ``y' = −rate · y`` into a scratch vector, kept if below ``limit``
    (the step before kept in ``spare``, cleared when ``limit`` is negative: never)."""
    y, spare = state
    new, _, _, _ = work
    rate, scale, limit = problem.rate, problem.scale, problem.limit
    h = t_new - t
    for i in range(y.size):
        new[i] = y[i] - h * rate[i] * scale[i] * y[i]
    if abs(new[0]) > limit[0]:
        return 1
    for i in range(y.size):
        spare[i], y[i] = y[i], new[i]
    if limit[0] < 0.0:  # an array into inlined code under a branch: numba counts it
        FILL(spare, 0.0)  # noqa: F821
    return OK


def _record(problem, state, work, records, i):
    records.y[i, 0] = state[0][0]


def _compile(**options):
    from numba import njit

    inline = njit(inline="always")
    step = inline(templates.bind(_step, "_euler_step", FILL=inline(_fill)))
    bound = templates.bind(templates.fixed_loop, "_euler_loop", WORK=inline(_work), STEP=step,
                           RECORD=inline(_record))  # fmt: skip
    return njit(error_model="numpy", **options)(bound)


def _refcounts_per_step(loop) -> int:
    """NRT_incref calls in the blocks of the loop function's LLVM IR that lie on a cycle."""
    (ir,) = loop.inspect_llvm().values()
    start = re.search(r"^define [^\n]*_euler_loop", ir, re.M)
    assert start is not None
    body = ir[start.start() : ir.index("\n}\n", start.start())]
    blocks, label = {}, "entry"
    for line in body.split("\n")[1:]:
        found = re.match(r"^([\w.$\-]+):", line)
        if found:
            label = found.group(1)
        blocks.setdefault(label, []).append(line)
    successors = {b: re.findall(r"label %([\w.$\-]+)", "\n".join(ls)) for b, ls in blocks.items()}

    def on_cycle(block: str) -> bool:
        seen, todo = set(), list(successors[block])
        while todo:
            b = todo.pop()
            if b == block:
                return True
            if b not in seen:
                seen.add(b)
                todo.extend(successors.get(b, []))
        return False

    return sum("@NRT_incref" in line for b, ls in blocks.items() if on_cycle(b) for line in ls)


def _run(loop):
    n = 4
    problem = _Problem(np.full(n, 2.0), np.full(n, 0.5), np.array([10.0]))
    state = (np.linspace(1.0, 2.0, n), np.zeros(n))
    records = _Records(np.empty(50), np.empty((50, 1)))
    result = loop(problem, (0.0, 1.0, 0.02, 50), state, 0, 50, 1, 0, records)
    return result, state, records


def test_the_loop_compiler_leaves_no_reference_count_in_the_step_loop():
    default, forwarded = _compile(), _compile(pipeline_class=LoopCompiler)
    runs = _run(default), _run(forwarded)
    assert runs[0][0] == runs[1][0] == (50, -1, OK)
    for a, b in zip(runs[0][1] + runs[0][2], runs[1][1] + runs[1][2], strict=True):
        np.testing.assert_array_equal(a, b)  # the same operations: the same bits
    # numba's pipeline: arrays the step binds from its tuples, counted at each step where its
    # pruning pass cannot reach past the branch (2 or 3 with numba 0.68; if a numba prunes
    # them all, the loop compiler has nothing left to do); the loop compiler's: none
    assert _refcounts_per_step(default) >= 1
    assert _refcounts_per_step(forwarded) == 0
