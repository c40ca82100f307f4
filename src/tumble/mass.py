"""Mass properties: mass, centre of mass and inertia tensor, primitives and composites.

Units are SI (kg, m, kg m²). A :class:`MassProperties` holds the inertia tensor about its
own centre of mass, in the axes of the frame its ``com`` is given in. Primitives are solids
of uniform density, built from ``density=`` (kg/m³) or ``mass=`` (kg), placed at ``center``
with their symmetry ``axis`` along "x", "y", "z" or any vector. Composites add by the
parallel-axis theorem: ``handle + shaft``. The mass properties of a closed
triangle mesh are :func:`tumble.meshes.from_mesh`.

Inertia formulas (``m`` the mass, about the centre of mass; standard closed forms):

=================  ==========================  ==================================
solid              about the axis              about a perpendicular (diameter)
=================  ==========================  ==================================
cylinder a, L      m a² / 2                    m (3 a² + L²) / 12
hex prism a, L     5 m a² / 12                 m (5 a² / 24 + L² / 12)
torus R, r         m (R² + 3 r² / 4)           m (R² / 2 + 5 r² / 8)
sphere a           2 m a² / 5                  2 m a² / 5
box (a, b, c)      I_x = m (b² + c²) / 12      and cyclically: I_y, I_z
=================  ==========================  ==================================

The hexagonal prism (circumradius ``a`` = side) follows from six equilateral triangles:
polar moment per area ``a²/12 + (a/√3)² = 5a²/12``; a regular hexagon is isotropic in its
plane, so half of that about any in-plane axis.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tumble import _checks, so3
from tumble.so3 import validate_rotation

SYMMETRY_RTOL = 1e-9
"""Allowed ‖I − Iᵀ‖ relative to max ‖I‖ before an inertia is refused as not symmetric."""
TRIANGLE_RTOL = 1e-9
"""Allowed violation of I_a + I_b >= I_c, relative to the largest principal moment."""
AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}

Array = NDArray[np.float64]


def validate_mass(mass: float, name: str = "mass") -> float:
    """Return ``mass`` (kg) as a float, or raise ValueError unless finite and > 0.

    Examples
    --------
    >>> validate_mass(0.25)
    0.25
    """
    return _checks.positive(name, mass, "kg")


def validate_inertia(
    inertia: ArrayLike, *, name: str = "inertia", allow_unphysical: bool = False
) -> Array:
    """Check an inertia tensor and return a symmetrised float copy.

    Accepted: shape (3, 3), finite, symmetric (to ``SYMMETRY_RTOL``), positive definite,
    and, unless ``allow_unphysical``, principal moments obeying the triangle inequality
    ``I_a + I_b >= I_c`` (to ``TRIANGLE_RTOL``), which every real mass distribution does.

    Parameters
    ----------
    inertia : array_like, shape (3, 3)
        Inertia tensor (kg m²).
    name : str
        Argument name used in error messages.
    allow_unphysical : bool
        Skip the triangle inequality, for mathematical test bodies such as
        diag(2, 1, 2/3) (Hairer, Lubich & Wanner).

    Returns
    -------
    ndarray, shape (3, 3)

    Raises
    ------
    ValueError
        Naming ``name``, the value and what is allowed.

    Examples
    --------
    >>> validate_inertia(np.diag([2.0, 1.0, 2 / 3]), allow_unphysical=True).shape
    (3, 3)
    """
    value = _checks.array(name, inertia, shape=(3, 3), unit="kg m²")
    scale = np.max(np.abs(value))
    if np.max(np.abs(value - value.T)) > SYMMETRY_RTOL * scale:
        raise _checks.fail(name, value.tolist(), "symmetric", "kg m²")
    value = 0.5 * value + 0.5 * value.T  # (not (I + Iᵀ)/2: it overflows past 9e307)
    if scale == 0.0:
        raise _checks.fail(name, value.tolist(), "positive definite", "kg m²",
                           "its principal moments are [0.0, 0.0, 0.0]")  # fmt: skip
    moments = np.linalg.eigvalsh(value / scale) * scale  # scaled: LAPACK fails past ~1e154
    if moments[0] <= 0.0:
        raise _checks.fail(
            name,
            value.tolist(),
            "positive definite",
            "kg m²",
            f"its principal moments are {moments.tolist()}",
        )
    if not allow_unphysical and moments[0] < moments[2] * (1 - TRIANGLE_RTOL) - moments[1]:
        raise _checks.fail(
            name,
            value.tolist(),
            "within the triangle inequality I_a + I_b >= I_c of its principal moments",
            "kg m²",
            f"its principal moments are {moments.tolist()}, and no real body has this "
            "inertia; for a mathematical test body pass allow_unphysical=True",
        )
    return value


def axis_vector(axis: str | ArrayLike, *, name: str = "axis") -> Array:
    """Unit vector of ``"x"``, ``"y"``, ``"z"`` or any nonzero 3-vector.

    Examples
    --------
    >>> axis_vector([0.0, 0.0, 2.0])
    array([0., 0., 1.])
    """
    allowed = '"x", "y", "z" or a finite nonzero 3-vector'
    if isinstance(axis, str):
        if axis not in AXES:
            raise _checks.fail(name, axis, allowed)
        return np.array(AXES[axis])
    try:
        vector = _checks.array(name, axis, shape=(3,))
    except ValueError:
        raise _checks.fail(name, axis, allowed) from None
    largest = float(np.max(np.abs(vector)))
    if largest == 0.0:
        raise _checks.fail(name, axis, allowed)
    vector = vector / largest  # |v|² of [1e308, 1e308, 0] would overflow
    return vector / np.linalg.norm(vector)


def rotation_matrix(value: ArrayLike, name: str) -> Array:
    """``value`` as one rotation matrix (3, 3) (a single scipy ``Rotation`` too), checked."""
    R = _checks.array(name, so3.from_scipy(value, name, single=True), shape=(3, 3))
    return validate_rotation(R, name=name)


def validate_point(value: ArrayLike, *, name: str) -> Array:
    """Return ``value`` as a float 3-vector, or raise ValueError unless it is finite.

    Examples
    --------
    >>> validate_point([0, 0, 1], name="center")
    array([0., 0., 1.])
    """
    return _checks.array(name, value, shape=(3,), unit="m")


def _read_only(array: Array) -> Array:
    array = np.array(array, dtype=float)
    array.flags.writeable = False
    return array


def _shift(mass: float, offset: Array) -> Array:
    """Parallel-axis term m (|d|² I - d dᵀ)."""
    return mass * (offset @ offset * np.eye(3) - np.outer(offset, offset))


@dataclass(frozen=True, eq=False)
class MassProperties:
    """Mass, centre of mass and inertia about the centre of mass; immutable.

    Parameters
    ----------
    mass : float
        Mass (kg), > 0.
    com : array_like, shape (3,)
        Centre of mass (m).
    inertia : array_like, shape (3, 3)
        Inertia tensor about ``com`` (kg m²), checked by :func:`validate_inertia`.
    allow_unphysical : bool
        Accept an inertia that violates the triangle inequality.

    Examples
    --------
    >>> body = MassProperties(2.0, [0.0, 0.0, 1.0], np.eye(3))
    >>> body.inertia_about([0.0, 0.0, 0.0]).diagonal()
    array([3., 3., 1.])
    """

    mass: float
    com: Array
    inertia: Array
    allow_unphysical: bool = field(default=False, kw_only=True)

    def __post_init__(self) -> None:
        unphysical = _checks.flag("allow_unphysical", self.allow_unphysical)
        inertia = validate_inertia(self.inertia, allow_unphysical=unphysical)
        object.__setattr__(self, "mass", validate_mass(self.mass))
        object.__setattr__(self, "com", _read_only(validate_point(self.com, name="com")))
        object.__setattr__(self, "inertia", _read_only(inertia))

    def __add__(self, other: MassProperties) -> MassProperties:
        """Composite body: masses add, ``com`` is the mass-weighted mean, inertias add
        about the common ``com`` by the parallel-axis theorem ``I + m (|d|² 1 - d dᵀ)``."""
        if not isinstance(other, MassProperties):
            return NotImplemented
        mass = self.mass + other.mass
        com = (self.mass * self.com + other.mass * other.com) / mass
        inertia = self.inertia_about(com) + other.inertia_about(com)
        unphysical = self.allow_unphysical or other.allow_unphysical
        return MassProperties(mass, com, inertia, allow_unphysical=unphysical)

    def __radd__(self, other: object) -> MassProperties:
        """Support ``sum(parts)``, which starts from 0."""
        if isinstance(other, int) and other == 0:
            return self
        return NotImplemented

    def translated(self, offset: ArrayLike) -> MassProperties:
        """The same body moved by ``offset`` (m); the inertia about the com is unchanged."""
        offset = validate_point(offset, name="offset")
        return MassProperties(
            self.mass, self.com + offset, self.inertia, allow_unphysical=self.allow_unphysical
        )

    def rotated(self, rotation: ArrayLike) -> MassProperties:
        """The body rotated about the origin: ``com -> R com``, ``I -> R I Rᵀ``."""
        R = rotation_matrix(rotation, "rotation")
        return MassProperties(
            self.mass, R @ self.com, R @ self.inertia @ R.T, allow_unphysical=self.allow_unphysical
        )

    def inertia_about(self, point: ArrayLike) -> Array:
        """Inertia (kg m²) about ``point``: ``I + m (|d|² 1 - d dᵀ)``, ``d = com - point``."""
        d = self.com - validate_point(point, name="point")
        with np.errstate(over="ignore", invalid="ignore"):
            inertia = self.inertia + _shift(self.mass, d)
        if np.count_nonzero(np.isfinite(inertia)) != 9:
            raise _checks.fail("point", point, "a point whose inertia about it is finite", "m",
                               remedy="m |d|² overflows past 1.8e308")  # fmt: skip
        return inertia

    def principal(self) -> tuple[Array, Array]:
        """Principal moments (ascending, kg m²) and axes (columns, right-handed).

        ``inertia == axes @ diag(moments) @ axes.T`` and ``det(axes) == +1``.

        Examples
        --------
        >>> moments, axes = MassProperties(1.0, [0, 0, 0], np.diag([3.0, 1.0, 2.0])).principal()
        >>> moments
        array([1., 2., 3.])
        """
        moments, axes = np.linalg.eigh(self.inertia)
        axes[:, 2] *= np.sign(np.linalg.det(axes))
        return moments, axes


def _mass(volume: float, density: float | None, mass: float | None) -> float:
    one = "give exactly one of density= (kg/m³) or mass= (kg)"
    if density is None and mass is None:
        raise _checks.fail("density", None, "a number when mass is not given", remedy=one)
    if density is not None and mass is not None:
        raise _checks.fail("density", density, "None when mass is given", remedy=one)
    if mass is not None:
        return validate_mass(mass)
    return _checks.positive("density", density, "kg/m³") * volume


@contextmanager
def _sized(
    density: float | None, mass: float | None, **sizes: float
) -> Iterator[Callable[..., None]]:
    """Compute a primitive inside: ``check(m, *moments)`` refuses a mass or moment that is not
    a finite float > 0 (an overflow, or an underflow to 0), and so is Python's OverflowError
    (``a**3`` past 1.8e308), naming the argument furthest from 1 (a size, the density or the
    mass) and the others."""
    _mass(1.0, density, mass)  # refuses a bad density or mass first, by its own name
    arguments = {name: (value, "m") for name, value in sizes.items()}
    if mass is None:
        arguments["density"] = (_checks.positive("density", density), "kg/m³")
    else:
        arguments["mass"] = (validate_mass(mass), "kg")

    def refuse(what: str) -> ValueError:
        name = max(arguments, key=lambda key: abs(math.log(arguments[key][0])))
        others = [f"{key}={v!r} {unit}" for key, (v, unit) in arguments.items() if key != name]
        given = ", ".join(others[:-1]) + " and " * (len(others) > 1) + others[-1]
        allowed = "such that the mass and the moments of inertia are finite and > 0"
        remedy = f"with {given} {what}; give the body in other units"
        return _checks.fail(name, arguments[name][0], allowed, arguments[name][1], remedy)

    def check(m: float, *moments: float) -> None:
        if math.isnan(m):
            raise refuse("a part's mass or moment of inertia is not a float > 0")
        if not 0 < m < math.inf:
            raise refuse(f"the mass is {m:g} kg")
        for moment in moments:
            if not 0 < moment < math.inf:
                raise refuse(f"a moment of inertia is {moment:g} kg m²")

    try:
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            yield check
    except OverflowError:
        raise refuse("they overflow a float (past 1.8e308)") from None


def _axisymmetric(
    mass: float, about_axis: float, about_diameter: float, axis: str | ArrayLike, center: ArrayLike
) -> MassProperties:
    """Body with inertia ``I_d (1 - n nᵀ) + I_a n nᵀ`` about its symmetry axis ``n``."""
    n = axis_vector(axis)
    along = np.outer(n, n)
    inertia = about_diameter * (np.eye(3) - along) + about_axis * along
    return MassProperties(mass, validate_point(center, name="center"), inertia)


def cylinder(
    radius: float,
    length: float,
    *,
    density: float | None = None,
    mass: float | None = None,
    axis: str | ArrayLike = "z",
    center: ArrayLike = (0.0, 0.0, 0.0),
) -> MassProperties:
    """Solid circular cylinder: ``m = ρ π a² L``, ``I_axis = m a²/2``,
    ``I_diameter = m (3a² + L²)/12``.

    Parameters
    ----------
    radius, length : float
        Radius ``a`` and length ``L`` (m), > 0.
    density, mass : float, optional
        Exactly one: density (kg/m³) or total mass (kg).
    axis : {"x", "y", "z"} or array_like, shape (3,)
        Direction of the cylinder axis.
    center : array_like, shape (3,)
        Centre of mass (m).

    Returns
    -------
    MassProperties

    Examples
    --------
    >>> cylinder(1.0, 2.0, mass=1.0).inertia.diagonal()
    array([0.58333333, 0.58333333, 0.5       ])
    """
    a = _checks.positive("radius", radius, "m")
    L = _checks.positive("length", length, "m")
    with _sized(density, mass, radius=a, length=L) as check:
        m = _mass(np.pi * a**2 * L, density, mass)
        about_axis, about_diameter = m * a**2 / 2, m * (3 * a**2 + L**2) / 12
        check(m, about_axis, about_diameter)
    return _axisymmetric(m, about_axis, about_diameter, axis, center)


def hex_prism(
    circumradius: float,
    length: float,
    *,
    density: float | None = None,
    mass: float | None = None,
    axis: str | ArrayLike = "z",
    center: ArrayLike = (0.0, 0.0, 0.0),
) -> MassProperties:
    """Solid regular hexagonal prism: ``m = ρ (3√3/2) a² L``, ``I_axis = 5 m a²/12``,
    ``I_diameter = m (5a²/24 + L²/12)`` (``a`` circumradius = side; module docstring).

    Parameters are those of :func:`cylinder` with ``circumradius`` for ``radius``; the
    inertia does not depend on how the hexagon is turned about its axis.

    Examples
    --------
    >>> hex_prism(1.0, 1.0, mass=12.0).inertia.diagonal()
    array([3.5, 3.5, 5. ])
    """
    a = _checks.positive("circumradius", circumradius, "m")
    L = _checks.positive("length", length, "m")
    with _sized(density, mass, circumradius=a, length=L) as check:
        m = _mass(1.5 * np.sqrt(3.0) * a**2 * L, density, mass)
        about_axis, about_diameter = 5 * m * a**2 / 12, m * (5 * a**2 / 24 + L**2 / 12)
        check(m, about_axis, about_diameter)
    return _axisymmetric(m, about_axis, about_diameter, axis, center)


def validate_torus_radii(major_radius: float, minor_radius: float) -> tuple[float, float]:
    """``(R, r)`` of a ring torus: both positive and ``r < R``; else a ValueError naming them."""
    R = _checks.positive("major_radius", major_radius, "m")
    r = _checks.positive("minor_radius", minor_radius, "m")
    if r >= R:
        raise _checks.fail(
            "minor_radius", minor_radius, f"less than major_radius={R!r} for a ring torus", "m"
        )
    return R, r


def torus(
    major_radius: float,
    minor_radius: float,
    *,
    density: float | None = None,
    mass: float | None = None,
    axis: str | ArrayLike = "z",
    center: ArrayLike = (0.0, 0.0, 0.0),
) -> MassProperties:
    """Solid ring torus: ``m = ρ 2π² R r²``, ``I_axis = m (R² + 3r²/4)``,
    ``I_diameter = m (R²/2 + 5r²/8)``.

    Parameters
    ----------
    major_radius, minor_radius : float
        Tube-centre radius ``R`` and tube radius ``r`` (m), ``0 < r < R``.
    density, mass, axis, center
        As in :func:`cylinder`; ``axis`` is the symmetry axis through the hole.

    Examples
    --------
    >>> np.round(torus(1.0, 0.5, density=1.0).inertia.diagonal(), 6)
    array([3.238464, 3.238464, 5.860078])
    """
    R, r = validate_torus_radii(major_radius, minor_radius)
    with _sized(density, mass, major_radius=R, minor_radius=r) as check:
        m = _mass(2 * np.pi**2 * R * r**2, density, mass)
        about_axis, about_diameter = m * (R**2 + 0.75 * r**2), m * (R**2 / 2 + 5 * r**2 / 8)
        check(m, about_axis, about_diameter)
    return _axisymmetric(m, about_axis, about_diameter, axis, center)


def sphere(
    radius: float,
    *,
    density: float | None = None,
    mass: float | None = None,
    center: ArrayLike = (0.0, 0.0, 0.0),
) -> MassProperties:
    """Solid sphere: ``m = ρ 4π a³/3``, ``I = 2 m a²/5`` about every axis.

    Examples
    --------
    >>> sphere(1.0, mass=5.0).inertia.diagonal()
    array([2., 2., 2.])
    """
    a = _checks.positive("radius", radius, "m")
    with _sized(density, mass, radius=a) as check:
        m = _mass(4 * np.pi * a**3 / 3, density, mass)
        moment = 0.4 * m * a**2
        check(m, moment)
    return _axisymmetric(m, moment, moment, "z", center)


def box(
    extents: ArrayLike,
    *,
    density: float | None = None,
    mass: float | None = None,
    rotation: ArrayLike | None = None,
    center: ArrayLike = (0.0, 0.0, 0.0),
) -> MassProperties:
    """Solid rectangular box: ``m = ρ a b c``, ``I_x = m (b² + c²)/12`` and cyclically.

    A box has no symmetry axis, so it takes a ``rotation`` (body-to-world matrix, default
    identity) instead of ``axis``: the inertia is ``R diag(I_x, I_y, I_z) Rᵀ``.

    Parameters
    ----------
    extents : array_like, shape (3,)
        Edge lengths ``(a, b, c)`` (m) along the box's x, y, z, each > 0.

    Examples
    --------
    >>> box([1.0, 2.0, 3.0], mass=12.0).inertia.diagonal()
    array([13., 10.,  5.])
    """
    sides = _checks.array("extents", extents, shape=(3,), unit="m", positive=True)
    sizes = {f"extents[{i}]": float(side) for i, side in enumerate(sides)}
    with _sized(density, mass, **sizes) as check:
        m = _mass(float(np.prod(sides)), density, mass)
        squares = sides**2
        moments = m * (squares.sum() - squares) / 12
        check(m, *moments)
    body = MassProperties(m, np.zeros(3), np.diag(moments))
    if rotation is not None:
        body = body.rotated(rotation)
    return body.translated(center)


def t_handle(
    *,
    handle_radius: float = 0.01,
    handle_length: float = 0.08,
    shaft_radius: float = 0.01,
    shaft_length: float = 0.04,
    density: float = 6700.0,
) -> MassProperties:
    """The T-handle of seed 002: two solid cylinders, centre of mass at the origin.

    The handle (axis y) lies on the side x < 0 touching the plane x = 0; the shaft (axis x)
    runs from x = 0 to x = ``shaft_length``; the whole is shifted so that its centre of mass
    is the origin. With the defaults (1 cm, 8 cm, 1 cm, 4 cm, 6700 kg/m³) the shift is zero:
    handle centre x = −1 cm, shaft centre x = +2 cm, and the inertia is seed 002's
    diag(9.82271303e-05, 7.22671030e-05, 1.57865031e-04) kg m².

    Examples
    --------
    >>> body = t_handle()
    >>> round(body.mass, 7), np.allclose(body.com, 0.0)
    (0.252584, True)
    """
    sizes = {"handle_radius": handle_radius, "handle_length": handle_length,
             "shaft_radius": shaft_radius, "shaft_length": shaft_length}  # fmt: skip
    for name, value in sizes.items():
        sizes[name] = _checks.positive(name, value, "m")
    density = _checks.positive("density", density, "kg/m³")
    with _sized(density, None, **sizes) as check:
        try:
            handle = cylinder(sizes["handle_radius"], sizes["handle_length"], density=density,
                              axis="y", center=(-sizes["handle_radius"], 0, 0))  # fmt: skip
            shaft = cylinder(sizes["shaft_radius"], sizes["shaft_length"], density=density,
                             axis="x", center=(sizes["shaft_length"] / 2, 0, 0))  # fmt: skip
            body = handle + shaft
        except ValueError:  # a part's mass or moment is not a float: named as t_handle's
            check(math.nan)
        check(body.mass, *np.linalg.eigvalsh(body.inertia))
    return body.translated(-body.com)
