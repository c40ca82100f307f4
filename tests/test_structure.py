"""The shape of the code that issue 25 asked for, kept: sizes, names, no switches on schemes
(the rigid families have theirs in ``tests/rigid/test_rigid_families.py``).

Each test reads the source tree (``src/tumble``) with :mod:`ast`, so it fails on the commit
that breaks the rule and names the place.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parents[1] / "src" / "tumble"
FILES = sorted(SOURCE.rglob("*.py"))
MAX_FILE_LINES = 700
MAX_FUNCTION_LINES = 80  # lines of code: no docstring, blank or comment-only lines


def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(), filename=str(path))


def _code_lines(node: ast.FunctionDef | ast.AsyncFunctionDef, lines: list[str]) -> int:
    docstring: set[int] = set()
    first = node.body[0]
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
        if isinstance(first.value.value, str):
            docstring = set(range(first.lineno, (first.end_lineno or first.lineno) + 1))
    end = node.end_lineno or node.lineno
    return sum(
        1
        for number in range(node.lineno, end + 1)
        if number not in docstring
        and lines[number - 1].strip()
        and not lines[number - 1].strip().startswith("#")
    )


def test_the_tree_is_there():
    assert len(FILES) > 50  # a wrong SOURCE would pass every test below


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(SOURCE)))
def test_no_source_file_is_over_700_lines(path):
    assert len(path.read_text().splitlines()) <= MAX_FILE_LINES


def test_no_function_is_over_80_lines_of_code():
    long = []
    for path in FILES:
        lines = path.read_text().splitlines()
        for node in ast.walk(_tree(path)):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                size = _code_lines(node, lines)
                if size > MAX_FUNCTION_LINES:
                    long.append(f"{path.relative_to(SOURCE)}:{node.lineno} {node.name} ({size})")
    assert not long, long


def test_the_line_counter_counts_code_only():
    source = 'def f():\n    """Doc.\n\n    More."""\n    # note\n\n    return 1\n'
    node = ast.parse(source).body[0]
    assert isinstance(node, ast.FunctionDef)
    assert _code_lines(node, source.splitlines()) == 2


def test_public_class_names_are_unique():
    where = defaultdict(list)
    for path in FILES:
        for node in ast.walk(_tree(path)):
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                where[node.name].append(str(path.relative_to(SOURCE)))
    clashes = {name: paths for name, paths in where.items() if len(paths) > 1}
    assert not clashes, clashes


def _subclasses(cls: type) -> set[type]:
    found = set(cls.__subclasses__())
    for sub in list(found):
        found |= _subclasses(sub)
    return found


def test_no_structural_scheme_is_tested_by_its_class():
    """What a scheme does is asked of the scheme (the ``Scheme`` protocol); only the registry
    may check that an object is a ``Scheme`` at all."""
    from tumble.structural.scheme import Scheme
    from tumble.structural.schemes import SCHEMES

    schemes = {cls.__name__ for cls in _subclasses(Scheme)}
    assert {type(scheme).__name__ for scheme in SCHEMES.values()} <= schemes
    found = []
    for path in FILES:
        for node in ast.walk(_tree(path)):
            if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "isinstance":
                names = {n.id for n in ast.walk(node.args[1]) if isinstance(n, ast.Name)}
                if names & schemes:
                    found.append(f"{path.relative_to(SOURCE)}:{node.lineno}")
    assert not found, found


STEPPER = {"step", "accept", "interpolant", "norm", "record", "error_order", "time_axis",
           "compiled"}  # fmt: skip
"""What a stepper of the one driver is: four methods, the record of a state, the order of
its error estimate, its record's time axis, and its optional compiled part."""
COMPILED_PART = ("march_block", "march_adaptive", "rewind", "steps", "block_steps")
"""The compiled part: its blocks (fixed, adaptive), what a terminal event makes it forget,
whether its blocks return their steps, and how many steps a block may take."""
OLD_CONTRACT = {"blocks", "adaptive_blocks", "block_interpolants", "block_steps", "finite",
                "failure", "scale", "march_block", "march_adaptive", "rewind", "in_place",
                "adaptive"}  # fmt: skip
