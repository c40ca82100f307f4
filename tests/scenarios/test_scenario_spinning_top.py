"""The spinning-top scenario: the Lagrange top's invariants and nutation bounds, as reported."""

import numpy as np
import pytest
from rigid_roundoff import invariant_bound

from tumble import scenarios
from tumble.scenarios import spinning_top


@pytest.fixture(scope="module")
def result():
    return scenarios.get("spinning-top").run()


def test_every_method_keeps_lz_and_nutates_between_the_classical_bounds(result):
    summary = result.summary
    low, high = summary["theta_bounds_deg"]
    # released with no transverse motion, the axis starts at the smallest θ: the tilt
    assert low == pytest.approx(np.degrees(0.3), abs=1e-9) and low < high < 90
    for method, r in summary["results"].items():
        assert r["t_reached"] == summary["t_end"]
        # the torque of gravity is horizontal: L_z is kept exactly, only its record rounds
        # (a few ulps; as in tests/rigid/test_rigid_pivot.py)
        assert r["L_z_drift"] < 1e-14, method
        theta_min, theta_max = r["theta_range_deg"]
        assert theta_min == pytest.approx(low, abs=1e-6)  # sampled every h: reached to 1e-6
        assert theta_max == pytest.approx(high, abs=1e-4)


def test_the_splitting_on_the_exact_flow_keeps_energy_and_spin_far_better_than_rkmk4(result):
    # Measured: yoshida4 2.1e-11 and 5.5e-15; rkmk4 7.4e-10 and 4.3e-10.
    results = result.summary["results"]
    assert results["yoshida4"]["energy_drift"] < 1e-10
    # on the exact flow L_3 is kept to the walk of the 5000 steps' round-off (1.2e-12)
    assert results["yoshida4"]["L_3_drift"] < invariant_bound("yoshida4", 5000)
    assert results["rkmk4"]["L_3_drift"] > 1e3 * results["yoshida4"]["L_3_drift"]


def test_the_fast_top_precesses_at_the_gyroscopic_rate(result):
    # For a fast top the mean precession tends to m g ℓ / (I₃ ω₃) (Goldstein §5.7); at 100 rad/s
    # the nutation adds a few per cent (measured 5.84 against 5.12 rad/s).
    body, tip, _ = spinning_top.top(7800.0)
    gyroscopic = body.mass * spinning_top.G * np.linalg.norm(tip) / (body.inertia[2, 2] * 100.0)
    rate = result.summary["results"]["yoshida4"]["precession_rate"]
    assert rate == pytest.approx(gyroscopic, rel=0.2)


@pytest.mark.parametrize("tilt", [0.0, np.pi, -0.1, float("nan")])
def test_a_tilt_outside_zero_to_pi_is_refused(tilt):
    with pytest.raises(ValueError, match=r"^tilt=.* is not allowed"):
        scenarios.get("spinning-top").run(tilt=tilt, t_end=0.1)
