"""Critical time steps and the dt sweep."""

import math

import numpy as np
import pytest
import scipy.linalg

from tumble import structural
from tumble.ode import Status

STEEL = {"E": 210e9, "rho": 7850.0, "width": 0.01, "height": 0.01}


@pytest.fixture(scope="module")
def beam():
    return structural.cantilever(1.0, 20, tip_load=1.0, **STEEL)


def dense_omega_max(system):
    lam = scipy.linalg.eigh(system.S.toarray(), system.M.toarray(), eigvals_only=True)
    return math.sqrt(lam.max())


def test_semi_implicit_critical_step_is_two_over_omega_max(beam):
    step = structural.critical_dt(beam, "semi-implicit")
    # the same dense eigenproblem: equal to round-off (measured 3e-16)
    assert step.dt == pytest.approx(2 / dense_omega_max(beam), rel=1e-12)
    assert step.omega == pytest.approx(dense_omega_max(beam), rel=1e-12)
    assert float(step) == step.dt


def test_critical_step_of_a_large_system_uses_arpack():
    beam = structural.cantilever(1.0, 300, **STEEL)  # 600 DOFs > DENSE_EIGEN_LIMIT
    step = structural.critical_dt(beam, "semi-implicit")
    # ARPACK converges to ~1e-14 on the extreme eigenvalue
    assert step.dt == pytest.approx(2 / dense_omega_max(beam), rel=1e-9)


def test_explicit_is_unstable_for_every_step(beam):
    assert structural.critical_dt(beam, "explicit").dt == 0.0


@pytest.mark.parametrize("scheme", ["implicit", "midpoint", "newmark"])
def test_unconditionally_stable_schemes_have_infinite_critical_step(beam, scheme):
    step = structural.critical_dt(beam, scheme)
    assert step.dt == math.inf and step.omega is None


@pytest.mark.parametrize(
    "beta, gamma, z", [(0.0, 0.5, 2.0), (1 / 12, 0.5, math.sqrt(6)), (0.25, 0.4, 0.0)]
)
def test_newmark_critical_step_follows_hughes(beam, beta, gamma, z):
    # Ω_crit = 1/sqrt(γ/2 − β): central difference 2, Fox–Goodwin √6; γ < ½ unstable
    step = structural.critical_dt(beam, structural.Newmark(beta=beta, gamma=gamma))
    assert step.dt == pytest.approx(z / dense_omega_max(beam), rel=1e-12)


def test_semi_implicit_stays_bounded_just_below_the_limit(beam):
    limit = structural.critical_dt(beam, "semi-implicit").dt
    run = structural.integrate(beam, "semi-implicit", 0.98 * limit, n_steps=4000)
    scale = structural.energy_scale(beam)
    assert run.success
    # modified energy is conserved; E itself wobbles by 2.5e-5 of the scale (measured)
    assert np.max(np.abs(run.energy - run.energy[0])) < 1e-3 * scale


def test_semi_implicit_blows_up_just_above_the_limit(beam):
    limit = structural.critical_dt(beam, "semi-implicit").dt
    run = structural.integrate(beam, "semi-implicit", 1.02 * limit, n_steps=4000)
    # |λ| = 1.49 per step for the highest mode: overflows after ~1800 steps
    assert run.status == Status.FAILED


def test_central_difference_newmark_blows_up_just_above_its_limit(beam):
    central = structural.Newmark(beta=0.0, gamma=0.5)
    limit = structural.critical_dt(beam, central).dt
    below = structural.integrate(beam, central, 0.98 * limit, n_steps=4000)
    above = structural.integrate(beam, central, 1.02 * limit, n_steps=4000)
    assert below.success and above.status == Status.FAILED


def test_coarse_frame_limit_is_set_by_an_axial_mode():
    frame = structural.cantilever(1.0, 10, axial=True, tip_load=1.0, **STEEL)
    step = structural.critical_dt(frame, "semi-implicit")
    assert step.mode == "axial"
    assert step.dt == pytest.approx(2 / dense_omega_max(frame), rel=1e-12)


def test_transverse_load_survives_above_an_axial_limit():
    frame = structural.cantilever(1.0, 10, axial=True, tip_load=1.0, **STEEL)
    limit = structural.critical_dt(frame, "semi-implicit").dt
    run = structural.integrate(frame, "semi-implicit", 1.05 * limit, n_steps=4000)
    # the axial DOFs are never loaded, so the unstable axial mode stays exactly zero
    assert run.success
    assert np.max(np.abs(run.energy)) < 1e-2 * structural.energy_scale(frame)


def test_bending_only_cantilever_limit_is_a_bending_mode():
    beam = structural.cantilever(1.0, 10, **STEEL)
    assert structural.critical_dt(beam, "semi-implicit").mode == "bending"


def test_sweep_marks_semi_implicit_stable_exactly_below_the_limit(beam):
    limit = structural.critical_dt(beam, "semi-implicit").dt
    factors = np.array([0.5, 0.9, 0.98, 1.02, 1.1, 2.0])
    sweep = structural.stability_sweep(beam, "semi-implicit", factors * limit, 3000)
    np.testing.assert_array_equal(sweep.stable, factors < 1)
    assert np.all(np.isinf(sweep.energy_growth[factors > 1]))


def test_sweep_finds_explicit_unstable_and_implicit_stable_everywhere(beam):
    dts = structural.critical_dt(beam, "semi-implicit").dt * np.array([0.1, 1.0, 100.0])
    explicit = structural.stability_sweep(beam, "explicit", dts, 1000)
    implicit = structural.stability_sweep(beam, "implicit", dts, 1000)
    assert not explicit.stable.any()
    assert implicit.stable.all()
    assert np.all(implicit.energy_growth <= 0)  # backward Euler never gains energy


def test_sweep_rejects_a_bad_step(beam):
    with pytest.raises(
        ValueError, match=r"dts\[1\]=0.0 is not allowed: must be finite and > 0 \(s\)"
    ):
        structural.stability_sweep(beam, "midpoint", [1e-5, 0.0], 10)


def test_sweep_needs_a_load_or_an_initial_state():
    beam = structural.cantilever(1.0, 4, **STEEL)  # no tip load
    with pytest.raises(ValueError, match="no load and no initial state"):
        structural.stability_sweep(beam, "midpoint", [1e-5], 10)


def test_critical_dt_rejects_unknown_scheme(beam):
    with pytest.raises(
        ValueError, match=r"scheme='leapfrog' is not allowed: must be one of .*'newmark'"
    ):
        structural.critical_dt(beam, "leapfrog")
