"""The exact response of ``M ẍ + C ẋ + S x = f`` by modal superposition.

With the M-orthonormal modes ``S φ_i = ω_i² M φ_i`` (:meth:`LinearSystem.modes
<tumble.structural.system.LinearSystem.modes>`, all of them), the static solution
``x_s = S⁻¹ f = Σ φ_i φ_iᵀ f / ω_i²`` and Rayleigh damping ``C = αM + βS`` (which keeps
the modes uncoupled, ``φ_iᵀ C φ_i = 2 ζ_i ω_i`` with ``ζ_i = α/(2ω_i) + βω_i/2``), each
modal coordinate ``u_i = φ_iᵀ M (x − x_s)`` is a damped oscillator
``ü + 2ζωu̇ + ω²u = 0`` with the closed form

.. math::

    u(t) = u_0\\,(\\dot h + 2ζω h) + \\dot u_0\\, h, \\qquad
    \\dot u(t) = -ω^2 u_0\\, h + \\dot u_0\\, \\dot h,

where ``h(t)`` is the impulse response (``h(0) = 0``, ``ḣ(0) = 1``):
``e^{−ζωt} sin(ω_d t)/ω_d`` with ``ω_d = ω√(1 − ζ²)`` below critical damping, ``t e^{−ωt}``
at it, and ``(e^{s₊t} − e^{s₋t})/(s₊ − s₋)`` above, with ``s_± = −ζω ± ω√(ζ² − 1)``
(``s₊ = −ω/(ζ + √(ζ² − 1))``, without cancellation). Then
``x(t) = x_s + Σ φ_i u_i(t)`` and ``y(t) = Σ φ_i u̇_i(t)`` at any ``t``, with no time step.

It is exact up to the eigen-solve's round-off: ``O(ε)`` in the shapes and ``ε ω_max/ω_i``
relative in ``ω_i`` (:meth:`~tumble.structural.system.LinearSystem.modes`), so the
phase error after time ``t`` is about ``ε ω_max t``. All modes are needed, so the
eigen-solve is dense: :data:`EXACT_DOF_LIMIT` DOFs at most.

References
----------
.. [1] R. W. Clough, J. Penzien, *Dynamics of Structures*, 3rd ed., Computers &
   Structures, 2003, ch. 2–3 (the damped oscillator) and ch. 12–13 (mode superposition).
.. [2] R. D. Cook et al., *Concepts and Applications of Finite Element Analysis*, 4th ed.,
   Wiley, 2002, §11.12 (Rayleigh damping).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tumble import _checks
from tumble.ode.driver import Status
from tumble.structural.schemes import Response
from tumble.structural.system import (
    LinearSystem,
    RayleighDamping,
    checked_damping,
    checked_system,
    dof_values,
)

EXACT_DOF_LIMIT = 4000
"""Largest system :func:`exact_response` takes (a dense SVD of this size takes ~1 min)."""


@dataclass(frozen=True, eq=False)
class ModalSolution:
    """The closed-form motion of a linear system from one initial state (module docstring).

    Build it with :meth:`from_system`; :meth:`state` evaluates ``x(t)``, ``y(t)``.

    Attributes
    ----------
    omega : ndarray, shape (n_dofs,)
        Natural frequencies ω_i [rad/s], ascending.
    shapes : ndarray, shape (n_dofs, n_dofs)
        M-orthonormal mode shapes, one per column.
    zeta : ndarray, shape (n_dofs,)
        Damping ratios ζ_i of the Rayleigh damping (0 without).
    static : ndarray, shape (n_dofs,)
        ``x_s = S⁻¹ f`` [m, rad].
    u0, v0 : ndarray, shape (n_dofs,)
        Modal coordinates of ``x0 − x_s`` and of ``y0`` [√kg m, √kg m/s].
    """

    omega: NDArray[np.float64]
    shapes: NDArray[np.float64]
    zeta: NDArray[np.float64]
    static: NDArray[np.float64]
    u0: NDArray[np.float64]
    v0: NDArray[np.float64]

    @classmethod
    def from_system(
        cls,
        system: LinearSystem,
        x0: ArrayLike | None = None,
        y0: ArrayLike | None = None,
        damping: RayleighDamping | None = None,
    ) -> ModalSolution:
        """Modes, static solution and modal initial conditions of ``system``."""
        n = system.n_dofs
        if n > EXACT_DOF_LIMIT:
            raise _checks.fail(
                "system", f"<LinearSystem with {n} DOFs>", f"at most {EXACT_DOF_LIMIT} DOFs",
                remedy="the exact response needs every mode from a dense eigen-solve; "
                "use fewer elements",
            )  # fmt: skip
        x0, y0 = (
            np.zeros(n) if v is None else _checks.array(name, v, shape=(n,), unit=unit)
            for name, v, unit in (("x0", x0, "m, rad"), ("y0", y0, "m/s, rad/s"))
        )
        omega, shapes = system.modes(n)
        if not omega[0] > 0:
            raise _checks.fail(
                "system", "<LinearSystem with a zero frequency>", "supported against rigid "
                "motion (every ω > 0)", remedy="add supports",
            )  # fmt: skip
        static = shapes @ ((shapes.T @ system.f) / omega**2)
        zeta = np.zeros(n)
        if damping is not None:
            alpha, beta = damping.mass_coefficient, damping.stiffness_coefficient
            zeta = alpha / (2 * omega) + beta * omega / 2
        u0 = shapes.T @ (system.M @ (x0 - static))
        v0 = shapes.T @ (system.M @ y0)
        return cls(omega, shapes, zeta, static, u0, v0)

    def modal_coordinates(self, t: ArrayLike) -> tuple[NDArray, NDArray]:
        """``u_i(t)``, ``u̇_i(t)``, each of shape (n_times, n_dofs)."""
        t = np.asarray(t, dtype=float)[:, None]
        h, dh = impulse_response(self.omega, self.zeta, t)
        u = self.u0 * (dh + 2 * self.zeta * self.omega * h) + self.v0 * h
        du = -(self.omega**2) * self.u0 * h + self.v0 * dh
        return u, du

    def state(self, t: ArrayLike) -> tuple[NDArray, NDArray]:
        """``x(t)`` [m, rad] and ``y(t)`` [m/s, rad/s], each of shape (n_times, n_dofs)."""
        u, du = self.modal_coordinates(t)
        return self.static + u @ self.shapes.T, du @ self.shapes.T


def impulse_response(
    omega: NDArray, zeta: NDArray, t: NDArray
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``h(t)`` and ``ḣ(t)`` of ``ḧ + 2ζωḣ + ω²h = 0``, ``h(0) = 0``, ``ḣ(0) = 1``.

    Broadcasts ``omega``, ``zeta`` (per mode) against ``t``. Below, at and above critical
    damping as in the module docstring; ``sin(ω_d t)/ω_d`` is computed as it stands, which
    tends to ``t`` without cancellation as ``ζ → 1``.

    Examples
    --------
    >>> h, dh = impulse_response(np.array([2.0]), np.array([0.0]), np.array([np.pi / 4]))
    >>> float(h[0]), round(float(dh[0]), 15)   # sin(2t)/2, cos(2t)
    (0.5, 0.0)
    """
    omega, zeta, t = np.broadcast_arrays(omega, zeta, t)
    h, dh = np.empty(t.shape), np.empty(t.shape)
    under = zeta < 1
    w, z, s = omega[under], zeta[under], t[under]
    wd = w * np.sqrt((1 - z) * (1 + z))
    decay = np.exp(-z * w * s)
    sine = np.where(wd > 0, np.sin(wd * s) / np.where(wd > 0, wd, 1.0), s)
    h[under] = decay * sine
    dh[under] = decay * (np.cos(wd * s) - z * w * sine)
    critical = zeta == 1
    w, s = omega[critical], t[critical]
    h[critical] = s * np.exp(-w * s)
    dh[critical] = (1 - w * s) * np.exp(-w * s)
    over = zeta > 1
    w, z, s = omega[over], zeta[over], t[over]
    root = w * np.sqrt((z - 1) * (z + 1))
    slow, fast = -w * w / (z * w + root), -(z * w + root)  # s₊ = −ω²/(ζω + μ), s₋
    h[over] = (np.exp(slow * s) - np.exp(fast * s)) / (slow - fast)
    dh[over] = (slow * np.exp(slow * s) - fast * np.exp(fast * s)) / (slow - fast)
    return h, dh


