"""The pieces scenario-file models are built from, and how their mistakes read.

Inside:

* value types: :data:`Number` (finite, strict), :data:`Positive`, :data:`NonNegative`,
  :data:`Integer`, :data:`PositiveInteger`, :data:`Flag`, :data:`Text`, :data:`Vector3`,
  :data:`Vector4`, :data:`Matrix3`; numbers are strict, because TOML has numbers, so a quoted
  ``"0.01"`` or a ``true`` where a number belongs is a mistake worth naming, not a value to
  coerce;
* :class:`Section`, the pydantic base of every TOML table (unknown keys refused, listing the
  allowed ones);
* value rules: :func:`one_of` (a name from a list), :func:`check_table` (a library check of a
  whole table), :func:`custom_error`;
* messages: :func:`error_lines` turns a pydantic ``ValidationError`` into one line per
  mistake, ``path = value: what is allowed``, and :func:`validate` raises them as one
  :class:`ValueError`.

The models themselves are elsewhere: the scenarios' options in
:mod:`tumble.scenarios.option_models`, the bodies of ``rigid-body`` in
:mod:`tumble.scenarios.bodies`, the file in :mod:`tumble.scenarios.files`.

Examples
--------
>>> class Spin(Section):
...     rate: Positive = 1.0
>>> validate(Spin, {"rate": -2}, prefix="options")
Traceback (most recent call last):
...
ValueError: options.rate = -2: must be > 0
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any, ClassVar, TypeVar

import numpy as np
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    Strict,
    ValidationError,
    model_validator,
)
from pydantic_core import PydanticCustomError

# ---------------------------------------------------------------------------------------
# Value types, the base of every table and value rules, shared by every model.


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


def check_table(build: Callable[[], Any]) -> Any:
    """``build()``; a ValueError from the library becomes an error of the whole table."""
    try:
        return build()
    except ValueError as error:
        raise custom_error("whole_invalid", "{reason}", reason=str(error)) from None


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


def short_repr(value: Any) -> str:
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
    return path, f"{path} = {short_repr(error['input'])}: {_phrase(error)}"


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


Model = TypeVar("Model", bound=BaseModel)


def validate(
    model: type[Model],
    data: Any,
    *,
    prefix: str = "",
    folder: Path | None = None,
) -> Model:
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


__all__ = [
    "Flag",
    "Integer",
    "Matrix3",
    "NonNegative",
    "Number",
    "Positive",
    "PositiveInteger",
    "Section",
    "Text",
    "Vector3",
    "Vector4",
    "check_table",
    "custom_error",
    "error_lines",
    "one_of",
    "short_repr",
    "validate",
]
