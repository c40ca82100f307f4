"""Animations: a rigid body's mesh moving and turning, written as a GIF or an MP4.

A :class:`~tumble.rigid.Trajectory` is resampled to evenly spaced frames (:func:`resample`),
the body-frame mesh is placed in the world at each frame (:func:`world_vertices`), loads are
turned into arrows (:func:`load_arrows`), and one matplotlib figure on the Agg canvas is
updated and drawn once per frame. Frames become a GIF through Pillow (one palette for all
frames, so unchanged pixels cost nothing) or an MP4 through ``ffmpeg``
(:func:`mp4_available`), chosen by the path's suffix alone, so a temporary name such as
``.animation.partial.gif`` works. The writing is in :mod:`tumble.viz._writers`;
:func:`write_animation`, :func:`animation_format` and :func:`mp4_available` are re-exported.

matplotlib is imported inside the functions that draw.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tumble import _checks, so3
from tumble.rigid.forces import Force, Gravity, Impulse, State, Torque, split_loads
from tumble.viz._figure import new_figure
from tumble.viz._writers import (
    FORMATS,
    GIF_COLOURS,
    LOAD_COLOURS,
    animation_format,
    mp4_available,
    write_animation,
)

if TYPE_CHECKING:
    import trimesh

    from tumble.rigid import Trajectory

PIXELS_PER_INCH = 100
"""Figure dpi of the frames, so ``size`` in pixels is ``figsize × 100``."""
IMPULSE_SHOWN = 0.5
"""An impulse's arrow is shown for this long (s) centred on its time, and in at least the
frames within 1.5 frame spacings of it."""
ARROW_FRACTION = 0.4
"""Every load arrow is this fraction of the body's size long: arrows show direction only."""
LIGHT = np.array([-0.196, -0.539, 0.819]) / np.linalg.norm([-0.196, -0.539, 0.819])
"""Direction (world) the light comes from, for the Lambert shading of the faces."""
BODY_COLOUR = np.array([0.12, 0.47, 0.71])


@dataclass(frozen=True)
class Frames:
    """A trajectory at the animation's frame times.

    Attributes
    ----------
    t : ndarray, shape (k,)
        Frame times (s), evenly spaced from the first sample to the last.
    x, v : ndarray, shape (k, 3)
        Centre of mass (m) and its velocity (m/s), world frame.
    R : ndarray, shape (k, 3, 3)
        Attitude, body to world.
    L : ndarray, shape (k, 3)
        World angular momentum (kg m²/s).
    """

    t: NDArray[np.float64]
    x: NDArray[np.float64]
    v: NDArray[np.float64]
    R: NDArray[np.float64]
    L: NDArray[np.float64]


class Arrow(NamedTuple):
    """A load drawn in one frame: from ``tail`` to ``head`` (m, world); ``kind`` names it."""

    tail: NDArray[np.float64]
    head: NDArray[np.float64]
    kind: str


def resample(trajectory: Trajectory, frames: int) -> Frames:
    """The trajectory at ``frames`` times evenly spaced over ``[t₀, t_end]``, interpolated.

    Between samples ``k`` and ``k + 1``, with ``s = (t − t_k)/(t_{k+1} − t_k)``, ``x``, ``v``
    and ``L`` are linear in ``s``. The attitude is split into its polar factors ``R = Q S``
    (``Q`` the nearest rotation, ``S`` symmetric; ``S = I`` on SO(3)), the rotation follows
    the geodesic ``Q(s) = Q_k exp(s log(Q_kᵀ Q_{k+1}))`` and ``S`` is linear in ``s``: exact
    at the samples, and a method that leaves SO(3) is drawn as distorted as it is. The
    samples must be close enough that the body turns less than π between two of them.

    Parameters
    ----------
    trajectory : Trajectory
        At least two samples.
    frames : int
        Number of frames, ≥ 2.

    Returns
    -------
    Frames
    """
    frames = _checks.count("frames", frames, 2)
    t = np.asarray(trajectory.t, dtype=float)
    if len(t) < 2:
        raise _checks.fail("trajectory.t", trajectory.t, "at least two samples", "s")
    times = np.linspace(t[0], t[-1], frames)
    k = np.clip(np.searchsorted(t, times, side="right") - 1, 0, len(t) - 2)
    span = t[k + 1] - t[k]
    s = np.clip(np.divide(times - t[k], span, out=np.zeros(frames), where=span > 0), 0, 1)

    def linear(values):
        values = np.asarray(values, dtype=float)
        return values[k] + s[:, None] * (values[k + 1] - values[k])

    R = np.asarray(trajectory.R, dtype=float)
    attitude = _interpolate_attitude(R[k], R[k + 1], s)
    return Frames(times, linear(trajectory.x), linear(trajectory.v), attitude,
                  linear(trajectory.L_world))  # fmt: skip


