"""Tests for tumble.exact: the exact references against tight numerical solutions and closed forms.

Numerical references use scipy's DOP853 at rtol = atol = 1e-13; over a few periods of these
well-conditioned motions it is good to about 1e-11, so 1e-8 (ω) and 1e-9 (R) leave a wide
margin while still catching any wrong sign, phase, amplitude or rate (those give O(1) errors).
"""

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.special import ellipj, ellipk

from tumble.exact import (
    fit_order,
    free_body,
    free_body_period,
    free_body_rotation,
    measure_order,
    observed_order,
    projectile,
    sphere,
    study,
)

T_HANDLE = np.array([9.82271303e-05, 7.22671030e-05, 1.57865031e-04])  # SPEC §4, kg m^2
HAIRER = np.array([2.0, 1.0, 2.0 / 3.0])  # Hairer–Lubich–Wanner's test body
HAIRER_OMEGA = np.array([math.cos(1.1), 0.0, math.sin(1.1)]) / HAIRER  # ω0 = I⁻¹ L0


def _rotated_tensor() -> np.ndarray:
    """diag(1, 2, 3) seen in body axes rotated by a fixed proper rotation."""
    q, _ = np.linalg.qr(np.random.default_rng(7).normal(size=(3, 3)))
    q = q * np.sign(np.linalg.det(q))
    return q @ np.diag([1.0, 2.0, 3.0]) @ q.T


CASES = {
    "t-handle-middle-axis": (T_HANDLE, [1.0, 0.05, 0.0]),
    "t-handle-smallest-axis": (T_HANDLE, [0.0, 1.0, 0.05]),
    "t-handle-largest-axis": (T_HANDLE, [0.05, 0.0, 1.0]),
    "hairer-body": (HAIRER, HAIRER_OMEGA),
    "unsorted-near-smallest": ([3.0, 1.0, 2.0], [0.3, -0.7, 1.1]),
    "unsorted-near-largest": ([3.0, 1.0, 2.0], [-1.0, 0.2, -0.4]),
    "unsorted-near-separatrix": ([3.0, 1.0, 2.0], [0.2, -0.3, -1.0]),
    "close-to-separatrix": ([1.0, 2.0, 3.0], [math.sqrt(3.0) * (1 + 1e-4), 0.1, 1.0]),
    "full-tensor": (_rotated_tensor(), [0.3, -0.5, 0.9]),
    "symmetric-prolate": ([2.0, 2.0, 1.0], [0.3, 0.4, 1.0]),
    "symmetric-oblate": ([1.0, 2.0, 2.0], [0.3, 0.4, -1.0]),
}
IDS = list(CASES)


def _tensor(inertia) -> np.ndarray:
    inertia = np.asarray(inertia, dtype=float)
    return np.diag(inertia) if inertia.ndim == 1 else inertia


def _euler_and_kinematics(inertia):
    """Right-hand side for y = (ω, R.ravel()): I ω̇ = (Iω) × ω, Ṙ = R ω̃."""
    tensor = _tensor(inertia)
    inverse = np.linalg.inv(tensor)

    def rhs(t, y):
        w, R = y[:3], y[3:].reshape(3, 3)
        hat = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
        return np.concatenate([inverse @ np.cross(tensor @ w, w), (R @ hat).ravel()])

    return rhs


def _reference(inertia, omega0, times, **kwargs):
    y0 = np.concatenate([omega0, np.eye(3).ravel()])
    return solve_ivp(
        _euler_and_kinematics(inertia),
        (0.0, times[-1]),
        y0,
        method="DOP853",
        rtol=1e-13,
        atol=1e-13,
        t_eval=times,
        **kwargs,
    )


@pytest.mark.parametrize("case", IDS)
def test_free_body_matches_tight_numerical_solution(case):
    inertia, omega0 = CASES[case]
    times = np.linspace(0.0, 2.2 * free_body_period(inertia, omega0), 120)
    expected = _reference(inertia, omega0, times).y[:3].T
    # DOP853 at 1e-13 is good to ~1e-11 here; the required agreement is 1e-8.
    np.testing.assert_allclose(free_body(inertia, omega0, times), expected, rtol=0, atol=1e-8)


