"""Seed 000's projectile, with the impact located by an event instead of the last sample
=====================================================================================

Run it: ``python examples/projectile.py``.
"""

from __future__ import annotations

import numpy as np

from tumble import OdeResult, solve


def flight(h: float = 0.01) -> OdeResult:
    """Fly 500 m/s at 45° under g = 9.81 m/s² with RK4 until the height crosses zero."""

    def ground(t, y):
        return y[1]

    ground.terminal, ground.direction = True, -1
    v = 500.0 / np.sqrt(2.0)
    return solve(
        lambda t, y: [y[2], y[3], 0.0, -9.81], (0.0, 100.0), [0, 0, v, v], h=h, events=ground
    )


def run(h: float = 0.01) -> dict[str, float]:
    """Fly 500 m/s at 45° under g = 9.81 m/s² with RK4; return the impact time and range."""
    result = flight(h)
    return {"impact_time": float(result.t_events[0][0]), "range": float(result.y[0, -1])}


def figure(h: float = 0.01):
    """The path in km, and the impact the event found."""
    import matplotlib.pyplot as plt

    result = flight(h)
    x, z = result.y[0] / 1000, result.y[1] / 1000
    fig, axes = plt.subplots(figsize=(7, 3.8), layout="constrained")
    axes.plot(x, z, lw=1.5, label=f"rk4, h = {h} s")
    t_hit, x_hit = result.t_events[0][0], result.y_events[0][0, 0]
    axes.plot(x_hit / 1000, 0, "o", color="C3", label="impact (event)")
    axes.annotate(
        f"t = {t_hit:.6f} s\nx = {x_hit:.4f} m",
        (x_hit / 1000, 0),
        textcoords="offset points",
        xytext=(-120, 25),
        arrowprops={"arrowstyle": "->"},
    )
    axes.set(xlabel="horizontal distance x [km]", ylabel="height z [km]")
    axes.set(title="500 m/s at 45°, no drag", ylim=(-0.2, None))
    axes.grid(alpha=0.3)
    axes.legend(loc="upper right")
    return fig


if __name__ == "__main__":
    import matplotlib.pyplot as plt

    numbers = run()
    print(f"impact at t = {numbers['impact_time']:.6f} s, x = {numbers['range']:.4f} m")
    figure()
    plt.show()