def _polar(R: NDArray) -> tuple[NDArray, NDArray]:
    """``R = Q S``: ``Q = U Vᵀ`` the nearest rotation, ``S = V Σ Vᵀ``, shape (k, 3, 3) each."""
    U, sigma, Vt = np.linalg.svd(R)
    V = np.swapaxes(Vt, -1, -2)
    return U @ Vt, V @ (sigma[..., :, None] * Vt)


def _interpolate_attitude(A: NDArray, B: NDArray, s: NDArray) -> NDArray:
    QA, SA = _polar(A)
    QB, SB = _polar(B)
    turn = so3.log(np.swapaxes(QA, -1, -2) @ QB)
    S = (1 - s)[:, None, None] * SA + s[:, None, None] * SB
    return QA @ so3.exp(s[:, None] * turn) @ S


def world_vertices(vertices: ArrayLike, x: ArrayLike, R: ArrayLike) -> NDArray[np.float64]:
    """Mesh vertices in the world at each frame: ``r_kj = x_k + R_k v_j``.

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
        Vertices in body coordinates, relative to the centre of mass (m).
    x : array_like, shape (k, 3)
        Centre of mass (m, world).
    R : array_like, shape (k, 3, 3)
        Attitude, body to world.

    Returns
    -------
    ndarray, shape (k, n, 3)

    Examples
    --------
    A quarter turn about z takes the body's x axis to y; the centre of mass is at z = 5 m:

    >>> turn = so3.exp([0.0, 0.0, np.pi / 2])
    >>> np.round(world_vertices([[1.0, 0.0, 0.0]], [[0.0, 0.0, 5.0]], [turn]), 12) + 0.0
    array([[[0., 1., 5.]]])
    """
    vertices, x, R = (np.asarray(a, dtype=float) for a in (vertices, x, R))
    return x[:, None, :] + np.einsum("kij,nj->kni", R, vertices)


def load_arrows(
    frames: Frames, loads: Sequence[object], *, mass: float, length: float
) -> list[list[Arrow]]:
    """The arrows to draw in each frame, all ``length`` long (m): direction, not magnitude.

    * :class:`~tumble.rigid.Impulse`: ends at its world ``point``, along ``J``, in the frames
      with ``|t − time| ≤ max(IMPULSE_SHOWN/2, 1.5 Δt_frame)``.
    * :class:`~tumble.rigid.Force`: starts at its point moved with the body, ``x + R p``
      (the centre of mass if it has none), along the world force ``F`` (a callable force is
      evaluated at the frame's state), in every frame where ``F ≠ 0``.
    * :class:`~tumble.rigid.Gravity` and :class:`~tumble.rigid.Torque` get no arrow
      (:func:`animate_body` names them in a caption).

    Parameters
    ----------
    frames : Frames
        From :func:`resample`.
    loads : sequence
        Loads as :func:`tumble.rigid.simulate` takes them.
    mass : float
        The body's mass (kg), for the momentum ``p = m v`` a callable force sees.
    length : float
        Arrow length (m).

    Returns
    -------
    list of list of Arrow
        One list per frame.
    """
    split_loads(loads)  # refuses anything that is not a load, naming its index
    spacing = (frames.t[-1] - frames.t[0]) / max(len(frames.t) - 1, 1)
    window = max(IMPULSE_SHOWN / 2, 1.5 * spacing)
    arrows: list[list[Arrow]] = [[] for _ in frames.t]
    for k, time in enumerate(frames.t):
        state = State(frames.x[k], frames.R[k], mass * frames.v[k], frames.L[k])
        for load in loads:
            if isinstance(load, Impulse) and abs(time - load.time) <= window:
                direction = _unit(load.impulse)
                if direction is not None:
                    tail = load.point - length * direction
                    arrows[k].append(Arrow(tail, load.point.copy(), "impulse"))
            elif isinstance(load, Force):
                direction = _unit(load(time, state, mass)[0])
                if direction is not None:
                    point = state.x if load.point is None else state.x + state.R @ load.point
                    arrows[k].append(Arrow(point, point + length * direction, "force"))
    return arrows


def _unit(vector: NDArray) -> NDArray | None:
    norm = float(np.linalg.norm(vector))
    return vector / norm if norm > 0 else None


