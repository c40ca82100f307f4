"""The steel cantilever every structural command shares, and the time-step analyser."""

import inspect

import numpy as np
import pytest

from tumble import structural
from tumble.scenarios import beam


@pytest.mark.parametrize("option", sorted(beam.STEEL))
def test_the_beam_scenario_defaults_to_the_steel_cantilever(option):
    assert inspect.signature(beam.run).parameters[option].default == beam.STEEL[option]


def test_steel_cantilever_is_the_seed_beam():
    """1 m, 1 cm square steel, 1 N at the tip: M, S and f of cantilever(...) with those."""
    shared = beam.steel_cantilever(6)
    seed = structural.cantilever(1.0, 6, 210e9, 7850.0, 0.01, 0.01, 1.0)
    assert (shared.M != seed.M).nnz == 0 and (shared.S != seed.S).nnz == 0
    assert np.array_equal(shared.f, seed.f)


def test_steel_cantilever_frequencies_are_the_clamped_free_roots():
    # 20 Hermite elements (FE error ∝ h⁴): measured 6e-8 for ω₁, 6.2e-5 for ω₄
    omega = beam.steel_cantilever(20).natural_frequencies(4)
    exact = beam.exact_frequencies(*(beam.STEEL[k] for k in ("length", "E", "rho", "width",
                                                             "height")))  # fmt: skip
    np.testing.assert_allclose(omega, exact, rtol=1e-4)
    assert abs(omega[0] / exact[0] - 1) < 1e-7


def test_analyse_steps_tables_every_mode_at_the_default_step():
    analysis = beam.analyse_steps(4)
    omega = beam.steel_cantilever(4).natural_frequencies(8)
    assert analysis.dt == pytest.approx(2 * np.pi / omega[0] / 20, rel=1e-14)
    np.testing.assert_allclose(analysis.table.omega, omega, rtol=1e-12)
    assert list(analysis.table.schemes) == list(structural.SCHEMES)


def test_analyse_steps_refuses_a_bad_step_before_any_picture():
    with pytest.raises(ValueError, match=r"dt=-1.0 is not allowed"):
        beam.analyse_steps(2, dt=-1.0)
