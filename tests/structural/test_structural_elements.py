"""Element matrices and element-level internal forces (tumble.structural.elements, kernels)."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from roundoff import error_bound, sum_bound

from tumble import structural
from tumble.structural import elements

lengths = st.floats(1e-3, 10.0)
angles = st.floats(-np.pi, np.pi)
stiffnesses = st.floats(1e-2, 1e9)


def rigid_motions(length, angle):
    """Columns: translation along x, along y, rotation about node i, as element DOFs."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array(
        [
            [1, 0, 0, 1, 0, 0],
            [0, 1, 0, 0, 1, 0],
            [0, 0, 1, -length * s, length * c, 1],  # node j moves by θ × (x_j − x_i)
        ],
        dtype=float,
    ).T


@given(length=lengths, angle=angles, EA=stiffnesses, slenderness=st.floats(1.0, 1e3))
def test_stiffness_is_symmetric_positive_semidefinite_with_rank_three(
    length, angle, EA, slenderness
):
    EI = EA * (length / slenderness) ** 2  # radius of gyration h/slenderness: real beams
    K = elements.stiffness_matrices([length], [np.cos(angle)], [np.sin(angle)], [EA], [EI])[0]
    # K_ij and K_ji are sums of 4 terms T_ai k_ab T_bj (|T| ≤ 1; each ≤ max|k| ≤ 2 max|K|),
    # rounded in two orders, chains of 6: sum_bound(8 max|K|, 6) = 1.1e-14 max|K|
    np.testing.assert_allclose(K, K.T, rtol=0, atol=sum_bound(8 * np.abs(K).max(), 6))
    # Jacobi scaling makes the eigenvalues O(1) however far apart EA and EI are
    scaling = 1 / np.sqrt(np.diag(K))
    eigenvalues = np.linalg.eigvalsh(scaling[:, None] * K * scaling[None, :])
    assert eigenvalues.min() > -1e-12  # eigvalsh is backward stable: zeros come out O(ε)
    assert np.sum(eigenvalues > 1e-8) == 3


@given(length=lengths, angle=angles, EA=stiffnesses, EI=stiffnesses)
def test_rigid_motions_cost_no_force(length, angle, EA, EI):
    c, s = np.cos(angle), np.sin(angle)
    K = elements.stiffness_matrices([length], [c], [s], [EA], [EI])[0]
    forces = K @ rigid_motions(length, angle)
    # a rigid motion of size O(1 + h) against entries O(‖K‖): round-off only
    assert np.abs(forces).max() <= 1e-12 * np.abs(K).max() * (1 + length)


@given(length=lengths, angle=angles, rho_A=st.floats(1e-3, 1e4))
def test_mass_is_positive_definite_and_translates_the_element_mass(length, angle, rho_A):
    c, s = np.cos(angle), np.sin(angle)
    M = elements.mass_matrices([length], [c], [s], [rho_A])[0]
    assert np.linalg.eigvalsh(M).min() > 0
    translations = rigid_motions(length, angle)[:, :2]
    # ½ tᵀ M t = ½ m |t|² for a unit rigid translation: tᵀ M t = ρ A h
    np.testing.assert_allclose(
        translations.T @ M @ translations,
        rho_A * length * np.eye(2),
        rtol=1e-12,
        atol=1e-12 * rho_A * length,
    )


def test_horizontal_stiffness_has_the_textbook_entries():
    h, EA, EI = 2.0, 3.0, 5.0
    K = elements.stiffness_matrices([h], [1.0], [0.0], [EA], [EI])[0]
    bending = (
        EI
        / h**3
        * np.array(
            [
                [12, 6 * h, -12, 6 * h],
                [6 * h, 4 * h**2, -6 * h, 2 * h**2],
                [-12, -6 * h, 12, -6 * h],
                [6 * h, 2 * h**2, -6 * h, 4 * h**2],
            ]
        )
    )
    transverse = np.ix_([1, 2, 4, 5], [1, 2, 4, 5])
    # c = 1, s = 0 (exact zeros): EI, h and the integers in another order, ≤ 5 roundings a
    # side, 1.1e-15 relative
    np.testing.assert_allclose(K[transverse], bending, rtol=1e-14)
    np.testing.assert_allclose(K[np.ix_([0, 3], [0, 3])], EA / h * np.array([[1, -1], [-1, 1]]))


