"""Misuse of the rigid-body API: ValueErrors naming the argument and what is allowed."""

import numpy as np
import pytest

from tumble.rigid import METHODS, Impulse, RigidBody, simulate

BODY = RigidBody(1.0, [1.0, 2.0, 2.5])


@pytest.mark.parametrize("mass", [0.0, -1.0, np.nan])
def test_non_positive_mass_is_refused(mass):
    with pytest.raises(ValueError, match="mass"):
        RigidBody(mass, np.eye(3))


def test_inertia_not_positive_definite_is_refused():
    with pytest.raises(ValueError, match="inertia"):
        RigidBody(1.0, [1.0, -1.0, 1.0])


def test_non_symmetric_inertia_is_refused():
    with pytest.raises(ValueError, match="inertia"):
        RigidBody(1.0, [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


def test_triangle_inequality_violation_names_the_remedy():
    with pytest.raises(ValueError, match="allow_unphysical"):
        RigidBody(1.0, [2.0, 1.0, 2.0 / 3.0])


def test_triangle_inequality_waived_on_request():
    body = RigidBody(1.0, [2.0, 1.0, 2.0 / 3.0], allow_unphysical=True)
    assert body.inertia[0, 0] == 2.0


def test_r0_not_a_rotation_is_refused():
    with pytest.raises(ValueError, match="R0"):
        simulate(BODY, 1.0, h=0.1, R0=np.diag([1.0, 1.0, -1.0]))


def test_zero_quaternion_is_refused():
    with pytest.raises(ValueError, match="q0"):
        simulate(BODY, 1.0, h=0.1, q0=[0, 0, 0, 0])


@pytest.mark.parametrize("h", [0.0, -0.1, np.nan])
def test_bad_step_is_refused(h):
    with pytest.raises(ValueError, match="h="):
        simulate(BODY, 1.0, h=h)


def test_missing_step_for_fixed_method_is_refused():
    with pytest.raises(ValueError, match="h=None"):
        simulate(BODY, 1.0)


def test_both_omega0_and_l0_are_refused():
    with pytest.raises(ValueError, match="omega0.*L0"):
        simulate(BODY, 1.0, h=0.1, omega0=(1, 0, 0), L0=(1, 0, 0))


def test_unknown_method_lists_the_known_ones():
    with pytest.raises(ValueError, match="method='rk5'.*rkmk4"):
        simulate(BODY, 1.0, method="rk5", h=0.1)


def test_t_end_before_t0_is_refused():
    with pytest.raises(ValueError, match="t_end"):
        simulate(BODY, -1.0, h=0.1)


@pytest.mark.parametrize("rtol", [0.0, -1e-6])
def test_non_positive_rtol_is_refused(rtol):
    with pytest.raises(ValueError, match="rtol"):
        simulate(BODY, 1.0, method="rkmk45", rtol=rtol)


def test_tolerance_for_fixed_step_method_is_refused():
    with pytest.raises(ValueError, match="rtol"):
        simulate(BODY, 1.0, h=0.1, rtol=1e-6)


def test_unknown_load_is_refused():
    with pytest.raises(ValueError, match=r"forces\[0\]"):
        simulate(BODY, 1.0, h=0.1, forces=[(0, 0, -9.81)])


# Issue 18 item 11: values that were accepted silently or answered with a bare TypeError.
@pytest.mark.parametrize(
    "options, message",
    [
        (dict(events=42), r"^events=42 is not allowed: must be a callable"),
        (dict(events=[42]), r"^events\[0\]=42 is not allowed: must be a callable"),
        (dict(progress="x"), r"^progress='x' is not allowed: must be True or False"),
        (
            dict(forces=[Impulse((0, 0, 0), (1, 0, 0), time=5.0)]),
            r"^forces\[0\]\.time=5\.0 is not allowed: must be within the run, \[0\.0, 1\.0\]",
        ),
    ],
    ids=["events-int", "events-item", "progress-str", "impulse-after-the-end"],
)
def test_silently_accepted_values_are_refused(options, message):
    with pytest.raises(ValueError, match=message):
        simulate(RigidBody(1.0, [1.0, 2.0, 3.0]), 1.0, h=0.1, **options)


@pytest.mark.parametrize(
    "options, message",
    [
        (dict(events=42), r"^events=42 is not allowed"),
        (dict(dense_output="yes"), r"^dense_output='yes' is not allowed: must be True or False"),
    ],
)
def test_solve_refuses_the_same(options, message):
    from tumble import solve

    with pytest.raises(ValueError, match=message):
        solve(lambda t, y: -y, (0.0, 1.0), [1.0], h=0.1, **options)


def test_io_load_of_none_names_the_path():
    from tumble import io

    with pytest.raises(ValueError, match=r"^path=None is not allowed"):
        io.load(None)


@pytest.mark.parametrize("method", [name for name, spec in METHODS.items() if spec.adaptive])
def test_an_adaptive_run_whose_load_turns_nan_says_so_not_minimum_step(method):
    from tumble.rigid.forces import Force

    def force(t, state):
        return np.array([np.nan, 0.0, 0.0]) if t > 0.5 else np.array([0.0, 1.0, 0.0])

    body = RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))
    run = simulate(
        body, 2.0, method=method, omega0=[1, 0.1, 0], forces=[Force(force, point=[0.1, 0, 0])]
    )
    assert run.status == -1
    assert run.message.startswith("the state became non-finite (nan or inf)"), run.message
    assert "a load" in run.message and run.t[-1] == pytest.approx(0.5)


@pytest.mark.parametrize(
    ("name", "options"),
    [
        ("omega0", {"omega0": [1e155, 0.0, 0.0]}),
        ("L0", {"L0": [1e200, 0.0, 0.0]}),
        ("v0", {"v0": [1e160, 0.0, 0.0]}),
    ],
)
def test_an_initial_motion_whose_energy_overflows_is_refused_by_name(name, options):
    # ½ ω·L overflowed and the run reported status 0 with energy inf from its first sample
    with pytest.raises(ValueError, match=rf"^{name}=.* kinetic energy are finite floats"):
        simulate(RigidBody(1.0, np.eye(3)), 1.0, h=0.1, **options)