def exact_response(
    system: LinearSystem,
    t: ArrayLike,
    *,
    x0: ArrayLike | None = None,
    y0: ArrayLike | None = None,
    damping: RayleighDamping | None = None,
) -> Response:
    """The exact motion of ``M ẍ + C ẋ + S x = f`` from ``(x0, y0)`` at the times ``t``.

    Modal superposition (module docstring): the loads ``f`` act as a step at ``t = 0``, as
    in :func:`~tumble.structural.integrate`, whose :class:`~tumble.structural.Response`
    this returns (``scheme="exact"``, ``solver="modal"``, ``dt = 0``), so that a scheme's
    error is ``run.x − exact_response(system, run.t).x``.

    Parameters
    ----------
    system : LinearSystem
        At most :data:`EXACT_DOF_LIMIT` DOFs, supported (every ω > 0).
    t : array_like, shape (n_times,)
        Times [s], finite, ≥ 0, in any order.
    x0, y0 : ndarray, shape (n_dofs,), optional
        Initial displacement [m, rad] and velocity [m/s, rad/s]; rest by default.
    damping : RayleighDamping, optional
        ``C = αM + βS``; each mode then decays with ``ζ_i = α/(2ω_i) + βω_i/2``.

    Returns
    -------
    Response
        ``x``, ``y`` and ``energy`` at ``t``.

    Examples
    --------
    >>> from tumble.structural import cantilever
    >>> beam = cantilever(1.0, 10, E=210e9, rho=7850, width=0.01, height=0.01, tip_load=1.0)
    >>> damping = RayleighDamping(mass_coefficient=50.0)
    >>> late = exact_response(beam, [10.0], damping=damping)   # at rest at F L³/(3EI)
    >>> round(float(late.tip_displacement[0] * 3 * 175.0), 12)
    1.0
    """
    system = checked_system(system)
    damping = checked_damping(damping)
    times = np.atleast_1d(_checks.array("t", t, unit="s"))
    if times.ndim != 1 or np.any(times < 0):
        raise _checks.fail("t", t, "a 1-D array of finite times >= 0", "s")
    solution = ModalSolution.from_system(system, x0, y0, damping)
    with np.errstate(over="ignore"):
        phase = solution.omega[-1] * times.max() if times.size else 0.0
    if not np.isfinite(phase):
        raise _checks.fail(
            "t", t, f"times with ω_max t finite (ω_max = {solution.omega[-1]:.3g} rad/s)", "s",
            remedy="past that the phase ω t overflows and sin(ω t) has no digit",
        )  # fmt: skip
    x, y = solution.state(times)
    energy = system.energy(x, y)
    message = "the exact response by modal superposition"
    return Response(times, x, y, energy, "exact", 0.0, system.tip_dof, Status.SUCCESS, message,
                    "modal")  # fmt: skip


