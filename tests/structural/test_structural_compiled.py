"""The compiled loop (banded Cholesky) against the NumPy reference loop (sparse LU)."""

import numpy as np
import pytest
from structural_frames import shuffled_cantilever, tilted_frame, wheel

from tumble import structural
from tumble.ode import Status
from tumble.structural.factorization import MAX_BANDWIDTH
from tumble.structural.increments import Increments

STEEL = {"E": 210e9, "rho": 7850.0, "width": 0.01, "height": 0.01}
STEPS = 300
ROUND_OFF = 1e-11
"""Largest difference allowed, relative to the largest |x| or |y| of the run: the two
loops differ only in the solver (banded Cholesky vs SuperLU), measured ≤ 1.3e-12 here."""

SCHEMES = [*structural.SCHEMES, structural.Newmark(beta=0.3025, gamma=0.6)]
SCHEME_IDS = [*structural.SCHEMES, "newmark-2beta!=gamma"]


def both(system, scheme, dt, **options):
    compiled = structural.integrate(system, scheme, dt, compiled=True, **options)
    reference = structural.integrate(system, scheme, dt, compiled=False, **options)
    assert (compiled.solver, reference.solver) == ("banded-cholesky", "sparse-lu")
    return compiled, reference


def assert_same_run(compiled, reference):
    assert compiled.status == reference.status and compiled.message == reference.message
    np.testing.assert_array_equal(compiled.t, reference.t)
    for name in ("x", "y"):
        a, b = getattr(compiled, name), getattr(reference, name)
        np.testing.assert_allclose(a, b, rtol=0, atol=ROUND_OFF * np.abs(b).max(), err_msg=name)


def time_steps(system):
    """A step where every scheme stays bounded, and T₁/50 for the stable ones."""
    small = 0.05 * structural.critical_dt(system, "semi-implicit").dt
    return small, 2 * np.pi / system.natural_frequencies(1)[0] / 50


@pytest.fixture(scope="module")
def cantilever():
    return structural.cantilever(1.0, 8, tip_load=1.0, **STEEL)


@pytest.fixture(scope="module")
def frame():
    return tilted_frame()


@pytest.mark.parametrize("scheme", SCHEMES, ids=SCHEME_IDS)
def test_compiled_loop_matches_the_reference_on_a_cantilever(cantilever, scheme):
    small, large = time_steps(cantilever)
    assert_same_run(*both(cantilever, scheme, small, n_steps=STEPS))
    if structural.critical_dt(cantilever, scheme).dt == np.inf:
        assert_same_run(*both(cantilever, scheme, large, n_steps=STEPS))


@pytest.mark.parametrize("scheme", SCHEMES, ids=SCHEME_IDS)
def test_compiled_loop_matches_the_reference_on_a_frame_with_axial_dofs(frame, scheme):
    small, large = time_steps(frame)
    assert_same_run(*both(frame, scheme, small, n_steps=STEPS))
    if structural.critical_dt(frame, scheme).dt == np.inf:
        assert_same_run(*both(frame, scheme, large, n_steps=STEPS))


def test_compiled_loop_matches_the_reference_with_damping_and_a_start(frame):
    damping = structural.RayleighDamping(mass_coefficient=3.0, stiffness_coefficient=1e-4)
    x0 = frame.static_displacement()
    y0 = np.random.default_rng(0).standard_normal(frame.n_dofs) * 1e-3
    _, large = time_steps(frame)
    for scheme in ("midpoint", "implicit", structural.Newmark(beta=0.3025, gamma=0.6)):
        runs = both(frame, scheme, large, n_steps=STEPS, damping=damping, x0=x0, y0=y0)
        assert_same_run(*runs)


def test_compiled_loop_permutes_a_shuffled_numbering_and_back():
    beam = shuffled_cantilever(12)
    dt = time_steps(beam)[1]
    compiled, reference = both(beam, "newmark", dt, n_steps=STEPS, record_every=7)
    assert_same_run(compiled, reference)
    assert compiled.x.shape == (STEPS // 7 + 2, beam.n_dofs)


def test_compiled_loop_stops_at_the_same_step_when_it_diverges(cantilever):
    _, large = time_steps(cantilever)
    compiled, reference = both(cantilever, "semi-implicit", large, n_steps=STEPS)
    assert compiled.status == Status.FAILED
    assert compiled.message == reference.message  # the same step number and time
    assert compiled.t[-1] == reference.t[-1]
    assert np.all(np.isfinite(compiled.x[-1]))  # both keep the last finite state


def test_compiled_loop_in_blocks_gives_the_same_numbers(cantilever, monkeypatch):
    _, large = time_steps(cantilever)
    whole = structural.integrate(cantilever, "midpoint", large, n_steps=100, record_every=9)
    monkeypatch.setattr(structural.schemes, "BLOCK_WORK", 7 * cantilever.n_dofs)  # 7 steps
    blocks = structural.integrate(cantilever, "midpoint", large, n_steps=100, record_every=9)
    np.testing.assert_array_equal(blocks.x, whole.x)
    np.testing.assert_array_equal(blocks.t, whole.t)


def test_integrate_picks_the_banded_path_for_a_beam_and_sparse_lu_for_a_wheel(cantilever):
    dt = time_steps(cantilever)[1]
    assert structural.integrate(cantilever, "midpoint", dt, n_steps=2).solver == (
        "banded-cholesky"
    )
    hub = wheel(12)
    assert structural.integrate(hub, "midpoint", 1e-4, n_steps=2).solver == "sparse-lu"


def test_compiled_true_refuses_a_band_wider_than_the_kernel_takes():
    with pytest.raises(
        ValueError,
        match=rf"compiled=True is not allowed: must be None or False .* > {MAX_BANDWIDTH}; "
        "this one has 27",
    ):
        structural.integrate(wheel(12), "midpoint", 1e-4, n_steps=2, compiled=True)


@pytest.mark.parametrize(
    "scheme, k_g, k_dy, k_sa, k_a",
    [
        ("explicit", 0, 0, 0, 0),
        ("semi-implicit", 0, 1, 0, 0),
        ("implicit", 1, 1, 0, 0),
        ("midpoint", 0.5, 0.5, 0, 0),
        ("newmark", 0.5, 0.5, 0, 0),  # average acceleration: no a-terms
    ],
)
def test_schemes_as_increment_constants(scheme, k_g, k_dy, k_sa, k_a):
    dt = 0.01
    expected = Increments(dt, k_g * dt, k_dy * dt, k_sa * dt**2, k_a * dt**2)
    assert structural.SCHEMES[scheme].increments(dt) == expected


def test_general_newmark_needs_the_mass_solve():
    k = structural.Newmark(beta=0.3025, gamma=0.6).increments(0.1)
    # (γ/2 − β) Δt² and (½ − β/γ) Δt²
    assert k.mass_solve
    assert k.k_sa == pytest.approx(-0.0025 * 0.01) and k.k_a == pytest.approx(-0.00416667e-2)


def test_integrate_steps_with_sparse_lu_when_the_banded_cholesky_breaks_down(
    cantilever, monkeypatch
):
    def breaks_down(A, order=None):
        raise np.linalg.LinAlgError("not positive definite")  # as at 10⁵ elements

    monkeypatch.setattr(structural.schemes, "banded_cholesky", breaks_down)
    dt = time_steps(cantilever)[1]
    run = structural.integrate(cantilever, "midpoint", dt, n_steps=5)
    assert run.success and run.solver == "sparse-lu"
    with pytest.raises(np.linalg.LinAlgError):
        structural.integrate(cantilever, "midpoint", dt, n_steps=5, compiled=True)
