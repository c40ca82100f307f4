"""The seed's four schemes and Newmark-β: one increment step with four constants.

The seed's four schemes differ only in which ``x`` and ``y`` the right-hand side uses, so
each is two numbers (:class:`ThetaScheme`):

.. math::

    M (y^{n+1} - y^n) = Δt \\,(f - S x^θ - C y^θ), \\qquad x^{n+1} = x^n + Δt\\, y^θ,

    x^θ = (1 - θ_x) x^n + θ_x x^{n+1}, \\qquad y^θ = (1 - θ_y) y^n + θ_y y^{n+1}.

=============== ====== ====== ========================================================
name            θ_x    θ_y    seed name; stability
=============== ====== ====== ========================================================
explicit        0      0      "almost explicit"; unstable for every Δt
semi-implicit   0      1      "semi-implicit" (symplectic Euler); Δt < 2/ω_max
implicit        1      1      "fully implicit" (backward Euler); unconditional, dissipates
midpoint        ½      ½      "w pół kroku" (quarter steps); unconditional, keeps energy
=============== ====== ====== ========================================================

Eliminating ``x^{n+1}`` gives one linear system per step with a constant matrix,
factorised once:

.. math::

    (M + θ_y Δt C + θ_x θ_y Δt^2 S)\\, Δy = Δt\\,(r^n - θ_x Δt\\, S y^n), \\qquad
    Δx = Δt\\,(y^n + θ_y Δy),

with ``r^n = f − S x^n − C y^n``. :class:`Newmark` (average acceleration by default) is the
same kind of step. So every scheme here is one step with four constants
(:class:`Increments`): with ``r = q − C y``, ``q = f − S x`` and, for Newmark with
``2β ≠ γ``, ``a = M⁻¹ r``,

.. math::

    A\\, Δy = Δt\\,(r - k_{sa}\\, S a - k_g\\, S y), \\qquad
    Δx = Δt\\, y + k_{dy}\\, Δy + k_a\\, a,

then ``x += Δx``, ``y += Δy`` and ``q −= S Δx``. Every product with ``S`` is summed
element by element; ``S y`` is summed afresh each step (carrying it too made the midpoint
energy drift 10× faster, measured). On fine meshes (``κ(S) ∝ N⁴``) the increments keep the
midpoint tip deflection within 1.1e-4 (of ``F L³/3EI``) of a converged 100-element run over
2000 steps at N = 10000, where the seed's plain form (``b = M y + Δt (f − S x)`` each step)
is off by 195 % and increments with a global ``S Δx`` by 193 % (measured). A step costs one
solve with the constant ``A`` and one pass over the elements for ``S Δx`` and ``S y`` (plus
a mass solve and ``S a`` for Newmark with ``2β ≠ γ``).

Stability on one mode ``ẍ = −ω² x``, ``z = ωΔt``: a :class:`ThetaScheme` step is a 2 × 2 map
``G`` with

.. math::

    \\det G = \\frac{1 + z^2 (1-θ_x)(1-θ_y)}{1 + z^2 θ_x θ_y}, \\qquad
    \\operatorname{tr} G = \\frac{2 - z^2 (θ_x + θ_y - 2 θ_x θ_y)}{1 + z^2 θ_x θ_y},

stable when ``|det G| ≤ 1`` and ``|tr G| ≤ 1 + det G``: never if ``θ_x + θ_y < 1`` (the
explicit scheme: energy grows at every step, by ``½ Δyᵀ M Δy + ½ Δxᵀ S Δx``); otherwise for
``z < 2/sqrt(q)`` with ``q = 2θ_x + 2θ_y − 4θ_xθ_y − 1``, which is ``Δt < 2/ω_max`` for
the semi-implicit scheme and every Δt (``q ≤ 0``) for the implicit and midpoint schemes.
Newmark is unconditionally stable for ``2β ≥ γ ≥ ½``, unstable for ``γ < ½``, and otherwise
needs ``ω_max Δt < 1/sqrt(γ/2 − β)`` (Hughes 2000, §9.1.2). These are the undamped limits;
Rayleigh damping only enlarges them here.

References
----------
.. [1] Ł. Łaniewski-Wołłk, *Metody Numeryczne, Instrukcja 5: Równania ruchu* (seed 003).
.. [2] N. M. Newmark, "A method of computation for structural dynamics", *J. Eng. Mech.
   Div. ASCE* 85 (EM3), 67–94, 1959.
.. [3] T. J. R. Hughes, *The Finite Element Method*, Dover, 2000, §9.1–9.3.
.. [4] E. Hairer, C. Lubich, G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
   Springer, 2006, §I.1 (symplectic Euler) and §IX (modified energy).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from fractions import Fraction

import numba
import numpy as np
import scipy.sparse as sp

from tumble import _checks
from tumble.structural.kernels import (
    StepKernel,
    assemble_internal_forces,
    assemble_internal_forces_pair,
    banded_solve,
)
from tumble.structural.scheme import Scheme
from tumble.structural.stepping import BeamState, Solve
from tumble.structural.system import LinearSystem


@dataclass(frozen=True)
class Increments:
    """The constants of one increment step (module docstring), for a scheme and a Δt.

    Attributes
    ----------
    dt : float
        Time step Δt [s].
    k_g : float
        [s]: ``θ_x Δt`` for a θ-scheme, ``γ Δt`` for Newmark.
    k_dy : float
        [s]: ``θ_y Δt``, or ``(β/γ) Δt``.
    k_sa : float
        [s²]: ``(γ/2 − β) Δt²`` for Newmark, else 0.
    k_a : float
        [s²]: ``(½ − β/γ) Δt²`` for Newmark, else 0.
    """

    dt: float
    k_g: float
    k_dy: float
    k_sa: float = 0.0
    k_a: float = 0.0

    @property
    def mass_solve(self) -> bool:
        """Whether a step needs ``a = M⁻¹ r`` (Newmark with ``2β ≠ γ``)."""
        return self.k_sa != 0.0 or self.k_a != 0.0


def increment_step(
    state: BeamState, system: LinearSystem, solves: list[Solve], C: sp.spmatrix | None,
    coefficients: tuple[float, ...],
) -> None:  # fmt: skip
    """One increment step (module docstring) in NumPy, updating ``state`` in place.

    ``coefficients`` are :class:`Increments`' fields; ``solves`` apply ``A⁻¹`` and, when the
    step needs ``a``, ``M⁻¹``.
    """
    dt, k_g, k_dy, k_sa, k_a = coefficients
    mass_solve = k_sa != 0.0 or k_a != 0.0
    forces = system.internal_forces
    r = state.q.copy()
    if C is not None:
        r -= C @ state.y
    rhs = r
    if mass_solve:
        a = solves[1](r)
        rhs = r - k_sa * forces(a)
    dy = solves[0](dt * (rhs - k_g * state.g))
    dx = dt * state.y + k_dy * dy
    if mass_solve:
        dx += k_a * a
    state.x += dx
    state.y += dy
    state.q -= forces(dx)
    if k_g:
        state.g = forces(state.y)


@numba.njit(cache=True, nogil=True, inline="always")
def increment_kernel(coefficients, state, frame, factors, damping, work):  # noqa: ANN001, ANN201
    """:func:`increment_step` compiled, for :func:`tumble.structural.kernels.time_loop`.

    The same operations in the same order, with the banded solve and no allocation: a pass
    for the right-hand side (which also takes the previous step's ``S Δx`` from ``q``: the
    step's ``lag``), the banded solve, a pass updating ``x`` and ``y``, and one pass over
    the elements for ``S Δx`` and ``S y`` together. Fusing the passes into the two sweeps
    of the solve made a step 3–15 % slower (measured), so they stay apart. ``state`` is
    ``(x, y, q, g = S y)``; ``factors`` hold the step matrix's and, for the mass solve,
    ``M``'s; ``work`` is the right-hand side (then ``Δy``, then ``Δx``), ``S Δx`` (the
    lag), ``a`` and ``S a``.
    """
    dt, k_g, k_dy, k_sa, k_a = coefficients
    use_mass = k_sa != 0.0 or k_a != 0.0
    x, y, q, g = state
    factor, mass_factor = factors[0], factors[-1]
    rhs, h, a, sa = work
    indptr, indices, data = damping
    n = x.size
    for i in range(n):  # r = q − C y, q = f − S x first taking the last step's S Δx
        q[i] -= h[i]
        r = q[i]
        if indptr.size:
            cy = 0.0
            for j in range(indptr[i], indptr[i + 1]):
                cy += data[j] * y[indices[j]]
            r -= cy
        rhs[i] = r
    if use_mass:  # a = M⁻¹ r
        a[:] = rhs
        banded_solve(mass_factor[0], mass_factor[1], mass_factor[2], a, mass_factor[3])
        assemble_internal_forces(a, *frame, sa)
        for i in range(n):
            rhs[i] -= k_sa * sa[i]
    for i in range(n):
        rhs[i] = dt * (rhs[i] - k_g * g[i])
    banded_solve(factor[0], factor[1], factor[2], rhs, factor[3])  # rhs = Δy
    non_finite = 0
    for i in range(n):
        dx = dt * y[i] + k_dy * rhs[i]
        if use_mass:
            dx += k_a * a[i]
        x[i] += dx
        y[i] += rhs[i]
        rhs[i] = dx
        non_finite += not (np.isfinite(x[i]) and np.isfinite(y[i]))
    if k_g != 0.0:
        # h = S Δx, g = S y
        assemble_internal_forces_pair(rhs, y, *frame, h, g)
    else:
        assemble_internal_forces(rhs, *frame, h)
    return non_finite


INCREMENTS = StepKernel("increments", increment_kernel, work=4, lag=1)
"""The compiled step of every :class:`ThetaScheme` and :class:`Newmark`."""


class IncrementScheme(Scheme):
    """What :class:`ThetaScheme` and :class:`Newmark` share: the increment step with the
    constants of :meth:`increments`, and its matrices."""

    kernel = INCREMENTS

    def increments(self, dt: float) -> Increments:
        """The four constants of the step for ``dt`` [s]."""
        raise NotImplementedError

    def coefficients(self, dt: float) -> tuple[float, ...]:
        """``(Δt, k_g, k_dy, k_sa, k_a)``: :meth:`increments` as the step reads them."""
        return dataclasses.astuple(self.increments(dt))

    def step(
        self, state: BeamState, system: LinearSystem, solves: list[Solve],
        C: sp.spmatrix | None, coefficients: tuple[float, ...],
    ) -> None:  # fmt: skip
        increment_step(state, system, solves, C, coefficients)


@dataclass(frozen=True)
class ThetaScheme(IncrementScheme):
    """A seed scheme: which of old/new ``x`` (θ_x) and ``y`` (θ_y) the step uses.

    See the module docstring for the equations. Instances: ``EXPLICIT``, ``SEMI_IMPLICIT``,
    ``IMPLICIT``, ``MIDPOINT`` of :mod:`tumble.structural.schemes`.
    """

    name: str
    theta_x: float
    theta_y: float
    seed_name: str

    def __post_init__(self) -> None:
        for name in ("name", "seed_name"):
            if not isinstance(getattr(self, name), str) or not getattr(self, name):
                raise _checks.fail(name, getattr(self, name), "a non-empty str")
        for name in ("theta_x", "theta_y"):
            theta = _checks.finite(name, getattr(self, name))
            if not 0 <= theta <= 1:
                raise _checks.fail(name, getattr(self, name), "in [0, 1]: the weight of the new "
                                   "value (0 old, 1 new, 1/2 midpoint)")  # fmt: skip

    @property
    def order(self) -> int:
        """Order of accuracy: 2 for θ_x = θ_y = ½ (midpoint), else 1."""
        return 2 if self.theta_x == self.theta_y == 0.5 else 1

    def matrices(self, system: LinearSystem, C: sp.spmatrix | None, dt: float) -> list:
        """The constant matrix ``M + θ_y Δt C + θ_x θ_y Δt² S``, in a list."""
        A = system.M + (self.theta_x * self.theta_y * dt * dt) * system.S
        return [A if C is None else A + (self.theta_y * dt) * C]

    def increments(self, dt: float) -> Increments:
        """``k_g = θ_x Δt``, ``k_dy = θ_y Δt``: ``Δx = Δt (yⁿ + θ_y Δy)``."""
        return Increments(dt, self.theta_x * dt, self.theta_y * dt)

    def critical_omega(self) -> float:
        """``2/sqrt(q)``, ``q = 2θ_x + 2θ_y − 4θ_xθ_y − 1`` (module docstring); 0 when
        ``θ_x + θ_y < 1``, ``inf`` when ``q ≤ 0``."""
        theta_x, theta_y = self.theta_x, self.theta_y
        if theta_x + theta_y < 1:
            return 0.0
        q = 2 * theta_x + 2 * theta_y - 4 * theta_x * theta_y - 1
        return math.inf if q <= 0 else 2.0 / math.sqrt(q)


@dataclass(frozen=True)
class Newmark(IncrementScheme):
    """Newmark-β: ``x⁺ = x + Δt y + Δt²((½ − β) a + β a⁺)``, ``y⁺ = y + Δt((1 − γ) a + γ a⁺)``.

    With ``M a = f − S x − C y`` at every step. Written in velocity increments like the
    θ-schemes, using ``M aⁿ = rⁿ``:

    .. math::

        (M + γ Δt C + β Δt^2 S)\\, Δy = Δt\\,(r^n - γ Δt\\, S y^n - (γ/2 - β) Δt^2 S a^n),

        Δx = Δt\\, y^n + (β/γ) Δt\\, Δy + (½ - β/γ) Δt^2 a^n,

    where ``aⁿ = M⁻¹ rⁿ`` is needed only when ``2β ≠ γ``. β = ¼, γ = ½ (average
    acceleration, the default) is the midpoint scheme; it is unconditionally stable for
    ``2β ≥ γ ≥ ½``.

    Parameters
    ----------
    beta : float
        β ≥ 0.
    gamma : float
        γ > 0 (γ < ½ is unstable, γ > ½ damps high frequencies).
    """

    beta: float = 0.25
    gamma: float = 0.5
    name: str = field(default="newmark", init=False)

    def __post_init__(self) -> None:
        _checks.non_negative("beta", self.beta)
        _checks.positive("gamma", self.gamma)

    @property
    def order(self) -> int:
        """Order of accuracy: 2 for γ = ½, else 1 (Hughes 2000, §9.1)."""
        return 2 if self.gamma == 0.5 else 1

    @property
    def carries_acceleration(self) -> bool:
        """With ``2β ≠ γ`` its steps use ``aⁿ = M⁻¹ rⁿ``: ``x`` moves by ``Δt² a₀`` terms."""
        return 2 * self.beta != self.gamma

    @property
    def label(self) -> str:
        """The scheme with its parameters, as messages name it: ``Newmark β=1/6, γ=1/2``."""
        return f"Newmark β={_fraction(self.beta)}, γ={_fraction(self.gamma)}"

    def matrices(self, system: LinearSystem, C: sp.spmatrix | None, dt: float) -> list:
        """The constant matrix ``M + γ Δt C + β Δt² S``, and ``M`` when ``2β ≠ γ``."""
        A = system.M + (self.beta * dt * dt) * system.S
        A = A if C is None else A + (self.gamma * dt) * C
        return [A, system.M] if self.increments(dt).mass_solve else [A]

    def increments(self, dt: float) -> Increments:
        """The constants of the equations above; the ``aⁿ`` terms vanish when ``2β = γ``."""
        beta, gamma = self.beta, self.gamma
        return Increments(
            dt,
            k_g=gamma * dt,
            k_dy=beta / gamma * dt,
            k_sa=(gamma / 2 - beta) * dt * dt,
            k_a=(0.5 - beta / gamma) * dt * dt,
        )

    def critical_omega(self) -> float:
        """0 for ``γ < ½``, ``inf`` for ``2β ≥ γ``, else ``1/sqrt(γ/2 − β)`` (Hughes 2000,
        §9.1.2)."""
        beta, gamma = self.beta, self.gamma
        if gamma < 0.5:
            return 0.0
        return math.inf if 2 * beta >= gamma else 1.0 / math.sqrt(gamma / 2 - beta)


def _fraction(value: float) -> str:
    """``1/6`` for a simple fraction, else 4 digits."""
    fraction = Fraction(value).limit_denominator(64)
    if abs(float(fraction) - value) <= 1e-12 * abs(value):
        return str(fraction)
    return f"{value:.4g}"
