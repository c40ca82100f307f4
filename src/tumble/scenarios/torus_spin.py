"""Seed 000's spinning torus: which methods keep R on SO(3) over a long run.

Seed 000 turned its torus mesh (R = 1, r = 0.5) by integrating the nine entries of R with
``odeint`` under ``Ṙ = ω̃ R`` with a constant ω = (1, 1, 1) rad/s, a kinematic rotation that
a free body performs only if its inertia is isotropic. A torus is symmetric, not spherical
(I = diag(3.238464, 3.238464, 5.860078) kg m² at ρ = 1 kg/m³), so as a free body its ω
precesses about the symmetry axis at ``Ω = (I⊥ − I_s) ω_s / I⊥`` and is not constant.

**Choice.** tumble simulates the *free* torus from ω_body(0) = (1, 1, 1) rad/s — the physics,
with an exact reference (:func:`tumble.exact.free_body_rotation`, closed form for a symmetric
body) — rather than prescribing the seed's constant ω, which no torque-free torus follows. What
the seed wanted to show survives unchanged: integrating R as nine numbers (``rk4-matrix``,
seed 000's ``odeint`` way) lets ``‖RᵀR − I‖`` grow steadily, while ``lie-euler`` and ``rkmk4``
(R ← R exp(…)) and ``rk4-quat`` (renormalised) stay on SO(3) to round-off. Explicit Euler is
left out by default: at h = 0.1 it grows by (1 + h²|ω|²)^½ per step and overflows near t = 53 s.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial

import numpy as np

from tumble import exact, mass, meshes
from tumble.io import ScenarioResult
from tumble.rigid import RigidBody, simulate
from tumble.scenarios._base import rigid_attrs, rigid_outputs, showcase
from tumble.scenarios._common import json_number, method_names
from tumble.scenarios.option_models import OptionRules
from tumble.viz import rigid

NAME = "torus-spin"
SUMMARY = "Seed 000: a free torus spun at ω(0) = (1, 1, 1); rk4-matrix drifts off SO(3)."

METHODS = ("rk4-matrix", "rk4-quat", "lie-euler", "rkmk4")
OPTION_RULES = OptionRules(
    positive=["t_end", "h", "major_radius", "minor_radius", "density"], three_vectors=["omega0"]
)
"""What :func:`run`'s options must be beyond its signature: ω₀ is a 3-vector (rad/s)."""
"""The methods compared by default."""
OMEGA0 = (1.0, 1.0, 1.0)
"""Seed 000's angular velocity (rad/s), here the initial body-frame value."""
GRID_SPAN = 20.0
"""Seconds of R(t) shown in the component grid (the whole run would be a blur)."""


def run(
    *,
    t_end: float = 100.0,
    h: float = 0.1,
    methods: Sequence[str] | str = METHODS,
    omega0: Sequence[float] = OMEGA0,
    major_radius: float = 1.0,
    minor_radius: float = 0.5,
    density: float = 1.0,
) -> ScenarioResult:
    """Spin the free torus with each method and measure how far R leaves SO(3).

    Parameters
    ----------
    t_end : float
        End time (s); long enough (default 100 s = 1000 steps) for the drift to show.
    h : float
        Step (s).
    methods : sequence of str
        Fixed-step methods to compare.
    omega0 : array_like, shape (3,)
        Initial body-frame angular velocity (rad/s).
    major_radius, minor_radius, density : float
        The torus (m, m, kg/m³); symmetry axis z, centre of mass at the origin.

    Returns
    -------
    ScenarioResult
        ``summary`` with the body (``mass``, ``inertia`` diagonal), the precession rate
        ``precession_rate`` (rad/s) and per method (``results``): ``orthogonality_error``
        (``‖RᵀR − I‖_F`` at ``t_end``), ``max_orthogonality_error``, ``error_vs_exact``
        (``‖R − R_exact‖_F`` at ``t_end``), ``energy_drift`` (largest ``|E/E₀ − 1|``) and
        ``t_reached`` (s; a method that overflows stops early and its numbers are None).
        ``data`` holds the trajectories; figures ``drift.png``, ``error_vs_exact.png`` and
        ``rotation_grid.png`` (the first :data:`GRID_SPAN` s); one dataset per method;
        ``animation.gif`` and ``view.html`` of the best-behaved method's run.

    Examples
    --------
    >>> result = run(t_end=10.0, methods=("rk4-matrix", "rkmk4"))
    >>> drift = result.summary["results"]
    >>> drift["rk4-matrix"]["orthogonality_error"] > 1e-5 > 1e-12 > drift["rkmk4"][
    ...     "orthogonality_error"]
    True
    """
    methods = method_names(methods)
    properties = mass.torus(major_radius, minor_radius, density=density)
    body = RigidBody.from_mass_properties(properties)
    runs = {method: simulate(body, t_end, method=method, h=h, omega0=omega0) for method in methods}
    exact_R = {
        method: exact.free_body_rotation(body.inertia, omega0, run.t)
        for method, run in runs.items()
    }
    summary = _summary(body, runs, exact_R, h, t_end, omega0)
    title = f"{NAME} — free torus, ω₀ = {tuple(float(w) for w in omega0)} rad/s, h = {h} s"
    shown = showcase(runs)
    mesh = meshes.torus(major_radius, minor_radius, 32, minor_sections=16)  # light for view.html
    return ScenarioResult(
        name=NAME,
        summary=summary,
        data={"trajectories": runs, "body": body},
        figures=_figures(body, runs, exact_R, title, omega0),
        attrs=rigid_attrs(body, methods=list(methods), h=h, t_end=t_end, omega0=list(omega0)),
        **rigid_outputs(runs, mesh, shown=shown, title=f"{title}, {shown}"),
    )


