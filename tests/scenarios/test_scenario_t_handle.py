"""Seed 002 tasks 5–6: the T-handle's three spins and the period of the intermediate-axis flip."""

import json

import numpy as np
import pytest

from tumble import scenarios
from tumble.io import write_run_folder
from tumble.scenarios.t_handle import SPINS, measured_period, zero_crossings


@pytest.fixture(scope="module")
def result():
    # 65 s at h = 0.02: the unstable spin (period 47.26 s) crosses zero three times
    # (11.8, 35.4, 59.1 s), enough for one measured period; the stable ones many more.
    return scenarios.get("t-handle").run(t_end=65.0, h=0.02)


def test_seed_inertia_is_used(result):
    np.testing.assert_allclose(
        result.summary["inertia"], [9.82271303e-05, 7.22671030e-05, 1.57865031e-04], rtol=1e-8
    )


def test_the_spin_about_x_is_the_unstable_middle_axis(result):
    roles = [spin["axis_role"] for spin in result.summary["spins"]]
    assert roles == ["intermediate (unstable)", "smallest (stable)", "largest (stable)"]


def test_the_intermediate_spin_flips(result):
    omega_x = result.data["trajectories"][0].omega_body[:, 0]
    assert omega_x.max() > 0.99 and omega_x.min() < -0.99


@pytest.mark.parametrize("index", [0, 1, 2])
def test_measured_period_matches_the_closed_form(result, index):
    spin = result.summary["spins"][index]
    # 1e-3 relative on this short, coarse run (measured ~1e-9); tests/rigid checks 1e-6.
    assert spin["period_measured"] == pytest.approx(spin["period_closed_form"], rel=1e-3)


def test_flip_times_by_event_agree_with_the_exact_half_period(result):
    flipping, *stable = result.summary["spins"]
    # 11.8, 35.4, 59.1 s: FLIP_RTOL leaves ~1e-11 of the half period per flip (measured)
    assert len(flipping["flip_times"]) == 3
    assert max(abs(d) for d in flipping["flip_relative_differences"]) < 1e-8
    assert flipping["half_period_exact"] == pytest.approx(flipping["period_closed_form"] / 2)
    assert all(spin["flip_times"] is None for spin in stable)


def test_closed_form_periods(result):
    periods = [spin["period_closed_form"] for spin in result.summary["spins"]]
    np.testing.assert_allclose(periods, [47.2614505, 16.6503765, 7.4083571], rtol=1e-7)


def test_rkmk4_keeps_so3_energy_and_momentum(result):
    for spin in result.summary["spins"]:
        assert spin["max_orthogonality_error"] < 1e-12
        assert spin["energy_drift"] < 1e-8  # measured ≤ 1.4e-10 at h = 0.02
        assert spin["momentum_drift"] == 0.0


def test_zero_crossings_of_a_cosine_are_odd_multiples_of_half_pi():
    t = np.linspace(0.0, 10.0, 2001)
    np.testing.assert_allclose(
        zero_crossings(t, np.cos(t)), [np.pi / 2, 1.5 * np.pi, 2.5 * np.pi], atol=1e-5
    )


def test_too_short_a_run_measures_no_period():
    t = np.linspace(0.0, 3.0, 301)
    omega = np.stack([np.cos(t), np.sin(t), np.ones_like(t)], axis=1)
    period, _, crossings = measured_period(t, omega)
    assert period is None and len(crossings) == 1


def test_summary_is_json_with_the_promised_keys(result):
    summary = json.loads(json.dumps(result.summary))
    assert summary["scenario"] == "t-handle"
    assert summary["method"] == "rkmk4" and summary["h"] == 0.02
    assert [spin["omega0"] for spin in summary["spins"]] == [
        [1.0, 0.05, 0.0],
        [0.0, 1.0, 0.05],
        [0.05, 0.0, 1.0],
    ]


