"""Wilson-θ (tumble.structural.wilson) against closed forms derived here, by another route.

The scheme steps in the acceleration form ``A a_θ = q − g − C(y + T/2 a)``. The references
below are Bathe's displacement form of the same assumption (the acceleration linear over
``T = θΔt``, equilibrium at ``t + T``): solve ``K̃ x_θ = R̃`` with
``K̃ = K + 3/T C + 6/T² M``, ``R̃ = f + M(6/T² x + 6/T y + 2a) + C(3/T x + 2y + T/2 a)``, then

    a⁺ = 6/(θ³Δt²)(x_θ − x) − 6/(θ²Δt) y + (1 − 3/θ) a,
    y⁺ = y + Δt/2 (a⁺ + a),   x⁺ = x + Δt y + Δt²/6 (a⁺ + 2a),

evaluated in 40-digit arithmetic (mpmath) on one mode, ``K = Ω²``, ``C = 2ξΩ``, ``M = 1``,
``Δt = 1``.
"""

import math

import mpmath as mp
import numpy as np
import pytest
from test_structural_alpha import same_map_bound
from test_structural_compiled import assert_same_run, both

from tumble import structural
from tumble.structural.wilson import UNCONDITIONAL_THETA, WilsonTheta

STEEL = {"E": 210e9, "rho": 7850.0, "width": 0.01, "height": 0.01}
LINEAR_ACCELERATION = structural.Newmark(beta=1 / 6, gamma=0.5)
mp.mp.dps = 40


def displacement_form_step(theta, omega, xi, x, y, a):
    """One step of Bathe's displacement form (module docstring) on one mode, Δt = 1."""
    T = theta
    K, C = omega * omega, 2 * xi * omega
    stiffness = K + 3 / T * C + 6 / T**2
    load = (6 / T**2 * x + 6 / T * y + 2 * a) + C * (3 / T * x + 2 * y + T / 2 * a)
    x_theta = load / stiffness
    a_new = 6 / theta**3 * (x_theta - x) - 6 / theta**2 * y + (1 - 3 / theta) * a
    return x + y + (a_new + 2 * a) / 6, y + (a_new + a) / 2, a_new


def closed_form(theta, omega, xi=0.0):
    """G on (x, Δt y, Δt² a), column by column, in mpmath."""
    theta, omega, xi = mp.mpf(theta), mp.mpf(omega), mp.mpf(xi)
    columns = [displacement_form_step(theta, omega, xi, *unit) for unit in np.eye(3).tolist()]
    return mp.matrix(columns).T


def as_array(matrix):
    return np.array(matrix.tolist(), dtype=float)


OMEGAS = [1e-3, 0.1, 1.0, 3.0, 10.0, 1e3, 1e6]


@pytest.mark.parametrize("theta", [1.0, 1.2, 1.4, 2.0])
@pytest.mark.parametrize("xi", [0.0, 0.05, 0.7])
def test_amplification_matrix_matches_the_displacement_form(theta, xi):
    G = structural.amplification(WilsonTheta(theta), OMEGAS, xi).matrix
    for omega, computed in zip(OMEGAS, G, strict=True):
        reference = as_array(closed_form(theta, omega, xi))
        # a step is some 20 roundings of numbers no larger than the largest entry (Ω² and
        # the 1/(1 + Ω²T²/6) it is divided by cancel in the code's form, not in this one):
        # 20 u max|G| ≈ 2.2e-15 max|G|; measured ≤ 2.2e-16
        scale = np.abs(reference).max()
        np.testing.assert_allclose(computed, reference, rtol=0, atol=2.2e-15 * scale,
                                   err_msg=f"Ω = {omega}")  # fmt: skip


@pytest.mark.parametrize("theta", [UNCONDITIONAL_THETA, 1.37, 1.4, 2.0, 10.0])
@pytest.mark.parametrize("xi", [0.0, 0.1])
def test_spectral_radius_is_at_most_one_at_every_omega_from_the_threshold_on(theta, xi):
    omega = np.logspace(-3, 8, 111)
    radius = structural.amplification(WilsonTheta(theta), omega, xi).spectral_radius
    # |λ| of a 3 × 3 matrix from LAPACK: backward stable, a few ulps of ‖G‖ ≤ 2 (1e-15);
    # at the threshold itself the real eigenvalue at −1 is exactly 1 in exact arithmetic
    assert np.all(radius <= 1 + 1e-12), radius.max()
    assert WilsonTheta(theta).critical_omega() == math.inf