"""The flags and methods of the contract before issue 25 (12 methods, 7 flags and
``in_place``), gone from every stepper class."""


def test_the_stepper_contract_is_narrow():
    """A stepper is :data:`STEPPER`, its compiled part :data:`COMPILED_PART` (and the one
    question the driver asks it, ``takes``); no stepper class keeps the old flags."""
    from tumble.ode.contract import Compiled, Stepper

    assert {name for name in vars(Stepper) if not name.startswith("_")} == STEPPER
    assert Compiled._fields == COMPILED_PART
    methods = {name for name in vars(Compiled) if not name.startswith("_")}
    assert methods - set(COMPILED_PART) == {"takes"}
    import tumble.ode.compiled
    import tumble.rigid.batch
    import tumble.structural.stepping  # noqa: F401  (every stepper class of the library)

    classes = {cls for cls in _subclasses(Stepper) if cls.__module__.startswith("tumble.")}
    assert len(classes) >= 10
    stale = {
        f"{cls.__module__}.{cls.__name__}.{name}"
        for cls in classes
        for name in vars(cls)
        if name in OLD_CONTRACT
    }
    assert not stale, sorted(stale)


def test_the_driver_reads_of_a_stepper_only_its_contract():
    """Every attribute :mod:`tumble.ode.driver` takes of a stepper (``stepper.x``,
    ``run.stepper.x``) or of its compiled part (``part.x``) is in the contract: the driver
    chooses its loop by asking whether there is a compiled part for the run, not by flags."""
    tree = _tree(SOURCE / "ode" / "driver.py")
    read = defaultdict(set)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute):
            owner = node.value
            name = owner.id if isinstance(owner, ast.Name) else getattr(owner, "attr", "")
            if name in ("stepper", "part"):
                read[name].add(node.attr)
    assert read["stepper"] and read["stepper"] <= STEPPER, read["stepper"]
    assert read["part"] and read["part"] <= {*COMPILED_PART, "takes"}, read["part"]


# The loops that advance time in compiled code (issue 25): the two templates of
# tumble/ode/templates.py, which every family binds, and the batch's structure-of-arrays loop
# (tumble/rigid/soa.py: bodies as SIMD columns, the declared exception).
TIME_LOOPS = {("ode/templates.py", "fixed_loop"), ("ode/templates.py", "adaptive_loop"),
              ("rigid/soa.py", "_block")}  # fmt: skip
COMPILERS = {"njit", "jit", "bind", "loop", "time_loop"}  # also with a leading underscore
"""Calls that compile a function or bind it into compiled code (their first argument)."""
TIME_NAMES = {"t", "t_old", "t_new", "time"}
"""Assigned inside a loop: the loop moves time on."""
STEP_CALLS = {"STEP", "TRY", "GRID_TIME", "STEP_FACTOR", "MINIMUM_STEP_OF", "MINIMUM_STEP",
              "grid_time", "step_factor", "minimum_step"}  # fmt: skip
"""Called inside a loop (also with a leading underscore): a step, or the clock of one."""


def _name(node: ast.AST) -> str:
    """``f`` of ``f``, ``a.f`` and ``f(…)`` (a call that returns a compiler: ``njit(…)``)."""
    if isinstance(node, ast.Call):
        return _name(node.func)
    if isinstance(node, ast.Attribute):
        return node.attr
    return node.id if isinstance(node, ast.Name) else ""