def precession_rate(inertia: np.ndarray, omega0: Sequence[float]) -> float:
    """Rate ``Ω = (I⊥ − I_s) ω_s / I⊥`` (rad/s) of a symmetric body's precession.

    In the body frame ``ω(t) = exp(−Ω t ẑ̃) ω(0)``: the transverse part of ω turns about the
    symmetry axis z by the angle ``−Ω t`` (Landau & Lifshitz §36).

    Parameters
    ----------
    inertia : ndarray, shape (3, 3)
        Diagonal inertia with ``I_xx = I_yy = I⊥`` and ``I_zz = I_s`` (kg m²).
    omega0 : array_like, shape (3,)
        Body angular velocity (rad/s); ``ω_s`` is its z component.

    Examples
    --------
    >>> round(precession_rate(np.diag([1.0, 1.0, 2.0]), (0.0, 0.0, 3.0)), 12)
    -3.0
    """
    perpendicular, symmetric = inertia[0, 0], inertia[2, 2]
    return float((perpendicular - symmetric) * omega0[2] / perpendicular)


def _summary(body, runs, exact_R, h, t_end, omega0) -> dict:
    results = {}
    for method, run in runs.items():
        with np.errstate(all="ignore"):  # euler may end near overflow
            error = np.linalg.norm(run.R[-1] - exact_R[method][-1])
        results[method] = {
            "t_reached": float(run.t[-1]),
            "orthogonality_error": json_number(run.orthogonality_error[-1]),
            "max_orthogonality_error": json_number(run.orthogonality_drift),
            "error_vs_exact": json_number(error),
            "energy_drift": json_number(run.energy_drift),
        }
    return {
        "scenario": NAME,
        "methods": list(runs),
        "h": h,
        "t_end": t_end,
        "omega0": [float(w) for w in omega0],
        "mass": body.mass,
        "inertia": np.diag(body.inertia).tolist(),
        "precession_rate": precession_rate(body.inertia, omega0),
        "results": results,
    }


def _figures(body, runs, exact_R, title, omega0) -> list:
    with np.errstate(all="ignore"):
        errors = [
            (method, run.t, np.linalg.norm(run.R - exact_R[method], axis=(1, 2)))
            for method, run in runs.items()
        ]
    grid = []
    for method, run in runs.items():
        shown = run.t <= run.t[0] + GRID_SPAN
        grid.append((method, run.t[shown], run.R[shown]))
    t_fine = np.linspace(0.0, min(GRID_SPAN, max(run.t[-1] for run in runs.values())), 801)
    grid.append(("exact", t_fine, exact.free_body_rotation(body.inertia, omega0, t_fine)))
    return [
        ("drift.png", partial(rigid.drift, list(runs.items()), title=title)),
        ("error_vs_exact.png", partial(rigid.error_vs_exact, errors, title=title)),
        ("rotation_grid.png", partial(rigid.rotation_grid, grid, title=title)),
    ]


def free_body() -> tuple[RigidBody, np.ndarray]:
    """The seeds' torus and ω(0) = (1, 1, 1) rad/s, for ``tumble compare torus-spin``."""
    return RigidBody.from_mass_properties(mass.torus(1.0, 0.5, density=1.0)), np.array(OMEGA0)
