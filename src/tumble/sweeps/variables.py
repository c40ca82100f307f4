"""What a ``rigid-body`` sweep stores per member: one row per variable.

Each row of :data:`VARIABLES` is a variable of the store: its dimensions after the members'
(and after ``time`` for a series), dtype, CF units and long name, and how to compute it from
a batch of runs (:class:`Runs`: the members of one ``simulate_batch`` call, or one
``simulate`` run as a batch of one). :mod:`~tumble.sweeps.members` fills every row the same
way for both, :mod:`~tumble.sweeps.store` declares the store from the rows, and
:mod:`~tumble.sweeps.plan` sizes the tasks from them (:func:`member_bytes`). Adding a
variable is adding a row here.

A built-in scenario's sweep stores the numbers of its summary instead
(:func:`~tumble.sweeps.members.summary_numbers`), beside :data:`WALL_TIME`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from tumble.rigid import BatchTrajectory, Trajectory
from tumble.scenarios.t_handle import measured_periods

EXTRA_DIMS: dict[str, list] = {"axis": ["x", "y", "z"], "row": [0, 1, 2], "col": [0, 1, 2]}
"""The dimensions a variable may have after ``time`` (vectors, matrices), with the labels
the store gives them as coordinates."""


@dataclass(frozen=True)
class Runs:
    """A batch of runs on one time grid: what every row of :data:`VARIABLES` computes from.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times (s).
    x, v, L_world, omega_body : ndarray, shape (m, n, 3)
        Centre of mass (m), its velocity (m/s), angular momentum (kg m²/s, world) and body
        angular velocity (rad/s); NaN after a run that stopped.
    R : ndarray, shape (m, n, 3, 3)
        Attitude, body to world.
    energy : ndarray, shape (m, n)
        Total energy (J).
    status, n_steps, n_recorded : ndarray, shape (m,)
        Each run's :class:`~tumble.ode.driver.Status` code, steps, and valid samples.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    R: np.ndarray
    L_world: np.ndarray
    omega_body: np.ndarray
    energy: np.ndarray
    status: np.ndarray
    n_steps: np.ndarray
    n_recorded: np.ndarray

    @classmethod
    def from_batch(cls, batch: BatchTrajectory) -> Runs:
        """The runs of one :func:`~tumble.rigid.simulate_batch` call."""
        return cls(batch.t, batch.x, batch.v, batch.R, batch.L_world, batch.omega_body,
                   batch.energy, batch.status, batch.n_steps, batch.n_recorded)  # fmt: skip

    @classmethod
    def from_trajectory(cls, run: Trajectory) -> Runs:
        """One :func:`~tumble.rigid.simulate` run as a batch of one (its own arrays, so its
        numbers are the run's bit for bit)."""
        return cls(run.t, run.x[None], run.v[None], run.R[None], run.L_world[None],
                   run.omega_body[None], run.energy[None], np.array([int(run.status)]),
                   np.array([run.n_steps]), np.array([len(run.t)]))  # fmt: skip


def energy_error(runs: Runs) -> np.ndarray:
    """``|E(t_end)/E(0) − 1|`` of each run (at its last valid sample; NaN where E(0) = 0)."""
    first = runs.energy[:, 0]
    last = np.take_along_axis(runs.energy, runs.n_recorded[:, None] - 1, axis=1)[:, 0]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return np.where(first != 0, np.abs(last / first - 1), np.nan)


def flip_period(runs: Runs) -> np.ndarray:
    """The period of ω_body (:func:`~tumble.scenarios.t_handle.measured_periods`), NaN for a
    run that stopped or saw fewer than three crossings."""
    return np.where(runs.status >= 0, measured_periods(runs.t, runs.omega_body), np.nan)


class Variable(NamedTuple):
    """One stored variable: a row of :data:`VARIABLES`.

    Attributes
    ----------
    extra : tuple of str
        Its dimensions after the members' and ``time`` (a series), or after the members'
        (a summary): names of :data:`EXTRA_DIMS`.
    dtype : str
        NumPy dtype of the stored values.
    units : str
        CF units.
    long_name : str
        What it is.
    compute : callable or None
        ``compute(runs)``: an array with a leading run axis (shape ``(m, n, *extra)`` for a
        series, ``(m,)`` for a summary). None for :data:`WALL_TIME`, which the task
        measures itself.
    series : bool
        Whether it is a time series (stored only when the members share their times).
    """

    extra: tuple[str, ...]
    dtype: str
    units: str
    long_name: str
    compute: Callable[[Runs], np.ndarray] | None
    series: bool = False

    def sample_bytes(self) -> int:
        """Bytes of one member's value (of one sample, for a series)."""
        size = math.prod(len(EXTRA_DIMS[dim]) for dim in self.extra)
        return size * np.dtype(self.dtype).itemsize


def _series(name: str) -> Callable[[Runs], np.ndarray]:
    """The rows' ``compute`` of a series the runs hold under ``name``."""

    def compute(runs: Runs) -> np.ndarray:
        return getattr(runs, name)

    compute.__name__ = name
    return compute


WALL_TIME = "wall_time"
"""The variable every sweep stores (a built-in's too): the member's share of its run's time."""

VARIABLES: dict[str, Variable] = {
    "x": Variable(("axis",), "float64", "m", "centre of mass, world frame", _series("x"), True),
    "v": Variable(("axis",), "float64", "m/s", "velocity of the centre of mass, world frame",
                  _series("v"), True),
    "R": Variable(("row", "col"), "float64", "1", "attitude, body to world", _series("R"), True),
    "L_world": Variable(("axis",), "float64", "kg m2/s",
                        "angular momentum about the centre of mass, world frame",
                        _series("L_world"), True),
    "omega_body": Variable(("axis",), "float64", "rad/s", "angular velocity, body frame",
                           _series("omega_body"), True),
    "energy": Variable((), "float64", "J", "total energy T + V", _series("energy"), True),
    "status": Variable((), "int8", "1",
                       "how the run ended: 0 reached t_end, 1 terminal event, -1 failed",
                       lambda runs: runs.status),
    "n_steps": Variable((), "int64", "1", "steps taken", lambda runs: runs.n_steps),
    "energy_error": Variable((), "float64", "1",
                             "final relative energy error |E(t_end)/E(0) - 1|", energy_error),
    "flip_period": Variable(
        (), "float64", "s",
        "period of the body angular velocity from its zero crossings (NaN: fewer than three)",
        flip_period),
    WALL_TIME: Variable((), "float64", "s",
                        "wall-clock time of the member (its share of its batch)", None),
}  # fmt: skip
"""Every variable a ``rigid-body`` sweep stores per member, by name."""

SERIES = {name: row for name, row in VARIABLES.items() if row.series}
"""The rows of the time series (stored when the members share their sample times)."""
SUMMARY = {name: row for name, row in VARIABLES.items() if not row.series}
"""The rows of one number per member."""


def member_bytes(n_times: int | None, rows: dict[str, Variable] = VARIABLES) -> int:
    """Bytes one member adds to the store: its summary numbers, and its series at
    ``n_times`` samples (None: no series stored).

    Examples
    --------
    >>> member_bytes(None), member_bytes(2) - member_bytes(None)  # int8 + int64 + 3 float64
    (33, 352)
    """
    total = 0
    for row in rows.values():
        if row.series and n_times is None:
            continue
        total += row.sample_bytes() * (n_times if row.series else 1)  # type: ignore[operator]
    return total
