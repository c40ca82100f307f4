"""Seed 000's projectile: the impact located by an event (SPEC §4)."""

import json

import pytest

from tumble import scenarios
from tumble.io import write_run_folder


@pytest.fixture(scope="module")
def result():
    return scenarios.get("projectile").run()


def test_impact_time_matches_spec(result):
    # SPEC §4: t = 72.080202 s to 1e-6 relative (RK4 is exact for a parabola).
    assert result.summary["impact_time"] == pytest.approx(72.080202, rel=1e-6)


def test_range_matches_spec(result):
    assert result.summary["range"] == pytest.approx(25484.1998, rel=1e-6)


def test_impact_is_on_the_ground_not_the_last_sample_above_it(result):
    ode = result.data["ode"]
    assert abs(ode.y[1, -1]) < 1e-6
    assert ode.t[-1] - ode.t[-2] < 0.01  # the last step was cut short at the impact


def test_run_folder_has_summary_and_picture(result, tmp_path):
    folder = write_run_folder(result, tmp_path / "run")
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["impact_time"] == pytest.approx(72.080202, rel=1e-6)
    assert summary["method"] == "rk4" and summary["h"] == 0.01
    assert (folder / "trajectory.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_run_folder_is_not_overwritten_without_force(result, tmp_path):
    write_run_folder(result, tmp_path)
    with pytest.raises(ValueError, match="force"):
        write_run_folder(result, tmp_path)
    write_run_folder(result, tmp_path, force=True)


@pytest.mark.parametrize(("option", "value"), [("speed", -1.0), ("angle", 0.0), ("g", 0.0)])
def test_bad_option_is_refused_by_name(option, value):
    with pytest.raises(ValueError, match=f"{option}="):
        scenarios.get("projectile").run(**{option: value})


def test_unknown_scenario_lists_the_known_ones():
    with pytest.raises(ValueError, match="projectile"):
        scenarios.get("no-such-thing")
