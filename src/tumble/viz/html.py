"""An interactive HTML viewer of a rigid-body run: the moving mesh, a time slider, the energy.

:func:`html_viewer` writes one self-contained page (plotly, with plotly.js inlined, so it
opens with no network): on top a 3D scene with the body's mesh at the chosen time, drawn on
fixed equal-aspect axes that hold the whole run; under it a Play/Pause button and a time
slider; at the bottom the energy ``T + V`` against time with a marker at the current time.
:func:`viewer_figure` returns the same plotly figure without writing it.

The world vertices at sample ``k`` are ``x[k] + R[k] v`` for each body-frame vertex ``v``.
The animation has one plotly frame per shown time: the recorded sample nearest to each of
``frames`` evenly spaced times (duplicates dropped, so a run with fewer samples has fewer
frames). The faces are sent once; a frame carries only the vertex coordinates, as float32
(7 significant digits, ample for a picture and half the size of float64). The mesh is drawn
smooth-shaded with its vertices split along sharp edges (:func:`display_mesh`): plotly's flat
shading drew jagged dark patches on a torus in software WebGL (SwiftShader). How the figure
looks (colours, axes, the play controls) is in :mod:`tumble.viz._viewer_layout`.

plotly is imported only inside the functions.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from os import PathLike
from typing import TYPE_CHECKING

import numpy as np

from tumble import _checks
from tumble._atomic import atomic_write
from tumble.rigid.forces import Force, Gravity, Impulse, Torque
from tumble.viz._viewer_layout import (
    ARROW_COLOR,
    ENERGY_POINTS,
    ENERGY_TOP,
    FRAME_DURATION_MS,
    MESH_COLOR,
    NOW_COLOR,
    SCENE_BOTTOM,
    SLIDER_TOP,
    apply_layout,
    controls,
    energy_curve,
    style_arrow,
    style_mesh,
    style_now,
)

if TYPE_CHECKING:
    import plotly.graph_objects
    import trimesh

    from tumble.rigid.trajectory import Trajectory

DIV_ID = "tumble-view"
"""The ``id`` of the plot's ``<div>`` in the page (for scripts and browser tests)."""
DEFAULT_FRAMES = 100
"""Default number of animation frames."""
IMPULSE_WINDOW_FRAMES = 2
"""An impulse's arrow is shown in the frames within this many frame spacings of its time."""
ARROW_LENGTH = 0.6
"""Length of an impulse arrow as a fraction of the mesh's largest extent."""
SHARP_EDGE_DEGREES = 30.0
"""Edges whose faces meet at a larger angle are drawn sharp, the others smooth."""


def html_viewer(
    trajectory: Trajectory,
    mesh: trimesh.Trimesh,
    path: str | PathLike[str] | None = None,
    *,
    title: str,
    loads: Sequence[Gravity | Force | Torque | Impulse] = (),
    frames: int = DEFAULT_FRAMES,
) -> str:
    """A self-contained HTML page showing the body's mesh moving along ``trajectory``.

    Parameters
    ----------
    trajectory : tumble.rigid.Trajectory
        The run: ``t`` shape (n,) in s, ``x`` shape (n, 3) in m, ``R`` shape (n, 3, 3)
        body → world, ``energy`` shape (n,) in J.
    mesh : trimesh.Trimesh
        The body's surface in body coordinates (m, centre of mass at the origin).
    path : str or path-like, optional
        Where to write the page (UTF-8); omitted: only returned.
    title : str
        Shown above the plot and as the page's title.
    loads : sequence
        Loads of :mod:`tumble.rigid.forces`. Each :class:`~tumble.rigid.forces.Impulse` is
        drawn as an arrow (line and cone) ending at its world point, in the frames near its
        time; :class:`~tumble.rigid.forces.Gravity`, :class:`~tumble.rigid.forces.Force` and
        :class:`~tumble.rigid.forces.Torque` are accepted and not drawn.
    frames : int
        Number of animation frames, ≥ 2 (at most this many; see the module docstring).

    Returns
    -------
    str
        The page. plotly.js is inlined (about 4.8 MB); each frame adds about 20 bytes per
        mesh vertex (base64 float32), e.g. 5.3 MB in all for a 260-vertex T-handle and
        13 MB for a 4096-vertex torus at 100 frames (pass a coarser mesh or fewer frames to
        shrink it).

    Raises
    ------
    ValueError
        If ``frames`` < 2, the mesh has no faces, the trajectory's arrays disagree in
        length or shape, ``title`` is not a string or a load is not a load.

    Examples
    --------
    >>> import tumble
    >>> from tumble import meshes
    >>> from tumble.viz.html import html_viewer
    >>> body = tumble.rigid.RigidBody.from_mass_properties(tumble.mass.t_handle())
    >>> run = tumble.rigid.simulate(body, 0.1, h=0.01, omega0=(0.0, 5.0, 0.1))
    >>> page = html_viewer(run, meshes.t_handle(8), title="T-handle", frames=5)
    >>> page.startswith("<!doctype html>"), 'id="tumble-view"' in page
    (True, True)
    """
    figure = viewer_figure(trajectory, mesh, title=title, loads=loads, frames=frames)
    page = figure.to_html(
        include_plotlyjs=True,
        full_html=True,
        div_id=DIV_ID,
        auto_play=False,
        config={"displaylogo": False, "responsive": True},
    )
    page = page.replace("</head>", f"    <title>{html.escape(title)}</title>\n</head>", 1)
    if path is not None:
        atomic_write(path, lambda tmp: tmp.write_text(page, encoding="utf-8"))
    return page


