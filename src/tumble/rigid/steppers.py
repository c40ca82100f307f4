"""The rigid-body stepper of the driver: a method's chart and tableau, in Python or compiled.

:class:`RigidStepper` is the readable NumPy reference: one :func:`~tumble.ode.stepper.rk_step`
of the method's tableau in the method's chart (:mod:`tumble.rigid.charts`).
:class:`CompiledStepper` adds a compiled part that marches whole blocks of a fixed grid in
the chart's numba loop (:mod:`tumble.rigid._compiled`), the same algorithm;
``tests/rigid`` checks they agree to round-off. Both plug into
:func:`tumble.ode.driver.march`, which owns the time loop.

:class:`SplitStepper` and :class:`CompiledSplitStepper` are the same pair for the ``split``
family: one step of :func:`~tumble.rigid.geometric.split_step` in NumPy, and its compiled
loop. The method's family (:mod:`tumble.rigid.families`) chooses and builds them.

The stepped state is ``(attitude, Y)``: the chart's attitude (R, or q for the ``quat`` chart,
or ``R_p = R P`` in the principal frame for the ``split`` family) and ``Y = (x, p, L)``,
shape (9,). A compiled block goes on from the loop's own arrays ``(z, R_n)`` when it is
handed the state the last block returned: packing that state again would normalise a
quaternion once more, and the blocks' sizes would change the numbers.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from tumble import so3
from tumble._progress import announce_compilation
from tumble.ode.contract import FAILURES, UNCONVERGED
from tumble.ode.dense import StepInterpolant, step_coefficients
from tumble.ode.driver import AdaptiveBlock, Block, Compiled, Control, Grid, Stepper
from tumble.ode.stepper import rk_step
from tumble.rigid import geometric
from tumble.rigid.charts import LIE, Chart, Dynamics, error_norm, separatrix_form
from tumble.rigid.forces import State

if TYPE_CHECKING:  # methods.py registers the families, which build these steppers
    from tumble.rigid.methods import Method

RigidState = tuple[np.ndarray, np.ndarray]
"""``(attitude, Y)``: the chart's attitude and ``(x, p, L)``."""


