"""Running one task's members: batched through ``simulate_batch`` where they allow it.

Members that differ only in their initial state (``[options.initial]``) form one *group*:
the options are checked once, and :func:`tumble.scenarios.rigid_body.prepare` builds the body,
its loads and the base initial state once. A group whose run is
:attr:`~tumble.scenarios.rigid_body.Preparation.batchable` (a fixed-step method under
constant loads) runs in one :func:`~tumble.rigid.simulate_batch` call; any other member runs
alone through :func:`~tumble.rigid.simulate`, as ``tumble run`` would run its options. Both
give each member the numbers of a single ``simulate`` run (``simulate_batch``'s contract), so
a sweep's member equals the scenario run alone, bit for bit.

Either way the stored variables are the rows of :mod:`tumble.sweeps.variables`, each
computed from the runs (a lone run is a batch of one). The members' initial states are laid
out as arrays without building each member's options, so a task of thousands of members
spends its time in the compiled loop.
"""

from __future__ import annotations

import copy
import itertools
import json
import math
import time as clock
from typing import Any

import numpy as np

from tumble.scenarios import rigid_body
from tumble.scenarios.schema import validate
from tumble.sweeps.plan import RIGID, Plan, set_path
from tumble.sweeps.variables import EXTRA_DIMS, VARIABLES, WALL_TIME, Runs

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


MAX_PROBES = 64
"""At most this many first runs name a built-in sweep's stored numbers (:func:`probes`)."""


def shaping_columns(plan: Plan) -> list[int]:
    """The swept columns whose values may change which numbers a built-in's summary has.

    A column of real numbers (with at least one float) moves the numbers, not their names;
    any other (names, lists such as ``methods``, booleans, integers such as a count of
    elements) may add or remove entries of the summary (``results.split-axes.…``).
    """
    shaping = []
    for k, column in enumerate(plan.values):
        numbers = all(isinstance(v, int | float) and not isinstance(v, bool) for v in column)
        if not (numbers and any(isinstance(v, float) for v in column)):
            shaping.append(k)
    return shaping


def probes(plan: Plan) -> list[tuple[int, ...]]:
    """One member for each combination of the :func:`shaping_columns`' values.

    For a grid, the product of each shaping dimension's distinct values (the first index of
    each), every other dimension at its first value; for samples, the first row of each
    distinct combination. Their summaries together have every number of every member.

    Raises
    ------
    ValueError
        When there are more than :data:`MAX_PROBES` combinations.
    """
    shaping = shaping_columns(plan)
    if plan.samples:
        firsts: dict[str, int] = {}
        for row in range(plan.size):
            key = json.dumps([plan.values[k][row] for k in shaping], sort_keys=True)
            firsts.setdefault(key, row)
        count = len(firsts)
    else:
        axes = [_first_of_each(column) if k in shaping else [0]
                for k, column in enumerate(plan.values)]  # fmt: skip
        count = math.prod(map(len, axes))
    if count > MAX_PROBES:
        names = ", ".join(plan.names[k] for k in shaping)
        raise ValueError(
            f"a sweep of scenario {plan.scenario!r} stores the numbers its summary has, named "
            f"by a first run of each combination of the swept values that are not real "
            f"numbers ({names}): this sweep has {count}, more than {MAX_PROBES}; sweep fewer "
            "of them at a time (one store each)"
        )
    if plan.samples:
        return [(row,) for row in firsts.values()]
    return list(itertools.product(*axes))


def _first_of_each(column: list) -> list[int]:
    """The index of the first occurrence of each distinct value of ``column``."""
    seen: dict[str, int] = {}
    for index, value in enumerate(column):
        seen.setdefault(json.dumps(value, sort_keys=True), index)
    return list(seen.values())


def member_options(plan: Plan, index: tuple[int, ...]) -> dict:
    """A built-in member's options: the plan's, with each swept path set to its value."""
    options = copy.deepcopy(plan.options)
    for k, (path, values) in enumerate(zip(plan.paths, plan.values, strict=True)):
        set_path(options, path, values[index[0] if plan.samples else index[k]])
    return options


def summary_names(plan: Plan, index: tuple[int, ...]) -> list[str]:
    """The numbers of member ``index``'s summary (a built-in's), by dotted key."""
    from tumble.scenarios import registry
    from tumble.scenarios.files import check_options

    options = check_options(plan.scenario, member_options(plan, index))
    return list(summary_numbers(registry.get(plan.scenario).run(**options).summary))


def echoes(plan: Plan) -> set[str]:
    """Summary keys a sweep does not store: the swept options' echo and its own variables."""
    return {*plan.dims, *plan.names, "member", "done", WALL_TIME}


