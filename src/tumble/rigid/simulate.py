"""``simulate``: one entry point for every rigid-body method."""

from __future__ import annotations

import logging

import numpy as np

from tumble import so3
from tumble._progress import progress_bar
from tumble.ode.control import StepController, error_norm, minimum_step
from tumble.ode.events import EventTracker
from tumble.ode.solve import fixed_step_count
from tumble.rigid import initial
from tumble.rigid.body import RigidBody
from tumble.rigid.forces import State, compiled_loads, split_loads
from tumble.rigid.methods import Method, get_method
from tumble.rigid.steppers import Dynamics, step
from tumble.rigid.trajectory import Trajectory

log = logging.getLogger(__name__)
_CHART_SCALE = np.ones(3)  # the Lie-algebra error is in radians, measured against 1


class _Run:
    """The current state of one simulation and its record (blocks of samples)."""

    def __init__(self, method: Method, dynamics: Dynamics, t, R, Y, record_every: int):
        self.method, self.dynamics, self.record_every = method, dynamics, record_every
        self.t, self.Y = t, Y
        self.attitude = so3.quat_from_matrix(R) if method.family == "quat" else R
        self.n_steps = self.n_rejected = 0
        self.status, self.message = 0, "The simulation reached t_end."
        self.blocks: list[tuple] = []
        self.record()

    @property
    def R(self) -> np.ndarray:
        return _matrix(self, self.attitude)

    def extend(self, t, R, Y, q) -> None:
        """Append recorded samples: t (k,), R (k, 3, 3), Y (k, 9), q (k, 4) or None."""
        if len(t):
            self.blocks.append((t, R, Y, q))

    def record(self) -> None:
        """Record the current state (replacing a sample at the same time, e.g. before a kick)."""
        if self.blocks and self.blocks[-1][0][-1] == self.t:
            self.blocks[-1] = tuple(None if a is None else a[:-1] for a in self.blocks[-1])
        q = self.attitude[None] if self.method.family == "quat" else None
        self.extend(np.array([self.t]), self.R[None], self.Y[None], q)

    def fail_non_finite(self, t_old: float, t_new: float) -> None:
        self.status = -1
        self.message = (
            f"the state became non-finite (nan or inf) in the step from t={t_old!r} to "
            f"t={t_new!r}; the trajectory ends with the last finite state"
        )

    def advance(self, t_new: float, attitude, Y) -> bool:
        """Accept a step; False (and status -1) if the new state is not finite."""
        if not (np.all(np.isfinite(attitude)) and np.all(np.isfinite(Y))):
            self.fail_non_finite(self.t, t_new)
            return False
        self.t, self.attitude, self.Y = t_new, attitude, Y
        self.n_steps += 1
        if self.n_steps % self.record_every == 0:
            self.record()
        return True

    def kick(self, impulses) -> None:
        """Apply impulses at the current time: ``Δp = J``, ``ΔL = (point − x) × J``."""
        for impulse in impulses:
            dp, dL = impulse.kick(self.Y[:3])
            self.Y = self.Y + np.concatenate([np.zeros(3), dp, dL])
        if impulses:
            self.record()

    def trajectory(self, body: RigidBody, settings: dict, t_events) -> Trajectory:
        if not self.blocks or self.blocks[-1][0][-1] != self.t:
            self.record()
        t, R, Y, q = (
            None if self.blocks[0][i] is None else np.concatenate([b[i] for b in self.blocks])
            for i in range(4)
        )
        return Trajectory(
            t=t,
            x=Y[:, :3],
            v=Y[:, 3:6] / body.mass,
            R=R,
            L_world=Y[:, 6:],
            body=body,
            method=self.method.name,
            settings=settings,
            status=self.status,
            message=self.message,
            n_steps=self.n_steps,
            n_rejected=self.n_rejected,
            t_events=t_events,
            q_raw=q,
        )


def _flat(R, Y) -> np.ndarray:
    return np.concatenate([R.ravel(), Y])


def _wrap_event(event):
    def g(t, z):
        return event(t, State(z[9:12], z[:9].reshape(3, 3), z[12:15], z[15:]))

    g.terminal = getattr(event, "terminal", False)
    g.direction = getattr(event, "direction", 0)
    return g


