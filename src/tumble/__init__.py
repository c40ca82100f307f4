"""tumble — rigid bodies and vibrating structures with integrators that keep the physics."""

__version__ = "0.1.0"
