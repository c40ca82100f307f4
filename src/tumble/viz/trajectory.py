"""Trajectory pictures."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tumble.viz._figure import new_figure, save


def projectile_figure(
    t: np.ndarray, x: np.ndarray, z: np.ndarray, summary: dict, path: str | Path
) -> None:
    """Draw a planar trajectory with the impact point marked, to ``path`` (PNG).

    Parameters
    ----------
    t, x, z : ndarray, shape (m,)
        Times (s), horizontal and vertical positions (m).
    summary : dict
        Needs ``impact_time``, ``range``, ``method`` and ``h``.
    path : str or Path
        Output file.
    """
    fig, ax = new_figure(figsize=(7, 3.8))
    ax.plot(x / 1000, z / 1000, lw=1.5, label="trajectory")
    ax.plot(summary["range"] / 1000, 0, "o", color="C3", label="impact (event)")
    ax.annotate(
        f"t = {summary['impact_time']:.6f} s\nx = {summary['range']:.4f} m",
        (summary["range"] / 1000, 0),
        textcoords="offset points",
        xytext=(-110, 25),
        arrowprops={"arrowstyle": "->"},
    )
    ax.set_xlabel("horizontal distance x (km)")
    ax.set_ylabel("height z (km)")
    ax.set_title(f"projectile — {summary['method']}, h = {summary['h']} s")
    ax.set_ylim(bottom=min(0.0, float(np.min(z)) / 1000) - 0.2)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right")
    save(fig, path)
