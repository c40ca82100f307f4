"""The options model of each scenario: declared as ``OPTIONS``, or derived from ``run``.

A scenario may declare its pydantic model as ``OPTIONS`` (``rigid-body`` does: its options
are nested tables, :mod:`tumble.scenarios.rigid_body`); otherwise :func:`options_model`
derives one from the signature of its ``run`` — names, types and defaults — with value
rules looked up by option name: :data:`POSITIVE` (must be > 0), :data:`THREE_VECTORS` (lists
of exactly 3 numbers), :data:`MIN_DISTINCT` (enough distinct values) and
:data:`METHOD_CHOICES` (a method name). An option whose default is a non-empty sequence must
be a non-empty list. Deriving keeps a single source of truth: an option added to a built-in
``run`` is accepted in files at once, and cannot drift from a hand-written copy.

The types and the messages come from :mod:`tumble.scenarios.schema`;
:func:`tumble.scenarios.files.check_options` validates options with these models.
"""

from __future__ import annotations

import inspect
import types
import typing
from collections.abc import Sequence
from functools import cache
from typing import Annotated, Any, Union

import numpy as np
from numpy.typing import ArrayLike
from pydantic import AfterValidator, BaseModel, create_model

from tumble.scenarios import registry
from tumble.scenarios.schema import (
    Flag,
    Integer,
    Number,
    Section,
    Text,
    Vector3,
    custom_error,
    one_of,
)

POSITIVE = frozenset(
    {
        "h", "t_end", "t_max", "rtol", "speed", "g", "density", "duration", "body_mass",
        "circumradius", "length", "major_radius", "minor_radius", "E", "rho", "width",
        "height", "n_elements", "steps_per_period", "n_steps", "sweep_steps",
        "frame_every", "step_counts", "record_every",
    }
)  # fmt: skip
"""Options of a built-in scenario that must be > 0 (every number, for a list)."""
THREE_VECTORS = frozenset({"center", "hit_from", "vertex", "omega0", "spins"})
"""Options of a built-in scenario made of 3-vectors (a point in m, a direction, an angular
velocity in rad/s): a list of exactly 3 numbers, or for a list of vectors (``spins``) a list
of such lists."""
MIN_DISTINCT = {"step_counts": 2}
"""Options whose list needs at least this many distinct values (a slope needs two steps)."""


def _rigid_methods() -> list[str]:
    from tumble.rigid import METHODS

    return list(METHODS)


def _fixed_step_rigid_methods() -> list[str]:
    from tumble.scenarios._common import fixed_step_methods

    return list(fixed_step_methods())


def _ode_methods() -> list[str]:
    from tumble.ode import TABLEAUX

    return list(TABLEAUX)


METHOD_CHOICES = {"projectile": _ode_methods, "convergence": _fixed_step_rigid_methods}
"""Where a scenario's ``method``/``methods`` come from; others: :data:`tumble.rigid.METHODS`."""


def _numbers(value: Any) -> list[float]:
    if isinstance(value, list):
        return [number for item in value for number in _numbers(item)]
    return [value] if isinstance(value, int | float) else []


def _positive(value: Any) -> Any:
    if any(number <= 0 for number in _numbers(value)):
        phrase = "every number must be > 0" if isinstance(value, list) else "must be > 0"
        raise custom_error("positive", phrase)
    return value


def _non_empty(value: Any) -> Any:
    if isinstance(value, list) and not value:
        raise custom_error("empty", "must have at least one item")
    return value


def _distinct(count: int) -> AfterValidator:
    """An after-validator: a list of at least ``count`` distinct values."""

    def check(value: Any) -> Any:
        if isinstance(value, list) and len(set(value)) < count:
            raise custom_error(
                "distinct", "must hold at least {count} distinct values", count=count
            )
        return value

    return AfterValidator(check)


def _is_array_like(annotation: Any) -> bool:
    members = set(typing.get_args(ArrayLike))
    return bool(members) and members <= set(typing.get_args(annotation))


def _field_type(annotation: Any, default: Any, vector: bool = False) -> Any:
    """The pydantic type of one option: Sequence → list, array_like → nested list.

    With ``vector``, the innermost list of numbers is a :data:`Vector3` (3 numbers).
    """
    simple = {bool: Flag, int: Integer, float: Number, str: Text}
    if annotation in simple:
        return simple[annotation]
    args = typing.get_args(annotation)
    optional = type(None) in args
    if _is_array_like(annotation):
        depth = max(1, np.ndim(default)) if default is not None else 1
        result: Any = Vector3 if vector else list[Number]
        for _ in range(depth - 1):
            result = list[result]
        return result | None if optional else result
    origin = typing.get_origin(annotation)
    if origin in (Union, types.UnionType):
        members = [_field_type(arg, default, vector) for arg in args if arg is not type(None)]
        result = Union[tuple(members)]  # noqa: UP007 - built from a list
        return result | None if optional else result
    if origin in (list, tuple, Sequence) and args:
        item = _field_type(args[0], None, vector)
        return Vector3 if vector and item is Number else list[item]  # type: ignore[valid-type]
    return Any


def _option(scenario: str, name: str, parameter: inspect.Parameter, annotation: Any):
    default = parameter.default
    if isinstance(default, tuple):
        default = list(default)
    kind = _field_type(annotation, default, vector=name in THREE_VECTORS)
    checks = []
    if isinstance(default, list) and default:
        checks.append(AfterValidator(_non_empty))
    if name in MIN_DISTINCT:
        checks.append(_distinct(MIN_DISTINCT[name]))
    if name in POSITIVE:
        checks.append(AfterValidator(_positive))
    if name in ("method", "methods"):
        checks.append(AfterValidator(one_of(METHOD_CHOICES.get(scenario, _rigid_methods)())))
    if checks:
        kind = Annotated[kind, *checks]
    required = default is inspect.Parameter.empty
    return kind, (... if required else default)


@cache
def options_model(scenario: str) -> type[BaseModel]:
    """The pydantic model of ``scenario``'s options (its ``OPTIONS``, or derived from run).

    Raises
    ------
    ValueError
        If ``scenario`` is not known.

    Examples
    --------
    >>> sorted(options_model("t-handle").model_fields)
    ['h', 'method', 'rtol', 'spins', 't_end']
    """
    module = _scenario(scenario)
    declared = getattr(module, "OPTIONS", None)
    if declared is not None:
        return declared
    hints = typing.get_type_hints(module.run)
    fields = {
        name: _option(scenario, name, parameter, hints.get(name, Any))
        for name, parameter in inspect.signature(module.run).parameters.items()
        if parameter.kind is inspect.Parameter.KEYWORD_ONLY
    }
    model = create_model(f"{module.__name__}.Options", __base__=Section, **fields)
    model.what = f"an option of scenario {scenario!r}"
    return model


def _scenario(name: Any):
    if name not in registry.names():
        raise ValueError(
            f"scenario = {name!r} is not known; allowed: {', '.join(registry.names())}"
        )
    return registry.get(name)


__all__ = ["METHOD_CHOICES", "MIN_DISTINCT", "POSITIVE", "THREE_VECTORS", "options_model"]
