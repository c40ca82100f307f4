"""Running one task's members: batched through ``simulate_batch`` where they allow it.

Members that differ only in their initial state (``[options.initial]``) and run a
fixed-step method under constant loads form one *group* and run in one
:func:`~tumble.rigid.simulate_batch` call; any other member runs alone through
:func:`~tumble.rigid.simulate`, as ``tumble run`` would run its options. Both give each member
the numbers of a single ``simulate`` run (``simulate_batch``'s contract), so a sweep's member
equals the scenario run alone, bit for bit.

The options are checked once per group (every swept value was checked by the plan); the
members' initial states are laid out as arrays without building each member's options, so
a task of thousands of members spends its time in the compiled loop.
"""

from __future__ import annotations

import copy
import json
import time as clock
from typing import Any

import numpy as np

from tumble.rigid import Impulse, RigidBody, simulate, simulate_batch
from tumble.rigid.methods import get_method
from tumble.scenarios import rigid_body
from tumble.scenarios.schema import validate
from tumble.scenarios.t_handle import measured_period
from tumble.sweeps.plan import RIGID, Plan, set_path

SERIES = {
    "x": (("axis",), "m", "centre of mass, world frame"),
    "v": (("axis",), "m/s", "velocity of the centre of mass, world frame"),
    "R": (("row", "col"), "1", "attitude, body to world"),
    "L_world": (("axis",), "kg m2/s", "angular momentum about the centre of mass, world frame"),
    "omega_body": (("axis",), "rad/s", "angular velocity, body frame"),
    "energy": ((), "J", "total energy T + V"),
}
"""The state and diagnostic series per member: extra dimensions after ``time``, units,
long name."""
SUMMARY = {
    "status": ("int8", "1", "how the run ended: 0 reached t_end, 1 terminal event, -1 failed"),
    "n_steps": ("int64", "1", "steps taken"),
    "energy_error": ("float64", "1", "final relative energy error |E(t_end)/E(0) - 1|"),
    "flip_period": (
        "float64", "s",
        "period of the body angular velocity from its zero crossings (NaN: fewer than three)",
    ),
    "wall_time": ("float64", "s", "wall-clock time of the member (its share of its batch)"),
}  # fmt: skip
"""The summary variables per member: dtype, units, long name."""
VECTORS = ("x0", "v0", "omega0", "L0")
"""Initial vectors a task lays out as arrays (one row per member)."""
ATTITUDES = ("R0", "q0", "euler_zyx")
"""Initial attitudes: swept, each member's is built from its own table."""


def summary_numbers(summary: Any, key: str = "") -> dict[str, float]:
    """The numbers of a scenario's summary, by dotted key: what a built-in's sweep stores.

    Numbers, flags (0/1) and None (NaN) inside tables, and inside lists of tables (indexed
    from 0, as option paths are: ``spins.0.period_measured``); lists of numbers and text
    are left out.

    Examples
    --------
    >>> summary_numbers({"h": 0.01, "spins": [{"period": 47.2, "ok": True}], "dt": [1, 2]})
    {'h': 0.01, 'spins.0.period': 47.2, 'spins.0.ok': 1.0}
    """
    if isinstance(summary, dict):
        found: dict[str, float] = {}
        for name, value in summary.items():
            found.update(summary_numbers(value, f"{key}.{name}" if key else str(name)))
        return found
    if isinstance(summary, list) and summary and all(isinstance(v, dict) for v in summary):
        found = {}
        for index, value in enumerate(summary):
            found.update(summary_numbers(value, f"{key}.{index}"))
        return found
    if summary is None or isinstance(summary, bool | int | float):
        return {key: np.nan if summary is None else float(summary)}
    return {}


