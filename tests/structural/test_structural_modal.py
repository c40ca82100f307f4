"""The exact modal response, and the eigen-solve it rests on (issue 16 item 1, issue 18 item 6)."""

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp

from tumble import structural
from tumble.structural.modal import impulse_response

STEEL = {"E": 210e9, "rho": 7850.0, "width": 0.01, "height": 0.01}
EI = 210e9 * 0.01**4 / 12
BETA_L = 1.87510406871196  # first root of cos βL cosh βL = −1
OMEGA_1 = BETA_L**2 * np.sqrt(EI / (7850.0 * 1e-4))  # exact ω₁ of the 1 m cantilever [rad/s]


@pytest.fixture(scope="module")
def beam():
    return structural.cantilever(1.0, 10, tip_load=1.0, **STEEL)


def first_order(system, damping):
    """``ż = A z + g`` for ``z = (x, y)``, dense."""
    n = system.n_dofs
    inverse_mass = np.linalg.inv(system.M.toarray())
    C = np.zeros((n, n)) if damping is None else damping.matrix(system).toarray()
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-inverse_mass @ system.S, -inverse_mass @ C]])
    return A, np.concatenate([np.zeros(n), inverse_mass @ system.f])


@pytest.mark.parametrize(
    "damping", [None, structural.RayleighDamping(3.0, 1e-6)], ids=["undamped", "rayleigh"]
)
def test_exact_response_matches_dop853_on_a_ten_element_cantilever(beam, damping):
    A, g = first_order(beam, damping)
    t = np.linspace(0.0, np.pi / OMEGA_1, 11)  # half a period of mode 1, every mode excited
    n = beam.n_dofs
    reference = solve_ivp(lambda _, z: A @ z + g, (0, t[-1]), np.zeros(2 * n), method="DOP853",
                          rtol=1e-12, atol=1e-20, t_eval=t)  # fmt: skip
    exact = structural.exact_response(beam, t, damping=damping)
    # measured 1.2e-12 and 2.8e-12 in x; in y 1.5e-9 and 1.8e-10, DOP853's own error in the
    # velocities of the highest modes (ω_max/ω₁ = 1700)
    x_error = np.abs(reference.y[:n].T - exact.x).max() / np.abs(exact.x).max()
    y_error = np.abs(reference.y[n:].T - exact.y).max() / np.abs(exact.y).max()
    assert x_error < 1e-10 and y_error < 1e-8, (x_error, y_error)


def test_exact_response_matches_the_matrix_exponential_from_a_general_start(beam):
    rng = np.random.default_rng(1)
    x0, y0 = rng.standard_normal((2, beam.n_dofs)) * 1e-3
    damping = structural.RayleighDamping(2.0, 5e-5)  # ζ from 0.02 (mode 1) to 2.3: the top
    assert damping.stiffness_coefficient * beam.natural_frequencies(20)[-1] / 2 > 1  # overdamped
    A, g = first_order(beam, damping)
    z0 = np.concatenate([x0, y0])
    static = np.concatenate([beam.static_displacement(), np.zeros(beam.n_dofs)])
    t = 0.0123
    z = static + scipy.linalg.expm(A * t) @ (z0 - static)
    exact = structural.exact_response(beam, [t], x0=x0, y0=y0, damping=damping)
    # expm is accurate to about ε ‖A t‖ ≈ 1e-10 relative here; measured 6.6e-14 in x and
    # 6.3e-12 in y (of the largest velocity)
    n = beam.n_dofs
    np.testing.assert_allclose(exact.x[0], z[:n], rtol=0, atol=1e-9 * np.abs(z).max())
    np.testing.assert_allclose(exact.y[0], z[n:], rtol=0, atol=1e-9 * np.abs(z[n:]).max())