class _Events:
    """User events ``g(t, state)``, located by re-stepping from the last accepted state."""

    def __init__(self, events, run: _Run):
        wrapped = [_wrap_event(event) for event in events]
        self.tracker = EventTracker(wrapped, run.t, _flat(run.R, run.Y))

    def check(self, run: _Run, t_old, attitude_old, Y_old, t_new) -> bool:
        """After a step: record crossings; on a terminal one move ``run`` there, True."""

        def sol(t):
            if t == t_old:
                return _flat(_matrix(run, attitude_old), Y_old)
            attitude, Y, _ = step(run.dynamics, run.method, t_old, attitude_old, Y_old, t - t_old)
            return _flat(_matrix(run, attitude), Y)

        t_stop = self.tracker.update(t_old, t_new, _flat(run.R, run.Y), sol)
        if t_stop is None:
            return False
        z = sol(t_stop)
        R = z[:9].reshape(3, 3)
        run.t, run.Y = t_stop, z[9:]
        run.attitude = so3.quat_from_matrix(R) if run.method.family == "quat" else R
        run.status, run.message = 1, "A terminal event occurred."
        return True


def _matrix(run: _Run, attitude) -> np.ndarray:
    return so3.matrix_from_quat(attitude) if run.method.family == "quat" else attitude


def _fixed_segment(run: _Run, b: float, h: float, events) -> bool:
    a = run.t
    n = fixed_step_count(a, b, h)
    for k in range(1, n + 1):
        t_old, attitude_old, Y_old = run.t, run.attitude, run.Y
        t_new = b if k == n else a + k * h
        attitude, Y, _ = step(run.dynamics, run.method, t_old, attitude_old, Y_old, t_new - t_old)
        if not run.advance(t_new, attitude, Y):
            return False
        if events is not None and events.check(run, t_old, attitude_old, Y_old, t_new):
            return False
    return True


def _adaptive_segment(run: _Run, b: float, h: float, rtol: float, atol: float, events):
    controller, order = StepController(), run.method.tableau.error_order
    rejected = False
    while run.t < b:
        t_old, attitude_old, Y_old = run.t, run.attitude, run.Y
        t_new = min(t_old + max(h, minimum_step(t_old)), b)
        attitude, Y, error = step(
            run.dynamics, run.method, t_old, attitude_old, Y_old, t_new - t_old
        )
        scale_old = np.concatenate([_CHART_SCALE, Y_old])
        norm = error_norm(error, scale_old, np.concatenate([_CHART_SCALE, Y]), rtol, atol)
        accepted, h = controller.propose(t_new - t_old, norm, order, after_rejection=rejected)
        rejected = not accepted
        if not accepted:
            run.n_rejected += 1
            if h < minimum_step(t_old):
                run.status = -1
                run.message = f"step size fell below the minimum at t={t_old!r}"
                return False, h
            continue
        if not run.advance(t_new, attitude, Y):
            return False, h
        if events is not None and events.check(run, t_old, attitude_old, Y_old, t_new):
            return False, h
    return True, h


def _segments(t0: float, t_end: float, impulses):
    """Split ``[t0, t_end]`` at the impulses' times: ``[(a, b, kicks at a), ...]``."""
    times = sorted({imp.time for imp in impulses if t0 <= imp.time <= t_end} | {t0, t_end})
    segments = []
    for a, b in zip(times[:-1], times[1:], strict=True):
        segments.append((a, b, [imp for imp in impulses if imp.time == a]))
    finals = [imp for imp in impulses if imp.time == t_end]
    return segments, finals


