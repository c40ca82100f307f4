"""The truth suite's references, checked against each other before they judge tumble.

- the mpmath closed form (Jacobi's functions, the third integral) against scipy's DOP853
  at rtol 1e-13 on Euler's equations with a quaternion: two derivations, two codes;
- its precession angle, from the continued third integral, against a quadrature of
  ``φ̇ = M (Aω₁² + Bω₂²)/(A²ω₁² + B²ω₂²)`` with ω from Jacobi's functions;
- the forced DOP853 reference against mpmath's Taylor integrator (``mpmath.odefun``) at 20
  digits, on short spans (it costs a second or two a case).
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_truth_methods import problems
from truth_problems import principal_moments, sample, spins
from truth_reference import (
    DPS,
    ULP,
    Loads,
    Orbit,
    _body_frame,
    _euler_field,
    _quaternion,
    _quaternion_rotation,
    forced_body,
    free_body,
)

pytestmark = pytest.mark.truth


@sample(default=4, nightly=100)
@given(moments=principal_moments(), data=st.data(), turns=st.floats(0.5, 30.0))
def test_closed_form_agrees_with_dop853(moments, data, turns):
    """DOP853's own error is bounded by its change from rtol 1e-11 to 1e-13."""
    _, omega0 = data.draw(spins(moments))
    t_end = turns / float(np.linalg.norm(omega0))  # ``turns`` radians
    closed = free_body(moments, omega0, t_end)
    integrated = forced_body(moments, omega0, tuple(map(tuple, np.eye(3))), Loads(), t_end)
    gap = float(np.linalg.norm(closed.R - integrated.R))
    # twice DOP853's measured error, and 64 ulps for the quaternion's conversions to and
    # from a matrix (a few ulps each) should its two runs agree by chance
    assert gap <= 2.0 * integrated.error + 64 * ULP, (
        f"closed form and DOP853 differ by {gap:.2e}, DOP853's error ≤ {integrated.error:.2e}; "
        f"moments {moments}, omega0 {omega0}, T = {t_end:.4g} s"
    )


@sample(default=3, nightly=50)
@given(moments=principal_moments(), data=st.data(), share=st.floats(0.05, 1.0))
def test_precession_from_the_third_integral_matches_quadrature(moments, data, share):
    _, omega0 = data.draw(spins(moments, ("generic", "near-axis", "separatrix")))
    with mp.workdps(DPS):
        _, sorted_moments, m0 = _body_frame(moments, omega0)
        orbit = Orbit(sorted_moments, m0)
        A, B, _ = sorted_moments
        t_end = min(
            share * 4 * orbit.K / orbit.rate, 30 / mp.sqrt(sum(w * w for w in orbit.omega(0)))
        )

        def rate(t):
            w = orbit.omega(t)
            return (
                orbit.M * (A * w[0] ** 2 + B * w[1] ** 2) / (A**2 * w[0] ** 2 + B**2 * w[1] ** 2)
            )

        # φ̇ peaks where sn or cn vanishes (τ = jK), sharply when the spin is near an axis:
        # split there, where tanh-sinh quadrature clusters its nodes
        first = int(mp.ceil(orbit.tau0 / orbit.K))
        last = int(mp.floor((orbit.tau0 + orbit.rate * t_end) / orbit.K))
        peaks = [(j * orbit.K - orbit.tau0) / orbit.rate for j in range(first, last + 1)]
        points = [mp.mpf(0)] + [t for t in peaks if 0 < t < t_end] + [t_end]
        quadrature, error = mp.quad(rate, points, error=True)
        closed = orbit.precession(t_end)
        assert abs(closed - quadrature) <= 10 * error + mp.mpf(1e-25) * (1 + abs(quadrature)), (
            f"φ: third integral {mp.nstr(closed, 25)}, quadrature {mp.nstr(quadrature, 25)} "
            f"± {mp.nstr(error, 3)}"
        )


def _taylor_rotation(moments, omega0, loads: Loads, t_end: float) -> np.ndarray:
    """R(t_end) by mpmath's Taylor integrator at 20 digits, on the same equations as the
    DOP853 reference but in mpmath numbers."""
    inertia = loads.inertia(moments)
    field64 = _euler_field(inertia, loads)  # only to check the mp field agrees at t = 0
    inverse = mp.inverse(mp.matrix(inertia.tolist()))
    I = mp.matrix(inertia.tolist())

    def field(t, y):
        q, w = y[:4], mp.matrix(y[4:])
        norm = mp.sqrt(sum(x * x for x in q))
        q0, q1, q2, q3 = (x / norm for x in q)
        R = np.array(
            [
                [1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
                [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
                [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)],
            ],
            dtype=object,
        )
        Iw = I * w
        gyro = [
            Iw[1] * w[2] - Iw[2] * w[1],
            Iw[2] * w[0] - Iw[0] * w[2],
            Iw[0] * w[1] - Iw[1] * w[0],
        ]
        torque = loads.body_torque(R)
        dw = inverse * mp.matrix([gyro[i] + torque[i] for i in range(3)])
        w0, w1, w2 = w
        dq = [
            (-q1 * w0 - q2 * w1 - q3 * w2) / 2,
            (q0 * w0 + q2 * w2 - q3 * w1) / 2,
            (q0 * w1 + q3 * w0 - q1 * w2) / 2,
            (q0 * w2 + q1 * w1 - q2 * w0) / 2,
        ]
        return dq + [dw[0], dw[1], dw[2]]

    y0 = [mp.mpf(float(x)) for x in np.concatenate([_quaternion(np.eye(3)), omega0])]
    start = np.array([float(x) for x in field(0, y0)])
    assert np.allclose(start, field64(0.0, np.array([float(x) for x in y0])), rtol=1e-14)
    with mp.workdps(20):
        y = mp.odefun(field, 0, y0)(t_end)
    return _quaternion_rotation(np.array([float(x) for x in y[:4]]))


@sample(default=1, nightly=10)
@given(problem=problems(), turns=st.floats(0.2, 2.0))
def test_forced_reference_agrees_with_mpmath_taylor(problem, turns):
    t_end = turns * problem.time_scale
    integrated = forced_body(problem.moments, problem.omega0, tuple(map(tuple, np.eye(3))),
                             problem.loads, t_end)  # fmt: skip
    taylor = _taylor_rotation(problem.moments, np.array(problem.omega0), problem.loads, t_end)
    gap = float(np.linalg.norm(taylor - integrated.R))
    # as above, the 64 ulps of the conversions carried by the problem's sensitivity
    assert gap <= 2.0 * integrated.error + 64 * ULP * (1 + integrated.sensitivity), (
        f"DOP853 and mpmath's Taylor series differ by {gap:.2e} (DOP853's error ≤ "
        f"{integrated.error:.2e}); {problem}, T = {t_end:.3g} s"
    )
    assert math.isfinite(gap)