def test_run_folder_has_summary_and_every_figure(result, tmp_path):
    folder = write_run_folder(result, tmp_path / "run")
    assert json.loads((folder / "summary.json").read_text())["t_end"] == 65.0
    names = {name for name, _ in result.figures}
    expected = {f"rotation_grid_spin{k}.png" for k in (1, 2, 3)}
    expected |= {f"euler_angles_spin{k}.png" for k in (1, 2, 3)}
    assert names == expected | {"angular_velocity.png", "drift.png"}
    for name in names:
        assert (folder / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_no_spins_is_refused_by_name():
    with pytest.raises(ValueError, match="spins="):
        scenarios.get("t-handle").run(spins=())


@pytest.fixture(scope="module")
def diverged():
    # euler at h = 5 s multiplies |R| by about √(1 + (h ω)²) per step: the state overflows
    # between t = 65 and 70 s, long before t_end; the step is said to be too large first
    with pytest.warns(UserWarning, match=r"h=5.0 s turns the body by h\|ω\| = 5.01 rad"):
        return scenarios.get("t-handle").run(method="euler", h=5.0, t_end=200.0,
                                             spins=[SPINS[0]])  # fmt: skip


def test_a_diverged_spin_reports_its_status_and_no_measured_numbers(diverged):
    spin = diverged.summary["spins"][0]
    assert spin["status"] == -1
    assert "non-finite" in spin["message"] and "t=65.0 to t=70.0" in spin["message"]
    measured = [
        "period_measured",
        "period_relative_difference",
        "energy_drift",
        "momentum_drift",
        "error_vs_exact",
        "max_orthogonality_error",
    ]
    assert {name: spin[name] for name in measured} == dict.fromkeys(measured)
    assert spin["period_closed_form"] == pytest.approx(47.2614505, rel=1e-7)
    assert json.loads(json.dumps(spin, allow_nan=False)) == spin  # no Infinity or NaN


def test_spins_that_reach_t_end_report_status_zero(result):
    for spin in result.summary["spins"]:
        assert (spin["status"], spin["message"]) == (0, "The run reached the end of the interval.")


def test_a_diverged_spin_still_writes_its_run_folder_without_warnings(diverged, tmp_path):
    folder = write_run_folder(diverged, tmp_path / "run")  # filterwarnings = error
    assert json.loads((folder / "summary.json").read_text())["spins"][0]["status"] == -1
    assert (folder / "drift.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_measured_periods_are_the_mean_of_every_other_crossing_interval():
    """The telescoped, vectorised period equals the mean of c[k + 2] − c[k] to round-off."""
    from tumble.scenarios.t_handle import measured_periods

    t = np.linspace(0.0, 40.0, 4001)
    rates = [0.7, 1.3, 2.9]
    omega = np.stack([np.stack([np.cos(w * t), np.sin(w * t), 0.1 + 0 * t], axis=1)
                      for w in rates])  # fmt: skip
    omega[2, :, 0] += 0.3 * np.sin(5.1 * t)  # uneven crossings: the mean is not one interval
    found = measured_periods(t, omega)
    for k in range(len(rates)):
        crossings = zero_crossings(t, omega[k, :, 0])
        assert found[k] == pytest.approx(np.mean(crossings[2:] - crossings[:-2]), rel=1e-13)
    assert found[0] == pytest.approx(2 * np.pi / rates[0], rel=1e-4)  # linear interpolation


def test_measured_periods_are_nan_for_fewer_than_three_crossings_and_after_a_stop():
    from tumble.scenarios.t_handle import measured_periods

    t = np.linspace(0.0, 3.0, 301)
    short = np.stack([np.cos(t), np.sin(t), np.ones_like(t)], axis=1)[None]
    assert np.isnan(measured_periods(t, short)).all()
    t = np.linspace(0.0, 30.0, 3001)
    spin = np.stack([np.cos(t), np.sin(t), np.ones_like(t)], axis=1)
    stopped = spin.copy()
    stopped[1000:] = np.nan  # 10 s: three crossings of cos t (1.6, 4.7, 7.9 s) before
    found = measured_periods(t, np.stack([spin, stopped]))
    assert found == pytest.approx([2 * np.pi, 2 * np.pi], rel=1e-4)
