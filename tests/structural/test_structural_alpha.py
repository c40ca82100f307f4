"""Generalized-α, HHT and ρ∞-Bathe; every scheme's order against the exact response."""

import numpy as np
import pytest
from roundoff import walk_bound
from test_structural_compiled import assert_same_run, both

from tumble import structural
from tumble.structural.factorization import band_structure

STEEL = {"E": 210e9, "rho": 7850.0, "width": 0.01, "height": 0.01}


@pytest.fixture(scope="module")
def beam():
    return structural.cantilever(1.0, 20, tip_load=1.0, **STEEL)


@pytest.fixture(scope="module")
def dt(beam):
    return 2 * np.pi / beam.natural_frequencies(1)[0] / 100  # T₁/100


def same_map_bound(beam, dt, steps: int) -> tuple[float, float]:
    """How far two roundings of one energy-conserving map may drift apart in x and in y,
    relative to the largest |x| and |y|: a step's longest chain of roundings is the banded
    substitution's, 2 n (b + 1), and the steps' roundings random-walk (tests/roundoff.py)
    under a map that keeps the energy norm; in y the highest mode amplifies them by ω_max Δt.
    """
    b = band_structure(beam.M + dt**2 * beam.S).bandwidth
    x = float(walk_bound(steps, 2 * beam.n_dofs * (b + 1), 1.0))
    return x, x * structural.critical_dt(beam, "semi-implicit").omega * dt


@pytest.mark.parametrize("name", structural.SCHEMES)
def test_every_scheme_has_its_declared_order_against_the_exact_response(name):
    scheme = structural.SCHEMES[name]
    beam = structural.cantilever(1.0, 1, tip_load=1.0, **STEEL)  # ω₂/ω₁ ≈ 10: explicit survives
    t_end = 0.3 * 2 * np.pi / beam.natural_frequencies(1)[0]
    exact = structural.exact_response(beam, [t_end]).x[0]
    # first-order schemes reach their asymptotic regime only once ω₂Δt ≪ 1 (implicit's
    # damping of mode 2 is exp(−ω₂²Δt t/2)): they start finer. The second-order ones start
    # at ω₂Δt = 0.16: from 60 steps (0.31) Wilson-θ's large third-order term still showed
    # (local slopes 2.40, 2.23, 2.11; the others' 2.10 at most)
    steps = (120 if scheme.order == 2 else 2000) * 2 ** np.arange(4)
    errors = []
    for n in steps:
        run = structural.integrate(beam, scheme, t_end / n, n_steps=int(n), record_every=int(n))
        errors.append(np.abs(run.x[-1] - exact).max() / np.abs(exact).max())
    slope = np.polyfit(np.log(t_end / steps), np.log(errors), 1)[0]
    # measured: 1.02, 1.00, 0.98 (first order); 2.03, 2.03, 2.04, 2.03, 2.03, 2.13 (second:
    # midpoint, newmark, hht, generalized-alpha, bathe, wilson)
    assert abs(slope - scheme.order) < 0.2, f"slope {slope:.3f}"
    assert errors[-1] < (1e-3 if scheme.order == 1 else 1e-4)  # measured ≤ 8.5e-4, 2.9e-5


@pytest.mark.parametrize(
    "damping", [None, structural.RayleighDamping(2.0, 1e-5)], ids=["undamped", "rayleigh"]
)
def test_generalized_alpha_with_rho_inf_one_is_the_midpoint_trajectory(beam, dt, damping):
    alpha = structural.integrate(beam, structural.GeneralizedAlpha(1.0), dt, n_steps=500,
                                 damping=damping)  # fmt: skip
    midpoint = structural.integrate(beam, "midpoint", dt, n_steps=500, damping=damping)
    # α_m = α_f = ½, γ = ½, β = ¼: the same map, rounded differently (the carried
    # acceleration): x measured 3.5e-15 … 8.7e-15 of its largest value, y 7.5e-13 … 4.4e-12
    # (with and without FMA; the velocities of the highest modes, ω_max Δt = 680, amplify the
    # rounding), against same_map_bound's 6.5e-13 and 2.8e-10
    for name, tolerance in zip("xy", same_map_bound(beam, dt, 500), strict=True):
        a, b = getattr(alpha, name), getattr(midpoint, name)
        np.testing.assert_allclose(a, b, rtol=0, atol=tolerance * np.abs(b).max(), err_msg=name)


def test_hht_with_alpha_zero_is_newmark(beam, dt):
    hht = structural.integrate(beam, structural.HHT(0.0), dt, n_steps=300)
    newmark = structural.integrate(beam, "newmark", dt, n_steps=300)
    # the same map rounded differently: measured 4.2e-15 … 6.6e-15 of the largest |x|
    tolerance, _ = same_map_bound(beam, dt, 300)
    np.testing.assert_allclose(hht.x, newmark.x, rtol=0, atol=tolerance * np.abs(newmark.x).max())


def test_bathe_with_rho_inf_one_is_two_trapezoidal_half_steps(beam, dt):
    bathe = structural.integrate(beam, structural.Bathe(1.0), dt, n_steps=200)
    halves = structural.integrate(beam, "midpoint", dt / 2, n_steps=400)
    # γ₀ = ½, q = (¼, ½, ¼): the second sub-step is the trapezoidal rule too
    np.testing.assert_allclose(bathe.x, halves.x[::2], rtol=0, atol=1e-12 * np.abs(halves.x).max())


