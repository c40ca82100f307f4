"""Trajectory ↔ xarray.Dataset (xarray imported only here)."""

from __future__ import annotations

import json

import numpy as np


def trajectory_dataset(trajectory):
    """Build the dataset: every array with its dimensions, units and the run's settings."""
    import xarray as xr

    from tumble._version import __version__

    vec, mat = ("time", "axis"), ("time", "row", "col")
    variables = {
        "x": (vec, trajectory.x, "m", "centre of mass, world frame"),
        "v": (vec, trajectory.v, "m/s", "velocity of the centre of mass, world frame"),
        "R": (mat, trajectory.R, "1", "attitude, body to world"),
        "q": (("time", "component"), trajectory.q, "1", "unit quaternion [w, x, y, z]"),
        "omega_body": (vec, trajectory.omega_body, "rad/s", "angular velocity, body frame"),
        "L_world": (vec, trajectory.L_world, "kg m2/s", "angular momentum, world frame"),
        "energy": (("time",), trajectory.energy, "J", "total energy T + V"),
        "kinetic_energy": (("time",), trajectory.kinetic_energy, "J", "kinetic energy"),
        "potential_energy": (("time",), trajectory.potential_energy, "J", "potential energy"),
        "orthogonality_error": (("time",), trajectory.orthogonality_error, "1", "|RᵀR − I|_F"),
    }
    data_vars = {
        name: xr.Variable(dims, values, attrs={"units": units, "long_name": text})
        for name, (dims, values, units, text) in variables.items()
    }
    settings = {k: v for k, v in trajectory.settings.items() if v is not None}
    attrs = {
        "method": trajectory.method,
        "mass": trajectory.body.mass,
        "inertia": np.asarray(trajectory.body.inertia).ravel(),
        "settings": json.dumps(settings),
        "status": trajectory.status,
        "message": trajectory.message,
        "tumble_version": __version__,
    }
    coords = {
        "time": ("time", trajectory.t, {"units": "s"}),
        "axis": ["x", "y", "z"],
        "component": ["w", "x", "y", "z"],
    }
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def trajectory_from_dataset(dataset):
    """The :class:`~tumble.rigid.Trajectory` a :func:`trajectory_dataset` was made from.

    Times, states, the body (mass, inertia), method, settings, status and message come back;
    step counts and event times are not stored.
    """
    from tumble.rigid.body import RigidBody
    from tumble.rigid.trajectory import Trajectory

    attrs = dataset.attrs
    inertia = np.asarray(attrs["inertia"], dtype=float).reshape(3, 3)
    body = RigidBody(float(attrs["mass"]), inertia, allow_unphysical=True)
    values = {name: np.asarray(dataset[name].values) for name in ("x", "v", "R", "L_world", "q")}
    return Trajectory(
        t=np.asarray(dataset["time"].values),
        x=values["x"],
        v=values["v"],
        R=values["R"],
        L_world=values["L_world"],
        body=body,
        method=str(attrs["method"]),
        settings=json.loads(attrs.get("settings", "{}")),
        status=int(attrs.get("status", 0)),
        message=str(attrs.get("message", "")),
        q_raw=values["q"],
        potential_energy=(
            np.asarray(dataset["potential_energy"].values)
            if "potential_energy" in dataset
            else None
        ),
    )
