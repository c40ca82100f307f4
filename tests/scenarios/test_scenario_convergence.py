"""Observed orders on Hairer's body diag(2, 1, 2/3): seed 002's RK4 is order 2, RKMK4 order 4,
RKMK8 order 8."""

import json

import numpy as np
import pytest

from tumble import scenarios
from tumble.io import write_run_folder
from tumble.scenarios.convergence import (
    CLAIMED_ORDERS,
    DEFAULT_METHODS,
    HIGH_ORDER_STEP_COUNTS,
    ROUND_OFF_FLOOR,
    final_errors,
)


@pytest.fixture(scope="module")
def result():
    # h = 10/200 … 10/800: every method in its asymptotic range, the fourth-order ones
    # still far above round-off (rkmk4 reaches 3.6e-10).
    return scenarios.get("convergence").run(step_counts=(200, 400, 800))


@pytest.mark.parametrize("method", DEFAULT_METHODS)
def test_observed_order_is_the_claimed_one(result, method):
    measured = result.summary["results"][method]
    assert measured["observed_order"] == pytest.approx(CLAIMED_ORDERS[method], abs=0.25), (
        f"{method}: slope {measured['observed_order']:.3f}, errors {measured['errors']}"
    )


def test_rkmk8_is_eighth_order_on_its_coarser_steps():
    # h = 0.5 … 0.2: errors 7.7e-10 … 4.8e-13, far above round-off (1e-15); slope 8.03.
    result = scenarios.get("convergence").run(step_counts=HIGH_ORDER_STEP_COUNTS, methods="rkmk8")
    measured = result.summary["results"]["rkmk8"]
    assert measured["claimed_order"] == CLAIMED_ORDERS["rkmk8"] == 8
    assert measured["observed_order"] == pytest.approx(8, abs=0.2), measured["errors"]
    assert measured["errors"][-1] < 2e-12  # measured 4.8e-13


def test_halving_h_divides_the_rkmk4_error_by_16_and_the_seed_rk4_error_by_4(result):
    results = result.summary["results"]
    assert results["rkmk4"]["last_halving_ratio"] == pytest.approx(16.0, rel=0.05)
    assert results["seed-rk4"]["last_halving_ratio"] == pytest.approx(4.0, rel=0.05)


def test_summary_is_json_with_the_promised_keys(result):
    summary = json.loads(json.dumps(result.summary))
    assert summary["scenario"] == "convergence"
    assert summary["h"] == pytest.approx([0.05, 0.025, 0.0125])
    assert summary["methods"] == list(DEFAULT_METHODS)


def test_run_folder_has_summary_and_the_plot(result, tmp_path):
    folder = write_run_folder(result, tmp_path / "run")
    assert json.loads((folder / "summary.json").read_text())["t_end"] == 10.0
    assert [name for name, _ in result.figures] == ["convergence.png"]
    assert (folder / "convergence.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_single_step_count_is_refused_by_name():
    with pytest.raises(ValueError, match="step_counts="):
        scenarios.get("convergence").run(step_counts=(100, 100))


@pytest.mark.parametrize("methods", ["rkmk45", ("rkmk4", "rkmk45")])
def test_an_adaptive_method_is_refused_naming_methods_and_the_fixed_step_ones(methods):
    with pytest.raises(
        ValueError,
        match=r"methods=.* is not allowed: must be .*\['euler'.*'rkmk8'.*'dmv'.*\]; "
        r"'rkmk45' is adaptive",
    ):
        scenarios.get("convergence").run(methods=methods)


def test_an_unknown_method_is_refused_naming_methods():
    with pytest.raises(
        ValueError,
        match=r"methods=\('rk9',\) is not allowed: .*; 'rk9' is not a rigid-body method",
    ):
        scenarios.get("convergence").run(methods=["rk9"])


def test_final_errors_refuses_an_adaptive_method_by_name():
    with pytest.raises(
        ValueError, match=r"method='rkmk45' is not allowed: .*; 'rkmk45' is adaptive"
    ):
        final_errors("rkmk45", [0.1, 0.05])


@pytest.fixture(scope="module")
def round_off():
    # h = 0.05 … 0.0125: every rkmk8 error is round-off (5e-15 … 8e-15); a slope through
    # them (0.11) would be meaningless.
    return scenarios.get("convergence").run(step_counts=(200, 400, 800), methods="rkmk8")


def test_rkmk8_at_round_off_has_no_observed_order(round_off):
    measured = round_off.summary["results"]["rkmk8"]
    assert max(measured["errors"]) < ROUND_OFF_FLOOR
    assert measured["observed_order"] is None and measured["fitted"] == 0
    assert "round-off" in measured["note"]
    assert "step_counts=(20, 25, 32, 40, 50)" in measured["note"]


def test_a_method_at_round_off_writes_its_run_folder_with_a_nan_order(round_off, tmp_path):
    folder = write_run_folder(round_off, tmp_path / "run")
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["results"]["rkmk8"]["observed_order"] is None
    assert (folder / "convergence.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert np.isnan(round_off.datasets[""]["observed_order"].sel(method="rkmk8").item())


def test_round_off_errors_are_left_out_of_the_fit():
    # h = 1 … 1/16: errors 2.9e-7, 7.7e-10, 2.8e-12 above the floor; 1.2e-14 and 3.2e-15
    # below it. Through all five the slope would be 6.5; through the three, 8.3.
    result = scenarios.get("convergence").run(step_counts=(10, 20, 40, 80, 160), methods="rkmk8")
    measured = result.summary["results"]["rkmk8"]
    assert measured["fitted"] == 3 and "2 of 5 errors" in measured["note"]
    assert measured["observed_order"] == pytest.approx(8, abs=0.5)


def test_methods_above_round_off_are_fitted_through_every_error(result):
    for method in DEFAULT_METHODS:
        measured = result.summary["results"][method]
        assert (measured["fitted"], measured["note"]) == (3, None), method
