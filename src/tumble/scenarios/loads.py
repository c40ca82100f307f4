"""The loads of a ``rigid-body`` scenario file: one row of :data:`LOADS` per load type.

Each row names a load class of :mod:`tumble.rigid.forces` (a frozen dataclass); the file's
table of that ``type`` takes the class's fields as keys, with the class's defaults, checked
by a :class:`~tumble.scenarios.schema.Section` made from them (:func:`section`):

.. code-block:: toml

    [[options.loads]]
    type = "magnetic-dipole"
    moment = [0.0, 0.0, 0.2]    # A m², body axes
    field = [2e-5, 0.0, 0.0]    # T, world axes

A field's kind comes from its annotation in the class (:data:`KINDS`: ``Vector`` is three
numbers, ``float`` a finite number), or from the row's ``kinds``. A new load class is one
row here: the scenario files, their messages, the sweeps' short paths (``<type>.<key>``)
and the ``conserved`` flags of the summary then take it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import create_model

from tumble.rigid import Force, Gravity, GravityGradient, Impulse, MagneticDipole, Torque
from tumble.scenarios.schema import NonNegative, Number, Positive, Section, Vector3

KINDS: dict[str, Any] = {
    "Vector": Vector3,
    "VectorOrCallable": Vector3,  # a file gives a constant
    "Vector | None": Vector3 | None,
    "float": Number,
}
"""A load field's annotation (as written in :mod:`tumble.rigid.forces`) → its file kind."""


def _turns(load: Any) -> bool:
    return False


@dataclass(frozen=True)
class LoadRow:
    """One load type of the scenario files.

    Attributes
    ----------
    load : type
        The load class it builds (a dataclass of :mod:`tumble.rigid.forces`).
    body_points : tuple of str
        Keys that are points fixed on the body, given in the description's coordinates
        (shifted to the centre of mass when the load is built).
    kinds : mapping
        A key's kind where its annotation does not say enough (a time that must be >= 0).
    torque_free : callable
        ``torque_free(load)``: whether the built load exerts no torque about the centre of
        mass (then it leaves the angular momentum constant).
    from_body : tuple of str
        Fields the file does not give: left at their default, ``simulate`` fills them from
        the body (the inertia of a gravity gradient).
    """

    load: type
    body_points: tuple[str, ...] = ()
    kinds: Mapping[str, Any] = field(default_factory=dict)
    torque_free: Callable[[Any], bool] = _turns
    from_body: tuple[str, ...] = ()


LOADS: dict[str, LoadRow] = {
    "gravity": LoadRow(Gravity, torque_free=lambda load: True),
    "force": LoadRow(Force, body_points=("point",), torque_free=lambda load: load.point is None),
    "torque": LoadRow(Torque),
    "magnetic-dipole": LoadRow(MagneticDipole),
    "impulse": LoadRow(Impulse, kinds={"time": NonNegative}, torque_free=lambda load: False),
    "gravity-gradient": LoadRow(GravityGradient, kinds={"mu": Positive}, from_body=("inertia",)),
}
"""Every load type of the scenario files, by its ``type``."""


class LoadSection(Section):
    """A load's table: its ``type`` and the keys of its row's class (:func:`section`)."""

    row: ClassVar[LoadRow]
    type: str

    def build(self, com: np.ndarray) -> Any:
        """The load, its body points taken from the centre of mass ``com`` (m)."""
        given = self.model_dump(exclude={"type"})
        for key in self.row.body_points:
            if given[key] is not None:
                given[key] = np.subtract(given[key], com)
        return self.row.load(**given)


def section(name: str, row: LoadRow) -> type[LoadSection]:
    """The checked table of load ``name``: ``type`` and the fields of ``row.load``."""
    fields: dict[str, Any] = {"type": (Literal[name], ...)}
    for item in dataclasses.fields(row.load):
        if item.name in row.from_body:
            continue
        kind = row.kinds.get(item.name) or KINDS.get(str(item.type))
        if kind is None:
            raise TypeError(
                f"load {name!r}: field {item.name!r} is annotated {item.type!r}, which has no "
                f"scenario-file kind; give it one in its row's kinds"
            )
        default = item.default
        if default is dataclasses.MISSING:
            default = ...
        elif isinstance(default, tuple):
            default = list(default)
        fields[item.name] = (kind, default)
    model = create_model(
        f"{row.load.__name__}Load",
        __base__=LoadSection,
        __doc__=f"A ``{name}`` load: :class:`tumble.rigid.{row.load.__name__}`.",
        **fields,
    )
    model.what = f"a key of {'an' if name[0] in 'aeiou' else 'a'} {name} load"
    model.row = row
    return model


SECTIONS: dict[str, type[LoadSection]] = {name: section(name, row) for name, row in LOADS.items()}
"""The checked table of each load type (``SECTIONS["force"]``)."""

_ROWS_BY_CLASS = {row.load: row for row in LOADS.values()}


def torque_free(load: Any) -> bool:
    """Whether a built load exerts no torque (False for a class no row names)."""
    row = _ROWS_BY_CLASS.get(type(load))
    return row is not None and row.torque_free(load)
