"""Crouch–Grossman methods: Runge–Kutta stages as products of exponentials on SO(3).

A Crouch–Grossman (CG) method (Crouch & Grossman 1993 [1]_) steps ``Ṙ = R ω̂`` with the
coefficients ``(A, b, c)`` of an explicit Runge–Kutta method, but where RK adds the stages'
slopes, CG composes their flows, each frozen at its stage:

.. math:: R_i = R_n \\exp(h a_{i1} \\hat\\omega_1) \\cdots
          \\exp(h a_{i,i-1} \\hat\\omega_{i-1}), \\qquad
          R_{n+1} = R_n \\exp(h b_1 \\hat\\omega_1) \\cdots \\exp(h b_s \\hat\\omega_s),

with ``ω_i = I⁻¹ R_iᵀ L_i``; the vector part ``Y = (x, p, L)`` takes the ordinary RK stages
``Y_i = Y_n + h Σ_j a_ij K_j``, ``K_j = (p_j/m, F_j, τ_j)``. Every stage and the step stay
on SO(3) to round-off (products of rotations), and unlike RKMK no ``dexp⁻¹`` is needed; in
exchange the coefficients must satisfy order conditions beyond the classical ones (Owren &
Marthinsen 1999 [2]_): RK4's tableau, used so, has order 2 on an asymmetric body (measured).

* ``cg3``: 3 stages, order 3, with rational coefficients (Crouch & Grossman [1]_).
* ``cg4``: 5 stages, order 4 (Jackiewicz, Marthinsen & Owren 2000 [3]_), the coefficients
  to 16 digits as published. Two versions of ``a₅₄`` circulate (…113565 and …113465); the
  second makes row 5 of ``A`` sum to ``c₅`` to the last digit, the first misses by 1e-14,
  so it is taken here (the order measured by the tests is 4 with either).

This module is the NumPy reference (:func:`cg_step`, :class:`CrouchGrossmanStepper`); its
compiled twin is :mod:`tumble.rigid._compiled.crouch_grossman`, bound into the fixed-step
template of :mod:`tumble.ode.templates`; ``tests/rigid`` checks they agree to round-off.

References
----------
.. [1] P. E. Crouch, R. Grossman, "Numerical integration of ordinary differential equations
   on manifolds", J. Nonlinear Sci. 3 (1993) 1–33.
.. [2] B. Owren, A. Marthinsen, "Runge–Kutta methods adapted to manifolds and based on rigid
   frames", BIT 39 (1999) 116–142.
.. [3] Z. Jackiewicz, A. Marthinsen, B. Owren, "Construction of Runge–Kutta methods of
   Crouch–Grossman type of high order", Adv. Comput. Math. 13 (2000) 405–415.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from tumble import so3
from tumble._progress import announce_compilation
from tumble.ode.driver import Block, Compiled, Grid
from tumble.ode.tableaux import ButcherTableau
from tumble.rigid.charts import Dynamics
from tumble.rigid.families import ANGULAR_MOMENTUM, ON_SO3
from tumble.rigid.steppers import BodyStepper, RigidState, _records

if TYPE_CHECKING:
    from tumble.rigid.methods import Method

CG3 = ButcherTableau(
    name="cg3",
    c=[0.0, 3 / 4, 17 / 24],
    A=[[0, 0, 0], [3 / 4, 0, 0], [119 / 216, 17 / 108, 0]],
    b=[13 / 51, -2 / 3, 24 / 17],
    order=3,
    reference="Crouch & Grossman (1993): order 3 as a Crouch–Grossman method.",
)

CG4 = ButcherTableau(
    name="cg4",
    c=[0.0, 0.8177227988124852, 0.3859740639032449, 0.3242290522866937, 0.8768903263420429],
    A=[
        [0, 0, 0, 0, 0],
        [0.8177227988124852, 0, 0, 0, 0],
        [0.3199876375476427, 0.0659864263556022, 0, 0, 0],
        [0.9214417194464946, 0.4997857776773573, -1.0969984448371582, 0, 0],
        [0.3552358559023322, 0.2390958372307326, 1.3918565724203246, -1.1092979392113465, 0],
    ],
    b=[
        0.1370831520630755,
        -0.0183698531564020,
        0.7397813985370780,
        -0.1907142565505889,
        0.3322195591068374,
    ],
    order=4,
    reference="Jackiewicz, Marthinsen & Owren (2000): order 4 as a Crouch–Grossman method.",
)


def cg_step(
    dynamics: Dynamics, tableau: ButcherTableau, t: float, R: np.ndarray, Y: np.ndarray, h: float
) -> tuple[np.ndarray, np.ndarray]:
    """One Crouch–Grossman step of ``tableau`` from ``(R, Y)`` at ``t`` (module docstring).

    Returns ``(R_{n+1}, Y_{n+1})``; ``R`` is a product of rotations, so a rotation to
    round-off.
    """
    A, b, c = tableau.A, tableau.b, tableau.c
    s = b.size
    omegas, K = np.empty((s, 3)), np.empty((s, 9))
    for i in range(s):
        Ri = R
        for j in range(i):
            Ri = Ri @ so3.exp(h * A[i, j] * omegas[j])
        Yi = Y + h * (A[i, :i] @ K[:i])
        omegas[i] = dynamics.omega(Ri, Yi[6:])
        K[i] = dynamics.rates(t + c[i] * h, Ri, Yi)
    R_new = R
    for j in range(s):
        R_new = R_new @ so3.exp(h * b[j] * omegas[j])
    return R_new, Y + h * (b @ K)


class CrouchGrossmanStepper(BodyStepper):
    """One step of a Crouch–Grossman method (:func:`cg_step`, NumPy). The state is
    ``(R, Y)``."""

    def __init__(self, method: Method, dynamics: Dynamics):
        assert method.tableau is not None
        self.method, self.dynamics, self.tableau = method, dynamics, method.tableau

    def start(self, state: tuple[np.ndarray, np.ndarray]) -> RigidState:
        R, Y = state
        return np.array(R, dtype=float), np.array(Y, dtype=float)

    def matrix(self, attitude: np.ndarray) -> np.ndarray:
        return attitude

    def step(self, t: float, state: RigidState, h: float) -> tuple[RigidState, None]:
        return cg_step(self.dynamics, self.tableau, t, *state, h), None


class CompiledCrouchGrossmanStepper(CrouchGrossmanStepper):
    """:class:`CrouchGrossmanStepper` with a compiled part: fixed grids march in the
    compiled loop (:data:`tumble.rigid._compiled.crouch_grossman.COMPILED_CG`)."""

    def __init__(self, method: Method, dynamics: Dynamics, problem):
        from tumble.rigid._compiled.crouch_grossman import COMPILED_CG

        super().__init__(method, dynamics)
        self.problem, self.loop = problem, COMPILED_CG.loop

    @property
    def compiled(self) -> Compiled:
        """The loop as the compiled part (made when asked: no reference cycle)."""
        return Compiled(self._march_block)

    def _march_block(
        self, state: RigidState, grid: Grid, k0: int, k1: int, every: int, step0: int
    ) -> Block:
        records = _records((k1 - k0) // every + 1)
        R, Y = np.array(state[0], dtype=float), np.array(state[1], dtype=float)
        announce_compilation(self.loop, "the Crouch–Grossman loop")
        count, failed, _ = self.loop(self.problem, grid, (Y, R), k0, k1, every, step0, records)
        return Block(
            t=records.t[:count],
            records=(records.R[:count], records.Y[:count], np.empty((count, 0))),
            state=(R, Y),
            failed=failed,
        )


class CrouchGrossmanFamily:
    """The Crouch–Grossman methods as a family (:class:`~tumble.rigid.families.Family`): the
    attitude is R itself, every stage and step a product of rotations, so R stays on SO(3)
    and with it the Casimir ``|RᵀL|``; not symplectic. Compiled for constant loads at fixed
    steps (none is adaptive); a batch runs one body per thread."""

    name = "cg"
    symplectic = False
    quaternion = False
    principal_frame = False
    columns = False

    def conserves(self, method: Method) -> frozenset[str]:
        return ANGULAR_MOMENTUM | ON_SO3

    def compiles(self, method: Method, kernel_loads: tuple | None) -> bool:
        return kernel_loads is not None and not method.adaptive

    def frame(self, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return np.ones(3), np.eye(3)

    def stepper(self, method: Method, dynamics: Dynamics, problem: Any) -> BodyStepper:
        if problem is None:
            return CrouchGrossmanStepper(method, dynamics)
        return CompiledCrouchGrossmanStepper(method, dynamics, problem)

    def batch_loop(self, method: Method) -> Callable[..., None]:
        from tumble.rigid._compiled.crouch_grossman import COMPILED_CG

        return COMPILED_CG.batch

    def start(self, R: np.ndarray, Y: np.ndarray, axes: np.ndarray) -> RigidState:
        return R, Y

    def matrix(self, attitude: np.ndarray, axes: np.ndarray) -> np.ndarray:
        return attitude

    def pack(self, attitude: np.ndarray, Y: np.ndarray) -> RigidState:
        return np.array(Y, dtype=float), np.array(attitude, dtype=float)

    def read(self, Z: np.ndarray, RN: np.ndarray) -> RigidState:
        return RN, Z
