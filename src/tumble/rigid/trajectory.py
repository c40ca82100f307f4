"""What ``simulate`` returns: the recorded states and the diagnostics along them."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from tumble import so3
from tumble.ode.driver import Status
from tumble.rigid.body import RigidBody


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
        The quaternions the ``quat`` method carried (otherwise ``q`` comes from ``R``).
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

    @property
    def success(self) -> bool:
        """True unless the run stopped on a non-finite state."""
        return self.status >= 0

    @cached_property
    def q(self) -> np.ndarray:
        """Unit quaternions ``[w, x, y, z]``, shape (n, 4), with ``w ≥ 0``."""
        if self.q_raw is not None:
            q = self.q_raw
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
    def energy(self) -> np.ndarray:
        """Kinetic energy ``½ m |v|² + ½ ω·(Rᵀ L)``, shape (n,), J."""
        with np.errstate(over="ignore", invalid="ignore"):  # a diverged run: inf, no warning
            body_L = np.einsum("nji,nj->ni", self.R, self.L_world)
            rotational = 0.5 * np.einsum("ni,ni->n", self.omega_body, body_L)
            return 0.5 * self.body.mass * np.einsum("ni,ni->n", self.v, self.v) + rotational

    @cached_property
    def orthogonality_error(self) -> np.ndarray:
        """``‖RᵀR − I‖_F`` at each sample, shape (n,)."""
        with np.errstate(over="ignore", invalid="ignore"):
            defect = np.einsum("nki,nkj->nij", self.R, self.R) - np.eye(3)
            return np.linalg.norm(defect, axis=(1, 2))

    @cached_property
    def quaternion_norm_error(self) -> np.ndarray:
        """``|q| − 1`` of the carried quaternions (zeros for the other families), shape (n,)."""
        if self.q_raw is None:
            return np.zeros(len(self.t))
        return np.linalg.norm(self.q_raw, axis=1) - 1.0

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
