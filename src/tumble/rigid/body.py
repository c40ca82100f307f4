"""The rigid-body model: mass and inertia about the centre of mass, in body axes."""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks
from tumble.mass import MassProperties, validate_inertia, validate_mass

LARGEST = sys.float_info.max
"""The largest double, 1.8e308."""


@dataclass(frozen=True)
class RigidBody:
    """A rigid body: its mass (kg) and inertia tensor about the centre of mass (kg m²).

    Parameters
    ----------
    mass : float
        Mass in kg, > 0.
    inertia : array_like, shape (3, 3) or (3,)
        Inertia about the centre of mass in body axes; a (3,) array is the diagonal. A full
        symmetric tensor is allowed.
    allow_unphysical : bool
        Accept principal moments that violate the triangle inequality ``I_a + I_b ≥ I_c``,
        which no real mass distribution does, for mathematical test problems such as
        Hairer–Lubich–Wanner's ``diag(2, 1, 2/3)``.

    Raises
    ------
    ValueError
        If the mass is not positive, or the inertia is not symmetric positive definite, or
        (unless ``allow_unphysical``) violates the triangle inequality.

    Examples
    --------
    >>> body = RigidBody(1.0, [2.0, 1.0, 2.0 / 3.0], allow_unphysical=True)
    >>> body.inertia_inverse.diagonal()
    array([0.5, 1. , 1.5])
    """

    mass: float
    inertia: Any  # array_like, shape (3, 3) or (3,) given; a read-only (3, 3) ndarray after
    allow_unphysical: bool = False
    inertia_inverse: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        mass = validate_mass(self.mass)
        if not math.isfinite(1.0 / mass):  # v = p/m: a subnormal mass makes every velocity inf
            raise _checks.fail("mass", self.mass, f">= {1 / LARGEST:.3g} (1/mass finite)", "kg",
                               remedy="give the body in other units")  # fmt: skip
        unphysical = _checks.flag("allow_unphysical", self.allow_unphysical)
        inertia = _checks.array("inertia", self.inertia, unit="kg m²")
        if inertia.shape == (3,):
            inertia = np.diag(inertia)
        elif inertia.shape != (3, 3):
            raise _checks.fail("inertia", self.inertia,
                               "of shape (3, 3), or (3,) for the diagonal", "kg m²")  # fmt: skip
        inertia = validate_inertia(inertia, name="inertia", allow_unphysical=unphysical).copy()
        with np.errstate(over="ignore"):
            inverse = np.linalg.inv(inertia)
        if np.count_nonzero(np.isfinite(inverse)) != 9:  # ω = I⁻¹ L: subnormal moments
            raise _checks.fail(
                "inertia", inertia.tolist(), "principal moments whose inverses are finite",
                "kg m²", remedy=f"I⁻¹ overflows past {LARGEST:.2g}; give the body in other units",
            )  # fmt: skip
        inertia.setflags(write=False)
        inverse.setflags(write=False)
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "inertia", inertia)
        object.__setattr__(self, "allow_unphysical", unphysical)
        object.__setattr__(self, "inertia_inverse", inverse)

    @classmethod
    def from_mass_properties(cls, properties: MassProperties) -> RigidBody:
        """The body with the mass and inertia (about its centre of mass) of ``properties``."""
        return cls(
            properties.mass,
            properties.inertia,
            allow_unphysical=getattr(properties, "allow_unphysical", False),
        )

    def angular_velocity(self, R: ArrayLike, L: ArrayLike) -> np.ndarray:
        """Body-frame angular velocity ``ω_body = I⁻¹ Rᵀ L`` (rad/s)."""
        return self.inertia_inverse @ (np.asarray(R).T @ np.asarray(L))
