"""The user's own rigid body: a primitive, a composite or a mesh, with loads, by any method.

A scenario file with ``scenario = "rigid-body"`` runs this. Its options are checked by the
pydantic model :data:`OPTIONS`, the same whether they come from a file or from Python. The
body is described in its own coordinates (m):

* a primitive: ``{"shape": "cylinder", "radius": 0.01, "length": 0.08, "axis": "y",
  "center": [-0.01, 0, 0], "density": 6700}``, with shapes ``cylinder``, ``box``,
  ``sphere``, ``torus`` and ``hex_prism`` (:mod:`tumble.mass`, :mod:`tumble.meshes`);
* a composite: ``{"density": 6700, "parts": [...]}``, primitives or meshes added by the
  parallel-axis theorem (a part with neither ``density`` nor ``mass`` takes the
  composite's ``density``);
* a mesh file: ``{"mesh": "part.stl", "density": 2700, "scale": 0.001}``
  (:func:`tumble.meshes.from_mesh`; the mesh must be closed and outward-oriented).

The simulated body has its centre of mass ``com`` at the origin and keeps the axes of the
description (its inertia need not be diagonal). At ``t = 0`` the body stands where the
description puts it: ``x0`` defaults to ``com`` and the attitude to the identity.

Loads are constant, one row each of :data:`tumble.scenarios.loads.LOADS`: ``gravity`` (``g``
in m/s²); ``force`` (``force`` in N, world frame, at a ``point`` fixed on the body, in the
description's coordinates; default the centre of mass); ``torque`` (N m, world frame);
``magnetic-dipole`` (``moment`` in A m², body axes, in a uniform ``field`` in T, world axes);
``impulse`` (``impulse`` in N s at the world ``point`` at ``time``).

The body models are in :mod:`tumble.scenarios.bodies`; this module holds the rest of
:data:`OPTIONS` (initial state, loads, method), :func:`prepare` (the body, its loads, its
initial state and ``simulate``'s settings, built from checked options: what :func:`run`
simulates, and what a sweep's members share, :mod:`tumble.sweeps.members`) and :func:`run`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Annotated, Any, ClassVar, Union

import numpy as np
from pydantic import AfterValidator, Field, model_validator

from tumble import so3
from tumble.io import ScenarioResult
from tumble.mass import MassProperties
from tumble.rigid import (
    BatchTrajectory,
    Impulse,
    RigidBody,
    Trajectory,
    simulate,
    simulate_batch,
)
from tumble.rigid.initial import check_steps, initial_attitude
from tumble.rigid.methods import METHODS, get_method
from tumble.scenarios._base import rigid_attrs, rigid_outputs
from tumble.scenarios._common import json_number
from tumble.scenarios.bodies import Body
from tumble.scenarios.loads import SECTIONS, LoadSection, torque_free
from tumble.scenarios.schema import (
    Matrix3,
    NonNegative,
    Positive,
    PositiveInteger,
    Section,
    Text,
    Vector3,
    Vector4,
    check_table,
    custom_error,
    one_of,
    validate,
)
from tumble.viz import rigid

NAME = "rigid-body"
SUMMARY = "Your own body (primitive, composite or mesh file) with loads, from a scenario file."

# --- initial state and loads ---------------------------------------------------------------


class Initial(Section):
    """``x0`` (m), ``v0`` (m/s); attitude ``R0``, ``q0`` or ``euler_zyx`` (rad); ``omega0``
    (rad/s, body) or ``L0`` (kg m²/s, world)."""

    what: ClassVar[str] = "a key of [options.initial]"
    x0: Vector3 | None = None
    v0: Vector3 | None = None
    R0: Matrix3 | None = None
    q0: Vector4 | None = None
    euler_zyx: Vector3 | None = None
    omega0: Vector3 | None = None
    L0: Vector3 | None = None

    @model_validator(mode="after")
    def _consistent(self) -> Initial:
        for group in (("R0", "q0", "euler_zyx"), ("omega0", "L0")):
            given = [name for name in group if getattr(self, name) is not None]
            if len(given) > 1:
                raise custom_error(
                    "whole_exclusive",
                    "give at most one of {group} (they set the same thing); got {given}",
                    group=", ".join(group),
                    given=" and ".join(given),
                )
        check_table(self.attitude)
        return self

    def attitude(self) -> np.ndarray:
        """The initial rotation matrix (body to world)."""
        if self.euler_zyx is not None:
            return so3.matrix_from_euler_zyx(self.euler_zyx)
        return initial_attitude(self.R0, self.q0)


if TYPE_CHECKING:
    Load = LoadSection
else:  # one of the sections, told apart by their type
    Load = Annotated[Union[tuple(SECTIONS.values())], Field(discriminator="type")]  # noqa: UP007
"""A load table of the file: one of :data:`tumble.scenarios.loads.SECTIONS`, by ``type``."""


class Options(Section):
    """The options of :func:`run`; defaults as there."""

    what: ClassVar[str] = f"an option of scenario {NAME!r}"
    body: Body
    initial: Initial = Initial()
    loads: list[Load] = []
    method: Annotated[Text, AfterValidator(one_of(list(METHODS)))] = "rkmk4"
    h: Positive | None = 0.01
    rtol: Positive | None = None
    atol: NonNegative | None = None
    t_end: Positive = 10.0
    record_every: PositiveInteger = 1

    @model_validator(mode="after")
    def _consistent(self) -> Options:
        check_table(lambda: check_steps(get_method(self.method), self.h, self.rtol, self.atol))
        for index, load in enumerate(self.loads):
            time = getattr(load, "time", 0.0)  # a kick's, the only load at one instant
            if time > self.t_end:
                raise custom_error(
                    "whole_late",
                    "loads[{index}].time = {time} is after t_end = {t_end}; the impulse "
                    "would never act",
                    index=index,
                    time=time,
                    t_end=self.t_end,
                )
        return self


OPTIONS = Options
"""The options model :func:`tumble.scenarios.files.check_options` uses for this scenario."""

# --- a run, prepared -------------------------------------------------------------------------


@dataclass(frozen=True)
class Preparation:
    """A run of checked options, ready to simulate: the body, its loads, its initial state.

    Attributes
    ----------
    options : Options
        The checked options.
    properties : tumble.mass.MassProperties
        The described body's mass, centre of mass ``com`` (m, the description's
        coordinates) and inertia about it (kg m², body axes).
    body : RigidBody
        The simulated body (centre of mass at the origin of its frame).
    forces : list
        The loads, built (:mod:`tumble.rigid.forces`; points relative to the centre of mass).
    start : dict
        ``simulate``'s initial state: ``x0`` (m; the centre of mass unless given), ``v0``,
        ``R0`` (from ``R0``, ``q0`` or ``euler_zyx``), ``omega0``, ``L0`` (None: not given).
    """

    options: Options
    properties: MassProperties
    body: RigidBody
    forces: list
    start: dict[str, Any]

    @property
    def com(self) -> np.ndarray:
        """The centre of mass in the description's coordinates (m), shape (3,)."""
        return np.asarray(self.properties.com)

    @property
    def batchable(self) -> bool:
        """Whether runs from other initial states can share one ``simulate_batch`` call: a
        fixed-step method under constant loads (no impulse, no callable load)."""
        constant = all(getattr(load, "compiled", False) for load in self.forces)
        impulses = any(isinstance(load, Impulse) for load in self.forces)
        return not get_method(self.options.method).adaptive and constant and not impulses

    def simulate(self, **start: Any) -> Trajectory:
        """:func:`~tumble.rigid.simulate` from :attr:`start`, entries of ``start`` replaced."""
        o = self.options
        return simulate(self.body, o.t_end, method=o.method, h=o.h, rtol=o.rtol, atol=o.atol,
                        forces=self.forces, record_every=o.record_every,
                        **{**self.start, **start})  # fmt: skip

    def simulate_batch(self, **starts: Any) -> BatchTrajectory:
        """:func:`~tumble.rigid.simulate_batch` from per-run initial states (arrays of rows:
        ``x0``, ``v0``, ``R0``, ``omega0``, ``L0``; only when :attr:`batchable`)."""
        o = self.options
        return simulate_batch(self.body, o.t_end, method=o.method, h=o.h, forces=self.forces,
                              record_every=o.record_every, **starts)  # fmt: skip