def modal_energies(system: LinearSystem, x: ArrayLike, y: ArrayLike) -> NDArray[np.float64]:
    """Energy in each mode, ``½ (u̇_i² + ω_i² u_i²)`` [J], shape (..., n_dofs), ascending ω.

    ``u = Φᵀ M (x − x_s)`` and ``u̇ = Φᵀ M y`` are the modal coordinates about the static
    solution ``x_s``; the energies sum to ``E − E_s`` with ``E_s = −½ fᵀ x_s`` the energy
    at rest at ``x_s``, and each stays constant in the exact undamped motion.

    Examples
    --------
    >>> from tumble.structural import cantilever
    >>> beam = cantilever(1.0, 4, E=210e9, rho=7850, width=0.01, height=0.01, tip_load=1.0)
    >>> energies = modal_energies(beam, np.zeros(8), np.zeros(8))   # at rest, unloaded shape
    >>> bool(np.isclose(energies.sum(), 0.5 / (3 * 175.0)))   # ½ F δ_static
    True
    """
    system = checked_system(system)
    x, y = dof_values(system, "x", x), dof_values(system, "y", y)
    omega, shapes = system.modes(system.n_dofs)
    static = shapes @ ((shapes.T @ system.f) / omega**2)
    u = (x - static) @ (system.M @ shapes)
    du = y @ (system.M @ shapes)
    return 0.5 * (du**2 + (omega * u) ** 2)
