"""Free-body flows of the geometric methods, and the splitting that adds the loads (NumPy).

Each flow advances the attitude of a torque-free body over ``h`` with the world angular
momentum ``L`` fixed. It works in the *principal* frame: ``R_p = R P`` with ``P`` the
principal axes (:func:`principal_frame`), so that the inertia is ``diag(I₁, I₂, I₃)`` and the
body momentum is ``m = R_pᵀ L``; the free body's equations are

.. math:: \\dot m = m \\times \\omega, \\qquad \\dot R_p = R_p \\hat\\omega, \\qquad
          \\omega = I^{-1} m,

and ``R_p m = L`` stays constant. Every flow below turns ``R_p`` by an exact rotation
``R_p ← R_p Ω`` (so R stays on SO(3) and ``|m| = |L|`` to round-off) with ``m ← Ωᵀ m``:

``axes``
    The Hamiltonian ``H = Σ mᵢ²/(2Iᵢ)`` split by axes, each part's flow exact: a rotation
    about axis i by ``h mᵢ/Iᵢ``; Strang's order ``1, 2, 3, 2, 1`` with half steps outside
    (McLachlan 1993; Reich 1994; Dullweber–Leimkuhler–McLachlan 1997). Explicit, order 2.
``midpoint``
    The implicit midpoint rule on the Lie–Poisson equation,
    ``m̄ = m + (h/2) m̄ × I⁻¹m̄``, ``Ω = cay(h I⁻¹m̄)`` with the Cayley map
    ``cay(v) = (1 − v̂/2)⁻¹(1 + v̂/2)``: then ``Ωᵀ m`` *is* the midpoint rule's
    ``m_{n+1} = 2m̄ − m``, and both quadratic invariants, ``|m|²`` and the energy
    ``½ mᵀI⁻¹m``, are kept exactly (Austin–Krishnaprasad–Wang 1993; Hairer–Lubich–Wanner
    §IV.2 and §VII.5). Order 2.
``dmv``
    The discrete Moser–Veselov algorithm: ``Ω`` is the rotation with
    ``h m̂ = Ω D − D Ωᵀ``, ``D = diag(dᵢ)``, ``dᵢ = (I_j + I_k − Iᵢ)/2`` (Moser & Veselov 1991;
    Hairer–Lubich–Wanner §VII.5.3). Written with Ω's quaternion ``(e₀, e)``, the equation
    reads ``h m = 2 e₀ I e + 2 (D e) × e``. Symplectic, order 2; it keeps the energy exactly
    (Moser–Veselov's integrals of the discrete map include it; ``tests/rigid`` measures
    round-off at h up to 0.5).

``exact``
    The exact flow: ω(t) by Jacobi's elliptic functions and R(t) by the closed form of
    :func:`tumble.exact.free_body_rotation` (Landau–Lifshitz §37; Celledoni, Fassò, Säfström
    and Zanna 2008), evaluated afresh from each step's state, so its error is round-off
    whatever h. The elliptic parameter's complement ``1 − m`` is formed without cancellation;
    the phase and the precession integral are taken from sn, cn² and dn² themselves (never
    through an angle, which near the middle axis keeps a small cn only to an absolute ε),
    and Jacobi's functions keep each of sn, cn, dn to a few ε relative: so a step is
    accurate to its round-off up to the separatrix ``m → 1``. Only where the state cannot
    tell which side of the separatrix it is on, ``|x − y| ≤ 2ε (x + y)`` for
    ``Δ = |L|² − 2EB = x² − y²`` (the round-off of x and y,
    :data:`tumble._elliptic.SEPARATRIX_RTOL`), does the step use the limit ``sn → tanh``,
    ``cn, dn → sech``, where the elliptic form's period is infinite. Over many steps the
    error is the problem's own round-off floor (an ulp of the state, propagated), which
    near the separatrix is large; docs/geometric.md has the measurements. Each step ends
    with one Newton step to the polar factor, ``R ← R (3 − RᵀR)/2``: the closed form's
    round-off otherwise grows ``det R`` by about 1.6e-16 a step, a secular energy drift.

The two implicit flows are solved by Newton's method (a 3 × 3 system) to round-off, at most
:data:`NEWTON_MAX` iterations; when that does not converge the step fails with
:class:`FlowNotConverged` (``simulate`` stops with status −1 and names the time).

:func:`split_step` is one step of a ``split`` method with loads: the symmetric
``K(h/2) ∘ D(h) ∘ K(h/2)``, kicks ``(p, L) += (h/2)(F, τ)`` around the drift ``x += h p/m``
and the flow, composed with the method's weights. Its compiled twin is in
:mod:`tumble.rigid._compiled`; ``tests/rigid`` checks that they agree to round-off.

References
----------
.. [1] R. I. McLachlan, "Explicit Lie–Poisson integration and the Euler equations",
   Phys. Rev. Lett. 71 (1993) 3043–3046.
.. [2] S. Reich, "Momentum conserving symplectic integrators", Physica D 76 (1994) 375–383.
.. [3] A. Dullweber, B. Leimkuhler, R. McLachlan, "Symplectic splitting methods for rigid
   body molecular dynamics", J. Chem. Phys. 107 (1997) 5840–5851.
.. [4] J. Moser, A. P. Veselov, "Discrete versions of some classical integrable systems and
   factorization of matrix polynomials", Comm. Math. Phys. 139 (1991) 217–243.
.. [5] M. Austin, P. S. Krishnaprasad, L.-S. Wang, "Almost Poisson integration of rigid body
   systems", J. Comput. Phys. 107 (1993) 105–117.
.. [6] E. Hairer, C. Lubich, G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
   Springer 2006, §VII.5.
.. [7] H. Yoshida, "Construction of higher order symplectic integrators", Phys. Lett. A 150
   (1990) 262–268.
.. [8] E. Celledoni, F. Fassò, N. Säfström, A. Zanna, "The exact computation of the free
   rigid body motion and its use in splitting methods", SIAM J. Sci. Comput. 30 (2008)
   2084–2112.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from tumble import so3
from tumble._elliptic import flow_rotation, principal_axes

NEWTON_MAX = 30
"""Newton iterations allowed to an implicit flow; converged flows take 3–6."""

NEWTON_TOL = 4.0 * np.finfo(float).eps
"""Newton stops when its update is below this fraction of the unknown (a few ulps)."""

_AXES_SEQUENCE = ((0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5))
"""Strang's splitting by axes: (axis, fraction of h)."""


