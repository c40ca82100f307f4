"""Pictures of structural dynamics: energy against time, the dt sweep, the moving beam.

Every function builds a :class:`matplotlib.figure.Figure` on the Agg canvas (matplotlib is
imported inside the functions, never at module import, and pyplot's global state is not
used). :func:`figure_writer` turns a figure function into the ``writer(path)`` that a
:class:`~tumble.io.ScenarioResult` lists; :func:`beam_frames` renders RGB
arrays for an animation and :func:`beam_animation` writes them as a GIF (or MP4).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tumble import _checks
from tumble.viz._figure import new_figure, save

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from tumble.structural import LinearSystem, Response, StabilitySweep

FIGURE_SIZE = (7.0, 4.0)
"""Default figure size [inch]."""

DPI = 120


def figure_writer(
    make: Callable[..., Figure], *args: Any, **kwargs: Any
) -> Callable[[Path], None]:
    """A ``writer(path)`` that draws ``make(*args, **kwargs)`` and saves it at ``path``."""

    def write(path: Path) -> None:
        save(make(*args, **kwargs), path, dpi=DPI, tight=False)

    return write


def _new_figure(size: tuple[float, float] = FIGURE_SIZE) -> tuple[Figure, Axes]:
    return new_figure(figsize=size, layout="constrained")


def energy_figure(response: Response, *, scale: float, title: str) -> Figure:
    """Total energy against time, ``(E(t) − E(0)) / scale``, for one scheme.

    Parameters
    ----------
    response : Response
        From :func:`tumble.structural.integrate`.
    scale : float
        Energy scale [J] (e.g. :func:`tumble.structural.energy_scale`).
    title : str
        Names the scenario and the scheme.
    """
    figure, axes = _new_figure()
    with np.errstate(over="ignore", invalid="ignore"):
        change = (response.energy - response.energy[0]) / scale
    finite = np.isfinite(change)
    if np.any(np.abs(change[finite]) > 1e3):  # a diverging run: show the growth on a log axis
        axes.semilogy(response.t[finite], np.clip(np.abs(change[finite]), 1e-30, 1e250), lw=1.2)
    else:
        axes.plot(response.t[finite], change[finite], lw=1.2)
    axes.set_xlabel("time t [s]")
    axes.set_ylabel(
        f"(E − E₀) / {scale:.3g} J  [–]" + (", |·|" if axes.get_yscale() == "log" else "")
    )
    note = "" if response.success else f"  ({response.message})"
    axes.set_title(title + note, fontsize=10)
    axes.grid(alpha=0.3)
    return figure


def stability_figure(sweeps: Sequence[StabilitySweep], *, title: str) -> Figure:
    """Energy growth against time step for each scheme, diverged runs drawn at the top.

    The critical step of every scheme that has a finite one is a dashed vertical line.
    """
    figure, axes = _new_figure()
    top = 1e6
    for sweep in sweeps:
        growth = np.clip(
            np.where(np.isfinite(sweep.energy_growth), sweep.energy_growth, top), 1e-16, top
        )
        (line,) = axes.loglog(sweep.dt, growth, "o-", label=sweep.scheme, ms=4)
        critical = sweep.critical.dt
        if 0 < critical < np.inf:
            axes.axvline(critical, ls="--", color=line.get_color(), lw=1)
    axes.axhline(1.0, color="0.5", lw=0.8)
    axes.set_xlabel("time step Δt [s]")
    axes.set_ylabel("max (E − E₀) / energy scale  [–]")
    axes.set_title(f"{title}\n(diverged runs drawn at {top:.0e}; dashed: 2/ω_max)", fontsize=10)
    axes.legend(fontsize=8)
    axes.grid(alpha=0.3, which="both")
    return figure


def deformed_nodes(system: LinearSystem, x: ArrayLike, magnification: float = 1.0) -> NDArray:
    """Node positions [m] after displacement ``x`` (free DOFs), shape (..., n_nodes, 2)."""
    full = system.expand(x).reshape(np.shape(x)[:-1] + (-1, 3))
    return system.nodes + magnification * full[..., :2]


def beam_figure(
    system: LinearSystem, t: ArrayLike, x: ArrayLike, *, title: str, every: int = 10
) -> Figure:
    """Deflected shapes at several times overlaid, coloured by time.

    Parameters
    ----------
    system : LinearSystem
    t : ndarray, shape (n,)
        Times [s].
    x : ndarray, shape (n, n_dofs)
        Displacements [m, rad] (free DOFs).
    every : int
        Draw every this many rows.
    """
    import matplotlib as mpl

    figure, axes = _new_figure()
    t, x = np.asarray(t)[::every], np.asarray(x)[::every]
    magnification = _magnification(system, x)
    colours = mpl.colormaps["viridis"](np.linspace(0, 1, max(len(t), 1)))
    for position, colour in zip(deformed_nodes(system, x, magnification), colours, strict=True):
        _draw_frame(axes, system, position, colour=colour, lw=0.8)
    _draw_frame(axes, system, system.nodes, colour="0.6", lw=1.5, ls=":")
    axes.set_xlabel("x [m]")
    axes.set_ylabel(f"y [m], displacement × {magnification:.3g}")
    axes.set_title(f"{title}: t = {t[0]:.3g}…{t[-1]:.3g} s", fontsize=10)
    axes.grid(alpha=0.3)
    return figure


def beam_frames(
    system: LinearSystem,
    t: ArrayLike,
    x: ArrayLike,
    *,
    title: str,
    size: tuple[int, int] = (640, 360),
) -> list[NDArray[np.uint8]]:
    """One RGB image per row of ``x``: the frame, deformed, on fixed axes.

    Returns
    -------
    list of ndarray, shape (height, width, 3), dtype uint8
        Ready for an animation writer (e.g. Pillow or imageio).
    """
    t, x = np.asarray(t), np.asarray(x)
    magnification = _magnification(system, x)
    positions = deformed_nodes(system, x, magnification)
    lower, upper = positions.min(axis=(0, 1)), positions.max(axis=(0, 1))
    pad = 0.05 * max(float(np.max(upper - lower)), 1e-12)
    figure, axes = _new_figure((size[0] / 100, size[1] / 100))
    frames = []
    for time, position in zip(t, positions, strict=True):
        axes.clear()
        _draw_frame(axes, system, system.nodes, colour="0.7", lw=1.0, ls=":")
        _draw_frame(axes, system, position, colour="C0", lw=2.0)
        axes.set_xlim(lower[0] - pad, upper[0] + pad)
        axes.set_ylim(lower[1] - pad, upper[1] + pad)
        axes.set_xlabel("x [m]")
        axes.set_ylabel(f"y [m], displacement × {magnification:.3g}")
        axes.set_title(f"{title}, t = {time:.4f} s", fontsize=10)
        figure.canvas.draw()
        figure.set_layout_engine("none")  # same labels every frame: keep the first layout
        frames.append(np.asarray(figure.canvas.buffer_rgba())[..., :3].copy())  # type: ignore[attr-defined]  # Agg canvas
    return frames


def beam_animation(
    system: LinearSystem,
    response: Response,
    path: str | Path,
    *,
    every: int = 10,
    title: str,
    fps: float = 20,
    size: tuple[int, int] = (640, 360),
) -> Path:
    """Write the moving beam as an animation: :func:`beam_frames` of every ``every``-th record.

    Each frame is the deformed frame ``nodes + m u`` on fixed axes (one magnification ``m``
    for the whole run, in the y label) over the undeformed one, titled ``"{title} —
    {scheme}, t = … s"``. Records that are not finite (the last one of a diverged run) are
    left out.

    Parameters
    ----------
    system : LinearSystem
    response : Response
        From :func:`tumble.structural.integrate`; its records are every ``record_every``
        steps, so a frame is every ``every × record_every`` steps.
    path : str or Path
        ``.gif`` or ``.mp4`` (by suffix only; see :func:`tumble.viz.animation.write_animation`).
    every : int
        Keep every this many records, ≥ 1.
    title : str
        Names the scenario; the scheme's name is appended.
    fps : float
        Frames per second.
    size : (int, int)
        Width and height in pixels.

    Returns
    -------
    Path
        ``path``.
    """
    from tumble.viz.animation import animation_format, write_animation

    animation_format(path)  # refuse a bad suffix before drawing
    every = _checks.count("every", every)
    t, x = np.asarray(response.t)[::every], np.asarray(response.x)[::every]
    finite = np.all(np.isfinite(x), axis=1)
    if not np.any(finite):
        raise _checks.fail(
            "response.x", response.x, "finite in at least one record", "m, rad", response.message
        )
    images = beam_frames(
        system, t[finite], x[finite], title=f"{title} — {response.scheme}", size=size
    )
    return write_animation(images, path, fps=fps)


def _magnification(system: LinearSystem, x: NDArray) -> float:
    """Scale displacements so the largest is a tenth of the frame's size."""
    full = system.expand(x).reshape(np.shape(x)[:-1] + (-1, 3))[..., :2]
    largest = float(np.max(np.abs(full[np.isfinite(full)]), initial=0.0))
    extent = float(np.max(np.ptp(system.nodes, axis=0)))
    return 0.1 * extent / largest if largest > 0 else 1.0


def _draw_frame(
    axes: Axes, system: LinearSystem, position: NDArray, colour: Any, **style: Any
) -> None:
    from matplotlib.collections import LineCollection

    segments = position[system.elements.connectivity]  # (n_elements, 2 ends, 2 coordinates)
    axes.add_collection(LineCollection(list(segments), colors=[colour], **style))
    axes.autoscale_view()
