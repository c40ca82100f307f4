"""A structural run that blows up ends FAILED (issue 24, part 4): tumble.structural.divergence."""

import math

import numpy as np
import pytest

from tumble import structural
from tumble.ode import Status
from tumble.structural import divergence
from tumble.structural.schemes import resolve_scheme
from tumble.structural.stepping import BeamState

ALUMINIUM = {"E": 70e9, "rho": 2700.0, "width": 0.02, "height": 0.003}
STEEL = {"E": 210e9, "rho": 7850.0, "width": 0.01, "height": 0.01}
LINEAR_ACCELERATION = structural.Newmark(beta=1 / 6, gamma=0.5)


@pytest.fixture(scope="module")
def strip():
    """The issue's 10-element aluminium strip under a 1 N tip load."""
    return structural.cantilever(1.0, 10, tip_load=1.0, **ALUMINIUM)


@pytest.fixture(scope="module")
def beam():
    return structural.cantilever(1.0, 20, tip_load=1.0, **STEEL)


def mechanical_energy(system, run):
    """½ yᵀMy + ½ xᵀSx of every record, from the element strain energies."""
    return system.kinetic_energy(run.y) + system.strain_energy(run.x)


def bound(system, run):
    """(√V₀ + P t)², P = |f|_M⁻¹/√2, at every record (the module docstring's B)."""
    V0 = mechanical_energy(system, run)[0]
    return (math.sqrt(V0) + divergence.load_power(system) * run.t) ** 2


@pytest.mark.parametrize("compiled", [None, False], ids=["compiled", "reference"])
def test_newmark_far_beyond_its_critical_step_fails_naming_time_growth_and_cause(strip, compiled):
    # Before: status 0 and "The run reached the end of the interval." with the tip at 1e52 m.
    critical = structural.critical_dt(strip, LINEAR_ACCELERATION).dt
    dt = 62 * critical
    run = structural.integrate(strip, LINEAR_ACCELERATION, dt, n_steps=100, compiled=compiled)
    assert run.status == Status.FAILED
    assert run.t[-1] < 100 * dt and np.all(np.isfinite(run.x)) and np.all(np.isfinite(run.energy))
    message = run.message
    assert f"at t={64 * dt!r} s" in message  # the first check, after step 64
    assert "had grown" in message and "beyond what the initial state and the loads" in message
    assert f"dt = {dt:.3g} s is 62× the scheme's critical step {critical:.3g} s" in message
    assert "(Newmark β=1/6, γ=1/2;" in message and f"take dt below {critical:.3g} s" in message


def test_growth_in_the_message_is_the_energy_over_the_bound(strip):
    dt = 62 * structural.critical_dt(strip, LINEAR_ACCELERATION).dt
    run = structural.integrate(strip, LINEAR_ACCELERATION, dt, n_steps=100)
    growth = float(run.message.split(" had grown ")[1].split("×")[0])
    assert growth > divergence.GROWTH_LIMIT


def test_compiled_and_reference_loops_fail_at_the_same_step(strip):
    dt = 2 * structural.critical_dt(strip, "semi-implicit").dt
    runs = [structural.integrate(strip, "semi-implicit", dt, n_steps=300, compiled=flag)
            for flag in (None, False)]  # fmt: skip
    assert [run.solver for run in runs] == ["banded-cholesky", "sparse-lu"]
    assert all(run.status == Status.FAILED for run in runs)
    np.testing.assert_array_equal(runs[0].t, runs[1].t)
    assert runs[0].message == runs[1].message


def test_the_last_step_is_checked_too(strip):
    # At 1.01× the critical step the energy passes 1e6 × its bound near step 85: after the
    # check at step 64, before the run's last step, 100, which is checked as well.
    dt = 1.01 * structural.critical_dt(strip, LINEAR_ACCELERATION).dt
    run = structural.integrate(strip, LINEAR_ACCELERATION, dt, n_steps=100)
    assert run.status == Status.FAILED
    assert f"at t={100 * dt!r} s" in run.message
    assert "1.01× the scheme's critical step" in run.message


def test_the_explicit_scheme_is_told_it_is_unstable_at_every_step(beam):
    dt = 0.5 * structural.critical_dt(beam, "semi-implicit").dt
    run = structural.integrate(beam, "explicit", dt, n_steps=4000)
    assert run.status == Status.FAILED
    assert "the explicit scheme is unstable at every dt" in run.message


def test_a_state_that_overflows_between_checks_still_names_the_cause(beam):
    # explicit at 10⁴× the semi-implicit limit overflows within a few steps, before any check
    dt = 1e4 * structural.critical_dt(beam, "semi-implicit").dt
    run = structural.integrate(beam, "explicit", dt, n_steps=200)
    assert run.status == Status.FAILED
    assert "non-finite" in run.message or "energy stopped being finite" in run.message
    assert "likely cause: the explicit scheme is unstable at every dt" in run.message


UNCONDITIONAL = [name for name in structural.SCHEMES if name not in ("explicit", "semi-implicit")]


