"""Argument checks shared by the structural modules.

Each raises :class:`ValueError` naming the argument, the bad value and what is allowed.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable

import numpy as np
from numpy.typing import ArrayLike, NDArray


def positive(name: str, value: ArrayLike, unit: str = "") -> NDArray[np.float64]:
    """Return ``value`` as a float array after checking it is finite and > 0.

    Examples
    --------
    >>> float(positive("E", 210e9, "Pa"))
    210000000000.0
    >>> positive("E", -1.0, "Pa")
    Traceback (most recent call last):
    ...
    ValueError: E must be a finite number > 0 Pa; got -1.0
    """
    array = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(array) & (array > 0)):
        bad = float(array.ravel()[~(np.isfinite(array.ravel()) & (array.ravel() > 0))][0])
        raise ValueError(f"{name} must be a finite number > 0{_unit(unit)}; got {bad!r}")
    return array


def finite(name: str, value: ArrayLike, unit: str = "") -> NDArray[np.float64]:
    """Return ``value`` as a float array after checking every entry is finite."""
    array = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(array)):
        bad = float(array.ravel()[~np.isfinite(array.ravel())][0])
        raise ValueError(f"{name} must be finite{_unit(unit)}; got {bad!r}")
    return array


def time_step(dt: object) -> float:
    """Check a time step: a finite real number > 0 [s]."""
    if not isinstance(dt, numbers.Real) or not math.isfinite(dt) or dt <= 0:
        raise ValueError(f"dt must be a finite number > 0 s; got {dt!r}")
    return float(dt)


def count(name: str, value: object, minimum: int = 1) -> int:
    """Check an integer count ``>= minimum`` (bools rejected)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}; got {value!r}")
    return int(value)


def choice(name: str, value: object, allowed: Iterable[str]) -> str:
    """Check that ``value`` is one of the ``allowed`` names.

    Examples
    --------
    >>> choice("scheme", "rk4", ["explicit", "midpoint"])
    Traceback (most recent call last):
    ...
    ValueError: scheme must be one of 'explicit', 'midpoint'; got 'rk4'
    """
    allowed = list(allowed)
    if value not in allowed:
        names = ", ".join(repr(a) for a in allowed)
        raise ValueError(f"{name} must be one of {names}; got {value!r}")
    return str(value)


def _unit(unit: str) -> str:
    return f" {unit}" if unit else ""