def viewer_figure(
    trajectory: Trajectory,
    mesh: trimesh.Trimesh,
    *,
    title: str,
    loads: Sequence[Gravity | Force | Torque | Impulse] = (),
    frames: int = DEFAULT_FRAMES,
) -> plotly.graph_objects.Figure:
    """The plotly figure of :func:`html_viewer` (same parameters, no ``path``).

    Returns
    -------
    plotly.graph_objects.Figure
        Traces: 0 the mesh (``Mesh3d``), then a line and a cone per drawn impulse, then the
        energy curve, the current-time line and the current-time marker. Each frame updates
        every trace but the energy curve; ``layout.sliders[0].steps[k]`` shows frame ``k``.
    """
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    t, x, R, energy = _trajectory_arrays(trajectory)
    vertices, faces = _mesh_arrays(display_mesh(mesh))
    _check_title_and_frames(title, frames)
    impulses = _impulses(loads)

    index = frame_indices(t, frames)
    times = t[index]
    world = x[index][:, None, :] + np.einsum("kij,vj->kvi", R[index], vertices)
    with np.errstate(over="ignore"):  # a diverged run (|R| > 3e38) is drawn as inf
        world = world.astype(np.float32)
    size = float(np.max(np.ptp(vertices, axis=0)))
    arrows = [_arrow(impulse, ARROW_LENGTH * size) for impulse in impulses]
    shown = [(np.abs(times - impulse.time) <= _window(times)).tolist() for impulse in impulses]
    energy_range = _padded_range(energy)

    def animated(k: int) -> list:
        """The traces frame ``k`` updates: the mesh, the arrows, the current-time marks."""
        traces = [go.Mesh3d(x=world[k, :, 0], y=world[k, :, 1], z=world[k, :, 2])]
        for (line, cone), visible in zip(arrows, shown, strict=True):
            traces += [go.Scatter3d(line, visible=visible[k]), go.Cone(cone, visible=visible[k])]
        traces.append(go.Scatter(x=[times[k]] * 2, y=energy_range))
        traces.append(go.Scatter(x=[times[k]], y=[energy[index[k]]]))
        return traces

    fig = make_subplots(rows=2, cols=1, specs=[[{"type": "scene"}], [{"type": "xy"}]])
    first = animated(0)
    fig.add_trace(style_mesh(first[0], faces), row=1, col=1)
    for line, cone in zip(first[1:-2:2], first[2:-2:2], strict=True):
        fig.add_traces(style_arrow(line, cone), rows=1, cols=1)
    fig.add_trace(energy_curve(t, energy), row=2, col=1)
    fig.add_traces(style_now(*first[-2:]), rows=2, cols=1)

    animated_indices = [0, *range(1, 1 + 2 * len(arrows)), len(fig.data) - 2, len(fig.data) - 1]
    names = [str(k) for k in range(len(index))]
    fig.frames = [
        go.Frame(name=name, data=animated(k), traces=animated_indices)
        for k, name in enumerate(names)
    ]
    apply_layout(fig, title, times, world, arrows, energy_range)
    fig.update_layout(**controls(names, times))
    return fig


def display_mesh(
    mesh: trimesh.Trimesh, *, sharp_edge_degrees: float = SHARP_EDGE_DEGREES
) -> trimesh.Trimesh:
    """``mesh`` with its vertices split along sharp edges, for smooth shading.

    The triangles are the same (possibly reordered); a vertex is duplicated where faces
    meeting at more than ``sharp_edge_degrees`` share it, so that the renderer's averaged
    normals keep a prism's edges sharp and a torus smooth.

    Examples
    --------
    >>> from tumble import meshes
    >>> cube = meshes.box((1.0, 1.0, 1.0))
    >>> len(cube.vertices), len(display_mesh(cube).vertices)  # 3 faces meet at each corner
    (8, 24)
    """
    import trimesh

    vertices, faces = _mesh_arrays(mesh)
    triangles = trimesh.Trimesh(vertices, faces, process=False)
    return trimesh.graph.smooth_shade(triangles, angle=np.radians(sharp_edge_degrees))


def frame_indices(t: np.ndarray, frames: int) -> np.ndarray:
    """Indices of the recorded samples nearest to ``frames`` evenly spaced times.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times (s), non-decreasing.
    frames : int
        Number of evenly spaced times from ``t[0]`` to ``t[-1]``.

    Returns
    -------
    ndarray of int, shape (m,)
        Increasing, without repeats (``m ≤ frames``; ``m < frames`` when samples are fewer
        or uneven).

    Examples
    --------
    >>> frame_indices(np.array([0.0, 0.1, 0.2, 0.3, 0.4]), 3)
    array([0, 2, 4])
    """
    if len(t) == 1:
        return np.zeros(1, dtype=int)
    wanted = np.linspace(t[0], t[-1], frames)
    right = np.clip(np.searchsorted(t, wanted), 1, len(t) - 1)
    nearer_left = np.abs(wanted - t[right - 1]) <= np.abs(t[right] - wanted)
    return np.unique(np.where(nearer_left, right - 1, right))


