"""The bodies of scenario ``rigid-body``: a primitive, a composite or a mesh file, as models.

Each model checks a body described in its own coordinates (m) and builds what the scenario
needs from it: :meth:`mass_properties` (a :class:`tumble.mass.MassProperties`: mass,
centre of mass, inertia), :meth:`surface` (a closed :class:`trimesh.Trimesh`) and
:meth:`label` (what the body is, for titles and summaries).

* a primitive (:data:`Primitive`, one of :class:`Cylinder`, :class:`Box`, :class:`Sphere`,
  :class:`Torus`, :class:`HexPrism`, named by ``shape``): the arguments of the functions of
  the same name in :mod:`tumble.mass` and :mod:`tumble.meshes`, plus ``density`` or
  ``mass``;
* a mesh file (:class:`MeshBody`): ``mesh``, ``density`` and ``scale``, read relative to the
  scenario file's folder; the mesh must be closed and outward-oriented;
* a composite (:class:`Composite`): ``parts``, primitives or meshes added by the
  parallel-axis theorem; a part with neither ``density`` nor ``mass`` takes the composite's
  ``density``.

:data:`Body` is the union of the three, told apart by the key that says which (``shape``,
``mesh`` or ``parts``); :data:`Part` is a composite's part. The options around the body
(initial state, loads, method) are in :mod:`tumble.scenarios.rigid_body`.

Examples
--------
>>> from tumble.scenarios.schema import validate
>>> class Check(Section):
...     body: Body
>>> rod = {"shape": "cylinder", "radius": 0.01, "length": 0.1, "mass": 0.5, "axis": "y"}
>>> round(float(validate(Check, {"body": rod}).body.mass_properties().mass), 12)
0.5
>>> validate(Check, {"body": {**rod, "radius": -1}})
Traceback (most recent call last):
...
ValueError: body.radius = -1: must be > 0
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, ClassVar, Literal, Union

import numpy as np
from pydantic import (
    AfterValidator,
    Discriminator,
    Field,
    Tag,
    ValidationInfo,
    field_validator,
    model_validator,
)

from tumble import _parts, mass, meshes
from tumble.mass import MassProperties
from tumble.scenarios.schema import (
    Matrix3,
    Positive,
    Section,
    Text,
    Vector3,
    check_table,
    custom_error,
)

if TYPE_CHECKING:
    import trimesh


def _axis(value: Any) -> str | list[float]:
    if isinstance(value, str) and value in mass.AXES:
        return value
    if not isinstance(value, str | bool):
        try:
            mass.axis_vector(value)
            return np.asarray(value, dtype=float).tolist()
        except (TypeError, ValueError):
            pass
    raise custom_error("axis", 'must be "x", "y", "z" or a nonzero vector of 3 numbers')


Axis = Annotated[Any, AfterValidator(_axis)]
"""``"x"``, ``"y"``, ``"z"`` or a nonzero 3-vector."""


class _Solid(Section):
    """A primitive of :mod:`tumble.mass` and :mod:`tumble.meshes`, named by ``shape``.

    Each primitive lists its ``dimensions`` (passed first, in order) and its ``placement``
    keys; both modules take the same arguments, plus ``density`` (kg/m³) or ``mass`` (kg)
    for the mass properties.
    """

    dimensions: ClassVar[tuple[str, ...]] = ()
    placement: ClassVar[tuple[str, ...]] = ("axis", "center")
    if TYPE_CHECKING:  # each primitive declares its own Literal
        shape: str
    density: Positive | None = None
    mass: Positive | None = None
    center: Vector3 = [0.0, 0.0, 0.0]

    @model_validator(mode="after")
    def _consistent(self) -> _Solid:
        if (self.density is None) == (self.mass is None):
            given = "both" if self.density is not None else "neither"
            raise custom_error(
                "whole_amount",
                "a {shape} needs exactly one of density (kg/m³) or mass (kg); got {given}",
                shape=self.shape,
                given=given,
            )
        check_table(self.mass_properties)
        return self

    def _arguments(self) -> tuple[list, dict[str, Any]]:
        sizes = [getattr(self, name) for name in self.dimensions]
        return sizes, {name: getattr(self, name) for name in self.placement}

    def mass_properties(self) -> MassProperties:
        """Mass, centre of mass (m) and inertia (kg m²) in the description's coordinates."""
        sizes, placement = self._arguments()
        build = getattr(mass, self.shape)
        return build(*sizes, density=self.density, mass=self.mass, **placement)

    def surface(self) -> trimesh.Trimesh:
        """The closed triangle mesh, in the description's coordinates."""
        sizes, placement = self._arguments()
        return getattr(meshes, self.shape)(*sizes, **placement)

    def label(self) -> str:
        return self.shape


class Cylinder(_Solid):
    """A solid circular cylinder: ``radius`` and ``length`` (m) along ``axis``."""

    what: ClassVar[str] = "a key of a cylinder"
    dimensions: ClassVar[tuple[str, ...]] = ("radius", "length")
    shape: Literal["cylinder"]
    radius: Positive
    length: Positive
    axis: Axis = "z"


class HexPrism(_Solid):
    """A regular hexagonal prism: ``circumradius`` (= side) and ``length`` (m) along ``axis``."""

    what: ClassVar[str] = "a key of a hex_prism"
    dimensions: ClassVar[tuple[str, ...]] = ("circumradius", "length")
    shape: Literal["hex_prism"]
    circumradius: Positive
    length: Positive
    axis: Axis = "z"


