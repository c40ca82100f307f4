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
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from functools import cache
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray


class LargeStepWarning(UserWarning):
    """A fixed step so large for the motion that the method cannot resolve it (a rigid body
    turned by more than a radian a step): the run goes on, and its result is not accurate.

    Filter it as any warning, e.g. ``warnings.simplefilter("ignore", LargeStepWarning)``;
    :func:`tumble.exact.study` silences it in its runs, which measure their errors.
    """


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


def count(name: str, value: object, minimum: int = 1, maximum: int | None = None,
          remedy: str = "") -> int:  # fmt: skip
    """``value`` as an int, after checking it is an integer ``>= minimum`` (bools refused),
    and ``<= maximum`` if one is given (a bound on what fits in memory or a machine word)."""
    if type(value) is int and value >= minimum and (maximum is None or value <= maximum):
        return value
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or int(value) < minimum:
        raise fail(name, value, f"an integer >= {minimum}", remedy=remedy)
    if maximum is not None and int(value) > maximum:
        raise fail(name, value, f"an integer from {minimum} to {maximum}", remedy=remedy)
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


def _numbers(value: object) -> NDArray[np.float64] | None:
    """``value`` as a new float array, or None unless it is numbers (reals, not bools,
    complex numbers or strings: ``np.array(["1", "2"], dtype=float)`` would parse strings,
    and ``[True, 2.0]`` or ``1j`` would pass as numbers)."""
    try:
        result = np.array(value)
    except (TypeError, ValueError):  # a ragged nesting
        return None
    kind = result.dtype.kind
    if kind == "f":
        return result if result.dtype == _FLOAT else result.astype(float)
    if kind in "iu":
        return result.astype(float)
    if kind == "O":  # Fractions, Decimals, None, or a mixture with other objects
        if any(isinstance(item, bool | str | bytes | complex) or item is None
               for item in result.flat):  # fmt: skip
            return None
        try:
            return result.astype(float)
        except (TypeError, ValueError):
            return None
    return None


_FLOAT = np.dtype(float)


def _all_finite(result: NDArray[np.float64]) -> bool:
    """Whether every entry is finite (count_nonzero: half of ``.all()``'s cost on 3-vectors)."""
    return np.count_nonzero(np.isfinite(result)) == result.size


def array(
    name: str,
    value: ArrayLike,
    *,
    shape: Sequence[int] | None = None,
    unit: str = "",
    positive: bool = False,
    finite: bool = True,
) -> NDArray[np.float64]:
    """``value`` as a float array (a copy), every entry finite (and > 0 if ``positive``);
    with ``finite=False`` inf and NaN pass (a failed run's error, say).

    ``shape`` is the shape required, if any. The message names the first bad entry. Only
    real numbers count: strings, bools, complex numbers and None are refused (whole; a bool
    among floats is a number to NumPy).

    Examples
    --------
    >>> array("x0", [0.0, 1.0], shape=(3,), unit="m")
    Traceback (most recent call last):
    ...
    ValueError: x0=[0.0, 1.0] is not allowed: must be of shape (3,), every entry finite (m)
    >>> array("atol", True)
    Traceback (most recent call last):
    ...
    ValueError: atol=True is not allowed: must be an array of numbers, every entry finite
    """
    each = "finite and > 0" if positive else "finite"
    whole = "an array of numbers" if shape is None else f"of shape {tuple(shape)}"
    wanted = f"{whole}, every entry {each}"
    if not finite:
        wanted = wanted.replace(", every entry finite", "")
    result = _numbers(value)
    if result is None or (shape is not None and result.shape != tuple(shape)):
        raise fail(name, value, wanted, unit)
    if not finite:
        return result
    good = _all_finite(result)
    if good and positive:
        good = np.count_nonzero(result > 0) == result.size
    if not good:
        bad = ~(np.isfinite(result) & (result > 0)) if positive else ~np.isfinite(result)
        if result.ndim == 0:
            raise fail(name, value, wanted, unit)
        index = tuple(int(i) for i in np.argwhere(bad)[0])
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
    result = _numbers(value)
    if result is None or result.ndim != 1 or result.size < minimum:
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