@pytest.mark.parametrize("case", IDS)
def test_free_body_period_matches_measured_period(case):
    inertia, omega0 = CASES[case]
    period = free_body_period(inertia, omega0)
    middle_axis = np.linalg.eigh(_tensor(inertia))[1][:, 1]

    def crossing(t, y):  # the middle-axis component (sn, or transverse) rises through 0
        return y[:3] @ middle_axis

    crossing.direction = 1.0
    times = np.array([0.0, 2.5 * period])
    found = _reference(inertia, omega0, times, events=crossing).t_events[0]
    measured = np.diff(found)
    assert measured.size >= 1
    # Events located by root finding on DOP853's dense output: ~1e-10 relative; required 1e-6.
    np.testing.assert_allclose(measured, period, rtol=1e-6)


def test_free_body_agrees_with_landau_lifshitz_formula_via_scipy_ellipj():
    # I = (1, 2, 3), ω0 = (a1, 0, a3): L&L §37 with τ = λt and no phase offset.
    moments, omega0 = np.array([1.0, 2.0, 3.0]), np.array([0.4, 0.0, 1.0])
    two_e, l2 = moments @ omega0**2, (moments * omega0) @ (moments * omega0)
    a, b, c = moments
    amp = np.sqrt(
        [(two_e * c - l2) / (a * (c - a)), (two_e * c - l2) / (b * (c - b)), omega0[2] ** 2]
    )
    rate = np.sqrt((c - b) * (l2 - two_e * a) / (a * b * c))
    m = (b - a) * (two_e * c - l2) / ((c - b) * (l2 - two_e * a))
    times = np.linspace(0.0, 30.0, 50)
    sn, cn, dn, _ = ellipj(rate * times, m)
    expected = amp * np.stack([cn, sn, dn], axis=-1)
    # Two evaluations of the same formula: round-off only. Each side rounds the rate in about
    # 8 operations, so the phase λt ≤ 30 in about 8 u · 30, which cn, sn, dn pass on with
    # slope ≤ 1, plus their own ~10 u: 16 u · 30 + 20 u ≈ 5.5e-14 (measured 2.9e-14, with
    # and without numpy's SIMD loops); the period's 4K/λ a few roundings (measured 2.2e-16).
    np.testing.assert_allclose(free_body(moments, omega0, times), expected, rtol=0, atol=1e-13)
    assert free_body_period(moments, omega0) == pytest.approx(4 * ellipk(m) / rate, rel=1e-14)


@pytest.mark.parametrize("case", IDS)
def test_free_body_starts_at_omega0(case):
    inertia, omega0 = CASES[case]
    # The phase offset u0 must reproduce ω0; only round-off in F(φ|m) and the AGM remains
    # (measured ≤ 2.2e-16 for |ω0| ≤ 1, 45 ulps below the bound).
    np.testing.assert_allclose(free_body(inertia, omega0, 0.0), omega0, rtol=0, atol=1e-14)


@pytest.mark.parametrize("case", IDS)
def test_free_body_conserves_energy_and_angular_momentum(case):
    inertia, omega0 = CASES[case]
    tensor = _tensor(inertia)
    w = free_body(inertia, omega0, np.linspace(0.0, 500.0, 400))
    energy = np.einsum("ni,ij,nj->n", w, tensor, w)
    momentum = np.linalg.norm(w @ tensor, axis=1)
    # Exact invariants of the closed form; round-off in ω is ~1e-15 relative, and the sums of
    # 3 positive terms add a few u (measured ≤ 1e-15 against 1e-13).
    np.testing.assert_allclose(energy, omega0 @ tensor @ omega0, rtol=1e-13)
    np.testing.assert_allclose(momentum, np.linalg.norm(tensor @ omega0), rtol=1e-13)