def _caption(loads: Sequence[object]) -> str:
    """One line per load: what it is, and whether it is drawn."""
    lines = []
    for load in loads:
        if isinstance(load, Impulse):
            magnitude = np.linalg.norm(load.impulse)
            lines.append(f"red: impulse |J| = {magnitude:.3g} N s at t = {load.time:g} s")
        elif isinstance(load, Force):
            size = (
                "F(t, state)"
                if callable(load.force)
                else f"|F| = {np.linalg.norm(load.force):.3g} N"
            )
            lines.append(f"orange: force {size}")
        elif isinstance(load, Torque):
            torque = "τ(t, state)" if callable(load.torque) else _vector_text(load.torque)
            lines.append(f"torque τ = {torque} N m (not drawn)")
        elif isinstance(load, Gravity):
            lines.append(f"gravity g = {_vector_text(load.g)} m/s² (not drawn)")
    return "\n".join(lines)


def _vector_text(vector: NDArray) -> str:
    return "(" + ", ".join(f"{value:.3g}" for value in vector) + ")"


def _time_text(spacing: float) -> str:
    """A format for ``t`` with enough decimals that consecutive frames differ."""
    decimals = int(np.clip(np.ceil(-np.log10(spacing)), 0, 9)) if spacing > 0 else 3
    return f"t = {{:.{decimals}f}} s"


def animate_body(
    trajectory: Trajectory,
    mesh: trimesh.Trimesh,
    path: str | Path,
    *,
    title: str,
    loads: Sequence[object] = (),
    frames: int = 80,
    fps: float = 20,
    size: tuple[int, int] = (480, 480),
) -> Path:
    """Write an animation of the body's mesh moving and turning along ``trajectory``.

    Each frame draws the faces at ``r = x(t) + R(t) r_body`` (:func:`world_vertices`) at the
    :func:`resample` times (interpolated between samples), shaded by the angle between each
    face's world normal and :data:`LIGHT`, the centre of mass's path so far, and the load
    arrows of :func:`load_arrows`; a caption lists the loads (gravity and torques only
    there). The axes keep one range, equal in x, y and z, for the whole run, so the body is
    not distorted.

    Parameters
    ----------
    trajectory : Trajectory
        From :func:`tumble.rigid.simulate`.
    mesh : trimesh.Trimesh
        The body in body coordinates, centre of mass at the origin (m).
    path : str or Path
        Output file; ``.gif`` (Pillow) or ``.mp4`` (ffmpeg, H.264), by suffix only.
    title : str
        Names the scenario and the method; ``t = … s`` is added below it.
    loads : sequence
        The loads passed to ``simulate`` (:class:`~tumble.rigid.Impulse`,
        :class:`~tumble.rigid.Force`, :class:`~tumble.rigid.Torque`,
        :class:`~tumble.rigid.Gravity`).
    frames : int
        Number of frames, ≥ 2, evenly spaced in time.
    fps : float
        Frames per second of the file.
    size : (int, int)
        Width and height in pixels.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        Bad ``frames``, ``fps``, ``size``, ``loads`` or suffix of ``path``.
    RuntimeError
        ``.mp4`` without an ffmpeg (imageio-ffmpeg ships one).
    """
    animation_format(path)  # refuse a bad suffix before rendering
    fps = _checks.positive("fps", fps, "frames per second")
    width, height = (_checks.count(f"size[{i}]", value, 16) for i, value in enumerate(size))
    sampled = resample(trajectory, frames)
    vertices, faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)
    world = world_vertices(vertices, sampled.x, sampled.R)
    extent = float(np.max(np.ptp(vertices, axis=0)))
    arrows = load_arrows(sampled, loads, mass=trajectory.body.mass, length=ARROW_FRACTION * extent)
    caption = _caption(loads)
    if np.ptp(sampled.x, axis=0).max() > 1e-9 * max(extent, 1e-300):
        caption = "\n".join(filter(None, ["black: path of the centre of mass", caption]))
    images = _render(world, faces, sampled, arrows, title, caption, (width, height))
    return write_animation(images, path, fps=fps)


def _face_colours(world: NDArray, faces: NDArray) -> NDArray:
    """RGBA of each face in each frame, Lambert-shaded: shape (k, f, 4)."""
    triangles = world[:, faces]  # (k, f, 3 corners, 3)
    normals = np.cross(
        triangles[:, :, 1] - triangles[:, :, 0], triangles[:, :, 2] - triangles[:, :, 0]
    )
    normals /= np.maximum(np.linalg.norm(normals, axis=-1, keepdims=True), 1e-300)
    light = 0.35 + 0.65 * np.clip(normals @ LIGHT, 0.0, 1.0)
    rgb = np.clip(light[..., None] * BODY_COLOUR + (1 - light[..., None]) * 0.15, 0, 1)
    return np.concatenate([rgb, np.ones(rgb.shape[:-1] + (1,))], axis=-1)