@pytest.mark.parametrize("rho_inf", [0.0, 0.5, 0.8, 1.0])
def test_bathe_default_splitting_shares_one_matrix(rho_inf):
    scheme = structural.Bathe(rho_inf)
    q0, q1, q2 = scheme.weights
    # a few roundings of numbers ≤ 2 in Python floats (and √2 correctly rounded): ≤ 4.4e-16,
    # the same bits on any machine (measured ≤ 1.1e-16)
    assert q0 + q1 + q2 == pytest.approx(1.0, abs=1e-15)  # consistency
    assert q2 == pytest.approx(scheme.splitting / 2, abs=1e-15)  # γ₀: one factorisation
    assert structural.Bathe(0.0).splitting == pytest.approx(2 - np.sqrt(2), abs=1e-15)


def test_generalized_alpha_parameters_follow_chung_hulbert():
    alpha_m, alpha_f, beta, gamma = structural.GeneralizedAlpha(0.5).parameters
    # ρ∞ = ½: α_m = 0, α_f = ⅓, γ = ½ + ⅓, β = ¼ (4/3)²
    assert (alpha_m, alpha_f) == (0.0, pytest.approx(1 / 3))
    assert gamma == pytest.approx(5 / 6) and beta == pytest.approx(4 / 9)
    assert structural.HHT(-0.1).parameters == pytest.approx((0.0, 0.1, 0.3025, 0.6))


def upper_half_energy(beam, run):
    energies = structural.modal_energies(beam, run.x, run.y)
    return energies[:, beam.n_dofs // 2 :].sum(axis=1)


def test_high_modes_are_damped_by_generalized_alpha_but_not_by_newmark(beam, dt):
    runs = {name: structural.integrate(beam, scheme, dt, n_steps=400, record_every=10)
            for name, scheme in (("newmark", "newmark"),
                                 ("alpha", structural.GeneralizedAlpha(0.5)))}  # fmt: skip
    newmark, alpha = (upper_half_energy(beam, runs[k]) for k in ("newmark", "alpha"))
    # the step load puts 4.0e-9 J into modes 21–40 (Ω = ωΔt from 10 to 430 here)
    assert abs(newmark[-1] / newmark[0] - 1) < 1e-8  # kept: measured 1.7e-10
    assert alpha[-1] < 1e-12 * alpha[0]  # ρ ≈ ½ per step for 400 steps: measured 2e-19
    lowest = structural.modal_energies(beam, runs["alpha"].x, runs["alpha"].y)[:, 0]
    assert lowest[-1] / lowest[0] > 0.98  # while mode 1 (Ω = 0.063) keeps 99 %


DAMPED_SCHEMES = [structural.HHT(-0.2), structural.GeneralizedAlpha(0.3),
                  structural.Bathe(0.4, gamma=0.35)]  # fmt: skip


@pytest.mark.parametrize("scheme", DAMPED_SCHEMES, ids=lambda s: s.name)
def test_compiled_family_loops_match_their_reference_with_damping_and_a_start(beam, scheme, dt):
    damping = structural.RayleighDamping(mass_coefficient=3.0, stiffness_coefficient=1e-5)
    x0 = beam.static_displacement() * 0.5
    y0 = np.random.default_rng(0).standard_normal(beam.n_dofs) * 1e-3
    assert_same_run(*both(beam, scheme, dt, n_steps=300, damping=damping, x0=x0, y0=y0))


@pytest.mark.parametrize(
    "make, match",
    [
        (lambda: structural.GeneralizedAlpha(1.2), r"rho_inf=1.2 is not allowed: must be in"),
        (lambda: structural.GeneralizedAlpha(-0.1), r"rho_inf=-0.1 is not allowed"),
        (lambda: structural.GeneralizedAlpha(np.nan), r"rho_inf=nan is not allowed"),
        (lambda: structural.HHT(-0.5), r"alpha=-0.5 is not allowed: must be in \[-1/3, 0\]"),
        (lambda: structural.HHT(0.1), r"alpha=0.1 is not allowed"),
        (lambda: structural.HHT(-0.1, gamma=0.4), r"gamma=0.4 is not allowed: must be >= 1/2"),
        (lambda: structural.HHT(-0.1, beta=0.2), r"beta=0.2 is not allowed: must be >= \(gamma"),
        (lambda: structural.Bathe(1.5), r"rho_inf=1.5 is not allowed: must be in \[0, 1\]"),
        (lambda: structural.Bathe(0.5, gamma=1.0), r"gamma=1.0 is not allowed: must be in \(0, 1"),
    ],
)  # fmt: skip
def test_parameters_that_break_unconditional_stability_are_refused(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_newmark_outside_the_stable_range_is_allowed_and_reports_its_critical_step(beam):
    scheme = structural.Newmark(beta=0.0, gamma=0.5)  # central difference
    step = structural.critical_dt(beam, scheme)
    assert step.dt == pytest.approx(2 / step.omega, rel=1e-14)  # one division: ≤ 1.1e-16
