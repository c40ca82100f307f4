"""A body turning about a fixed point (the heavy top), as a free body about that point.

A body whose point ``r`` (body coordinates, from the centre of mass) is held fixed in space
turns about it with the inertia taken there, by the parallel-axis theorem,

.. math:: I_p = I + m\\,(|r|^2\\,\\mathbb{1} - r r^T),

and its angular momentum about the pivot obeys ``L̇_p = τ_p``, the loads' torque about the
pivot; the centre of mass follows, ``x = x_p − R r`` and ``v = ω × (x − x_p)``. So the run is
the free-body machinery of every method on a reduced body (mass ``m``, inertia ``I_p``)
whose origin is the pivot: each load becomes the same force at its point measured from the
pivot (gravity acts at ``−r``), plus the pivot's reaction, an equal and opposite force at the
pivot, which keeps the reduced body's origin in place and adds no torque. Impulses get their
reaction impulse the same way.

References
----------
.. [1] L. D. Landau, E. M. Lifshitz, *Mechanics*, 3rd ed., §35 (the heavy symmetric top).
.. [2] H. Goldstein, C. Poole, J. Safko, *Classical Mechanics*, 3rd ed., §5.7.
"""

from __future__ import annotations

import numpy as np

from tumble import _checks
from tumble.rigid.body import RigidBody
from tumble.rigid.forces import (
    Force,
    Gravity,
    GravityGradient,
    Impulse,
    MagneticDipole,
    Torque,
)


def pivot_body(body: RigidBody, pivot: np.ndarray) -> RigidBody:
    """The body with its inertia about ``pivot`` (parallel-axis theorem); a pivot so far out
    that ``m |r|²`` overflows is refused, naming it."""
    with np.errstate(over="ignore", invalid="ignore"):
        shift = body.mass * (pivot @ pivot * np.eye(3) - np.outer(pivot, pivot))
        inertia = body.inertia + shift
    if np.count_nonzero(np.isfinite(inertia)) != 9:
        raise _checks.fail(
            "pivot", pivot.tolist(), "a point whose inertia about it is finite", "m",
            remedy=f"m |r|² = {body.mass:.3g} kg × ({float(np.max(np.abs(pivot))):.3g} m)² "
            "overflows past 1.8e308 kg m²; give the body in other units",
        )  # fmt: skip
    return RigidBody(body.mass, inertia, allow_unphysical=True)


def pivot_forces(forces, mass: float, pivot: np.ndarray, x_pivot: np.ndarray) -> list:
    """The loads and impulses of the reduced body: each at its point from the pivot, with the
    pivot's reaction. Callable loads are refused (their state would be the reduced body's)."""
    reduced: list = []
    for index, item in enumerate(forces):
        if isinstance(item, Gravity):
            F = mass * item.g
            reduced += [Force(F, point=-pivot), Force(-F)]
        elif isinstance(item, Force):
            if callable(item.force):
                raise _checks.fail(
                    f"forces[{index}]", item, "a constant load with a pivot",
                    remedy="a callable force would see the reduced body's state; give a "
                    "constant force, or simulate the free body",
                )  # fmt: skip
            point = np.zeros(3) if item.point is None else item.point
            reduced += [Force(item.force, point=point - pivot), Force(-item.force)]
        elif isinstance(item, Torque | MagneticDipole):
            if isinstance(item, Torque) and callable(item.torque):
                raise _checks.fail(
                    f"forces[{index}]", item, "a constant load with a pivot",
                    remedy="give a constant torque, or simulate the free body",
                )  # fmt: skip
            reduced.append(item)
        elif isinstance(item, GravityGradient):
            raise _checks.fail(
                f"forces[{index}]", item, "a load other than GravityGradient with a pivot",
                remedy="its expansion is about the centre of mass, not the pivot; simulate "
                "the free body",
            )  # fmt: skip
        elif isinstance(item, Impulse):
            reduced += [item, Impulse(x_pivot, -item.impulse, item.time)]
        else:
            reduced.append(item)  # split_loads names what is not a load
    return reduced


def centre_of_mass_motion(
    body: RigidBody, reduced: RigidBody, pivot: np.ndarray, x_pivot: np.ndarray,
    R: np.ndarray, L_pivot: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """``(x, v, L)`` of the centre of mass from the reduced run's samples: ``x = x_p − R r``,
    ``v = ω × (x − x_p)`` and the momentum about the centre of mass
    ``L = L_p − m (x − x_p) × v``."""
    arm = -np.einsum("nij,j->ni", R, pivot)  # x − x_p, world
    omega_body = np.einsum("ij,nkj,nk->ni", reduced.inertia_inverse, R, L_pivot)
    omega_world = np.einsum("nij,nj->ni", R, omega_body)
    v = np.cross(omega_world, arm)
    return x_pivot + arm, v, L_pivot - body.mass * np.cross(arm, v)
