"""Seed 001: a hexagonal prism at rest, hit at a vertex by an impulse, then free motion.

Seed 001 pushes its ``Prism_hexagon.stl`` (not available; tumble generates the prism) from the
outside point ``f0 = (40, 20, 10)`` towards a vertex ``f1`` of the mesh with the force
``F = f1 − f0`` for ``Δt = (5 − 0)/20 = 0.25`` s, and then lets it fly for 5 s in steps of
0.25 s by explicit Euler on the quaternion (and, in its ``sim_rk4.py``, by RK4). Its numbers
are kept, read as SI: metres, newtons, a 1 kg body. Its defects are not (SPEC §1):

* the full impulse ``J = F Δt`` acts at ``f1``: ``Δp = J`` and ``ΔL = (f1 − x_cm) × J``
  (seed 001 projected the force on the line to the centre of mass for its drawing, and its two
  listings disagree on the sign of the torque);
* the inertia is that of the prism itself (1 kg, :func:`tumble.mass.hex_prism`), not the mesh's
  inertia scaled by 0.1 by hand.

The prism here has circumradius 10 m and length 20 m along z, its centre of mass at
(50, 10, 10), which puts it where the seed's plot window (x 30–70, y and z −10–30) shows it;
``f1`` is its top vertex nearest ``f0``, (45, 18.660254, 20).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks, mass, meshes
from tumble.io import ScenarioResult
from tumble.rigid import Impulse, RigidBody, simulate
from tumble.scenarios._base import rigid_attrs, rigid_outputs, showcase
from tumble.scenarios._common import method_names
from tumble.scenarios.option_models import OptionRules
from tumble.viz import rigid

NAME = "prism-impulse"
SUMMARY = "Seed 001: a hexagonal prism hit at a vertex by an impulse, then free flight."

METHODS = ("euler", "rk4-quat", "rkmk4")
"""Seed 001's Euler and RK4 on the quaternion, and RKMK4 for comparison."""
OPTION_RULES = OptionRules(
    positive=["t_end", "h", "duration", "body_mass", "circumradius", "length"],
    three_vectors=["center", "hit_from", "vertex"],
)
"""What :func:`run`'s options must be beyond its signature: points are 3-vectors (m)."""
CENTER = (50.0, 10.0, 10.0)
"""Centre of mass of the prism (m)."""
HIT_FROM = (40.0, 20.0, 10.0)
"""Seed 001's outside point ``f0`` (m)."""


def default_vertex(center: ArrayLike, circumradius: float, length: float) -> np.ndarray:
    """The prism's top vertex at 120° about its axis: ``c + (−a/2, a√3/2, L/2)`` (m).

    Examples
    --------
    >>> default_vertex(CENTER, 10.0, 20.0).round(6)
    array([45.      , 18.660254, 20.      ])
    """
    a = circumradius
    return np.asarray(center, dtype=float) + np.array([-a / 2, a * np.sqrt(3.0) / 2, length / 2])


def _signed_distance(mesh, point: np.ndarray) -> float:
    """Distance of ``point`` outside the convex ``mesh`` (m): > 0 outside, ≤ 0 inside."""
    return float(np.max(np.einsum("ij,ij->i", point - mesh.triangles[:, 0], mesh.face_normals)))


def _check_hit(mesh, vertex: np.ndarray, hit_from: np.ndarray) -> None:
    """The hit point on the prism's surface, the outside point outside it (the prism is convex)."""
    distance = _signed_distance(mesh, vertex)
    if abs(distance) > 1e-9 * max(1.0, float(np.abs(vertex).max())):
        raise _checks.fail(
            "vertex",
            vertex.tolist(),
            "a point on the prism's surface",
            "m",
            f"it lies {distance:g} m outside it (negative: inside); pick a vertex of the mesh, "
            "e.g. the default",
        )
    if _signed_distance(mesh, hit_from) <= 0:
        raise _checks.fail(
            "hit_from", hit_from.tolist(), "a point outside the prism", "m", "it lies inside"
        )


