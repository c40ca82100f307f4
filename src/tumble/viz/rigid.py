"""Rigid-body pictures: R(t) grids, Euler angles, drift, long-run energy error, error against
an exact solution, convergence, body rates and 3D snapshots.

Every function draws one PNG at ``path`` through :mod:`tumble.viz._figure` (matplotlib on the
Agg backend, imported only when a picture is drawn). Curves are passed as plain tuples, one per
method or initial condition, so the callers decide what is compared:

* ``(label, t, R)`` with ``t`` shape (n,) in s and ``R`` shape (n, 3, 3);
* ``(label, t, values)`` with ``values`` shape (n,) or (n, 3).

Quantities that are conserved to round-off are drawn on log axes; values at or below
:data:`LOG_FLOOR` (exact zeros included) are drawn at the floor, and the panel says so; values
above :data:`LOG_CEILING` (a run that diverged, such as explicit Euler overflowing) are not
drawn, so the curve ends where the run blew up.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tumble.viz._figure import new_figure, save

if TYPE_CHECKING:
    from tumble.rigid.trajectory import Trajectory

LOG_FLOOR = 1e-17
"""Smallest value drawn on a log axis; smaller ones (and zeros) are drawn here."""
LOG_CEILING = 1e30
"""Largest value drawn on a log axis; larger ones (a diverged run) are left out."""
SPARSE_SAMPLES = 50
"""Curves with at most this many samples are drawn with a marker at each sample."""
_LINESTYLES = ("-", "--", "-.", ":")
_ANGLE_NAMES = ("φ (about z)", "θ (about y)", "ψ (about x)")
_OMEGA_NAMES = ("ω_x", "ω_y", "ω_z")

Curve = tuple[str, np.ndarray, np.ndarray]


def _style(index: int) -> dict:
    """Colour and line style of the index-th curve (overlapping curves stay visible)."""
    return {"color": f"C{index % 10}", "linestyle": _LINESTYLES[index % len(_LINESTYLES)]}


def _floored(values: np.ndarray) -> tuple[np.ndarray, bool]:
    """Values for a log axis: non-finite and diverged ones masked, tiny ones floored.

    Also says whether any value after the first was floored (the first sample of a drift or
    an error is zero by construction and needs no note).
    """
    values = np.array(values, dtype=float)
    values[~(np.abs(values) <= LOG_CEILING)] = np.nan
    floored = bool(np.any(values[1:] <= LOG_FLOOR))
    return np.where(values <= LOG_FLOOR, LOG_FLOOR, values), floored


def _note_floor(ax) -> None:
    """Say, in the right margin of ``ax``, that tiny values are drawn at the floor."""
    ax.text(
        1.008,
        0.5,
        f"≤ {LOG_FLOOR:g} (and 0) drawn at {LOG_FLOOR:g}",
        transform=ax.transAxes,
        rotation=90,
        ha="left",
        va="center",
        fontsize=7,
        color="0.35",
    )


def _figure_legend(fig, ax, columns: int) -> None:
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=max(1, min(columns, 4)), frameon=False)


def rotation_grid(curves: Sequence[Curve], path: str | Path, *, title: str) -> None:
    """The nine entries ``R_ij(t)``, one panel each, the curves overlaid.

    Parameters
    ----------
    curves : sequence of (str, ndarray (n,), ndarray (n, 3, 3))
        Label, times (s) and attitudes (body to world) of each method or run.
    path : str or Path
        Output PNG.
    title : str
        Figure title (scenario and method).
    """
    fig, axes = new_figure(3, 3, figsize=(10, 7.6), sharex=True, sharey=True)
    for index, (label, t, R) in enumerate(curves):
        marker = "." if len(t) <= SPARSE_SAMPLES else None
        for i in range(3):
            for j in range(3):
                axes[i, j].plot(
                    t, R[:, i, j], lw=1.1, marker=marker, ms=3, label=label, **_style(index)
                )
    for i in range(3):
        for j in range(3):
            ax = axes[i, j]
            ax.set_title(f"$R_{{{i + 1}{j + 1}}}$", fontsize=10)
            ax.grid(alpha=0.3)
        axes[i, 0].set_ylabel("entry (–)")
        axes[2, i].set_xlabel("t (s)")
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    _figure_legend(fig, axes[0, 0], len(curves))
    save(fig, path)


def _unwrapped_degrees(angles: np.ndarray) -> np.ndarray:
    """Angles in degrees with a gap (NaN) where they wrap past ±180°, so no vertical lines."""
    degrees = np.degrees(angles)
    jumps = np.abs(np.diff(degrees, axis=0)) > 180.0
    degrees[1:][jumps] = np.nan
    return degrees


def euler_angles(curves: Sequence[Curve], path: str | Path, *, title: str) -> None:
    """ZYX Euler angles ``φ, θ, ψ`` (``R = Rz(φ) Ry(θ) Rx(ψ)``) against time, in degrees.

    Parameters
    ----------
    curves : sequence of (str, ndarray (n,), ndarray (n, 3))
        Label, times (s) and angles ``(φ, θ, ψ)`` in radians, as
        :meth:`tumble.rigid.Trajectory.euler_zyx` gives them.
    path : str or Path
        Output PNG.
    title : str
        Figure title.
    """
    fig, axes = new_figure(3, 1, figsize=(9, 7), sharex=True)
    for index, (label, t, angles) in enumerate(curves):
        degrees = _unwrapped_degrees(np.asarray(angles, dtype=float))
        for k in range(3):
            axes[k].plot(t, degrees[:, k], lw=1.0, label=label, **_style(index))
    for k, ax in enumerate(axes):
        limit = 90 if k == 1 else 180
        ax.set_ylim(-limit * 1.05, limit * 1.05)
        ax.set_yticks(np.linspace(-limit, limit, 5))
        ax.set_ylabel(f"{_ANGLE_NAMES[k]} (deg)")
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    _figure_legend(fig, axes[0], len(curves))
    save(fig, path)


def _drift_series(run) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``|E − E₀|/E₀``, ``‖L − L₀‖/‖L₀‖`` (unscaled if L₀ = 0) and ``‖RᵀR − I‖`` of one run.

    The series behind :class:`~tumble.rigid.Trajectory`'s ``energy_drift``, ``momentum_drift``
    and ``orthogonality_drift`` (their maxima).
    """
    with np.errstate(all="ignore"):
        energy = np.abs(run.energy_error) / abs(run.energy[0])
        momentum = run.momentum_error / (np.linalg.norm(run.L_world[0]) or 1.0)
    return energy, momentum, run.orthogonality_error


