"""The rigid-body stepper of the driver: a method's chart and tableau, in Python or compiled.

:class:`RigidStepper` is the readable NumPy reference: one :func:`~tumble.ode.stepper.rk_step`
of the method's tableau in the method's chart (:mod:`tumble.rigid.charts`).
:class:`CompiledStepper` marches whole blocks of a fixed grid in the chart's numba loop
(:mod:`tumble.rigid.kernels`), the same algorithm; ``tests/rigid`` checks they agree to
round-off. Both plug into :func:`tumble.ode.driver.march`, which owns the time loop.

:class:`SplitStepper` and :class:`CompiledSplitStepper` are the same pair for the ``split``
family: one step of :func:`~tumble.rigid.geometric.split_step` in NumPy, and its compiled
loop.

The stepped state is ``(attitude, Y)``: the chart's attitude (R, or q for the ``quat`` chart,
or ``R_p = R P`` in the principal frame for the ``split`` family) and ``Y = (x, p, L)``,
shape (9,).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from tumble._progress import announce_compilation
from tumble.ode.driver import Block, Grid, Stepper, non_finite_message
from tumble.ode.stepper import rk_step
from tumble.rigid import geometric
from tumble.rigid.charts import CHARTS, Dynamics
from tumble.rigid.forces import State
from tumble.rigid.methods import Method

RigidState = tuple[np.ndarray, np.ndarray]
"""``(attitude, Y)``: the chart's attitude and ``(x, p, L)``."""


class BodyStepper(Stepper):
    """What every rigid-body stepper shares: the attitude as R, users' events, impulses."""

    _quat = False

    def matrix(self, attitude: np.ndarray) -> np.ndarray:
        """R for the carried attitude."""
        raise NotImplementedError

    def record(self, state: RigidState) -> tuple:
        attitude, Y = state
        q = attitude[None] if self._quat else np.empty((1, 0))
        return np.array(self.matrix(attitude))[None], Y[None], q

    def public(self, state: RigidState) -> State:
        """The state as users' loads and events see it: ``State(x, R, p, L)``."""
        attitude, Y = state
        return State(Y[:3], self.matrix(attitude), Y[3:6], Y[6:])

    def event(self, event: Callable) -> Callable:
        """A user's ``g(t, State)`` as the driver's ``g(t, state)``."""

        def g(t: float, state: RigidState) -> float:
            return event(t, self.public(state))

        g.terminal = getattr(event, "terminal", False)  # type: ignore[attr-defined]
        g.direction = getattr(event, "direction", 0)  # type: ignore[attr-defined]
        return g

    def kick(self, impulses) -> Callable[[RigidState], RigidState]:
        """The jump of ``impulses`` at one time: ``Δp = J``, ``ΔL = (point − x) × J``."""

        def apply(state: RigidState) -> RigidState:
            attitude, Y = state
            for impulse in impulses:
                dp, dL = impulse.kick(Y[:3])
                Y = Y + np.concatenate([np.zeros(3), dp, dL])
            return attitude, Y

        return apply


class RigidStepper(BodyStepper):
    """One step of ``method`` on ``dynamics``: its tableau in its chart (NumPy)."""

    def __init__(self, method: Method, dynamics: Dynamics):
        assert method.tableau is not None
        self.method, self.dynamics = method, dynamics
        self.chart = CHARTS[method.family]
        self.adaptive = method.adaptive
        self.error_order = method.tableau.error_order
        self._chart_scale = np.ones(self.chart.size)  # chart errors measured against 1
        self._quat = self.chart.name == "quat"

    def start(self, state: tuple[np.ndarray, np.ndarray]) -> RigidState:
        """The stepped state for ``(R, Y)``: the attitude matrix and ``Y = (x, p, L)``."""
        R, Y = state
        return self.chart.attitude(R), Y

    def matrix(self, attitude: np.ndarray) -> np.ndarray:
        return self.chart.matrix(attitude)

    def step(self, t: float, state: RigidState, h: float) -> tuple[RigidState, np.ndarray | None]:
        chart, tableau = self.chart, self.method.tableau
        assert tableau is not None
        z, Rn = chart.pack(*state)
        f = chart.field(self.dynamics, self.method.dexpinv, Rn)
        K = np.empty((tableau.stages, z.size))
        z_new, error = rk_step(f, t, z, f(t, z), h, tableau, K)
        return chart.advance(z_new, Rn), error

    def scale(self, state: RigidState) -> np.ndarray:
        return np.concatenate([self._chart_scale, np.abs(state[1])])


