"""Built-in scenarios that reproduce the seeds, by name.

Each scenario is a module with ``NAME``, ``SUMMARY`` and ``run(**options) -> ScenarioResult``
(see :mod:`tumble.scenarios._base`). ``tumble run NAME`` runs one and writes its run folder.
"""

from __future__ import annotations

from importlib import import_module
from types import ModuleType

from tumble import _checks
from tumble.scenarios._base import ScenarioResult

_MODULES = {
    "projectile": "tumble.scenarios.projectile",
    "torus-spin": "tumble.scenarios.torus_spin",
    "prism-impulse": "tumble.scenarios.prism_impulse",
    "sphere-exact": "tumble.scenarios.sphere_exact",
    "t-handle": "tumble.scenarios.t_handle",
    "convergence": "tumble.scenarios.convergence",
    "beam": "tumble.scenarios.beam",
    "rigid-body": "tumble.scenarios.rigid_body",
}


def names() -> list[str]:
    """The built-in scenarios' names, sorted."""
    return sorted(_MODULES)


def get(name: str) -> ModuleType:
    """The scenario module called ``name``.

    Raises
    ------
    ValueError
        If there is no such scenario (the message lists the known ones).
    """
    return import_module(_MODULES[_checks.choice("scenario", name, names())])


__all__ = ["ScenarioResult", "get", "names"]
