"""Banded Cholesky against dense solves, and the choice between banded and sparse LU."""

import numpy as np
import pytest
import scipy.sparse as sp
from roundoff import error_bound, sum_bound
from structural_frames import shuffled_cantilever, tilted_frame, wheel

from tumble import structural
from tumble.structural.factorization import (
    BAND_FILL_LIMIT,
    MAX_BANDWIDTH,
    BandedCholesky,
    band_structure,
    banded_cholesky,
    bandwidth,
)

STEEL = {"E": 210e9, "rho": 7850.0, "width": 0.01, "height": 0.01}


def step_matrix(system):
    """The midpoint matrix ``M + Δt²/4 S`` at Δt = T₁/200, as `integrate` factorises it."""
    dt = 2 * np.pi / system.natural_frequencies(1)[0] / 200
    return structural.MIDPOINT.matrices(system, None, dt)[0]


def random_banded_spd(n, b, seed):
    """``B Bᵀ + I`` with ``B`` random lower banded (half-bandwidth b): SPD, κ about 10²."""
    rng = np.random.default_rng(seed)
    B = sp.diags([rng.uniform(-1, 1, n - k) for k in range(b + 1)], [-k for k in range(b + 1)])
    return (B @ B.T + sp.identity(n)).tocsr()


@pytest.mark.parametrize(
    "name",
    ["cantilever", "cantilever with axial DOFs", "tilted frame", "random b = 7"],
)
def test_banded_cholesky_solve_equals_a_dense_solve(name):
    A = {
        "cantilever": lambda: step_matrix(structural.cantilever(1.0, 12, **STEEL)),
        "cantilever with axial DOFs": lambda: step_matrix(
            structural.cantilever(1.0, 12, axial=True, **STEEL)
        ),
        "tilted frame": lambda: step_matrix(tilted_frame()),
        "random b = 7": lambda: random_banded_spd(60, 7, seed=1),
    }[name]()
    dense = A.toarray()
    r = np.random.default_rng(2).standard_normal(A.shape[0])
    expected = np.linalg.solve(dense, r)
    # both solves are backward stable, each a chain of about b + 2 roundings a row (banded
    # Cholesky) against LAPACK's: the difference is (b + 2) ε κ(A) |x|; κ ≤ 1e4 here
    for factor in (BandedCholesky.from_matrix(A), banded_cholesky(A)):
        magnitude = np.linalg.cond(dense) * np.abs(expected).max()
        tolerance = sum_bound(magnitude, factor.bandwidth + 2)
        np.testing.assert_allclose(factor.solve(r), expected, rtol=0, atol=tolerance)


def test_banded_factor_arrays_rebuild_the_matrix():
    A = random_banded_spd(40, 4, seed=3)
    order = np.random.default_rng(4).permutation(40)  # any order: the band just widens
    factor = BandedCholesky.from_matrix(A, order)
    n, b = 40, factor.bandwidth
    L = np.diag(1 / factor.inverse_diagonal)
    for p in range(n):  # forward[p, j] = L[p, p − b + j] / L[p, p]
        for j in range(b):
            if p - b + j >= 0:
                L[p, p - b + j] = factor.forward[p, j] / factor.inverse_diagonal[p]
    # Cholesky's backward error, |L Lᵀ − A| ≤ γ_{b+1} |L| |Lᵀ| (Higham §10.1), plus this
    # rebuild's own b + 1 sums and the divisions undone: 2b + 4 roundings (measured 3.8 u)
    rebuilt = np.abs(L @ L.T - A.toarray()[np.ix_(order, order)])
    assert np.all(rebuilt <= error_bound(np.abs(L) @ np.abs(L.T), 2 * b + 4))
    for p in range(n):  # backward[p, j] = L[p + b − j, p] / L[p, p]
        for j in range(b):
            q = p + b - j
            expected = L[q, p] * factor.inverse_diagonal[p] if q < n else 0.0
            # a division, a product and their undoing: 4 roundings (measured 2.6 u); the
            # zeros past the end are exact
            assert factor.backward[p, j] == pytest.approx(expected, rel=error_bound(1.0, 4), abs=0)


def test_banded_cholesky_rejects_a_matrix_that_is_not_positive_definite():
    with pytest.raises(np.linalg.LinAlgError):
        BandedCholesky.from_matrix(sp.diags([1.0, -1.0, 2.0]))


def test_band_structure_keeps_a_beam_in_its_own_order():
    beam = step_matrix(structural.cantilever(1.0, 30, **STEEL))
    structure = band_structure(beam)
    # (v, θ) per node, coupled to the next node's: b = 3; the band holds 1.3× tril A
    assert (structure.bandwidth, structure.narrow, structure.natural) == (3, True, True)
    assert structure.fill < BAND_FILL_LIMIT


@pytest.mark.parametrize(
    "make, expected",
    [
        (lambda: structural.cantilever(1.0, 30, axial=True, **STEEL), 4),  # u decoupled
        (tilted_frame, 5),  # inclined members couple u_i to θ_j
    ],
)
def test_band_structure_of_frames_with_axial_dofs(make, expected):
    structure = band_structure(step_matrix(make()))
    assert structure.bandwidth == expected and structure.narrow and structure.natural


def test_band_structure_renumbers_a_shuffled_beam_by_reverse_cuthill_mckee():
    A = step_matrix(shuffled_cantilever(40))
    assert bandwidth(A) > 50  # random numbering: the natural band is wide
    structure = band_structure(A)
    assert structure.narrow and not structure.natural
    assert structure.bandwidth <= 5


def test_band_structure_falls_back_to_sparse_lu_when_a_hub_couples_every_node():
    structure = band_structure(step_matrix(wheel(12)))
    # the hub's row is full whatever the order: b = 27 after reverse Cuthill–McKee
    assert not structure.narrow
    assert structure.bandwidth > MAX_BANDWIDTH or structure.fill > BAND_FILL_LIMIT


def test_band_structure_falls_back_to_sparse_lu_for_a_random_sparse_matrix():
    rng = np.random.default_rng(5)
    R = sp.random(300, 300, density=0.01, random_state=rng)
    structure = band_structure(R @ R.T + sp.identity(300))
    assert not structure.narrow
    assert structure.bandwidth > 100  # measured 251


def test_bandwidth_ignores_stored_zeros():
    A = sp.csr_matrix(([2.0, 0.0, 2.0, 0.0, 2.0], ([0, 0, 1, 2, 2], [0, 2, 1, 0, 2])))
    assert A.nnz == 5 and bandwidth(A) == 0  # the corners hold stored zeros


def test_banded_cholesky_eliminates_a_cantilever_from_its_free_tip():
    beam = structural.cantilever(1.0, 100, **STEEL)
    A = step_matrix(beam)
    chosen = banded_cholesky(A)
    clamp_first = BandedCholesky.from_matrix(A)
    # from the clamp the tip's pivot is a difference of nearly equal numbers: L²/A_pp
    # measured 3.9e-4 here, falling as N⁻³ (4e-10 at 10⁴ elements); from the tip 0.13
    assert clamp_first.pivot_ratio < 1e-3
    assert chosen.pivot_ratio > 0.1
    assert chosen.order[0] == beam.n_dofs - 1


def test_banded_cholesky_reports_a_breakdown_in_both_directions():
    indefinite = sp.diags([[1.0, 3.0, 1.0, 1.0], [2.0, 2.0, 2.0]], [0, 1])
    with pytest.raises(np.linalg.LinAlgError, match="both directions"):
        banded_cholesky(indefinite + indefinite.T)
