"""Families of rigid-body methods: what ``simulate`` and ``simulate_batch`` ask of each.

A method (:class:`~tumble.rigid.methods.Method`) names its family: how it carries the
attitude and steps it. :data:`tumble.rigid.methods.FAMILIES` registers the families beside
:data:`~tumble.rigid.methods.METHODS`, and each answers, for the methods of its own, every
question the rest of :mod:`tumble.rigid` has; nothing else in ``tumble`` tests a family's
name (``tests/rigid/test_rigid_families.py`` checks). The questions, the :class:`Family`
protocol:

* ``stepper(method, dynamics, problem)``: the stepper :func:`~tumble.ode.driver.march` runs,
  the NumPy reference, or with the kernels' ``problem`` the compiled one;
* ``compiles(method, kernel_loads)``: whether a compiled loop runs the method with these
  loads (``kernel_loads`` is None unless they are constants) at its adaptivity;
* ``frame(inertia)`` and ``principal_frame``: the principal frame ``(moments, P)`` the
  compiled loops need, a placeholder where they need none (a batch then skips computing it
  per body);
* ``conserves(method)`` and ``symplectic``: what :attr:`Method.conserves
  <tumble.rigid.methods.Method.conserves>` and :attr:`Method.symplectic
  <tumble.rigid.methods.Method.symplectic>` declare, and the report card measures;
* ``quaternion``: whether the attitude carried is a quaternion, recorded as ``q``
  (:attr:`Trajectory.q_raw <tumble.rigid.trajectory.Trajectory.q_raw>`);
* ``batch_loop(method)`` and ``columns``: the compiled loop over a batch's bodies, and
  whether large batches run in the structure-of-arrays loops (:mod:`tumble.rigid.soa`);
* ``start``, ``matrix``, ``pack``, ``read``: a batch's state, ``(R, Y)`` to the attitude
  carried and back, and to the kernels' ``(Z, R_N)`` and back.

Two kinds implement it. A :class:`ChartFamily` steps the method's tableau in a chart of
:mod:`tumble.rigid.charts` (``matrix``, ``quat``, ``lie``: the Runge–Kutta and RKMK
methods; Munthe-Kaas 1998); the :class:`SplitFamily` composes kicks of the loads with a
free-body flow of :mod:`tumble.rigid.geometric` (the ``split`` methods; McLachlan 1993,
Reich 1994). A family that is neither, such as the Crouch–Grossman methods whose stages
are products of exponentials (Crouch & Grossman 1993), is one more class with these
members; ``docs/architecture.md`` lists the files adding one touches.

Examples
--------
>>> from tumble.rigid.methods import FAMILIES, METHODS
>>> family = FAMILIES[METHODS["rk4-quat"].family]
>>> family.quaternion, sorted(family.conserves(METHODS["rk4-quat"]))
(True, ['angular_momentum', 'casimir', 'orthogonality'])
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

from tumble.rigid import geometric
from tumble.rigid.charts import Chart, Dynamics
from tumble.rigid.steppers import (
    BodyStepper,
    CompiledSplitStepper,
    CompiledStepper,
    RigidState,
    RigidStepper,
    SplitStepper,
)

if TYPE_CHECKING:
    from tumble.rigid.methods import Method

ANGULAR_MOMENTUM = frozenset({"angular_momentum"})
"""What every method keeps: each steps ``L̇ = τ`` linearly (or kicks it), so without torque
``L`` is constant."""

ON_SO3 = frozenset({"orthogonality", "casimir"})
"""What a family that never leaves SO(3) (or renormalises onto it) keeps besides ``L``: R
stays a rotation, and so the body momentum's norm ``|RᵀL| = |L|``, the Casimir of the
Lie–Poisson equation."""


@runtime_checkable
class Family(Protocol):
    """What ``simulate``, ``simulate_batch`` and :class:`~tumble.rigid.methods.Method` ask of
    a family of methods (module docstring)."""

    @property
    def name(self) -> str:
        """The name methods give as their ``family``."""
        ...

    @property
    def symplectic(self) -> bool:
        """Whether every method of the family is symplectic (and Poisson)."""
        ...

    @property
    def quaternion(self) -> bool:
        """Whether the attitude carried is a quaternion, recorded as ``q``."""
        ...

    @property
    def principal_frame(self) -> bool:
        """Whether the compiled loops carry ``R_p = R P`` in each body's principal frame."""
        ...

    @property
    def columns(self) -> bool:
        """Whether large batches run in :func:`tumble.rigid.soa.run_batch`."""
        ...

    def conserves(self, method: Method) -> frozenset[str]:
        """The invariants ``method`` keeps to round-off on a free body."""
        ...

    def compiles(self, method: Method, kernel_loads: tuple | None) -> bool:
        """Whether a compiled loop runs ``method`` with ``kernel_loads``."""
        ...

    def frame(self, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(moments, P)`` of the kernels' :class:`~tumble.rigid._compiled.base.KernelProblem`."""
        ...

    def stepper(self, method: Method, dynamics: Dynamics, problem: Any) -> BodyStepper:
        """The NumPy stepper (``problem`` None) or the compiled one."""
        ...

    def batch_loop(self, method: Method) -> Callable[..., None]:
        """The compiled loop over a batch's bodies, one body per thread."""
        ...

    def start(self, R: np.ndarray, Y: np.ndarray, axes: np.ndarray) -> RigidState:
        """The carried state of ``(R, Y)`` (``axes``: the principal frame, or unused)."""
        ...

    def matrix(self, attitude: np.ndarray, axes: np.ndarray) -> np.ndarray:
        """R for the carried attitude."""
        ...

    def pack(self, attitude: np.ndarray, Y: np.ndarray) -> RigidState:
        """The kernels' ``(Z, R_N)`` for a carried state (new arrays: the loops write them)."""
        ...

    def read(self, Z: np.ndarray, RN: np.ndarray) -> RigidState:
        """The carried state a kernel left in ``(Z, R_N)``."""
        ...


_NO_FRAME = (np.ones(3), np.eye(3))
"""The kernels' ``moments`` and ``axes`` where they are unused (never written: built once)."""


@dataclass(frozen=True)
class ChartFamily:
    """The methods that step their tableau in ``chart`` (:mod:`tumble.rigid.charts`): one
    :func:`~tumble.ode.stepper.rk_step` in the chart's coordinates, then its map back.

    Attributes
    ----------
    chart : Chart
        How the attitude is carried; its name is the family's.
    keeps : frozenset of str
        What the family keeps besides ``L`` (:data:`ON_SO3`, or nothing for a chart that
        leaves SO(3)).
    compiled_adaptive : bool
        Whether the chart has a compiled adaptive loop (the error norm is the ``lie``
        chart's, :func:`~tumble.rigid.charts.error_norm`); without one an adaptive method
        of the family steps in Python.
    columns : bool
        Whether the chart has structure-of-arrays batch loops (:mod:`tumble.rigid.soa`).
    """

    chart: Chart
    keeps: frozenset[str] = frozenset()
    compiled_adaptive: bool = False
    columns: bool = False
    symplectic = False
    principal_frame = False

    @property
    def name(self) -> str:
        return self.chart.name

    @property
    def quaternion(self) -> bool:
        return self.chart.quaternion

    def conserves(self, method: Method) -> frozenset[str]:
        return ANGULAR_MOMENTUM | self.keeps

    def compiles(self, method: Method, kernel_loads: tuple | None) -> bool:
        return kernel_loads is not None and (self.compiled_adaptive or not method.adaptive)

    def frame(self, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return _NO_FRAME

    def stepper(self, method: Method, dynamics: Dynamics, problem: Any) -> BodyStepper:
        if problem is None:
            return RigidStepper(method, self.chart, dynamics)
        return CompiledStepper(method, self.chart, dynamics, problem)

    def batch_loop(self, method: Method) -> Callable[..., None]:
        from tumble.rigid._compiled.charts import COMPILED

        return COMPILED[self.chart.name].batch

    def start(self, R: np.ndarray, Y: np.ndarray, axes: np.ndarray) -> RigidState:
        return self.chart.attitude(R), Y

    def matrix(self, attitude: np.ndarray, axes: np.ndarray) -> np.ndarray:
        return self.chart.matrix(attitude)

    def pack(self, attitude: np.ndarray, Y: np.ndarray) -> RigidState:
        return self.chart.pack(attitude, Y)

    def read(self, Z: np.ndarray, RN: np.ndarray) -> RigidState:
        return self.chart.read(Z, RN)


@dataclass(frozen=True)
class SplitFamily:
    """The splittings of :mod:`tumble.rigid.geometric`: kicks of the loads around a drift
    that turns the body by the method's free-body ``flow``, composed by the method's
    ``weights``. The attitude is carried in the principal frame, ``R_p = R P``; every
    flow turns it by an exact rotation (so R stays on SO(3)), and those of
    :data:`~tumble.rigid.geometric.ENERGY_FLOWS` keep the free body's energy too.
    """

    name: str = "split"
    symplectic = True
    quaternion = False
    principal_frame = True
    columns = False

    def conserves(self, method: Method) -> frozenset[str]:
        kept = ANGULAR_MOMENTUM | ON_SO3
        return (kept | {"energy"}) if method.flow in geometric.ENERGY_FLOWS else kept

    def compiles(self, method: Method, kernel_loads: tuple | None) -> bool:
        return kernel_loads is not None and not method.adaptive

    def frame(self, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return geometric.principal_frame(inertia)

    def stepper(self, method: Method, dynamics: Dynamics, problem: Any) -> BodyStepper:
        if problem is None:
            return SplitStepper(method, dynamics)
        return CompiledSplitStepper(method, dynamics, problem)

    def batch_loop(self, method: Method) -> Callable[..., None]:
        from tumble.rigid._compiled.flows import COMPILED_FLOWS

        assert method.flow is not None
        return COMPILED_FLOWS[method.flow].batch

    def start(self, R: np.ndarray, Y: np.ndarray, axes: np.ndarray) -> RigidState:
        return R @ axes, Y

    def matrix(self, attitude: np.ndarray, axes: np.ndarray) -> np.ndarray:
        return attitude @ np.swapaxes(axes, -1, -2)

    def pack(self, attitude: np.ndarray, Y: np.ndarray) -> RigidState:
        return np.array(Y, dtype=float), np.array(attitude, dtype=float)

    def read(self, Z: np.ndarray, RN: np.ndarray) -> RigidState:
        return RN, Z
