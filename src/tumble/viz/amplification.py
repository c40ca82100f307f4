"""The time-step analyser's picture: spectral radius, damping, period error against Δt/T.

As in Chung & Hulbert (1993), Figs. 1–3: for each scheme, from
:func:`tumble.structural.amplification`, the spectral radius ρ, the algorithmic damping
ratio ξ̄ and the relative period elongation (T̄ − T)/T against ``Δt/T = Ω/(2π)`` on a log
axis. matplotlib is imported only when drawing (:mod:`tumble.viz._figure`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from tumble.viz._figure import new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from tumble.structural import Amplification

LIMITS = {"spectral_radius": (0.0, 1.25), "damping_ratio": (-0.05, 0.3),
          "period_elongation": (-0.1, 0.5)}  # fmt: skip
"""The y ranges shown: the region where schemes differ (beyond it a curve leaves the plot)."""

PERIOD_RANGE = (1e-2, 1.0)
"""Δt/T shown for the period error: past one step per period every scheme has lost the
period (Chung–Hulbert plot it up to 0.4)."""

LABELS = {
    "spectral_radius": "spectral radius ρ",
    "damping_ratio": "damping ratio ξ̄",
    "period_elongation": "period elongation (T̄ − T)/T",
}


def amplification_figure(analyses: Sequence[Amplification], *, title: str) -> Figure:
    """Three panels against ``Δt/T`` (log axis), one line per scheme.

    Parameters
    ----------
    analyses : sequence of Amplification
        The same ``Ω`` grid for every scheme is not required.
    title : str
        The figure's title.
    """
    fig, axes = new_figure(1, 3, figsize=(15.0, 4.6), layout="constrained")
    colours = [f"C{k}" for k in range(10)] + ["black", "grey"]
    styles = ["-", "--", "-.", ":"]
    for k, analysis in enumerate(analyses):
        ratio = analysis.omega / (2 * np.pi)
        style = {"color": colours[k % len(colours)], "linestyle": styles[k // 4 % 4], "lw": 1.6}
        for ax, name in zip(axes, LIMITS, strict=True):
            ax.semilogx(ratio, getattr(analysis, name), label=analysis.scheme, **style)
    for ax, (name, limits) in zip(axes, LIMITS.items(), strict=True):
        ax.set_ylim(*limits)
        ax.set_xlabel("Δt / T  (= ωΔt / 2π)")
        ax.set_title(LABELS[name])
        ax.grid(True, which="major", alpha=0.4)
    axes[0].axhline(1.0, color="0.3", lw=0.8)
    axes[1].axhline(0.0, color="0.3", lw=0.8)
    axes[2].axhline(0.0, color="0.3", lw=0.8)
    axes[2].set_xlim(*PERIOD_RANGE)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside right upper", fontsize="small", title="scheme")
    fig.suptitle(title)
    return fig
