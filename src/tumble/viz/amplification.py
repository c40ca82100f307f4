"""The time-step analyser's pictures: ρ, damping and period error against Δt/T; the
schemes against the exact response over time.

As in Chung & Hulbert (1993), Figs. 1–3: for each scheme, from
:func:`tumble.structural.amplification`, the spectral radius ρ, the algorithmic damping
ratio ξ̄ and the relative period elongation (T̄ − T)/T against ``Δt/T = Ω/(2π)`` on a log
axis. matplotlib is imported only when drawing (:mod:`tumble.viz._figure`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from tumble.viz._figure import new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from tumble.structural import Amplification, LinearSystem, Response

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


def comparison_figure(
    system: LinearSystem,
    runs: Mapping[str, Response],
    exact: Response,
    *,
    title: str,
) -> Figure:
    """Each scheme against the exact response over time: tip error, energy, high modes.

    Panels: ``|x_tip − x_tip,exact| / δ`` with ``δ`` the static tip deflection; the total
    energy change ``(E − E₀)`` over :func:`~tumble.structural.energy_scale`; and the energy
    in the upper half of the modes (:func:`~tumble.structural.modal_energies`) over its
    exact, constant value, on a log axis. Every run must share ``exact.t``.
    """
    from tumble import structural

    fig, axes = new_figure(1, 3, figsize=(15.0, 4.6), layout="constrained")
    static = system.static_displacement()[system.tip_dof]
    scale = structural.energy_scale(system)
    half = system.n_dofs // 2
    reference = structural.modal_energies(system, exact.x, exact.y)[:, half:].sum(axis=1)
    colours = [f"C{k}" for k in range(10)]
    for k, (name, run) in enumerate(runs.items()):
        # alternate solid and dashed, so that schemes with the same trajectory both show
        style = {"color": colours[k % 10], "lw": 1.4, "label": name, "ls": "-" if k % 2 else "--"}
        error = np.abs(run.tip_displacement - exact.tip_displacement) / abs(static)
        axes[0].semilogy(run.t, np.maximum(error, 1e-17), **style)
        axes[1].plot(run.t, (run.energy - run.energy[0]) / scale, **style)
        upper = structural.modal_energies(system, run.x, run.y)[:, half:].sum(axis=1)
        axes[2].semilogy(run.t, np.maximum(upper / reference, 1e-30), **style)
    axes[0].set_title("tip error / static tip deflection")
    axes[1].set_title("energy change (E − E₀) / energy scale")
    axes[2].set_title(f"energy in modes {half + 1}–{system.n_dofs} / exact")
    for ax in axes:
        ax.set_xlabel("t [s]")
        ax.grid(True, alpha=0.4)
    axes[0].set_ylim(1e-6, 3)
    axes[2].set_ylim(1e-22, 10)  # the modal split's round-off floor is about 1e-19 here
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside right upper", fontsize="small", title="scheme")
    fig.suptitle(title)
    return fig
