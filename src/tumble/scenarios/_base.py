"""What a scenario is, and the pieces the rigid-body scenarios share.

A built-in scenario is a module in :mod:`tumble.scenarios` with

* ``NAME`` — the name used on the command line (``tumble run NAME``),
* ``SUMMARY`` — one line for ``tumble list``,
* ``run(**options) -> ScenarioResult`` — pure computation, no files, no printing.

:class:`tumble.io.ScenarioResult` (also ``tumble.scenarios.ScenarioResult``) is defined beside
the run folders it becomes (:func:`tumble.io.write_run_folder`). The helpers here build its
animations, datasets and attributes for a rigid-body run (:func:`rigid_outputs`), and draw
a run folder's ``view.html`` again from its ``data.nc`` (:func:`view_page`, ``tumble view``):
the same page the run wrote, since the ``mesh`` group records what the page shows.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from tumble.io import FigureWriter


def rigid_animations(
    trajectory, mesh, *, title: str, loads: tuple = (), animation: bool = True
) -> list[tuple[str, FigureWriter]]:
    """The moving-body outputs of a rigid-body run: ``animation.gif`` and ``view.html``.

    Parameters
    ----------
    trajectory : tumble.rigid.Trajectory
        The run to show.
    mesh : trimesh.Trimesh
        The body's surface in body coordinates (centre of mass at the origin).
    title : str
        Scenario and method, shown on both.
    loads : tuple
        Forces and impulses to draw as arrows (:mod:`tumble.rigid.forces`).
    animation : bool
        False returns no writers (``--no-animation``).
    """
    if not animation:
        return []
    frames = animation_frames(trajectory)

    def gif(path: Path) -> None:
        from tumble.viz.animation import animate_body

        with np.errstate(**_quiet(trajectory)):
            animate_body(trajectory, mesh, path, title=title, loads=loads, frames=frames)

    def html(path: Path) -> None:
        _draw_view(trajectory, mesh, path, title=title, loads=loads)

    return [("animation.gif", gif), (VIEW_FILE, html)]


def _quiet(trajectory) -> dict[str, Any]:
    """A run stopped by overflow ends in huge, non-rotation matrices: draw them quietly."""
    return {"over": "ignore", "invalid": "ignore"} if trajectory.status < 0 else {}


def _draw_view(trajectory, mesh, path: Path, *, title: str, loads: tuple) -> None:
    """``view.html`` of ``trajectory``: what a run writes and :func:`view_page` draws again."""
    from tumble.viz.html import html_viewer

    with np.errstate(**_quiet(trajectory)):
        html_viewer(trajectory, mesh, path, title=title, loads=loads,
                    frames=animation_frames(trajectory))  # fmt: skip


def rigid_outputs(
    runs: Mapping[str, Any], mesh, *, shown: str | None = None, title: str, loads: tuple = ()
) -> dict[str, Any]:
    """The datasets and the moving-body outputs of a rigid-body scenario, as
    ``ScenarioResult(..., **rigid_outputs(...))`` takes them.

    Parameters
    ----------
    runs : mapping of str to tumble.rigid.Trajectory
        The runs, by name (the groups of ``data.nc``; one run is its root group).
    mesh : trimesh.Trimesh
        The body's surface in body coordinates (centre of mass at the origin).
    shown : str, optional
        The run the animation and ``view.html`` show (default :func:`showcase`'s choice).
    title : str
        Shown on the animation and the page.
    loads : tuple
        Forces and impulses to draw as arrows.

    Returns
    -------
    dict
        ``datasets`` (:func:`rigid_datasets`, the ``mesh`` group recording the shown run,
        the title and the impulses) and ``animations`` (:func:`rigid_animations`).
    """
    shown = shown if shown is not None else showcase(runs)
    return {
        "datasets": rigid_datasets(runs, mesh, shown, title=title, loads=loads),
        "animations": rigid_animations(runs[shown], mesh, title=title, loads=loads),
    }


MAX_TURN_PER_FRAME = 0.5
"""Largest turn (rad) between two animation frames, so the eye can follow the spin."""
FRAMES = (40, 200)
"""Fewest and most animation frames."""


def animation_frames(trajectory) -> int:
    """Frames enough that the body turns at most :data:`MAX_TURN_PER_FRAME` between two.

    ``n = ⌈max|ω| · T / 0.5⌉`` clipped to :data:`FRAMES` (T-handle, 100 s at 1 rad/s: 200).
    """
    with np.errstate(invalid="ignore", over="ignore"):
        rate = np.nanmax(np.linalg.norm(trajectory.omega_body, axis=1), initial=0.0)
    span = float(trajectory.t[-1] - trajectory.t[0])
    wanted = np.ceil(rate * span / MAX_TURN_PER_FRAME) if np.isfinite(rate) else FRAMES[1]
    return int(np.clip(wanted, *FRAMES))


SHOWCASE_ORDER = ("rkmk4", "rkmk45", "rk4-quat", "lie-euler")
"""Which run of a multi-method scenario the animation shows: the first of these present."""


def showcase(runs: Mapping[str, Any]) -> str:
    """The name of the run to animate: the best-behaved method present, else the first."""
    return next((name for name in SHOWCASE_ORDER if name in runs), next(iter(runs)))


def rigid_datasets(
    runs: Mapping[str, Any],
    mesh=None,
    shown: str | None = None,
    *,
    title: str | None = None,
    loads: tuple = (),
) -> dict[str, Any]:
    """One ``xarray.Dataset`` per trajectory, keyed like ``runs`` (the groups of ``data.nc``).

    A single run is keyed ``""``: ``data.nc``'s root group, what ``xr.open_dataset`` shows.
    With ``mesh``, a group ``mesh`` (:func:`mesh_dataset`) holds its ``vertices`` (m, body
    frame) and ``faces``, names the run the animation shows (attribute ``shows``; ``""`` for
    the root) and records the page's ``title`` and the impulses among ``loads``, so
    ``tumble view`` draws the same ``view.html`` again from ``data.nc`` alone.
    """
    if len(runs) == 1:
        datasets = {"": next(iter(runs.values())).to_xarray()}
        shown = ""
    else:
        datasets = {name: run.to_xarray() for name, run in runs.items()}
        shown = shown or showcase(runs)
    if mesh is not None:
        datasets["mesh"] = mesh_dataset(mesh, shows=shown, title=title, loads=loads)
    return datasets


def mesh_dataset(mesh, *, shows: str, title: str | None = None, loads: tuple = ()):
    """A triangle mesh as an ``xarray.Dataset`` (``vertices`` in m, ``faces`` as indices).

    Attributes ``shows`` (the run shown) and ``title`` (the viewer's, when given); the
    :class:`~tumble.rigid.forces.Impulse` loads, drawn as arrows, as ``impulse`` (N s),
    ``impulse_point`` (m, world) and ``impulse_time`` (s), one per ``kick`` (a netCDF
    dimension cannot share the name of a 2-D variable).
    """
    import xarray as xr

    from tumble.rigid import Impulse

    variables: dict[str, Any] = {
        "vertices": (("vertex", "axis"), np.asarray(mesh.vertices), {"units": "m"}),
        "faces": (("face", "corner"), np.asarray(mesh.faces, dtype=np.int64)),
    }
    impulses = [load for load in loads if isinstance(load, Impulse)]
    if impulses:
        variables["impulse"] = (
            ("kick", "axis"),
            [i.impulse for i in impulses],
            {"units": "N s", "long_name": "impulse J, world frame"},
        )
        variables["impulse_point"] = (
            ("kick", "axis"),
            [i.point for i in impulses],
            {"units": "m", "long_name": "where J acts, world frame"},
        )
        variables["impulse_time"] = (
            "kick",
            [float(i.time) for i in impulses],
            {"units": "s", "long_name": "when J acts"},
        )
    attrs = {"shows": shows} if title is None else {"shows": shows, "title": title}
    return xr.Dataset(variables, coords={"axis": ["x", "y", "z"]}, attrs=attrs)


def _mesh_loads(mesh_data) -> tuple:
    """The impulses :func:`mesh_dataset` recorded, as loads again."""
    from tumble.rigid import Impulse

    if "impulse" not in mesh_data:
        return ()
    return tuple(
        Impulse(point=point, impulse=impulse, time=float(time))
        for impulse, point, time in zip(mesh_data["impulse"].values,
                                        mesh_data["impulse_point"].values,
                                        mesh_data["impulse_time"].values, strict=True)
    )  # fmt: skip


def rigid_attrs(body, **settings: Any) -> dict[str, Any]:
    """The root attributes of ``data.nc`` for a rigid-body scenario: settings, mass, inertia."""
    return {**settings, "mass": float(body.mass), "inertia": np.ravel(body.inertia).tolist()}


VIEW_FILE = "view.html"
"""The interactive viewer's page in a run folder."""


def view_page(run_dir: str | Path) -> Path:
    """The run's ``view.html``, drawn again from ``data.nc`` when it is not there.

    A page the run's ``summary.json`` does not list (left by an earlier run) is drawn again
    too. The run shown, the body, the title and the impulses come from ``data.nc``'s
    ``mesh`` group (:func:`mesh_dataset`), so the page is the one the run wrote, byte for
    byte. (Run folders written before the group held a title get one made of the scenario,
    the run's name and its method, and no arrows.)

    Raises
    ------
    ValueError
        If ``run_dir`` is not a complete run folder (:func:`tumble.io.load`), or its run has
        no body mesh (a projectile, a beam).
    """
    run_dir = Path(run_dir)
    page = run_dir / VIEW_FILE
    if page.is_file() and _listed(run_dir, page.name):
        return page
    import trimesh

    from tumble._atomic import atomic_write
    from tumble.io import load
    from tumble.rigid import Trajectory

    run = load(run_dir)
    if "mesh" not in run.groups:
        raise ValueError(
            f"run_dir={str(run_dir)!r} holds no body mesh (scenario "
            f"{run.attrs.get('scenario')!r}); the viewer shows rigid-body runs only"
        )
    mesh_data = run.dataset("mesh")
    mesh = trimesh.Trimesh(mesh_data["vertices"].values, mesh_data["faces"].values, process=False)
    shows = mesh_data.attrs["shows"]
    trajectory = Trajectory.from_xarray(run.dataset(shows))
    title = mesh_data.attrs.get("title") or (
        f"{run.attrs.get('scenario')} — {f'{shows}, ' if shows else ''}{trajectory.method}"
    )
    loads = _mesh_loads(mesh_data)
    atomic_write(page, lambda tmp: _draw_view(trajectory, mesh, tmp, title=title, loads=loads))
    return page


def _listed(run_dir: Path, name: str) -> bool:
    """Whether the run's ``summary.json`` lists ``name`` (a file of this run, not a stale one)."""
    import json

    from tumble.io import SUMMARY_FILE

    try:
        return name in json.loads((run_dir / SUMMARY_FILE).read_text(encoding="utf-8"))["files"]
    except (OSError, ValueError, KeyError, TypeError):
        return False
