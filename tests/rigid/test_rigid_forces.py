"""Loads: exact momentum changes, the parabola, torques, events; the gravity gradient."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from rigid_roundoff import assert_kernel_matches, kernel_bound
from roundoff import error_bound
from scipy.integrate import solve_ivp
from strategies import FINITE, bodies, rotation_matrices, unit_vectors

from tumble import exact, so3
from tumble.rigid import (
    METHODS,
    Force,
    Gravity,
    GravityGradient,
    Impulse,
    MagneticDipole,
    RigidBody,
    State,
    Torque,
    simulate,
    simulate_batch,
)

BODY = RigidBody(2.0, [1.0, 2.0, 2.5])


def test_impulse_changes_velocity_by_j_over_m_exactly():
    J, point = np.array([0.3, -0.2, 1.0]), np.array([0.5, 0.1, -0.2])
    run = simulate(BODY, 1.0, h=0.1, forces=[Impulse(point, J, time=0.0)])
    # J / m and r × J (a b − c d) from zero, with no torque after: the same IEEE operations
    # here and in the kernel, so the same bits on any machine
    np.testing.assert_array_equal(run.v[0], J / BODY.mass)
    np.testing.assert_array_equal(run.L_world[-1], np.cross(point, J))


def test_impulse_mid_run_lands_a_step_on_its_time():
    J = np.array([1.0, 0.0, 0.0])
    run = simulate(BODY, 1.0, h=0.1, x0=(0, 0, 0), forces=[Impulse((0, 1, 0), J, time=0.35)])
    assert 0.35 in run.t
    before = run.t < 0.35
    np.testing.assert_array_equal(run.v[before], 0.0)
    np.testing.assert_allclose(run.v[~before], np.broadcast_to(J / BODY.mass, (8, 3)), atol=0)
    np.testing.assert_allclose(run.L_world[-1], np.cross([0, 1, 0], J), atol=0)


def test_impulse_arm_is_measured_from_the_current_centre_of_mass():
    J = np.array([0.0, 0.0, 1.0])
    run = simulate(BODY, 2.0, h=0.1, v0=(1, 0, 0), forces=[Impulse((1.0, 1.0, 0.0), J, time=1.0)])
    # At t = 1 the centre of mass is at (1, 0, 0): the arm is (0, 1, 0), up to x's ten steps
    # of two roundings at |x| ≤ 1 and the arm's own.
    np.testing.assert_allclose(run.L_world[-1], np.cross([0.0, 1.0, 0.0], J),
                               atol=error_bound(1.0, 22))  # fmt: skip


@pytest.mark.parametrize("method", ["rkmk4", "rk4-quat", "euler"])
def test_gravity_centre_of_mass_follows_the_parabola(method):
    g = np.array([0.0, 0.0, -9.81])
    x0, v0 = np.array([1.0, 2.0, 3.0]), np.array([3.0, 0.0, 4.0])
    run = simulate(BODY, 2.0, method=method, h=0.01, x0=x0, v0=v0, forces=[Gravity(g)])
    expected = x0 + np.outer(run.t, v0) + 0.5 * np.outer(run.t**2, g)
    # Euler's position lags by h/2 · g t (first order); RK4 is exact for a parabola.
    tol = 0.1 if method == "euler" else 1e-11
    np.testing.assert_allclose(run.x, expected, atol=tol)


def test_constant_torque_grows_angular_momentum_linearly():
    tau = np.array([0.1, -0.2, 0.3])
    run = simulate(BODY, 1.0, h=0.01, L0=(1, 0, 0), forces=[Torque(tau)])
    # L += h τ: 100 steps of two roundings at |L| ≤ 1.1, and t τ + L0's own two
    bound = error_bound(1.1, 2 * 100) + error_bound(1.1, 2)
    np.testing.assert_allclose(run.L_world, [1, 0, 0] + np.outer(run.t, tau), atol=bound)


def test_force_at_a_body_point_gives_torque_r_cross_f():
    F, point = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0])
    run = simulate(BODY, 1e-3, h=1e-3, forces=[Force(F, point=point)])
    # Over one tiny step from rest, ΔL ≈ (R r × F) h with R = I.
    np.testing.assert_allclose(run.L_world[-1] / 1e-3, np.cross(point, F), rtol=1e-6)
    np.testing.assert_allclose(run.v[-1] * BODY.mass / 1e-3, F, rtol=1e-12)


def test_terminal_event_finds_the_ground():
    def ground(t, state):
        return state.x[2]

    ground.terminal, ground.direction = True, -1
    run = simulate(BODY, 10.0, h=0.05, x0=(0, 0, 10), forces=[Gravity()], events=[ground])
    assert run.status == 1
    assert run.t[-1] == pytest.approx(np.sqrt(2 * 10 / 9.81), abs=1e-9)
    assert run.t_events[0][0] == pytest.approx(np.sqrt(2 * 10 / 9.81), abs=1e-9)
    assert run.x[-1, 2] == pytest.approx(0.0, abs=1e-9)


def test_nan_from_a_user_force_stops_with_the_time():
    def force(t, state):
        return (np.nan, 0.0, 0.0) if t >= 0.5 else (1.0, 0.0, 0.0)

    run = simulate(BODY, 1.0, h=0.1, forces=[Force(force)])
    assert run.status == -1 and not run.success
    assert "non-finite" in run.message and "t=0.5" in run.message
    assert np.all(np.isfinite(run.x))
    assert run.t[-1] == pytest.approx(0.4)


def test_exceptions_from_a_user_force_come_through_unchanged():
    def force(t, state):
        raise KeyError("user bug")

    with pytest.raises(KeyError, match="user bug"):
        simulate(BODY, 1.0, h=0.1, forces=[Force(force)])


# GravityGradient: the point mass's force, torque and potential, against its own potential,
# an independent integration, the NumPy reference and the batch, and over a million steps.

FIXED = [name for name, method in METHODS.items() if not method.adaptive and not method.exact]
"""The fixed-step methods that take loads."""
ORBITER = RigidBody(1.0, [[0.15, 0.01, 0.0], [0.01, 0.2, 0.02], [0.0, 0.02, 0.3]])
"""A body whose size is not small beside its distance (I/(m r²) ≈ 0.05 at r = 2): the force's
gradient term and the torque both matter."""
ORBIT = {"x0": (2.0, 0.0, 0.0), "v0": (0.0, 0.75, 0.1), "omega0": (0.3, 0.1, -0.2)}
"""An inclined, slightly eccentric orbit about μ = 1 at the origin (period ≈ 18), tumbling."""
POINT_MASS = GravityGradient(mu=1.0)


@given(
    rotation_matrices(),
    unit_vectors(),
    st.floats(1.5, 10.0, **FINITE),
    bodies(),
    st.floats(0.1, 10.0, **FINITE),
)
def test_gravity_gradient_force_and_torque_are_the_gradient_of_its_potential(
    R, direction, distance, box, body_mass
):
    # The complex step, Im V(y + i s δ)/s with s = 1e-30, is V's derivative along δ to
    # round-off (no difference of two V's), so τ·e = −dV/dε along R → exp(ε ê) R, whose
    # first order is δR = ê R, and F·e = −∂V/∂x·e, to the round-off of the two formulas.
    load = GravityGradient(mu=1.0, centre=(0.3, -0.2, 0.1), inertia=box.inertia)
    x = load.centre + distance * direction
    F, tau = load(0.0, State(x, R, np.zeros(3), np.zeros(3)), body_mass)
    step = 1e-30
    for e in np.eye(3):
        turned = load.potential(x[None], (R + 1j * step * so3.hat(e) @ R)[None], body_mass)
        moved = load.potential((x + 1j * step * e)[None], R[None], body_mass)
        # terms: μ/r³ times |I| (the torque), μ m/r² and μ|I|/r⁴ (the force), a few each
        size = np.abs(box.inertia).max()
        torque_terms = 9.0 * size / distance**3
        force_terms = body_mass / distance**2 + 30.0 * size / distance**4
        assert abs(-turned.imag[0] / step - e @ tau) <= error_bound(torque_terms, 60)
        assert abs(-moved.imag[0] / step - e @ F) <= error_bound(force_terms, 60)


def dop853_orbiter(t_end: float) -> dict[str, np.ndarray]:
    """The orbiter written out for scipy: ``ẋ = v``, ``m v̇ = F``, ``Ṙ = R ω̂``,
    ``I ω̇ = I ω × ω + Rᵀ τ`` with F and τ of the point mass (μ = 1, the origin), body-frame
    ``s = Rᵀ x``: ``Rᵀ τ = 3μ/r⁵ s × I s``; DOP853 at rtol = atol = 1e-12."""
    inertia, m = ORBITER.inertia, ORBITER.mass

    def rates(t, y):
        x, v, R, w = y[:3], y[3:6], y[6:15].reshape(3, 3), y[15:]
        r2 = x @ x
        r = np.sqrt(r2)
        s = R.T @ x
        Is = inertia @ s
        torque = 3.0 / r**5 * np.cross(s, Is)
        F = -m * x / r**3 - 3.0 / r**5 * ((0.5 * np.trace(inertia) - 2.5 * (s @ Is) / r2) * x
                                          + R @ Is)  # fmt: skip
        w_dot = np.linalg.solve(inertia, np.cross(inertia @ w, w) + torque)
        return np.concatenate([v, F / m, (R @ so3.hat(w)).ravel(), w_dot])

    y0 = np.concatenate([ORBIT["x0"], ORBIT["v0"], np.eye(3).ravel(), ORBIT["omega0"]])
    end = solve_ivp(rates, (0.0, t_end), y0, method="DOP853", rtol=1e-12, atol=1e-12).y[:, -1]
    return {"x": end[:3], "R": end[6:15].reshape(3, 3), "omega": end[15:]}


STEP_COUNTS = {1: [200, 400, 800, 1600], 2: [50, 100, 200, 400], 3: [25, 50, 100, 200],
               4: [25, 50, 100, 200], 8: [5, 6, 8, 10]}  # fmt: skip
"""Steps over the 5 s run by declared order: errors between 1e-10 and 3e-2 (measured)."""


@pytest.mark.parametrize("method", FIXED)
def test_gravity_gradient_runs_converge_to_an_independent_integration_at_their_order(method):
    # The reference agrees with itself at rtol 1e-13 to 9e-13: errors above 1e-10 are the
    # method's. Measured slopes 0.99–1.00, 2.00, 3.00, 3.97–4.07 and 8.06.
    reference = dop853_orbiter(5.0)
    order = METHODS[method].order
    steps = 5.0 / np.array(STEP_COUNTS[order])
    errors = []
    for h in steps:
        run = simulate(ORBITER, 5.0, method=method, h=h, forces=[POINT_MASS], **ORBIT)
        attitude = np.linalg.norm(run.R[-1] - reference["R"])
        position = np.linalg.norm(run.x[-1] - reference["x"]) / 2.0  # over |x|
        rate = np.linalg.norm(run.omega_body[-1] - reference["omega"]) / 0.4  # over |ω|
        errors.append(max(attitude, position, rate))
    fit = exact.fit_order(steps, errors, window=(1e-10, 0.1))
    assert fit is not None and fit.points == 4, errors
    assert abs(fit.order - order) < 0.2, f"{method}: measured {fit.order:.3f}, claimed {order}"


ORBIT_CONDITION = 9.0
"""The orbiter's condition over 5 s (rigid_roundoff): measured 7.6."""