def run_summaries(plan: Plan, indices: list[tuple[int, ...]]) -> dict[str, np.ndarray]:
    """A built-in scenario's members, one ``run`` each: their summaries' numbers and times."""
    from tumble.scenarios import registry
    from tumble.scenarios.files import check_options

    out = {name: np.full(len(indices), np.nan) for name in (*plan.outputs, "wall_time")}
    for m, index in enumerate(indices):
        start = clock.perf_counter()
        options = copy.deepcopy(plan.options)
        for k, (path, values) in enumerate(zip(plan.paths, plan.values, strict=True)):
            set_path(options, path, values[index[0] if plan.samples else index[k]])
        result = registry.get(plan.scenario).run(**check_options(plan.scenario, options))
        for name, value in summary_numbers(result.summary).items():
            if name in out:
                out[name][m] = value
        out["wall_time"][m] = clock.perf_counter() - start
    return out


def run_members(plan: Plan, indices: list[tuple[int, ...]]) -> dict[str, np.ndarray]:
    """Run the members at ``indices``; their variables stacked along a leading member axis.

    Returns
    -------
    dict
        ``SERIES`` names (shape (m, n_time, …), only when ``plan.time`` is set; NaN after a
        run that stopped) and ``SUMMARY`` names (shape (m,)), in the order of ``indices``;
        for a built-in scenario, :func:`run_summaries`'.
    """
    if plan.scenario != RIGID:
        return run_summaries(plan, indices)
    columns = [
        [values[index[0] if plan.samples else index[k]] for index in indices]
        for k, values in enumerate(plan.values)
    ]
    shared = [k for k, path in enumerate(plan.paths) if path[0] != "initial"]
    groups: dict[str, list[int]] = {"": list(range(len(indices)))}
    if shared:  # members grouped by every option but the initial state
        groups = {}
        for m in range(len(indices)):
            key = json.dumps([columns[k][m] for k in shared])
            groups.setdefault(key, []).append(m)
    out = _allocate(plan, len(indices))
    for members in groups.values():
        start = clock.perf_counter()
        options = copy.deepcopy(plan.options)
        for k in shared:
            set_path(options, plan.paths[k], columns[k][members[0]])
        initial = {
            path: np.asarray([columns[k][m] for m in members], dtype=float)
            for k, path in enumerate(plan.paths)
            if path[0] == "initial"
        }
        _run_group(plan, validate(rigid_body.OPTIONS, options), initial, members, out)
        out["wall_time"][members] = (clock.perf_counter() - start) / len(members)
    return out


def _allocate(plan: Plan, m: int) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    if plan.time is not None:
        for name, (extra, _, _) in SERIES.items():
            out[name] = np.full((m, len(plan.time), *(3 for _ in extra)), np.nan)
    for name, (dtype, _, _) in SUMMARY.items():
        out[name] = np.full(m, np.nan) if dtype == "float64" else np.zeros(m, dtype=dtype)
    return out


def _run_group(plan: Plan, checked, initial: dict, members: list[int], out: dict) -> None:
    """Run members that share every option but the initial state; fill their rows of ``out``."""
    description: Any = checked.body  # a union of pydantic models, each with mass_properties
    properties = description.mass_properties()
    body = RigidBody.from_mass_properties(properties)
    com = np.asarray(properties.com)
    forces = [load.build(com) for load in checked.loads]
    starts = _initial_arrays(checked.initial, initial, len(members), com)
    constant = all(getattr(load, "compiled", False) for load in forces)
    impulses = any(isinstance(load, Impulse) for load in forces)
    if not get_method(checked.method).adaptive and constant and not impulses:
        batch = simulate_batch(
            body, checked.t_end, method=checked.method, h=checked.h, forces=forces,
            record_every=checked.record_every, **starts,
        )  # fmt: skip
        if plan.time is not None:
            for name in SERIES:
                out[name][members] = getattr(batch, name)
        out["status"][members] = batch.status
        out["n_steps"][members] = batch.n_steps
        energy = batch.energy
        last = np.take_along_axis(energy, batch.n_recorded[:, None] - 1, axis=1)[:, 0]
        out["energy_error"][members] = _energy_error(energy[:, 0], last)
        out["flip_period"][members] = np.where(
            batch.status >= 0, periods(batch.t, batch.omega_body), np.nan
        )
        return
    for row, m in enumerate(members):
        given = {name: value[row] for name, value in starts.items()}
        trajectory = simulate(
            body, checked.t_end, method=checked.method, h=checked.h, rtol=checked.rtol,
            atol=checked.atol, forces=forces, record_every=checked.record_every, **given,
        )  # fmt: skip
        if plan.time is not None:
            for name in SERIES:
                values = getattr(trajectory, name)
                out[name][m, : len(values)] = values
        out["status"][m] = trajectory.status
        out["n_steps"][m] = trajectory.n_steps
        energy = trajectory.energy
        out["energy_error"][m] = _energy_error(energy[:1], energy[-1:])[0]
        period, _, _ = measured_period(trajectory.t, trajectory.omega_body)
        out["flip_period"][m] = np.nan if period is None or trajectory.status < 0 else period