@pytest.mark.parametrize("relative_offset", [1e-6, 1e-10])
def test_free_body_satisfies_euler_equations_near_separatrix(relative_offset):
    # Here a numerical reference is ill-conditioned (errors grow by 1/offset), so check the
    # residual of I ω̇ = (Iω) × ω with a 5-point derivative (truncation ~1e-11 at h = 1e-3).
    moments = np.array([1.0, 2.0, 3.0])
    omega0 = np.array([math.sqrt(3.0) * (1 + relative_offset), 0.0, 1.0])
    times = np.linspace(0.0, 1.5 * free_body_period(moments, omega0), 600)
    h = 1e-3

    def w(s):
        return free_body(moments, omega0, s)

    derivative = (-w(times + 2 * h) + 8 * w(times + h) - 8 * w(times - h) + w(times - 2 * h)) / (
        12 * h
    )
    residual = derivative - np.cross(moments * w(times), w(times)) / moments
    assert np.abs(residual).max() < 1e-9


def test_free_body_raises_on_separatrix():
    # |L|² = 2EB for I = (1, 2, 3) when ω_A² = 3 ω_C²: ω0 = (√3, 0.5, 1).
    with pytest.raises(ValueError, match="separatrix"):
        free_body([1.0, 2.0, 3.0], [math.sqrt(3.0), 0.5, 1.0], 1.0)


def test_free_body_period_is_infinite_on_separatrix():
    assert math.isinf(free_body_period([1.0, 2.0, 3.0], [math.sqrt(3.0), 0.5, 1.0]))


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_free_body_spin_about_a_principal_axis_is_constant(axis):
    omega0 = 0.7 * np.eye(3)[axis]  # axis 0 is the T-handle's middle axis
    w = free_body(T_HANDLE, omega0, np.linspace(0.0, 100.0, 11))
    np.testing.assert_array_equal(w, np.tile(omega0, (11, 1)))


def test_free_body_period_of_steady_spin_is_the_small_oscillation_limit():
    nearby = free_body_period([1.0, 2.0, 3.0], [0.0, 1e-7, 1.0])
    # The period depends on the perturbation only at second order (m ∝ amplitude²).
    assert free_body_period([1.0, 2.0, 3.0], [0.0, 0.0, 1.0]) == pytest.approx(nearby, rel=1e-12)


@pytest.mark.parametrize(
    ("inertia", "omega0"),
    [
        ([1.0, 1.0, 1.0], [0.3, 0.2, 0.1]),
        ([1.0, 2.0, 3.0], [0.0, 1.0, 0.0]),
        ([2.0, 2.0, 1.0], [1.0, 0.0, 0.0]),
    ],
    ids=["sphere", "middle-axis-spin", "transverse-spin-of-symmetric-body"],
)
def test_free_body_period_is_infinite_where_no_oscillation_is_near(inertia, omega0):
    assert math.isinf(free_body_period(inertia, omega0))


def test_free_body_scalar_time_gives_one_vector():
    assert free_body(HAIRER, HAIRER_OMEGA, 1.0).shape == (3,)
    assert free_body(HAIRER, HAIRER_OMEGA, [1.0, 2.0]).shape == (2, 3)


@given(
    moments=st.lists(st.floats(0.5, 3.0), min_size=3, max_size=3, unique=True),
    omega0=st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3),
    angles=st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3),
)
def test_free_body_rotates_with_the_body_axes(moments, omega0, angles):
    # Euler's equations are covariant: I → Q I Qᵀ, ω0 → Q ω0 gives ω(t) → Q ω(t) (Q proper).
    q = sphere(1.0, angles)
    times = np.array([0.0, 0.7, 3.1])
    try:
        expected = free_body(moments, omega0, times) @ q.T
        rotated = free_body(q @ np.diag(moments) @ q.T, q @ np.asarray(omega0), times)
    except ValueError as error:  # on the separatrix (to round-off in eigh): nothing to compare
        assert "separatrix" in str(error)
        assume(False)
    # eigh's principal axes carry ~1e-15 error, amplified near the separatrix: 1e-7 is loose.
    np.testing.assert_allclose(rotated, expected, rtol=0, atol=1e-7)


