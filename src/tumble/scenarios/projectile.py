"""Seed 000's projectile: 500 m/s at 45°, gravity only, stopped by an event at the ground."""

from __future__ import annotations

from functools import partial

import numpy as np

from tumble import _checks
from tumble.io import ScenarioResult
from tumble.ode import TABLEAUX, solve
from tumble.scenarios.option_models import OptionRules

NAME = "projectile"
SUMMARY = "Seed 000: a 1 kg point mass launched at 500 m/s, 45°; the impact found by an event."
OPTION_RULES = OptionRules(positive=["speed", "g", "h", "t_max"], methods=list(TABLEAUX))
"""What :func:`run`'s options must be: the method is an ODE tableau (any angle is allowed)."""


def _ground(t: float, y: np.ndarray) -> float:
    return y[1]


_ground.terminal = True  # type: ignore[attr-defined]
_ground.direction = -1  # type: ignore[attr-defined]


def _free_flight(t: float, y: np.ndarray, g: float) -> np.ndarray:
    """State ``y = (x, z, vx, vz)``; ``y' = (vx, vz, 0, -g)``."""
    return np.array([y[2], y[3], 0.0, -g])


def run(
    *,
    speed: float = 500.0,
    angle: float = 45.0,
    g: float = 9.81,
    method: str = "rk4",
    h: float | None = 0.01,
    t_max: float = 1000.0,
) -> ScenarioResult:
    """Fly the projectile until it lands.

    Parameters
    ----------
    speed : float
        Launch speed in m/s (seed 000 turns a 500 N push on 1 kg into 500 m/s).
    angle : float
        Launch angle above the horizontal, in degrees.
    g : float
        Gravitational acceleration in m/s².
    method, h : str, float
        Integrator and step for :func:`tumble.solve` (RK4 is exact for this motion).
    t_max : float
        Give up if the ground is not reached by then (s).

    Returns
    -------
    ScenarioResult
        ``summary`` with ``impact_time`` (s), ``range`` (m), ``max_height`` (m); ``data``
        with the :class:`~tumble.ode.OdeResult`; one figure, ``trajectory.png``; the flight
        (x, y, vx, vy against time) as the dataset.

    Examples
    --------
    >>> result = run()
    >>> round(result.summary["impact_time"], 6), round(result.summary["range"], 4)
    (72.080202, 25484.1998)
    """
    _checks.positive("speed", speed, "m/s")
    if not 0 < _checks.finite("angle", angle, "degrees") < 180:
        raise _checks.fail("angle", angle, "in (0, 180)", "degrees")
    _checks.positive("g", g, "m/s²")
    theta = np.radians(angle)
    y0 = [0.0, 0.0, speed * np.cos(theta), speed * np.sin(theta)]
    ode = solve(partial(_free_flight, g=g), (0.0, t_max), y0, method=method, h=h, events=_ground)
    if ode.status != 1:
        raise _checks.fail(
            "t_max", t_max, "long enough for the projectile to land", "s", "it is still flying"
        )
    impact_time = float(ode.t_events[0][0])
    summary = {
        "scenario": NAME,
        "method": method,
        "h": h,
        "impact_time": impact_time,
        "range": float(ode.y_events[0][0, 0]),
        "max_height": float(ode.y[1].max()),
        "steps": int(ode.n_steps),
    }
    return ScenarioResult(
        name=NAME,
        summary=summary,
        data={"ode": ode},
        figures=[("trajectory.png", partial(_draw, ode=ode, summary=summary))],
        datasets={"": _dataset(ode)},
        attrs={"method": method, "h": h, "speed": speed, "angle": angle, "g": g},
    )


def _dataset(ode):
    """The flight as an ``xarray.Dataset``: position and velocity against time."""
    import xarray as xr

    names = [("x", "m", "horizontal position"), ("y", "m", "height")]
    names += [("vx", "m/s", "horizontal velocity"), ("vy", "m/s", "vertical velocity")]
    data_vars = {
        name: ("time", row, {"units": units, "long_name": text})
        for (name, units, text), row in zip(names, ode.y, strict=True)
    }
    return xr.Dataset(data_vars, coords={"time": ("time", ode.t, {"units": "s"})})


def _draw(path, *, ode, summary) -> None:
    from tumble.viz.trajectory import projectile_figure

    projectile_figure(ode.t, ode.y[0], ode.y[1], summary, path)
