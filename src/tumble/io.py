"""Run folders: what a scenario returns, and every file written whole or not at all.

A scenario's :class:`ScenarioResult` (headline numbers, datasets, picture writers) becomes a
run folder, which holds

* ``data.nc`` — the trajectories as netCDF-4 (h5netcdf): one group per run, the run's settings
  (scenario, method, step or tolerances, mass, inertia, tumble version) as root attributes;
* the scenario's PNGs, and ``animation.gif`` and ``view.html`` for the moving body;
* ``summary.json`` — the headline numbers and the list of files, written last.

Each file is first written under a temporary name in the same folder and then renamed, so a
crash never leaves half a file behind (a folder without ``summary.json`` was interrupted).
:func:`load` reads a folder back.

Examples
--------
>>> import tempfile
>>> from tumble import io, scenarios
>>> result = scenarios.get("projectile").run(h=0.5)
>>> folder = io.write_run_folder(result, tempfile.mkdtemp())
>>> run = io.load(folder)
>>> run.attrs["scenario"], run.summary["method"]
('projectile', 'rk4')
>>> round(float(run.dataset()["x"][-1]), 1) > 25000
True
"""

from __future__ import annotations

import errno
import json
import logging
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from tumble import _checks
from tumble._atomic import atomic_write, stale_partials
from tumble._version import __version__

log = logging.getLogger(__name__)

FigureWriter = Callable[[Path], None]
"""Draws one file (a picture, an animation) at the path it is given; the drawing is in viz."""


@dataclass
class ScenarioResult:
    """The outcome of one scenario run: pure data and writers, nothing written yet.

    A scenario's ``run(**options)`` returns one (:mod:`tumble.scenarios`);
    :func:`write_run_folder` turns it into a run folder.

    Attributes
    ----------
    name : str
        The scenario's name.
    summary : dict
        Headline numbers and settings, JSON-serialisable (written to ``summary.json``).
    data : dict
        Arrays and objects (trajectories, datasets) for further use; not written as-is.
    figures : list of (str, callable)
        ``(file_name, writer)`` pairs; ``writer(path)`` draws the file at ``path``.
    datasets : dict of str to xarray.Dataset
        Written to ``data.nc``, one netCDF group per entry (a single entry named ``""`` is
        the root group).
    attrs : dict
        The run's settings (method, step or tolerances, mass, inertia, …), written as the
        root attributes of ``data.nc``; numbers, strings and lists of numbers only.
    animations : list of (str, callable)
        Like ``figures``, for the slower outputs (``animation.gif``, ``view.html``).
    expected_stops : tuple of str
        Runs in ``data`` (as :meth:`unfinished` names them) whose stop is what the scenario
        shows, such as a conditionally stable scheme past its step limit: not reported as
        unfinished.
    """

    name: str
    summary: dict[str, Any]
    data: dict[str, Any] = field(default_factory=dict)
    figures: list[tuple[str, FigureWriter]] = field(default_factory=list)
    datasets: dict[str, Any] = field(default_factory=dict)
    attrs: dict[str, Any] = field(default_factory=dict)
    animations: list[tuple[str, FigureWriter]] = field(default_factory=list)
    expected_stops: tuple[str, ...] = ()

    def unfinished(self) -> list[tuple[str, str]]:
        """The runs in :attr:`data` that stopped before their end: ``(where, message)`` for
        every result whose ``status`` (a :class:`~tumble.ode.Status`, or one per body of a
        batch) is negative, found through nested dicts, lists and tuples, less
        :attr:`expected_stops`.

        Examples
        --------
        >>> from tumble.ode.driver import Status
        >>> class Run:
        ...     status, message = Status.FAILED, "the state became non-finite at t=0.3"
        >>> ScenarioResult("demo", {}, data={"trajectories": {"rkmk4": Run()}}).unfinished()
        [('trajectories.rkmk4', 'the state became non-finite at t=0.3')]
        """
        found: list[tuple[str, str]] = []
        _collect_unfinished(self.data, "", found)
        return [(where, message) for where, message in found if where not in self.expected_stops]