class FlowNotConverged(ArithmeticError):
    """An implicit flow's Newton iteration did not converge in :data:`NEWTON_MAX` steps."""


_EVEN = {(0, 1, 2), (1, 2, 0), (2, 0, 1)}


def principal_frame(inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(moments, P)``: principal moments (ascending) and the proper rotation ``P`` whose
    columns are the principal axes in body coordinates, ``I = P diag(moments) Pᵀ``.

    ``inertia`` is a :class:`~tumble.rigid.RigidBody`'s (checked already); a diagonal one takes
    a fast path that gives what :func:`tumble._elliptic.principal_axes` gives.
    """
    if inertia[0, 1] == inertia[0, 2] == inertia[1, 2] == 0.0:
        diagonal = inertia.diagonal().tolist()
        order = tuple(sorted(range(3), key=diagonal.__getitem__))  # stable, as argsort's
        axes = np.zeros((3, 3))
        axes[order, (0, 1, 2)] = 1.0  # column j is the axis order[j]
        if order not in _EVEN:
            axes[:, 0] = -axes[:, 0]
        return np.array([diagonal[k] for k in order]), axes
    return principal_axes(inertia)


def _axis_rotation(axis: int, angle: float) -> np.ndarray:
    return so3.exp(angle * np.eye(3)[axis])


def axes_flow(Rp: np.ndarray, L: np.ndarray, moments: np.ndarray, h: float) -> np.ndarray:
    """The ``axes`` flow over ``h``: ``R_p`` after the five exact axis rotations."""
    m = Rp.T @ L
    for axis, fraction in _AXES_SEQUENCE:
        turn = _axis_rotation(axis, fraction * h * m[axis] / moments[axis])
        Rp, m = Rp @ turn, turn.T @ m
    return Rp


def _newton(residual: Callable, jacobian: Callable, guess: np.ndarray) -> np.ndarray:
    """Newton's method on a 3-vector: converged to :data:`NEWTON_TOL`, else the error."""
    x = guess
    for _ in range(NEWTON_MAX):
        delta = np.linalg.solve(jacobian(x), residual(x))
        x = x - delta
        if not np.all(np.isfinite(x)):
            break
        if np.linalg.norm(delta) <= NEWTON_TOL * np.linalg.norm(x):
            return x
    raise FlowNotConverged


def cayley(v: np.ndarray) -> np.ndarray:
    """``cay(v) = (1 − v̂/2)⁻¹(1 + v̂/2) = 1 + 4/(4 + |v|²) (v̂ + v̂²/2)``: a rotation."""
    V = so3.hat(v)
    return np.eye(3) + 4.0 / (4.0 + v @ v) * (V + 0.5 * V @ V)


def midpoint_flow(Rp: np.ndarray, L: np.ndarray, moments: np.ndarray, h: float) -> np.ndarray:
    """The ``midpoint`` flow over ``h`` (module docstring); FlowNotConverged if Newton fails."""
    m, inverse = Rp.T @ L, 1.0 / moments

    def residual(w):
        return w - m - 0.5 * h * np.cross(w, inverse * w)

    def jacobian(w):
        return np.eye(3) - 0.5 * h * (so3.hat(w) @ np.diag(inverse) - so3.hat(inverse * w))

    mean = _newton(residual, jacobian, m)
    return Rp @ cayley(h * inverse * mean)


def dmv_flow(Rp: np.ndarray, L: np.ndarray, moments: np.ndarray, h: float) -> np.ndarray:
    """The ``dmv`` flow over ``h`` (module docstring); FlowNotConverged if Newton fails."""
    m, d = Rp.T @ L, 0.5 * moments.sum() - moments

    def residual(e):
        e0 = np.sqrt(1.0 - e @ e)
        return 2.0 * e0 * moments * e + 2.0 * np.cross(d * e, e) - h * m

    def jacobian(e):
        e0 = np.sqrt(1.0 - e @ e)
        return (
            2.0 * e0 * np.diag(moments)
            - 2.0 * np.outer(moments * e, e) / e0
            + 2.0 * (so3.hat(d * e) - so3.hat(e) @ np.diag(d))
        )

    e = _newton(residual, jacobian, 0.5 * h * m / moments)
    if e @ e >= 1.0:
        raise FlowNotConverged
    return Rp @ so3.matrix_from_quat(np.concatenate([[np.sqrt(1.0 - e @ e)], e]))


def exact_flow(Rp: np.ndarray, L: np.ndarray, moments: np.ndarray, h: float) -> np.ndarray:
    """The ``exact`` flow over ``h``: the closed form of :func:`tumble.exact.free_body_rotation`
    from the state, on the separatrix its ``m = 1`` limit (module docstring)."""
    R = flow_rotation(moments, (Rp.T @ L) / moments, Rp, h)
    return R @ (1.5 * np.eye(3) - 0.5 * R.T @ R)  # back onto SO(3): one Newton step


FLOWS: dict[str, Callable[[np.ndarray, np.ndarray, np.ndarray, float], np.ndarray]] = {
    "axes": axes_flow,
    "midpoint": midpoint_flow,
    "dmv": dmv_flow,
    "exact": exact_flow,
}
"""Each free-body flow by name: ``flow(R_p, L, moments, h) -> R_p`` (module docstring)."""

ENERGY_FLOWS = frozenset({"midpoint", "dmv", "exact"})
"""The flows that keep the free body's kinetic energy exactly (up to round-off and Newton's
tolerance): a quadratic invariant of the midpoint rule, an integral of the Moser–Veselov
map, the exact solution. ``axes`` keeps it only to ``O(h²)``, bounded over long runs."""


def split_step(
    flow: Callable,
    weights: tuple[float, ...],
    kick: Callable[[float, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]],
    moments: np.ndarray,
    mass: float,
    t: float,
    Rp: np.ndarray,
    Y: np.ndarray,
    h: float,
) -> tuple[np.ndarray, np.ndarray]:
    """One step of a ``split`` method: ``∏ S(wᵢ h)`` with ``S = K(h/2) ∘ D(h) ∘ K(h/2)``.

    ``kick(t, R_p, Y)`` returns ``(F, τ)`` at the state; ``Y = (x, p, L)``. The drift moves
    ``x += h p/m`` and turns ``R_p`` by ``flow``; time advances with the drift.
    """
    Y = Y.copy()
    for weight in weights:
        sub = weight * h
        F, tau = kick(t, Rp, Y)
        Y[3:6] += 0.5 * sub * F
        Y[6:] += 0.5 * sub * tau
        Y[:3] += sub * Y[3:6] / mass
        Rp = flow(Rp, Y[6:], moments, sub)
        t += sub
        F, tau = kick(t, Rp, Y)
        Y[3:6] += 0.5 * sub * F
        Y[6:] += 0.5 * sub * tau
    return Rp, Y
