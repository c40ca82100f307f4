"""Detumbling a cubesat with your own controller: a B-dot law in Python, then under numba
========================================================================================

A 3U cubesat tumbles at 15 °/s on a 400 km orbit. Its magnetorquers command the B-dot law
``m = −k dB_b/dt``, clipped at ``±M`` per body axis, and the torque is ``m × B_b``: written
below as a user would, one function ``bdot(t, state)`` that returns the torque (N m, inertial
axes), handed to :func:`tumble.simulate` as a :class:`tumble.Torque`. The orbit is
integrated with the attitude under :class:`tumble.GravityGradient` (the Earth as a point
mass, and its gravity-gradient torque); the field is IGRF-13's centred dipole, turning with
the Earth; the run stops when ``|ω|`` falls below a threshold, found by an event.

The same function compiled with ``numba.njit`` gives the same numbers. Today a callable load
is called from Python at each stage either way, so the compiled one saves only its own
arithmetic; once compiled loads run inside the kernels (issue 26), decorating the function is
the only change. ``tumble run detumble`` is the same law as a scenario, with every option
(``examples/detumble.toml``).

Run it: ``python examples/detumble.py``.
"""

from __future__ import annotations

import math
import time

import numba
import numpy as np

from tumble import GravityGradient, Torque, simulate
from tumble.rigid import State
from tumble.scenarios.detumble import DipoleField, circular_orbit, cubesat

GAIN, MAX_DIPOLE = 3.0e4, 0.1
"""The B-dot gain k (A m² s/T) and each magnetorquer's saturation (A m²)."""
BODY, MESH = cubesat()
FIELD = DipoleField.igrf()
AXIS, STRENGTH, RATE = FIELD.axis, FIELD.strength, FIELD.rate
"""The dipole's direction at t = 0, μ₀M/4π (T m³) and its turn with the Earth (rad/s)."""
MASS, INVERSE = BODY.mass, np.array(BODY.inertia_inverse)
X0, V0, PERIOD = circular_orbit(400.0, 51.6)
OMEGA0 = (0.1, -0.15, 0.2)


def bdot(t, state):
    """The B-dot torque at ``(t, state)``: the dipole field and its rate at the satellite,
    ``dB_b/dt = Rᵀ dB/dt − ω × B_b`` in body axes, ``m`` clipped, ``τ = (R m) × B``."""
    r, v, R = state.x, state.p / MASS, state.R
    c, s = math.cos(RATE * t), math.sin(RATE * t)
    m = np.array([c * AXIS[0] - s * AXIS[1], s * AXIS[0] + c * AXIS[1], AXIS[2]])
    m_dot = RATE * np.array([-m[1], m[0], 0.0])
    d = math.sqrt(r @ r)
    B = STRENGTH * (3.0 * (m @ r) * r / d**5 - m / d**3)
    B_dot = STRENGTH * (
        3.0 * ((m @ v) * r + (m @ r) * v + (r @ v) * m + (m_dot @ r) * r) / d**5
        - 15.0 * (m @ r) * (r @ v) * r / d**7
        - m_dot / d**3
    )
    B_body = R.T @ B
    omega = INVERSE @ (R.T @ state.L)
    B_dot_body = R.T @ B_dot - np.cross(omega, B_body)
    dipole = np.minimum(np.maximum(-GAIN * B_dot_body, -MAX_DIPOLE), MAX_DIPOLE)
    return np.cross(R @ dipole, B)


bdot_njit = numba.njit(bdot)
"""The same law compiled: ``@numba.njit`` on ``bdot`` (numba reads the constants above when it
compiles, on the first call)."""


def detumbled(threshold: float):
    """The terminal event ``|ω| = threshold``, falling."""

    def event(t, state):
        return np.linalg.norm(state.omega) - threshold

    event.terminal, event.direction = True, -1
    return event


def detumble(law, *, threshold: float = 0.1, h: float = 2.0):
    """The cubesat under ``law`` from ``OMEGA0`` until ``|ω| < threshold`` (at most 4 orbits),
    with rkmk4 at step ``h`` (s); the run and its wall time (s)."""
    start = time.perf_counter()
    forces = [GravityGradient(), Torque(law)]
    run = simulate(BODY, 4 * PERIOD, method="rkmk4", h=h, x0=X0, v0=V0, omega0=OMEGA0,
                   forces=forces, events=[detumbled(threshold)])  # fmt: skip
    return run, time.perf_counter() - start


def run(threshold: float = 0.1, h: float = 2.0) -> dict:
    """Detumble from 15.4 °/s to ``threshold`` (rad/s; 0.1: 5.7 °/s, the first 17 minutes)
    with the Python law and with the compiled one (compiled first, outside the timing);
    return the detumble times (s), the largest difference of the two runs' attitudes and
    the µs per step of each."""
    bdot_njit(0.0, State(X0, np.eye(3), MASS * V0, np.zeros(3)))  # numba compiles here
    (python, python_s), (compiled, compiled_s) = (
        detumble(law, threshold=threshold, h=h) for law in (bdot, bdot_njit)
    )
    return {
        "threshold": threshold,
        "time_to_detumble": float(python.t_events[0][0]),
        "time_to_detumble_njit": float(compiled.t_events[0][0]),
        "attitude_difference": float(np.abs(python.R - compiled.R).max()),
        "steps": python.n_steps,
        "us_per_step": 1e6 * python_s / python.n_steps,
        "us_per_step_njit": 1e6 * compiled_s / compiled.n_steps,
        "runs": (python, compiled),
    }


def figure(numbers: dict):
    """|ω| of both runs on a log scale, and the dipole the Python law commanded."""
    import matplotlib.pyplot as plt

    python, compiled = numbers["runs"]
    fig, (rate, torque) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, layout="constrained")
    for run, label, style in ((python, "Python law", "-"), (compiled, "numba.njit law", "--")):
        rate.semilogy(run.t / 60, np.linalg.norm(run.omega_body, axis=1), style, label=label)
    rate.axhline(numbers["threshold"], color="C3", lw=0.8, ls=":", label="threshold")
    rate.set(ylabel="|ω| (rad/s)", title="A 3U cubesat detumbled by B-dot, 400 km, 51.6°")
    rate.legend()
    rate.grid(alpha=0.3, which="both")
    B, B_dot = FIELD.at(python.t, python.x, python.v)
    B_body = np.einsum("nji,nj->ni", python.R, B)
    rates = np.einsum("nji,nj->ni", python.R, B_dot) - np.cross(python.omega_body, B_body)
    dipole = np.clip(-GAIN * rates, -MAX_DIPOLE, MAX_DIPOLE)
    for k, axis in enumerate("xyz"):
        torque.plot(python.t / 60, dipole[:, k], lw=0.7, label=f"m_{axis}")
    torque.set(xlabel="t (min)", ylabel="commanded dipole (A m²)", ylim=(-0.13, 0.17))
    torque.legend(ncol=3, loc="upper right")
    torque.grid(alpha=0.3)
    return fig


if __name__ == "__main__":
    import matplotlib.pyplot as plt

    numbers = run()
    print(f"detumbled after {numbers['time_to_detumble']:.3f} s (Python law), "
          f"{numbers['time_to_detumble_njit']:.3f} s (numba.njit law); attitudes differ by "
          f"{numbers['attitude_difference']:.1e}")  # fmt: skip
    print(f"{numbers['steps']} steps: {numbers['us_per_step']:.0f} µs a step (Python law), "
          f"{numbers['us_per_step_njit']:.0f} µs a step (numba.njit law, called from "
          "Python)")  # fmt: skip
    figure(numbers)
    plt.show()
