"""What a sweep runs: the scenario, the swept option paths, the members and their tasks.

A sweep is one scenario (a file, a built-in's name, or the ``rigid-body`` options) and a set
of *option paths*, each with values. A path is dotted, relative to the file's ``[options]``:
``h``, ``method``, ``initial.omega0.1`` (entry 1 of the list), ``loads.0.impulse.2``,
``body.density``, ``spins.0.1``. For ``rigid-body``, a path whose first key is not an option
but a key of ``[options.initial]`` (``omega0.1``) or the type of the one load of that type
(``impulse.point.0``) is short for the full path.

* ``grid``: the paths' values multiply, each path is a dimension of the output;
* ``samples``: a table of rows (columns of equal length, one per path), one member per row,
  along one dimension ``member``.

Every path and every value is checked against the scenario's schema before any work
(:func:`make_plan`): an unknown path, a value of the wrong type or an empty grid is a
:class:`ValueError` that names the key, the value and what is allowed.

The members are cut into *tasks*, blocks of the grid (:meth:`Plan.tasks`), that each run and
write one region of the store; the store's chunks are the same blocks, so no two tasks write
one chunk and no locks are needed.
"""

from __future__ import annotations

import copy
import hashlib
import inspect
import itertools
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tumble import _checks
from tumble.scenarios import registry, rigid_body
from tumble.scenarios.files import check_options, read
from tumble.scenarios.option_models import options_model
from tumble.scenarios.schema import short_repr, validate
from tumble.sweeps.text import grid_from_table
from tumble.sweeps.variables import VARIABLES, WALL_TIME, member_bytes

RIGID = "rigid-body"
"""The scenario whose members are trajectories (batched); any other stores its summary."""
CHUNK_BYTES = 16 * 2**20
"""Default size of one task's output (bytes): a worker holds about this much at a time."""
MAX_CHUNK = 16384
"""Default largest number of members in one task: a task's fixed cost (writing its region and
flags, about 30 ms; its bookkeeping) should stay small beside its compiled loop (16384 free
bodies of 300 ``rkmk4`` steps: about 0.25 s on one core)."""
TIME_GRID = ("h", "t_end", "record_every")
"""Options that set a member's sample times: swept, the members share no time axis."""


@dataclass(frozen=True)
class Plan:
    """A checked sweep: the base options, the swept paths and the members' blocks.

    Attributes
    ----------
    options : dict
        The scenario's checked options (``[options]`` of the file), shared by every member.
    dims : tuple of str
        The output's member dimensions: the grid's paths as given, or ``("member",)``.
    paths : tuple of tuple
        Each swept path as keys and indices into ``options`` (``("initial", "omega0", 1)``).
    values : tuple of list
        The values of each path: along its dimension (grid) or per member (samples).
    samples : bool
        True for a table of rows (one ``member`` dimension), False for a grid.
    chunks : tuple of int
        Members per task along each dimension of ``dims``.
    source : str
        The scenario file, or ``"<options>"`` when given as a model or a mapping.
    source_hash : str
        SHA-256 of the file's bytes (or of the options' JSON).
    names : tuple of str
        The swept paths as the user wrote them (the grid's dimensions, the samples'
        coordinates).
    scenario : str
        The scenario's name: ``rigid-body`` (members are trajectories), or a built-in whose
        members are its summary's numbers.
    outputs : tuple of str
        For a built-in: the summary's numbers stored per member (:func:`summary_numbers`
        of a first run).
    time : ndarray or None
        The sample times every member shares (s), or None when they differ (a swept
        ``h``, ``t_end`` or ``record_every``, an adaptive method): then only the summary
        variables are stored.
    """

    options: dict
    dims: tuple[str, ...]
    paths: tuple[tuple, ...]
    values: tuple[list, ...]
    samples: bool
    chunks: tuple[int, ...]
    source: str
    source_hash: str
    time: np.ndarray | None
    names: tuple[str, ...] = ()
    scenario: str = "rigid-body"
    outputs: tuple[str, ...] = ()

    @property
    def shape(self) -> tuple[int, ...]:
        """Members along each dimension."""
        if self.samples:
            return (len(self.values[0]),)
        return tuple(len(values) for values in self.values)

    @property
    def size(self) -> int:
        """The number of members."""
        return math.prod(self.shape)

    def tasks(self) -> list[tuple[int, ...]]:
        """Each task's block index (one per chunk of the member dimensions), C order."""
        counts = [math.ceil(n / c) for n, c in zip(self.shape, self.chunks, strict=True)]
        return list(itertools.product(*map(range, counts)))

    def region(self, task: tuple[int, ...]) -> dict[str, slice]:
        """The store region of ``task``: a slice along each member dimension."""
        return {
            dim: slice(k * c, min((k + 1) * c, n))
            for dim, k, c, n in zip(self.dims, task, self.chunks, self.shape, strict=True)
        }

    def grid_attr(self) -> str:
        """The sweep as JSON (the store's ``grid`` attribute): each dimension's path and values."""
        if self.samples:
            columns = {
                name: {"path": dim_path(p)} for name, p in zip(self.names, self.paths, strict=True)
            }
            return json.dumps({"samples": columns, "members": self.size})
        return json.dumps(
            {dim: {"path": dim_path(p), "values": v}
             for dim, p, v in zip(self.dims, self.paths, self.values, strict=True)}
        )  # fmt: skip