def _collect_unfinished(value: Any, where: str, found: list, depth: int = 0) -> None:
    if depth > 4:
        return
    if isinstance(value, dict):
        for key, item in value.items():
            _collect_unfinished(item, f"{where}.{key}" if where else str(key), found, depth + 1)
    elif isinstance(value, list | tuple):
        for index, item in enumerate(value):
            _collect_unfinished(item, f"{where}[{index}]", found, depth + 1)
    elif hasattr(value, "status"):
        status = np.atleast_1d(np.asarray(value.status))
        messages = getattr(value, "messages", None) or [getattr(value, "message", "")]
        for stopped in np.flatnonzero(status < 0).tolist():
            label = f"{where}[{stopped}]" if status.size > 1 else where
            found.append((label, str(messages[min(stopped, len(messages) - 1)])))


def _finite(value: Any) -> Any:
    """``value`` with every non-finite float (NaN, ±inf) replaced by None, recursively."""
    if isinstance(value, dict):
        return {key: _finite(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(item) for item in value]
    if isinstance(value, float | np.floating) and not np.isfinite(value):
        return None
    return value


def write_json(path: str | Path, data: dict) -> Path:
    """Write ``data`` as indented, strict JSON (NaN and ±inf become ``null``), atomically."""
    text = json.dumps(_finite(data), indent=2, sort_keys=False, allow_nan=False) + "\n"
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def prepare_folder(out: str | Path, *, force: bool = False) -> Path:
    """Create the run folder ``out``; refuse a non-empty one unless ``force``.

    Temporary files that an interrupted run left behind (``.NAME.XXXX.partial.SUFFIX``) are
    removed first: they are never a run's files.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"out={str(out)!r} exists and is not a folder")
    if out.is_dir():
        for stale in stale_partials(out):
            stale.unlink(missing_ok=True)
    if out.is_dir() and any(out.iterdir()) and not force:
        raise ValueError(
            f"out={str(out)!r} already holds files; choose another folder or pass force=True "
            "(--force on the command line) to overwrite them"
        )
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise ValueError(
            f"out={str(out)!r} cannot be created: {error.strerror or error}; choose a folder "
            "under one you can write to"
        ) from None
    return out


DATA_FILE = "data.nc"
SUMMARY_FILE = "summary.json"


def _attribute(value: Any) -> Any:
    """A netCDF-storable attribute: numbers, strings and flat numeric arrays as they are."""
    if isinstance(value, bool | np.bool_):
        return int(value)
    if isinstance(value, str | int | float | np.integer | np.floating):
        return value
    array = np.asarray(value) if isinstance(value, list | tuple | np.ndarray) else None
    if array is not None and array.dtype.kind in "iuf" and array.size:
        return array.ravel()
    return json.dumps(value, default=str)


def netcdf_attrs(attrs: Mapping[str, Any]) -> dict[str, Any]:
    """``attrs`` made storable: None dropped, bools as 0/1, nested data as JSON text."""
    return {key: _attribute(value) for key, value in attrs.items() if value is not None}


def write_dataset(path: str | Path, datasets: Mapping[str, Any], attrs: Mapping[str, Any]) -> Path:
    """Write ``datasets`` as one netCDF-4 file, one group each, ``attrs`` on the root group.

    A dataset named ``""`` becomes the root group itself, what ``xarray.open_dataset`` shows.
    Without one, the root's attribute ``groups`` lists the groups, and ``comment`` says how to
    open them all. The file is written atomically.
    """
    import xarray as xr

    groups = {
        f"/{name}" if name else "/": ds.assign_attrs(netcdf_attrs(ds.attrs))
        for name, ds in datasets.items()
    }
    root = groups.pop("/", xr.Dataset())
    attrs = {**attrs, "tumble_version": __version__}
    if not root.data_vars and groups:
        attrs["groups"] = ", ".join(name.lstrip("/") for name in groups)
        attrs["comment"] = (
            "one group per run: xarray.open_datatree(path) opens them all, "
            "xarray.open_dataset(path, group=name) one; tumble.io.load(folder) reads the "
            "run folder"
        )
    root = root.assign_attrs(netcdf_attrs(attrs))
    tree = xr.DataTree.from_dict({"/": root, **groups})
    return atomic_write(path, lambda tmp: tree.to_netcdf(tmp, engine="h5netcdf"))


def write_run_folder(
    result: ScenarioResult,
    out: str | Path,
    *,
    force: bool = False,
    animation: bool = True,
    on_file: Callable[[str], None] | None = None,
    mp4: bool = False,
) -> Path:
    """Write a scenario's run folder: pictures, ``data.nc``, then ``summary.json``.

    Parameters
    ----------
    result : ScenarioResult
        What :func:`tumble.scenarios.get(name).run() <tumble.scenarios.get>` returned.
    out : path
        The folder; created if missing, refused if it holds files unless ``force``.
    force : bool
        Overwrite files in an existing folder.
    animation : bool
        Write ``result.animations`` (``animation.gif``, ``view.html``) too.
    on_file : callable, optional
        Called with each file's name before it is written (for progress display).
    mp4 : bool
        Write ``animation.mp4`` too: beside ``animation.gif``, or alone without
        ``animation`` (the GIF's writer: the format comes from the suffix; ffmpeg from the
        ``imageio-ffmpeg`` dependency).

    Returns
    -------
    Path
        The folder.

    Raises
    ------
    ValueError
        With ``mp4`` for a result that has no animation (before anything is written).
    """
    given = list(result.animations)
    movie = [("animation.mp4", w) for name, w in given if name == "animation.gif"] if mp4 else []
    if mp4 and not movie:
        raise _checks.fail("mp4", True, "given only for a result with an animation",
                           remedy=f"{result.name!r} draws none; leave out --mp4")  # fmt: skip
    out = prepare_folder(out, force=force)
    _forget_previous_run(out)
    animations = (given if animation else []) + movie
    writers = list(result.figures) + animations
    files = []
    notify = on_file or (lambda name: None)
    for name, writer in writers:
        log.info("writing %s", out / name)
        notify(name)
        atomic_write(out / name, writer)
        files.append(name)
    if result.datasets:
        notify(DATA_FILE)
        attrs = {"scenario": result.name, **result.attrs}
        write_dataset(out / DATA_FILE, result.datasets, attrs)
        files.append(DATA_FILE)
    write_json(out / SUMMARY_FILE, {**result.summary, "files": files})
    return out


def write_figures(
    out: str | Path, figures: Sequence[tuple[str, FigureWriter]], *, force: bool = False
) -> list[Path]:
    """Write each ``(name, writer)`` of ``figures`` into the folder ``out``, atomically.

    Unlike :func:`write_run_folder`, only these files are written (no ``summary.json``, no
    ``data.nc``), beside whatever the folder holds; the folder is created if missing.

    Returns
    -------
    list of Path
        The files, in the order of ``figures``.

    Raises
    ------
    FileExistsError
        If one of the files exists and ``force`` is False (its path is the error's
        ``filename``); nothing is written then.
    """
    folder = Path(out)
    paths = [folder / name for name, _ in figures]
    for path in paths:
        if path.exists() and not force:
            raise FileExistsError(
                errno.EEXIST, "exists; pass force=True to overwrite it", str(path)
            )
    folder.mkdir(parents=True, exist_ok=True)
    for path, (_, writer) in zip(paths, figures, strict=True):
        atomic_write(path, writer)
    return paths


def _forget_previous_run(out: Path) -> None:
    """Remove an earlier run's ``summary.json`` and then the files it lists (``--force``).

    The summary goes first, so an interruption never leaves the old summary beside new files.
    """
    summary = out / SUMMARY_FILE
    if not summary.is_file():
        return
    try:
        listed = json.loads(summary.read_text(encoding="utf-8")).get("files", [])
    except (OSError, ValueError, AttributeError):
        listed = []
    summary.unlink()
    for name in listed:
        if isinstance(name, str) and Path(name).name == name:
            (out / name).unlink(missing_ok=True)


@dataclass(frozen=True)
class Run:
    """A run folder read back by :func:`load`.

    Attributes
    ----------
    path : Path
        The folder.
    summary : dict
        ``summary.json``.
    data : xarray.DataTree
        ``data.nc``, loaded into memory (one group per run).
    """

    path: Path
    summary: dict
    data: Any

    @property
    def attrs(self) -> dict:
        """The run's settings: the root attributes of ``data.nc``."""
        return dict(self.data.attrs)

    @property
    def groups(self) -> list[str]:
        """Names of the runs in ``data.nc`` (``""`` is the root group)."""
        return [node.path.lstrip("/") for node in self.data.subtree if node.data_vars]

    def dataset(self, name: str | None = None):
        """The ``xarray.Dataset`` of one run (the only one when ``name`` is None).

        ``""`` is the root group: a single-run scenario's data. The body's ``mesh`` group is
        not a run, so it is never chosen for ``name=None``.
        """
        groups = self.groups
        if name is None:
            runs = [group for group in groups if group != "mesh"]
            if len(runs) != 1:
                raise ValueError(f"name=None is ambiguous: this run has the groups {groups}")
            name = runs[0]
        if name not in groups:
            raise ValueError(f"name={name!r} is not a run in {self.path}; choose one of {groups}")
        return self.data[f"/{name}" if name else "/"].to_dataset()


def load(path: str | Path) -> Run:
    """Read a run folder (or its ``data.nc``) written by :func:`write_run_folder`.

    Raises
    ------
    ValueError
        If the folder or its ``summary.json`` / ``data.nc`` is missing or unreadable, or a file
        that ``summary.json`` lists is not in the folder.
    """

    if not isinstance(path, str | PathLike):
        raise _checks.fail("path", path, "a run folder or its data.nc, as a str or Path")
    path = Path(path)
    folder = path.parent if path.name == DATA_FILE else path
    for name in (SUMMARY_FILE, DATA_FILE):
        if not (folder / name).is_file():
            raise ValueError(f"path={str(path)!r} is not a complete run folder: {name} is missing")
    summary = _read_summary(folder)
    missing = [name for name in summary["files"] if not (folder / name).is_file()]
    if missing:
        raise ValueError(
            f"path={str(path)!r} is not a complete run folder: {SUMMARY_FILE} lists {missing}, "
            "which are not there (moved, deleted, or the folder was copied in part)"
        )
    data, reason = _read_tree(folder / DATA_FILE)
    if data is None:
        raise ValueError(
            f"path={str(path)!r}: {DATA_FILE} could not be read ({reason}); it is damaged or not "
            "a netCDF-4 file written by tumble: run the scenario again"
        )
    shared = [
        key
        for key, value in data.attrs.items()
        if key in summary and np.ndim(value) == 0 and isinstance(summary[key], str | int | float)
        and summary[key] == summary[key]  # not NaN
    ]  # fmt: skip
    differ = [key for key in shared if not summary[key] == data.attrs[key]]
    if differ:  # summary.json and data.nc of two runs (the README: checked against each other)
        key, written = differ[0], np.asarray(data.attrs[differ[0]]).item()
        raise ValueError(
            f"path={str(path)!r} mixes two runs: {SUMMARY_FILE} has {key}={summary[key]!r} and "
            f"{DATA_FILE} {key}={written!r}; copy both files of one run, or run it again"
        )
    return Run(folder, summary, data)


def _read_tree(file: Path) -> tuple[Any, str]:
    """``(the file's DataTree, "")``, or ``(None, why not)`` for a damaged file.

    h5netcdf leaves a half-opened file behind when the root group's header is damaged; its
    ``close`` fails again when it is collected, and Python prints "Exception ignored in ..."
    on stderr. It is collected here, with that report silenced, before the caller refuses
    the file in one message.
    """
    import gc
    import sys

    import xarray as xr

    hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: None
    try:
        try:
            with xr.open_datatree(file, engine="h5netcdf") as tree:
                return tree.load().copy(), ""
        except Exception as error:  # noqa: BLE001 - h5py and netCDF raise KeyError, OSError, ...
            reason = str(error)
        gc.collect()  # the half-opened file, now that the traceback holding it is gone
        return None, reason
    finally:
        sys.unraisablehook = hook


def _read_summary(folder: Path) -> dict:
    """``summary.json``, checked to be an object whose ``files`` is a list of file names."""
    where = f"{str(folder / SUMMARY_FILE)!r}"
    try:
        summary = json.loads((folder / SUMMARY_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise ValueError(f"{where} could not be read: {error}") from None
    files = summary.get("files") if isinstance(summary, dict) else None
    if not isinstance(files, list) or not all(
        isinstance(name, str) and Path(name).name == name for name in files
    ):
        raise ValueError(f"{where} is not a tumble run summary: it needs 'files', a list of names")
    return summary
