"""Sweep values written as text: ``--grid PATH=start:stop:count`` and a file's ``[sweep.grid]``."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from tumble import _checks


def parse_values(key: str, text: str) -> list:
    """The values of ``--grid KEY=TEXT``: ``start:stop:count`` or ``a,b,c``.

    ``start:stop:count`` is ``count`` evenly spaced numbers from ``start`` to ``stop``, both
    included (``numpy.linspace``); ``a,b,c`` a list of numbers, ``true``/``false`` or names.

    Examples
    --------
    >>> parse_values("omega0.1", "0.0:0.1:3")
    [0.0, 0.05, 0.1]
    >>> parse_values("method", "rkmk4,split-axes")
    ['rkmk4', 'split-axes']
    >>> parse_values("h", "0.01:0.1")
    Traceback (most recent call last):
    ...
    ValueError: grid h='0.01:0.1' is not allowed: must be start:stop:count (numbers, count an integer >= 1) or a comma-separated list
    """  # noqa: E501 - the doctest's message is one line
    parts = text.split(":")
    if len(parts) == 1:
        return [_scalar(item.strip()) for item in text.split(",")]
    allowed = "start:stop:count (numbers, count an integer >= 1) or a comma-separated list"
    try:
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
    except (ValueError, IndexError):
        raise _checks.fail(f"grid {key}", text, allowed) from None
    if len(parts) != 3 or count < 1 or not (math.isfinite(start) and math.isfinite(stop)):
        raise _checks.fail(f"grid {key}", text, allowed)
    return np.linspace(start, stop, count).tolist()


def grid_from_arguments(items: Sequence[str]) -> dict[str, list] | None:
    """The ``--grid PATH=VALUES`` arguments as dotted path → values; None for none.

    Examples
    --------
    >>> grid_from_arguments(["omega0.1=0:0.1:3", "method=rkmk4"])
    {'omega0.1': [0.0, 0.05, 0.1], 'method': ['rkmk4']}
    >>> grid_from_arguments(["h"])
    Traceback (most recent call last):
    ...
    ValueError: --grid 'h': must be PATH=VALUES, e.g. omega0.1=0:0.1:5
    """
    grid = {}
    for item in items:
        key, sign, text = item.partition("=")
        if not sign:
            raise ValueError(f"--grid {item!r}: must be PATH=VALUES, e.g. omega0.1=0:0.1:5")
        grid[key.strip()] = parse_values(key.strip(), text)
    return grid or None


def _scalar(text: str) -> Any:
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return {"true": True, "false": False}.get(text, text)


def grid_from_table(table: Mapping, prefix: str = "") -> dict[str, list]:
    """A file's ``[sweep.grid]`` as dotted path → values (nested tables are dotted keys).

    A value is a list, or text in :func:`parse_values`'s grammar.

    Examples
    --------
    >>> grid_from_table({"omega0": {"1": "0:0.1:3"}, "method": ["rkmk4"]})
    {'omega0.1': [0.0, 0.05, 0.1], 'method': ['rkmk4']}
    """
    grid: dict[str, list] = {}
    for key, value in table.items():
        path = f"{prefix}.{key}" if prefix else str(key)
        if isinstance(value, Mapping):
            grid.update(grid_from_table(value, path))
        elif isinstance(value, str):
            grid[path] = parse_values(path, value)
        else:
            grid[path] = value
    return grid
