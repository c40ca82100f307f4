"""The numba kernels run the same algorithm as the NumPy reference: agreement to round-off."""

import numpy as np
import pytest

from tumble.rigid import (
    METHODS,
    Force,
    Gravity,
    Impulse,
    MagneticDipole,
    RigidBody,
    Torque,
    simulate,
)

FIXED = [name for name, method in METHODS.items() if not method.adaptive and not method.exact]
"""The fixed-step methods that take loads (the exact flow takes none: test_rigid_geometric)."""
FORCES = [
    Gravity(),
    Force((0.1, 0.2, 0.3), point=(0.1, 0.0, 0.05)),
    Force((0.0, -0.5, 0.0)),
    Torque((0.01, 0.0, -0.02)),
    MagneticDipole((0.2, -0.1, 0.3), (0.0, 0.5, 0.4)),
    Impulse((0.1, 0.2, 0.3), (0.5, 0.0, 0.1), time=0.333),
]


@pytest.fixture(scope="module")
def body():
    return RigidBody(2.0, [[2.0, 0.1, 0.0], [0.1, 1.5, 0.05], [0.0, 0.05, 1.0]])


@pytest.mark.parametrize("method", FIXED)
def test_kernel_matches_reference(body, method):
    options = dict(method=method, h=0.01, omega0=(0.3, 1.0, -0.2), v0=(1, 0, 0), forces=FORCES)
    reference = simulate(body, 1.0, compiled=False, record_every=3, **options)
    kernel = simulate(body, 1.0, compiled=True, record_every=3, **options)
    np.testing.assert_array_equal(kernel.t, reference.t)
    np.testing.assert_allclose(kernel.R, reference.R, rtol=0, atol=1e-13)
    # x and v reach 8 m, 8 m/s: the sums of the loads in another order differ by ulps there
    np.testing.assert_allclose(kernel.x, reference.x, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(kernel.v, reference.v, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(kernel.L_world, reference.L_world, rtol=0, atol=1e-13)


def test_kernel_is_the_default_for_constant_loads(body):
    run = simulate(body, 0.1, h=0.01, omega0=(1, 0, 0), forces=[Gravity()])
    assert run.settings["compiled"] is True


def test_callable_load_runs_in_python(body):
    run = simulate(body, 0.1, h=0.01, forces=[Torque(lambda t, s: (0.0, 0.0, t))])
    assert run.settings["compiled"] is False


def test_compiled_true_is_refused_for_a_callable_load(body):
    with pytest.raises(ValueError, match="compiled=True"):
        simulate(body, 0.1, h=0.01, forces=[Torque(lambda t, s: (0, 0, t))], compiled=True)


def test_record_every_keeps_every_kth_step_and_the_last(body):
    run = simulate(body, 1.0, h=0.01, omega0=(1, 0, 0), record_every=30)
    np.testing.assert_allclose(run.t, [0.0, 0.3, 0.6, 0.9, 1.0], atol=1e-14)
    assert run.n_steps == 100


@pytest.mark.parametrize("h", [0.08, 0.3], ids=["series-edge", "sin-cos"])
@pytest.mark.parametrize("method", ["lie-euler", "seed-rk4", "rkmk4", "rkmk8"])
def test_kernel_matches_reference_for_large_rotations_per_step(body, method, h):
    # |ω| ≈ 2.7 rad/s: h = 0.08 turns ≈ 0.22 rad per step, near the end of the kernels'
    # Taylor series for exp and dexp⁻¹ (kernels.SERIES_ANGLE = 0.25), where their truncation
    # matters most; h = 0.3 turns ≈ 0.8 rad, on their sin/cos branch. The test above stays at
    # 0.01 rad.
    options = dict(method=method, h=h, omega0=(1.0, 2.0, -1.5), forces=FORCES[:2])
    reference = simulate(body, 3.0, compiled=False, **options)
    kernel = simulate(body, 3.0, compiled=True, **options)
    np.testing.assert_allclose(kernel.R, reference.R, rtol=0, atol=1e-13)
    np.testing.assert_allclose(kernel.L_world, reference.L_world, rtol=0, atol=1e-13)
