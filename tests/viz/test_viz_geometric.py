"""The long-run energy picture and the heavy top's pictures draw what they say."""

import numpy as np
import pytest
from PIL import Image

from tumble import RigidBody, simulate
from tumble.viz import rigid, top


@pytest.fixture(scope="module")
def runs():
    body = RigidBody(1.0, [2.0, 1.0, 2.0 / 3.0], allow_unphysical=True)
    L0 = (np.cos(1.1), 0.0, np.sin(1.1))
    return [(m, simulate(body, 200.0, method=m, h=0.1, L0=L0)) for m in ("split-axes", "rkmk4")]


def captured(monkeypatch, module):
    """Keep the figure a drawing function saves (and still write it)."""
    figures = []
    original = module.save

    def keep(fig, path, **kwargs):
        figures.append(fig)
        original(fig, path, **kwargs)

    monkeypatch.setattr(module, "save", keep)
    return figures


def test_energy_error_loglog_draws_the_running_maximum_on_log_axes(runs, tmp_path, monkeypatch):
    figures = captured(monkeypatch, rigid)
    rigid.energy_error_loglog(runs, tmp_path / "e.png", title="T")
    ax = figures[0].axes[0]
    assert ax.get_xscale() == ax.get_yscale() == "log"
    for line, (label, run) in zip(ax.get_lines(), runs, strict=True):
        assert line.get_label() == label
        expected = np.maximum.accumulate(np.abs(run.energy_error) / run.energy[0])[1:]
        np.testing.assert_allclose(line.get_xdata(), run.t[1:])
        np.testing.assert_allclose(line.get_ydata(), np.maximum(expected, rigid.LOG_FLOOR))
        assert np.all(np.diff(line.get_ydata()) >= 0)  # a running maximum never falls
    with Image.open(tmp_path / "e.png") as image:
        assert image.format == "PNG" and min(image.size) > 300


def test_top_motion_draws_theta_between_the_given_bounds(tmp_path, monkeypatch):
    from tumble.scenarios import spinning_top

    result = spinning_top.run(t_end=0.5, methods=("yoshida4",))
    figures = captured(monkeypatch, top)
    run = result.data["trajectories"]["yoshida4"]
    bounds = result.summary["theta_bounds_deg"]
    top.top_motion([("yoshida4", run)], bounds, tmp_path / "top.png", title="T", window=0.3)
    left, right = figures[0].axes
    theta = left.get_lines()[0]
    shown = run.t <= 0.3
    np.testing.assert_allclose(theta.get_xdata(), run.t[shown])
    np.testing.assert_allclose(theta.get_ydata(), np.degrees(np.arccos(run.R[shown, 2, 2])))
    levels = sorted(line.get_ydata()[0] for line in left.get_lines()[1:])
    np.testing.assert_allclose(levels, sorted(bounds))
    np.testing.assert_allclose(right.get_lines()[0].get_ydata(), run.R[shown, 1, 2])
