"""Rigid-body dynamics: the model, its loads, the methods and ``simulate``.

=========================  ===================================================================
:class:`RigidBody`         mass and inertia about the centre of mass (body axes)
:func:`simulate`           one entry point for every method; returns a :class:`Trajectory`
:func:`simulate_batch`     many bodies in one compiled, parallel call; a :class:`BatchTrajectory`
:class:`Gravity` …         loads: :class:`Force`, :class:`Torque`, :class:`MagneticDipole`,
                           :class:`GravityGradient`, :class:`Impulse`
:data:`METHODS`            every method by name (the table: :mod:`tumble.rigid.methods`)
:func:`flip_event`         an event at each flip of an intermediate-axis spin
=========================  ===================================================================
"""

from tumble.rigid.batch import BatchTrajectory, simulate_batch
from tumble.rigid.body import RigidBody
from tumble.rigid.events import flip_event
from tumble.rigid.forces import (
    GM_EARTH,
    Force,
    Gravity,
    GravityGradient,
    Impulse,
    MagneticDipole,
    State,
    Torque,
)
from tumble.rigid.methods import METHODS, Method
from tumble.rigid.simulation import simulate
from tumble.rigid.trajectory import Trajectory

__all__ = [
    "GM_EARTH",
    "METHODS",
    "BatchTrajectory",
    "Force",
    "Gravity",
    "GravityGradient",
    "Impulse",
    "MagneticDipole",
    "Method",
    "RigidBody",
    "State",
    "Torque",
    "Trajectory",
    "flip_event",
    "simulate",
    "simulate_batch",
]