def _render(world, faces, sampled: Frames, arrows, title, caption, size) -> list[NDArray]:
    """Draw every frame on one reused figure; RGB arrays, shape (height, width, 3).

    The axes (panes, ticks, labels) do not change, so they are drawn once and the frames
    restore that background and draw only the body, the path, the arrows and the heading.
    """
    figure, axes, body, trail, heading = _scene(world, faces, sampled, arrows, caption, size)
    canvas = figure.canvas
    colours = _face_colours(world, faces)
    time_text = _time_text(float(sampled.t[1] - sampled.t[0]))
    canvas.draw()
    background = canvas.copy_from_bbox(figure.bbox)
    images = []
    for k, time in enumerate(sampled.t):
        canvas.restore_region(background)
        body.set_verts(world[k][faces])
        body.set_facecolor(colours[k])
        body.set_edgecolor(colours[k])
        body.do_3d_projection()
        axes.draw_artist(body)
        trail.set_data_3d(*sampled.x[: k + 1].T)
        axes.draw_artist(trail)
        for arrow in arrows[k]:
            quiver = _arrow(axes, arrow)
            quiver.do_3d_projection()
            axes.draw_artist(quiver)
            quiver.remove()
        heading.set_text(f"{title}\n{time_text.format(time)}")
        figure.draw_artist(heading)
        images.append(np.asarray(canvas.buffer_rgba())[..., :3].copy())
    return images


def _scene(world, faces, sampled: Frames, arrows, caption, size):
    """The figure with fixed, equal axes and the (not yet visible) moving artists."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    figure, axes = new_figure(
        figsize=(size[0] / PIXELS_PER_INCH, size[1] / PIXELS_PER_INCH),
        subplot_kw={"projection": "3d"},
    )
    figure.set_dpi(PIXELS_PER_INCH)
    figure.subplots_adjust(left=0.02, right=0.9, bottom=0.1 if caption else 0.04, top=0.9)
    axes.computed_zorder = False  # arrows on top even where the body hides their point
    body = Poly3DCollection(world[0][faces], lw=0.3, animated=True)
    axes.add_collection3d(body)
    (trail,) = axes.plot(*sampled.x[:1].T, color="k", lw=1.0, animated=True)
    points = [world.reshape(-1, 3)] + [np.vstack([a.tail, a.head]) for f in arrows for a in f]
    _equal_limits(axes, np.vstack(points))
    for name in "xyz":
        getattr(axes, f"set_{name}label")(f"{name} (m)", fontsize=8, labelpad=2)
    axes.tick_params(labelsize=6, pad=0)
    heading = figure.text(
        0.5, 0.985, "", ha="center", va="top", fontsize=9, wrap=True, animated=True
    )
    if caption:
        figure.text(0.02, 0.015, caption, ha="left", va="bottom", fontsize=7, color="0.2")
    return figure, axes, body, trail, heading


def _arrow(axes, arrow: Arrow):
    shaft = arrow.head - arrow.tail
    return axes.quiver(*arrow.tail, *shaft, color=LOAD_COLOURS[arrow.kind], lw=2.0,
                       arrow_length_ratio=0.25)  # fmt: skip


def _equal_limits(axes, points: NDArray) -> None:
    """One span for x, y and z around ``points`` and a cubic box: no distortion."""
    low, high = points.min(axis=0), points.max(axis=0)
    centre, half = (low + high) / 2, max(float((high - low).max()), 1e-12) / 2 * 1.05
    axes.set_xlim(centre[0] - half, centre[0] + half)
    axes.set_ylim(centre[1] - half, centre[1] + half)
    axes.set_zlim(centre[2] - half, centre[2] + half)
    axes.set_box_aspect((1, 1, 1))


__all__ = [
    "ARROW_FRACTION",
    "BODY_COLOUR",
    "FORMATS",
    "GIF_COLOURS",
    "IMPULSE_SHOWN",
    "LIGHT",
    "LOAD_COLOURS",
    "PIXELS_PER_INCH",
    "Arrow",
    "Frames",
    "animate_body",
    "animation_format",
    "load_arrows",
    "mp4_available",
    "resample",
    "world_vertices",
    "write_animation",
]