@pytest.mark.parametrize("case", IDS)
def test_free_body_rotation_matches_tight_numerical_kinematics(case):
    inertia, omega0 = CASES[case]
    times = np.linspace(0.0, 2.2 * free_body_period(inertia, omega0), 60)
    expected = _reference(inertia, omega0, times).y[3:].T.reshape(-1, 3, 3)
    # DOP853 at 1e-13 is good to ~1e-11 here; the required agreement is 1e-9.
    np.testing.assert_allclose(
        free_body_rotation(inertia, omega0, times), expected, rtol=0, atol=1e-9
    )


@pytest.mark.parametrize("case", IDS)
def test_free_body_rotation_keeps_world_angular_momentum(case):
    inertia, omega0 = CASES[case]
    tensor = _tensor(inertia)
    R0 = sphere(1.0, [0.3, -0.2, 0.5])
    times = np.linspace(0.0, 300.0, 200)
    R = free_body_rotation(inertia, omega0, times, R0=R0)
    momentum = np.einsum("nij,jk,nk->ni", R, tensor, free_body(inertia, omega0, times))
    # L = R I ω is constant: a wrong precession angle φ(t) breaks it at O(1).
    np.testing.assert_allclose(momentum, np.tile(R0 @ tensor @ omega0, (200, 1)), atol=1e-12)


def test_free_body_rotation_from_R0_is_R0_times_rotation_from_identity():
    R0 = sphere(2.0, [0.1, 0.7, -0.4])
    times = np.linspace(0.0, 20.0, 9)
    from_identity = free_body_rotation(HAIRER, HAIRER_OMEGA, times)
    # Left-invariance of the free rigid body; round-off only: two 3-term products of unit
    # entries, ≤ 12 u · 3 = 4e-15 (measured 1.7e-16).
    np.testing.assert_allclose(
        free_body_rotation(HAIRER, HAIRER_OMEGA, times, R0=R0), R0 @ from_identity, atol=1e-13
    )


def test_free_body_rotation_rejects_a_reflection_as_R0():
    with pytest.raises(ValueError, match="R0"):
        free_body_rotation(HAIRER, HAIRER_OMEGA, 1.0, R0=-np.eye(3))


def test_sphere_at_t1_is_the_spec_rotation_about_x():
    # SPEC §4: the exact rotation about x by angle 1 (what Lie–Euler reproduces to round-off).
    expected = np.array(
        [
            [1.0, 0.0, 0.0],
            [0.0, math.cos(1.0), -math.sin(1.0)],
            [0.0, math.sin(1.0), math.cos(1.0)],
        ]
    )
    # numpy's cos and sin (SIMD loops, ≤ 4 ulps) against libm's, on |entries| ≤ 1: ≤ 4.4e-16
    np.testing.assert_allclose(sphere(1.0), expected, rtol=0, atol=1e-15)


def test_sphere_agrees_with_free_body_rotation_of_identity_inertia():
    # the same Rodrigues formula (measured equal); 1e-14 covers its phase |ω| t ≤ 13 rad
    times, omega0 = np.linspace(0.0, 10.0, 7), [0.3, -1.2, 0.5]
    np.testing.assert_allclose(
        sphere(times, omega0), free_body_rotation([1.0, 1.0, 1.0], omega0, times), atol=1e-14
    )


def test_projectile_meets_spec_acceptance_figures():
    shot = projectile(500.0, math.pi / 4, g=9.81)
    # SPEC §4 gives 8 significant digits; 1e-6 relative is the acceptance tolerance.
    assert shot.flight_time == pytest.approx(72.080202, rel=1e-6)
    assert shot.range == pytest.approx(25484.1998, rel=1e-6)


