"""``simulate``: one entry point for every rigid-body method."""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks
from tumble._progress import progress_bar
from tumble.ode.driver import Control, Jump, Outcome, march
from tumble.rigid import initial, overflow
from tumble.rigid.body import RigidBody
from tumble.rigid.charts import Dynamics
from tumble.rigid.forces import (
    Impulse,
    Load,
    State,
    compiled_loads,
    for_body,
    potential_energy,
    split_loads,
)
from tumble.rigid.methods import FAMILIES, Method, get_method
from tumble.rigid.pivot import centre_of_mass_motion, pivot_body, pivot_forces
from tumble.rigid.steppers import BodyStepper
from tumble.rigid.trajectory import Solution, Trajectory

if TYPE_CHECKING:
    from tumble.rigid._compiled.base import KernelProblem

log = logging.getLogger(__name__)


def problem(method: Method, inertia_inverse, mass, loads, axes, moments,
            inertia=None) -> KernelProblem:  # fmt: skip
    """The kernels' :class:`~tumble.rigid._compiled.base.KernelProblem` for ``method`` and
    constant ``loads`` (:func:`~tumble.rigid.forces.compiled_loads`); ``axes``, ``moments`` are the
    principal frame (``split`` methods; with a leading body axis in a batch), ``inertia`` the
    body's (the inverse of ``inertia_inverse`` when not given)."""
    from tumble.rigid._compiled.base import KernelProblem  # numba only for a compiled run

    if method.tableau is None:
        A, b = np.zeros((0, 0)), np.array(method.weights)
    else:
        A, b = method.tableau.A, method.tableau.b
    F, tau, points, point_forces, gravity = loads
    if inertia is None:
        inertia = np.linalg.inv(inertia_inverse)
    return KernelProblem(method.dexpinv, A, b, inertia_inverse, mass, F, tau, points, point_forces,
                   axes, moments, gravity, np.asarray(inertia, dtype=float))  # fmt: skip


def check_free(method: Method, loads) -> None:
    """The exact flow takes no continuous load: a ValueError pointing to the splittings."""
    if method.exact and loads:
        raise _checks.fail(
            "forces", [type(load).__name__ for load in loads],
            f"no continuous loads with method={method.name!r} (impulses are allowed)",
            remedy="the exact flow is the torque-free body's; with loads use 'strang' or "
            "'yoshida4' (the exact flow split with kicks of the loads, order 2 and 4)",
        )  # fmt: skip


def stepper_for(method: Method, body: RigidBody, loads, kernel_loads) -> BodyStepper:
    """The stepper of ``method``'s family (:data:`~tumble.rigid.methods.FAMILIES`): compiled
    when ``kernel_loads`` (constant loads) are given, else the NumPy reference."""
    family = FAMILIES[method.family]
    dynamics = Dynamics(body, loads)
    if kernel_loads is None:
        return family.stepper(method, dynamics, None)
    moments, axes = family.frame(body.inertia)
    kernel_problem = problem(method, body.inertia_inverse, body.mass, kernel_loads, axes, moments,
                             body.inertia)  # fmt: skip
    return family.stepper(method, dynamics, kernel_problem)