def prepare(options: Options) -> Preparation:
    """The body, loads and initial state of checked ``options`` (:func:`run` simulates them).

    Examples
    --------
    >>> options = validate(Options, {"body": {"shape": "sphere", "radius": 0.1, "mass": 1.0},
    ...                              "initial": {"omega0": [0.0, 0.0, 2.0]}})
    >>> ready = prepare(options)
    >>> ready.start["x0"].tolist(), ready.start["omega0"], ready.batchable
    ([0.0, 0.0, 0.0], [0.0, 0.0, 2.0], True)
    """
    properties = options.body.mass_properties()
    com = np.asarray(properties.com)
    start = options.initial
    return Preparation(
        options=options,
        properties=properties,
        body=RigidBody.from_mass_properties(properties),
        forces=[load.build(com) for load in options.loads],
        start={
            "x0": com if start.x0 is None else start.x0,
            "v0": start.v0,
            "R0": start.attitude(),
            "omega0": start.omega0,
            "L0": start.L0,
        },
    )


# --- the run ---------------------------------------------------------------------------------


def run(
    *,
    body: dict[str, Any],
    initial: dict[str, Any] | None = None,
    loads: list[dict[str, Any]] | tuple = (),
    method: str = "rkmk4",
    h: float | None = 0.01,
    rtol: float | None = None,
    atol: float | None = None,
    t_end: float = 10.0,
    record_every: int = 1,
) -> ScenarioResult:
    """Simulate the described body from ``t = 0`` to ``t_end``.

    Parameters
    ----------
    body : dict
        A primitive, a composite or a mesh file (module docstring; keys with units in
        ``docs/scenario-files.md``).
    initial : dict, optional
        ``x0`` (m; default the centre of mass), ``v0`` (m/s), one of ``R0`` (3×3), ``q0``
        (``[w, x, y, z]``) or ``euler_zyx`` (``[φ_z, θ_y, ψ_x]``, rad), one of ``omega0``
        (rad/s, body frame) or ``L0`` (kg m²/s, world frame).
    loads : list of dict
        Each with a ``type`` of :data:`tumble.scenarios.loads.LOADS` (``"gravity"``,
        ``"force"``, ``"torque"``, ``"magnetic-dipole"``, ``"impulse"``) and its keys.
    method : str
        A :data:`tumble.rigid.METHODS` name.
    h : float or None
        Step (s); the first step for ``rkmk45``.
    rtol, atol : float, optional
        Tolerances of ``rkmk45``.
    t_end : float
        End time (s).
    record_every : int
        Keep every k-th step (and the last).

    Returns
    -------
    ScenarioResult
        ``summary``: ``body`` (what it is), ``mass`` (kg), ``com`` (m, description's
        coordinates), ``inertia`` (kg m², about the centre of mass, body axes),
        ``principal_moments``, the settings, ``status``/``message``, ``n_steps``, the
        ``final`` state (``t``, ``x``, ``v``, ``R``, ``q``, ``omega_body``, ``L_world``,
        ``energy``), ``energy_drift`` (largest ``|E − E₀|/E₀``), ``momentum_drift``
        (largest ``|L − L₀|/|L₀|``; each None when its reference is zero),
        ``max_orthogonality_error`` and ``conserved`` (whether the loads leave energy and
        angular momentum constant, so the drifts measure the method's error). Figures
        ``rotation_grid.png``, ``euler_angles.png``, ``angular_velocity.png``,
        ``drift.png``, ``snapshots.png``; the trajectory and the mesh as datasets;
        ``animation.gif`` and ``view.html``.

    Raises
    ------
    ValueError
        Naming the key path (``body.parts[1].radius``), the bad value and what is allowed.

    Examples
    --------
    A sphere spun about z turns at constant rate (no loads):

    >>> result = run(body={"shape": "sphere", "radius": 0.1, "density": 1000.0},
    ...              initial={"omega0": [0.0, 0.0, 2.0]}, t_end=1.0, h=0.1)
    >>> round(result.summary["final"]["omega_body"][2], 12), result.summary["conserved"]
    (2.0, {'energy': True, 'angular_momentum': True})
    """
    given = {
        "body": body,
        "initial": {} if initial is None else initial,
        "loads": list(loads),
        "method": method,
        "h": h,
        "rtol": rtol,
        "atol": atol,
        "t_end": t_end,
        "record_every": record_every,
    }
    options = validate(Options, given)
    ready = prepare(options)
    properties, rigid_body, forces, com = ready.properties, ready.body, ready.forces, ready.com
    surface = options.body.surface().apply_translation(-com)
    trajectory = ready.simulate()
    summary = _summary(options, properties, trajectory, forces)
    title = f"{NAME}: {options.body.label()} — {_setting(options)}"
    return ScenarioResult(
        name=NAME,
        summary=summary,
        data={"trajectory": trajectory, "body": rigid_body, "mesh": surface, "options": options},
        figures=_figures(trajectory, surface, title, summary["conserved"]),
        attrs=rigid_attrs(
            rigid_body,
            method=options.method,
            h=options.h,
            rtol=options.rtol,
            atol=options.atol,
            t_end=options.t_end,
            body_kind=options.body.label(),
            com=com.tolist(),
        ),
        **rigid_outputs({options.method: trajectory}, surface, title=title, loads=tuple(forces)),
    )


