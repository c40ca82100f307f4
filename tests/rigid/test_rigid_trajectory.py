"""The trajectory's derived quantities and its xarray form."""

import numpy as np
import pytest
from rigid_roundoff import invariant_bound
from roundoff import error_bound

from tumble import so3
from tumble.rigid import Gravity, RigidBody, Trajectory, simulate


@pytest.fixture(scope="module")
def run():
    body = RigidBody(2.0, [1.0, 2.0, 2.5])
    return simulate(body, 1.0, h=0.01, omega0=(0.5, 1.0, -0.3), v0=(1, 2, 3))


def test_energy_is_translational_plus_half_omega_dot_l(run):
    body_L = run.R[0].T @ run.L_world[0]
    expected = 0.5 * 2.0 * 14.0 + 0.5 * np.dot([0.5, 1.0, -0.3], body_L)
    # two evaluations of about ten roundings on positive terms: 20 u = 2.2e-15 at most
    assert run.energy[0] == pytest.approx(expected, rel=1e-14)


def test_omega_body_at_start_is_omega0(run):
    # L0 = I ω0 and back through R0 = Id: two roundings of |ω| ≤ 1
    np.testing.assert_allclose(run.omega_body[0], [0.5, 1.0, -0.3], atol=1e-15)


def test_quaternions_match_the_matrices(run):
    # q is the rotation nearest R: they differ by R's own departure from SO(3), the walk of
    # the run's round-off, and by the round trip's 3-term sums (measured 1.7e-15)
    bound = invariant_bound("rkmk4", 100) + error_bound(3.0, 30)
    np.testing.assert_allclose(so3.matrix_from_quat(run.q), run.R, atol=bound)


def test_xarray_dataset_carries_dimensions_units_and_settings(run):
    ds = run.to_xarray()
    assert ds["R"].dims == ("time", "row", "col")
    assert ds["L_world"].attrs["units"] == "kg m2/s"
    assert ds.attrs["method"] == "rkmk4"
    np.testing.assert_array_equal(ds["time"].values, run.t)
    np.testing.assert_array_equal(ds["energy"].values, run.energy)


def _trajectory(body, *, v=None, L_world=None, R=None):
    """A three-sample trajectory built by hand (the fields not given are at rest, R = Id)."""
    n = 3
    return Trajectory(
        t=np.arange(n, dtype=float),
        x=np.zeros((n, 3)),
        v=np.zeros((n, 3)) if v is None else np.asarray(v, dtype=float),
        R=np.tile(np.eye(3), (n, 1, 1)) if R is None else np.asarray(R, dtype=float),
        L_world=np.zeros((n, 3)) if L_world is None else np.asarray(L_world, dtype=float),
        body=body,
        method="by hand",
    )


def test_energy_error_and_drift_by_hand():
    # Translation only: E = ½ m |v|² = 1, 1.21, 0.81 J for m = 2 kg.
    run = _trajectory(RigidBody(2.0, [1.0, 2.0, 2.5]), v=[[1, 0, 0], [1.1, 0, 0], [0.9, 0, 0]])
    # By hand, here and below: a few roundings of numbers ≤ 2, each ≤ 2.2e-16 (exact zeros
    # elsewhere), so the same bits on any machine
    np.testing.assert_allclose(run.energy_error, [0.0, 0.21, -0.19], atol=1e-15)
    assert run.energy_drift == pytest.approx(0.21, rel=1e-14)  # max |E − E₀| / |E₀|


def test_momentum_error_and_drift_by_hand():
    run = _trajectory(
        RigidBody(2.0, [1.0, 2.0, 2.5]), L_world=[[2, 0, 0], [2, 0.3, 0], [2, 0, -0.4]]
    )
    np.testing.assert_allclose(run.momentum_error, [0.0, 0.3, 0.4], atol=1e-15)
    assert run.momentum_drift == pytest.approx(0.4 / 2.0, rel=1e-14)  # max ‖L − L₀‖ / ‖L₀‖


def test_orthogonality_drift_by_hand():
    stretched = np.diag([1.0, 1.0, 1.1])  # RᵀR − I = diag(0, 0, 0.21)
    run = _trajectory(RigidBody(1.0, [1.0, 1.0, 1.0]), R=[np.eye(3), stretched, np.eye(3)])
    assert run.orthogonality_drift == pytest.approx(0.21, rel=1e-14)


def test_drifts_relative_to_a_zero_reference_are_nan():
    run = _trajectory(RigidBody(1.0, [1.0, 1.0, 1.0]), v=[[0, 0, 0], [1, 0, 0], [0, 0, 0]])
    assert np.isnan(run.energy_drift) and np.isnan(run.momentum_drift)
    np.testing.assert_array_equal(run.energy_error, [0.0, 0.5, 0.0])  # the change is still J


