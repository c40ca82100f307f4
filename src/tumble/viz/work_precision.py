"""The work–precision diagram: error against cost, one curve per method.

Draws the points of :func:`tumble.rigid.work_precision.work_precision` on two log–log panels,
error against wall time and error against the number of steps. matplotlib is imported only
when a figure is drawn (through :mod:`tumble.viz._figure`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tumble import _checks
from tumble.viz._figure import new_figure, save

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from tumble.rigid.work_precision import WorkPrecisionPoint

ERROR_FLOOR = 1e-17
"""Errors at or below this (an exact result) are drawn here, on the log axis."""
_MARKERS = ("o", "s", "^", "v", "D", "P", "X", "*")


def draw_work_precision(points: Sequence[WorkPrecisionPoint], *, title: str) -> Figure:
    """The work–precision figure: ``‖R(T) − R_exact(T)‖_F`` against wall time and steps.

    One line with markers per method, its points in order of cost; errors that are not
    finite (a run that diverged) are left out, errors at or below :data:`ERROR_FLOOR` are
    drawn at the floor.

    Parameters
    ----------
    points : sequence of WorkPrecisionPoint
        From :func:`tumble.rigid.work_precision.work_precision`.
    title : str
        Names the scenario (body, ``t_end``, ``ω₀``).

    Returns
    -------
    Figure
        Two axes: error against wall time (s), error against accepted steps.
    """
    if len(points) == 0:
        raise _checks.fail(
            "points", points, "at least one point", remedy="pass the result of work_precision(...)"
        )
    figure, (by_time, by_steps) = new_figure(1, 2, figsize=(12.5, 4.6), layout="constrained")
    methods = list(dict.fromkeys(point.method for point in points))
    palette = "tab20" if len(methods) > 10 else "tab10"  # one colour per method
    colours = _colours(palette, len(methods))
    for index, method in enumerate(methods):
        mine = sorted((p for p in points if p.method == method), key=lambda p: p.steps)
        error = np.array([p.error for p in mine], dtype=float)
        shown = np.isfinite(error)
        error = np.maximum(error, ERROR_FLOOR)[shown]
        style = {"marker": _MARKERS[index % len(_MARKERS)], "color": colours[index], "ms": 5}
        seconds = np.array([p.seconds for p in mine])[shown]
        steps = np.array([p.steps for p in mine])[shown]
        by_time.loglog(seconds, error, label=f"{method} ({mine[0].setting_name})", **style)
        by_steps.loglog(steps, error, **style)
    by_time.set_xlabel("wall time (s), best of repeats")
    by_steps.set_xlabel("accepted steps (–)")
    for axes in (by_time, by_steps):
        axes.set_ylabel("‖R(T) − R_exact(T)‖_F (–)")
        axes.grid(alpha=0.3, which="both")
        _sparse_log_ticks(axes.xaxis)
    figure.legend(
        loc="outside right upper", fontsize=8, title="method (varied)", title_fontsize=8
    )  # beside the panels: inside, fifteen methods hide the fastest points
    figure.suptitle(title)
    return figure


def _colours(palette: str, count: int) -> list:
    """``count`` distinct colours of a qualitative matplotlib palette (repeating past its end)."""
    from matplotlib import colormaps

    colours = colormaps[palette].colors  # type: ignore[attr-defined]  # a ListedColormap
    return [colours[k % len(colours)] for k in range(count)]


def _sparse_log_ticks(axis) -> None:
    """Label decades (and 2, 5 within a decade when the data span less than ~two), never the
    minor ticks: matplotlib's default labels every minor tick of a short log axis, and
    their labels run into each other."""
    from matplotlib.ticker import LogFormatterSciNotation, LogLocator, NullFormatter

    low, high = axis.axes.dataLim.intervalx
    subs = (1.0,) if high / low > 100 else (1.0, 2.0, 5.0)
    axis.set_major_locator(LogLocator(base=10, subs=subs))
    axis.set_major_formatter(LogFormatterSciNotation(labelOnlyBase=False))
    axis.set_minor_formatter(NullFormatter())


def work_precision_figure(
    points: Sequence[WorkPrecisionPoint], path: str | Path, *, title: str
) -> Path:
    """Write :func:`draw_work_precision` of ``points`` as an image (PNG by suffix) at ``path``."""
    save(draw_work_precision(points, title=title), path)
    return Path(path)