class SplitStepper(BodyStepper):
    """One step of a ``split`` method (:func:`~tumble.rigid.geometric.split_step`, NumPy).

    The attitude is carried in the principal frame, ``R_p = R P``. A flow whose Newton
    iteration fails leaves a NaN state, and :meth:`failure` says why.
    """

    def __init__(self, method: Method, dynamics: Dynamics, frame=None):
        assert method.flow is not None
        self.method, self.dynamics = method, dynamics
        frame = geometric.principal_frame(dynamics.body.inertia) if frame is None else frame
        self.moments, self.axes = frame  # (moments, axes)
        self.flow = geometric.FLOWS[method.flow]
        self.unconverged = False

    def start(self, state: tuple[np.ndarray, np.ndarray]) -> RigidState:
        R, Y = state
        return R @ self.axes, Y

    def matrix(self, attitude: np.ndarray) -> np.ndarray:
        return attitude @ self.axes.T

    def _loads(self, t: float, Rp: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        rates = self.dynamics.rates(t, self.matrix(Rp), Y)
        return rates[3:6], rates[6:]

    def step(self, t: float, state: RigidState, h: float) -> tuple[RigidState, None]:
        method, dynamics = self.method, self.dynamics
        try:
            new = geometric.split_step(self.flow, method.weights, self._loads, self.moments,
                                       dynamics.mass, t, *state, h)  # fmt: skip
        except geometric.FlowNotConverged:
            self.unconverged = True
            return (np.full((3, 3), np.nan), np.full(9, np.nan)), None
        return new, None

    def failure(self, t_old: float, t_new: float) -> str:
        if self.unconverged:
            return unconverged_message(self.method, t_old, t_new)
        return non_finite_message(t_old, t_new)


def unconverged_message(method: Method, t_old: float, t_new: float) -> str:
    """The message of a run whose implicit flow did not converge."""
    return (
        f"the implicit solve of method={method.name!r} did not converge in "
        f"{geometric.NEWTON_MAX} Newton iterations in the step from t={t_old!r} to "
        f"t={t_new!r}: the step turns the body too far; take a smaller h"
    )


class CompiledStepper(RigidStepper):
    """:class:`RigidStepper` whose fixed grids march in the chart's compiled loop.

    ``problem`` is the kernels' :class:`~tumble.rigid.kernels.Problem` (constant loads).
    """

    blocks = True

    def __init__(self, method: Method, dynamics: Dynamics, problem):
        from tumble.rigid.kernels import COMPILED

        super().__init__(method, dynamics)
        self.problem, self.loop = problem, COMPILED[self.chart.name].loop

    def march_block(
        self, state: RigidState, grid: Grid, k0: int, k1: int, every: int, step0: int
    ) -> Block:
        records = _records((k1 - k0) // every + 1)
        z, Rn = self.chart.pack(*state)
        announce_compilation(self.loop, f"the {self.chart.name} chart's loop")
        count, failed, _ = self.loop(self.problem, grid, z, Rn, k0, k1, every, step0, records)
        q = records.q[:count] if self._quat else np.empty((count, 0))
        return Block(
            t=records.t[:count],
            records=(records.R[:count], records.Y[:count], q),
            state=self.chart.read(z, Rn),
            failed=failed,
        )


def _records(size: int):
    from tumble.rigid.kernels import Records

    return Records(np.empty(size), np.empty((size, 3, 3)), np.empty((size, 4)),
                   np.empty((size, 9)))  # fmt: skip


class CompiledSplitStepper(SplitStepper):
    """:class:`SplitStepper` whose fixed grids march in the flow's compiled ``split`` loop."""

    blocks = True

    def __init__(self, method: Method, dynamics: Dynamics, problem):
        from tumble.rigid.kernels import COMPILED_FLOWS

        super().__init__(method, dynamics, (problem.moments, problem.axes))
        assert method.flow is not None
        self.problem, self.loop = problem, COMPILED_FLOWS[method.flow].loop

    def march_block(
        self, state: RigidState, grid: Grid, k0: int, k1: int, every: int, step0: int
    ) -> Block:
        from tumble.rigid.kernels import UNCONVERGED

        records = _records((k1 - k0) // every + 1)
        Rp, Y = np.array(state[0], dtype=float), np.array(state[1], dtype=float)
        announce_compilation(self.loop, f"the {self.method.flow} flow's loop")
        count, failed, cause = self.loop(self.problem, grid, Y, Rp, k0, k1, every, step0,
                                         records)  # fmt: skip
        self.unconverged = failed >= 0 and cause == UNCONVERGED
        return Block(
            t=records.t[:count],
            records=(records.R[:count], records.Y[:count], np.empty((count, 0))),
            state=(Rp, Y),
            failed=failed,
        )
