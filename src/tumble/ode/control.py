"""Step-size control, kept apart from the stepper: norms, the controller, the first step.

The controller never sees a tableau and the stepper never picks a step size (the diffrax
split). Constants follow Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tumble import _checks

MIN_RTOL = 100 * np.finfo(float).eps
"""The smallest ``rtol`` accepted (100 machine epsilons, 2.2e-14): below it round-off decides."""

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0


def relative_tolerance(rtol: object) -> float:
    """``rtol`` checked: finite and at least :data:`MIN_RTOL` (the ValueError names it)."""
    value = _checks.positive("rtol", rtol)
    if value < MIN_RTOL:
        raise _checks.fail("rtol", rtol, ">= 100 × machine epsilon (2.2e-14)", remedy="raise it")
    return value


def error_norm(
    error: np.ndarray, y: np.ndarray, y_new: np.ndarray, rtol: float, atol: np.ndarray | float
) -> float:
    """Hairer's weighted root-mean-square norm of a local error estimate.

    .. math::

        \\|e\\| = \\sqrt{\\frac{1}{n} \\sum_i
        \\Bigl(\\frac{e_i}{\\mathrm{atol}_i + \\mathrm{rtol}\\,\\max(|y_i|, |y^{new}_i|)}\\Bigr)^2}

    A step is acceptable when the norm is at most 1.
    """
    scaled = error / (atol + rtol * np.maximum(np.abs(y), np.abs(y_new)))
    return math.sqrt(float(scaled @ scaled) / scaled.size)


def step_factor(
    error_norm: float,
    order: int,
    safety: float,
    min_factor: float,
    max_factor: float,
    after_rejection: bool,
) -> float:
    """How much the next step may grow or must shrink: the controller's one formula.

    ``s ‖e‖^(−1/(q+1))`` bounded to ``[min_factor, max_factor]`` (to 1 after a rejection or
    for a rejected step); a non-finite norm shrinks by ``min_factor``. Plain scalar code, so
    that :class:`StepController` and the compiled adaptive loops of
    :mod:`tumble.rigid._compiled` (which compile this very function) share it.
    """
    if not math.isfinite(error_norm):
        return min_factor
    if error_norm == 0.0:
        factor = max_factor
    else:
        factor = safety * error_norm ** (-1.0 / (order + 1))
    upper = 1.0 if (after_rejection or error_norm > 1.0) else max_factor
    return min(upper, max(min_factor, factor))


@dataclass(frozen=True)
class StepController:
    """The classical (integral) step-size controller.

    .. math::

        h_{next} = h \\cdot \\min\\bigl(f_{max}, \\max(f_{min},
        s \\cdot \\|e\\|^{-1/(q+1)})\\bigr)

    with ``q`` the order of the error estimate. After a rejected step the step may not grow.

    Parameters
    ----------
    safety : float
        Safety factor ``s`` in (0, 1).
    min_factor, max_factor : float
        Bounds on the shrink and growth of one step.
    """

    safety: float = SAFETY
    min_factor: float = MIN_FACTOR
    max_factor: float = MAX_FACTOR

    def propose(
        self, h: float, error_norm: float, order: int, *, after_rejection: bool = False
    ) -> tuple[bool, float]:
        """Accept or reject a step and propose the next step size.

        Parameters
        ----------
        h : float
            The step just tried.
        error_norm : float
            Its weighted error norm (see :func:`error_norm`); NaN counts as infinite.
        order : int
            Order ``q`` of the error estimate.
        after_rejection : bool
            Whether the previous attempt at this step was rejected (then no growth).

        Returns
        -------
        accepted : bool
            ``error_norm <= 1``.
        h_next : float
            The step to try next: the following step if accepted, a retry if not.
        """
        factor = step_factor(float(error_norm), order, self.safety, self.min_factor,
                             self.max_factor, after_rejection)  # fmt: skip
        return bool(error_norm <= 1.0), h * factor


def fixed_step_count(t0: float, t1: float, h: float) -> int:
    """Number of steps of size ``h`` (the last one shortened) that cover ``[t0, t1]``.

    A ratio within round-off of an integer counts as that integer, so ``h = 0.1`` on
    ``[0, 1]`` takes 10 steps, not 11. Step ``k`` ends at ``t0 + k h``, the last at ``t1``
    exactly (:func:`grid_time`).

    Examples
    --------
    >>> fixed_step_count(0.0, 1.0, 0.1), fixed_step_count(0.0, 1.0, 0.3)
    (10, 4)
    """
    ratio = (t1 - t0) / h
    nearest = round(ratio)
    if nearest >= 1 and abs(ratio - nearest) <= 1e-9 * max(1.0, ratio):
        return int(nearest)
    return max(1, math.ceil(ratio))


def grid_time(t0: float, t1: float, h: float, k: int, n: int) -> float:
    """Where step ``k`` of the ``n`` steps of :func:`fixed_step_count` ends: ``t0 + k h``,
    or ``t1`` exactly for the last."""
    return t1 if k == n else t0 + k * h


def minimum_step(t: float) -> float:
    """The smallest step that still moves ``t``: ten units in the last place.

    ``np.spacing(|t|)`` is ``math.ulp(t)``, in a form numba compiles too (the compiled
    adaptive loops call this function)."""
    return 10.0 * float(np.spacing(abs(t)))


def initial_step(
    fun: Callable[[float, np.ndarray], np.ndarray],
    t0: float,
    y0: np.ndarray,
    f0: np.ndarray,
    order: int,
    rtol: float,
    atol: np.ndarray | float,
) -> float:
    """Choose a first step from the scale of ``y0``, ``f0`` and one trial Euler step.

    Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4, algorithm (4.14). Costs one evaluation.
    """
    scale = atol + np.abs(y0) * rtol
    d0 = np.sqrt(np.mean(np.square(y0 / scale)))
    d1 = np.sqrt(np.mean(np.square(f0 / scale)))
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    f1 = fun(t0 + h0, y0 + h0 * f0)
    d2 = np.sqrt(np.mean(np.square((f1 - f0) / scale))) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1))
    return float(min(100 * h0, h1))
