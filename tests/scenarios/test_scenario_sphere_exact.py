"""Seed 002 tasks 2–4: the unit sphere spun about x, every method against exp(t x̃)."""

import json

import numpy as np
import pytest
from rigid_roundoff import invariant_bound
from roundoff import error_bound

from tumble import exact, scenarios
from tumble.io import write_run_folder

# Seed 002, "Figur 18": eq. 24 (explicit Euler) at h = 0.1 on [0, 1], entries (R22, R32) of
# each of the 11 samples, printed by numpy to 8 decimals (the values are (1 + 0.1 i)^k).
SEED_EULER_TABLE = [
    (1.0, 0.0),
    (1.0, 0.1),
    (0.99, 0.2),
    (0.97, 0.299),
    (0.9401, 0.396),
    (0.9005, 0.49001),
    (0.851499, 0.58006),
    (0.793493, 0.6652099),
    (0.72697201, 0.7445592),
    (0.65251609, 0.8172564),
    (0.57079045, 0.88250801),
]


@pytest.fixture(scope="module")
def result():
    return scenarios.get("sphere-exact").run()


def _seed_matrix(c, s):
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def test_euler_reproduces_the_seed_table(result):
    run = result.data["trajectories"]["euler"]
    assert len(run.t) == 11
    expected = np.array([_seed_matrix(c, s) for c, s in SEED_EULER_TABLE])
    # 1e-8: the seed printed 8 decimals (rounding error ≤ 5e-9).
    np.testing.assert_allclose(run.R, expected, rtol=0, atol=1e-8)


def test_euler_end_matches_spec_section_4(result):
    assert result.summary["euler_vs_seed"] < 1e-8
    np.testing.assert_allclose(
        result.summary["euler_R_end"], _seed_matrix(0.57079045, 0.88250801), atol=1e-8
    )


def test_lie_euler_is_the_exact_rotation_to_round_off(result):
    run = result.data["trajectories"]["lie-euler"]
    assert len(run.t) == 11
    # ten products of exact rotations, a few ulps each: the walk of 10 steps' round-off and
    # the closed form's own (as in tests/rigid/test_rigid_methods.py)
    bound = 2 * invariant_bound("lie-euler", 10) + error_bound(3.0, 10)
    np.testing.assert_allclose(run.R, exact.sphere(run.t), rtol=0, atol=bound)


@pytest.mark.parametrize("method", ["seed-rk4", "rkmk4", "rkmk8", "rkmk45"])
def test_lie_algebra_methods_are_exact_because_commutators_vanish(result, method):
    bound = 2 * invariant_bound(method, 10) + error_bound(3.0, 10)  # as above
    assert result.summary["results"][method]["max_error"] < bound


@pytest.mark.parametrize("method", ["euler", "rk4-matrix"])
def test_matrix_methods_leave_so3_on_the_sphere(result, method):
    assert result.summary["results"][method]["max_orthogonality_error"] > 1e-8


def test_rk4_methods_are_close_but_not_exact(result):
    for method in ("rk4-matrix", "rk4-quat"):
        assert 1e-9 < result.summary["results"][method]["final_error"] < 1e-5


def test_summary_is_json_with_the_promised_keys(result):
    summary = json.loads(json.dumps(result.summary))
    assert summary["scenario"] == "sphere-exact"
    assert summary["h"] == 0.1
    assert summary["methods"] == list(scenarios.get("sphere-exact").METHODS)


def test_run_folder_has_summary_and_every_figure(result, tmp_path):
    folder = write_run_folder(result, tmp_path / "run")
    assert json.loads((folder / "summary.json").read_text())["scenario"] == "sphere-exact"
    for name, _ in result.figures:
        assert (folder / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert {name for name, _ in result.figures} == {
        "error_vs_exact.png",
        "rotation_grid.png",
        "drift.png",
    }


def test_no_methods_is_refused_by_name():
    with pytest.raises(ValueError, match="methods="):
        scenarios.get("sphere-exact").run(methods=())


def test_unknown_method_is_refused_by_name():
    with pytest.raises(ValueError, match="method='rk5'"):
        scenarios.get("sphere-exact").run(methods=("rk5",))
