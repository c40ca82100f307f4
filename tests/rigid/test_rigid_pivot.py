"""A body with a fixed point: the heavy (Lagrange) top and the compound pendulum."""

import numpy as np
import pytest
from rigid_roundoff import invariant_bound
from roundoff import error_bound

from tumble import so3
from tumble.rigid import METHODS, Force, Gravity, RigidBody, Torque, simulate

I1, I3, MASS, ELL, G = 0.02, 0.01, 1.0, 0.1, 9.81
TOP = RigidBody(MASS, [I1, I1, I3])
PIVOT = np.array([0.0, 0.0, -ELL])  # on the symmetry axis, ELL below the centre of mass
R0 = so3.exp([0.5, 0.0, 0.0])  # axis tilted 0.5 rad from the vertical
OMEGA0 = np.array([0.0, 0.0, 60.0])  # spin about the symmetry axis
X_PIVOT = R0 @ PIVOT
TOLERANCES = {
    # method: (relative energy, L_3) after 20 s at h = 1e-3; measured 1.6e-12 / 5.7e-15
    # (yoshida4), 7.5e-8 / 3.3e-15 (strang), 1.8e-10 / 8.4e-11 (split-axes4), 2.4e-10 /
    # 1.3e-10 (rkmk4). On the exact flow L_3 is kept to round-off: the walk of 2·10⁴ steps'
    # roundings (rigid_roundoff.invariant_bound: 2.3e-12 and 1.3e-12).
    "yoshida4": (1e-11, invariant_bound("yoshida4", 20_000)),
    "strang": (5e-7, invariant_bound("strang", 20_000)),
    "split-axes4": (1e-9, 5e-10),
    "rkmk4": (1e-9, 5e-10),
}


def lagrange_top(method: str, t_end: float = 20.0, h: float = 1e-3):
    return simulate(TOP, t_end, method=method, h=h, R0=R0, omega0=OMEGA0, pivot=PIVOT,
                    forces=[Gravity((0.0, 0.0, -G))])  # fmt: skip


def nutation_bounds(energy: float, L_z: float, L_3: float) -> np.ndarray:
    """The roots in [−1, 1] of the classical cubic for u = cos θ (Goldstein §5.7):
    u̇² = (1 − u²)(2/I₁')(E' − m g ℓ u) − ((L_z − L₃ u)/I₁')², E' = E − L₃²/(2 I₃)."""
    I1p = I1 + MASS * ELL**2
    E_prime = energy - L_3**2 / (2 * I3)
    P = np.polynomial.Polynomial
    f = (
        P([1, 0, -1]) * P([2 * E_prime / I1p, -2 * MASS * G * ELL / I1p])
        - P([L_z / I1p, -L_3 / I1p]) ** 2
    )
    roots = f.roots()
    real = np.sort(roots[np.abs(roots.imag) < 1e-9].real)
    return real[(real >= -1) & (real <= 1)]


@pytest.mark.parametrize("method", list(TOLERANCES))
def test_lagrange_top_keeps_its_three_invariants_and_nutates_between_the_roots(method):
    run = lagrange_top(method)
    L_pivot = run.angular_momentum_about(X_PIVOT)
    L_3 = np.einsum("nji,nj->ni", run.R, L_pivot)[:, 2]  # body symmetry-axis component
    # the energy about the pivot: tumble's V = m g z includes the pivot's height
    energy = run.energy - MASS * G * X_PIVOT[2]
    energy_tol, spin_tol = TOLERANCES[method]
    assert np.abs(run.energy_error).max() < energy_tol * abs(run.energy[0])
    # the torque is horizontal: L_z is kept exactly, and only its record rounds (a few ulps of
    # |L| = 0.6, measured 1.1e-16 over the 2·10⁴ steps)
    assert np.abs(L_pivot[:, 2] - L_pivot[0, 2]).max() < 1e-14
    assert np.abs(L_3 - L_3[0]).max() < spin_tol * abs(L_3[0])
    low, high = nutation_bounds(energy[0], L_pivot[0, 2], L_3[0])
    u = run.R[:, 2, 2]  # cos θ: the symmetry axis against the vertical
    assert u.min() > low - 1e-8 and u.max() < high + 1e-8
    assert u.min() < low + 1e-5 and u.max() > high - 1e-5  # it reaches both (sampled at h)