def limit_matrix(theta):
    """The docstring's G∞ (Ω → ∞) with u = 1/θ, in mpmath."""
    u = 1 / mp.mpf(theta)
    return mp.matrix([[1 - u**3, 1 - u**2, (1 - u) / 2],
                      [-3 * u**3, 1 - 3 * u**2, 1 - 3 * u / 2],
                      [-6 * u**3, -6 * u**2, 1 - 3 * u]])  # fmt: skip


@pytest.mark.parametrize("theta", [1.0, 1.2, 1.3, UNCONDITIONAL_THETA, 1.4, 2.0])
def test_the_high_frequency_limit_and_its_threshold(theta):
    G_inf = limit_matrix(theta)
    np.testing.assert_allclose(as_array(closed_form(theta, 1e12)), as_array(G_inf), atol=1e-20)
    u = 1 / mp.mpf(theta)
    determinant = float(mp.det(G_inf + mp.eye(3)))
    assert determinant == pytest.approx(float(2 * (u - 2) * (u * u + 2 * u - 2)), abs=1e-30)
    radius = max(abs(v) for v in mp.eig(G_inf)[0])
    computed = structural.amplification(WilsonTheta(theta), [1e12]).spectral_radius[0]
    # at Ω = 1e12 the computed G is G∞ to 1e-24 plus its rounding (1e-15 of ‖G‖)
    assert computed == pytest.approx(float(radius), abs=1e-12)
    if theta < UNCONDITIONAL_THETA:
        assert radius > 1  # unstable at large Ω: a real eigenvalue beyond −1
    if theta == UNCONDITIONAL_THETA:
        assert float(radius) == pytest.approx(1, abs=1e-15)


@pytest.mark.parametrize("theta", [1.0, 1.1, 1.2, 1.3, 1.36])
def test_critical_omega_is_where_an_eigenvalue_passes_minus_one(theta):
    # Below the threshold the step is stable up to Ω_c, where det(G(Ω) + I) = 0 in the
    # displacement form (a real eigenvalue at −1); found here by the secant method from the
    # scheme's own answer
    computed = WilsonTheta(theta).critical_omega()

    def at_minus_one(omega):
        return mp.det(closed_form(theta, omega) + mp.eye(3))

    reference = mp.findroot(at_minus_one, (computed * 0.99, computed * 1.01))
    # the scheme bisects ρ(Ω) − 1 > 1e-12: ρ − 1 grows like c (Ω − Ω_c) (like √ at θ = 1,
    # a double root), so Ω_c is found to 1e-12/(c Ω_c); measured 6.7e-16 (θ = 1) to 1.4e-11
    # (θ = 1.36, where ρ − 1 grows slowest)
    assert computed == pytest.approx(float(reference), rel=1e-9)
    if theta == 1.0:
        assert computed == pytest.approx(math.sqrt(12), rel=1e-12)  # Newmark's 1/√(γ/2 − β)


def test_theta_one_has_the_critical_step_of_linear_acceleration():
    beam = structural.cantilever(1.0, 20, **STEEL)
    wilson = structural.critical_dt(beam, WilsonTheta(1.0))
    newmark = structural.critical_dt(beam, LINEAR_ACCELERATION)
    assert wilson.dt == pytest.approx(newmark.dt, rel=1e-12) and wilson.mode == newmark.mode


@pytest.mark.parametrize("omega", [0.01, 0.5, 2.0, 3.4])
def test_theta_one_has_the_eigenvalues_of_linear_acceleration(omega):
    G = structural.amplification(WilsonTheta(1.0), [omega]).matrix[0]
    wilson = np.linalg.eigvals(G)
    newmark = np.linalg.eigvals(structural.amplification(LINEAR_ACCELERATION, [omega]).matrix[0])
    wilson = wilson[np.argsort(np.abs(wilson))]
    # the third state, a, is slaved to (x, y) when θ = 1: its eigenvalue is 0 (det G∞ = 0);
    # measured ≤ 5e-16
    assert abs(wilson[0]) < 1e-14
    # both pairs on the unit circle below √12, from backward-stable eigensolves: a rounding
    # of G (a few ε‖G‖) moves a pair by up to that over its separation; measured 8.7e-15 at
    # Ω = 0.01 (separation 0.02), ≤ 1.4e-15 at the others
    separation = abs(newmark[0] - newmark[1])
    tolerance = 8 * np.finfo(float).eps * np.linalg.norm(G) / separation
    np.testing.assert_allclose(np.sort_complex(wilson[1:]), np.sort_complex(newmark),
                               rtol=0, atol=tolerance)  # fmt: skip