def compiled_functions(files: list[Path]) -> set[str]:
    """The names of the module-level functions that are compiled: decorated by ``njit``/
    ``jit``, handed to a compiler or binder (:data:`COMPILERS`) or rebuilt from their
    ``__code__`` anywhere in ``files``."""
    names = set()
    for path in files:
        for node in ast.walk(_tree(path)):
            if isinstance(node, ast.FunctionDef):
                if any(_name(d) in {"njit", "jit"} for d in node.decorator_list):
                    names.add(node.name)
            elif isinstance(node, ast.Call) and node.args:
                if _name(node.func).lstrip("_") in COMPILERS:
                    names.add(_name(node.args[0]))
            elif isinstance(node, ast.Attribute) and node.attr == "__code__":
                names.add(_name(node.value))  # a function rebuilt from its code, to bind it
    return names


def _over_steps(loop: ast.For | ast.While) -> bool:
    """``for k in range(k0 + 1, k1 + 1)``, ``range(1, n + 1)``: a loop over step numbers."""
    call = loop.iter if isinstance(loop, ast.For) else None
    if not (isinstance(call, ast.Call) and _name(call.func) == "range" and len(call.args) == 2):
        return False
    stop = call.args[1]
    return (
        isinstance(stop, ast.BinOp) and isinstance(stop.op, ast.Add)
        and isinstance(stop.left, ast.Name | ast.Attribute)
        and isinstance(stop.right, ast.Constant) and stop.right.value == 1
    )  # fmt: skip


def _advances_time(function: ast.FunctionDef) -> bool:
    for loop in ast.walk(function):
        if not isinstance(loop, ast.For | ast.While):
            continue
        if _over_steps(loop):
            return True
        for node in ast.walk(loop):
            targets = node.targets if isinstance(node, ast.Assign) else (
                [node.target] if isinstance(node, ast.AugAssign) else [])  # fmt: skip
            names = {n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)}
            if names & TIME_NAMES:
                return True
            if isinstance(node, ast.Call) and _name(node.func).lstrip("_") in STEP_CALLS:
                return True
    return False


def time_loops(source: Path) -> set[tuple[str, str]]:
    """``(file, function)`` of every compiled function under ``source`` with a loop that
    advances time: a loop over step numbers (:func:`_over_steps`), or one that assigns a
    time (:data:`TIME_NAMES`) or calls a step or its clock (:data:`STEP_CALLS`). Read from
    the source, so a heuristic: it finds every such loop of the tree before issue 25 (9)
    and after its first part (7), and the test below checks its forms."""
    files = sorted(source.rglob("*.py"))
    compiled = compiled_functions(files)
    found = set()
    for path in files:
        for node in _tree(path).body:
            if (
                isinstance(node, ast.FunctionDef)
                and node.name in compiled
                and _advances_time(node)
            ):
                found.add((str(path.relative_to(source)), node.name))
    return found


def test_time_advances_in_compiled_code_only_in_the_templates_and_the_batch_loop():
    """A family binds the templates (``templates.loop``); a new hand-written compiled time
    loop fails here, by its file and name."""
    assert time_loops(SOURCE) == TIME_LOOPS


def test_the_time_loop_finder_finds_a_hand_written_loop(tmp_path):
    (tmp_path / "family.py").write_text(
        "from numba import njit\n\n"
        "@njit\ndef _loop(y, h, n):\n    for k in range(n):\n        t_new = k * h\n"
        "        y = STEP(y, t_new)\n    return y\n\n"
        "def _step_loop(y, n):\n    for k in range(n):\n        y = STEP(y)\n    return y\n\n"
        "LOOP = njit(bind(_step_loop, 'x', STEP=None))\n\n"
        "@njit\ndef _steps(x, first, last):\n    for k in range(first + 1, last + 1):\n"
        "        x = 2 * x\n    return x\n\n"
        "@njit\ndef _band(x, p, b):\n    for j in range(1, min(p, b) + 1):\n        x += j\n"
        "    return x\n\n"
        "def python_loop(n):\n    for k in range(n):\n        t = k\n    return t\n"
    )
    assert time_loops(tmp_path) == {("family.py", n) for n in ("_loop", "_step_loop", "_steps")}