def _integrate(run: _Run, t_end, h, rtol, atol, impulses, events, loads, progress):
    """Integrate segment by segment (split at impulses); return the event times."""
    tracker = _Events(events, run) if events else None
    segments, finals = _segments(run.t, t_end, impulses)
    t0 = run.t
    with progress_bar(progress, t_end - t0, "simulating") as update:

        def advance(t: float) -> None:
            update(completed=t - t0)

        for a, b, kicks in segments:
            run.kick(kicks)
            if loads is not None:
                from tumble.rigid.kernels import run_segment

                going = run_segment(run, b, h, loads, advance if progress else None)
            elif run.method.adaptive:
                h = h or _first_step(b - a, run.Y, run.dynamics.body, rtol)
                going, h = _adaptive_segment(run, b, h, rtol, atol, tracker)
            else:
                going = _fixed_segment(run, b, h, tracker)
            advance(run.t)
            if not going:
                break
        else:
            run.kick(finals)
    return tracker.tracker.results(18)[0] if tracker else []


def _first_step(t_span: float, Y, body: RigidBody, rtol: float) -> float:
    omega = np.linalg.norm(body.inertia_inverse @ Y[6:]) + 1e-12
    return min(t_span / 10, 0.1 * rtol ** (1 / 5) / omega)


def simulate(
    body: RigidBody,
    t_end: float,
    *,
    method: str = "rkmk4",
    h: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    t0: float = 0.0,
    x0=None,
    v0=None,
    R0=None,
    q0=None,
    omega0=None,
    L0=None,
    forces=(),
    events=(),
    progress: bool = False,
    record_every: int = 1,
    compiled: bool | None = None,
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
        ``"euler"``, ``"lie-euler"``, ``"rk4-matrix"``, ``"rk4-quat"``, ``"seed-rk4"``,
        ``"rkmk4"`` (default), ``"rkmk8"`` (order 8) or ``"rkmk45"`` (adaptive); see
        :mod:`tumble.rigid.methods`.
    h : float
        Step (s): required for the fixed-step methods; the first step for ``rkmk45``.
    rtol, atol : float, optional
        Tolerances of ``rkmk45`` (default 1e-6, 1e-9); refused for fixed-step methods.
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
        :class:`~tumble.Impulse` (a step lands on each impulse's time).
    events : sequence of callables
        ``g(t, state) -> float`` with ``terminal``/``direction`` as in :func:`tumble.solve`;
        ``state`` is a :class:`~tumble.rigid.forces.State`.
    progress : bool
        Show a progress bar (rich) for long runs.
    record_every : int
        Keep every k-th step (and the last), to bound memory on long runs.
    compiled : bool, optional
        Force (True) or forbid (False) the numba kernels; by default they run whenever the
        method has a fixed step, every load is a constant and there are no events.

    Returns
    -------
    Trajectory
        ``t``, ``x``, ``v``, ``R``, ``q``, ``omega_body``, ``L_world``, ``energy``,
        ``orthogonality_error``; ``status``/``message`` tell how the run ended (a non-finite
        state stops it with ``status = -1`` and the time in the message).

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
    spec = get_method(method)
    t0, t_end = initial.check_times(t0, t_end)
    h, rtol, atol = initial.check_steps(spec, h, rtol, atol)
    R, Y = initial.initial_state(body, x0, v0, R0, q0, omega0, L0)
    if not (isinstance(record_every, int | np.integer) and record_every >= 1):
        raise ValueError(f"record_every={record_every!r} must be a positive integer")
    loads, impulses = split_loads(forces)
    events = list(events)
    kernel_loads = compiled_loads(loads, body.mass)
    use_kernel = not spec.adaptive and kernel_loads is not None and not events
    if compiled and not use_kernel:
        raise ValueError("compiled=True needs a fixed-step method, constant loads and no events")
    use_kernel = use_kernel if compiled is None else bool(compiled)
    settings = {
        "h": h,
        "rtol": rtol or None,
        "atol": atol or None,
        "record_every": int(record_every),
        "compiled": use_kernel,
    }
    run = _Run(spec, Dynamics(body, loads), t0, R, Y, int(record_every))
    loads_for_kernel = kernel_loads if use_kernel else None
    # A blow-up is detected and reported as status -1, not as numpy warnings on the way.
    with np.errstate(over="ignore", invalid="ignore"):
        t_events = _integrate(
            run, t_end, h, rtol, atol, impulses, events, loads_for_kernel, progress
        )
    if run.status == -1:
        log.warning("simulate stopped early: %s", run.message)
    return run.trajectory(body, settings, t_events)
