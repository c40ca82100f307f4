"""Input checks: one module, one message grammar.

Every check raises :class:`ValueError` with a message of one form,

    ``{name}={value!r} is not allowed: must be {what is allowed} ({unit}); {remedy}``

naming the argument, the value, what is allowed and the unit (the unit and the remedy only
where there is one). "Positive" always means finite and > 0: an infinite step, mass or
tolerance is refused like a negative one.

Examples
--------
>>> positive("h", 0.01, "s")
0.01
>>> positive("h", -0.1, "s")
Traceback (most recent call last):
...
ValueError: h=-0.1 is not allowed: must be finite and > 0 (s)
>>> count("record_every", 0)
Traceback (most recent call last):
...
ValueError: record_every=0 is not allowed: must be an integer >= 1
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray


def fail(name: str, value: object, allowed: str, unit: str = "", remedy: str = "") -> ValueError:
    """The ValueError of this module's grammar (returned, for the caller to raise).

    Examples
    --------
    >>> str(fail("method", "rk5", "one of 'rk4', 'dopri5'", remedy="see tumble.ode.TABLEAUX"))
    "method='rk5' is not allowed: must be one of 'rk4', 'dopri5'; see tumble.ode.TABLEAUX"
    """
    message = f"{name}={value!r} is not allowed: must be {allowed}"
    if unit:
        message += f" ({unit})"
    if remedy:
        message += f"; {remedy}"
    return ValueError(message)


def _finite_real(value: object) -> float | None:
    """``value`` as a float if it is a finite real number (not a bool), else None."""
    if type(value) is float:  # the common case first: checks run on every call of a run
        return value if math.isfinite(value) else None
    if isinstance(value, bool):
        return None
    if isinstance(value, float | int | np.floating | np.integer) or isinstance(
        value, numbers.Real
    ):
        number = float(value)
        if math.isfinite(number):
            return number
    return None


def positive(name: str, value: object, unit: str = "", remedy: str = "") -> float:
    """``value`` as a float, after checking it is a finite real number > 0."""
    number = _finite_real(value)
    if number is None or not number > 0:
        raise fail(name, value, "finite and > 0", unit, remedy)
    return number


def non_negative(name: str, value: object, unit: str = "", remedy: str = "") -> float:
    """``value`` as a float, after checking it is a finite real number >= 0."""
    number = _finite_real(value)
    if number is None or not number >= 0:
        raise fail(name, value, "finite and >= 0", unit, remedy)
    return number


def finite(name: str, value: object, unit: str = "", remedy: str = "") -> float:
    """``value`` as a float, after checking it is a finite real number."""
    number = _finite_real(value)
    if number is None:
        raise fail(name, value, "a finite number", unit, remedy)
    return number


def count(name: str, value: object, minimum: int = 1) -> int:
    """``value`` as an int, after checking it is an integer ``>= minimum`` (bools refused)."""
    if type(value) is int and value >= minimum:
        return value
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or int(value) < minimum:
        raise fail(name, value, f"an integer >= {minimum}")
    return int(value)


def choice(name: str, value: object, allowed: Iterable[str], remedy: str = "") -> str:
    """``value``, after checking it is one of the ``allowed`` names.

    Examples
    --------
    >>> choice("scheme", "rk4", ["explicit", "midpoint"])
    Traceback (most recent call last):
    ...
    ValueError: scheme='rk4' is not allowed: must be one of 'explicit', 'midpoint'
    """
    names = list(allowed)
    if not isinstance(value, str) or value not in names:
        raise fail(name, value, "one of " + ", ".join(map(repr, names)), remedy=remedy)
    return value


def array(
    name: str,
    value: ArrayLike,
    *,
    shape: Sequence[int] | None = None,
    unit: str = "",
    positive: bool = False,
) -> NDArray[np.float64]:
    """``value`` as a float array (a copy), every entry finite (and > 0 if ``positive``).

    ``shape`` is the shape required, if any. The message names the first bad entry.

    Examples
    --------
    >>> array("x0", [0.0, 1.0], shape=(3,), unit="m")
    Traceback (most recent call last):
    ...
    ValueError: x0=[0.0, 1.0] is not allowed: must be of shape (3,), every entry finite (m)
    """
    each = "finite and > 0" if positive else "finite"
    whole = "an array of numbers" if shape is None else f"of shape {tuple(shape)}"
    wanted = f"{whole}, every entry {each}"
    try:
        result = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise fail(name, value, wanted, unit) from None
    if shape is not None and result.shape != tuple(shape):
        raise fail(name, value, wanted, unit)
    good = np.isfinite(result) & (result > 0) if positive else np.isfinite(result)
    if not good.all():  # the method: a third of np.all(good)'s cost
        if result.ndim == 0:
            raise fail(name, value, wanted, unit)
        index = tuple(int(i) for i in np.argwhere(~good)[0])
        label = f"{name}[{', '.join(map(str, index))}]"
        raise fail(label, float(result[index]), each, unit)
    return result


def values(
    name: str,
    value: ArrayLike,
    *,
    minimum: int = 1,
    unit: str = "",
    positive: bool = False,
    remedy: str = "",
) -> NDArray[np.float64]:
    """``value`` as a 1-D float array (a copy) of at least ``minimum`` entries, each finite
    (and > 0 if ``positive``): step sizes, tolerances, errors, time steps to sweep.

    The message names the first bad entry.

    Examples
    --------
    >>> values("h", [0.1], minimum=2, unit="s")
    Traceback (most recent call last):
    ...
    ValueError: h=[0.1] is not allowed: must be a 1-D array of >= 2 entries, each finite (s)
    >>> values("errors", [1e-3, 0.0], positive=True, remedy="an exact method has no order")
    Traceback (most recent call last):
    ...
    ValueError: errors[1]=0.0 is not allowed: must be finite and > 0; an exact method has no order
    """
    each = "finite and > 0" if positive else "finite"
    wanted = f"a 1-D array of >= {minimum} entries, each {each}"
    try:
        result = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise fail(name, value, wanted, unit, remedy) from None
    if result.ndim != 1 or result.size < minimum:
        raise fail(name, value, wanted, unit, remedy)
    good = np.isfinite(result) & (result > 0) if positive else np.isfinite(result)
    if not good.all():
        index = int(np.argmin(good))
        raise fail(f"{name}[{index}]", float(result[index]), each, unit, remedy)
    return result


def flag(name: str, value: object) -> bool:
    """``value`` if it is a boolean (``True``/``False``, numpy's too), else the ValueError:
    a string such as ``"yes"`` or ``"false"`` is refused, not read as true.

    Examples
    --------
    >>> flag("progress", False)
    False
    >>> flag("progress", "x")
    Traceback (most recent call last):
    ...
    ValueError: progress='x' is not allowed: must be True or False
    """
    if isinstance(value, bool | np.bool_):
        return bool(value)
    raise fail(name, value, "True or False")


def callables(name: str, value: object, remedy: str = "") -> list:
    """``value`` as a list of callables: one callable, or a sequence of them; None is
    ``[]``. Anything else is refused naming ``name`` (or ``name[i]`` for a bad item)."""
    if value is None or (type(value) is tuple and not value):
        return []
    if callable(value):
        return [value]
    if isinstance(value, str | bytes) or not isinstance(value, Iterable):
        raise fail(name, value, "a callable g(t, y) or a sequence of them", remedy=remedy)
    items = list(value)
    for index, item in enumerate(items):
        if not callable(item):
            raise fail(f"{name}[{index}]", item, "a callable g(t, y)", remedy=remedy)
    return items


def sample_times(name: str, value: ArrayLike, t0: float, t1: float) -> NDArray[np.float64]:
    """``value`` as a 1-D float array of times, sorted (increasing) and within ``[t0, t1]``:
    where a run is asked to sample its dense output (``t_eval``).

    Examples
    --------
    >>> sample_times("t", [0.0, 2.0, 1.0], 0.0, 3.0)
    Traceback (most recent call last):
    ...
    ValueError: t=[0.0, 2.0, 1.0] is not allowed: must be increasing: t[2]=1.0 follows 2.0 (s)
    >>> sample_times("t_eval", [0.5, 4.0], 0.0, 3.0)
    Traceback (most recent call last):
    ...
    ValueError: t_eval[1]=4.0 is not allowed: must be within the run, [0.0, 3.0] (s)
    """
    times = values(name, value, unit="s")
    outside = np.flatnonzero((times < t0) | (times > t1))
    if outside.size:
        i = int(outside[0])
        raise fail(f"{name}[{i}]", float(times[i]), f"within the run, [{t0!r}, {t1!r}]", "s")
    steps = np.flatnonzero(np.diff(times) <= 0)
    if steps.size:
        i = int(steps[0]) + 1
        raise fail(
            name,
            value,
            f"increasing: {name}[{i}]={float(times[i])!r} follows {float(times[i - 1])!r}",
            "s",
        )
    return times