@pytest.mark.parametrize(
    "scheme",
    [*UNCONDITIONAL, structural.Newmark(0.3025, 0.6), structural.HHT(-1 / 3),
     structural.GeneralizedAlpha(0.0), structural.Bathe(0.5)],
    ids=str,
)  # fmt: skip
@pytest.mark.parametrize("steps_per_period", [2000, 200, 20, 0.3])
def test_long_stable_runs_never_fail_the_check(beam, scheme, steps_per_period):
    # A step load from rest with 2 % Rayleigh damping at modes 1 and 2: 5000 steps, up to
    # 3 fundamental periods a step (ωΔt up to 1e4 in the highest mode).
    omega = beam.natural_frequencies(2)
    dt = 2 * np.pi / omega[0] / steps_per_period
    damping = structural.RayleighDamping.from_damping_ratio(0.02, *omega)
    run = structural.integrate(beam, scheme, dt, n_steps=5000, damping=damping, record_every=7)
    assert run.status == Status.SUCCESS, run.message
    # From the first check on (step 64), what the check sees: measured at most 0.029 (from
    # rest the bound is loose); 1e6 is where the check fires. Before it a scheme may
    # overshoot: Wilson-θ's displacement after one step from a₀ grows as Ω² (module
    # tumble.structural.wilson), 2e8 B at step 1 and 2.1e5 at step 7 at 0.3 steps a period
    # (ωΔt up to 1e4), which ρ∞ = 0.78 a step takes to 7e-9 by step 64 (the others: 0.078
    # at most from step 7 on).
    checked = run.t >= divergence.CHECK_EVERY * dt * (1 - 1e-12)
    assert np.max(mechanical_energy(beam, run)[checked] / bound(beam, run)[checked]) < 10


@pytest.mark.parametrize(
    "scheme", [*UNCONDITIONAL, structural.Newmark(0.3025, 0.6), structural.HHT(-1 / 3)], ids=str
)
@pytest.mark.parametrize("start", ["x0", "y0"])
def test_energy_put_in_the_highest_mode_never_fails_the_check(scheme, start):
    # The worst start for the α family: their overshoot (ωΔt ≈ 5e3 here) lifts the energy
    # far above the bound for a few steps, and it has decayed by the first check, step 64.
    beam = structural.cantilever(1.0, 40, **STEEL)  # no load: B = V₀ for ever
    omega, shapes = beam.modes(beam.n_dofs)
    dt = 2 * np.pi / omega[0]
    run = structural.integrate(beam, scheme, dt, n_steps=3000, **{start: 1e-3 * shapes[:, -1]})
    assert run.status == Status.SUCCESS, run.message


def test_the_alpha_overshoot_really_passes_the_bound_before_the_first_check():
    # What the previous test relies on: HHT from a displacement in the highest mode reaches
    # far more than 1e6 V₀ within its first steps (Hilber–Hughes overshoot, ∝ (ωΔt)²), so a
    # check in those steps would call a stable run diverged.
    beam = structural.cantilever(1.0, 40, **STEEL)
    omega, shapes = beam.modes(beam.n_dofs)
    run = structural.integrate(beam, "hht", 2 * np.pi / omega[0], n_steps=64,
                               x0=1e-3 * shapes[:, -1])  # fmt: skip
    energy = mechanical_energy(beam, run)
    assert run.status == Status.SUCCESS
    assert energy[1:20].max() > divergence.GROWTH_LIMIT * energy[0]  # measured 1.4e10 V₀
    assert energy[-1] < 1e-2 * divergence.GROWTH_LIMIT * energy[0]  # 2.1e3 V₀ at step 64


@pytest.mark.parametrize("ratio", [0.5, 0.9, 0.99])
@pytest.mark.parametrize("scheme", ["semi-implicit", LINEAR_ACCELERATION], ids=str)
def test_conditionally_stable_schemes_below_their_limit_pass(strip, scheme, ratio):
    dt = ratio * structural.critical_dt(strip, scheme).dt
    x0 = strip.modes(strip.n_dofs)[1][:, -1] * 1e-3  # the mode that sets the limit, excited
    run = structural.integrate(strip, scheme, dt, n_steps=20_000, x0=x0, record_every=50)
    assert run.status == Status.SUCCESS, run.message


def test_the_exact_motion_stays_within_the_bound(beam):
    # The bound's derivation (module docstring) holds for the true motion: here the modal
    # superposition of a damped beam, started moving, under its step load.
    omega, shapes = beam.modes(4)
    x0, y0 = 2e-3 * shapes[:, 0], 0.5 * shapes[:, 1]
    damping = structural.RayleighDamping.from_damping_ratio(0.05, omega[0], omega[1])
    t = np.linspace(0.0, 3.0, 3001)
    motion = structural.exact_response(beam, t, x0=x0, y0=y0, damping=damping)
    V = beam.kinetic_energy(motion.y) + beam.strain_energy(motion.x)
    B = (math.sqrt(V[0]) + divergence.load_power(beam) * t) ** 2
    # round-off: V is summed from terms of its own size, 1e-12 relative is far above it
    assert np.all(V <= B * (1 + 1e-12))