@pytest.mark.parametrize("method", FIXED)
def test_gravity_gradient_kernel_matches_the_numpy_reference(method):
    forces = [POINT_MASS, MagneticDipole((0.2, -0.1, 0.3), (0.0, 0.5, 0.4))]
    options = dict(method=method, h=0.01, forces=forces, record_every=5, **ORBIT)
    reference = simulate(ORBITER, 5.0, compiled=False, **options)
    kernel = simulate(ORBITER, 5.0, compiled=True, **options)
    assert kernel.settings["compiled"] and not reference.settings["compiled"]
    assert_kernel_matches(kernel, reference, method, ("R", "x", "v", "L_world"), ORBIT_CONDITION)


@pytest.mark.parametrize("method", [name for name, m in METHODS.items() if m.adaptive])
def test_gravity_gradient_adaptive_kernel_ends_where_the_reference_does(method):
    options = dict(method=method, rtol=1e-9, forces=[POINT_MASS], **ORBIT)
    reference = simulate(ORBITER, 5.0, compiled=False, **options)
    kernel = simulate(ORBITER, 5.0, compiled=True, **options)
    assert kernel.settings["compiled"] and not reference.settings["compiled"]
    assert (kernel.n_steps, kernel.n_rejected) == (reference.n_steps, reference.n_rejected)
    # The steps between differ by up to 4e-5 of h (measured): the estimate of x's error,
    # h Σ eᵢ pᵢ/m over stages that differ little, cancels to ~1e-4 of its terms' round-off,
    # so the two norms, and the steps they propose, differ there. Both runs follow the same
    # solution: at t_end (both land on it) they agree to the round-off of their steps.
    steps = reference.n_steps
    for name in ("R", "x", "L_world"):
        end = getattr(reference, name)[-1]
        bound = kernel_bound(method, steps, 3 * np.abs(end).max(), ORBIT_CONDITION)
        np.testing.assert_allclose(getattr(kernel, name)[-1], end, rtol=0, atol=bound,
                                   err_msg=name)  # fmt: skip