@given(length=lengths, angle=angles, EA=stiffnesses, EI=stiffnesses)
def test_element_forces_equal_stiffness_times_displacement(length, angle, EA, EI):
    c, s = np.cos(angle), np.sin(angle)
    x = np.random.default_rng(1).standard_normal((1, 6))
    K = elements.stiffness_matrices([length], [c], [s], [EA], [EI])[0]
    forces = elements.element_forces(x, [length], [c], [s], [EA], [EI])
    # two orders of summation of the same terms: agree to round-off of the largest term
    np.testing.assert_allclose(forces[0], K @ x[0], rtol=0, atol=1e-12 * np.abs(K).max())


def test_strain_energy_is_half_x_K_x():
    rng = np.random.default_rng(2)
    h, c, s, EA, EI = rng.uniform(0.1, 1, 4), *np.eye(2)[:, 0:1].repeat(4, 1), [9.0] * 4, [2.0] * 4
    x = rng.standard_normal((4, 6))
    K = elements.stiffness_matrices(h, c, s, EA, EI)
    energy = elements.strain_energy(x, h, c, s, EA, EI).sum(axis=-1)
    np.testing.assert_allclose(energy, 0.5 * np.einsum("ei,eij,ej->e", x, K, x), rtol=1e-12)


def test_compiled_internal_forces_match_the_assembled_matrix():
    frame = structural.cantilever(1.0, 7, E=7e10, rho=2700, width=0.02, height=0.01, axial=True)
    x = np.random.default_rng(3).standard_normal(frame.n_dofs)
    # same sums in a different order: round-off relative to the largest term |S| |x|
    np.testing.assert_allclose(
        frame.internal_forces(x),
        frame.S @ x,
        rtol=0,
        atol=1e-12 * (abs(frame.S) @ np.abs(x)).max(),
    )


def test_compiled_kernel_matches_the_numpy_reference():
    frame = tilted_frame()
    x = np.random.default_rng(4).standard_normal(frame.n_dofs)
    e = frame.elements
    forces = elements.element_forces(e.gather(x), e.length, e.cos, e.sin, e.EA, e.EI)
    reference, terms = np.zeros(frame.n_dofs + 1), np.zeros(frame.n_dofs + 1)
    np.add.at(reference, e.dof_map, forces)  # the last slot collects the fixed DOFs
    np.add.at(terms, e.dof_map, np.abs(forces))
    # the same formulas per element, in numba or NumPy (≤ 6 roundings), and the scatter's
    # sums in another order: on the element forces meeting at each DOF (up to 2e8 N here,
    # cancelling at the joints; measured 2.3e-10)
    assert np.all(np.abs(frame.internal_forces(x) - reference[:-1]) <= sum_bound(terms[:-1], 8))


def tilted_frame():
    """A portal frame with a leaning column: elements in three directions."""
    nodes = np.array([[0, 0], [0.3, 2], [2, 2], [2, 0]], dtype=float)
    return structural.build_frame(
        nodes,
        [[0, 1], [1, 2], [2, 3]],
        E=2e11,
        rho=7850,
        area=1e-3,
        second_moment=1e-6,
        supports={0: "clamped", 3: "pinned"},
        loads={1: (1e3, 0, 0)},
    )


@pytest.mark.parametrize("angle", [0.0, 0.5, np.pi / 2, 2.0])
def test_element_deformations_vanish_for_rigid_rotation(angle):
    x = rigid_motions(1.5, angle)[:, 2][None, :]
    d = elements.natural_deformations(x, [1.5], [np.cos(angle)], [np.sin(angle)])
    # c Δu + s Δv and (c Δv − s Δu)/h on terms ≤ 2 × 1.5: a difference, products, a sum, and
    # the rounding of x itself (measured ≤ 2.2e-16)
    np.testing.assert_allclose(d, 0.0, atol=error_bound(2 * 1.5, 5))
