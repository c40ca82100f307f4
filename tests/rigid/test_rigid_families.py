"""The families of :data:`tumble.rigid.methods.FAMILIES`: what each declares holds, and no
module of ``tumble`` tells families apart by their names (issue 25)."""

import ast
from pathlib import Path

import numpy as np
import pytest

import tumble
from tumble import so3
from tumble.rigid import METHODS, RigidBody, simulate
from tumble.rigid.families import Family
from tumble.rigid.forces import compiled_loads
from tumble.rigid.methods import FAMILIES

SOURCE = Path(tumble.__file__).parent
REGISTRY = {SOURCE / "rigid" / "families.py", SOURCE / "rigid" / "methods.py"}
"""Where a family's name may be spelled out: the families and their registration."""


def _names_in(node: ast.expr) -> set[str]:
    """The family names a literal spells: a string, or a tuple, list or set of them."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return {node.value} & FAMILIES.keys()
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return set().union(*(_names_in(item) for item in node.elts))
    return set()


def _name_tests(path: Path, root: Path = SOURCE) -> list[str]:
    """Each comparison (``==``, ``!=``, ``in``, …) or ``match`` case of ``path`` against a
    family's name, as ``file:line: code`` (the file relative to ``root``)."""
    found, where = [], path.relative_to(root)
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Compare):
            if any(_names_in(operand) for operand in [node.left, *node.comparators]):
                found.append(f"{where}:{node.lineno}: {ast.unparse(node)}")
        elif isinstance(node, ast.match_case):
            for pattern in ast.walk(node.pattern):
                if isinstance(pattern, ast.MatchValue) and _names_in(pattern.value):
                    found.append(f"{where}:{pattern.lineno}: case {ast.unparse(pattern)}")
    return found


def test_no_module_outside_the_registry_tests_a_family_name():
    tests = [
        line
        for path in sorted(SOURCE.rglob("*.py"))
        if path not in REGISTRY
        for line in _name_tests(path)
    ]
    assert not tests, "ask the family (tumble.rigid.families) instead:\n" + "\n".join(tests)


def test_the_name_check_finds_the_tests_main_had(tmp_path):
    # Forms of the 11 tests main had before issue 25 (and a match), beside a string that
    # only happens to be a family's name.
    module = tmp_path / "module.py"
    module.write_text(
        'if method.family == "split":\n    pass\n'
        'kept = spec.family in ("lie", "quat")\n'
        'quat = self.chart.name != "quat"\n'
        'match chart.name:\n    case "quat":\n        pass\n'
        'label = "split" if fast else "slow"\n',
        encoding="utf-8",
    )
    found = [line.split(": ", 1)[0] for line in _name_tests(module, tmp_path)]
    assert found == ["module.py:1", "module.py:3", "module.py:4", "module.py:6"]


@pytest.mark.parametrize("name", METHODS)
def test_every_method_names_a_registered_family(name):
    assert isinstance(FAMILIES[METHODS[name].family], Family)


@pytest.fixture(scope="module")
def body():
    return RigidBody(2.0, [[2.0, 0.1, 0.0], [0.1, 1.5, 0.05], [0.0, 0.05, 1.0]])


@pytest.mark.parametrize("name", FAMILIES)
def test_a_batch_state_packs_and_reads_back_to_its_rotations(body, name):
    family = FAMILIES[name]
    rng = np.random.default_rng(7)
    R = so3.exp(rng.normal(size=(5, 3)))
    Y = rng.normal(size=(5, 9))
    axes = np.broadcast_to(family.frame(body.inertia)[1], (5, 3, 3))
    attitude, Y_started = family.start(R, Y, axes)
    Z, RN = family.pack(attitude, Y_started)
    attitude_read, Y_read = family.read(Z, RN)
    np.testing.assert_array_equal(Y_read, Y)
    # q ↦ R and R P Pᵀ are a few roundings of order one
    np.testing.assert_allclose(family.matrix(attitude_read, axes), R, atol=1e-15)


@pytest.mark.parametrize("name", METHODS)
def test_what_a_run_records_and_compiles_is_what_its_family_declares(body, name):
    method, step = METHODS[name], {"rtol": 1e-6} if METHODS[name].adaptive else {"h": 0.05}
    run = simulate(body, 0.2, method=name, omega0=(0.3, 1.0, -0.2), **step)
    family = FAMILIES[method.family]
    assert (run.q_raw is not None) == family.quaternion
    assert run.settings["compiled"] == family.compiles(method, compiled_loads([], body.mass))
    assert method.conserves == family.conserves(method) >= {"angular_momentum"}