def simulate(
    body: RigidBody,
    t_end: float,
    *,
    method: str = "rkmk4",
    h: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    t0: float = 0.0,
    x0: ArrayLike | None = None,
    v0: ArrayLike | None = None,
    R0: ArrayLike | None = None,
    q0: ArrayLike | None = None,
    omega0: ArrayLike | None = None,
    L0: ArrayLike | None = None,
    forces: Sequence[Load | Impulse] = (),
    events: Sequence[Callable[[float, State], float]] = (),
    progress: bool = False,
    record_every: int = 1,
    compiled: bool | None = None,
    pivot: ArrayLike | None = None,
    t_eval: ArrayLike | None = None,
    dense_output: bool = False,
) -> Trajectory:
    """Simulate a rigid body from ``t0`` to ``t_end``.

    The state is ``(x, R, p, L)``: centre of mass, attitude (body → world), linear momentum
    and world angular momentum. The equations are

    .. math::

        \\dot x = p/m,\\quad \\dot R = R\\,\\hat\\omega,\\quad \\dot p = F,\\quad
        \\dot L = \\tau,\\qquad \\omega = I^{-1} R^T L,

    so without torque ``L`` stays exactly constant (every method steps it linearly).

    Parameters
    ----------
    body : RigidBody
        Mass and inertia.
    t_end : float
        End time (s), > ``t0``. The last step lands on it exactly.
    method : str
        A name in :data:`tumble.rigid.METHODS` (default ``"rkmk4"``); the table of
        methods, their charts, tableaux and orders is in :mod:`tumble.rigid.methods`.
    h : float
        Step (s): required for the fixed-step methods; the first step for the adaptive ones
        (``rkmk45``, ``rkmk-dopri5``; chosen from ω and rtol when omitted).
    rtol : float, optional
        Relative tolerance of the adaptive methods (default 1e-6, at least 2.2e-14); refused
        for fixed-step methods. What it measures (:func:`tumble.rigid.charts.error_norm`):
        the attitude in radians against ``rtol`` alone; x and p against ``atol + rtol |y|``;
        the body momentum ``m = Rᵀ L`` component by component against ``atol + rtol |m|``;
        each step gets its share ``h/T`` of that (error per unit step), so that ``rtol``
        bounds the run's error, not each step's. Without torque each step also keeps the
        distance to the separatrix ``Δ = |m|² − 2 E I₂`` (the free body's invariant that
        decides when a spin near the middle axis turns over) to a tenth of ``rtol |Δ|``.
        Measured (docs/rigid-body.md: the tables against scipy and the closed form), the
        attitude error at T = 100 s is within 2× rtol on the bodies there, and near the
        separatrix within rtol or within 3× the problem's own round-off floor, which there
        is far above the machine's (1.7e-6 at 1e-5 off the middle axis of diag(3, 2, 1.5)).
        Near that axis the runs take 2000–12500 steps per 100 s (scipy RK45: 230–1600).
    atol : float or array_like, shape (9,), optional
        Absolute tolerance of x (m), p (kg m/s) and L (kg m²/s), L's three in the body frame
        (components of ``Rᵀ L``); it never applies to the attitude's radians. Default:
        ``rtol`` times each part's characteristic size (:func:`tumble.rigid.initial.sizes`),
        so that it scales with rtol; a smaller atol holds the small body-frame components of
        L (a spin near a principal axis) closer. A UserWarning says when a given atol is so
        large that rtol no longer matters for any part.
    t0 : float
        Start time (s).
    x0, v0 : array_like, shape (3,), optional
        Initial position (m) and velocity (m/s) of the centre of mass; default 0.
    R0, q0 : array_like, optional
        Initial attitude as a rotation matrix (3, 3) or a quaternion ``[w, x, y, z]``
        (at most one; default identity).
    omega0, L0 : array_like, shape (3,), optional
        Initial body-frame angular velocity (rad/s) or world angular momentum (kg m²/s)
        (at most one; default at rest).
    forces : sequence
        :class:`~tumble.Gravity`, :class:`~tumble.Force`, :class:`~tumble.Torque`,
        :class:`~tumble.MagneticDipole`, :class:`~tumble.GravityGradient` (given the body's
        inertia), :class:`~tumble.Impulse` (a step lands on each impulse's time, which must
        lie within the run).
    events : sequence of callables
        ``g(t, state) -> float`` with ``terminal``/``direction`` as in :func:`tumble.solve`;
        ``state`` is a :class:`~tumble.rigid.forces.State` with ``x``, ``R``, ``p``, ``L``,
        ``omega`` (body frame) and ``q``. Crossings are located by root finding on each
        step's interpolant (as ``t_eval``); an event that is zero at ``t0`` does not fire
        there. :func:`tumble.rigid.flip_event` is the flip of an intermediate-axis spin.
    progress : bool
        Show a progress bar (rich) for long runs.
    record_every : int
        Keep every k-th step (and the last), to bound memory on long runs.
    compiled : bool, optional
        Force (True) or forbid (False) the numba kernels; by default they run whenever every
        load is a constant and there are no events, ``t_eval`` or dense output (fixed-step
        methods, and the adaptive ``lie`` methods).
    t_eval : array_like, shape (k,), optional
        Record the state at these times only (increasing, within ``[t0, t_end]``), from each
        step's interpolant: for the ``lie`` methods ``R(t) = R_n exp(û(θ))`` with the
        tableau's continuous extension (order 4 for ``rkmk45`` and ``rkmk-dopri5``), a
        rotation to round-off. Runs in Python (no compiled kernel).
    dense_output : bool
        Keep every step's interpolant: ``Trajectory.sol(t)`` gives the state at any ``t`` of
        the run. Runs in Python (no compiled kernel).
    pivot : array_like, shape (3,), optional
        A point of the body held fixed in space (body coordinates from the centre of mass, m):
        the heavy top. The body turns about it with its inertia there (parallel axis) under
        the loads' torques about it (:mod:`tumble.rigid.pivot`); ``x0`` is the initial centre
        of mass, ``v0`` must be None (it follows from ω), ``L0`` is taken about the pivot, and
        loads must be constants. The trajectory's ``x``, ``v`` and ``L_world`` are the centre
        of mass's, as without a pivot; :meth:`Trajectory.angular_momentum_about
        <tumble.rigid.trajectory.Trajectory.angular_momentum_about>` gives ``L`` about it.

    Returns
    -------
    Trajectory
        ``t``, ``x``, ``v``, ``R``, ``q``, ``omega_body``, ``L_world``, ``energy``,
        ``orthogonality_error``; ``status`` (a :class:`~tumble.ode.driver.Status`) and
        ``message`` tell how the run ended: a non-finite state stops it with
        ``Status.FAILED`` (-1), the time in the message, the last finite state kept.

    Examples
    --------
    The isotropic sphere spun about x turns by exactly ``t`` radians with ``lie-euler``:

    >>> import numpy as np
    >>> from tumble import RigidBody, simulate
    >>> run = simulate(RigidBody(1.0, np.eye(3)), 1.0, method="lie-euler", h=0.1,
    ...                omega0=(1.0, 0.0, 0.0))
    >>> len(run.t), round(float(run.R[-1, 1, 1]), 12) == round(float(np.cos(1.0)), 12)
    (11, True)
    """
    if pivot is not None:
        return _about_pivot(
            body, t_end, pivot, method=method, h=h, rtol=rtol, atol=atol, t0=t0, x0=x0, v0=v0,
            R0=R0, q0=q0, omega0=omega0, L0=L0, forces=forces, events=events, progress=progress,
            record_every=record_every, compiled=compiled, t_eval=t_eval, dense_output=dense_output,
        )  # fmt: skip
    # The inputs, checked one by one in this order (the first bad one raises); the state.
    spec = get_method(method)
    t0, t_end = initial.check_times(t0, t_end)
    h, rtol, given_atol = initial.check_steps(spec, h, rtol, atol)
    R, Y = initial.initial_state(body, x0, v0, R0, q0, omega0, L0)
    record_every = initial.check_record_every(record_every)
    progress = _checks.flag("progress", progress)
    compiled = _checks.optional_flag("compiled", compiled, remedy=COMPILED_REMEDY)
    loads, impulses = _checked_loads(spec, forces, t0, t_end)
    loads = for_body(loads, body.inertia)
    events = _checks.callables("events", events, remedy="g(t, state) with state a State")
    dense_output = _checks.flag("dense_output", dense_output)
    initial.warn_large_step(spec, h, t_end - t0, body.inertia_inverse, R, Y[6:])
    times = None if t_eval is None else _checks.sample_times("t_eval", t_eval, t0, t_end)
    control = _control(spec, body, Y, t_end - t0, rtol, given_atol)
    # The stepper, from the method's family: compiled where its loop runs these loads.
    plain = not events and times is None and not dense_output  # nothing only Python steps do
    kernel_loads = _kernel_loads(spec, loads, body.mass, compiled, plain)
    stepper = stepper_for(spec, body, loads, kernel_loads)
    settings = _settings(h, rtol, control, record_every, compiled=kernel_loads is not None)
    # The march, landing on every impulse.
    state = stepper.start((R, Y))
    jumps = _jumps(stepper, impulses, t0, t_end)
    if control is not None and h is None:
        h = _first_step(body, Y, state, jumps, t0, t_end, rtol)
    out = _march(stepper, state, (t0, t_end), h=h, control=control, jumps=jumps, events=events,
                 record_every=record_every, progress=progress, t_eval=times,
                 dense_output=dense_output)  # fmt: skip
    # The records as a Trajectory, ended at a first overflow.
    return _trajectory(out, stepper, spec, body, loads, settings)