def test_the_centre_of_mass_turns_about_the_fixed_pivot():
    run = lagrange_top("yoshida4", t_end=1.0)
    # x is X − R p at every step: x + R p rounds 3-term sums of size ℓ twice (measured 7e-18)
    pivots = run.x + np.einsum("nij,j->ni", run.R, PIVOT)
    np.testing.assert_allclose(pivots, np.broadcast_to(X_PIVOT, pivots.shape),
                               atol=error_bound(3 * ELL, 8))  # fmt: skip
    # ω × r of terms |ω| |r| (60 rad/s × 0.1 m) cancelling to |v| ≤ 0.2 m/s, each side a chain
    # of 12 roundings (ω from Rᵀ L and I, R ω, x − X, the cross product); measured 1.3e-14
    omega_world = np.einsum("nij,nj->ni", run.R, run.omega_body)
    terms = 2 * np.abs(omega_world).max() * np.abs(run.x - X_PIVOT).max()
    np.testing.assert_allclose(run.v, np.cross(omega_world, run.x - X_PIVOT),
                               atol=error_bound(terms, 24))  # fmt: skip


def test_a_compound_pendulum_swings_with_its_small_amplitude_period():
    # A rod-like body hung 0.3 m below its pivot, 1e-3 rad amplitude: T = 2π √(I_p/(m g ℓ)),
    # I_p = I + m ℓ² about the swing axis (x). Measured: within 2e-7 relative.
    body = RigidBody(2.0, [0.05, 0.05, 0.001])
    ell, amplitude = 0.3, 1e-3
    period = 2 * np.pi * np.sqrt((0.05 + 2.0 * ell**2) / (2.0 * 9.81 * ell))
    run = simulate(body, 3 * period, method="yoshida4", h=period / 2000, pivot=(0, 0, ell),
                   R0=so3.exp([amplitude, 0, 0]), forces=[Gravity()])  # fmt: skip
    angle = np.arctan2(run.R[:, 2, 1], run.R[:, 2, 2])  # the tilt about x
    crossings = run.t[1:][(angle[:-1] > 0) & (angle[1:] <= 0)]
    measured = np.diff(crossings).mean()
    assert measured == pytest.approx(period, rel=1e-5)


@pytest.mark.parametrize("method", [name for name, m in METHODS.items() if not m.exact])
def test_a_pivot_at_the_centre_of_mass_is_the_free_body(method):
    body = RigidBody(1.5, [[2.0, 0.1, 0.0], [0.1, 1.5, 0.05], [0.0, 0.05, 1.0]])
    options = dict(method=method, omega0=(0.3, 1.0, -0.2), forces=[Torque((0.0, 0.01, 0.0))])
    step = {"rtol": 1e-8} if METHODS[method].adaptive else {"h": 0.05}
    pinned = simulate(body, 2.0, pivot=(0.0, 0.0, 0.0), **options, **step)
    free = simulate(body, 2.0, **options, **step)
    # the same compiled loop, the pivot adding exact zeros: equal bit for bit (measured) on any
    # machine (numba: no FMA, no reassociation)
    np.testing.assert_allclose(pinned.R, free.R, atol=1e-14)
    np.testing.assert_allclose(pinned.L_world, free.L_world, atol=1e-14)
    np.testing.assert_allclose(pinned.x, 0.0, atol=1e-15)


@pytest.mark.parametrize(
    "options, message",
    [
        (dict(pivot=(0.0, np.nan, 0.0)), r"^pivot\[1\]=nan is not allowed"),
        (dict(pivot=(0.0, 0.0)), r"^pivot=.* is not allowed: must be of shape \(3,\)"),
        (dict(pivot=(0.0, 0.0, 1.0), v0=(1.0, 0.0, 0.0)), r"^v0=.* is not allowed: .*pivot"),
        (
            dict(pivot=(0.0, 0.0, 1.0), forces=[Force(lambda t, s: (0.0, 0.0, -1.0))]),
            r"^forces\[0\]=.* is not allowed: must be a constant load with a pivot",
        ),
        (
            dict(pivot=(0.0, 0.0, 1.0), forces=[Gravity()], method="exact"),
            r"^forces=\['Gravity'\] is not allowed: .*'strang'",
        ),
    ],
    ids=["nan", "shape", "v0", "callable", "exact"],
)
def test_bad_pivot_input_is_refused_naming_the_argument(options, message):
    options = {"method": "rkmk4", **options}
    with pytest.raises(ValueError, match=message):
        simulate(TOP, 1.0, h=0.01, **options)
