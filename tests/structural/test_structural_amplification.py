"""The time-step analyser: amplification matrix, spectral radius, damping, period error."""

import numpy as np
import pytest
from roundoff import error_bound

from tumble import structural
from tumble.structural.amplification import amplification, mode_table

OMEGAS = np.array([0.01, 0.1, 0.5, 1.0, 3.0, 10.0, 100.0])


def newmark_closed_form(beta, gamma, omega):
    """Hughes (2000) §9.2: ``λ² − 2A₁λ + A₂ = 0`` with ``D = 1 + βΩ²``,
    ``A₁ = 1 − Ω²(γ + ½)/(2D)``, ``A₂ = 1 − Ω²(γ − ½)/D``; ``Ω̄ = atan(√(A₂ − A₁²)/A₁)``,
    ``ξ̄ = −ln A₂/(2Ω̄)``."""
    D = 1 + beta * omega**2
    A1 = 1 - omega**2 * (gamma + 0.5) / (2 * D)
    A2 = 1 - omega**2 * (gamma - 0.5) / D
    omega_bar = np.arctan2(np.sqrt(A2 - A1**2), A1)
    return -np.log(A2) / (2 * omega_bar), omega / omega_bar - 1


@pytest.mark.parametrize("beta, gamma", [(0.25, 0.5), (0.3025, 0.6), (0.3, 0.55)])
def test_newmark_damping_and_period_match_the_closed_form(beta, gamma):
    out = amplification(structural.Newmark(beta=beta, gamma=gamma), OMEGAS)
    damping, elongation = newmark_closed_form(beta, gamma, OMEGAS)
    # to 1e-10: measured ≤ 8e-13 absolute, at Ω = 0.01 where the closed form's own
    # √(A₂ − A₁²) cancels 4 digits (the values are 1e-5 there, 31 at Ω = 100)
    np.testing.assert_allclose(out.damping_ratio, damping, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(out.period_elongation, elongation, rtol=1e-10, atol=1e-10)


def test_average_acceleration_has_no_damping_and_the_arctangent_period():
    out = amplification("newmark", OMEGAS)
    # LAPACK's eigenvalues are exact for G + E, ‖E‖ ≤ c u ‖G‖ (backward stable; c = 20 for a
    # 2 × 2 Hessenberg QR, with the rounding of G itself), and the pair's |λ|² = det(G + E)
    # moves by at most ‖G‖ ‖E‖: |λ| = 1 to c u ‖G‖² / 2 (‖G‖ ≤ 4.2; measured 1.1e-16)
    norm = np.linalg.norm(out.matrix, 2, axis=(1, 2))
    np.testing.assert_array_less(np.abs(out.spectral_radius - 1.0), error_bound(norm**2 / 2, 20))
    # Ω̄ = 2 atan(Ω/2)
    np.testing.assert_allclose(out.period_elongation, OMEGAS / (2 * np.arctan(OMEGAS / 2)) - 1,
                               rtol=1e-10)  # fmt: skip


def hht_textbook(alpha, beta, gamma, omega):
    """Hilber–Hughes–Taylor (1977), eq. 9: ``L zⁿ⁺¹ = R zⁿ`` for ``z = (x, Δt v, Δt² a)``."""
    damping, elongation = [], []
    for w in omega:
        L = np.array([[(1 + alpha) * w * w, 0, 1], [1, 0, -beta], [0, 1, -gamma]])
        R = np.array([[alpha * w * w, 0, 0], [1, 1, 0.5 - beta], [0, 1, 1 - gamma]])
        roots = np.linalg.eigvals(np.linalg.solve(L, R))
        principal = roots[np.argmax(roots.imag)]
        omega_bar = np.angle(principal)
        damping.append(-np.log(abs(principal) ** 2) / (2 * omega_bar))
        elongation.append(w / omega_bar - 1)
    return np.array(damping), np.array(elongation)


@pytest.mark.parametrize("alpha", [-0.05, -0.1, -0.3])
def test_hht_damping_and_period_match_the_textbook_amplification(alpha):
    scheme = structural.HHT(alpha)
    _, _, beta, gamma = scheme.parameters
    out = amplification(scheme, OMEGAS)
    damping, elongation = hht_textbook(alpha, beta, gamma, OMEGAS)
    # measured ≤ 6e-14 absolute (values from 1e-8 to 3e1)
    np.testing.assert_allclose(out.damping_ratio, damping, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(out.period_elongation, elongation, rtol=1e-10, atol=1e-10)


@pytest.mark.parametrize("rho_inf", [0.0, 0.5, 0.8, 1.0])
def test_generalized_alpha_spectral_radius_tends_to_rho_inf(rho_inf):
    out = amplification(structural.GeneralizedAlpha(rho_inf), [1e10])
    G = out.matrix[0]
    # all three roots tend to −ρ∞ (Chung–Hulbert): their mean and the product of their
    # moduli are well conditioned, measured to 2e-16
    assert np.trace(G) / 3 == pytest.approx(-rho_inf, abs=1e-12)
    assert abs(np.linalg.det(G)) ** (1 / 3) == pytest.approx(rho_inf, abs=1e-12)
    # max |λ| of a near-Jordan block carries ε^⅓ ≈ 5e-6 of rounding: measured 3.3e-6 (0.8)
    assert out.spectral_radius[0] == pytest.approx(rho_inf, abs=1e-5)


@pytest.mark.parametrize("rho_inf", [0.0, 0.5, 0.8, 1.0])
def test_bathe_spectral_radius_tends_to_rho_inf(rho_inf):
    out = amplification(structural.Bathe(rho_inf), [1e10])
    assert out.spectral_radius[0] == pytest.approx(rho_inf, abs=1e-6)


@pytest.mark.parametrize("name", structural.SCHEMES)
def test_spectral_radius_crosses_one_at_the_critical_omega(name):
    out = amplification(name, np.logspace(-2, 4, 61))
    limit = out.critical_omega
    below = out.omega < limit * (1 - 1e-9)
    assert np.all(out.spectral_radius[below] <= 1 + 1e-12)
    assert np.all(out.spectral_radius[~below] > 1)


@pytest.mark.parametrize("name", structural.SCHEMES)
def test_second_order_schemes_lose_period_as_omega_squared(name):
    scheme = structural.SCHEMES[name]
    out = amplification(scheme, [1e-2, 2e-2])
    slope = np.log2(abs(out.period_elongation[1] / out.period_elongation[0]))
    if scheme.order == 2:
        assert abs(slope - 2) < 0.2, slope
    assert np.all(out.spectral_radius[:1] < 1 + 1e-4)


def test_physical_damping_is_reproduced_at_small_omega():
    out = amplification("midpoint", [1e-3], xi=0.05)
    # the exact λ = exp(−ξΩ ± iΩ√(1 − ξ²)) reads ξ̄ = ξ/√(1 − ξ²) by this definition
    assert out.damping_ratio[0] == pytest.approx(0.05 / np.sqrt(1 - 0.05**2), rel=1e-6)


def test_mode_table_gives_each_mode_its_omega_and_damping():
    beam = structural.cantilever(1.0, 10, 210e9, 7850.0, 0.01, 0.01)
    dt = 2 * np.pi / beam.natural_frequencies(1)[0] / 100
    table = mode_table(beam, dt)
    assert table.schemes == tuple(structural.SCHEMES)
    newmark = table.schemes.index("newmark")
    alpha = table.schemes.index("generalized-alpha")
    np.testing.assert_allclose(table.damping_ratio[newmark], 0.0, atol=1e-12)
    direct = amplification(structural.SCHEMES["generalized-alpha"], table.omega * dt)
    # the same function of the same numbers, on the same machine: the same bits
    np.testing.assert_array_equal(table.spectral_radius[alpha], direct.spectral_radius)
    # ρ∞ = 0.8: mode 1 (Ω = 0.063) kept, the top mode (Ω = 108) at 0.833 on its way to 0.8
    assert table.spectral_radius[alpha, 0] > 0.99999
    assert 0.8 < table.spectral_radius[alpha, -1] < 0.84


@pytest.mark.parametrize(
    "options, match",
    [({"omega": [0.0]}, r"omega\[0\]=0.0 is not allowed"), ({"omega": [1.0], "xi": 1.0}, "xi=1.0"),
     ({"omega": [1.0], "scheme": "rk4"}, "scheme='rk4'")],
)  # fmt: skip
def test_amplification_rejects_bad_input(options, match):
    with pytest.raises(ValueError, match=match):
        amplification(options.pop("scheme", "newmark"), **options)