def test_static_limit_is_the_tip_deflection_formula(beam):
    late = structural.exact_response(beam, [50.0], damping=structural.RayleighDamping(5.0))
    # all modes have decayed by e^{−125}; the Hermite element is exact for a tip load
    assert late.tip_displacement[0] == pytest.approx(1.0 / (3 * EI), rel=1e-12)  # 1.1e-14
    assert np.abs(late.y).max() < 1e-40


def test_exact_undamped_energy_is_constant(beam):
    run = structural.exact_response(beam, np.linspace(0, 1.0, 200))
    scale = structural.energy_scale(beam)
    assert np.abs(run.energy).max() < 1e-12 * scale  # E(0) = 0 from rest; measured 6e-14


def test_exact_response_starts_at_the_initial_state(beam):
    x0 = np.linspace(0, 1e-3, beam.n_dofs)
    y0 = np.linspace(1e-2, 0, beam.n_dofs)
    run = structural.exact_response(beam, [0.0], x0=x0, y0=y0)
    np.testing.assert_allclose(run.x[0], x0, rtol=0, atol=1e-15)
    np.testing.assert_allclose(run.y[0], y0, rtol=0, atol=1e-14)


@pytest.mark.parametrize("zeta", [0.0, 0.3, 1 - 1e-9, 1.0, 1 + 1e-9, 4.0])
def test_impulse_response_solves_the_damped_oscillator(zeta):
    omega, t = 7.0, np.linspace(0, 2, 9)
    h, dh = impulse_response(np.array(omega), np.array(zeta), t)
    # the same from the 2 × 2 matrix exponential of (h, ḣ)' = [[0, 1], [−ω², −2ζω]] (h, ḣ)
    system = np.array([[0.0, 1.0], [-(omega**2), -2 * zeta * omega]])
    expected = np.array([scipy.linalg.expm(system * s) @ [0.0, 1.0] for s in t])
    np.testing.assert_allclose(h, expected[:, 0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(dh, expected[:, 1], rtol=0, atol=1e-11)


@pytest.mark.parametrize("n_elements", [160, 640, 1280, 5000])
def test_lowest_frequency_keeps_full_relative_accuracy_on_fine_meshes(n_elements):
    if n_elements > 3700:  # the builder warns for static and stepped results from here
        with pytest.warns(structural.IllConditionedWarning):
            beam = structural.cantilever(1.0, n_elements, **STEEL)
    else:
        beam = structural.cantilever(1.0, n_elements, **STEEL)
    # the assembled S lost ε κ(S): 3.1e-9, 7.6e-6, 7.0e-6, 6.4e-8 before (issue 18, item 6);
    # the element factor S = GᵀG: 1.1e-11 (the discretisation error, 1.3e-11), 1.5e-13,
    # 3e-14, 8.6e-12
    error = abs(beam.natural_frequencies(1)[0] / OMEGA_1 - 1)
    assert error < 3e-11, error


def test_modes_are_mass_orthonormal_on_both_paths():
    for n_elements in (50, 400):  # dense SVD, then ARPACK with a Ritz step
        beam = structural.cantilever(1.0, n_elements, **STEEL)
        _, shapes = beam.modes(4)
        np.testing.assert_allclose(shapes.T @ (beam.M @ shapes), np.eye(4), atol=1e-12)


def test_strain_factor_reproduces_the_stiffness(beam):
    G = beam.strain_factor
    np.testing.assert_allclose((G.T @ G).toarray(), beam.S.toarray(), rtol=0,
                               atol=1e-13 * abs(beam.S).max())  # fmt: skip


@pytest.mark.parametrize(
    "options, match",
    [({"t": [-1.0]}, r"t=.* is not allowed"), ({"t": [np.nan]}, r"t\[0\]=nan"),
     ({"t": [0.0], "x0": np.zeros(3)}, r"x0=.* must be of shape \(20,\)")],
)  # fmt: skip
def test_exact_response_rejects_bad_input(beam, options, match):
    with pytest.raises(ValueError, match=match):
        structural.exact_response(beam, **options)