class BodyStepper(Stepper):
    """What every rigid-body stepper shares: the attitude as R, users' events, impulses."""

    _quat = False
    dynamics: Dynamics

    def start(self, state: tuple[np.ndarray, np.ndarray]) -> RigidState:
        """The stepped state for ``(R, Y)``: the attitude matrix and ``Y = (x, p, L)``."""
        raise NotImplementedError

    def matrix(self, attitude: np.ndarray) -> np.ndarray:
        """R for the carried attitude."""
        raise NotImplementedError

    def record(self, state: RigidState) -> tuple:
        attitude, Y = state
        q = attitude[None] if self._quat else np.empty((1, 0))
        return np.array(self.matrix(attitude))[None], Y[None], q

    def public(self, state: RigidState) -> State:
        """The state as users' events and ``Trajectory.sol`` see it: ``State(x, R, p, L,
        omega, q)``."""
        attitude, Y = state
        R = self.matrix(attitude)
        q = attitude / np.linalg.norm(attitude) if self._quat else so3.quat_from_matrix(R)
        omega = self.dynamics.omega(R, Y[6:])
        return State(Y[:3], R, Y[3:6], Y[6:], omega, q)

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
    """One step of ``method`` on ``dynamics``: its tableau in ``chart``, its family's (NumPy)."""

    def __init__(self, method: Method, chart: Chart, dynamics: Dynamics):
        assert method.tableau is not None
        self.method, self.chart, self.dynamics = method, chart, dynamics
        self.adaptive = method.adaptive
        self.error_order = method.tableau.error_order
        self._quat = chart.quaternion
        self._last: tuple = ()  # the last step's field, z, base point, stages, z_new and h
        self._fsal = method.tableau.fsal and self.chart.first_same_as_last is not None
        self._first: tuple = (None, None)  # (accepted state, its first stage) with FSAL
        if self.adaptive and self.chart is not LIE:
            raise NotImplementedError(f"{method.name!r}: the error norm is the lie chart's")
        self.separatrix = separatrix_form(dynamics.body.inertia) if self.adaptive else None

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
        first = self._first[1] if self._first[0] is state else f(t, z)
        z_new, error = rk_step(f, t, z, first, h, tableau, K)
        self._last = (f, z, Rn, K, z_new, h)
        return chart.advance(z_new, Rn), error

    def accept(self, t_old: float, old: RigidState, t_new: float, new: RigidState) -> str | None:
        """With a FSAL tableau keep the accepted step's last stage as the next one's first
        (:attr:`~tumble.rigid.charts.Chart.first_same_as_last`): one evaluation saved. A
        state that is not finite is refused."""
        refused = super().accept(t_old, old, t_new, new)
        if refused is None and self._fsal:
            _, _, _, K, z_new, _ = self._last
            assert self.chart.first_same_as_last is not None
            self._first = (new, self.chart.first_same_as_last(K, z_new))
        return refused

    def norm(self, error: np.ndarray, old: RigidState, new: RigidState, control: Control) -> float:
        """:func:`~tumble.rigid.charts.error_norm` of the last step: the attitude in radians
        against rtol, x and p against ``atol + rtol |y|``, the body momentum ``Rᵀ L``
        component by component against ``atol + rtol |m|``, and without torque the drift of
        the distance to the separatrix against rtol."""
        _, z, Rn, _, z_new, h = self._last
        share = h / control.horizon if control.horizon else 1.0
        atol = np.broadcast_to(np.asarray(control.atol, dtype=float), (9,))
        return error_norm(error, z, z_new, Rn, control.rtol, atol, self.separatrix, share)

    def interpolant(
        self, t_old: float, old: RigidState, t_new: float, new: RigidState
    ) -> Callable[[float], RigidState]:
        """The state between two accepted ones: the tableau's interpolant in the step's chart,
        mapped back. For the ``lie`` chart ``R(t) = R_n exp(û(θ))`` with ``u(θ)`` the
        tableau's continuous extension (order 4 for Fehlberg's and Dormand–Prince's pairs,
        cubic Hermite otherwise), so every sample is a rotation to round-off; ``x``, ``p``,
        ``L`` are interpolated the same way. Costs one field evaluation a step without a FSAL
        tableau (``f`` at the step's end, in the step's chart)."""
        f, z, Rn, K, z_new, _ = self._last
        tableau, chart, h = self.method.tableau, self.chart, t_new - t_old
        assert tableau is not None
        f1 = K[-1] if tableau.fsal else f(t_new, z_new)
        poly = StepInterpolant(
            t_old, h, z, step_coefficients(tableau, K, z, z_new, f1, h, f, t_old)
        )

        def sol(t: float) -> RigidState:
            return new if t == t_new else chart.advance(poly(t), Rn)

        return sol


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

    def accept(self, t_old: float, old: RigidState, t_new: float, new: RigidState) -> str | None:
        """A state that is not finite is refused; why, if a flow did not converge."""
        refused = super().accept(t_old, old, t_new, new)
        if refused is not None and self.unconverged:
            return unconverged_message(self.method, t_old, t_new)
        return refused


def unconverged_message(method: Method, t_old: float, t_new: float) -> str:
    """The message of a run whose implicit flow did not converge."""
    return (
        f"the implicit solve of method={method.name!r} did not converge in "
        f"{geometric.NEWTON_MAX} Newton iterations in the step from t={t_old!r} to "
        f"t={t_new!r}: the step turns the body too far; take a smaller h"
    )


ADAPTIVE_BLOCK = 4096
"""Samples a compiled adaptive block records before it returns to the driver."""


