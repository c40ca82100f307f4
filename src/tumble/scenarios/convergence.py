"""Observed order of every fixed-step rigid-body method on an asymmetric free body.

Hairer, Lubich & Wanner's test body I = diag(2, 1, 2/3) kg m² (it violates the triangle
inequality, hence ``allow_unphysical=True``) starts at R(0) = Id with the world angular
momentum L = (cos 1.1, 0, sin 1.1) kg m²/s and runs to T = 10 s. The reference is the exact
attitude :func:`tumble.exact.free_body_rotation`; the error of a run is ``‖R(T) − R_exact(T)‖_F``
and the observed order is the least-squares slope of log(error) against log(h) through the
errors above round-off (:func:`tumble.exact.fit_order`; the runs through
:func:`tumble.exact.study`).

The point of the study is seed 002's "RK4" (``seed-rk4``): its stages live in the Lie algebra
but leave out the ``dexp⁻¹`` correction of Runge–Kutta–Munthe-Kaas. The neglected terms are
commutators ``[u, ω]``, which vanish when ω keeps its direction — on the seed's sphere, the only
test it had — so there it looked exact; on this body it is order 2, while ``rkmk4`` (the
stages corrected by ``dexp⁻¹``) is order 4: halving h divides its error by 16, not 4. The same
correction with DOP853's eighth-order tableau (``rkmk8``) is order 8, shown on coarser steps.

References
----------
E. Hairer, C. Lubich, G. Wanner, Geometric Numerical Integration, 2nd ed., Springer 2006,
§IV.1.4 and §VII.5; H. Munthe-Kaas, Runge–Kutta methods on Lie groups, BIT 38 (1998) 92–111.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import partial

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks, exact
from tumble.io import ScenarioResult
from tumble.rigid import METHODS, RigidBody, Trajectory, simulate
from tumble.scenarios._common import fixed_step_methods, method_names
from tumble.scenarios.option_models import OptionRules
from tumble.viz import rigid

NAME = "convergence"
SUMMARY = "Observed order of each method on the body diag(2, 1, 2/3); seed 002's RK4 is order 2."

CLAIMED_ORDERS = {name: method.order for name, method in METHODS.items() if not method.adaptive}
"""The order each fixed-step method should show: its :attr:`~tumble.rigid.Method.order`."""
DEFAULT_MAX_ORDER = 4
"""Orders studied by default. A higher order (``rkmk8``) reaches round-off (about 1e-15) at
the default steps; it shows its order with ``step_counts=HIGH_ORDER_STEP_COUNTS``."""
DEFAULT_METHODS = fixed_step_methods(max_order=DEFAULT_MAX_ORDER)
"""The methods studied by default: every fixed-step method of order at most 4."""
HIGH_ORDER_STEP_COUNTS = (20, 25, 32, 40, 50)
"""Steps over [0, 10 s] for ``rkmk8``: h = 0.5 … 0.2, errors 7.7e-10 … 4.8e-13."""
INERTIA = (2.0, 1.0, 2.0 / 3.0)
"""Hairer–Lubich–Wanner's principal moments (kg m²)."""
L0 = (float(np.cos(1.1)), 0.0, float(np.sin(1.1)))
"""World angular momentum (kg m²/s), constant."""
STEP_COUNTS = (200, 400, 800, 1600)
"""Steps over [0, T] by default: h = T/200 … T/1600, inside every method's asymptotic range
and above round-off for the fourth-order ones."""
OPTION_RULES = OptionRules(
    positive=["t_end", "step_counts"],
    min_distinct={"step_counts": 2},
    methods=fixed_step_methods(),
)
"""What :func:`run`'s options must be: two distinct step counts make a slope; a method
with an order in h (:func:`~tumble.scenarios._common.fixed_step_methods`)."""
ROUND_OFF_FLOOR = 1e-13
"""Errors at or below this are round-off, not truncation error, and are left out of the fit.

Double-precision rounding over a run of a few thousand steps leaves ``‖R − R_exact‖_F`` at
about 1e-15 … 1e-14 whatever h is (``rkmk8`` at the default steps: 5e-15 … 8e-15, a slope of
0.1); 1e-13 keeps a decade of margin above it."""
FIXED_STEP_METHODS = fixed_step_methods()
"""The methods that have an observed order in h: every method with a fixed step."""


