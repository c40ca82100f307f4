"""tumble — rigid bodies and vibrating structures with integrators that keep the physics.

Conventions (SPEC §2): SI units; ``R`` maps body to world (``r_world = x_cm + R r_body``);
quaternions are scalar-first ``[w, x, y, z]`` with the Hamilton product; inertia is about the
centre of mass in body axes; ``L`` is the world angular momentum, ``ω_body = I⁻¹ Rᵀ L``;
ZYX Euler angles ``R = Rz(φ) Ry(θ) Rx(ψ)``.

==================================  ==========================================================
ODE core
:func:`solve`                       integrate ``y' = f(t, y)`` (tableaux, step control, events)
:class:`Status`                     how a run ended: every result carries one
:class:`ButcherTableau`             a Runge–Kutta method as data
Rigid bodies
:class:`RigidBody`                  mass and inertia about the centre of mass
:func:`simulate`                    every rigid-body method through one entry point
:class:`Gravity`, :class:`Force`    loads (also :class:`Torque`, :class:`MagneticDipole`,
                                    :class:`GravityGradient`, :class:`Impulse`)
:class:`Trajectory`                 what ``simulate`` returns
:func:`simulate_batch`              many bodies at once (compiled, parallel); a
                                    :class:`BatchTrajectory`
Sweeps
:func:`sweep`                       one scenario over a grid of options, on Dask, into one
                                    Zarr store (resumable)
Modules
:mod:`tumble.so3`                   rotations: exp/log, dexp, quaternions, Euler angles
:mod:`tumble.mass`                  mass properties: primitives, composites
:mod:`tumble.meshes`                trimesh meshes of the same shapes; a mesh's mass properties
:mod:`tumble.exact`                 exact references: sphere, projectile, free body
:mod:`tumble.structural`            finite-element beams and their time-stepping schemes
:func:`report`                      the integrator report card: every method measured
==================================  ==========================================================

Every submodule and name here is imported on first use (PEP 562), so ``import tumble`` is
quick and loads neither numba nor trimesh, xarray or plotly.
"""

from __future__ import annotations

import importlib
import logging
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # what static type checkers see; at run time __getattr__ imports on demand
    from tumble import exact, mass, meshes, so3, structural
    from tumble import io as io
    from tumble import ode as ode
    from tumble import rigid as rigid
    from tumble import scenarios as scenarios
    from tumble import sweeps as sweeps
    from tumble import viz as viz
    from tumble._version import __version__ as __version__
    from tumble.ode import ButcherTableau, OdeResult, Status, solve
    from tumble.report_card import report as report
    from tumble.rigid import (
        METHODS,
        BatchTrajectory,
        Force,
        Gravity,
        GravityGradient,
        Impulse,
        MagneticDipole,
        RigidBody,
        Torque,
        Trajectory,
        simulate,
        simulate_batch,
    )
    from tumble.sweeps import sweep

# The library never prints: it logs, and stays silent unless the application configures logging.
logging.getLogger(__name__).addHandler(logging.NullHandler())

__all__ = [
    "BatchTrajectory",
    "ButcherTableau",
    "Force",
    "Gravity",
    "GravityGradient",
    "Impulse",
    "MagneticDipole",
    "METHODS",
    "OdeResult",
    "RigidBody",
    "Status",
    "Torque",
    "Trajectory",
    "exact",
    "mass",
    "meshes",
    "simulate",
    "simulate_batch",
    "so3",
    "solve",
    "report",
    "structural",
    "sweep",
]

_SUBMODULES = frozenset(
    {
        "exact",
        "io",
        "mass",
        "meshes",
        "ode",
        "rigid",
        "scenarios",
        "so3",
        "structural",
        "sweeps",
        "viz",
    }
)
"""Modules reachable as ``tumble.<name>`` after a bare ``import tumble``."""
_NAMES = {
    **dict.fromkeys(["ButcherTableau", "OdeResult", "Status", "solve"], "tumble.ode"),
    **dict.fromkeys(
        [
            "METHODS",
            "BatchTrajectory",
            "Force",
            "Gravity",
            "GravityGradient",
            "Impulse",
            "MagneticDipole",
            "RigidBody",
            "Torque",
            "Trajectory",
            "simulate",
            "simulate_batch",
        ],
        "tumble.rigid",
    ),
    "report": "tumble.report_card",
    "sweep": "tumble.sweeps",
    "__version__": "tumble._version",
}
"""Each public name and the module it comes from."""


def __getattr__(name: str) -> Any:
    """Import the submodule or public name ``name`` on first use, then keep it (PEP 562)."""
    if name in _SUBMODULES:
        value = importlib.import_module(f"{__name__}.{name}")
    elif name in _NAMES:
        value = getattr(importlib.import_module(_NAMES[name]), name)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The module's attributes, the ones not yet imported included."""
    return sorted({*globals(), *_SUBMODULES, *_NAMES})
