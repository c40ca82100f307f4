"""Observed orders on Hairer's body diag(2, 1, 2/3): seed 002's RK4 is order 2, RKMK4 order 4,
RKMK8 order 8."""

import json

import pytest

from tumble import scenarios
from tumble.io import write_run_folder
from tumble.scenarios.convergence import (
    CLAIMED_ORDERS,
    DEFAULT_METHODS,
    HIGH_ORDER_STEP_COUNTS,
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
