"""What a scenario is, and the pieces the rigid-body scenarios share.

A built-in scenario is a module in :mod:`tumble.scenarios` with

* ``NAME`` — the name used on the command line (``tumble run NAME``),
* ``SUMMARY`` — one line for ``tumble list``,
* ``run(**options) -> ScenarioResult`` — pure computation, no files, no printing.

:class:`tumble.io.ScenarioResult` (also ``tumble.scenarios.ScenarioResult``) is defined beside
the run folders it becomes (:func:`tumble.io.write_run_folder`). The helpers here build its
animations, datasets and attributes for a rigid-body run.
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

    # a run stopped by overflow ends in huge, non-rotation matrices: draw them quietly
    quiet: dict[str, Any] = (
        {"over": "ignore", "invalid": "ignore"} if trajectory.status < 0 else {}
    )

    def gif(path: Path) -> None:
        from tumble.viz.animation import animate_body

        with np.errstate(**quiet):
            animate_body(trajectory, mesh, path, title=title, loads=loads, frames=frames)

    def html(path: Path) -> None:
        from tumble.viz.html import html_viewer

        with np.errstate(**quiet):
            html_viewer(trajectory, mesh, path, title=title, loads=loads, frames=frames)

    return [("animation.gif", gif), ("view.html", html)]


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


def rigid_datasets(runs: Mapping[str, Any], mesh=None, shown: str | None = None) -> dict[str, Any]:
    """One ``xarray.Dataset`` per trajectory, keyed like ``runs`` (the groups of ``data.nc``).

    A single run is keyed ``""``: ``data.nc``'s root group, what ``xr.open_dataset`` shows.
    With ``mesh``, a group ``mesh`` holds its ``vertices`` (m, body frame) and ``faces``, and
    names the run the animation shows (attribute ``shows``; ``""`` for the root), so
    ``tumble view`` can draw it again from ``data.nc`` alone.
    """
    if len(runs) == 1:
        datasets = {"": next(iter(runs.values())).to_xarray()}
        shown = ""
    else:
        datasets = {name: run.to_xarray() for name, run in runs.items()}
        shown = shown or showcase(runs)
    if mesh is not None:
        datasets["mesh"] = mesh_dataset(mesh, shows=shown)
    return datasets


def mesh_dataset(mesh, *, shows: str):
    """A triangle mesh as an ``xarray.Dataset`` (``vertices`` in m, ``faces`` as indices)."""
    import xarray as xr

    return xr.Dataset(
        {
            "vertices": (("vertex", "axis"), np.asarray(mesh.vertices), {"units": "m"}),
            "faces": (("face", "corner"), np.asarray(mesh.faces, dtype=np.int64)),
        },
        coords={"axis": ["x", "y", "z"]},
        attrs={"shows": shows},
    )


def rigid_attrs(body, **settings: Any) -> dict[str, Any]:
    """The root attributes of ``data.nc`` for a rigid-body scenario: settings, mass, inertia."""
    return {**settings, "mass": float(body.mass), "inertia": np.ravel(body.inertia).tolist()}


VIEW_FILE = "view.html"
"""The interactive viewer's page in a run folder."""


def view_page(run_dir: str | Path) -> Path:
    """The run's ``view.html``, drawn again from ``data.nc`` when it is not there.

    A page the run's ``summary.json`` does not list (left by an earlier run) is drawn again
    too. The run shown and the body come from ``data.nc``'s ``mesh`` group
    (:func:`rigid_datasets`).

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
    from tumble.viz.html import html_viewer

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
    title = f"{run.attrs.get('scenario')} — {f'{shows}, ' if shows else ''}{trajectory.method}"
    atomic_write(page, lambda tmp: html_viewer(trajectory, mesh, tmp, title=title))
    return page


def _listed(run_dir: Path, name: str) -> bool:
    """Whether the run's ``summary.json`` lists ``name`` (a file of this run, not a stale one)."""
    import json

    from tumble.io import SUMMARY_FILE

    try:
        return name in json.loads((run_dir / SUMMARY_FILE).read_text(encoding="utf-8"))["files"]
    except (OSError, ValueError, KeyError, TypeError):
        return False
