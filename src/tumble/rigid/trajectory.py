"""What ``simulate`` returns: the recorded states and the diagnostics along them."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from tumble import _checks, so3
from tumble.ode.dense import DenseOutput
from tumble.ode.driver import Status
from tumble.rigid.body import RigidBody
from tumble.rigid.forces import State


class NoSolution:
    """``Trajectory.sol`` of a run without dense output: calling it says how to get one.

    It is falsy, so ``if run.sol:`` tells the two apart.
    """

    def __call__(self, t: object) -> State:
        raise _checks.fail(
            "dense_output", False, "True for Trajectory.sol(t)",
            remedy="simulate(..., dense_output=True) keeps every step's interpolant (Python "
            "steps); t_eval=[...] records the state at given times instead",
        )  # fmt: skip

    def __bool__(self) -> bool:
        return False

    def __repr__(self) -> str:
        return "NoSolution()"


NO_SOLUTION = NoSolution()
"""The one :class:`NoSolution`."""


class Solution:
    """The continuous solution of a run (``simulate(..., dense_output=True).sol``).

    ``sol(t)`` is the :class:`~tumble.rigid.forces.State` at ``t`` (``x``, ``R``, ``p``,
    ``L``, ``omega``, ``q``), from the interpolant of the step that holds ``t``: for the
    ``lie`` methods ``R(t) = R_n exp(û(θ))``, a rotation to round-off. An array of ``k``
    times gives each field with a leading axis of length ``k``.

    Examples
    --------
    >>> import numpy as np
    >>> from tumble import RigidBody, simulate
    >>> body = RigidBody(1.0, [2.0, 1.0, 2 / 3], allow_unphysical=True)
    >>> run = simulate(body, 10.0, method="rkmk-dopri5", rtol=1e-10, omega0=(0.2, 1.0, 0.3),
    ...                dense_output=True)
    >>> R = run.sol([2.5, 7.25]).R
    >>> R.shape, bool(np.abs(R[1].T @ R[1] - np.eye(3)).max() < 1e-13)
    ((2, 3, 3), True)
    """

    def __init__(self, stepper: Any, ts: Sequence[float], interpolants: Sequence[Callable]):
        self.stepper, self.dense = stepper, DenseOutput(ts, interpolants)

    def __call__(self, t: float | Sequence[float] | np.ndarray) -> State:
        times = _checks.array("t", t, unit="s")  # NaN would pick no step: refused
        if times.size == 0:
            raise _checks.fail("t", t, "a time or a non-empty array of times", "s")
        times, index = self.dense.steps(times)
        states = [
            self.stepper.public(self.dense.interpolants[int(i)](float(s)))
            for i, s in zip(np.ravel(index), np.ravel(times), strict=True)
        ]
        if times.ndim == 0:
            return states[0]
        return State(*(np.stack(parts) for parts in zip(*states, strict=True)))


@dataclass
class Trajectory:
    """A rigid-body trajectory, sampled at ``t``.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times (s).
    x, v : ndarray, shape (n, 3)
        Centre of mass (m) and its velocity (m/s), world frame.
    R : ndarray, shape (n, 3, 3)
        Attitude, body to world (for the ``matrix`` methods not exactly a rotation).
    L_world : ndarray, shape (n, 3)
        Angular momentum about the centre of mass, world frame (kg m²/s).
    body : RigidBody
        The body simulated.
    method : str
        The method's name.
    settings : dict
        ``h`` or ``rtol``/``atol``, ``record_every``, the compiled-kernel flag.
    status : Status
        ``SUCCESS`` (0): reached ``t_end``; ``TERMINAL_EVENT`` (1); ``FAILED`` (-1): stopped
        by a non-finite state (see :class:`~tumble.ode.driver.Status`).
    message : str
        What happened, naming ``t`` on failure.
    n_steps, n_rejected : int
        Accepted and rejected steps.
    t_events : list of ndarray
        For each event, the times at which it fired.
    q_raw : ndarray, shape (n, 4), optional
        The quaternions the ``quat`` method carried, as each step left them (before the
        renormalisation the next step starts with); otherwise ``q`` comes from ``R``.
    potential_energy : ndarray, shape (n,), optional
        ``V`` of the loads that derive from a potential (gravity, constant forces, magnetic
        dipoles), J; zeros without such loads (``None`` given: zeros).
    sol : Solution or NoSolution
        The continuous solution, ``sol(t)``, with ``simulate(..., dense_output=True)``;
        otherwise a falsy :class:`NoSolution` whose call raises a ValueError naming that
        remedy.

    Notes
    -----
    The diagnostics are computed from these on first use: ``omega_body``, ``q``,
    ``kinetic_energy`` and ``energy`` (kinetic plus potential);
    along the run ``orthogonality_error`` (``‖RᵀR − I‖_F``), ``quaternion_norm_error``,
    ``energy_error`` (``E − E₀``) and ``momentum_error`` (``‖L − L₀‖``); and over the run
    ``orthogonality_drift``, ``energy_drift`` and ``momentum_drift`` (the largest of each,
    the last two relative to ``E₀`` and ``‖L₀‖``). The scenarios' summaries and the drift
    plot report these.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    R: np.ndarray
    L_world: np.ndarray
    body: RigidBody
    method: str
    settings: dict = field(default_factory=dict)
    status: Status = Status.SUCCESS
    message: str = Status.SUCCESS.message
    n_steps: int = 0
    n_rejected: int = 0
    t_events: list = field(default_factory=list)
    q_raw: np.ndarray | None = None
    potential_energy: np.ndarray = None  # type: ignore[assignment]
    sol: Solution | NoSolution | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.potential_energy is None:
            self.potential_energy = np.zeros(len(self.t))
        if self.sol is None:
            self.sol = NO_SOLUTION

    @property
    def success(self) -> bool:
        """True unless the run stopped on a non-finite state."""
        return self.status >= 0

    @cached_property
    def q(self) -> np.ndarray:
        """Unit quaternions ``[w, x, y, z]``, shape (n, 4), with ``w ≥ 0``."""
        if self.q_raw is not None:
            with np.errstate(invalid="ignore", over="ignore"):
                q = self.q_raw / np.linalg.norm(self.q_raw, axis=1, keepdims=True)
        else:
            U, _, Vt = np.linalg.svd(self.R)  # nearest rotation, for matrices off SO(3)
            q = so3.quat_from_matrix(U @ Vt)
        return np.where(q[:, :1] < 0, -q, q)

    @cached_property
    def omega_body(self) -> np.ndarray:
        """Body-frame angular velocity ``ω = I⁻¹ Rᵀ L``, shape (n, 3), rad/s."""
        with np.errstate(over="ignore", invalid="ignore"):
            body_L = np.einsum("nji,nj->ni", self.R, self.L_world)
            return body_L @ self.body.inertia_inverse.T

    @cached_property
    def kinetic_energy(self) -> np.ndarray:
        """Kinetic energy ``T = ½ m |v|² + ½ ω·(Rᵀ L)``, shape (n,), J."""
        with np.errstate(over="ignore", invalid="ignore"):  # a diverged run: inf, no warning
            body_L = np.einsum("nji,nj->ni", self.R, self.L_world)
            rotational = 0.5 * np.einsum("ni,ni->n", self.omega_body, body_L)
            return 0.5 * self.body.mass * np.einsum("ni,ni->n", self.v, self.v) + rotational

    @cached_property
    def energy(self) -> np.ndarray:
        """Total energy ``T + V``, shape (n,), J: :attr:`kinetic_energy` plus
        :attr:`potential_energy` (the loads that have a potential; a torque or a callable
        load has none, so with one of those this is not an invariant)."""
        with np.errstate(over="ignore", invalid="ignore"):
            return self.kinetic_energy + self.potential_energy

    @cached_property
    def orthogonality_error(self) -> np.ndarray:
        """``‖RᵀR − I‖_F`` at each sample, shape (n,)."""
        with np.errstate(over="ignore", invalid="ignore"):
            defect = np.einsum("nki,nkj->nij", self.R, self.R) - np.eye(3)
            return np.linalg.norm(defect, axis=(1, 2))

    @cached_property
    def energy_error(self) -> np.ndarray:
        """``E − E₀``, shape (n,), J: the total energy's change since the first sample."""
        with np.errstate(over="ignore", invalid="ignore"):
            return self.energy - self.energy[0]

    @cached_property
    def momentum_error(self) -> np.ndarray:
        """``‖L − L₀‖``, shape (n,), kg m²/s: how far the world angular momentum has moved."""
        with np.errstate(over="ignore", invalid="ignore"):
            return np.linalg.norm(self.L_world - self.L_world[0], axis=1)

    @property
    def energy_drift(self) -> float:
        """Largest relative energy change over the run, ``max_k |E_k − E₀| / |E₀|``.

        The same as ``max_k |E_k/E₀ − 1|``. NaN when ``E₀ = 0`` (a body at rest has no
        relative drift); inf or NaN when the run diverged. Without loads after ``t₀`` the
        energy is an invariant, so this measures the method's error.

        Examples
        --------
        >>> from tumble.rigid import RigidBody, simulate
        >>> body = RigidBody(1.0, [1.0, 2.0, 3.0])
        >>> lie = simulate(body, 10.0, method="lie-euler", h=0.1, omega0=[0.1, 1.0, 0.1])
        >>> round(lie.energy_drift, 4), lie.momentum_drift  # first order; L kept exactly
        (0.124, 0.0)
        """
        return _relative_drift(np.abs(self.energy_error), abs(self.energy[0]))

    @property
    def momentum_drift(self) -> float:
        """Largest relative change of the world angular momentum, ``max_k ‖L_k − L₀‖ / ‖L₀‖``.

        NaN when ``L₀ = 0``. Every method steps ``L̇ = τ`` with its tableau, so without torque
        this is 0 exactly (see :attr:`tumble.rigid.Method.conserves`).
        """
        return _relative_drift(self.momentum_error, float(np.linalg.norm(self.L_world[0])))

    @property
    def orthogonality_drift(self) -> float:
        """Largest ``‖RᵀR − I‖_F`` over the run (0 for an exact rotation)."""
        return float(np.max(self.orthogonality_error))

    @cached_property
    def quaternion_norm_error(self) -> np.ndarray:
        """``|q| − 1`` of the carried quaternions before each renormalisation (zeros for the
        other families), shape (n,): what the ``quat`` methods' ``q ← q/|q|`` removes, the
        step's departure from the unit sphere (the first sample is the initial unit q)."""
        if self.q_raw is None:
            return np.zeros(len(self.t))
        return np.linalg.norm(self.q_raw, axis=1) - 1.0

    def angular_momentum_about(self, point) -> np.ndarray:
        """World angular momentum about a fixed world ``point``, ``L + m (x − point) × v``,
        shape (n, 3), kg m²/s: for a body with a pivot, ``point`` is the pivot.

        Examples
        --------
        >>> from tumble.rigid import RigidBody, simulate
        >>> run = simulate(RigidBody(2.0, [1.0, 1.0, 1.0]), 1.0, h=0.1, v0=(1.0, 0.0, 0.0))
        >>> run.angular_momentum_about((0.0, 1.0, 0.0))[-1]  # 2 (1, −1, 0) × (1, 0, 0)
        array([0., 0., 2.])
        """
        arm = self.x - np.asarray(point, dtype=float)
        return self.L_world + self.body.mass * np.cross(arm, self.v)

    @property
    def rotation(self):
        """The attitudes as one ``scipy.spatial.transform.Rotation`` of ``n`` rotations (for
        the ``matrix`` methods, scipy takes the nearest rotation of each R).

        Examples
        --------
        >>> from tumble.rigid import RigidBody, simulate
        >>> run = simulate(RigidBody(1.0, [1.0, 1.0, 1.0]), 1.0, h=0.5, omega0=(0.0, 0.0, 1.0))
        >>> len(run.rotation), round(float(run.rotation[-1].magnitude()), 12)
        (3, 1.0)
        """
        from scipy.spatial.transform import Rotation

        return Rotation.from_matrix(self.R)

    def euler_zyx(self) -> np.ndarray:
        """ZYX Euler angles ``(φ_z, θ_y, ψ_x)`` in rad, shape (n, 3); see :mod:`tumble.so3`."""
        return so3.euler_zyx_from_matrix(self.R)

    def to_xarray(self):
        """The trajectory as an ``xarray.Dataset`` (dimension ``time``, SI units in attrs)."""
        from tumble.rigid._xarray import trajectory_dataset

        return trajectory_dataset(self)

    @classmethod
    def from_xarray(cls, dataset) -> Trajectory:
        """The trajectory back from :meth:`to_xarray`'s dataset (e.g. a run's ``data.nc``).

        Step counts and event times are not stored and come back as 0 and ``[]``.

        Examples
        --------
        >>> from tumble.rigid import RigidBody, simulate
        >>> run = simulate(RigidBody(1.0, [1.0, 2.0, 3.0]), 1.0, h=0.1, omega0=[0, 1, 0.1])
        >>> back = Trajectory.from_xarray(run.to_xarray())
        >>> bool(np.array_equal(back.R, run.R)), bool(np.allclose(back.energy, run.energy))
        (True, True)
        """
        from tumble.rigid._xarray import trajectory_from_dataset

        return trajectory_from_dataset(dataset)


def _relative_drift(errors: np.ndarray, scale: float) -> float:
    """``max(errors) / scale``, or NaN when the reference ``scale`` is 0 or not finite."""
    if scale == 0.0 or not np.isfinite(scale):
        return float("nan")
    with np.errstate(over="ignore", invalid="ignore"):
        return float(np.max(errors) / scale)