COMPILED_REMEDY = "None runs the numba kernels where they apply (the default)"
"""What ``compiled``'s message adds."""


def _checked_loads(
    method: Method, forces, t0: float, t_end: float
) -> tuple[list[Load], list[Impulse]]:
    """``forces`` split into continuous loads and impulses (:func:`split_loads`), checked:
    a sequence (None: none), none continuous for the exact flow, every impulse within the
    run."""
    forces = _checks.items("forces", forces, "a sequence of loads and impulses")
    loads, impulses = split_loads(forces)
    check_free(method, loads)
    _check_impulse_times(forces, t0, t_end)
    return loads, impulses


def _check_impulse_times(forces, t0: float, t_end: float) -> None:
    """Every impulse within the run: one outside it would be silently ignored."""
    for index, item in enumerate(forces):
        if isinstance(item, Impulse) and not t0 <= item.time <= t_end:
            raise _checks.fail(
                f"forces[{index}].time", item.time, f"within the run, [{t0!r}, {t_end!r}]", "s",
                remedy="an impulse outside the run would never be applied",
            )  # fmt: skip


def _control(method: Method, body: RigidBody, Y, span: float, rtol: float, atol) -> Control | None:
    """An adaptive method's step control: ``rtol``, ``atol`` per part of ``Y``
    (:func:`~tumble.rigid.initial.tolerances`), each step held to its share of the ``span``;
    None for a fixed-step method."""
    if not method.adaptive:
        return None
    return Control(rtol, initial.tolerances(body, Y, span, rtol, atol), horizon=span)


