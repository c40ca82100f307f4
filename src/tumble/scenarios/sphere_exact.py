"""Seed 002, tasks 2–4: the isotropic sphere spun about x, every method against the exact rotation.

With I = Id, R(0) = Id and L = (1, 0, 0) the body turns about x at 1 rad/s, so the exact
attitude is the rotation about x by the angle t, ``R(t) = exp(t x̃)``
(:func:`tumble.exact.sphere`). Seed 002 tabulated eq. 24 (explicit Euler, ``W + h W Ω̃``) and
eq. 25 (Lie–Euler, ``W exp(h Ω̃)``) at h = 0.1 on [0, 1]: Euler leaves SO(3) and ends at
``R_22 = 0.57079045, R_32 = 0.88250801`` (SPEC §4), Lie–Euler is exact to round-off.

On the sphere ω = I⁻¹ Rᵀ L stays (1, 0, 0) in the body, so every commutator in the RKMK
correction vanishes and seed 002's RK4 without ``dexp⁻¹`` (``seed-rk4``) is as exact as
``rkmk4``: this problem cannot tell them apart, which is why the seed did not notice that its
RK4 is only order 2 (:mod:`tumble.scenarios.convergence` shows it on an asymmetric body).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial

import numpy as np

from tumble import exact, meshes
from tumble.io import ScenarioResult
from tumble.rigid import RigidBody
from tumble.rigid import methods as rigid_methods
from tumble.scenarios._base import rigid_attrs, rigid_outputs, showcase
from tumble.scenarios._common import method_names, simulate_method
from tumble.scenarios.option_models import OptionRules
from tumble.viz import rigid

NAME = "sphere-exact"
SUMMARY = "Seed 002 tasks 2–4: the unit sphere spun about x; every method against exp(t x̃)."

METHODS = tuple(rigid_methods.METHODS)
OPTION_RULES = OptionRules(positive=["h", "t_end", "rtol"])
"""What :func:`run`'s options must be beyond its signature."""
"""The methods compared by default: every one of :data:`tumble.rigid.METHODS`, in its order."""
OMEGA0 = (1.0, 0.0, 0.0)
"""Seed 002's initial angular velocity (rad/s); with I = Id also L (kg m²/s)."""
SEED_EULER_AT_1 = np.array(
    [[1.0, 0.0, 0.0], [0.0, 0.57079045, -0.88250801], [0.0, 0.88250801, 0.57079045]]
)
"""Seed 002's eq. 24 (explicit Euler) at h = 0.1, t = 1, printed to 8 decimals."""


def run(
    *,
    h: float = 0.1,
    t_end: float = 1.0,
    methods: Sequence[str] | str = METHODS,
    rtol: float = 1e-6,
) -> ScenarioResult:
    """Spin the unit sphere about x with each method and measure its error.

    Parameters
    ----------
    h : float
        Step (s); the first step for ``rkmk45``.
    t_end : float
        End time (s).
    methods : sequence of str
        Methods to compare (names of :data:`tumble.rigid.METHODS`).
    rtol : float
        Relative tolerance of the adaptive methods (``rkmk45``); the others ignore it.

    Returns
    -------
    ScenarioResult
        ``summary`` with, per method (under ``results``), ``final_error`` and ``max_error``
        (``‖R − R_exact‖_F``), ``max_orthogonality_error`` (``‖RᵀR − I‖_F``) and
        ``samples``; ``euler_R_end`` (R at ``t_end`` by eq. 24) and, at the seed's h = 0.1,
        t = 1, ``euler_vs_seed`` (largest entry difference from :data:`SEED_EULER_AT_1`).
        ``data`` holds the trajectories and errors; figures ``error_vs_exact.png``,
        ``rotation_grid.png`` (the fixed-step methods and the exact rotation) and
        ``drift.png``.

    Examples
    --------
    >>> result = run(methods=("euler", "lie-euler"))
    >>> round(result.summary["euler_R_end"][1][1], 8), result.summary["euler_vs_seed"] < 5e-9
    (0.57079045, True)
    """
    methods = method_names(methods)
    body = RigidBody(1.0, np.eye(3))
    runs = {
        method: simulate_method(body, t_end, method, h=h, rtol=rtol, omega0=OMEGA0)
        for method in methods
    }
    errors = {
        method: np.linalg.norm(run.R - exact.sphere(run.t, OMEGA0), axis=(1, 2))
        for method, run in runs.items()
    }
    summary = _summary(runs, errors, h, t_end)
    title = f"{NAME} — I = Id, ω₀ = (1, 0, 0) rad/s, h = {h} s"
    shown, mesh = showcase(runs), _mesh()
    return ScenarioResult(
        name=NAME,
        summary=summary,
        data={"trajectories": runs, "errors": errors},
        figures=_figures(runs, errors, title),
        attrs=rigid_attrs(body, methods=list(methods), h=h, rtol=rtol, t_end=t_end),
        **rigid_outputs(runs, mesh, shown=shown, title=f"{title}, {shown}"),
    )


def _summary(runs: dict, errors: dict, h: float, t_end: float) -> dict:
    results = {
        method: {
            "final_error": float(errors[method][-1]),
            "max_error": float(errors[method].max()),
            "max_orthogonality_error": run.orthogonality_drift,
            "samples": len(run.t),
        }
        for method, run in runs.items()
    }
    summary = {
        "scenario": NAME,
        "methods": list(runs),
        "h": h,
        "t_end": t_end,
        "omega0": list(OMEGA0),
        "results": results,
    }
    if "euler" in runs:
        R_end = runs["euler"].R[-1]
        summary["euler_R_end"] = R_end.tolist()
        if h == 0.1 and t_end == 1.0:
            summary["euler_vs_seed"] = float(np.abs(R_end - SEED_EULER_AT_1).max())
    return summary


def _figures(runs: dict, errors: dict, title: str) -> list:
    fixed = [method for method in runs if not rigid_methods.METHODS[method].adaptive]
    grid = [(method, runs[method].t, runs[method].R) for method in fixed]
    t_fine = np.linspace(0.0, max(run.t[-1] for run in runs.values()), 201)
    grid.append(("exact", t_fine, exact.sphere(t_fine, OMEGA0)))
    error_curves = [(method, runs[method].t, errors[method]) for method in runs]
    return [
        ("error_vs_exact.png", partial(rigid.error_vs_exact, error_curves, title=title)),
        ("rotation_grid.png", partial(rigid.rotation_grid, grid, title=title)),
        ("drift.png", partial(rigid.drift, list(runs.items()), title=title)),
    ]


def _mesh():
    """A coarse icosphere (its facets show the turning) of the unit-inertia, 1 kg sphere.

    ``I = (2/5) m r² = 1`` gives ``r = sqrt(5/2)`` m.
    """
    return meshes.sphere(np.sqrt(2.5), 1)


def free_body() -> tuple[RigidBody, np.ndarray]:
    """The unit sphere spun about x, for ``tumble compare sphere-exact``."""
    return RigidBody(1.0, np.eye(3)), np.array(OMEGA0)