def test_theta_one_is_the_linear_acceleration_trajectory():
    beam = structural.cantilever(1.0, 20, tip_load=1.0, **STEEL)
    dt = 0.5 * structural.critical_dt(beam, LINEAR_ACCELERATION).dt
    wilson = structural.integrate(beam, WilsonTheta(1.0), dt, n_steps=500)
    newmark = structural.integrate(beam, LINEAR_ACCELERATION, dt, n_steps=500)
    # the same map, rounded differently (Newmark solves with M for a each step, Wilson
    # carries it): to the random walk of same_map_bound (6.5e-13, 1.1e-12); measured 9.2e-16
    # in x, 3.5e-14 in y
    for name, tolerance in zip("xy", same_map_bound(beam, dt, 500), strict=True):
        a, b = getattr(wilson, name), getattr(newmark, name)
        np.testing.assert_allclose(a, b, rtol=0, atol=tolerance * np.abs(b).max(), err_msg=name)


@pytest.mark.parametrize("theta", [1.0, 1.4, 2.0])
def test_wilson_is_second_order_on_an_undamped_oscillator(theta):
    # ẍ = −x from x = 1 at rest, to T = 1, by the scheme's own step (its amplification
    # matrix, built by the NumPy step) on (x, Δt y, Δt² a), a₀ = −x₀
    steps = 20 * 2 ** np.arange(5)
    errors = []
    for n in steps:
        G = structural.amplification(WilsonTheta(theta), [1.0 / n]).matrix[0]
        z = np.linalg.matrix_power(G, int(n)) @ np.array([1.0, 0.0, -1.0 / n**2])
        errors.append(abs(z[0] - math.cos(1.0)))
    slope = np.polyfit(np.log(1.0 / steps), np.log(errors), 1)[0]
    # the errors are 1e-3 … 3e-7, far above the round-off of 320 steps (1e-14); measured
    # slopes 2.00, 1.98, 1.96
    assert abs(slope - 2) < 0.2, f"slope {slope:.3f}"


@pytest.mark.parametrize("theta", [1.0, 1.4, 2.0])
def test_compiled_wilson_matches_its_reference_with_damping_and_a_start(theta):
    beam = structural.cantilever(1.0, 20, tip_load=1.0, **STEEL)
    damping = structural.RayleighDamping(mass_coefficient=3.0, stiffness_coefficient=1e-5)
    x0 = beam.static_displacement() * 0.5
    y0 = np.random.default_rng(0).standard_normal(beam.n_dofs) * 1e-3
    scheme = WilsonTheta(theta)
    dt = min(2 * np.pi / beam.natural_frequencies(1)[0] / 100,
             0.5 * structural.critical_dt(beam, scheme).dt)  # fmt: skip
    assert_same_run(*both(beam, scheme, dt, n_steps=300, damping=damping, x0=x0, y0=y0))


def test_wilson_is_in_the_registry_with_its_label_and_default():
    scheme = structural.SCHEMES["wilson"]
    assert scheme == WilsonTheta(1.4) and scheme.label == "Wilson θ=1.4"
    assert scheme.order == 2 and scheme.carries_acceleration
    beam = structural.cantilever(1.0, 4, **STEEL)
    assert structural.critical_dt(beam, "wilson").dt == math.inf


@pytest.mark.parametrize(
    "theta, match",
    [(0.9, r"theta=0.9 is not allowed: must be >= 1 \(1 is Newmark's linear acceleration\)"),
     (np.nan, r"theta=nan is not allowed: must be a finite number"),
     ("1.4", r"theta='1.4' is not allowed")],
)  # fmt: skip
def test_theta_below_one_is_refused(theta, match):
    with pytest.raises(ValueError, match=match):
        WilsonTheta(theta)
