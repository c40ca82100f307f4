"""The numba kernels run the same algorithm as the NumPy reference: agreement to round-off.

Round-off here is what :func:`rigid_roundoff.kernel_bound` allows: each step's chain of
roundings, random-walking over the run and grown by the flow's condition, measured as the
largest ratio of a state's change to a change of 1e-7 in ω0, v0, x0 or R0 over the run (a
property of the problem, not of the machine).
"""

import numpy as np
import pytest
from rigid_roundoff import assert_kernel_matches

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


CONDITION = 2.5
"""The flow's condition over test_kernel_matches_reference's second: measured 2.0."""
CONDITION_FAST = 4.5
"""Over the three seconds of the fast spin, ω0 = (1, 2, −1.5): measured 3.8."""


@pytest.fixture(scope="module")
def body():
    return RigidBody(2.0, [[2.0, 0.1, 0.0], [0.1, 1.5, 0.05], [0.0, 0.05, 1.0]])


@pytest.mark.parametrize("method", FIXED)
def test_kernel_matches_reference(body, method):
    options = dict(method=method, h=0.01, omega0=(0.3, 1.0, -0.2), v0=(1, 0, 0), forces=FORCES)
    reference = simulate(body, 1.0, compiled=False, record_every=3, **options)
    kernel = simulate(body, 1.0, compiled=True, record_every=3, **options)
    np.testing.assert_array_equal(kernel.t, reference.t)  # both t0 + k h, in IEEE arithmetic
    # x and v reach 8 m, 8 m/s: the sums of the loads in another order differ by ulps there
    assert_kernel_matches(kernel, reference, method, ("R", "x", "v", "L_world"), CONDITION)


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
    # t0 + k h: two roundings at |t| ≤ 1, 2.2e-16 at most
    np.testing.assert_allclose(run.t, [0.0, 0.3, 0.6, 0.9, 1.0], atol=1e-14)
    assert run.n_steps == 100


@pytest.mark.parametrize("h", [0.08, 0.3], ids=["series-edge", "sin-cos"])
@pytest.mark.parametrize("method", ["lie-euler", "seed-rk4", "rkmk4", "rkmk8"])
def test_kernel_matches_reference_for_large_rotations_per_step(body, method, h):
    # |ω| ≈ 2.7 rad/s: h = 0.08 turns ≈ 0.22 rad per step, near the end of the kernels'
    # Taylor series for exp and dexp⁻¹ (SERIES_ANGLE = 0.25 in rigid/_compiled/charts.py), where
    # their truncation
    # matters most; h = 0.3 turns ≈ 0.8 rad, on their sin/cos branch. The test above stays at
    # 0.01 rad.
    options = dict(method=method, h=h, omega0=(1.0, 2.0, -1.5), forces=FORCES[:2])
    reference = simulate(body, 3.0, compiled=False, **options)
    kernel = simulate(body, 3.0, compiled=True, **options)
    assert_kernel_matches(kernel, reference, method, ("R", "L_world"), CONDITION_FAST)