def drift(runs: Sequence[tuple[str, Trajectory]], path: str | Path, *, title: str) -> None:
    """What each method fails to conserve: energy, angular momentum, orthogonality of R.

    Three panels on log axes against time: ``|E − E₀|/E₀``, ``|L − L₀|/|L₀|`` (world
    frame) and ``‖RᵀR − I‖_F``.

    Parameters
    ----------
    runs : sequence of (str, Trajectory)
        Label and :class:`tumble.rigid.Trajectory` of each method.
    path : str or Path
        Output PNG.
    title : str
        Figure title.
    """
    fig, axes = new_figure(3, 1, figsize=(9, 8), sharex=True)
    labels = ("|E − E₀| / E₀ (–)", "|L − L₀| / |L₀| (–)", "‖RᵀR − I‖_F (–)")
    floored = [False, False, False]
    for index, (label, run) in enumerate(runs):
        for k, series in enumerate(_drift_series(run)):
            values, low = _floored(series)
            floored[k] |= low
            axes[k].semilogy(run.t, values, lw=1.1, label=label, **_style(index))
    for k, ax in enumerate(axes):
        ax.set_ylabel(labels[k])
        ax.grid(alpha=0.3, which="both")
        if floored[k]:
            _note_floor(ax)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    _figure_legend(fig, axes[0], len(runs))
    save(fig, path)


