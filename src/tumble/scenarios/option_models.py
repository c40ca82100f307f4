"""The options model of each scenario: declared as ``OPTIONS``, or derived from ``run``.

A scenario may declare its pydantic model as ``OPTIONS`` (``rigid-body`` does: its options
are nested tables, :mod:`tumble.scenarios.rigid_body`); otherwise :func:`options_model`
derives one from the signature of its ``run`` — names, types and defaults — and from the
rules its module declares beside ``run`` as ``OPTION_RULES`` (:class:`OptionRules`): which
options must be > 0, which are 3-vectors, which lists need distinct values, and where its
``method``/``methods`` come from. An option whose default is a non-empty sequence must be a
non-empty list. Deriving keeps a single source of truth: an option added to a built-in
``run`` is accepted in files at once, and cannot drift from a hand-written copy. This module
holds only that machinery; each rule lives with its scenario.

:data:`POSITIVE`, :data:`THREE_VECTORS`, :data:`MIN_DISTINCT` and :data:`METHOD_CHOICES`
gather the built-ins' rules (read on first use, which imports every scenario module).

The types and the messages come from :mod:`tumble.scenarios.schema`;
:func:`tumble.scenarios.files.check_options` validates options with these models.
"""

from __future__ import annotations

import inspect
import types
import typing
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
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


@dataclass(frozen=True)
class OptionRules:
    """What a built-in scenario declares of its options beyond ``run``'s signature.

    A scenario module sets ``OPTION_RULES = OptionRules(...)`` beside its ``run``; a module
    without one has no rules but the signature's types and defaults.

    Attributes
    ----------
    positive : iterable of str
        Options that must be > 0 (every number, for a list).
    three_vectors : iterable of str
        Options made of 3-vectors (a point in m, a direction, an angular velocity in rad/s):
        a list of exactly 3 numbers, or for a list of vectors (``spins``) a list of such
        lists.
    min_distinct : mapping of str to int
        Options whose list needs at least this many distinct values (a slope needs two
        steps).
    methods : sequence of str, optional
        The names ``method``/``methods`` may take; None: every :data:`tumble.rigid.METHODS`
        name.

    Examples
    --------
    >>> OptionRules(positive=["h", "t_end"]).positive == {"h", "t_end"}
    True
    """

    positive: Iterable[str] = frozenset()
    three_vectors: Iterable[str] = frozenset()
    min_distinct: Mapping[str, int] = field(default_factory=dict)
    methods: Sequence[str] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "positive", frozenset(self.positive))
        object.__setattr__(self, "three_vectors", frozenset(self.three_vectors))
        object.__setattr__(self, "min_distinct", dict(self.min_distinct))
        if self.methods is not None:
            object.__setattr__(self, "methods", tuple(self.methods))

    def names(self) -> set[str]:
        """Every option a rule names (each must be an option of the scenario's ``run``)."""
        return {*self.positive, *self.three_vectors, *self.min_distinct}


def rules(scenario: str) -> OptionRules:
    """``scenario``'s declared :class:`OptionRules` (none declared: no rules).

    Examples
    --------
    >>> sorted(rules("t-handle").positive), sorted(rules("t-handle").three_vectors)
    (['h', 'rtol', 't_end'], ['spins'])
    """
    return getattr(_scenario(scenario), "OPTION_RULES", OptionRules())


def _gathered() -> dict[str, Any]:
    """The built-ins' rules gathered by kind (what :data:`POSITIVE` and the others hold)."""
    declared = {name: rules(name) for name in registry.names() if name != "rigid-body"}
    return {
        "POSITIVE": frozenset().union(*(r.positive for r in declared.values())),
        "THREE_VECTORS": frozenset().union(*(r.three_vectors for r in declared.values())),
        "MIN_DISTINCT": {k: v for r in declared.values() for k, v in r.min_distinct.items()},
        "METHOD_CHOICES": {n: r.methods for n, r in declared.items() if r.methods is not None},
    }


def __getattr__(name: str) -> Any:
    """:data:`POSITIVE`, :data:`THREE_VECTORS`, :data:`MIN_DISTINCT`, :data:`METHOD_CHOICES`:
    the rules every built-in scenario declares, gathered by kind on first use."""
    if name in ("POSITIVE", "THREE_VECTORS", "MIN_DISTINCT", "METHOD_CHOICES"):
        return _gathered()[name]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _rigid_methods() -> list[str]:
    from tumble.rigid import METHODS

    return list(METHODS)


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


def _option(declared: OptionRules, name: str, parameter: inspect.Parameter, annotation: Any):
    default = parameter.default
    if isinstance(default, tuple):
        default = list(default)
    kind = _field_type(annotation, default, vector=name in declared.three_vectors)
    checks = []
    if isinstance(default, list) and default:
        checks.append(AfterValidator(_non_empty))
    if name in declared.min_distinct:
        checks.append(_distinct(declared.min_distinct[name]))
    if name in declared.positive:
        checks.append(AfterValidator(_positive))
    if name in ("method", "methods"):
        choices = declared.methods if declared.methods is not None else _rigid_methods()
        checks.append(AfterValidator(one_of(list(choices))))
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
    model = getattr(module, "OPTIONS", None)
    if model is not None:
        return model
    declared = rules(scenario)
    hints = typing.get_type_hints(module.run)
    fields = {
        name: _option(declared, name, parameter, hints.get(name, Any))
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


__all__ = ["OptionRules", "options_model", "rules"]  # and, gathered on first use, POSITIVE,
# THREE_VECTORS, MIN_DISTINCT and METHOD_CHOICES (module __getattr__)
