"""Seed 001: the hexagonal prism hit at a vertex, with the full impulse and the true inertia."""

import json

import numpy as np
import pytest

from tumble import scenarios
from tumble.io import write_run_folder

F0 = np.array([40.0, 20.0, 10.0])  # seed 001's outside point
F1 = np.array([45.0, 10.0 + 5.0 * np.sqrt(3.0), 20.0])  # top vertex at 120° of the prism
CENTER = np.array([50.0, 10.0, 10.0])
J = (F1 - F0) * 0.25  # seed 001: F = f1 − f0 for dt = (5 − 0)/20 s
INERTIA = np.diag(
    [54.166666666666667, 54.166666666666667, 41.666666666666667]
)  # 1 kg, a = 10, L = 20


@pytest.fixture(scope="module")
def result():
    return scenarios.get("prism-impulse").run()


def test_summary_reports_the_closed_form_kick(result):
    summary = result.summary
    np.testing.assert_allclose(summary["impulse"], J, rtol=0, atol=1e-12)
    np.testing.assert_allclose(summary["delta_v"], J / 1.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(summary["delta_L"], np.cross(F1 - CENTER, J), rtol=0, atol=1e-12)
    # r = (−5, 5√3, 10), J = (1.25, 2.5 − 1.25√3, 2.5): r × J = (25, 25, 12.5 − 12.5√3 + … )
    np.testing.assert_allclose(summary["delta_L"][:2], [25.0, 25.0], rtol=0, atol=1e-12)


@pytest.mark.parametrize("method", ["euler", "rk4-quat", "rkmk4"])
def test_every_method_gets_delta_v_and_delta_L_from_the_full_impulse(result, method):
    run = result.data["trajectories"][method]
    # Δv = J/m and ΔL = (f1 − x_cm) × J, to round-off (no projection, no sign flip).
    np.testing.assert_allclose(run.v[0], J, rtol=0, atol=1e-12)
    np.testing.assert_allclose(run.L_world[0], np.cross(F1 - CENTER, J), rtol=0, atol=1e-12)


def test_energy_after_the_hit_is_translational_plus_rotational(result):
    delta_L = np.cross(F1 - CENTER, J)
    expected = 0.5 * J @ J + 0.5 * delta_L @ np.linalg.solve(INERTIA, delta_L)
    assert result.summary["energy_after"] == pytest.approx(expected, rel=1e-12)
    assert result.summary["results"]["rkmk4"]["energy_after"] == pytest.approx(expected, rel=1e-12)


def test_rkmk4_conserves_energy_after_the_hit(result):
    # Measured 4.6e-9 over 5 s at h = 0.25 (local error O(h⁵)); 1e-7 leaves a margin of 20.
    assert result.summary["results"]["rkmk4"]["energy_drift"] < 1e-7


def test_free_flight_keeps_momentum_and_moves_in_a_straight_line(result):
    for method, run in result.data["trajectories"].items():
        assert result.summary["results"][method]["max_momentum_error"] == 0.0
        np.testing.assert_allclose(run.x, CENTER + np.outer(run.t, J), rtol=0, atol=1e-12)


def test_seed_euler_drifts_off_so3_where_rk4_quat_does_not(result):
    results = result.summary["results"]
    assert results["euler"]["max_orthogonality_error"] > 0.1
    assert results["rk4-quat"]["max_orthogonality_error"] < 1e-12


def test_summary_is_json_with_the_promised_keys(result):
    summary = json.loads(json.dumps(result.summary))
    assert summary["scenario"] == "prism-impulse"
    assert summary["h"] == 0.25
    assert summary["methods"] == ["euler", "rk4-quat", "rkmk4"]


def test_run_folder_has_summary_and_every_figure(result, tmp_path):
    folder = write_run_folder(result, tmp_path / "run")
    assert json.loads((folder / "summary.json").read_text())["mass"] == 1.0
    names = {name for name, _ in result.figures}
    assert names == {"snapshots.png", "drift.png", "rotation_grid.png"}
    for name in names:
        assert (folder / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("point", [(50.0, 10.0, 25.0), (50.0, 10.0, 10.0)])
def test_a_hit_point_off_the_surface_is_refused(point):
    with pytest.raises(ValueError, match="vertex="):
        scenarios.get("prism-impulse").run(vertex=point, t_end=0.5)


def test_a_hit_from_inside_the_prism_is_refused():
    with pytest.raises(ValueError, match="hit_from="):
        scenarios.get("prism-impulse").run(hit_from=(50.0, 10.0, 10.0), t_end=0.5)
