"""Scenario files: TOML that names a scenario and its options, validated with pydantic.

A file has one required key and three optional ones::

    scenario = "t-handle"          # a name from `tumble list`
    description = "..."            # free text, shown nowhere but kept
    [options]                      # keyword arguments of the scenario's run()
    h = 0.01
    [outputs]                      # what `tumble run` writes
    animation = true

``[options]`` holds exactly what :func:`tumble.scenarios.get(scenario).run(**options)
<tumble.scenarios.get>` takes, so a file that sets every option to its default gives the same
numbers as ``tumble run NAME``. The user's own body is the scenario ``"rigid-body"``
(:mod:`tumble.scenarios.rigid_body`), whose options are tables: ``[options.body]``,
``[options.initial]``, ``[[options.loads]]``. The format, key by key with units, is in
``docs/scenario-files.md``.

Options are checked by one pydantic model per scenario. A scenario may declare its model as
``OPTIONS`` (``rigid-body`` does: its options are nested tables); otherwise the model is
derived from the signature of its ``run`` — names, types and defaults — with value rules
looked up by option name (:data:`POSITIVE`, :data:`METHOD_CHOICES`). Deriving keeps a single
source of truth: an option added to a built-in ``run`` is accepted in files at once, and
cannot drift from a hand-written copy.

Every mistake is a :class:`ValueError` whose message names the key path, the bad value and
what is allowed, e.g. ``options.h = -0.01: must be > 0``.

Examples
--------
>>> check_options("t-handle", {"h": 0.005, "t_end": 20})
{'h': 0.005, 't_end': 20.0}
>>> check_options("t-handle", {"h": -0.01})
Traceback (most recent call last):
...
ValueError: options.h = -0.01: must be > 0
"""

from __future__ import annotations

import inspect
import tomllib
import types
import typing
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Annotated, Any, ClassVar, Union

import numpy as np
from numpy.typing import ArrayLike
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    Strict,
    ValidationError,
    create_model,
    model_validator,
)
from pydantic_core import PydanticCustomError

from tumble import scenarios

# ---------------------------------------------------------------------------------------
# Value types shared by every model. Numbers are strict: TOML has numbers, so a quoted
# "0.01" or a true where a number belongs is a mistake worth naming, not a value to coerce.


def custom_error(kind: str, message: str, **context: Any) -> PydanticCustomError:
    """A validation error whose message :func:`error_lines` shows after ``path = value:``."""
    return PydanticCustomError(kind, message, context or None)


def _plain_integer(value: Any) -> Any:
    """NumPy integers (from Python callers) as int, so the strict int type accepts them."""
    return int(value) if isinstance(value, np.integer) else value


Number = Annotated[float, Strict(), Field(allow_inf_nan=False)]
"""A finite number; an integer is accepted and becomes a float."""
Positive = Annotated[Number, Field(gt=0)]
NonNegative = Annotated[Number, Field(ge=0)]
Integer = Annotated[Annotated[int, Strict()], BeforeValidator(_plain_integer)]
PositiveInteger = Annotated[Integer, Field(gt=0)]
Flag = Annotated[bool, Strict()]
Text = Annotated[str, Strict()]


def _length(count: int, items: str) -> AfterValidator:
    """An after-validator: a list of exactly ``count`` items."""

    def check(value: list) -> list:
        if len(value) != count:
            raise custom_error(
                "length",
                "must be a list of {count} {items} (got {got})",
                count=count,
                items=items,
                got=len(value),
            )
        return value

    return AfterValidator(check)


Vector3 = Annotated[list[Number], _length(3, "numbers")]
"""Three finite numbers, e.g. a point (m) or an angular velocity (rad/s)."""
Matrix3 = Annotated[list[Vector3], _length(3, "rows")]
"""A 3×3 matrix as three rows."""
Vector4 = Annotated[list[Number], _length(4, "numbers")]
"""Four finite numbers, e.g. a quaternion ``[w, x, y, z]``."""


