"""Every example's run() reproduces its reference numbers."""

import importlib.util
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).parents[1] / "examples"


def load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_projectile_example_hits_the_ground_where_spec_says():
    numbers = load("projectile").run()
    assert numbers["impact_time"] == pytest.approx(72.080202, rel=1e-6)
    assert numbers["range"] == pytest.approx(25484.1998, rel=1e-6)
