"""tumble — rigid bodies and vibrating structures with integrators that keep the physics."""

from tumble.ode import ButcherTableau, OdeResult, solve

__version__ = "0.1.0"

__all__ = ["ButcherTableau", "OdeResult", "solve"]
