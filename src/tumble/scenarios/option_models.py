"""The options model of each scenario: declared as ``OPTIONS``, or derived from ``run``.

A scenario may declare its pydantic model as ``OPTIONS`` (``rigid-body`` does: its options
are nested tables, :mod:`tumble.scenarios.rigid_body`); otherwise :func:`options_model`
derives one from the signature of its ``run`` — names, types and defaults — with value
rules looked up by option name: :data:`POSITIVE` (must be > 0) and :data:`METHOD_CHOICES`
(a method name). Deriving keeps a single source of truth: an option added to a built-in
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

from tumble import scenarios
from tumble.scenarios.schema import Flag, Integer, Number, Section, Text, custom_error, one_of

POSITIVE = frozenset(
    {
        "h", "t_end", "t_max", "rtol", "speed", "g", "density", "duration", "body_mass",
        "circumradius", "length", "major_radius", "minor_radius", "E", "rho", "width",
        "height", "n_elements", "steps_per_period", "n_steps", "sweep_steps",
        "frame_every", "step_counts", "record_every",
    }
)  # fmt: skip
"""Options of a built-in scenario that must be > 0 (every number, for a list)."""


def _rigid_methods() -> list[str]:
    from tumble.rigid import METHODS

    return list(METHODS)


def _ode_methods() -> list[str]:
    from tumble.ode import TABLEAUX

    return list(TABLEAUX)


METHOD_CHOICES = {"projectile": _ode_methods}
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


def _is_array_like(annotation: Any) -> bool:
    members = set(typing.get_args(ArrayLike))
    return bool(members) and members <= set(typing.get_args(annotation))


def _field_type(annotation: Any, default: Any) -> Any:
    """The pydantic type of one option: Sequence → list, array_like → nested list."""
    simple = {bool: Flag, int: Integer, float: Number, str: Text}
    if annotation in simple:
        return simple[annotation]
    args = typing.get_args(annotation)
    optional = type(None) in args
    if _is_array_like(annotation):
        depth = max(1, np.ndim(default)) if default is not None else 1
        result: Any = Number
        for _ in range(depth):
            result = list[result]
        return result | None if optional else result
    origin = typing.get_origin(annotation)
    if origin in (Union, types.UnionType):
        members = [_field_type(arg, default) for arg in args if arg is not type(None)]
        result = Union[tuple(members)]  # noqa: UP007 - built from a list
        return result | None if optional else result
    if origin in (list, tuple, Sequence) and args:
        return list[_field_type(args[0], None)]
    return Any


def _option(scenario: str, name: str, parameter: inspect.Parameter, annotation: Any):
    default = parameter.default
    if isinstance(default, tuple):
        default = list(default)
    kind = _field_type(annotation, default)
    checks = []
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
    if name not in scenarios.names():
        raise ValueError(
            f"scenario = {name!r} is not known; allowed: {', '.join(scenarios.names())}"
        )
    return scenarios.get(name)


__all__ = ["METHOD_CHOICES", "POSITIVE", "options_model"]