def _setting(options: Options) -> str:
    if get_method(options.method).adaptive:
        return f"{options.method}, rtol = {options.rtol or 1e-6:g}"
    return f"{options.method}, h = {options.h:g} s"


def _conserved(forces: list) -> dict[str, bool]:
    """Whether energy and angular momentum stay constant under ``forces`` after ``t = 0``:
    the energy ``T + V`` when every continuous load has a potential, the angular momentum
    when none exerts a torque (:data:`tumble.scenarios.loads.LOADS`); a kick after the
    start changes both."""
    late_kick = any(isinstance(load, Impulse) and load.time > 0 for load in forces)
    continuous = [load for load in forces if not isinstance(load, Impulse)]
    return {
        "energy": all(load.conservative for load in continuous) and not late_kick,
        "angular_momentum": all(map(torque_free, continuous)) and not late_kick,
    }


def _summary(options: Options, properties, trajectory: Trajectory, forces: list) -> dict:
    moments, _ = properties.principal()
    final = {
        "t": float(trajectory.t[-1]),
        "x": trajectory.x[-1].tolist(),
        "v": trajectory.v[-1].tolist(),
        "R": trajectory.R[-1].tolist(),
        "q": trajectory.q[-1].tolist(),
        "omega_body": trajectory.omega_body[-1].tolist(),
        "L_world": trajectory.L_world[-1].tolist(),
        "energy": float(trajectory.energy[-1]),
    }
    return {
        "scenario": NAME,
        "body": options.body.label(),
        "mass": float(properties.mass),
        "com": np.asarray(properties.com).tolist(),
        "inertia": np.asarray(properties.inertia).tolist(),
        "principal_moments": moments.tolist(),
        "loads": [load.type for load in options.loads],
        "method": options.method,
        "h": options.h,
        "rtol": options.rtol,
        "atol": options.atol,
        "t_end": options.t_end,
        "status": trajectory.status,
        "message": trajectory.message,
        "n_steps": trajectory.n_steps,
        "final": final,
        "energy_drift": json_number(trajectory.energy_drift),  # None if E₀ = 0
        "momentum_drift": json_number(trajectory.momentum_drift),  # None if L₀ = 0
        "max_orthogonality_error": trajectory.orthogonality_drift,
        "conserved": _conserved(forces),
    }


