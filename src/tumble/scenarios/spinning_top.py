"""The heavy symmetric top: precession and nutation about a fixed pivot.

A steel top (a disc on an axle) stands on the tip of its axle, tilted from the vertical and
spun fast about its symmetry axis, then let go: gravity's torque about the tip makes the axis
precess about the vertical while it nods up and down (nutation). The symmetric (Lagrange) top
keeps three quantities: the energy, ``L_z`` (the vertical component of the angular momentum
about the tip) and ``L₃`` (its component along the symmetry axis); and its nutation angle θ
stays between two bounds, the roots of the classical cubic in ``u = cos θ``

.. math:: \\dot u^2 = (1 - u^2)\\,\\frac{2}{I_1'}\\,(E' - m g \\ell u)
          - \\Bigl(\\frac{L_z - L_3 u}{I_1'}\\Bigr)^2, \\qquad
          E' = E - \\frac{L_3^2}{2 I_3},

with ``I₁' = I₁ + m ℓ²`` about the tip and ℓ the tip's distance to the centre of mass
(Goldstein §5.7; Landau–Lifshitz §35). The scenario runs the top with each method through
``simulate(..., pivot=tip)`` and reports how well each keeps the three invariants and the
bounds.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial

import numpy as np

from tumble import _checks, mass, meshes, so3
from tumble.io import ScenarioResult
from tumble.rigid import Gravity, RigidBody, simulate
from tumble.scenarios._base import rigid_attrs, rigid_outputs, showcase
from tumble.scenarios._common import json_number, method_names
from tumble.scenarios.option_models import OptionRules

NAME = "spinning-top"
SUMMARY = "A heavy symmetric top on its tip: precession and nutation between the classical bounds."

METHODS = ("yoshida4", "rkmk4")
OPTION_RULES = OptionRules(positive=["t_end", "h", "density"])
"""What :func:`run`'s options must be beyond its signature (the tilt and spin are checked by
:func:`run`)."""
"""The methods compared by default: splitting on the exact flow, and RKMK4."""
G = 9.81
"""Gravity (m/s², along −z)."""
DISC_RADIUS, DISC_THICKNESS, DISC_HEIGHT = 0.04, 0.008, 0.04
"""The disc (m): radius, thickness, and its centre's height above the tip."""
AXLE_RADIUS, AXLE_LENGTH = 0.003, 0.06
"""The axle (m), from the tip up."""


def top(density: float) -> tuple[RigidBody, np.ndarray, object]:
    """The top: its body, the tip in body coordinates (from the centre of mass), its mesh."""
    disc = mass.cylinder(DISC_RADIUS, DISC_THICKNESS, density=density,
                         center=(0.0, 0.0, DISC_HEIGHT))  # fmt: skip
    axle = mass.cylinder(AXLE_RADIUS, AXLE_LENGTH, density=density,
                         center=(0.0, 0.0, AXLE_LENGTH / 2))  # fmt: skip
    whole = disc + axle
    com = np.asarray(whole.com)
    import trimesh

    mesh = trimesh.util.concatenate([
        meshes.cylinder(DISC_RADIUS, DISC_THICKNESS, 48, center=(0.0, 0.0, DISC_HEIGHT)),
        meshes.cylinder(AXLE_RADIUS, AXLE_LENGTH, 12, center=(0.0, 0.0, AXLE_LENGTH / 2)),
    ])  # fmt: skip
    mesh.apply_translation(-com)
    body = RigidBody.from_mass_properties(whole.translated(-com))
    return body, 0.0 - com, mesh  # 0.0 −: no −0.0 in summary.json


def classical_bounds(body: RigidBody, tip: np.ndarray, energy: float, L_z: float,
                     L_3: float) -> np.ndarray:  # fmt: skip
    """The nutation bounds ``(θ_min, θ_max)`` in rad: the roots of the cubic (module
    docstring) in [−1, 1]. ``energy`` is taken with the tip at height 0."""
    I1, I3 = body.inertia[0, 0], body.inertia[2, 2]
    ell = float(np.linalg.norm(tip))
    I1p = I1 + body.mass * ell**2
    reduced = energy - L_3**2 / (2.0 * I3)
    P = np.polynomial.Polynomial
    cubic = (
        P([1.0, 0.0, -1.0]) * P([2 * reduced / I1p, -2 * body.mass * G * ell / I1p])
        - P([L_z / I1p, -L_3 / I1p]) ** 2
    )
    roots = cubic.roots()
    real = np.sort(roots[np.abs(roots.imag) < 1e-9].real)
    u = real[(real >= -1.0 - 1e-12) & (real <= 1.0 + 1e-12)]
    return np.arccos(np.clip(u[::-1], -1.0, 1.0))  # θ grows as u falls