def test_projectile_is_on_the_ground_at_flight_time():
    shot = projectile(40.0, 0.6, y0=12.0, x0=3.0)
    x, y = shot.position(shot.flight_time)
    assert y == pytest.approx(0.0, abs=1e-12)
    # the same product v0 cos α t on both sides; x0 + R rounds once at |x0 + R| ≈ R
    assert x - 3.0 == pytest.approx(shot.range, rel=1e-15)


def test_projectile_velocity_is_the_derivative_of_position():
    shot, t, h = projectile(40.0, 0.6, y0=12.0), np.array([0.5, 2.0, 4.0]), 1e-4
    derivative = (shot.position(t + h) - shot.position(t - h)) / (2 * h)
    # Position is quadratic, so the central difference is exact up to round-off (~1e-9).
    np.testing.assert_allclose(shot.velocity(t), derivative, atol=1e-8)


def test_projectile_max_height_is_reached_at_the_apex():
    shot = projectile(30.0, 1.0, g=9.81, y0=2.0)
    apex_time = 30.0 * math.sin(1.0) / 9.81
    # y0 + vy t − ½ g t² cancels half of vy t: ≤ 8 roundings on terms twice the height
    assert shot.max_height == pytest.approx(shot.position(apex_time)[1], rel=1e-14)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"v0": -1.0, "angle": 0.5}, "v0"),
        ({"v0": 10.0, "angle": 45.0}, "angle"),
        ({"v0": 10.0, "angle": 0.5, "g": 0.0}, "g"),
        ({"v0": 10.0, "angle": 0.5, "y0": -1.0}, "y0"),
        ({"v0": float("nan"), "angle": 0.5}, "v0"),
    ],
)
def test_projectile_rejects_bad_input_naming_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=name):
        projectile(**kwargs)


@pytest.mark.parametrize(
    ("args", "name"),
    [
        (([1.0, 0.0, 2.0], [1.0, 0.0, 0.0], 1.0), "inertia"),
        (([1.0, -2.0, 3.0], [1.0, 0.0, 0.0], 1.0), "inertia"),
        (([[1.0, 0.5, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]], [1.0, 0.0, 0.0], 1.0), "inertia"),
        (([1.0, 2.0, 3.0], [1.0, 0.0], 1.0), "omega0"),
        (([1.0, 2.0, 3.0], [1.0, np.inf, 0.0], 1.0), "omega0"),
        (([1.0, 2.0, 3.0], [1.0, 0.0, 0.0], [0.0, np.nan]), "t"),
        (([1.0, 2.0, 3.0], [1.0, 0.0, 0.0], [[0.0, 1.0]]), "t"),
    ],
    ids=[
        "zero-moment",
        "negative-moment",
        "asymmetric-tensor",
        "short-omega0",
        "inf-omega0",
        "nan-time",
        "2d-time",
    ],
)
def test_free_body_rejects_bad_input_naming_the_argument(args, name):
    with pytest.raises(ValueError, match=f"^{name}"):
        free_body(*args)


def test_observed_order_recovers_an_exact_power_law():
    h = np.array([0.2, 0.1, 0.05, 0.025])
    # log-log fit of e = 7 h^3.5 is exact up to round-off.
    assert observed_order(h, 7.0 * h**3.5) == pytest.approx(3.5, abs=1e-12)


@pytest.mark.parametrize(("order", "stages"), [(1, "euler"), (2, "heun")])
def test_measure_order_finds_the_order_of_simple_methods(order, stages):
    def run(h):  # y' = -y, y(0) = 1, to t = 1
        y = 1.0
        for _ in range(round(1.0 / h)):
            k1 = -y
            y = y + h * k1 if stages == "euler" else y + h / 2 * (k1 - (y + h * k1))
        return abs(y - math.exp(-1.0))

    measured, errors = measure_order(run, [0.1, 0.05, 0.025, 0.0125])
    assert errors.shape == (4,)
    # The asymptotic regime is reached by h = 0.1 for this problem: within 0.1 of the order.
    assert abs(measured - order) < 0.1, f"slope {measured:.3f}"