def _kernel_loads(method: Method, loads, mass: float, compiled: bool | None, plain: bool):
    """The loads as the compiled loops take them (:func:`compiled_loads`), or None to step in
    Python.

    A compiled loop runs when the loads are constants, the family has a loop for the method
    (:meth:`~tumble.rigid.families.Family.compiles`) and the run asks nothing only the Python
    steps give (``plain``: no events, ``t_eval`` or dense output); ``compiled`` forces
    (True: a ValueError where none runs) or forbids (False) it.
    """
    kernel_loads = compiled_loads(loads, mass)
    runs = plain and FAMILIES[method.family].compiles(method, kernel_loads)
    if compiled and not runs:
        raise _checks.fail(
            "compiled", compiled, "False or None here",
            remedy="the compiled kernels need constant loads and no events, t_eval or dense "
            "output (and a fixed-step or a lie method)",
        )  # fmt: skip
    return kernel_loads if (runs if compiled is None else compiled) else None


def _settings(h, rtol: float, control: Control | None, record_every: int, compiled: bool) -> dict:
    """The run's settings as :attr:`Trajectory.settings
    <tumble.rigid.trajectory.Trajectory.settings>` keeps them (``h`` as given)."""
    atol = None if control is None else np.asarray(control.atol).tolist()
    return {"h": h, "rtol": rtol or None, "atol": atol, "record_every": record_every,
            "compiled": compiled}  # fmt: skip


def _jumps(stepper: BodyStepper, impulses, t0: float, t_end: float) -> list[Jump]:
    """The impulses as the driver's jumps, one per distinct time in ``[t0, t_end]``."""
    if not impulses:
        return []
    times = sorted({imp.time for imp in impulses if t0 <= imp.time <= t_end})
    return [(time, stepper.kick([imp for imp in impulses if imp.time == time])) for time in times]


def _first_step(body: RigidBody, Y, state, jumps: list[Jump], t0: float, t_end: float,
                rtol: float) -> float:  # fmt: skip
    """An adaptive run's first step when ``h`` is not given: ``0.1 rtol^(1/5) / |ω|`` with ω
    after the impulses at ``t0``, at most a tenth of the way to the first later impulse (or
    the end)."""
    first = [apply for time, apply in jumps if time == t0]
    Y_first = first[0](state)[1] if first else Y
    end = min([time for time, _ in jumps if time > t0] + [t_end])
    with np.errstate(over="ignore"):  # a spin too large for doubles: a status, later
        omega = np.linalg.norm(body.inertia_inverse @ Y_first[6:]) + 1e-12
    return min((end - t0) / 10, 0.1 * rtol ** (1 / 5) / omega)