class Section(BaseModel):
    """A TOML table: unknown keys are refused, listing the allowed ones.

    ``what`` says what the keys are (``"an option of scenario 't-handle'"``) and ``hint``
    adds a remedy to the message about an unknown key.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)
    what: ClassVar[str] = "a key here"
    hint: ClassVar[str] = ""

    @model_validator(mode="before")
    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if isinstance(data, Mapping):
            unknown = [key for key in data if key not in cls.model_fields]
            if unknown:
                raise custom_error(
                    "unknown_key",
                    "{key} is not {what}; allowed: {allowed}{hint}",
                    key=str(unknown[0]),
                    what=cls.what,
                    allowed=", ".join(sorted(cls.model_fields)),
                    hint=cls.hint,
                )
        return data


# ---------------------------------------------------------------------------------------
# From pydantic's errors to one line per mistake: "path = value: what is allowed".

_PHRASES = {
    "float_type": "must be a number",
    "float_parsing": "must be a number",
    "finite_number": "must be a finite number",
    "int_type": "must be an integer",
    "int_parsing": "must be an integer",
    "int_from_float": "must be an integer",
    "bool_type": "must be true or false",
    "bool_parsing": "must be true or false",
    "string_type": "must be a string",
    "list_type": "must be a list",
    "tuple_type": "must be a list",
    "dict_type": "must be a table",
    "model_type": "must be a table",
    "model_attributes_type": "must be a table",
}


def _phrase(error: Mapping[str, Any]) -> str:
    kind, context = error["type"], error.get("ctx") or {}
    if kind in _PHRASES:
        return _PHRASES[kind]
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        sign = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<"}.get(kind, "<=")
        bound = next(iter(context.values()))
        bound = f"{bound:g}" if isinstance(bound, int | float) else bound
        return f"must be {sign} {bound}"
    if kind in ("too_short", "too_long"):
        limit = "at least" if kind == "too_short" else "at most"
        count = context.get("min_length" if kind == "too_short" else "max_length")
        return f"must have {limit} {count} item(s) (got {context.get('actual_length')})"
    if kind == "literal_error":
        return f"must be {context['expected']}"
    if kind == "value_error":
        return str(context["error"])
    return str(error["msg"])


def _show(value: Any) -> str:
    """A value as the message shows it: repr, shortened."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _key_path(prefix: str, loc: Sequence[Any], data: Any, kind: str) -> str:
    """``loc`` made a TOML key path, walking ``data`` to drop pydantic's union tags.

    A discriminated union puts its tag (``'cylinder'``, ``'<composite>'``) into ``loc``; an
    item that is not a key (or index) of the input at that point is such a tag and is left
    out, as is a tag equal to the input's ``shape`` or ``type``. A missing key is kept.
    """
    path, node, tagged = prefix, data, False
    for position, item in enumerate(loc):
        last = position == len(loc) - 1
        if isinstance(node, Mapping):
            tag = not (last or tagged) and item in (node.get("shape"), node.get("type"))
            tagged = tagged or tag  # one tag per table: {type = "force", force = [...]}
            if item in node and not tag:
                path, node, tagged = f"{path}.{item}" if path else str(item), node[item], False
            elif last and kind == "missing":
                path = f"{path}.{item}" if path else str(item)
        elif isinstance(item, int) and isinstance(node, Sequence | np.ndarray):
            if not isinstance(node, str) and 0 <= item < len(node):
                path, node = f"{path}[{item}]", node[item]
    return path


def _line(error: Mapping[str, Any], data: Any, prefix: str) -> tuple[str, str]:
    """``(path, message)`` of one pydantic error."""
    kind, context = error["type"], error.get("ctx") or {}
    path = _key_path(prefix, error["loc"], data, kind)
    join = f"{path}." if path else ""
    if kind == "unknown_key":
        return path, f"{join}{error['msg']}"
    if kind == "missing":
        return path, f"{path} is missing (required)"
    if kind in ("union_tag_invalid", "union_tag_not_found"):
        key = str(context.get("discriminator", "")).strip("'")
        if kind == "union_tag_not_found":
            return path, f"{join}{key} is missing (required)"
        allowed = context["expected_tags"].replace("'", "")
        return path, f"{join}{key} = {context['tag']!r}: must be one of {allowed}"
    if kind.startswith("whole_"):  # checks across several keys of one table
        return path, f"{path or 'options'}: {error['msg']}"
    return path, f"{path} = {_show(error['input'])}: {_phrase(error)}"


def error_lines(error: ValidationError, data: Any, prefix: str = "") -> list[str]:
    """One line per bad key; the alternatives of a union are joined with "or"."""
    merged: dict[str, list[str]] = {}
    for item in error.errors():
        path, line = _line(item, data, prefix)
        merged.setdefault(path, [])
        if line not in merged[path]:
            merged[path].append(line)
    lines = []
    for found in merged.values():
        head, *alternatives = found
        rest = [line.rsplit(": must be ", 1)[-1] for line in alternatives]
        lines.append(" or ".join([head, *rest]))
    return lines


def validate(
    model: type[BaseModel],
    data: Any,
    *,
    prefix: str = "",
    folder: Path | None = None,
) -> BaseModel:
    """``model.model_validate(data)``, with a :class:`ValueError` naming every bad key.

    Parameters
    ----------
    model : type of pydantic.BaseModel
        The schema.
    data : mapping
        What to check.
    prefix : str
        Key path of ``data`` itself (``"options"``), put before every key in messages.
    folder : Path, optional
        The folder relative file names (mesh files) are read from; default the working
        folder.
    """
    try:
        return model.model_validate(data, context={"folder": folder})
    except ValidationError as error:
        raise ValueError("\n".join(error_lines(error, data, prefix))) from None


# ---------------------------------------------------------------------------------------
# Options models of the built-in scenarios, derived from run()'s signature.

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