@pytest.mark.parametrize("method", FIXED)
@pytest.mark.parametrize("n_bodies", [3, 40], ids=["a-body-a-thread", "columns"])
def test_a_batch_under_gravity_gradient_has_the_single_runs_numbers(method, n_bodies):
    rng = np.random.default_rng(11)
    x0 = np.asarray(ORBIT["x0"]) + 0.1 * rng.normal(size=(n_bodies, 3))
    v0 = np.asarray(ORBIT["v0"]) + 0.01 * rng.normal(size=(n_bodies, 3))
    omega0, R0 = 0.3 * rng.normal(size=(n_bodies, 3)), so3.exp(rng.normal(size=(n_bodies, 3)))
    bodies_ = [ORBITER, RigidBody(2.0, [0.1, 0.2, 0.25])] * (n_bodies // 2) + [ORBITER] * (
        n_bodies % 2
    )
    options = dict(method=method, h=0.05, forces=[POINT_MASS])
    batch = simulate_batch(bodies_, 1.0, x0=x0, v0=v0, omega0=omega0, R0=R0, **options)
    for k in (0, 1, n_bodies - 1):  # both bodies, and the last column
        single = simulate(bodies_[k], 1.0, x0=x0[k], v0=v0[k], omega0=omega0[k], R0=R0[k],
                          **options)  # fmt: skip
        for name in ("x", "v", "R", "L_world", "energy"):
            np.testing.assert_array_equal(getattr(batch[k], name), getattr(single, name), name)


