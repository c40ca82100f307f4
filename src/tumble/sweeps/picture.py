"""A sweep's map: one summary variable over two swept dimensions (``tumble sweep --map``)."""

from __future__ import annotations

from pathlib import Path

from tumble import _checks


def swept_dims(dataset) -> list[str]:
    """The member dimensions with more than one value, in the store's order."""
    grid = [dim for dim in dataset["done"].dims if dim != "member"]
    return [dim for dim in grid if dataset.sizes[dim] > 1]


DEFAULT_MAP = "flip_period"
"""What ``tumble sweep`` draws without ``--map``: the flip period, on a grid of two swept
dimensions."""
NO_PERIOD = ("no flip period measured (fewer than three crossings): no map; run longer, or "
             "choose another variable with --map")  # fmt: skip
"""Why ``tumble sweep`` draws no default map when no member measured a period."""


def check_map(plan, variable: str, name: str = "map") -> None:
    """Refuse ``--map variable`` before the sweep runs: a per-member variable of ``plan``'s
    store, over exactly two swept dimensions (:func:`draw_map`'s conditions).

    ``plan`` is a :class:`~tumble.sweeps.plan.Plan` whose outputs are named (a built-in's
    :attr:`~tumble.sweeps.plan.Plan.outputs`).
    """
    from tumble.sweeps.plan import RIGID
    from tumble.sweeps.variables import SUMMARY, WALL_TIME

    names = list(SUMMARY) if plan.scenario == RIGID else [*plan.outputs, WALL_TIME]
    _checks.choice(name, variable, names)
    swept = [name for name, n in zip(plan.dims, plan.shape, strict=True) if n > 1]
    if plan.samples or len(swept) != 2:
        raise _checks.fail(
            name, variable, "drawn over exactly two swept dimensions",
            remedy=f"this sweep has {0 if plan.samples else len(swept)}: "
            f"{'none (a table of samples)' if plan.samples else ', '.join(swept) or 'none'}",
        )  # fmt: skip


def map_variable(dataset, requested: str | None) -> tuple[str | None, str]:
    """``(variable to draw or None, a note why none)`` for ``tumble sweep --map``.

    ``requested`` is drawn whatever it holds (:func:`draw_map` checks it); without one,
    :data:`DEFAULT_MAP` when the sweep has it over exactly two swept dimensions and some
    member measured it (else the note :data:`NO_PERIOD`).
    """
    if requested:
        return requested, ""
    if len(swept_dims(dataset)) != 2 or DEFAULT_MAP not in dataset:
        return None, ""
    if dataset[DEFAULT_MAP].isnull().all():
        return None, NO_PERIOD
    return DEFAULT_MAP, ""


def draw_map(dataset, variable: str, path: str | Path, *, title: str = "") -> Path:
    """A heat map of ``variable`` over the two swept dimensions of a grid sweep.

    Parameters
    ----------
    dataset : xarray.Dataset
        A sweep's store (:func:`tumble.sweep`).
    variable : str
        A per-member variable: for a rigid-body sweep one of
        :data:`~tumble.sweeps.members.SUMMARY` (``flip_period``, ``energy_error``,
        ``wall_time``, ``status``, ``n_steps``); for a built-in, a number of its summary.
    path : str or Path
        Output PNG.
    title : str
        Figure title (default: the variable and the store's scenario source).

    Raises
    ------
    ValueError
        If ``variable`` is not a per-member variable, or the sweep has not exactly two swept
        dimensions (other dimensions must have one value).
    """
    from tumble.viz.sweep import heat_maps

    members = dataset["done"].dims
    names = [name for name in dataset.data_vars if dataset[name].dims == members]
    _checks.choice("map", variable, [name for name in names if name != "done"])
    dims = swept_dims(dataset)
    if len(dims) != 2:
        raise _checks.fail(
            "map", variable, "drawn over exactly two swept dimensions",
            remedy=f"this sweep has {len(dims)}: {', '.join(dims) or 'none'}",
        )  # fmt: skip
    y, x = dims
    values = dataset[variable].squeeze(drop=True).transpose(y, x).values.astype(float)
    units = dataset[variable].attrs.get("units", "")
    label = f"{variable} ({units})" if units else variable
    heat_maps(
        [(variable.replace("_", " "), values, label)], dataset[x].values, dataset[y].values,
        path, xlabel=axis_label(dataset, x), ylabel=axis_label(dataset, y),
        title=title or f"{variable} — {Path(dataset.attrs.get('scenario_source', '')).name}",
        log={label} if variable == "energy_error" else (),
    )  # fmt: skip
    return Path(path)


SYMBOLS = {"omega0": "ω", "L0": "L", "x0": "x", "v0": "v", "spins": "ω"}
"""The symbol of a swept vector, whose entry is labelled by its axis (``ω_y``)."""
UNITS = {"omega0": "rad/s", "spins": "rad/s", "h": "s", "t_end": "s", "L0": "kg m²/s",
         "x0": "m", "v0": "m/s", "tilt": "rad", "spin": "rad/s"}  # fmt: skip
"""Units of the options a sweep map's axes most often are."""


def axis_label(dataset, dim: str) -> str:
    """A swept dimension's axis label: a short name and its unit (``ω_y (rad/s)`` for
    ``initial.omega0.1``, ``h (s)``), not the option's full path."""
    path = str(dataset[dim].attrs.get("option_path", dim)).split(".")
    keys = [part for part in path if not part.isdigit()]
    unit = next((UNITS[key] for key in reversed(keys) if key in UNITS), "")
    name = dim
    if path[-1].isdigit() and len(path) >= 2 and path[-2] in SYMBOLS:
        index = int(path[-1])
        name = f"{SYMBOLS[path[-2]]}_{'xyz'[index]}" if index < 3 else dim
    elif path[-1].isdigit() and len(path) >= 3 and path[-3] in SYMBOLS:  # spins.0.1
        name = f"{SYMBOLS[path[-3]]}_{'xyz'[int(path[-1]) % 3]} of {path[-3]}[{path[-2]}]"
    return f"{name} ({unit})" if unit else name
