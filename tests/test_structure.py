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