def test_trajectory_energy_includes_the_gravity_gradient_potential():
    run = simulate(ORBITER, 2.0, h=0.01, forces=[POINT_MASS], **ORBIT)
    bound = GravityGradient(mu=1.0, inertia=ORBITER.inertia)
    np.testing.assert_array_equal(run.potential_energy,
                                  bound.potential(run.x, run.R, ORBITER.mass))  # fmt: skip
    np.testing.assert_array_equal(run.energy, run.kinetic_energy + run.potential_energy)


LIBRATING = RigidBody(1.0, 0.01 * np.array(ORBITER.inertia))
"""The orbiter a hundred times lighter in inertia: the orbit stays circular to 0.4 % and the
attitude librates about the gravity-gradient equilibrium (least axis along the radius,
greatest along the orbit normal), a regular motion."""
LONG_STEPS = 1_000_000


def librating(method: str):
    """10⁶ steps of h = 0.05 (2800 orbits) on a circular orbit of radius 2 about μ = 1, the
    body turning once an orbit plus a libration; every 100th step recorded."""
    rate = np.sqrt(1.0 / 8.0)
    return simulate(LIBRATING, LONG_STEPS * 0.05, method=method, h=0.05, x0=(2.0, 0.0, 0.0),
                    v0=(0.0, np.sqrt(0.5), 0.0), omega0=(0.02, 0.03, rate + 0.05),
                    forces=[POINT_MASS], record_every=100)  # fmt: skip