def final_errors(method: str, step_sizes: ArrayLike, *, t_end: float = 10.0) -> np.ndarray:
    """``‖R(T) − R_exact(T)‖_F`` of ``method`` on the test body at each step size.

    Parameters
    ----------
    method : str
        A fixed-step method, one of :data:`FIXED_STEP_METHODS`.
    step_sizes : sequence of float, shape (k,)
        Steps h (s); ``t_end`` should be a multiple of each.
    t_end : float
        T (s).

    Returns
    -------
    ndarray, shape (k,)
        The errors (dimensionless).

    Raises
    ------
    ValueError
        For an adaptive or unknown ``method``.

    Examples
    --------
    >>> errors = final_errors("rkmk4", [0.05, 0.025])
    >>> bool(15 < errors[0] / errors[1] < 17)
    True
    """
    _check_fixed_step("method", method, method)
    body = RigidBody(1.0, INERTIA, allow_unphysical=True)
    reference = exact.free_body_rotation(INERTIA, body.inertia_inverse @ L0, t_end)

    def run(h: float) -> Trajectory:
        return simulate(
            body, t_end, method=method, h=h, L0=L0, record_every=max(1, round(t_end / h))
        )

    trials = exact.study(run, step_sizes, lambda run: np.linalg.norm(run.R[-1] - reference))
    return np.array([trial.error for trial in trials])


def run(
    *,
    t_end: float = 10.0,
    step_counts: Sequence[int] = STEP_COUNTS,
    methods: Sequence[str] | str = DEFAULT_METHODS,
) -> ScenarioResult:
    """Measure each method's observed order and draw the convergence plot.

    Parameters
    ----------
    t_end : float
        T (s).
    step_counts : sequence of int
        Numbers of steps over [0, T], at least two distinct (h = T/n).
    methods : sequence of str
        Fixed-step methods to study (default :data:`DEFAULT_METHODS`; any of
        :data:`FIXED_STEP_METHODS`), reported with their claimed order.

    Returns
    -------
    ScenarioResult
        ``summary`` with ``h`` (the step sizes, s) and, per method (``results``),
        ``claimed_order``, ``observed_order`` (the slope through the errors above
        :data:`ROUND_OFF_FLOOR`; None when fewer than two are), ``errors``, ``fitted`` (how
        many errors the slope was fitted through), ``note`` (None, or why errors were left
        out) and ``last_halving_ratio`` (the error at the second-finest h over the error at
        the finest: 2^order when they differ by a factor 2, as by default). Figure
        ``convergence.png``.

    Raises
    ------
    ValueError
        For no methods, an adaptive or unknown one (``rkmk45`` takes h only as its first
        step, so its error has no order in h), or fewer than two distinct step counts.

    Examples
    --------
    >>> result = run(step_counts=(100, 200), methods=("seed-rk4",))
    >>> round(result.summary["results"]["seed-rk4"]["observed_order"], 1)
    2.0
    """
    methods = method_names(methods)
    for method in methods:
        _check_fixed_step("methods", methods, method)
    counts = np.asarray(step_counts)
    if counts.ndim != 1 or len(set(counts.tolist())) < 2 or np.any(counts < 1):
        raise _checks.fail(
            "step_counts", step_counts, "at least two distinct numbers of steps, each >= 1"
        )
    step_sizes = t_end / counts.astype(float)
    results = {method: _study(method, step_sizes, t_end) for method in methods}
    summary = {
        "scenario": NAME,
        "methods": list(methods),
        "h": step_sizes.tolist(),
        "t_end": t_end,
        "inertia": list(INERTIA),
        "L0": list(L0),
        "results": results,
    }
    studies = [_plotted(method, step_sizes, result) for method, result in results.items()]
    title = f"{NAME} — I = diag(2, 1, 2/3), L = (cos 1.1, 0, sin 1.1), T = {t_end:g} s"
    writer = partial(rigid.convergence, studies, title=title)
    return ScenarioResult(
        NAME,
        summary,
        {"step_sizes": step_sizes},
        [("convergence.png", writer)],
        datasets={"": _dataset(step_sizes, results)},
        attrs={"methods": list(methods), "t_end": t_end, "inertia": list(INERTIA), "L0": list(L0)},
    )


