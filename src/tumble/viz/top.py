"""The heavy top's picture: nutation between its classical bounds, and the apex's path.

:func:`top_motion` draws one PNG through :mod:`tumble.viz._figure`: on the left the angle θ
between the symmetry axis and the vertical against time, for each run, between the two
dashed lines of the classical bounds (the roots of the cubic in ``cos θ``); on the right the
path of the axis's tip seen from above, ``(R e₃)_x`` against ``(R e₃)_y``, whose loops or
cusps are the nutation riding on the precession.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tumble.viz._figure import new_figure, save

if TYPE_CHECKING:
    from tumble.rigid.trajectory import Trajectory

_LINESTYLES = ("-", "--", "-.", ":")


def top_motion(
    runs: Sequence[tuple[str, Trajectory]],
    bounds_deg: Sequence[float],
    path: str | Path,
    *,
    title: str,
    axis: int = 2,
    window: float | None = None,
) -> None:
    """Nutation θ(t) with its bounds, and the apex path from above (module docstring).

    Parameters
    ----------
    runs : sequence of (label, Trajectory)
        The runs to draw, one colour each.
    bounds_deg : sequence of two floats
        The classical nutation bounds θ_min, θ_max (degrees), drawn dashed.
    path : str or Path
        Where the PNG goes.
    title : str
        The figure's title.
    axis : int
        The body's symmetry axis (default 2: z).
    window : float, optional
        Draw only the first ``window`` seconds (say, one turn of the precession), so that
        the loops do not pile up; the whole run by default.
    """
    fig, (left, right) = new_figure(1, 2, figsize=(11.0, 4.6))
    for index, (label, run) in enumerate(runs):
        shown = slice(None) if window is None else run.t <= run.t[0] + window
        apex = run.R[shown, :, axis]  # R e_axis in world coordinates
        theta = np.degrees(np.arccos(np.clip(apex[:, 2], -1.0, 1.0)))
        style = {"color": f"C{index % 10}", "linestyle": _LINESTYLES[index % 4], "lw": 1.2}
        left.plot(run.t[shown], theta, label=label, **style)
        right.plot(apex[:, 0], apex[:, 1], label=label, **style)
    for k, bound in enumerate(bounds_deg):
        left.axhline(bound, color="0.3", lw=0.9, ls=(0, (4, 3)),
                     label="classical bounds" if k == 0 else None)  # fmt: skip
    span = max(bounds_deg) - min(bounds_deg)
    left.set_ylim(min(bounds_deg) - 0.15 * span, max(bounds_deg) + 0.25 * span)
    left.set_xlabel("t (s)")
    left.set_ylabel("nutation θ (deg), axis against the vertical")
    left.legend(loc="upper right", fontsize=8, ncol=2)
    left.grid(alpha=0.3)
    right.set_aspect("equal", adjustable="datalim")
    right.set_xlabel("axis tip, x (unit sphere)")
    right.set_ylabel("axis tip, y (unit sphere)")
    right.set_title("the axis seen from above", fontsize=10)
    right.grid(alpha=0.3)
    fig.suptitle(title, fontsize=11, y=1.03)
    save(fig, path)


def top_invariants(
    runs: Sequence[tuple[str, Trajectory]],
    pivot_world: np.ndarray,
    path: str | Path,
    *,
    title: str,
    axis: int = 2,
) -> None:
    """The heavy top's three invariants against time, on log axes, one panel each.

    ``|E − E₀|/|E₀|`` (total energy), ``|L_z − L_z₀|/|L₀|`` (vertical angular momentum about
    the pivot at ``pivot_world``) and ``|L₃ − L₃₀|/|L₃₀|`` (its component along the body's
    symmetry ``axis``). Round-off zeros are drawn at the floor of :mod:`tumble.viz.rigid`.
    """
    from tumble.viz.rigid import _floored, _note_floor

    fig, axes = new_figure(3, 1, figsize=(9.0, 7.6), sharex=True)
    names = ("|E − E₀| / |E₀|", "|L_z − L_z₀| / |L₀|, about the pivot", "|L₃ − L₃₀| / |L₃₀|")
    floored = [False, False, False]
    for index, (label, run) in enumerate(runs):
        L = run.angular_momentum_about(pivot_world)
        L_3 = np.einsum("nji,nj->ni", run.R, L)[:, axis]
        with np.errstate(all="ignore"):
            series = (
                np.abs(run.energy - run.energy[0]) / abs(run.energy[0]),
                np.abs(L[:, 2] - L[0, 2]) / np.linalg.norm(L[0]),
                np.abs(L_3 - L_3[0]) / abs(L_3[0]),
            )
        style = {"color": f"C{index % 10}", "linestyle": _LINESTYLES[index % 4], "lw": 1.1}
        for k, (ax, values) in enumerate(zip(axes, series, strict=True)):
            shown, low = _floored(values)
            floored[k] = floored[k] or low
            ax.semilogy(run.t, shown, label=label, **style)
    for ax, name, low in zip(axes, names, floored, strict=True):
        ax.set_ylabel(name, fontsize=9)
        ax.grid(alpha=0.3)
        if low:
            _note_floor(ax)
    axes[0].legend(loc="lower right", fontsize=8, ncol=len(runs))
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(title, fontsize=11)
    save(fig, path)