def shared_time(options: dict, paths: Sequence[tuple], values: Sequence[list]):
    """The sample times every member shares, or None (see :attr:`Plan.time`).

    The times of a fixed-step run: ``t = 0``, every ``record_every``-th step ``k h`` and the
    last step, which lands on ``t_end`` (:func:`tumble.ode.driver.march`).
    """
    from tumble.ode.control import fixed_step_count
    from tumble.ode.driver import Grid
    from tumble.rigid.batch import record_times
    from tumble.rigid.methods import get_method

    methods = {options.get("method", "rkmk4")}
    for path, column in zip(paths, values, strict=True):
        if path[0] in TIME_GRID:
            return None
        if path == ("method",):
            methods = set(column)
    if any(get_method(name).adaptive for name in methods):
        return None
    h, t_end = options.get("h", 0.01), options.get("t_end", 10.0)
    every = options.get("record_every", 1)
    grid = Grid(0.0, t_end, h, fixed_step_count(0.0, t_end, h))
    times = np.concatenate([[0.0], record_times(grid, every)])
    if times[-1] != grid.time(grid.n):
        times = np.append(times, grid.time(grid.n))
    return times


def dim_path(path: tuple) -> str:
    """A path as dotted text: ``("initial", "omega0", 1)`` → ``"initial.omega0.1"``."""
    return ".".join(map(str, path))


# ---------------------------------------------------------------------------------------
# Reading the scenario.


def load_scenario(scenario: Any) -> tuple[str, dict, str, str, Any]:
    """``(name, options, source, sha256, sweep)`` of what :func:`make_plan` was given.

    A ``rigid-body`` file, model or mapping gives the options as written; a built-in
    scenario's name (or a file of one) gives every option, its defaults filled in, since a
    swept path may point into a default (``spins.0.1``). ``sweep`` is the file's ``[sweep]``
    section (:class:`tumble.scenarios.files.Sweep`), or None. The hash is the file's bytes',
    the options' JSON, or for a built-in name its module's source.
    """
    if isinstance(scenario, rigid_body.Options):
        options = scenario.model_dump(mode="json", exclude_unset=True)
        return RIGID, options, "<options>", _json_hash(options), None
    if isinstance(scenario, Mapping):
        options = dict(validate(rigid_body.OPTIONS, dict(scenario), prefix="options")
                       .model_dump(mode="json", exclude_unset=True))  # fmt: skip
        return RIGID, options, "<options>", _json_hash(options), None
    if isinstance(scenario, str | Path) and str(scenario).endswith(".toml"):
        path = Path(scenario)
        found = read(path)
        options = found.options
        if found.scenario != RIGID:
            options = {**defaults(found.scenario), **options}
        return found.scenario, options, str(found.source), _hash(path.read_bytes()), found.sweep
    if isinstance(scenario, str) and scenario in registry.names() and scenario != RIGID:
        module = Path(registry.get(scenario).__file__ or "")
        return scenario, defaults(scenario), scenario, _hash(module.read_bytes()), None
    raise _checks.fail(
        "scenario", scenario,
        "a scenario file (.toml), a built-in scenario's name (tumble list; not 'rigid-body', "
        "which needs a body), or the rigid-body options as a mapping or "
        "tumble.scenarios.rigid_body.Options",
    )  # fmt: skip


def defaults(scenario: str) -> dict:
    """A built-in scenario's options, each at its default (JSON types: lists, not tuples)."""
    parameters = inspect.signature(registry.get(scenario).run).parameters.values()
    return {
        p.name: json.loads(json.dumps(p.default))
        for p in parameters
        if p.kind is inspect.Parameter.KEYWORD_ONLY and p.default is not inspect.Parameter.empty
    }


def _json_hash(options: dict) -> str:
    return _hash(json.dumps(options, sort_keys=True).encode())


