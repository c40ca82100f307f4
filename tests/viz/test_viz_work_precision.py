"""Work–precision: the measurements (tumble.rigid.work_precision) and their figure."""

import numpy as np
import pytest

from tumble.exact import free_body_rotation
from tumble.rigid import RigidBody, simulate
from tumble.rigid.work_precision import WorkPrecisionPoint, table, work_precision
from tumble.viz.work_precision import draw_work_precision, work_precision_figure

OMEGA0 = (0.2, 0.0, 1.3)
T_END = 10.0


@pytest.fixture(scope="module")
def body():
    """Hairer–Lubich–Wanner's asymmetric test body (no real mass has these moments)."""
    return RigidBody(1.0, [2.0, 1.0, 2.0 / 3.0], allow_unphysical=True)


@pytest.fixture(scope="module")
def points(body):
    methods = ["rkmk4", "lie-euler", "rkmk45"]
    return work_precision(
        body, T_END, methods, omega0=OMEGA0, steps=(50, 100, 200), tolerances=(1e-4, 1e-6, 1e-8),
        repeat=2,
    )  # fmt: skip


def _of(points, method):
    return [point for point in points if point.method == method]


def test_rkmk4_error_falls_sixteenfold_when_the_steps_double(points):
    errors = np.array([point.error for point in _of(points, "rkmk4")])
    ratios = errors[:-1] / errors[1:]
    # order 4: 2⁴ = 16 per halving of h; ±50 % allows for the pre-asymptotic range
    assert np.all((ratios > 16 / 1.5) & (ratios < 16 * 1.5)), ratios


def test_lie_euler_error_halves_when_the_steps_double(points):
    errors = np.array([point.error for point in _of(points, "lie-euler")])
    ratios = errors[:-1] / errors[1:]
    assert np.all((ratios > 2 / 1.5) & (ratios < 2 * 1.5)), ratios


def test_fixed_step_points_count_the_steps_asked_for(points):
    fixed = _of(points, "rkmk4")
    assert [point.steps for point in fixed] == [50, 100, 200]
    assert [point.rejected for point in fixed] == [0, 0, 0]
    np.testing.assert_allclose([point.setting for point in fixed], [0.2, 0.1, 0.05])
    assert {point.setting_name for point in fixed} == {"h"}


def test_rkmk45_takes_more_steps_and_errs_less_at_tighter_tolerances(points):
    adaptive = _of(points, "rkmk45")
    assert [point.setting for point in adaptive] == [1e-4, 1e-6, 1e-8]
    assert np.all(np.diff([point.steps for point in adaptive]) > 0)
    assert np.all(np.diff([point.error for point in adaptive]) < 0)
    assert adaptive[0].setting_name == "rtol"


def test_error_is_the_frobenius_distance_to_the_exact_attitude(body, points):
    run = simulate(body, T_END, method="rkmk4", h=T_END / 100, omega0=OMEGA0)
    expected = np.linalg.norm(run.R[-1] - free_body_rotation(body.inertia, OMEGA0, T_END))
    assert _of(points, "rkmk4")[1].error == pytest.approx(expected, rel=1e-12)


def test_every_run_is_timed(points):
    assert all(0 < point.seconds < 10 for point in points)


def test_table_has_one_row_per_point_naming_the_setting(points):
    rows = table(points)
    assert len(rows) == len(points)
    assert rows[0]["method"] == "rkmk4" and rows[0]["setting_name"] == "h"
    assert rows[0]["steps"] == 50 and rows[0]["error"] == points[0].error


def test_empty_methods_are_refused(body):
    with pytest.raises(ValueError, match="methods"):
        work_precision(body, 1.0, [], omega0=OMEGA0)


def test_empty_steps_are_refused_for_a_fixed_step_method(body):
    with pytest.raises(ValueError, match="steps"):
        work_precision(body, 1.0, ["rkmk4"], omega0=OMEGA0, steps=())


def test_unknown_method_is_refused(body):
    with pytest.raises(ValueError, match="'rk5'"):
        work_precision(body, 1.0, ["rk5"], omega0=OMEGA0)


def test_figure_has_two_log_panels_with_units_and_one_line_per_method(points):
    figure = draw_work_precision(points, title="free body, T = 10 s")
    by_time, by_steps = figure.axes[:2]
    assert "(s)" in by_time.get_xlabel()
    assert "steps" in by_steps.get_xlabel()
    for axes in (by_time, by_steps):
        assert "R_exact" in axes.get_ylabel() and "(–)" in axes.get_ylabel()
        assert axes.get_xscale() == axes.get_yscale() == "log"
        assert len(axes.get_lines()) == 3
    labels = [text.get_text() for text in figure.legends[0].get_texts()]  # beside the panels
    assert labels == ["rkmk4 (h)", "lie-euler (h)", "rkmk45 (rtol)"]
    assert figure.get_suptitle() == "free body, T = 10 s"


def test_figure_is_written_as_a_png(tmp_path, points):
    path = work_precision_figure(points, tmp_path / "work_precision.png", title="free body")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_figure_leaves_out_a_diverged_run():
    points = [WorkPrecisionPoint("euler", 0.5, 2, 0, 1e-4, np.inf),
              WorkPrecisionPoint("euler", 0.25, 4, 0, 2e-4, 0.5)]  # fmt: skip
    (line,) = draw_work_precision(points, title="t").axes[1].get_lines()
    np.testing.assert_array_equal(line.get_xdata(), [4])


def test_figure_of_no_points_is_refused():
    with pytest.raises(ValueError, match="points"):
        draw_work_precision([], title="t")


def _tick_labels_overlap(figure) -> list[str]:
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    clashes = []
    for axes in figure.axes:
        for axis in (axes.xaxis, axes.yaxis):
            boxes = [
                (label.get_text(), label.get_window_extent(renderer))
                for label in axis.get_ticklabels(which="both")
                if label.get_visible() and label.get_text()
            ]
            for k, (text, box) in enumerate(boxes):
                clashes += [f"{text} / {other}" for other, b in boxes[k + 1 :] if box.overlaps(b)]
    return clashes


@pytest.mark.parametrize("span", [1.5, 3.0, 30.0, 1e4])
def test_tick_labels_never_overlap_whatever_the_time_span(span):
    # The time axis of a fast run covers less than a decade; matplotlib's default labelled
    # each of its minor ticks there, and the labels ran into each other.
    points = [
        WorkPrecisionPoint(
            method, 0.1 / 2**k, 100 * 2**k, 0, 2e-4 * span ** (k / 3), 10.0 ** -(k + i)
        )
        for i, method in enumerate(["rkmk4", "rk4-quat", "lie-euler"])
        for k in range(4)
    ]
    assert _tick_labels_overlap(draw_work_precision(points, title="span")) == []


def test_every_method_gets_its_own_colour():
    from tumble.rigid import METHODS

    points = [WorkPrecisionPoint(name, 0.1, 100, 0, 1e-4, 1e-6) for name in METHODS]
    figure = draw_work_precision(points, title="every method")
    colours = {tuple(np.atleast_1d(line.get_color())) for line in figure.axes[0].lines}
    assert len(colours) == len(METHODS)