def _march(stepper: BodyStepper, state, t_span: tuple[float, float], *, h: float | None,
           control: Control | None, jumps: list[Jump], events, record_every: int,
           progress: bool, t_eval, dense_output: bool) -> Outcome:  # fmt: skip
    """:func:`~tumble.ode.driver.march`, with the users' events as the driver's and a progress
    bar if asked."""
    t0, t_end = t_span
    # A blow-up is detected and reported as status -1, not as numpy warnings on the way.
    with (
        progress_bar(progress, t_end - t0, "simulating") as update,
        np.errstate(over="ignore", invalid="ignore"),
    ):
        return march(
            stepper, t_span, state, h=h, control=control, jumps=jumps,
            events=[stepper.event(initial.finite_event(event, index))
                    for index, event in enumerate(events)],
            record_every=record_every,
            progress=(lambda t: update(completed=t - t0)) if progress else None,
            t_eval=t_eval, dense_output=dense_output,
        )  # fmt: skip


def _trajectory(out: Outcome, stepper: BodyStepper, method: Method, body: RigidBody, loads,
                settings: dict) -> Trajectory:  # fmt: skip
    """The driver's outcome as a :class:`Trajectory`, ended at its first record that
    overflows (:func:`tumble.rigid.overflow.checked`)."""
    if not out.status.success:
        log.warning("simulate stopped early: %s", out.message)
    R_samples, Y_samples, q_samples = out.records
    sol = None
    if out.step_times is not None and out.interpolants is not None:
        sol = Solution(stepper, out.step_times, out.interpolants)
    run = Trajectory(
        t=out.t,
        x=Y_samples[:, :3],
        v=Y_samples[:, 3:6] / body.mass,
        R=R_samples,
        L_world=Y_samples[:, 6:],
        body=body,
        method=method.name,
        settings=settings,
        status=out.status,
        message=out.message,
        n_steps=out.n_steps,
        n_rejected=out.n_rejected,
        t_events=[np.array(ts, dtype=float) for ts in out.t_events],
        q_raw=q_samples if FAMILIES[method.family].quaternion else None,
        potential_energy=potential_energy(loads, Y_samples[:, :3], R_samples, body.mass),
        sol=sol,
    )
    attitudes = None if "orthogonality" in method.conserves else R_samples  # may leave SO(3)
    run = overflow.checked(run, Y_samples, attitudes, any(load.conservative for load in loads))
    if not run.status.success and out.status.success:
        log.warning("simulate stopped: %s", run.message)
    return run


def _about_pivot(body: RigidBody, t_end: float, pivot: ArrayLike, *, x0, v0, R0, q0, forces,
                 dense_output, **options) -> Trajectory:  # fmt: skip
    """``simulate`` with ``pivot``: the reduced body about it (:mod:`tumble.rigid.pivot`)."""
    if dense_output is not False:
        raise _checks.fail("dense_output", dense_output, "False with a pivot",
                           remedy="use t_eval to sample the run")  # fmt: skip
    if not isinstance(body, RigidBody):
        raise _checks.fail("body", body, "a tumble.RigidBody")
    point = _checks.array("pivot", pivot, shape=(3,), unit="m")
    if v0 is not None:
        raise _checks.fail(
            "v0", v0, "None with a pivot",
            remedy="the centre of mass moves as the body turns: v = ω × (x − x_pivot)",
        )  # fmt: skip
    loads, _ = split_loads(forces)
    check_free(get_method(options["method"]), loads)
    R_start = initial.initial_attitude(R0, q0)
    x_start = np.zeros(3) if x0 is None else _checks.array("x0", x0, shape=(3,), unit="m")
    x_pivot = x_start + R_start @ point
    reduced = pivot_body(body, point)
    run = simulate(reduced, t_end, x0=x_pivot, R0=R_start,
                   forces=pivot_forces(forces, body.mass, point, x_pivot), **options)  # fmt: skip
    x, v, L = centre_of_mass_motion(body, reduced, point, x_pivot, run.R, run.L_world)
    V = potential_energy(loads, x, run.R, body.mass)
    settings = {**run.settings, "pivot": point.tolist()}
    return dataclasses.replace(run, x=x, v=v, L_world=L, body=body, settings=settings,
                               potential_energy=V)  # fmt: skip
