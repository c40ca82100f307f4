"""tumble — rigid bodies and vibrating structures with integrators that keep the physics.

Conventions (SPEC §2): SI units; ``R`` maps body to world (``r_world = x_cm + R r_body``);
quaternions are scalar-first ``[w, x, y, z]`` with the Hamilton product; inertia is about the
centre of mass in body axes; ``L`` is the world angular momentum, ``ω_body = I⁻¹ Rᵀ L``;
ZYX Euler angles ``R = Rz(φ) Ry(θ) Rx(ψ)``.

==================================  ==========================================================
ODE core
:func:`solve`                       integrate ``y' = f(t, y)`` (tableaux, step control, events)
:class:`ButcherTableau`             a Runge–Kutta method as data
Rigid bodies
:class:`RigidBody`                  mass and inertia about the centre of mass
:func:`simulate`                    every rigid-body method through one entry point
:class:`Gravity`, :class:`Force`    loads (also :class:`Torque`, :class:`Impulse`)
:class:`Trajectory`                 what ``simulate`` returns
:func:`simulate_batch`              many bodies at once (compiled, parallel); a
                                    :class:`BatchTrajectory`
Modules
:mod:`tumble.so3`                   rotations: exp/log, dexp, quaternions, Euler angles
:mod:`tumble.mass`                  mass properties: primitives, composites, meshes
:mod:`tumble.meshes`                trimesh meshes of the same shapes
:mod:`tumble.exact`                 exact references: sphere, projectile, free body
:mod:`tumble.structural`            finite-element beams and their time-stepping schemes
==================================  ==========================================================
"""

import logging

from tumble import exact, mass, meshes, so3, structural
from tumble._version import __version__ as __version__
from tumble.ode import ButcherTableau, OdeResult, solve
from tumble.rigid import (
    METHODS,
    BatchTrajectory,
    Force,
    Gravity,
    Impulse,
    RigidBody,
    Torque,
    Trajectory,
    simulate,
    simulate_batch,
)

# The library never prints: it logs, and stays silent unless the application configures logging.
logging.getLogger(__name__).addHandler(logging.NullHandler())

__all__ = [
    "METHODS",
    "BatchTrajectory",
    "ButcherTableau",
    "Force",
    "Gravity",
    "Impulse",
    "OdeResult",
    "RigidBody",
    "Torque",
    "Trajectory",
    "exact",
    "mass",
    "meshes",
    "simulate",
    "simulate_batch",
    "so3",
    "solve",
    "structural",
]