def test_a_false_alarm_against_the_first_bound_computes_the_true_one(beam):
    state = BeamState.start(beam, np.zeros(beam.n_dofs), np.zeros(beam.n_dofs))
    watch = divergence.EnergyWatch.start(beam, state.x, state.y, state.q, lambda f: 0 * f)
    assert watch.power == 0.0 and not watch.exact  # a "solve" that gives P_A = 0
    t = 1e-3
    energy = 1e-3 * divergence.GROWTH_LIMIT * (divergence.load_power(beam) * t) ** 2
    assert watch.exceeds(t, energy)
    assert not watch.confirms(t, energy)
    assert watch.exact and watch.power == divergence.load_power(beam)


def test_checks_come_every_interval_and_at_the_last_step():
    beam = structural.cantilever(1.0, 2, **STEEL)
    watch = divergence.EnergyWatch(beam, 1.0, 0.0, True, every=64, final=100)
    assert [k for k in range(1, 201) if watch.checks(k)] == [64, 100, 128, 192]
    short = divergence.EnergyWatch(beam, 1.0, 0.0, True, every=64, final=30)
    assert not any(short.checks(k) for k in range(1, 31))  # before the first check: none


@pytest.mark.parametrize(
    ("scheme", "text"),
    [(structural.Newmark(1 / 6, 0.5), "Newmark β=1/6, γ=1/2"),
     (structural.Newmark(0.3025, 0.6), "Newmark β=0.3025, γ=3/5"),
     ("semi-implicit", "the semi-implicit scheme")],
)  # fmt: skip
def test_schemes_are_named_with_their_parameters(scheme, text):
    assert divergence.describe(resolve_scheme(scheme)) == text


def checked_ratios(scheme, omega: np.ndarray, xi: float, steps: int = 640) -> np.ndarray:
    """V/B at every check of the modes ``ẍ + 2ξΩẋ + Ω²x = f`` (Δt = 1, unit mass) stepped
    by the scheme's own amplification matrix (:func:`~tumble.structural.amplification`),
    each started from ``x``, from ``y`` and from rest under a unit step load; shape
    (checks, 3 len(omega))."""
    G = np.tile(structural.amplification(scheme, omega, xi).matrix, (3, 1, 1))
    k = np.tile(omega * omega, 3)
    x0, y0, f = (np.repeat(np.eye(3)[i], omega.size) for i in range(3))  # x, y, load
    a0 = f - k * x0 - 2 * xi * np.sqrt(k) * y0
    static = f / k
    z = np.stack([x0 - static, y0, a0], axis=1)[:, : G.shape[1]]  # about the static solution
    carries = resolve_scheme(scheme).carries_acceleration
    V0 = 0.5 * y0 * y0 + 0.5 * k * x0 * x0 + (0.5 * a0 * a0 if carries else 0.0)
    ratios = []
    for n in range(1, steps + 1):
        z = np.einsum("nij,nj->ni", G, z)
        if n % divergence.CHECK_EVERY == 0:
            x, y = z[:, 0] + static, z[:, 1]
            B = (np.sqrt(V0) + f / math.sqrt(2) * n) ** 2
            ratios.append((0.5 * y * y + 0.5 * k * x * x) / B)
    return np.array(ratios)


MODAL_SCHEMES = [*UNCONDITIONAL, structural.Newmark(0.3025, 0.6), structural.HHT(-1 / 3),
                 structural.GeneralizedAlpha(0.0), structural.Bathe(0.5), "semi-implicit",
                 structural.Newmark(0.0, 0.5), LINEAR_ACCELERATION]  # fmt: skip


@pytest.mark.parametrize("scheme", MODAL_SCHEMES, ids=str)
def test_no_stable_mode_of_any_scheme_reaches_the_limit(scheme):
    # Linear systems with Rayleigh damping decouple into such modes, and the system's B
    # bounds the sum of the modes' (Minkowski), so this is the check on any system, mode by
    # mode: Ω from 1e-2 to 1e6 (up to 0.999 of a critical Ω), ξ from 0 to 0.99, three starts.
    scheme = resolve_scheme(scheme)
    limit = structural.amplification(scheme, [1.0]).critical_omega
    omegas = np.logspace(-2, 6, 33)
    if math.isfinite(limit):
        omegas = np.append(omegas[omegas < 0.9 * limit], limit * np.array([0.9, 0.99, 0.999]))
    worst = max(checked_ratios(scheme, omegas, xi).max() for xi in (0.0, 0.05, 0.5, 0.99))
    # measured: at most 1.0 for the unconditionally stable schemes; at 0.999 of their limit
    # 993 for the semi-implicit scheme, 497 for central difference and linear acceleration
    # (their modified energy: (1 + z/2)/(1 − z/2) for the semi-implicit scheme)
    assert worst < 1e-2 * divergence.GROWTH_LIMIT