def run(
    *,
    t_end: float = 5.0,
    h: float = 0.001,
    methods: Sequence[str] | str = METHODS,
    tilt: float = 0.3,
    spin: float = 100.0,
    density: float = 7800.0,
) -> ScenarioResult:
    """Let the top go, tilted and spinning, and follow its precession and nutation.

    Parameters
    ----------
    t_end : float
        End time (s).
    h : float
        Step (s).
    methods : sequence of str
        Fixed-step methods of :data:`tumble.rigid.METHODS` that take loads.
    tilt : float
        Initial angle between the axis and the vertical (rad), in (0, π).
    spin : float
        Initial spin about the symmetry axis (rad/s); the top starts with no other motion.
    density : float
        Steel by default (kg/m³).

    Returns
    -------
    ScenarioResult
        ``summary``: the top (``mass``, ``inertia``, ``tip``), the classical nutation bounds
        ``theta_bounds_deg`` and per method (``results``): ``energy_drift``, ``L_z_drift``
        and ``L_3_drift`` (largest change relative to the start), ``theta_range_deg``
        (smallest and largest θ reached) and ``precession_rate`` (mean, rad/s). Figures
        ``top.png`` (θ(t) with its bounds; the axis tip seen from above, over the first turn
        of the precession) and ``invariants.png`` (the three invariants against time);
        one dataset per method; ``animation.gif`` and ``view.html`` of the first method's run.

    Examples
    --------
    >>> result = run(t_end=0.5, methods=("yoshida4",))
    >>> r = result.summary["results"]["yoshida4"]
    >>> r["L_z_drift"] < 1e-13, r["energy_drift"] < 1e-9
    (True, True)
    """
    methods = method_names(methods)
    if not 0.0 < _checks.finite("tilt", tilt, "rad") < np.pi:
        raise _checks.fail("tilt", tilt, "in (0, pi)", "rad", "0 is the sleeping top")
    _checks.finite("spin", spin, "rad/s")
    body, tip, mesh = top(_checks.positive("density", density, "kg/m³"))
    R0 = so3.exp([tilt, 0.0, 0.0])
    runs = {
        method: simulate(
            body,
            t_end,
            method=method,
            h=h,
            R0=R0,
            omega0=(0.0, 0.0, spin),
            pivot=tip,
            forces=[Gravity((0.0, 0.0, -G))],
        )  # fmt: skip
        for method in methods
    }
    x_tip = R0 @ tip
    first = next(iter(runs.values()))
    L_tip = first.angular_momentum_about(x_tip)[0]
    energy = float(first.energy[0] - body.mass * G * x_tip[2])  # the tip at height 0
    bounds = classical_bounds(body, tip, energy, float(L_tip[2]),
                              float((R0.T @ L_tip)[2]))  # fmt: skip
    summary = _summary(body, tip, runs, x_tip, bounds, h=h, t_end=t_end, tilt=tilt, spin=spin)
    title = f"{NAME} — tilt {tilt} rad, spin {spin} rad/s, h = {h} s"
    shown = next(iter(runs)) if runs else showcase(runs)
    return ScenarioResult(
        name=NAME,
        summary=summary,
        data={"trajectories": runs, "body": body, "tip": tip},
        figures=_figures(runs, np.degrees(bounds), title, summary, x_tip),
        attrs=rigid_attrs(
            body, methods=list(methods), h=h, t_end=t_end, tilt=tilt, spin=spin, tip=tip.tolist()
        ),  # fmt: skip
        **rigid_outputs(runs, mesh, shown=shown, title=f"{title}, {shown}"),
    )


def _drift(values: np.ndarray) -> float | None:
    scale = float(np.abs(values[0]))
    with np.errstate(all="ignore"):
        return json_number(np.abs(values - values[0]).max() / scale) if scale else None


def _summary(body, tip, runs, x_tip, bounds, **settings) -> dict:
    results = {}
    for method, run in runs.items():
        L_tip = run.angular_momentum_about(x_tip)
        L_3 = np.einsum("nji,nj->ni", run.R, L_tip)[:, 2]
        axis = run.R[:, :, 2]
        theta = np.degrees(np.arccos(np.clip(axis[:, 2], -1.0, 1.0)))
        azimuth = np.unwrap(np.arctan2(axis[:, 1], axis[:, 0]))
        span = float(run.t[-1] - run.t[0])
        results[method] = {
            "t_reached": float(run.t[-1]),
            "energy_drift": json_number(run.energy_drift),
            "L_z_drift": _drift(L_tip[:, 2]),
            "L_3_drift": _drift(L_3),
            "theta_range_deg": [json_number(theta.min()), json_number(theta.max())],
            "precession_rate": json_number((azimuth[-1] - azimuth[0]) / span) if span else None,
        }
    return {
        "scenario": NAME,
        "methods": list(runs),
        **settings,
        "mass": body.mass,
        "inertia": np.diag(body.inertia).tolist(),
        "tip": tip.tolist(),
        "theta_bounds_deg": np.degrees(bounds).tolist(),
        "results": results,
    }


def _figures(runs, bounds_deg, title, summary, x_tip) -> list:
    from tumble.viz import top

    rate = summary["results"][next(iter(runs))]["precession_rate"] if runs else None
    window = 2.0 * np.pi / abs(rate) if rate else None  # one turn of the precession
    first_turn = f"{title}\nthe first turn of the precession ({window:.2f} s)" if window else title
    return [
        (
            "top.png",
            partial(
                top.top_motion,
                list(runs.items()),
                list(bounds_deg),
                title=first_turn,
                window=window,
            ),
        ),  # fmt: skip
        ("invariants.png", partial(top.top_invariants, list(runs.items()), x_tip, title=title)),
    ]
