"""The trajectory's derived quantities and its xarray form."""

import numpy as np
import pytest

from tumble import so3
from tumble.rigid import RigidBody, simulate


@pytest.fixture(scope="module")
def run():
    body = RigidBody(2.0, [1.0, 2.0, 2.5])
    return simulate(body, 1.0, h=0.01, omega0=(0.5, 1.0, -0.3), v0=(1, 2, 3))


def test_energy_is_translational_plus_half_omega_dot_l(run):
    body_L = run.R[0].T @ run.L_world[0]
    expected = 0.5 * 2.0 * 14.0 + 0.5 * np.dot([0.5, 1.0, -0.3], body_L)
    assert run.energy[0] == pytest.approx(expected, rel=1e-14)


def test_omega_body_at_start_is_omega0(run):
    np.testing.assert_allclose(run.omega_body[0], [0.5, 1.0, -0.3], atol=1e-15)


def test_quaternions_match_the_matrices(run):
    np.testing.assert_allclose(so3.matrix_from_quat(run.q), run.R, atol=1e-13)


def test_xarray_dataset_carries_dimensions_units_and_settings(run):
    ds = run.to_xarray()
    assert ds["R"].dims == ("time", "row", "col")
    assert ds["L_world"].attrs["units"] == "kg m2/s"
    assert ds.attrs["method"] == "rkmk4"
    np.testing.assert_array_equal(ds["time"].values, run.t)
    np.testing.assert_array_equal(ds["energy"].values, run.energy)
