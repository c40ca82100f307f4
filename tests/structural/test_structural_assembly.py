"""Assembled systems: cantilever frequencies and deflection, frames, warnings, bad input."""

import numpy as np
import pytest

from tumble import structural

BETA_L = np.array([1.87510406871196, 4.69409113297418, 7.85475743823761, 10.9955407348755])
STEEL = {"E": 210e9, "rho": 7850.0}


def exact_frequencies(length, E, rho, width, height):
    """Clamped–free Euler–Bernoulli beam: ω_k = (β_k L)² sqrt(EI/(ρ A L⁴))."""
    EI, rho_A = E * width * height**3 / 12, rho * width * height
    return BETA_L**2 * np.sqrt(EI / (rho_A * length**4))


def test_seed_cantilever_frequencies_match_exact_roots():
    beam = structural.cantilever(1.0, 20, width=0.01, height=0.01, **STEEL)
    omega = beam.natural_frequencies(4)
    # the SPEC §4 figures (6 digits): 1e-5 for ω₁ rising to 1e-3 for ω₄ (FE error ∝ k⁴)
    figures = np.array([52.4971, 328.993, 921.191, 1805.17])
    assert np.all(np.abs(omega / figures - 1) < [1e-5, 1e-4, 1e-4, 1e-3])
    error = omega / exact_frequencies(1.0, width=0.01, height=0.01, **STEEL) - 1
    # SPEC: 1e-5 for ω₁ and 1e-3 for ω₄ at 20 elements (measured 5.4e-8 and 6.2e-5)
    assert abs(error[0]) < 1e-5
    assert abs(error[3]) < 1e-3


@pytest.mark.parametrize(
    "length, n_elements, E, rho, width, height",
    [
        (0.5, 20, 70e9, 2700.0, 0.02, 0.005),  # aluminium strip, bending about its thin side
        (2.0, 24, 210e9, 7850.0, 0.03, 0.01),  # wide steel bar
        (3.0, 30, 11e9, 500.0, 0.05, 0.15),  # timber joist, bending about its deep side
    ],
)
def test_other_cantilevers_match_exact_roots(length, n_elements, E, rho, width, height):
    beam = structural.cantilever(length, n_elements, E, rho, width, height)
    error = beam.natural_frequencies(4) / exact_frequencies(length, E, rho, width, height) - 1
    # relative FE error depends only on N (h⁴): ≤ 6e-5 for the 4th mode at N ≥ 20
    assert abs(error[0]) < 1e-5
    assert np.all(np.abs(error) < 1e-3)
    assert np.all(error[1:] > 0)  # consistent mass: the Rayleigh–Ritz upper bound


def test_frequency_error_falls_as_the_fourth_power_of_element_size():
    counts = np.array([8, 16, 32])
    exact = exact_frequencies(1.0, width=0.01, height=0.01, **STEEL)[1]
    errors = [
        structural.cantilever(1.0, n, width=0.01, height=0.01, **STEEL).natural_frequencies(2)[1]
        / exact
        - 1
        for n in counts
    ]
    slope = np.polyfit(np.log(1.0 / counts), np.log(errors), 1)[0]
    assert abs(slope - 4) < 0.2, f"slope {slope:.3f}"  # Hermite cubics, consistent mass: h⁴
    assert errors[-1] < 5e-7


def test_static_tip_deflection_is_exact_at_the_nodes():
    load, length = 3.0, 1.2
    beam = structural.cantilever(length, 12, width=0.01, height=0.02, tip_load=load, **STEEL)
    EI = STEEL["E"] * 0.01 * 0.02**3 / 12
    x = beam.static_displacement()
    # Hermite cubics reproduce the cubic static solution exactly; κ(S) ε ~ 1e-12 round-off
    np.testing.assert_allclose(x[beam.tip_dof], load * length**3 / (3 * EI), rtol=1e-10)
    np.testing.assert_allclose(x[beam.tip_dof + 1], load * length**2 / (2 * EI), rtol=1e-10)


