"""The built-in scenarios by name: which module runs each one.

The scenario modules are imported only when asked for (:func:`get`), so listing the names
costs nothing, and a scenario that needs another one (``compare`` runs a torque-free body
scenario) imports this module rather than the package that holds them all.
"""

from __future__ import annotations

from importlib import import_module
from types import ModuleType

from tumble import _checks

_MODULES = {
    "projectile": "tumble.scenarios.projectile",
    "torus-spin": "tumble.scenarios.torus_spin",
    "prism-impulse": "tumble.scenarios.prism_impulse",
    "sphere-exact": "tumble.scenarios.sphere_exact",
    "t-handle": "tumble.scenarios.t_handle",
    "convergence": "tumble.scenarios.convergence",
    "beam": "tumble.scenarios.beam",
    "rigid-body": "tumble.scenarios.rigid_body",
    "spinning-top": "tumble.scenarios.spinning_top",
    "detumble": "tumble.scenarios.detumble",
}


def names() -> list[str]:
    """The built-in scenarios' names, sorted.

    Examples
    --------
    >>> "t-handle" in names()
    True
    """
    return sorted(_MODULES)


def get(name: str) -> ModuleType:
    """The scenario module called ``name``.

    Raises
    ------
    ValueError
        If there is no such scenario (the message lists the known ones).
    """
    return import_module(_MODULES[_checks.choice("scenario", name, names())])