@pytest.mark.parametrize(
    ("step_sizes", "errors", "name"),
    [
        ([0.1], [1e-3], "step_sizes"),
        ([0.1, -0.05], [1e-3, 1e-4], "step_sizes"),
        ([0.1, 0.05], [1e-3, 0.0], "errors"),
        ([0.1, 0.05], [1e-3, 1e-4, 1e-5], "errors"),
        ([0.1, 0.1], [1e-3, 1e-4], "step_sizes"),
    ],
    ids=["one-size", "negative-size", "zero-error", "length-mismatch", "repeated-size"],
)
def test_observed_order_rejects_bad_input_naming_the_argument(step_sizes, errors, name):
    with pytest.raises(ValueError, match=f"^{name}"):
        observed_order(step_sizes, errors)


# --- the one study harness and the one fit policy -------------------------------------------


def test_study_warms_up_once_and_keeps_the_fastest_of_repeat_runs():
    calls, warm = [], []
    times = iter([3.0, 1.0, 2.0, 5.0, 4.0, 6.0])  # each run's own time, in call order

    def run(h):
        calls.append(h)
        return {"error": h**2, "seconds": next(times)}

    trials = study(run, [0.2, 0.1], lambda r: r["error"], repeat=3,
                   warm_up=lambda: warm.append(True), seconds=lambda r: r["seconds"])  # fmt: skip
    assert warm == [True] and calls == [0.2] * 3 + [0.1] * 3
    assert [trial.seconds for trial in trials] == [1.0, 4.0]
    assert [trial.result["seconds"] for trial in trials] == [1.0, 4.0]
    assert trials[1].error == pytest.approx(0.01) and trials[1].setting == 0.1


def test_study_makes_a_failed_runs_error_infinite():
    trials = study(lambda h: h, [1.0, 2.0], lambda h: math.nan if h > 1 else h)
    assert [trial.error for trial in trials] == [1.0, math.inf]


def test_study_without_an_error_only_times():
    (trial,) = study(lambda h: h, [1.0])
    assert math.isnan(trial.error) and trial.seconds >= 0.0


def test_study_stops_when_until_says_finer_settings_add_nothing():
    trials = study(lambda h: h, [1e-1, 1e-2, 1e-3, 1e-4], lambda h: h,
                   until=lambda done: done[-1].error < 5e-2)  # fmt: skip
    assert [trial.setting for trial in trials] == [1e-1, 1e-2]


def test_fit_order_fits_the_finest_errors_inside_the_window():
    h = np.array([0.8, 0.4, 0.2, 0.1, 0.05, 0.025])
    e = 3.0 * h**4
    e[0], e[-1] = 10.0, 1e-16  # out of the asymptotic range; at round-off
    fit = fit_order(h, e, window=(1e-13, 1.0), finest=3)
    assert fit is not None and fit.order == pytest.approx(4.0, abs=1e-12)
    assert fit.step_sizes.tolist() == [0.2, 0.1, 0.05]  # the three finest inside
    assert (fit.h_min, fit.h_max, fit.points) == (0.05, 0.2, 3)
    assert fit.used.tolist() == [False, False, True, True, True, False]


def test_fit_order_leaves_out_failed_runs():
    fit = fit_order([0.4, 0.2, 0.1], [math.inf, 4e-2, 1e-2])
    assert fit is not None and fit.points == 2 and fit.order == pytest.approx(2.0)


def test_fit_order_is_none_with_fewer_distinct_steps_than_asked():
    assert fit_order([0.2, 0.1, 0.05], [1e-2, 1e-3, 1e-20], window=(1e-13, 1.0),
                     minimum=3) is None  # fmt: skip
    assert fit_order([0.2, 0.1, 0.05], [1e-2, 1e-3, 1e-20], window=(1e-13, 1.0)) is not None


def test_fit_order_refuses_mismatched_errors_by_name():
    with pytest.raises(ValueError, match="^errors"):
        fit_order([0.2, 0.1], [1e-2])
