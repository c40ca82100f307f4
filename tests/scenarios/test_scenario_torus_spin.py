"""Seed 000's torus: integrating R as nine numbers drifts off SO(3); the Lie methods do not."""

import json

import numpy as np
import pytest

from tumble import exact, scenarios
from tumble.io import write_run_folder
from tumble.scenarios.torus_spin import precession_rate


@pytest.fixture(scope="module")
def result():
    # 20 s = 200 steps of 0.1 s: long enough for rk4-matrix's drift to be unmistakable.
    return scenarios.get("torus-spin").run(t_end=20.0)


def test_torus_inertia_is_the_closed_form_of_spec_section_4(result):
    np.testing.assert_allclose(
        result.summary["inertia"], [3.238464, 3.238464, 5.860078], rtol=2e-7
    )
    assert result.summary["mass"] == pytest.approx(4.934802, rel=1e-6)


def test_rk4_matrix_drifts_off_so3_and_keeps_drifting(result):
    run = result.data["trajectories"]["rk4-matrix"]
    error = run.orthogonality_error
    # Measured 1.18e-4 at t = 20 s (5.9e-4 at 100 s): |P(hΩ)| < 1 loses ~θ⁶/72 per step.
    assert error[-1] > 1e-4
    halfway = np.searchsorted(run.t, 10.0)
    assert error[-1] > 1.8 * error[halfway]  # linear growth, not a bounded wobble


@pytest.mark.parametrize("method", ["lie-euler", "rkmk4", "rk4-quat"])
def test_lie_and_quaternion_methods_stay_on_so3(result, method):
    assert result.summary["results"][method]["max_orthogonality_error"] < 1e-12


def test_rkmk4_follows_the_exact_free_torus(result):
    # Measured 1.1e-4 at h = 0.1, T = 20 (fourth order; the precession is exact in closed form).
    assert result.summary["results"]["rkmk4"]["error_vs_exact"] < 2e-4


def test_free_torus_precesses_rather_than_keeping_omega_constant(result):
    run = result.data["trajectories"]["rkmk4"]
    body = result.data["body"]
    rate = precession_rate(body.inertia, (1.0, 1.0, 1.0))
    assert rate == pytest.approx((3.238464 - 5.860078) / 3.238464, rel=1e-6)
    expected = exact.free_body(body.inertia, (1.0, 1.0, 1.0), run.t)
    np.testing.assert_allclose(run.omega_body, expected, atol=1e-4)
    assert np.ptp(run.omega_body[:, 0]) > 2.0  # ω_x swings between ±√2: not constant


def test_summary_is_json_with_the_promised_keys(result):
    summary = json.loads(json.dumps(result.summary))
    assert summary["scenario"] == "torus-spin"
    assert summary["h"] == 0.1
    assert summary["methods"] == ["rk4-matrix", "rk4-quat", "lie-euler", "rkmk4"]


def test_run_folder_has_summary_and_every_figure(result, tmp_path):
    folder = write_run_folder(result, tmp_path / "run")
    assert json.loads((folder / "summary.json").read_text())["t_end"] == 20.0
    names = {name for name, _ in result.figures}
    assert names == {"drift.png", "error_vs_exact.png", "rotation_grid.png"}
    for name in names:
        assert (folder / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bad_torus_is_refused_by_name():
    with pytest.raises(ValueError, match="minor_radius"):
        scenarios.get("torus-spin").run(t_end=1.0, minor_radius=2.0)


def test_explicit_euler_overflows_and_is_reported_not_hidden(tmp_path):
    # (1 + h²|ω|²)^½ = 1.015 per step at h = 0.1: R overflows near t = 52 s.
    result = scenarios.get("torus-spin").run(t_end=60.0, methods=("euler", "rkmk4"))
    euler = result.summary["results"]["euler"]
    assert euler["t_reached"] < 55.0
    assert euler["orthogonality_error"] is None  # JSON has no inf: None marks the overflow
    assert result.summary["results"]["rkmk4"]["t_reached"] == 60.0
    folder = write_run_folder(result, tmp_path / "run")
    json.loads((folder / "summary.json").read_text())
    assert (folder / "drift.png").exists()
