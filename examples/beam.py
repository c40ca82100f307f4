"""The seed-003 cantilever: frequencies, the critical step, and the four schemes' energy.

A 1 m steel cantilever, 1 cm square (E = 210 GPa, ρ = 7850 kg/m³), clamped at x = 0,
starts at rest under a 1 N step load at the tip. ``run()`` returns the reference numbers;
``python examples/beam.py`` prints them.
"""

import numpy as np

from tumble import structural

BETA_L = np.array([1.87510406871196, 4.69409113297418, 7.85475743823761, 10.9955407348755])
LENGTH, E, RHO, SIDE, LOAD = 1.0, 210e9, 7850.0, 0.01, 1.0


def run(n_elements: int = 20, n_steps: int = 2000) -> dict:
    """Build the beam, step it with every scheme at Δt = T₁/200, return the numbers."""
    beam = structural.cantilever(LENGTH, n_elements, E, RHO, SIDE, SIDE, tip_load=LOAD)
    EI = E * SIDE**4 / 12
    exact = BETA_L**2 * np.sqrt(EI / (RHO * SIDE**2 * LENGTH**4))
    omega = beam.natural_frequencies(4)
    dt = 2 * np.pi / omega[0] / 200
    static_tip = LOAD * LENGTH**3 / (3 * EI)
    scale = structural.energy_scale(beam)
    runs = {s: structural.integrate(beam, s, dt, n_steps=n_steps) for s in structural.SCHEMES}
    midpoint = runs["midpoint"]
    critical = structural.critical_dt(beam, "semi-implicit")
    return {
        "omega": omega,
        "omega_relative_error": omega / exact - 1,
        "critical_dt": critical.dt,
        "critical_mode": critical.mode,
        "dt": dt,
        "status": {s: r.status.name for s, r in runs.items()},
        "midpoint_energy_drift": float(np.max(np.abs(midpoint.energy)) / scale),
        "implicit_energy_final": float(runs["implicit"].energy[-1] / scale),
        "newmark_minus_midpoint": float(np.max(np.abs(runs["newmark"].x - midpoint.x))),
        "tip_mean_over_static": float(midpoint.tip_displacement.mean() / static_tip),
        "tip_max_over_static": float(midpoint.tip_displacement.max() / static_tip),
    }


if __name__ == "__main__":
    for name, value in run().items():
        print(f"{name:24s} {value}")
