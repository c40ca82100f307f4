"""A sweep's map: values over two swept dimensions, as heat maps side by side."""

from __future__ import annotations

from collections.abc import Collection, Sequence
from pathlib import Path

import numpy as np

from tumble.viz._figure import new_figure, save

LOG_FLOOR = 1e-16
"""Where a log colour scale draws a zero (round-off of a double)."""
FEW = 8
"""An axis with at most this many cells gets a tick on each."""


def _edges(values: np.ndarray) -> np.ndarray:
    """Cell edges around the coordinates (midpoints; half a step beyond the ends)."""
    if len(values) == 1:
        return np.array([values[0] - 0.5, values[0] + 0.5])
    middle = (values[1:] + values[:-1]) / 2
    return np.concatenate([[2 * values[0] - middle[0]], middle, [2 * values[-1] - middle[-1]]])


def _axis(labels: Sequence) -> tuple[np.ndarray, list[str] | None]:
    """Numbers for an axis; names (a swept method) are placed at 0, 1, 2, … and labelled."""
    array = np.asarray(labels)
    if array.dtype.kind in "iuf":
        return array.astype(float), None
    return np.arange(len(array), dtype=float), [str(label) for label in array]


def _limits(panels, log: Collection[str]) -> dict[str, tuple[float, float]]:
    """The colour range of each colour label, over every panel that has it."""
    limits = {}
    for label in {label for _, _, label in panels}:
        values = np.concatenate(
            [v[np.isfinite(v)].ravel() for _, v, lab in panels if lab == label]
        )
        if label in log:
            values = values[values > 0]
        limits[label] = (values.min(), values.max()) if values.size else (LOG_FLOOR, 1.0)
    return limits


def heat_maps(
    panels: Sequence[tuple[str, np.ndarray, str]],
    x: Sequence,
    y: Sequence,
    path: str | Path,
    *,
    xlabel: str,
    ylabel: str,
    title: str,
    log: Collection[str] = (),
) -> None:
    """Heat maps of values over ``(y, x)``, one panel each, side by side.

    Parameters
    ----------
    panels : sequence of (str, ndarray (len(y), len(x)), str)
        Each panel's title, values and colour-bar label (with units). Panels with the same
        label share one colour scale, so they can be compared cell by cell. NaN cells (a
        run that failed, a period not seen) are left white.
    x, y : sequence
        The coordinates of the two swept dimensions (numbers, or names for a method).
    path : str or Path
        Output PNG.
    xlabel, ylabel : str
        The axes' names with units.
    title : str
        Figure title.
    log : collection of str
        Colour labels drawn on a logarithmic scale (errors spanning decades); zeros are
        drawn at :data:`LOG_FLOOR`.
    """
    from matplotlib.colors import LogNorm

    xs, xnames = _axis(x)
    ys, ynames = _axis(y)
    panels = [
        (name, np.where(values > 0, values, LOG_FLOOR) if label in log else values, label)
        for name, values, label in panels
    ]
    limits = _limits(panels, log)
    fig, axes = new_figure(1, len(panels), figsize=(4.6 * len(panels) + 0.8, 4.2), squeeze=False)
    for ax, (name, values, label) in zip(axes[0], panels, strict=True):
        low, high = limits[label]
        scale = {"norm": LogNorm(low, high)} if label in log else {"vmin": low, "vmax": high}
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(values),
                             cmap="viridis", **scale)  # fmt: skip
        ax.set_title(name, fontsize=10)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        for axis, places, names in ((ax.xaxis, xs, xnames), (ax.yaxis, ys, ynames)):
            if names is not None:
                axis.set_ticks(places, names)
            elif len(places) <= FEW:  # a tick on each cell
                axis.set_ticks(places, [f"{value:.4g}" for value in places])
        fig.colorbar(mesh, ax=ax, label=label)
    fig.suptitle(title)
    fig.tight_layout()
    save(fig, path)
