"""Time stepping: energy behaviour of each scheme, order, Newmark, damping, the driver."""

import numpy as np
import pytest
from roundoff import error_bound

from tumble import structural
from tumble.ode import Status

STEEL = {"E": 210e9, "rho": 7850.0, "width": 0.01, "height": 0.01}
LOAD = 1.0  # N
EI = 210e9 * 0.01**4 / 12
STATIC_TIP = LOAD * 1.0**3 / (3 * EI)  # F L³/(3EI) [m]
STEPS = 2000


@pytest.fixture(scope="module")
def beam():
    return structural.cantilever(1.0, 20, tip_load=LOAD, **STEEL)


@pytest.fixture(scope="module")
def dt(beam):
    return 2 * np.pi / beam.natural_frequencies(1)[0] / 200  # T₁/200


@pytest.fixture(scope="module")
def scale(beam):
    return structural.energy_scale(beam)  # ½ F δ_static: the strain-energy scale


@pytest.fixture(scope="module")
def runs(beam, dt):
    return {s: structural.integrate(beam, s, dt, n_steps=STEPS) for s in structural.SCHEMES}


def energy_roundoff(beam, run) -> np.ndarray:
    """How far two consecutive energies may be off by round-off: each is a sum of its
    kinetic, strain and load terms (E = 0 from rest: they cancel) in chains of at most
    n_dofs + 8 roundings (the sums over DOFs, M y, the element factor's squares)."""
    terms = (
        beam.kinetic_energy(run.y) + beam.strain_energy(run.x) + np.abs(run.x @ beam.f)
    )  # fmt: skip
    each = error_bound(terms, beam.n_dofs + 8)
    return each[1:] + each[:-1]


def test_energy_scale_is_half_load_times_static_deflection(scale):
    np.testing.assert_allclose(scale, 0.5 * LOAD * STATIC_TIP, rtol=1e-10)


def test_midpoint_keeps_energy_to_1e_9_of_the_strain_energy_scale(runs, scale):
    energy = runs["midpoint"].energy
    assert runs["midpoint"].success
    # the scheme conserves E exactly; 2000 steps of round-off measured 1.7e-14
    assert np.max(np.abs(energy - energy[0])) < 1e-9 * scale


def test_implicit_energy_falls_monotonically(runs, scale):
    energy = runs["implicit"].energy
    # each step loses ½ΔyᵀMΔy + ½ΔxᵀSΔx ≥ 1.3e-4 scale here; round-off is 1e-14
    assert np.all(np.diff(energy) < 0)
    assert energy[-1] < energy[0] - 0.5 * scale  # after 10 periods most of it is gone


def test_explicit_energy_grows_until_the_run_diverges(runs):
    run = runs["explicit"]
    assert run.status == Status.FAILED
    finite = run.energy[np.isfinite(run.energy)]
    assert np.all(np.diff(finite) > 0)
    assert finite[-1] > 1e100 * abs(finite[1])


def test_explicit_energy_grows_at_every_step_even_below_the_semi_implicit_limit(beam, scale):
    limit = structural.critical_dt(beam, "semi-implicit").dt
    run = structural.integrate(beam, "explicit", 0.05 * limit, n_steps=400)
    # E gains ½ΔyᵀMΔy + ½ΔxᵀSΔx ≥ 0 per step: never falls by more than round-off
    assert np.all(np.diff(run.energy) > -energy_roundoff(beam, run))
    assert run.energy[-1] > run.energy[0]


def test_newmark_average_acceleration_equals_midpoint(runs):
    midpoint, newmark = runs["midpoint"], runs["newmark"]
    # algebraically the same map; written with different rounding (measured 1e-14)
    np.testing.assert_allclose(newmark.x, midpoint.x, rtol=0, atol=1e-8 * np.abs(midpoint.x).max())
    np.testing.assert_allclose(newmark.y, midpoint.y, rtol=0, atol=1e-8 * np.abs(midpoint.y).max())


def test_tip_oscillates_about_the_static_deflection(runs):
    tip = runs["midpoint"].tip_displacement
    # 2000 steps = 10 periods of mode 1; higher modes shift the mean by 4e-4 (measured)
    assert abs(tip.mean() / STATIC_TIP - 1) < 2e-3