def tenths(run) -> tuple[float, float]:
    """Largest |E − E₀| over the first and over the last tenth of the run."""
    error, n = np.abs(run.energy_error), len(run.t) // 10
    return float(error[1:n].max()), float(error[-n:].max())


@pytest.mark.parametrize("method", ["strang", "yoshida4", "split-axes"])
def test_total_energy_under_gravity_gradient_stays_bounded_for_a_million_steps(method):
    run = librating(method)
    first, last = tenths(run)
    assert run.n_steps == LONG_STEPS
    assert last <= 2.0 * first, f"{first:.2e} then {last:.2e}"  # measured ratio 1.01
    # |T + V − E₀| below 1 % of the rotational energy exchanged (measured 0.05 % for the
    # order-2 methods, 4e-5 % for yoshida4)
    body_L = np.einsum("nji,nj->ni", run.R, run.L_world)
    rotational = 0.5 * np.einsum("ni,ni->n", run.omega_body, body_L)
    assert np.abs(run.energy_error).max() < 1e-2 * np.ptp(rotational)


def test_runge_kutta_drifts_under_gravity_gradient_where_the_splittings_do_not():
    first, last = tenths(librating("rkmk4"))
    assert last > 4.0 * first  # measured 10: a linear drift


def test_gravity_gradient_takes_the_body_inertia_and_refuses_another():
    load = GravityGradient(mu=1.0)
    with pytest.raises(ValueError, match=r"^GravityGradient.inertia=None .*body.inertia"):
        load(0.0, State(np.ones(3), np.eye(3), np.zeros(3), np.zeros(3)), 1.0)
    with pytest.raises(ValueError, match=r"^GravityGradient.inertia=.* must be None or the"):
        simulate(ORBITER, 0.1, h=0.01, forces=[GravityGradient(mu=1.0, inertia=[1.0, 2.0, 2.5])],
                 **ORBIT)  # fmt: skip
    run = simulate(ORBITER, 0.1, h=0.01, forces=[GravityGradient(1.0, inertia=ORBITER.inertia)],
                   **ORBIT)  # fmt: skip
    assert run.settings["compiled"]


@pytest.mark.parametrize(
    "kwargs, name",
    [({"mu": 0.0}, "mu"), ({"mu": np.inf}, "mu"), ({"centre": (0.0, np.nan, 0.0)}, "centre"),
     ({"inertia": [[1.0, 2.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]}, "inertia")],
)  # fmt: skip
def test_a_bad_gravity_gradient_is_refused_naming_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=rf"^{name}(\[\d\])?=.* is not allowed: must be"):
        GravityGradient(**kwargs)


def test_gravity_gradient_with_a_pivot_is_refused():
    with pytest.raises(ValueError, match=r"^forces\[0\]=.*other than GravityGradient"):
        simulate(ORBITER, 0.1, h=0.01, pivot=(0.0, 0.0, -0.1), forces=[POINT_MASS])
