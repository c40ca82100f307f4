"""The seed-003 cantilever: frequencies, the critical step, and the schemes' energy
=================================================================================

A 1 m steel cantilever, 1 cm square (E = 210 GPa, ρ = 7850 kg/m³), clamped at x = 0,
starts at rest under a 1 N step load at the tip. ``run()`` returns the reference numbers;
``python examples/beam.py`` prints them and draws the tip and the energy of each scheme.
"""

import numpy as np

from tumble import structural

BETA_L = np.array([1.87510406871196, 4.69409113297418, 7.85475743823761, 10.9955407348755])
LENGTH, E, RHO, SIDE, LOAD = 1.0, 210e9, 7850.0, 0.01, 1.0
EI = E * SIDE**4 / 12
STATIC_TIP = LOAD * LENGTH**3 / (3 * EI)
"""The static tip deflection P L³ / (3 EI) [m]."""


def responses(n_elements: int = 20, n_steps: int = 2000) -> tuple:
    """The beam, its step Δt = T₁/200 and one response per scheme at that step."""
    beam = structural.cantilever(LENGTH, n_elements, E, RHO, SIDE, SIDE, tip_load=LOAD)
    dt = 2 * np.pi / beam.natural_frequencies(1)[0] / 200
    runs = {s: structural.integrate(beam, s, dt, n_steps=n_steps) for s in structural.SCHEMES}
    return beam, dt, runs


def run(n_elements: int = 20, n_steps: int = 2000) -> dict:
    """Build the beam, step it with every scheme at Δt = T₁/200, return the numbers."""
    beam, dt, runs = responses(n_elements, n_steps)
    exact = BETA_L**2 * np.sqrt(EI / (RHO * SIDE**2 * LENGTH**4))
    omega = beam.natural_frequencies(4)
    scale = structural.energy_scale(beam)
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
        "tip_mean_over_static": float(midpoint.tip_displacement.mean() / STATIC_TIP),
        "tip_max_over_static": float(midpoint.tip_displacement.max() / STATIC_TIP),
    }


def figure(n_elements: int = 20, n_steps: int = 2000):
    """The tip over the static deflection, and (E − E₀)/scale, of each scheme that stays finite."""
    import matplotlib.pyplot as plt

    beam, dt, runs = responses(n_elements, n_steps)
    scale = structural.energy_scale(beam)
    fig, (tip, energy) = plt.subplots(1, 2, figsize=(10, 4.4), layout="constrained")
    for k, (name, response) in enumerate(runs.items()):
        if not response.success:  # the explicit schemes diverge at this step: say where
            tip.plot([], [], color=f"C{k}", label=f"{name}: diverged, t = {response.t[-1]:.3f} s")
            continue
        style = {"color": f"C{k}", "ls": "--" if name == "newmark" else "-", "lw": 1.2}
        tip.plot(response.t, response.tip_displacement / STATIC_TIP, label=name, **style)
        energy.plot(response.t, (response.energy - response.energy[0]) / scale, **style)
    tip.set(xlabel="time t [s]", ylabel="tip / static deflection [–]", title="tip deflection")
    energy.set(xlabel="time t [s]", ylabel=f"(E − E₀) / {scale:.3g} J [–]", title="energy")
    fig.legend(loc="outside lower center", ncols=3, fontsize=9)
    for axes in (tip, energy):
        axes.grid(alpha=0.3)
    fig.suptitle(f"cantilever, {n_elements} elements, Δt = T₁/200 = {dt * 1e3:.3f} ms")
    return fig


if __name__ == "__main__":
    import matplotlib.pyplot as plt

    for name, value in run().items():
        print(f"{name:24s} {value}")
    figure()
    plt.show()