class Torus(_Solid):
    """A ring torus: ``major_radius`` and ``minor_radius`` (m); ``axis`` through the hole."""

    what: ClassVar[str] = "a key of a torus"
    dimensions: ClassVar[tuple[str, ...]] = ("major_radius", "minor_radius")
    shape: Literal["torus"]
    major_radius: Positive
    minor_radius: Positive
    axis: Axis = "z"


class Sphere(_Solid):
    """A solid sphere of ``radius`` (m)."""

    what: ClassVar[str] = "a key of a sphere"
    dimensions: ClassVar[tuple[str, ...]] = ("radius",)
    placement: ClassVar[tuple[str, ...]] = ("center",)
    shape: Literal["sphere"]
    radius: Positive


class Box(_Solid):
    """A box of edge lengths ``extents`` (m), turned by ``rotation`` (3×3, body to world)."""

    what: ClassVar[str] = "a key of a box"
    dimensions: ClassVar[tuple[str, ...]] = ("extents",)
    placement: ClassVar[tuple[str, ...]] = ("rotation", "center")
    shape: Literal["box"]
    extents: Vector3
    rotation: Matrix3 | None = None


Primitive = Annotated[Cylinder | Box | Sphere | Torus | HexPrism, Field(discriminator="shape")]


class MeshBody(Section):
    """A closed triangle mesh file of uniform ``density``; its coordinates times ``scale``."""

    what: ClassVar[str] = "a key of a mesh body"
    mesh: Text
    density: Positive
    scale: Positive = 1.0

    @field_validator("mesh")
    @classmethod
    def _solid_file(cls, value: str, info: ValidationInfo) -> str:
        """Resolve ``mesh`` against the file's folder; it must be a closed, outward mesh."""
        folder = (info.context or {}).get("folder") or Path.cwd()
        path = (Path(folder) / value).resolve()
        if not path.is_file():
            raise custom_error("file", "no such file (looked for {path})", path=str(path))
        try:
            surface = meshes.validate_solid(meshes.load(path), name="the mesh")
            _parts.oriented(  # each part outward, each cavity inward
                surface.triangles, surface.faces, name="the mesh", value=value,
                fix_hint=" and save the file again",
            )  # fmt: skip
        except ValueError as error:
            raise custom_error("mesh", "{reason}", reason=str(error)) from None
        return str(path)

    @model_validator(mode="after")
    def _consistent(self) -> MeshBody:
        check_table(self.mass_properties)
        return self

    def surface(self) -> trimesh.Trimesh:
        return meshes.load(self.mesh).apply_scale(self.scale)

    def mass_properties(self) -> MassProperties:
        return meshes.from_mesh(self.surface(), density=self.density)

    def label(self) -> str:
        return f"mesh {Path(self.mesh).name}"


_KEYS = {"shape": "<primitive>", "mesh": "<mesh>", "parts": "<composite>"}
"""A body's kind, by the key that says it (the tags stay out of error messages)."""


def _kind(value: Any) -> str | None:
    if isinstance(value, dict):
        return next((tag for key, tag in _KEYS.items() if key in value), None)
    if isinstance(value, MeshBody | Composite):
        return _KEYS["mesh" if isinstance(value, MeshBody) else "parts"]
    return _KEYS["shape"] if isinstance(value, _Solid) else None


def _union(members: dict[str, Any], message: str) -> Any:
    tagged = tuple(Annotated[kind, Tag(tag)] for tag, kind in members.items())
    return Annotated[
        Union[tagged],  # noqa: UP007 - built from a tuple
        Discriminator(_kind, custom_error_type="whole_kind", custom_error_message=message),
    ]


if TYPE_CHECKING:  # what _union builds at run time: a tagged union with its own message
    Part = Cylinder | Box | Sphere | Torus | HexPrism | MeshBody
else:
    Part = _union(
        {"<primitive>": Primitive, "<mesh>": MeshBody},
        "each part needs a shape (cylinder, box, sphere, torus, hex_prism) or a mesh file",
    )


class Composite(Section):
    """Parts added by the parallel-axis theorem; ``density`` is the default of each part."""

    what: ClassVar[str] = "a key of a composite body"
    parts: Annotated[list[Part], Field(min_length=1)]
    density: Positive | None = None

    @model_validator(mode="before")
    @classmethod
    def _share_density(cls, data: Any) -> Any:
        if isinstance(data, dict) and "density" in data and isinstance(data.get("parts"), list):
            parts = [
                {**part, "density": data["density"]}
                if isinstance(part, dict) and not {"density", "mass"} & set(part)
                else part
                for part in data["parts"]
            ]
            data = {**data, "parts": parts}
        return data

    def mass_properties(self) -> MassProperties:
        first, *rest = (part.mass_properties() for part in self.parts)
        return sum(rest, first)

    def surface(self) -> trimesh.Trimesh:
        import trimesh

        return trimesh.util.concatenate([part.surface() for part in self.parts])  # type: ignore[return-value]  # trimesh annotates Geometry

    def label(self) -> str:
        return "composite (" + " + ".join(part.label() for part in self.parts) + ")"


if TYPE_CHECKING:  # as Part above
    Body = Cylinder | Box | Sphere | Torus | HexPrism | MeshBody | Composite
else:
    Body = _union(
        {"<primitive>": Primitive, "<mesh>": MeshBody, "<composite>": Composite},
        "the body needs shape (a primitive), parts (a composite) or mesh (a mesh file)",
    )


__all__ = [
    "Axis",
    "Body",
    "Box",
    "Composite",
    "Cylinder",
    "HexPrism",
    "MeshBody",
    "Part",
    "Primitive",
    "Sphere",
    "Torus",
]