def test_tip_peaks_near_twice_the_static_deflection(runs):
    tip = runs["midpoint"].tip_displacement
    # a step load on an undamped oscillator peaks at 2δ; modes 2+ are out of phase: 1.995
    assert abs(tip.max() / STATIC_TIP - 2) < 1e-2
    assert tip.min() > -1e-2 * STATIC_TIP  # it never swings back past the start


def test_newmark_with_acceleration_term_is_second_order_only_at_gamma_half():
    beam = structural.cantilever(1.0, 1, **STEEL)
    omega, shapes = beam.modes(1)
    x0 = shapes[:, 0] * 1e-3 / shapes[beam.tip_dof, 0]
    t_end = 0.3 * 2 * np.pi / omega[0]
    slopes = {}
    for gamma in (0.5, 0.6):
        scheme = structural.Newmark(beta=0.3025, gamma=gamma)
        errors = [
            np.abs(
                structural.integrate(beam, scheme, t_end / n, n_steps=n, x0=x0, record_every=n).x[
                    -1
                ]
                - x0 * np.cos(omega[0] * t_end)
            ).max()
            for n in (60, 120, 240)
        ]
        slopes[gamma] = np.polyfit(np.log([1, 0.5, 0.25]), np.log(errors), 1)[0]
    # Hughes §9.1: second order iff γ = ½
    assert abs(slopes[0.5] - 2) < 0.2 and abs(slopes[0.6] - 1) < 0.2, slopes


def test_rayleigh_damping_makes_midpoint_energy_fall(beam, dt, scale):
    damping = structural.RayleighDamping.from_damping_ratio(0.02, 50.0, 2000.0)
    run = structural.integrate(beam, "midpoint", dt, n_steps=500, damping=damping)
    # midpoint dissipates exactly Δt ȳᵀ C ȳ ≥ 0 per step
    assert np.all(np.diff(run.energy) < energy_roundoff(beam, run))
    assert run.energy[-1] < -0.1 * scale


def test_newmark_equals_midpoint_with_damping(beam, dt):
    damping = structural.RayleighDamping(mass_coefficient=2.0, stiffness_coefficient=1e-5)
    a = structural.integrate(beam, "midpoint", dt, n_steps=300, damping=damping)
    b = structural.integrate(beam, "newmark", dt, n_steps=300, damping=damping)
    np.testing.assert_allclose(b.x, a.x, rtol=0, atol=1e-8 * np.abs(a.x).max())


def test_step_increments_stay_accurate_on_a_very_fine_mesh(dt):
    coarse = structural.cantilever(1.0, 100, tip_load=LOAD, **STEEL)
    with pytest.warns(structural.IllConditionedWarning):
        fine = structural.cantilever(1.0, 10_000, tip_load=LOAD, **STEEL)
    reference = structural.integrate(coarse, "midpoint", dt, n_steps=150).tip_displacement
    tip = structural.integrate(fine, "midpoint", dt, n_steps=150, record_every=5)
    # The plain seed form drifts by 190 % here. Increments with element forces stay within
    # the fine mesh's round-off, amplified by its conditioning: a change of dt by one ulp
    # moves the deviation by as much as its size, 1.3e-5 … 3.8e-4 over dt ± 8 ulps (the
    # banded Cholesky from the tip, on an AMD EPYC; the CPU picks another sample of the same
    # spread). Bound at 5x the largest. The direction of elimination is checked by
    # test_banded_cholesky_eliminates_a_cantilever_from_its_free_tip.
    deviation = np.abs(tip.tip_displacement - reference[np.rint(tip.t / dt).astype(int)]).max()
    assert deviation < 2e-3 * STATIC_TIP


def test_record_every_keeps_the_last_step(beam, dt):
    run = structural.integrate(beam, "implicit", dt, n_steps=25, record_every=10)
    np.testing.assert_allclose(run.t, np.array([0, 10, 20, 25]) * dt)
    full = structural.integrate(beam, "implicit", dt, n_steps=25)
    np.testing.assert_array_equal(run.x, full.x[[0, 10, 20, 25]])


def test_t_end_gives_the_number_of_steps(beam, dt):
    run = structural.integrate(beam, "midpoint", dt, t_end=10 * dt)
    assert run.x.shape == (11, beam.n_dofs)


def test_initial_state_is_taken_from_x0_and_y0(beam, dt):
    x0 = beam.static_displacement()
    run = structural.integrate(beam, "midpoint", dt, n_steps=50, x0=x0)
    # started in static equilibrium at rest: nothing moves
    np.testing.assert_allclose(run.x, np.broadcast_to(x0, run.x.shape), atol=1e-12 * STATIC_TIP)