def test_cantilever_leaves_out_axial_dofs_unless_asked():
    kwargs = {"width": 0.01, "height": 0.01, **STEEL}
    assert structural.cantilever(1.0, 5, **kwargs).n_dofs == 10  # v, θ at nodes 1..5
    assert structural.cantilever(1.0, 5, axial=True, **kwargs).n_dofs == 15


def test_expand_puts_zeros_at_the_clamp():
    beam = structural.cantilever(1.0, 4, width=0.01, height=0.01, **STEEL)
    full = beam.expand(np.arange(1.0, 9.0)).reshape(5, 3)
    np.testing.assert_array_equal(full[0], 0.0)  # clamped node
    np.testing.assert_array_equal(full[:, 0], 0.0)  # axial DOFs fixed
    np.testing.assert_array_equal(full[1:, 1:].ravel(), np.arange(1.0, 9.0))


def test_expand_keeps_leading_axes():
    beam = structural.cantilever(1.0, 4, width=0.01, height=0.01, **STEEL)
    assert beam.expand(np.zeros((3, 2, beam.n_dofs))).shape == (3, 2, 15)


def test_rotated_cantilever_has_the_same_frequencies():
    angle, n = 0.7, 10
    nodes = np.outer(np.linspace(0, 1, n + 1), [np.cos(angle), np.sin(angle)])
    tilted = structural.build_frame(
        nodes,
        np.column_stack([np.arange(n), np.arange(1, n + 1)]),
        area=1e-4,
        second_moment=1e-8 / 12,
        supports={0: "clamped"},
        **STEEL,
    )
    straight = structural.cantilever(1.0, n, width=0.01, height=0.01, axial=True, **STEEL)
    # element matrices rotated by T: the spectrum is invariant up to round-off
    np.testing.assert_allclose(
        tilted.natural_frequencies(6), straight.natural_frequencies(6), rtol=1e-9
    )


def test_simply_supported_frame_matches_the_sine_modes():
    n, length = 16, 2.0
    nodes = np.column_stack([np.linspace(0, length, n + 1), np.zeros(n + 1)])
    beam = structural.build_frame(
        nodes,
        np.column_stack([np.arange(n), np.arange(1, n + 1)]),
        area=1e-4,
        second_moment=1e-8 / 12,
        supports={0: "pinned", n: "roller-x"},
        **STEEL,
    )
    EI, rho_A = STEEL["E"] * 1e-8 / 12, STEEL["rho"] * 1e-4
    exact = (np.arange(1, 4) * np.pi / length) ** 2 * np.sqrt(EI / rho_A)
    # the lowest axial mode is far above the third bending mode here
    np.testing.assert_allclose(beam.natural_frequencies(3), exact, rtol=1e-4)


def test_monitor_defaults_to_the_largest_load():
    nodes = np.array([[0, 0], [1, 0], [2, 0]], dtype=float)
    frame = structural.build_frame(
        nodes,
        [[0, 1], [1, 2]],
        area=1e-4,
        second_moment=1e-9,
        supports={0: "clamped"},
        loads={1: (0, 5, 0), 2: (0, -9, 0)},
        **STEEL,
    )
    assert frame.tip_dof == 4  # node 2 (free DOFs 3, 4, 5), component v
    assert frame.f[frame.tip_dof] == -9


def test_fine_mesh_warns_that_it_is_ill_conditioned():
    # κ(S) ≈ 2e17 at N = 10000: ε κ ≈ 40
    with pytest.warns(structural.IllConditionedWarning, match="condition number"):
        structural.cantilever(1.0, 10_000, width=0.01, height=0.01, **STEEL)


def test_moderate_mesh_does_not_warn():
    # κ(S) ≈ 2e13 at N = 1000; pytest turns any warning into an error
    beam = structural.cantilever(1.0, 1000, width=0.01, height=0.01, **STEEL)
    assert structural.condition_estimate(beam.S) < 1e14