def energy_error_loglog(
    runs: Sequence[tuple[str, Trajectory]], path: str | Path, *, title: str
) -> None:
    """The largest relative energy error so far, ``max_{s ≤ t} |E(s) − E₀| / |E₀|``, against
    t, both axes logarithmic.

    The running maximum drops the error's fast oscillation and keeps its envelope: on log–log
    axes a secular drift is a rising line (slope 1 for a linear drift) and a bounded error a
    flat one, so long runs of different methods tell apart at a glance. ``t = 0`` is left out;
    values at round-off or zero are drawn at :data:`LOG_FLOOR`.

    Parameters
    ----------
    runs : sequence of (str, Trajectory)
        Label and :class:`tumble.rigid.Trajectory` of each method.
    path : str or Path
        Output PNG.
    title : str
        Figure title.
    """
    fig, ax = new_figure(figsize=(9, 5.2))
    floored = False
    for index, (label, run) in enumerate(runs):
        with np.errstate(all="ignore"):
            error = np.fmax.accumulate(np.abs(run.energy_error) / abs(run.energy[0]))
        later = run.t > run.t[0]
        values, low = _floored(error[later])
        floored |= low
        ax.loglog(run.t[later] - run.t[0], values, lw=1.1, label=label, **_style(index))
    ax.set_xlabel("t (s)")
    ax.set_ylabel("largest |E − E₀| / |E₀| so far (–)")
    ax.grid(alpha=0.3, which="both")
    if floored:
        _note_floor(ax)
    ax.set_title(title, fontsize=11)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    _figure_legend(fig, ax, len(runs))
    save(fig, path)


def error_vs_exact(curves: Sequence[Curve], path: str | Path, *, title: str) -> None:
    """The distance ``‖R − R_exact‖_F`` of each method from the exact attitude, log axis.

    Parameters
    ----------
    curves : sequence of (str, ndarray (n,), ndarray (n,))
        Label, times (s) and errors (dimensionless) of each method.
    path : str or Path
        Output PNG.
    title : str
        Figure title.
    """
    fig, ax = new_figure(figsize=(8, 4.8))
    any_floored = False
    for index, (label, t, error) in enumerate(curves):
        values, low = _floored(error)
        any_floored |= low
        marker = "." if len(t) <= SPARSE_SAMPLES else None
        ax.semilogy(t, values, lw=1.2, marker=marker, ms=3, label=label, **_style(index))
    ax.set_xlabel("t (s)")
    ax.set_ylabel("‖R − R_exact‖_F (–)")
    ax.set_title(title)
    ax.grid(alpha=0.3, which="both")
    if any_floored:
        _note_floor(ax)
    ax.legend(loc="center left", bbox_to_anchor=(1.04, 0.5), frameon=False)
    save(fig, path)


def convergence(
    studies: Sequence[tuple[str, np.ndarray, np.ndarray, float]],
    path: str | Path,
    *,
    title: str,
    error_label: str = "‖R(T) − R_exact(T)‖_F (–)",
) -> None:
    """Log–log error against step size, with each method's fitted slope in the legend.

    Parameters
    ----------
    studies : sequence of (str, ndarray (k,), ndarray (k,), float)
        Label, step sizes (s), errors and the fitted slope (observed order) of each method.
    path : str or Path
        Output PNG.
    title : str
        Figure title.
    error_label : str
        The y-axis label (what the error measures).
    """
    fig, ax = new_figure(figsize=(7.5, 5.5))
    for index, (label, h, errors, slope) in enumerate(studies):
        h, errors = np.asarray(h, dtype=float), np.asarray(errors, dtype=float)
        style = _style(index)
        intercept = np.mean(np.log(errors) - slope * np.log(h))
        ax.loglog(h, errors, "o", color=style["color"], ms=5)
        ax.loglog(
            h,
            np.exp(intercept) * h**slope,
            lw=1.2,
            label=f"{label}: slope {slope:.2f}",
            **style,
        )
    ax.set_xlabel("step h (s)")
    ax.set_ylabel(error_label)
    ax.set_title(title)
    ax.grid(alpha=0.3, which="both")
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    save(fig, path)


