"""What the built-in scenarios share: method lists read off the declarations, one run, JSON.

Method lists are derived from :data:`tumble.rigid.METHODS` (each :class:`~tumble.rigid.Method`
declares its family, order and invariants), so a method added there reaches every scenario
whose default means "all of them" without an edit here.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tumble import _checks
from tumble.rigid import METHODS, RigidBody, Trajectory, simulate


def method_names(methods: Sequence[str] | str) -> tuple[str, ...]:
    """``methods`` as a tuple of names; one name is a tuple of one.

    Raises
    ------
    ValueError
        For an empty sequence (unknown names are refused by ``simulate``, which lists the
        known ones).

    Examples
    --------
    >>> method_names("rkmk4"), method_names(["euler", "rkmk4"])
    (('rkmk4',), ('euler', 'rkmk4'))
    """
    methods = (methods,) if isinstance(methods, str) else tuple(methods)
    if not methods:
        raise _checks.fail("methods", methods, "at least one method name")
    return methods


def fixed_step_methods(*, max_order: int | None = None) -> tuple[str, ...]:
    """Names of the methods of :data:`tumble.rigid.METHODS` that take a fixed step and have an
    order in h on the torque-free body, in order (not the adaptive one, nor those on the exact
    flow, whose error there is round-off at any h).

    Parameters
    ----------
    max_order : int, optional
        Keep only those whose declared :attr:`~tumble.rigid.Method.order` is at most this.

    Examples
    --------
    >>> "rkmk4" in fixed_step_methods(), "rkmk8" in fixed_step_methods(max_order=4)
    (True, False)
    """
    return tuple(
        name
        for name, method in METHODS.items()
        if not method.adaptive
        and method.flow != "exact"
        and (max_order is None or method.order <= max_order)
    )


def simulate_method(
    body: RigidBody, t_end: float, method: str, *, h: float | None, rtol: float | None, **start
) -> Trajectory:
    """:func:`~tumble.rigid.simulate` with the settings ``method`` takes.

    A scenario comparing several methods holds one ``h`` and one ``rtol``: ``h`` goes to every
    method (the first step of an adaptive one), ``rtol`` only to the adaptive ones (the
    fixed-step ones refuse a tolerance). ``start`` is the initial state (``omega0``, ``x0``,
    ``forces`` …), passed on as it is.
    """
    declared = METHODS.get(method)  # an unknown name is left to simulate, which lists them
    if declared is not None and not declared.adaptive:
        rtol = None
    return simulate(body, t_end, method=method, h=h, rtol=rtol, **start)


def json_number(value: float | np.floating) -> float | None:
    """A float for ``summary.json``, or None where it is inf or NaN (JSON has neither).

    Examples
    --------
    >>> json_number(np.float64(0.25)), json_number(np.inf), json_number(np.nan)
    (0.25, None, None)
    """
    return float(value) if np.isfinite(value) else None
