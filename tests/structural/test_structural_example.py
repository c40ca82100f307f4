"""examples/beam.py runs and reproduces its reference numbers."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from tumble.structural import SCHEMES

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "beam.py"


@pytest.fixture(scope="module")
def numbers():
    spec = importlib.util.spec_from_file_location("tumble_example_beam", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.run(n_elements=20, n_steps=400)


def test_example_reproduces_the_seed_frequencies(numbers):
    # SPEC §4 figures, to their 6 digits for ω₁ and within the FE error for ω₄
    np.testing.assert_allclose(numbers["omega"][0], 52.4971, rtol=1e-5)
    np.testing.assert_allclose(numbers["omega"][3], 1805.17, rtol=1e-3)


def test_example_reports_the_semi_implicit_limit(numbers):
    # 2/ω_max with ω_max = 357609.68 rad/s (dense eigen-solve, 40 DOFs)
    np.testing.assert_allclose(numbers["critical_dt"], 5.59268982e-6, rtol=1e-8)
    assert numbers["critical_mode"] == "bending"


def test_example_energy_behaviour(numbers):
    # at T₁/200 the two explicit schemes are far above 2/ω_max; every other scheme of the
    # registry is stable at every Δt
    failed = {"explicit": "FAILED", "semi-implicit": "FAILED"}
    assert numbers["status"] == {name: failed.get(name, "SUCCESS") for name in SCHEMES}
    assert numbers["midpoint_energy_drift"] < 1e-9  # measured 1e-14
    assert numbers["implicit_energy_final"] < -0.1  # backward Euler has lost energy
    assert numbers["newmark_minus_midpoint"] < 1e-8 * 4e-3  # |x| ≤ 2 F L³/(3EI) = 3.8 mm


def test_example_tip_swings_to_twice_the_static_deflection(numbers):
    # 400 steps = 2 periods of mode 1 (measured peak 1.995)
    assert abs(numbers["tip_max_over_static"] - 2) < 1e-2
    assert abs(numbers["tip_mean_over_static"] - 1) < 2e-2