def one_of(choices: list[str]) -> Callable[[Any], Any]:
    """An after-validator: a name, or a list of names, each one of ``choices``."""

    def check(value: Any) -> Any:
        for name in [value] if isinstance(value, str) else value:
            if name not in choices:
                raise custom_error(
                    "unknown_choice", "must be one of {allowed}", allowed=", ".join(choices)
                )
        if not isinstance(value, str) and not value:
            raise custom_error(
                "empty", "must name at least one of {allowed}", allowed=", ".join(choices)
            )
        return value

    return check


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


def check_options(
    scenario: str, options: Mapping[str, Any], *, folder: str | Path | None = None
) -> dict[str, Any]:
    """Validate the options of ``scenario``; return them ready for ``run(**options)``.

    Parameters
    ----------
    scenario : str
        A name of :func:`tumble.scenarios.names`.
    options : mapping
        Keyword arguments of the scenario's ``run``; missing ones keep run's defaults.
    folder : str or Path, optional
        The folder relative file names in the options (mesh files) are relative to; default
        the working folder.

    Returns
    -------
    dict
        The options given, checked and converted (integers to floats where a number is
        expected, relative file names to absolute ones); options not given are left out.

    Raises
    ------
    ValueError
        One line per mistake: the key path (``options.h``), the bad value and what is
        allowed; an unknown option lists the allowed ones.

    Examples
    --------
    >>> check_options("t-handle", {"spinz": []})
    Traceback (most recent call last):
    ...
    ValueError: options.spinz is not an option of scenario 't-handle'; allowed: h, method, rtol, spins, t_end
    """  # noqa: E501 - the doctest's message is one line
    model = options_model(scenario)
    if not isinstance(options, Mapping):
        raise ValueError(f"options = {_show(options)}: must be a table of option = value")
    where = None if folder is None else Path(folder)
    checked = validate(model, dict(options), prefix="options", folder=where)
    return checked.model_dump(mode="json", exclude_unset=True)


# ---------------------------------------------------------------------------------------
# The file.


class Outputs(Section):
    """``[outputs]``: what ``tumble run`` writes besides the figures, data and summary."""

    what: ClassVar[str] = "a key of [outputs]"
    animation: Flag = True
    """Write ``animation.gif`` and ``view.html`` (``--no-animation`` overrides)."""


class _File(Section):
    what: ClassVar[str] = "a top-level key of a scenario file"
    hint: ClassVar[str] = " (a scenario's options go under [options])"
    scenario: Text
    description: Text = ""
    options: dict[str, Any] = {}
    outputs: Outputs = Outputs()


@dataclass(frozen=True)
class ScenarioFile:
    """A scenario file, read and checked.

    Attributes
    ----------
    scenario : str
        The scenario's name (:func:`tumble.scenarios.get`).
    options : dict
        Checked options for ``run(**options)`` (:func:`check_options`).
    outputs : Outputs
        ``outputs.animation``: whether to write ``animation.gif`` and ``view.html``.
    source : Path
        The file, absolute.
    description : str
        The file's free-text ``description``.
    """

    scenario: str
    options: dict[str, Any]
    outputs: Outputs
    source: Path
    description: str = field(default="")


def _load_toml(path: Path) -> dict[str, Any]:
    if not path.is_file():
        reason = "it is a folder" if path.is_dir() else "no such file"
        raise ValueError(f"scenario file {str(path)!r} cannot be read: {reason}")
    try:
        return tomllib.loads(path.read_bytes().decode("utf-8"))
    except tomllib.TOMLDecodeError as error:
        raise ValueError(f"{path}: not valid TOML: {error}") from None
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"scenario file {str(path)!r} cannot be read: {error}") from None


def read(path: str | Path) -> ScenarioFile:
    """Read and check a scenario file.

    Relative file names inside it (a body's ``mesh``) are relative to the file's folder.

    Parameters
    ----------
    path : str or Path
        A TOML file (format: module docstring and ``docs/scenario-files.md``).

    Returns
    -------
    ScenarioFile

    Raises
    ------
    ValueError
        If the file is missing or unreadable, is not TOML (the message gives the line and
        column), names an unknown scenario or key, or has a bad value; the message starts
        with the file name and names the key path.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "spin.toml"
    ...     _ = path.write_text('scenario = "t-handle"\\n[options]\\nt_end = 20.0\\n')
    ...     spin = read(path)
    >>> spin.scenario, spin.options, spin.outputs.animation
    ('t-handle', {'t_end': 20.0}, True)
    """
    path = Path(path)
    data = _load_toml(path)
    try:
        top = validate(_File, data)
        options = check_options(top.scenario, top.options, folder=path.parent)
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None
    return ScenarioFile(
        scenario=top.scenario,
        options=options,
        outputs=top.outputs,
        source=path.resolve(),
        description=top.description,
    )


__all__ = [
    "METHOD_CHOICES",
    "POSITIVE",
    "Outputs",
    "ScenarioFile",
    "Section",
    "check_options",
    "options_model",
    "read",
    "validate",
]