class CompiledStepper(RigidStepper):
    """:class:`RigidStepper` with a compiled part: fixed grids march in the chart's compiled
    loop, and adaptive steps (``rkmk45``, ``rkmk-dopri5``) in the chart's compiled adaptive
    loop.

    ``problem`` is the kernels' :class:`~tumble.rigid._compiled.base.KernelProblem` (constant
    loads).
    """

    def __init__(self, method: Method, chart: Chart, dynamics: Dynamics, problem):
        from tumble.rigid._compiled.charts import COMPILED

        super().__init__(method, chart, dynamics)
        self.problem, self.loop = problem, COMPILED[self.chart.name].loop
        self.adaptive_loop = COMPILED[self.chart.name].adaptive
        self._adaptive = method.adaptive and self.adaptive_loop is not None
        self._handed: tuple = (None, None)  # the state the last block handed back, its (z, Rn)

    @property
    def compiled(self) -> Compiled:
        """The chart's loops as the compiled part (made when asked: no reference cycle)."""
        return Compiled(self._march_block, self._march_adaptive if self._adaptive else None)

    def _march_adaptive(
        self, state: RigidState, t: float, t1: float, h: float, control: Control, every: int,
        step0: int, max_steps: float,
    ) -> AdaptiveBlock:  # fmt: skip
        tableau, controller = self.method.tableau, control.controller
        assert tableau is not None and tableau.e is not None and self.adaptive_loop is not None
        records = _records(ADAPTIVE_BLOCK)
        z, Rn = self.chart.pack(*state)
        settings = (controller.safety, controller.min_factor, controller.max_factor,
                    tableau.error_order, float(control.horizon or 0.0))  # fmt: skip
        atol = np.broadcast_to(np.asarray(control.atol, dtype=float), (9,)).copy()
        announce_compilation(self.adaptive_loop, f"the {self.chart.name} chart's adaptive loop")
        tolerances = (tableau.e, control.rtol, atol, self.separatrix)
        count, t_end, h_next, accepted, rejected, cause, t_failed, finite = self.adaptive_loop(
            (self.problem, tolerances), t, t1, h, settings, self._fsal, (z, Rn), every, step0,
            float(max_steps), records,
        )  # fmt: skip
        q = records.q[:count] if self._quat else np.empty((count, 0))
        return AdaptiveBlock(
            t=records.t[:count],
            records=(records.R[:count], records.Y[:count], q),
            state=self.chart.read(z, Rn),
            t_end=t_end,
            h=h_next,
            n_steps=accepted,
            n_rejected=rejected,
            failure=FAILURES[cause],
            t_failed=t_failed,
            finite=finite,
        )

    def _march_block(
        self, state: RigidState, grid: Grid, k0: int, k1: int, every: int, step0: int
    ) -> Block:
        records = _records((k1 - k0) // every + 1)
        z, Rn = self._handed[1] if state is self._handed[0] else self.chart.pack(*state)
        announce_compilation(self.loop, f"the {self.chart.name} chart's loop")
        count, failed, _ = self.loop(self.problem, grid, (z, Rn), k0, k1, every, step0, records)
        q = records.q[:count] if self._quat else np.empty((count, 0))
        new = self.chart.read(z, Rn)
        self._handed = (new, (z, Rn))  # the next block goes on from them (module docstring)
        return Block(
            t=records.t[:count],
            records=(records.R[:count], records.Y[:count], q),
            state=new,
            failed=failed,
        )


def _records(size: int):
    from tumble.rigid._compiled.base import Records

    return Records(np.empty(size), np.empty((size, 3, 3)), np.empty((size, 4)),
                   np.empty((size, 9)))  # fmt: skip


class CompiledSplitStepper(SplitStepper):
    """:class:`SplitStepper` with a compiled part: fixed grids march in the flow's compiled
    ``split`` loop."""

    def __init__(self, method: Method, dynamics: Dynamics, problem):
        from tumble.rigid._compiled.flows import COMPILED_FLOWS

        super().__init__(method, dynamics, (problem.moments, problem.axes))
        assert method.flow is not None
        self.problem, self.loop = problem, COMPILED_FLOWS[method.flow].loop

    @property
    def compiled(self) -> Compiled:
        """The flow's loop as the compiled part (made when asked: no reference cycle)."""
        return Compiled(self._march_block)

    def _march_block(
        self, state: RigidState, grid: Grid, k0: int, k1: int, every: int, step0: int
    ) -> Block:
        records = _records((k1 - k0) // every + 1)
        Rp, Y = np.array(state[0], dtype=float), np.array(state[1], dtype=float)
        announce_compilation(self.loop, f"the {self.method.flow} flow's loop")
        count, failed, cause = self.loop(self.problem, grid, (Y, Rp), k0, k1, every, step0,
                                         records)  # fmt: skip
        message = None
        if failed >= 0 and cause == UNCONVERGED:
            message = unconverged_message(self.method, grid.time(failed - 1), grid.time(failed))
        return Block(
            t=records.t[:count],
            records=(records.R[:count], records.Y[:count], np.empty((count, 0))),
            state=(Rp, Y),
            failed=failed,
            message=message,
        )
