"""Seed 000's projectile, with the impact located by an event instead of the last sample.

Run it: ``python examples/projectile.py``.
"""

from __future__ import annotations

import numpy as np

from tumble import solve


def run(h: float = 0.01) -> dict[str, float]:
    """Fly 500 m/s at 45° under g = 9.81 m/s² with RK4; return the impact time and range."""

    def ground(t, y):
        return y[1]

    ground.terminal, ground.direction = True, -1
    v = 500.0 / np.sqrt(2.0)
    result = solve(
        lambda t, y: [y[2], y[3], 0.0, -9.81], (0.0, 100.0), [0, 0, v, v], h=h, events=ground
    )
    return {"impact_time": float(result.t_events[0][0]), "range": float(result.y[0, -1])}


if __name__ == "__main__":
    numbers = run()
    print(f"impact at t = {numbers['impact_time']:.6f} s, x = {numbers['range']:.4f} m")
