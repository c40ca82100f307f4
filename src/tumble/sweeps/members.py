"""Running one task's members: batched through ``simulate_batch`` where they allow it.

Members that differ only in their initial state (``[options.initial]``) and run a
fixed-step method under constant loads form one *group* and run in one
:func:`~tumble.rigid.simulate_batch` call; any other member runs alone through
:func:`~tumble.rigid.simulate`, as ``tumble run`` would run its options. Both give each member
the numbers of a single ``simulate`` run (``simulate_batch``'s contract), so a sweep's member
equals the scenario run alone, bit for bit.

Per member the task returns the state series on the plan's shared times (NaN after a run
that stopped) and the summary variables of :data:`SUMMARY`.
"""

from __future__ import annotations

import json
import time as clock
from dataclasses import dataclass
from typing import Any

import numpy as np

from tumble.rigid import Impulse, RigidBody, simulate, simulate_batch
from tumble.rigid.methods import get_method
from tumble.scenarios import rigid_body
from tumble.scenarios.schema import validate
from tumble.scenarios.t_handle import measured_period
from tumble.sweeps.plan import Plan

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


@dataclass
class _Member:
    """One member's run, read into arrays."""

    t: np.ndarray
    series: dict[str, np.ndarray]
    status: int
    n_steps: int


def run_members(plan: Plan, indices: list[tuple[int, ...]]) -> dict[str, np.ndarray]:
    """Run the members at ``indices``; their variables stacked along a leading member axis.

    Returns
    -------
    dict
        ``SERIES`` names (shape (m, n_time, …), only when ``plan.time`` is set) and
        ``SUMMARY`` names (shape (m,)), in the order of ``indices``.
    """
    groups: dict[str, list[int]] = {}
    options = [plan.member_options(index) for index in indices]
    for k, member in enumerate(options):
        shared = {key: value for key, value in member.items() if key != "initial"}
        groups.setdefault(json.dumps(shared, sort_keys=True), []).append(k)
    results: list[_Member | None] = [None] * len(indices)
    walls = np.zeros(len(indices))
    for members in groups.values():
        start = clock.perf_counter()
        for k, result in zip(members, _run_group([options[k] for k in members]), strict=True):
            results[k] = result
        walls[members] = (clock.perf_counter() - start) / len(members)
    return _stack(plan, [r for r in results if r is not None], walls)


def _run_group(members: list[dict]) -> list[_Member]:
    """Members sharing everything but the initial state: one batch when they can be."""
    checked = validate(rigid_body.OPTIONS, members[0], prefix="options")
    description: Any = checked.body  # a union of pydantic models, each with mass_properties
    properties = description.mass_properties()
    body = RigidBody.from_mass_properties(properties)
    com = np.asarray(properties.com)
    forces = [load.build(com) for load in checked.loads]
    starts = [validate(rigid_body.Initial, m.get("initial", {})) for m in members]
    compiled = all(getattr(load, "compiled", False) for load in forces)
    batchable = (
        not get_method(checked.method).adaptive
        and compiled
        and not any(isinstance(load, Impulse) for load in forces)
    )
    if batchable:
        return _batch(checked, body, com, forces, starts)
    return [_single(checked, body, com, forces, start) for start in starts]


def _initial_arrays(com: np.ndarray, starts: list) -> dict:
    """``simulate_batch``'s per-body arrays: each given by every member, or by none."""
    arrays: dict = {"x0": np.array([com if s.x0 is None else s.x0 for s in starts])}
    arrays["R0"] = np.array([s.attitude() for s in starts])
    for name in ("v0", "omega0", "L0"):
        given = [getattr(s, name) for s in starts]
        if any(value is not None for value in given):
            arrays[name] = np.array([np.zeros(3) if v is None else v for v in given])
    return arrays


def _batch(checked, body, com, forces, starts) -> list[_Member]:
    batch = simulate_batch(
        body, checked.t_end, method=checked.method, h=checked.h, forces=forces,
        record_every=checked.record_every, **_initial_arrays(com, starts),
    )  # fmt: skip
    series = {name: getattr(batch, name) for name in SERIES}
    return [
        _Member(
            t=batch.t[: batch.n_recorded[k]],
            series={name: values[k, : batch.n_recorded[k]] for name, values in series.items()},
            status=int(batch.status[k]),
            n_steps=int(batch.n_steps[k]),
        )
        for k in range(len(batch))
    ]


def _single(checked, body, com, forces, start) -> _Member:
    trajectory = simulate(
        body, checked.t_end, method=checked.method, h=checked.h, rtol=checked.rtol,
        atol=checked.atol, x0=com if start.x0 is None else start.x0, v0=start.v0,
        R0=start.attitude(), omega0=start.omega0, L0=start.L0, forces=forces,
        record_every=checked.record_every,
    )  # fmt: skip
    return _Member(
        t=trajectory.t,
        series={name: getattr(trajectory, name) for name in SERIES},
        status=int(trajectory.status),
        n_steps=int(trajectory.n_steps),
    )


def _stack(plan: Plan, results: list[_Member], walls: np.ndarray) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    if plan.time is not None:
        n = len(plan.time)
        for name, (extra, _, _) in SERIES.items():
            shape = (len(results), n, *(3 for _ in extra))
            stacked = np.full(shape, np.nan)
            for k, result in enumerate(results):
                values = result.series[name]
                stacked[k, : len(values)] = values
            out[name] = stacked
    out["status"] = np.array([r.status for r in results], dtype=np.int8)
    out["n_steps"] = np.array([r.n_steps for r in results], dtype=np.int64)
    out["energy_error"] = np.array([_energy_error(r.series["energy"]) for r in results])
    out["flip_period"] = np.array([_period(r) for r in results])
    out["wall_time"] = walls
    return out


def _energy_error(energy: np.ndarray) -> float:
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(abs(energy[-1] / energy[0] - 1)) if energy[0] != 0 else np.nan


def _period(result: _Member) -> float:
    with np.errstate(all="ignore"):
        period, _, _ = measured_period(result.t, result.series["omega_body"])
    return np.nan if period is None else period