def _hash(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


# ---------------------------------------------------------------------------------------
# Paths.

_SECTIONS = {"initial": rigid_body.Initial}


def resolve(key: Any, options: dict, scenario: str = RIGID) -> tuple:
    """The full path of a dotted ``key`` (short forms expanded); a ValueError if unknown."""
    if not isinstance(key, str) or not key or any(not part for part in key.split(".")):
        raise _checks.fail("grid key", key, "a dotted option path such as 'h' or 'omega0.1'")
    parts: list[Any] = [int(p) if p.isdigit() else p for p in key.split(".")]
    head = parts[0]
    if scenario != RIGID:
        allowed = sorted(options_model(scenario).model_fields)
        if head not in allowed:
            raise ValueError(
                f"grid key {key!r} is not an option path of scenario {scenario!r}; allowed: "
                f"{', '.join(allowed)} (and their entries, as spins.0.1)"
            )
        return tuple(parts)
    if head in rigid_body.Options.model_fields:
        return tuple(parts)
    for section, model in _SECTIONS.items():
        if head in model.model_fields:
            return (section, *parts)
    kinds = [load.get("type") for load in options.get("loads", [])]
    if kinds.count(head) == 1:
        return ("loads", kinds.index(head), *parts[1:])
    allowed = sorted(rigid_body.Options.model_fields) + [
        f"{name} (short for initial.{name})" for name in rigid_body.Initial.model_fields
    ]
    hint = "; a load's keys as loads.<k>.<key>, or <type>.<key> for the only load of a type"
    raise ValueError(
        f"grid key {key!r} is not an option path of scenario 'rigid-body'; allowed: "
        f"{', '.join(allowed)}{hint}"
    )


def set_path(options: dict, path: tuple, value: Any) -> None:
    """Set ``options[path[0]][path[1]]… = value``, making missing tables (or lists) on the way."""
    node: Any = options
    for position, part in enumerate(path[:-1]):
        following = path[position + 1]
        if isinstance(node, dict):
            if node.get(part) is None:
                node[part] = [] if isinstance(following, int) else {}
            node = node[part]
        else:
            node = node[part]
    node[path[-1]] = value


def _check_path(key: str, path: tuple, options: dict) -> None:
    """Every list index on ``path`` must exist in ``options`` (a list to sweep an entry of)."""
    node: Any = options
    for position, part in enumerate(path):
        where = "options." + dim_path(path[:position])
        if isinstance(part, int):
            if not isinstance(node, list):
                raise ValueError(
                    f"grid key {key!r}: {where} is not set to a list in the scenario, so it has "
                    f"no entry {part}; give it a value in the file to sweep one of its entries"
                )
            if part >= len(node):
                raise ValueError(
                    f"grid key {key!r}: {where} has {len(node)} entries, so index {part} is "
                    f"not allowed: must be 0 to {len(node) - 1}"
                )
            node = node[part]
        elif isinstance(node, dict):
            node = node.get(part)
        else:
            return


def _check_value(key: str, path: tuple, value: Any, options: dict, scenario: str) -> None:
    trial = copy.deepcopy(options)
    try:
        set_path(trial, path, value)
        if scenario == RIGID:
            validate(rigid_body.OPTIONS, trial, prefix="options")
        else:
            check_options(scenario, trial)
    except (ValueError, TypeError, IndexError) as error:
        raise ValueError(f"grid key {key!r}, value {short_repr(value)}: {error}") from None


def _plain(value: Any) -> Any:
    """NumPy scalars and arrays as Python numbers and lists (what the schema takes)."""
    if isinstance(value, np.generic | np.ndarray):
        return value.tolist()
    return value


def _check_column(key: str, path: tuple, values: list, options: dict, scenario: str) -> None:
    """Check each distinct value; a column of numbers is checked by its extremes and type."""
    kinds = set(map(type, values))
    if kinds <= {int, float} and len(values) > 2:
        # checked at once (ints are finite); a bad value is then named by the schema
        if float in kinds and not np.isfinite(np.asarray(values, dtype=float)).all():
            for value in values:
                if not math.isfinite(value):
                    _check_value(key, path, value, options, scenario)
        _check_value(key, path, min(values), options, scenario)
        _check_value(key, path, max(values), options, scenario)
        return
    seen: list = []
    for value in values:
        if value not in seen:
            seen.append(value)
            _check_value(key, path, value, options, scenario)


def make_plan(
    scenario: Any,
    grid: Mapping[str, Sequence] | None = None,
    samples: Any = None,
    *,
    chunk: int | None = None,
) -> Plan:
    """Check a sweep before any work: paths, values, and the members' blocks.

    Parameters
    ----------
    scenario : str, Path, mapping or tumble.scenarios.rigid_body.Options
        A scenario file, a built-in scenario's name, or the ``rigid-body`` options.
    grid : mapping of str to sequence, optional
        Option path → values; the values multiply. Default: the file's ``[sweep.grid]``.
    samples : mapping of str to sequence, sequence of mappings, or DataFrame, optional
        One member per row, instead of ``grid``.
    chunk : int, optional
        Members per task; default: tasks of about :data:`CHUNK_BYTES` of output (the bytes
        of a member from the rows of :data:`tumble.sweeps.variables.VARIABLES`), at most
        :data:`MAX_CHUNK` members.

    Returns
    -------
    Plan

    Raises
    ------
    ValueError
        For an unknown path, a value the schema refuses, an empty grid or column, both
        ``grid`` and ``samples``, or columns of different lengths: naming the key, the value
        and what is allowed.
    """
    name, options, source, digest, section = load_scenario(scenario)
    if grid is None and samples is None and section is not None and section.grid:
        grid = grid_from_table(section.grid)
        chunk = section.chunk if chunk is None else chunk
    if grid is not None and samples is not None:
        raise ValueError("give grid or samples, not both (a grid's values multiply; samples "
                         "are rows)")  # fmt: skip
    columns = _columns(samples) if samples is not None else grid
    if not isinstance(columns, Mapping) or not columns:
        raise _checks.fail(
            "samples" if samples is not None else "grid", columns,
            "a mapping of at least one option path to a non-empty list of values",
            remedy="for example grid={'omega0.1': [0.01, 0.05], 'method': ['rkmk4']}; on the "
            "command line --grid PATH=VALUES, or a [sweep.grid] table in the file",
        )  # fmt: skip
    paths, values = [], []
    for key, given in columns.items():
        path = resolve(key, options, name)
        _check_path(key, path, options)
        listed = _values(key, given)
        _check_column(key, path, listed, options, name)
        paths.append(path)
        values.append(listed)
    if samples is not None and len({len(v) for v in values}) > 1:
        lengths = {key: len(v) for key, v in zip(columns, values, strict=True)}
        raise _checks.fail("samples", lengths, "columns of one length (one value per row)")
    dims = ("member",) if samples is not None else tuple(columns)
    if samples is None and len({dim_path(p) for p in paths}) < len(paths):
        raise _checks.fail("grid", list(columns), "each option path at most once")
    shape = (len(values[0]),) if samples is not None else tuple(map(len, values))
    time = shared_time(options, paths, values) if name == RIGID else None
    # a built-in's summary numbers are named by its first run (sweep's _probed), after this
    rows = VARIABLES if name == RIGID else {WALL_TIME: VARIABLES[WALL_TIME]}
    per_member = member_bytes(None if time is None else len(time), rows)
    chunks = _chunks(shape, _chunk(chunk, per_member))
    return Plan(options, dims, tuple(paths), tuple(values), samples is not None, chunks,
                source, digest, time, tuple(columns), name)  # fmt: skip


def _columns(samples: Any) -> dict:
    """A table of rows as columns: path → list."""
    if hasattr(samples, "to_dict") and hasattr(samples, "columns"):  # a pandas DataFrame
        return {str(k): list(v) for k, v in samples.to_dict("list").items()}
    if isinstance(samples, Mapping):
        return dict(samples)
    if isinstance(samples, Sequence) and samples and all(isinstance(r, Mapping) for r in samples):
        keys = list(samples[0])
        for index, row in enumerate(samples):
            if list(row) != keys:
                raise _checks.fail(f"samples[{index}]", dict(row), f"a row with keys {keys}")
        return {key: [row[key] for row in samples] for key in keys}
    raise _checks.fail("samples", samples, "a mapping of option path to a column, or rows")


def _values(key: str, given: Any) -> list:
    if isinstance(given, str | bytes) or not isinstance(given, Sequence | np.ndarray):
        raise _checks.fail(f"grid[{key!r}]", given, "a non-empty list of values")
    if isinstance(given, np.ndarray) and given.ndim == 1:
        listed = given.tolist()  # Python numbers at C speed (a column of 10⁵ samples)
    else:
        listed = [_plain(value) for value in given]
    if not listed:
        raise _checks.fail(f"grid[{key!r}]", given, "a non-empty list of values")
    return listed


def _chunk(chunk: int | None, bytes_per_member: int) -> int:
    if chunk is not None:
        return _checks.count("chunk", chunk)
    return int(np.clip(CHUNK_BYTES // max(bytes_per_member, 1), 1, MAX_CHUNK))


def _chunks(shape: tuple[int, ...], members: int) -> tuple[int, ...]:
    """Block sizes of about ``members`` members: whole trailing dimensions first."""
    chunks = []
    room = members
    for n in reversed(shape):
        size = max(1, min(n, room))
        chunks.append(size)
        room = max(1, room // size)
    return tuple(reversed(chunks))