def test_divergence_is_a_status_with_the_time(beam, dt):
    run = structural.integrate(beam, "semi-implicit", dt, n_steps=STEPS)
    assert not run.success
    # the energy overflows (at |x| ≈ 1e150) before the state does: that ends the records
    assert "energy stopped being finite" in run.message
    assert f"t={float(run.t[-1])!r}" in run.message
    assert run.t[-1] < STEPS * dt
    assert np.all(np.isfinite(run.x[-1])) and np.all(np.isfinite(run.energy))


def test_progress_bar_does_not_change_the_result(beam, dt):
    shown = structural.integrate(beam, "midpoint", dt, n_steps=30, progress=True)
    np.testing.assert_array_equal(
        shown.x, structural.integrate(beam, "midpoint", dt, n_steps=30).x
    )


@pytest.mark.parametrize("dt", [0.0, -1e-3, np.nan, np.inf, "1e-3"])
def test_integrate_rejects_bad_time_steps(beam, dt):
    with pytest.raises(ValueError, match=r"dt=.* is not allowed: must be finite and > 0 \(s\)"):
        structural.integrate(beam, "midpoint", dt, n_steps=1)


def test_integrate_rejects_unknown_scheme_and_lists_the_schemes(beam):
    with pytest.raises(
        ValueError,
        match=r"scheme='rk4' is not allowed: must be one of 'explicit', 'semi-implicit', "
        r"'implicit', 'midpoint', 'newmark'",
    ):
        structural.integrate(beam, "rk4", 1e-4, n_steps=1)


@pytest.mark.parametrize("steps", [{}, {"n_steps": 5, "t_end": 1.0}])
def test_integrate_needs_exactly_one_of_n_steps_and_t_end(beam, steps):
    with pytest.raises(ValueError, match="exactly one of n_steps and t_end"):
        structural.integrate(beam, "midpoint", 1e-4, **steps)


def test_integrate_rejects_wrong_initial_shape(beam):
    with pytest.raises(ValueError, match=r"x0=.* is not allowed: must be of shape \(40,\)"):
        structural.integrate(beam, "midpoint", 1e-4, n_steps=1, x0=np.zeros(3))


@pytest.mark.parametrize("beta, gamma, name", [(-0.1, 0.5, "beta"), (0.25, 0.0, "gamma")])
def test_newmark_rejects_bad_parameters(beta, gamma, name):
    with pytest.raises(ValueError, match=rf"{name}=.* is not allowed: must be finite"):
        structural.Newmark(beta=beta, gamma=gamma)


def test_rayleigh_damping_from_ratio_hits_the_ratio_at_both_frequencies():
    damping = structural.RayleighDamping.from_damping_ratio(0.03, 40.0, 900.0)
    for omega in (40.0, 900.0):
        # ζ(ω) = α/(2ω) + βω/2 for C = αM + βS
        ratio = damping.mass_coefficient / (2 * omega) + damping.stiffness_coefficient * omega / 2
        assert ratio == pytest.approx(0.03, rel=1e-12)


def test_rayleigh_damping_rejects_negative_coefficients():
    with pytest.raises(
        ValueError, match=r"mass_coefficient=-1.0 is not allowed: must be finite and >= 0"
    ):
        structural.RayleighDamping(mass_coefficient=-1.0)


def test_a_run_whose_energy_overflows_is_reported_as_failed(monkeypatch):
    # Issue 18: an explicit run past its step limit ended with the state at 1e180, finite,
    # its energy NaN, and status 0. It now ends with the last record of finite energy.
    # (Issue 24's energy check stops this run at step 64, a step before the overflow; with
    # the check off, the records still end before the energy overflows.)
    import warnings

    from tumble.structural import divergence

    monkeypatch.setattr(divergence, "CHECK_EVERY", 10**9)
    beam = structural.cantilever(1.0, 20, 210e9, 7850.0, 0.01, 0.01, 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # and no numpy warning on the way
        run = structural.integrate(beam, "explicit", 6e-4, n_steps=80)
    assert run.status == -1
    assert "energy stopped being finite" in run.message and "t=" in run.message
    assert np.all(np.isfinite(run.energy)) and np.all(np.isfinite(run.x))
    assert len(run.t) == len(run.x) == len(run.energy) < 81