def _dataset(step_sizes: np.ndarray, results: dict):
    """Final errors against (method, h), with the observed orders, as an ``xarray.Dataset``."""
    import xarray as xr

    methods = list(results)
    errors = np.array([results[method]["errors"] for method in methods])
    observed = [results[method]["observed_order"] for method in methods]
    orders = np.array([np.nan if order is None else order for order in observed], dtype=float)
    return xr.Dataset(
        {
            "error": (("method", "h"), errors, {"units": "1", "long_name": "|R(T) − R_exact|_F"}),
            "observed_order": (
                "method",
                orders,
                {"units": "1", "description": "NaN: every error at round-off, no order"},
            ),
        },
        coords={"method": methods, "h": ("h", step_sizes, {"units": "s"})},
    )


def _check_fixed_step(argument: str, value, method) -> None:
    """A ValueError naming ``argument`` unless ``method`` is a fixed-step method."""
    if method in FIXED_STEP_METHODS:
        return
    if isinstance(method, str) and method in METHODS and METHODS[method].adaptive:
        why = "is adaptive: h is only its first step, so its error has no order in h"
    elif isinstance(method, str) and method in METHODS:
        why = "steps the exact flow: on the torque-free body its error is round-off at any h"
    else:
        why = "is not a rigid-body method"
    raise _checks.fail(
        argument, value, f"fixed-step, from {list(FIXED_STEP_METHODS)}", remedy=f"{method!r} {why}"
    )


def _fit(step_sizes: np.ndarray, errors: np.ndarray) -> exact.OrderFit | None:
    """:func:`tumble.exact.fit_order` through every error above :data:`ROUND_OFF_FLOOR`."""
    return exact.fit_order(step_sizes, errors, window=(ROUND_OFF_FLOOR, math.inf))


def _study(method: str, step_sizes: np.ndarray, t_end: float) -> dict:
    errors = final_errors(method, step_sizes, t_end=t_end)
    finest = np.argsort(step_sizes)[:2]
    fit = _fit(step_sizes, errors)
    left_out = errors.size - (0 if fit is None else fit.points)
    note = None
    if fit is None:
        note = (
            f"{left_out} of {errors.size} errors are at round-off (≤ {ROUND_OFF_FLOOR:g}): "
            "too few above it for an order; use fewer steps (larger h), e.g. step_counts="
            f"{HIGH_ORDER_STEP_COUNTS} for rkmk8"
        )
    elif left_out:
        note = (
            f"{left_out} of {errors.size} errors are at round-off (≤ {ROUND_OFF_FLOOR:g}) "
            "and are left out of the fit"
        )
    return {
        "claimed_order": CLAIMED_ORDERS.get(method),
        "observed_order": None if fit is None else fit.order,
        "errors": errors.tolist(),
        "fitted": 0 if fit is None else fit.points,
        "note": note,
        "last_halving_ratio": float(errors[finest[1]] / errors[finest[0]]),
    }


def _plotted(method: str, step_sizes: np.ndarray, result: dict) -> tuple:
    """``(label, h, errors, slope)`` for the plot: the fitted errors and their slope.

    A method at round-off has no slope; its errors are drawn on a flat line (slope 0).
    """
    errors = np.array(result["errors"])
    fit = _fit(step_sizes, errors)
    if fit is None:
        return f"{method} (at round-off, no order)", step_sizes, errors, 0.0
    left_out = errors.size - fit.points
    label = method if not left_out else f"{method} ({left_out} at round-off not shown)"
    return label, step_sizes[fit.used], errors[fit.used], fit.order


def free_body() -> tuple[RigidBody, np.ndarray]:
    """Hairer–Lubich–Wanner's body and ω(0) = I⁻¹ L0, for ``tumble compare convergence``."""
    return RigidBody(1.0, INERTIA, allow_unphysical=True), np.array(L0) / np.array(INERTIA)
