"""Built-in events for :func:`~tumble.rigid.simulate`: ``g(t, state)`` that users need often."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from tumble import _checks
from tumble.rigid.body import RigidBody
from tumble.rigid.forces import State


def flip_event(
    body: RigidBody, *, direction: int = 0, terminal: bool | int = False
) -> Callable[[float, State], float]:
    """The flip of a spin about the intermediate principal axis, as an event.

    .. math:: g(t) = \\frac{(R^T L) \\cdot a_2}{|L|}

    with ``a₂`` the intermediate principal axis (body frame): the share of the angular
    momentum along the middle axis. A spin near that axis (the tennis-racket or
    Dzhanibekov effect) turns it over again and again; each turn-over is a zero of ``g``,
    half a period of ω(t) apart (:func:`tumble.exact.free_body_period`), rising and
    falling in turn.

    Parameters
    ----------
    body : RigidBody
        The body (its principal axes): its three principal moments must differ (a sphere or
        a symmetric top has no intermediate axis, and is refused).
    direction : {0, 1, -1}
        Every flip (0), or only those where ``g`` rises (+1) or falls (−1).
    terminal : bool or int
        Stop the run at the first (True) or the ``k``-th flip.

    Returns
    -------
    callable
        ``g(t, state)`` with ``direction`` and ``terminal`` set, for ``simulate(events=...)``.

    Examples
    --------
    >>> import numpy as np
    >>> from tumble import RigidBody, exact, mass, simulate
    >>> body = RigidBody.from_mass_properties(mass.t_handle())
    >>> run = simulate(body, 60.0, method="rkmk-dopri5", rtol=1e-9, omega0=(1.0, 0.05, 0.0),
    ...                events=[flip_event(body)])
    >>> flips = run.t_events[0]  # every half period, from a quarter period on
    >>> period = exact.free_body_period(body.inertia, (1.0, 0.05, 0.0))
    >>> np.round(flips, 4), bool(abs((flips[2] - flips[0]) / period - 1) < 1e-8)
    (array([11.8154, 35.4461, 59.0768]), True)
    """
    if not isinstance(body, RigidBody):
        raise _checks.fail("body", body, "a tumble.RigidBody")
    if isinstance(direction, bool) or direction not in (-1, 0, 1):
        raise _checks.fail("direction", direction, "-1, 0 or +1")
    if not isinstance(terminal, bool | np.bool_) and not (
        isinstance(terminal, int | np.integer) and terminal >= 1
    ):
        raise _checks.fail("terminal", terminal, "True, False or an integer k >= 1 (the k-th)")
    moments, axes = np.linalg.eigh(body.inertia)
    _check_distinct(body, moments)
    middle = axes[:, 1].copy()

    def flip(t: float, state: State) -> float:
        return float(state.R.T @ state.L @ middle / np.linalg.norm(state.L))

    flip.direction = direction  # type: ignore[attr-defined]
    flip.terminal = terminal  # type: ignore[attr-defined]
    return flip


DISTINCT_RTOL = 1e-9
"""How far apart (relative to the largest) the principal moments must be for the middle axis
to be one: closer, the axis is not defined to round-off."""


def _check_distinct(body: RigidBody, moments: np.ndarray) -> None:
    """Refuse a body whose middle principal moment equals another: it has no intermediate
    axis. A sphere never flips (no event would ever fire), and on a symmetric top the
    "middle" axis is any axis in the symmetric plane, chosen by round-off: its zeros would be
    the precession's, not flips."""
    gap = min(moments[1] - moments[0], moments[2] - moments[1])
    if gap <= DISTINCT_RTOL * moments[2]:
        raise _checks.fail(
            "body", f"RigidBody(inertia with principal moments {moments.tolist()})",
            "a body with three distinct principal moments (an intermediate axis)",
            remedy="a flip is the turn-over of a spin near the middle axis; with two equal "
            "moments there is none (a symmetric body precesses steadily)",
        )  # fmt: skip