def test_euler_on_the_sphere_drifts_off_so3_by_the_closed_form():
    # I = Id, ω = (1, 0, 0): explicit Euler keeps R's first row and column (1, 0, 0) and
    # multiplies its yz block by a rotation times √(1 + h²) per step, so RᵀR − I =
    # diag(0, g, g) with g = (1 + h²)^k − 1, while ω = Rᵀ L and the energy stay exact.
    run = simulate(RigidBody(1.0, np.eye(3)), 1.0, method="euler", h=0.1, omega0=(1, 0, 0))
    assert run.orthogonality_drift == pytest.approx(np.sqrt(2) * (1.01**10 - 1), rel=1e-12)
    assert run.energy_drift == 0.0 and run.momentum_drift == 0.0


def test_energy_under_gravity_splits_into_the_closed_forms():
    # T − T₀ = m (v₀·g t + ½ |g|² t²), V = −m g·x = −(T − T₀); RK4 steps the linear v and the
    # quadratic x exactly, so the total energy T + V stays at T₀ to round-off.
    g, v0, body = np.array([0.0, 0.0, -9.81]), np.array([3.0, 0.0, 4.0]), RigidBody(2.0, np.eye(3))
    run = simulate(body, 1.0, h=0.1, v0=v0, forces=[Gravity(g)])
    expected = 2.0 * (v0 @ g * run.t + 0.5 * (g @ g) * run.t**2)
    kinetic = run.kinetic_energy - run.kinetic_energy[0]
    # Round-off only: each of the 10 steps rounds v and x in 6 operations on terms up to
    # |v| + h|g| (and |x| + h|v|); T = ½ m |v|² and V = −m g·x then carry m |v| δv and
    # m |g| δx, with their own few roundings on m |v|² (measured 7.1e-15 and 5.8e-15).
    speed, height = np.abs(run.v).max(), np.abs(run.x).max()
    dv = error_bound(speed + 0.1 * 9.81, 6 * 10)
    dx = error_bound(height + 0.1 * speed, 6 * 10)
    squares = error_bound(2.0 * speed**2, 8)
    np.testing.assert_allclose(kinetic, expected, rtol=0, atol=2.0 * speed * dv + squares)
    # −m g_z x_z both ways (g has two zeros): two roundings each side
    np.testing.assert_allclose(run.potential_energy, -2.0 * run.x @ g, rtol=1e-15)
    np.testing.assert_allclose(run.potential_energy, -expected, rtol=0,
                               atol=2.0 * 9.81 * dx + squares)  # fmt: skip
    assert np.abs(run.energy_error).max() < 1e-13 * 25.0
    assert run.energy_drift < 1e-13


def test_lie_euler_on_the_sphere_keeps_every_invariant():
    run = simulate(RigidBody(1.0, np.eye(3)), 1.0, method="lie-euler", h=0.1, omega0=(1, 0, 0))
    walk = invariant_bound("lie-euler", 10)  # round-off of 10 steps (measured 0 and 4.7e-16)
    assert run.energy_drift < walk and run.orthogonality_drift < walk
    assert run.momentum_drift == 0.0


def test_scipy_rotation_in_and_out():
    # Issue 18 item 15: Trajectory.rotation is a scipy Rotation; simulate takes one as R0; the
    # scalar-first quaternions of tumble and scipy's scalar-last ones convert both ways.
    from scipy.spatial.transform import Rotation

    start = Rotation.from_rotvec([0.3, -0.2, 0.9])
    run = simulate(RigidBody(1.0, [1.0, 2.0, 3.0]), 2.0, h=0.01, R0=start, omega0=(0.1, 1.0, 0.2))
    np.testing.assert_allclose(run.R[0], start.as_matrix(), atol=1e-15)  # equal, measured
    assert len(run.rotation) == len(run.t)
    # scipy's rotations are the nearest ones to R: R's departure from SO(3) after 200 steps
    # (the walk of their round-off) and the round trip's 3-term sums (measured ≤ 1.4e-15)
    bound = invariant_bound("rkmk4", 200) + error_bound(3.0, 30)
    np.testing.assert_allclose(run.rotation.as_matrix(), run.R, atol=bound)
    scalar_last = run.rotation.as_quat(canonical=True)  # [x, y, z, w], w ≥ 0
    np.testing.assert_allclose(np.roll(scalar_last, 1, axis=1), run.q, atol=bound)
    back = Rotation.from_quat(np.roll(run.q, -1, axis=1))  # scalar-first → scalar-last
    np.testing.assert_allclose(back.as_matrix(), run.R, atol=bound)
    with pytest.raises(
        ValueError, match=r"^R0='<Rotation of 2>' is not allowed: must be a single"
    ):
        simulate(RigidBody(1.0, [1.0, 2.0, 3.0]), 1.0, h=0.1, R0=Rotation.random(2, rng=1))