def angular_velocity(
    curves: Sequence[Curve],
    path: str | Path,
    *,
    title: str,
    marks: Sequence[np.ndarray] | None = None,
) -> None:
    """Body-frame angular velocity ``(ω_x, ω_y, ω_z)``, one panel per curve.

    Parameters
    ----------
    curves : sequence of (str, ndarray (n,), ndarray (n, 3))
        Label, times (s) and ``ω_body`` (rad/s) of each run.
    path : str or Path
        Output PNG.
    title : str
        Figure title.
    marks : sequence of ndarray, optional
        For each curve, times (s) to mark with vertical lines (e.g. the zero crossings a
        period was measured from).
    """
    fig, axes = new_figure(len(curves), 1, figsize=(9, 2.4 * len(curves) + 1), squeeze=False)
    for row, (label, t, omega) in enumerate(curves):
        ax = axes[row, 0]
        for k in range(3):
            ax.plot(t, omega[:, k], lw=1.0, color=f"C{k}", label=_OMEGA_NAMES[k])
        if marks is not None:
            for time in marks[row]:
                ax.axvline(time, color="0.5", lw=0.7, ls=":")
        ax.set_title(label, fontsize=10)
        ax.set_ylabel("ω_body (rad/s)")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("t (s)")
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    _figure_legend(fig, axes[0, 0], 3)
    save(fig, path)


def body_snapshots(
    vertices: np.ndarray,
    faces: np.ndarray,
    frames: Sequence[tuple[str, np.ndarray, np.ndarray]],
    path: str | Path,
    *,
    title: str,
    arrow: tuple[np.ndarray, np.ndarray] | None = None,
    trail: np.ndarray | None = None,
) -> None:
    """A triangle mesh drawn at several instants in one 3D view.

    Parameters
    ----------
    vertices : ndarray, shape (v, 3)
        Mesh vertices in body coordinates relative to the centre of mass (m).
    faces : ndarray, shape (f, 3)
        Vertex indices of each triangle.
    frames : sequence of (str, ndarray (3,), ndarray (3, 3))
        Label, centre of mass (m) and attitude of each snapshot: ``r = x + R r_body``.
    path : str or Path
        Output PNG.
    title : str
        Figure title.
    arrow : (ndarray (3,), ndarray (3,)), optional
        Start and end (m, world) of an arrow to draw, e.g. the impulse.
    trail : ndarray, shape (n, 3), optional
        The path of the centre of mass (m, world), drawn as a line.
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig, ax = new_figure(figsize=(7, 6.5), subplot_kw={"projection": "3d"})
    points = []
    for index, (label, x, R) in enumerate(frames):
        world = vertices @ np.asarray(R).T + x
        points.append(world)
        colour = f"C{index % 10}"
        ax.add_collection3d(
            Poly3DCollection(world[faces], alpha=0.2, facecolor=colour, edgecolor=colour, lw=0.3)
        )
        ax.plot(*x, "o", color=colour, ms=4, label=label)
    if trail is not None:
        ax.plot(*np.asarray(trail).T, color="0.2", lw=1.0, label="centre of mass path")
    if arrow is not None:
        start, end = (np.asarray(point, dtype=float) for point in arrow)
        ax.quiver(*start, *(end - start), color="k", lw=1.5, arrow_length_ratio=0.15)
        ax.plot(*start, "k^", ms=5, label="impulse (from f0 to f1)")
        points.append(np.vstack([start, end]))
    _equal_limits(ax, np.vstack(points))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(title)
    ax.legend(loc="upper left", fontsize=8, frameon=False)
    save(fig, path)


def _equal_limits(ax, points: np.ndarray) -> None:
    """Axis limits of one common span around ``points``, so the body is not distorted."""
    low, high = points.min(axis=0), points.max(axis=0)
    centre, half = (low + high) / 2, (high - low).max() / 2 * 1.05
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