@pytest.mark.parametrize(
    "argument, value",
    [
        ("length", 0.0),
        ("length", -1.0),
        ("length", np.nan),
        ("E", 0.0),
        ("E", -210e9),
        ("rho", 0.0),
        ("rho", np.inf),
        ("width", -0.01),
        ("height", 0.0),
        ("tip_load", np.nan),
    ],
)
def test_cantilever_rejects_bad_numbers(argument, value):
    kwargs = {"length": 1.0, "n_elements": 4, "width": 0.01, "height": 0.01, **STEEL}
    kwargs[argument] = value
    with pytest.raises(ValueError, match=rf"^{argument}={value!r} is not allowed: must be "):
        structural.cantilever(**kwargs)


@pytest.mark.parametrize("n_elements", [0, -3, 2.5, True])
def test_cantilever_rejects_bad_element_counts(n_elements):
    with pytest.raises(ValueError, match=r"n_elements=.* is not allowed: must be an integer >= 1"):
        structural.cantilever(1.0, n_elements, width=0.01, height=0.01, **STEEL)


def test_build_frame_rejects_unknown_support():
    with pytest.raises(
        ValueError, match=r"supports\[0\]='fixed' is not allowed: must be one of 'clamped', "
    ):
        structural.build_frame(
            [[0, 0], [1, 0]], [[0, 1]], area=1.0, second_moment=1.0, supports={0: "fixed"}, **STEEL
        )


def test_build_frame_rejects_coincident_nodes():
    with pytest.raises(ValueError, match="coincident nodes"):
        structural.build_frame(
            [[0, 0], [0, 0]],
            [[0, 1]],
            area=1.0,
            second_moment=1.0,
            supports={0: "clamped"},
            **STEEL,
        )


def test_build_frame_rejects_node_out_of_range():
    with pytest.raises(
        ValueError, match=r"connectivity=.* is not allowed: must be node indices 0..1"
    ):
        structural.build_frame(
            [[0, 0], [1, 0]],
            [[0, 2]],
            area=1.0,
            second_moment=1.0,
            supports={0: "clamped"},
            **STEEL,
        )


def test_natural_frequencies_rejects_too_many_modes():
    beam = structural.cantilever(1.0, 2, width=0.01, height=0.01, **STEEL)
    with pytest.raises(
        ValueError, match="k=5 is not allowed: must be an integer from 1 to n_dofs = 4"
    ):
        beam.natural_frequencies(5)


def test_build_frame_rejects_a_load_that_is_not_three_numbers():
    with pytest.raises(
        ValueError,
        match=r"loads\[1\]=\(0.0, 1.0\) is not allowed: must be of shape \(3,\).*F_x, F_y",
    ):
        structural.build_frame(
            [[0, 0], [1, 0]],
            [[0, 1]],
            area=1.0,
            second_moment=1.0,
            supports={0: "clamped"},
            loads={1: (0.0, 1.0)},
            **STEEL,
        )


def test_build_frame_rejects_supports_that_fix_every_dof():
    with pytest.raises(
        ValueError, match="supports=.* is not allowed: must be supports that leave some DOF free"
    ):
        structural.build_frame(
            [[0, 0], [1, 0]],
            [[0, 1]],
            area=1.0,
            second_moment=1.0,
            supports={0: "clamped", 1: "clamped"},
            **STEEL,
        )


def test_build_frame_rejects_a_free_floating_frame():
    with pytest.raises(
        ValueError, match="supports=.* is not allowed: must be supports that leave no mechanism"
    ):
        structural.build_frame(
            [[0, 0], [1, 0], [2, 0]],
            [[0, 1], [1, 2]],
            area=1e-4,
            second_moment=1e-9,
            supports={},
            **STEEL,
        )