def _initial_arrays(start, swept: dict, m: int, com: np.ndarray) -> dict[str, Any]:
    """``simulate``'s initial arguments, one row per member.

    ``start`` is the group's checked ``[options.initial]``; ``swept`` maps each swept
    ``initial`` path to its members' values. ``x0`` defaults to the centre of mass, as
    :func:`tumble.scenarios.rigid_body.run` does.
    """
    arrays: dict[str, Any] = {}
    for name in VECTORS:
        base = getattr(start, name)
        paths = [path for path in swept if path[1] == name]
        if base is None and not paths and name != "x0":
            continue
        row = com if base is None and name == "x0" else base
        array = np.tile(np.asarray(row if row is not None else np.zeros(3), dtype=float), (m, 1))
        for path in paths:
            if len(path) == 3:
                array[:, path[2]] = swept[path]
            else:
                array[:] = swept[path]
        arrays[name] = array
    if any(path[1] in ATTITUDES for path in swept):
        base = start.model_dump(exclude_none=True)
        tables = [copy.deepcopy(base) for _ in range(m)]
        for path, values in swept.items():
            for table, value in zip(tables, values.tolist(), strict=True):
                set_path(table, path[1:], value)
        attitudes = [validate(rigid_body.Initial, table).attitude() for table in tables]
        arrays["R0"] = np.array(attitudes)
    else:
        arrays["R0"] = np.tile(start.attitude(), (m, 1, 1))
    return arrays


def _energy_error(first: np.ndarray, last: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return np.where(first != 0, np.abs(last / first - 1), np.nan)


def periods(t: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """:func:`~tumble.scenarios.t_handle.measured_period` of many runs on one time grid.

    The mean of ``c[k + 2] − c[k]`` over the crossings ``c`` of the most-crossing component
    telescopes to ``(c[-1] + c[-2] − c[0] − c[1]) / (len(c) − 2)``, so only the first two and
    last two crossings of each run are located.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Times (s).
    omega : ndarray, shape (m, n, 3)
        Body angular velocities (rad/s); NaN after a run that stopped.

    Returns
    -------
    ndarray, shape (m,)
        The periods (s); NaN where fewer than three crossings were seen.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        positive = omega >= 0
        changes = positive[:, :-1] != positive[:, 1:]  # (m, n - 1, 3)
        component = np.argmax(changes.sum(axis=1), axis=1)
        rows = np.arange(len(omega))
        values = omega[rows, :, component]  # (m, n)
        crossing = changes[rows, :, component]
        count = crossing.sum(axis=1)
        dt = t[1:] - t[:-1]
        times = t[:-1] - values[:, :-1] * dt / (values[:, 1:] - values[:, :-1])
        order = np.cumsum(crossing, axis=1)
        first = _at(times, order, crossing, 1)
        second = _at(times, order, crossing, 2)
        last = _at(times, order, crossing, count)
        before_last = _at(times, order, crossing, count - 1)
        period = (last + before_last - first - second) / (count - 2)
    return np.where(count >= 3, period, np.nan)


def _at(times: np.ndarray, order: np.ndarray, crossing: np.ndarray, k) -> np.ndarray:
    """The time of each run's ``k``-th crossing (1-based; NaN where there is none)."""
    hit = crossing & (order == np.reshape(k, (-1, 1)))
    index = np.argmax(hit, axis=1)
    return np.where(hit.any(axis=1), times[np.arange(len(times)), index], np.nan)