def run_summaries(plan: Plan, indices: list[tuple[int, ...]]) -> dict[str, np.ndarray]:
    """A built-in scenario's members, one ``run`` each: their summaries' numbers and times.

    Raises
    ------
    ValueError
        If a member's summary has a number the store has no variable for (its task then
        writes nothing and marks nothing done): the store's variables were named by the
        first runs of :func:`probes`, so a real-valued option changed the summary's keys.
    """
    from tumble.scenarios import registry
    from tumble.scenarios.files import check_options

    out = {name: np.full(len(indices), np.nan) for name in (*plan.outputs, WALL_TIME)}
    skipped = echoes(plan)
    for m, index in enumerate(indices):
        start = clock.perf_counter()
        options = member_options(plan, index)
        result = registry.get(plan.scenario).run(**check_options(plan.scenario, options))
        numbers = summary_numbers(result.summary)
        unnamed = [name for name in numbers if name not in out and name not in skipped]
        if unnamed:
            where = ", ".join(
                f"{name}={plan.values[k][index[0] if plan.samples else index[k]]!r}"
                for k, name in enumerate(plan.names)
            )
            raise ValueError(
                f"member ({where}) of the sweep of {plan.scenario!r} has summary numbers the "
                f"store has no variable for: {', '.join(unnamed[:5])}; its numbers were not "
                "written. The store's variables come from a first run of each combination "
                "of the swept values that are not real numbers: sweep this option in "
                "separate sweeps"
            )
        for name, value in numbers.items():
            if name in out:
                out[name][m] = value
        out[WALL_TIME][m] = clock.perf_counter() - start
    return out


def run_members(plan: Plan, indices: list[tuple[int, ...]]) -> dict[str, np.ndarray]:
    """Run the members at ``indices``; their variables stacked along a leading member axis.

    Returns
    -------
    dict
        The rows of :data:`~tumble.sweeps.variables.VARIABLES`: series (shape
        (m, n_time, …), only when ``plan.time`` is set; NaN after a run that stopped) and
        summary variables (shape (m,)), in the order of ``indices``; for a built-in
        scenario, :func:`run_summaries`'.
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
        ready = rigid_body.prepare(validate(rigid_body.OPTIONS, options))
        _run_group(plan, ready, initial, members, out)
        out[WALL_TIME][members] = (clock.perf_counter() - start) / len(members)
    return out


def _allocate(plan: Plan, m: int) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    for name, row in VARIABLES.items():
        if row.series and plan.time is None:
            continue
        times = (len(plan.time),) if row.series and plan.time is not None else ()
        shape = (m, *times, *(len(EXTRA_DIMS[dim]) for dim in row.extra))
        fill = np.nan if np.dtype(row.dtype).kind == "f" else 0
        out[name] = np.full(shape, fill, dtype=row.dtype)
    return out


def _run_group(plan: Plan, ready, initial: dict, members: list[int], out: dict) -> None:
    """Run members that share every option but the initial state; fill their rows of ``out``.

    ``ready`` is the group's :class:`~tumble.scenarios.rigid_body.Preparation`.
    """
    starts = _initial_arrays(ready, initial, len(members))
    if ready.batchable:
        _store(Runs.from_batch(ready.simulate_batch(**starts)), members, out)
        return
    for row, m in enumerate(members):
        given = {name: value[row] for name, value in starts.items()}
        _store(Runs.from_trajectory(ready.simulate(**given)), [m], out)


def _store(runs: Runs, members: list[int], out: dict) -> None:
    """Each row of ``out`` (but the wall time) computed from ``runs``, at ``members``."""
    for name, array in out.items():
        compute = VARIABLES[name].compute
        if compute is None:
            continue
        values = compute(runs)
        if VARIABLES[name].series:  # a run that stopped early fills its first samples
            array[members, : values.shape[1]] = values
        else:
            array[members] = values


def _initial_arrays(ready, swept: dict, m: int) -> dict[str, Any]:
    """``simulate``'s initial arguments, one row per member.

    ``ready`` is the group's :class:`~tumble.scenarios.rigid_body.Preparation`, whose
    ``start`` is the base row (``x0`` the centre of mass unless given); ``swept`` maps each
    swept ``initial`` path to its members' values.
    """
    arrays: dict[str, Any] = {}
    for name in VECTORS:
        base = ready.start[name]
        paths = [path for path in swept if path[1] == name]
        if base is None and not paths:
            continue
        array = np.tile(np.asarray(base if base is not None else np.zeros(3), dtype=float), (m, 1))
        for path in paths:
            if len(path) == 3:
                array[:, path[2]] = swept[path]
            else:
                array[:] = swept[path]
        arrays[name] = array
    if any(path[1] in ATTITUDES for path in swept):
        base = ready.options.initial.model_dump(exclude_none=True)
        tables = [copy.deepcopy(base) for _ in range(m)]
        for path, values in swept.items():
            for table, value in zip(tables, values.tolist(), strict=True):
                set_path(table, path[1:], value)
        attitudes = [validate(rigid_body.Initial, table).attitude() for table in tables]
        arrays["R0"] = np.array(attitudes)
    else:
        arrays["R0"] = np.tile(ready.start["R0"], (m, 1, 1))
    return arrays