def _figures(trajectory: Trajectory, surface, title: str, conserved: dict[str, bool]) -> list:
    label, t = trajectory.method, trajectory.t
    changing = [name.replace("_", " ") for name, kept in conserved.items() if not kept]
    note = f"\n(the loads change the {' and '.join(changing)})" if changing else ""
    drift_title = title + note
    omega0 = ", ".join(f"{w:.3g}" for w in trajectory.omega_body[0])
    rates = f"{label}, ω₀ = ({omega0}) rad/s"
    moments = sorted({0, len(t) // 2, len(t) - 1})
    frames = [(f"t = {t[k]:g} s", trajectory.x[k], trajectory.R[k]) for k in moments]
    return [
        (
            "rotation_grid.png",
            partial(rigid.rotation_grid, [(label, t, trajectory.R)], title=title),
        ),
        (
            "euler_angles.png",
            partial(rigid.euler_angles, [(label, t, trajectory.euler_zyx())], title=title),
        ),
        (
            "angular_velocity.png",
            partial(rigid.angular_velocity, [(rates, t, trajectory.omega_body)], title=title),
        ),
        ("drift.png", partial(rigid.drift, [(label, trajectory)], title=drift_title)),
        (
            "snapshots.png",
            partial(
                rigid.body_snapshots,
                np.asarray(surface.vertices),
                np.asarray(surface.faces),
                frames,
                title=title,
                trail=trajectory.x,
            ),
        ),
    ]