def _trajectory_arrays(trajectory) -> tuple[np.ndarray, ...]:
    """``t, x, R, energy`` as float arrays, checked to describe the same n ≥ 1 samples."""
    t = np.asarray(trajectory.t, dtype=float)
    if t.ndim != 1 or len(t) == 0 or not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0):
        raise _checks.fail(
            "trajectory.t", trajectory.t, "a non-empty, finite, non-decreasing 1-D array", "s"
        )
    n = len(t)
    arrays = [t]
    for name, shape in (("x", (n, 3)), ("R", (n, 3, 3)), ("energy", (n,))):  # energy from x, R
        array = np.asarray(getattr(trajectory, name), dtype=float)
        if array.shape != shape:
            raise _checks.fail(
                f"trajectory.{name}",
                getattr(trajectory, name),
                f"of shape {shape}, one per sample of trajectory.t",
                remedy=f"it has shape {array.shape}",
            )
        arrays.append(array)
    return tuple(arrays)


def _mesh_arrays(mesh) -> tuple[np.ndarray, np.ndarray]:
    """Body-frame vertices (float) and faces (int32) of a triangle mesh with ≥ 1 face."""
    vertices = np.asarray(getattr(mesh, "vertices", None), dtype=float)
    faces = np.asarray(getattr(mesh, "faces", ()), dtype=np.int64)
    if vertices.ndim != 2 or vertices.shape[1:] != (3,) or len(vertices) == 0:
        raise _checks.fail("mesh", mesh, "a trimesh.Trimesh with vertices")
    if faces.ndim != 2 or faces.shape[1:] != (3,) or len(faces) == 0:
        raise _checks.fail(
            "mesh", mesh, "a triangle mesh (trimesh.Trimesh)", remedy="it has no faces"
        )
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise _checks.fail(
            "mesh",
            mesh,
            "a mesh whose faces index its vertices",
            remedy="some faces index missing vertices",
        )
    return vertices, faces.astype(np.int32)


def _check_title_and_frames(title: str, frames: int) -> None:
    if not isinstance(title, str):
        raise _checks.fail("title", title, "a string")
    _checks.count("frames", frames, 2)


def _impulses(loads) -> list[Impulse]:
    """The impulses among ``loads`` with a non-zero ``J``; the other loads are not drawn."""
    impulses = []
    for position, load in enumerate(loads):
        if isinstance(load, Impulse):
            if np.any(load.impulse != 0):
                impulses.append(load)
        elif not isinstance(load, Gravity | Force | Torque):
            raise _checks.fail(
                f"loads[{position}]",
                load,
                "a load: tumble.Gravity, tumble.Force, tumble.Torque or tumble.Impulse",
            )
    return impulses


def _window(times: np.ndarray) -> float:
    """Half-width (s) of the time window in which an impulse's arrow is shown."""
    spacing = (times[-1] - times[0]) / max(len(times) - 1, 1)
    return IMPULSE_WINDOW_FRAMES * spacing


def _arrow(impulse: Impulse, length: float) -> tuple[dict, dict]:
    """Line and cone data (world, m) of an arrow of ``length`` ending at the impulse's point."""
    direction = impulse.impulse / np.linalg.norm(impulse.impulse)
    head = 0.25 * length
    tail, neck = impulse.point - length * direction, impulse.point - head * direction
    line = {"x": [tail[0], neck[0]], "y": [tail[1], neck[1]], "z": [tail[2], neck[2]]}
    u, v, w = head * direction
    cone = {"x": [impulse.point[0]], "y": [impulse.point[1]], "z": [impulse.point[2]]}
    return line, {**cone, "u": [u], "v": [v], "w": [w]}


def _padded_range(values: np.ndarray) -> list[float]:
    """A y range holding the finite ``values`` with a margin (at least 1e-6 relative)."""
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return [0.0, 1.0]
    low, high = float(finite.min()), float(finite.max())
    margin = max(0.08 * (high - low), 1e-6 * max(abs(low), abs(high)), 1e-12)
    return [low - margin, high + margin]


__all__ = [
    "ARROW_COLOR",
    "ARROW_LENGTH",
    "DEFAULT_FRAMES",
    "DIV_ID",
    "ENERGY_POINTS",
    "ENERGY_TOP",
    "FRAME_DURATION_MS",
    "IMPULSE_WINDOW_FRAMES",
    "MESH_COLOR",
    "NOW_COLOR",
    "SCENE_BOTTOM",
    "SHARP_EDGE_DEGREES",
    "SLIDER_TOP",
    "display_mesh",
    "frame_indices",
    "html_viewer",
    "viewer_figure",
]