def run(
    *,
    t_end: float = 5.0,
    h: float = 0.25,
    methods: Sequence[str] | str = METHODS,
    duration: float = 0.25,
    body_mass: float = 1.0,
    circumradius: float = 10.0,
    length: float = 20.0,
    center: ArrayLike = CENTER,
    hit_from: ArrayLike = HIT_FROM,
    vertex: ArrayLike | None = None,
) -> ScenarioResult:
    """Hit the prism at ``vertex`` with ``J = (vertex − hit_from)·duration`` and let it fly.

    Parameters
    ----------
    t_end, h : float
        End time and step (s); the seed's 5 s in 20 steps.
    methods : sequence of str
        Fixed-step methods for the free flight.
    duration : float
        How long the force ``F = vertex − hit_from`` (N) acts, the seed's ``dt`` (s).
    body_mass : float
        Mass (kg).
    circumradius, length : float
        The regular hexagonal prism (m), axis z, one vertex of the hexagon on local +x.
    center : array_like, shape (3,)
        Centre of mass at t = 0 (m).
    hit_from : array_like, shape (3,)
        The outside point ``f0`` (m).
    vertex : array_like, shape (3,), optional
        The point ``f1`` hit (m, world), on the prism's surface; default
        :func:`default_vertex`.

    Returns
    -------
    ScenarioResult
        ``summary`` with ``impulse`` J (N s), ``point`` f1, ``lever_arm`` r = f1 − x_cm (m),
        ``delta_v`` = J/m (m/s), ``delta_L`` = r × J (kg m²/s), ``energy_after`` (J, closed
        form) and, per method (``results``), ``delta_v_error`` and ``delta_L_error`` (the
        largest component difference from the closed forms), ``energy_after``,
        ``energy_drift`` (largest ``|E/E₀ − 1|`` after the hit), ``max_momentum_error``
        (``|L − L₀|``) and ``max_orthogonality_error``. Figures ``snapshots.png``,
        ``drift.png`` and ``rotation_grid.png``; one dataset per method; ``animation.gif``
        and ``view.html`` (the hit drawn as an arrow).

    Examples
    --------
    >>> result = run(methods="rkmk4")
    >>> [round(value, 6) for value in result.summary["delta_v"]]
    [1.25, -0.334936, 2.5]
    """
    methods = method_names(methods)
    center, hit_from = np.asarray(center, dtype=float), np.asarray(hit_from, dtype=float)
    mesh = meshes.hex_prism(circumradius, length, center=center)
    f1 = (
        default_vertex(center, circumradius, length)
        if vertex is None
        else np.asarray(vertex, dtype=float)
    )
    _check_hit(mesh, f1, hit_from)
    properties = mass.hex_prism(circumradius, length, mass=body_mass, center=center)
    body = RigidBody.from_mass_properties(properties)
    impulse = Impulse(point=f1, impulse=(f1 - hit_from) * duration, time=0.0)
    runs = {
        method: simulate(body, t_end, method=method, h=h, x0=center, forces=[impulse])
        for method in methods
    }
    summary = _summary(body, impulse, center, runs, h, t_end)
    title = f"{NAME} — J = {duration} s × (f1 − f0), h = {h} s"
    figures = _figures(mesh, center, hit_from, f1, runs, title)
    shown, body_mesh = showcase(runs), mesh.copy().apply_translation(-center)
    return ScenarioResult(
        NAME,
        summary,
        {"trajectories": runs, "body": body},
        figures,
        attrs=rigid_attrs(
            body, methods=list(methods), h=h, t_end=t_end, impulse=impulse.impulse.tolist()
        ),
        **rigid_outputs(
            runs, body_mesh, shown=shown, title=f"{title}, {shown}", loads=(impulse,)
        ),  # fmt: skip
    )


def _expected(body: RigidBody, impulse: Impulse, center: np.ndarray) -> dict:
    """Closed forms right after the hit from rest, with R = Id."""
    J = impulse.impulse
    lever = impulse.point - center
    delta_L = np.cross(lever, J)
    energy = 0.5 * J @ J / body.mass + 0.5 * delta_L @ body.inertia_inverse @ delta_L
    return {"J": J, "lever": lever, "dv": J / body.mass, "dL": delta_L, "energy": energy}


def _summary(body, impulse, center, runs, h, t_end) -> dict:
    expected = _expected(body, impulse, center)
    results = {}
    for method, run in runs.items():
        results[method] = {
            "delta_v_error": float(np.abs(run.v[0] - expected["dv"]).max()),
            "delta_L_error": float(np.abs(run.L_world[0] - expected["dL"]).max()),
            "energy_after": float(run.energy[0]),
            "energy_drift": run.energy_drift,
            "max_momentum_error": float(np.max(run.momentum_error)),
            "max_orthogonality_error": run.orthogonality_drift,
        }
    return {
        "scenario": NAME,
        "methods": list(runs),
        "h": h,
        "t_end": t_end,
        "mass": body.mass,
        "inertia": np.diag(body.inertia).tolist(),
        "impulse": expected["J"].tolist(),
        "point": impulse.point.tolist(),
        "lever_arm": expected["lever"].tolist(),
        "delta_v": expected["dv"].tolist(),
        "delta_L": expected["dL"].tolist(),
        "energy_after": float(expected["energy"]),
        "results": results,
    }


def _figures(mesh, center, hit_from, f1, runs, title) -> list:
    shown = "rkmk4" if "rkmk4" in runs else next(iter(runs))
    run = runs[shown]
    frames = []
    for index in sorted({0, len(run.t) // 2, len(run.t) - 1}):
        frames.append((f"{shown}, t = {run.t[index]:g} s", run.x[index], run.R[index]))
    body_vertices = mesh.vertices - center
    snapshot = partial(
        rigid.body_snapshots,
        body_vertices,
        mesh.faces,
        frames,
        title=f"{NAME} — hit at a vertex, then free flight ({shown})",
        arrow=(hit_from, f1),
        trail=run.x,
    )
    grid = [(method, trajectory.t, trajectory.R) for method, trajectory in runs.items()]
    return [
        ("snapshots.png", snapshot),
        ("drift.png", partial(rigid.drift, list(runs.items()), title=title)),
        ("rotation_grid.png", partial(rigid.rotation_grid, grid, title=title)),
    ]