def optional_flag(name: str, value: object, remedy: str = "") -> bool | None:
    """``value`` if it is None, ``True`` or ``False`` (a choice left to the library when
    None), else the ValueError.

    Examples
    --------
    >>> optional_flag("compiled", "no")
    Traceback (most recent call last):
    ...
    ValueError: compiled='no' is not allowed: must be None, True or False
    """
    if value is None:
        return None
    if isinstance(value, bool | np.bool_):
        return bool(value)
    raise fail(name, value, "None, True or False", remedy=remedy)


def function(name: str, value: object, what: str = "a callable", remedy: str = "") -> Callable:
    """``value`` if it is callable, else the ValueError (``what`` says its signature).

    Examples
    --------
    >>> function("run", 3, "a callable run(setting)")
    Traceback (most recent call last):
    ...
    ValueError: run=3 is not allowed: must be a callable run(setting)
    """
    if callable(value):
        return value
    raise fail(name, value, what, remedy=remedy)


def instance(name: str, value: object, kind: type | tuple[type, ...], what: str,
             remedy: str = "") -> Any:  # fmt: skip
    """``value`` if it is an instance of ``kind``, else the ValueError naming ``what``.

    Examples
    --------
    >>> instance("system", 3.0, dict, "a tumble.structural.LinearSystem")
    Traceback (most recent call last):
    ...
    ValueError: system=3.0 is not allowed: must be a tumble.structural.LinearSystem
    """
    if isinstance(value, kind):
        return value
    raise fail(name, value, what, remedy=remedy)


def path(name: str, value: object, what: str = "a file path") -> Path:
    """``value`` (a ``str`` or path-like, not empty) as a :class:`~pathlib.Path`.

    Examples
    --------
    >>> path("out", 3)
    Traceback (most recent call last):
    ...
    ValueError: out=3 is not allowed: must be a file path, as a str or pathlib.Path
    """
    if isinstance(value, str | PathLike) and str(value) != "":
        return Path(value)
    raise fail(name, value, f"{what}, as a str or pathlib.Path")


def trailing(
    name: str, value: ArrayLike, shape: tuple[int, ...], what: str
) -> NDArray[np.float64]:
    """``value`` as a float array whose last axes are ``shape`` (any leading axes, for the
    batched pure functions of :mod:`tumble.so3`); entries may be NaN or inf (they propagate,
    as in NumPy's functions). ``what`` names one item, e.g. "rotation vectors".

    Examples
    --------
    >>> trailing("w", [1.0, 2.0], (3,), "3-vectors").shape
    Traceback (most recent call last):
    ...
    ValueError: w=[1.0, 2.0] is not allowed: must be 3-vectors of shape (..., 3); it has shape (2,)
    """
    result = value if type(value) is np.ndarray and value.dtype == _FLOAT else _numbers(value)
    if result is None or result.shape[max(result.ndim - len(shape), 0) :] != shape:
        dims = ", ".join(["...", *map(str, shape)])
        remedy = "" if result is None else f"it has shape {result.shape}"
        raise fail(name, value, f"{what} of shape ({dims})", remedy=remedy)
    return result


def items(name: str, value: object, what: str) -> list:
    """``value`` as a list: a sequence (not a string or a mapping), or None for ``[]``.

    Examples
    --------
    >>> items("forces", 3, "a sequence of loads")
    Traceback (most recent call last):
    ...
    ValueError: forces=3 is not allowed: must be a sequence of loads (or None)
    """
    if value is None:
        return []
    if isinstance(value, str | bytes | Mapping) or not isinstance(value, Iterable):
        raise fail(name, value, f"{what} (or None)")
    return list(value)


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


@cache
def memory() -> float:
    """This machine's physical memory in bytes (16 GiB if the system does not say): what
    the checks of a run's size measure against."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 16.0 * 2**30


def _byte_size(count: float) -> str:
    """Bytes in binary units, as the size checks print them: ``_byte_size(3 * 2**30)`` is
    ``'3 GiB'``."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if count < 1024 or unit == "PiB":
            return f"{count:.3g} {unit}"
        count /= 1024
    raise AssertionError  # pragma: no cover - the loop always returns


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
