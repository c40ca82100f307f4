"""The `beam` scenario and the structural pictures."""

import json

import numpy as np
import pytest

from tumble import structural
from tumble.scenarios import beam as scenario
from tumble.viz import structural as viz

SMALL = {"n_elements": 8, "n_steps": 200, "sweep_steps": 300}


@pytest.fixture(scope="module")
def result():
    return scenario.run(**SMALL)


def test_scenario_declares_name_and_summary():
    assert scenario.NAME == "beam"
    assert isinstance(scenario.SUMMARY, str) and "\n" not in scenario.SUMMARY


def test_summary_is_json_and_carries_the_frequencies(result):
    summary = json.loads(json.dumps(result.summary, allow_nan=False))
    # 8 elements: FE error 2e-6 for ω₁ (h⁴), 5e-3 for ω₄
    np.testing.assert_allclose(summary["omega"], summary["omega_exact"], rtol=5e-3)
    assert abs(summary["omega_relative_error"][0]) < 1e-5


def test_summary_reports_each_seed_scheme(result):
    schemes = result.summary["schemes"]
    assert list(schemes) == list(structural.SEED_SCHEMES)
    # Δt = T₁/200 is far above 2/ω_max: the two explicit schemes blow up (None: diverged)
    for name in ("explicit", "semi-implicit"):
        growth = schemes[name]["energy_change_max"]
        assert growth is None or growth > 1e3, (name, growth)
    assert schemes["midpoint"]["energy_change_max"] < 1e-9
    assert schemes["implicit"]["energy_change_final"] < 0


def test_sweep_brackets_the_semi_implicit_limit(result):
    sweep = result.summary["sweep"]["semi-implicit"]
    limit = result.summary["critical_dt_semi_implicit"]
    np.testing.assert_array_equal(sweep["stable"], np.array(sweep["dt"]) < limit)


def test_frames_are_every_tenth_step_on_all_dofs(result):
    frames = result.data["frames"]
    system = result.data["system"]
    assert frames["x"].shape == (SMALL["n_steps"] // 10 + 1, system.n_all_dofs)
    np.testing.assert_allclose(np.diff(frames["t"]), 10 * result.summary["dt"])


def test_every_figure_writer_draws_a_png(result, tmp_path):
    names = [name for name, _ in result.figures]
    assert names == [
        "energy_explicit.png",
        "energy_semi-implicit.png",
        "energy_implicit.png",
        "energy_midpoint.png",
        "stability_sweep.png",
        "beam_shapes.png",
    ]
    for name, write in result.figures:
        write(tmp_path / name)
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_beam_frames_are_rgb_images_that_move(result):
    system, frames = result.data["system"], result.data["frames"]
    free = frames["x"][:3][:, system.free]
    images = viz.beam_frames(
        system, frames["t"][:3], free, title="beam — midpoint", size=(320, 200)
    )
    assert len(images) == 3
    assert all(image.shape == (200, 320, 3) and image.dtype == np.uint8 for image in images)
    assert np.any(images[0] != images[2])  # the beam has moved between t = 0 and 20 Δt


def test_bad_option_value_is_named():
    with pytest.raises(ValueError, match=r"n_steps=0 is not allowed: must be an integer >= 1"):
        scenario.run(n_steps=0)
