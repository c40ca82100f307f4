"""The rigid-body methods by name: a family (how the attitude is carried) plus a tableau.

======================  ========  ==========  =================================================
name                    family    tableau     what it is
======================  ========  ==========  =================================================
``euler``               matrix    Euler       seed 002 eq. 24, ``W + h W Ω̃``: leaves SO(3)
``rk4-matrix``          matrix    RK4         classical RK4 on the flattened matrix (seed 000's
                                              ``odeint`` way): order 4, drifts off SO(3)
``euler-quat``          quat      Euler       seed 001's first listing: Euler on
                                              ``q̇ = ½ q ⊗ (0, ω)``, then ``q ← q/|q|``
``rk4-quat``            quat      RK4         seed 001: RK4 on ``q̇ = ½ q ⊗ (0, ω)``, then
                                              ``q ← q/|q|``
``lie-euler``           lie       Euler       seed 002 eq. 25, ``W exp(h Ω̃)``
``seed-rk4``            lie       RK4         seed 002's "RK4": Lie-algebra stages *without*
                                              dexp⁻¹; order 2 on an asymmetric body
``rkmk4``               lie       RK4         Runge–Kutta–Munthe-Kaas, stages corrected by
                                              dexp⁻¹: order 4, stays on SO(3)
``rkmk8``               lie       DOP853      RKMK with the 12 stages and order-8 weights of
                                              Dormand–Prince's DOP853: order 8
``rkmk45``              lie       Fehlberg    adaptive RKMK with Fehlberg's 4(5) pair
``rkmk-dopri5``         lie       DOPRI5      adaptive RKMK with Dormand–Prince's 5(4) pair
======================  ========  ==========  =================================================

The geometric methods (family ``split``) are splittings, not tableaux: each step is
``K(h/2) ∘ D(h) ∘ K(h/2)``, a kick of the loads ``(p, L) += (h/2)(F, τ)`` around a drift
``x += h p/m`` with the free body's rotation advanced by the method's *flow*; a composition
(Yoshida 1990) raises the order of that symmetric step to 4. :mod:`tumble.rigid.geometric`
has the flows and their sources.

======================  ========  ==========  =================================================
name                    family    flow        what it is
======================  ========  ==========  =================================================
``split-axes``          split     axes        rotations about the principal axes in turn
                                              (McLachlan 1993, Reich 1994): explicit, order 2
``split-axes4``         split     axes        ``split-axes`` composed by Yoshida: order 4
``midpoint-lp``         split     midpoint    implicit midpoint rule on the Lie–Poisson
                                              equation, Cayley map for R: keeps the energy
``dmv``                 split     dmv         discrete Moser–Veselov (Moser–Veselov 1991):
                                              keeps the energy
``exact``               split     exact       the exact free-body flow (Jacobi's elliptic
                                              functions): round-off at any h; no loads
``strang``              split     exact       Strang splitting of loads and the exact flow:
                                              order 2
``yoshida4``            split     exact       ``strang`` composed by Yoshida: order 4
======================  ========  ==========  =================================================

All are symplectic (with conservative loads), keep ``|L|`` and stay on SO(3); without
loads the energy error stays bounded over any number of steps, and ``midpoint-lp``,
``dmv`` and the three on the exact flow keep it exactly (a quadratic invariant of the
midpoint rule; an integral of the Moser–Veselov map; the exact solution). With loads,
``split-axes`` is the Strang splitting on the axes flow, ``strang`` on the exact one.

The Crouch–Grossman methods (family ``cg``, :mod:`tumble.rigid.crouch_grossman`) compose
the stages' rotations instead of adding their slopes, so every stage stays on SO(3) with no
``dexp⁻¹``:

======================  ========  ==========  =================================================
name                    family    tableau     what it is
======================  ========  ==========  =================================================
``cg3``                 cg        CG3         Crouch & Grossman (1993): 3 stages, order 3
``cg4``                 cg        CG4         Jackiewicz, Marthinsen & Owren (2000): 5
                                              stages, order 4
======================  ========  ==========  =================================================

Each family is registered in :data:`FAMILIES` (:mod:`tumble.rigid.families`): it says which
stepper runs its methods, in Python and compiled, what they record and keep, and how a batch
runs them. A method is one line of :data:`METHODS`; a family of methods is one entry of
:data:`FAMILIES` and the module that implements it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tumble import _checks
from tumble.ode.tableaux import (
    DORMAND_PRINCE8,
    DORMAND_PRINCE54,
    EULER,
    FEHLBERG45,
    RK4,
    ButcherTableau,
)
from tumble.rigid.charts import LIE, MATRIX, QUAT
from tumble.rigid.crouch_grossman import CG3, CG4, CrouchGrossmanFamily
from tumble.rigid.families import ON_SO3, ChartFamily, Family, SplitFamily

_CUBE_ROOT_2 = 2.0 ** (1.0 / 3.0)
YOSHIDA4 = (
    1.0 / (2.0 - _CUBE_ROOT_2),
    -_CUBE_ROOT_2 / (2.0 - _CUBE_ROOT_2),
    1.0 / (2.0 - _CUBE_ROOT_2),
)
"""Yoshida's triple jump: ``S(γ₁h) S(γ₂h) S(γ₁h)`` of a symmetric order-2 step ``S`` has
order 4 (H. Yoshida, Phys. Lett. A 150 (1990) 262–268, eq. 4.14)."""


@dataclass(frozen=True)
class Method:
    """A rigid-body integrator: how the attitude is carried, and the tableau that steps it.

    Attributes
    ----------
    name : str
        The name ``simulate`` takes.
    family : {"matrix", "quat", "lie", "split", "cg"}
        A name in :data:`FAMILIES`. ``matrix``: the nine entries of R in the state; ``quat``:
        a quaternion, renormalised after each step; ``lie``: RKMK in the local chart
        ``R = R_n exp(û)``; ``split``: a splitting of kicks and a free-body flow (module
        docstring).
    tableau : ButcherTableau, optional
        The Runge–Kutta coefficients (the ODE core's); None for the ``split`` family.
    dexpinv : bool
        For the ``lie`` family: whether the stages are corrected by ``dexp⁻¹`` (True for a
        true RKMK method; False only for ``seed-rk4``).
    order_override : int, optional
        The method's order on a general body, when it differs from the tableau's
        (``seed-rk4``: 2), or of a ``split`` method. Tests measure it.
    flow : {"axes", "midpoint", "dmv"}, optional
        For the ``split`` family: how the free body's rotation is advanced
        (:data:`tumble.rigid.geometric.FLOWS`).
    weights : tuple of float
        For the ``split`` family: the composition ``S(w₁h) ∘ S(w₂h) ∘ …`` of the symmetric
        step ``S`` (``(1,)``: one step; :data:`YOSHIDA4`: order 4).
    """

    name: str
    family: str
    tableau: ButcherTableau | None = None
    dexpinv: bool = True
    order_override: int | None = None
    flow: str | None = None
    weights: tuple[float, ...] = (1.0,)

    @property
    def exact(self) -> bool:
        """Whether the method is the exact flow itself (``exact``): its error is round-off
        whatever h, so it has no order (:attr:`order` is ``inf``) and takes no loads."""
        return self.flow == "exact" and self.order_override is None

    @property
    def order(self) -> float:
        """The convergence order the method claims (and the tests measure); ``inf`` for the
        exact flow."""
        if self.order_override is not None:
            return self.order_override
        if self.exact:
            return math.inf
        assert self.tableau is not None, "a split method declares its order"
        return self.tableau.order

    @property
    def conserves(self) -> frozenset[str]:
        """The invariants kept to round-off on a torque-free body.

        Its family answers (:meth:`Family.conserves
        <tumble.rigid.families.Family.conserves>`). ``"angular_momentum"``: every method
        steps ``L̇ = τ`` linearly (or kicks it), so without torque ``L`` is constant;
        ``"orthogonality"``: R stays a rotation (``lie``, ``quat`` and ``split`` families,
        which never leave SO(3) or renormalise onto it);
        ``"casimir"``: the body momentum's norm ``|RᵀL| = |L|``, the Casimir of the
        Lie–Poisson equation (the same families: it follows from R staying a rotation);
        ``"energy"``: the kinetic energy of the free body (``midpoint-lp``, ``dmv`` and the
        methods on the exact flow). :mod:`tumble.report_card` measures each claim.
        """
        return FAMILIES[self.family].conserves(self)

    @property
    def symplectic(self) -> bool:
        """Whether the method is symplectic (and Poisson) on the rigid body: the ``split``
        family. Its energy error then stays bounded over long runs, without loads or with
        loads that derive from a potential (Hairer–Lubich–Wanner, ch. VI and IX)."""
        return FAMILIES[self.family].symplectic

    @property
    def adaptive(self) -> bool:
        """Whether the method chooses its own steps (an embedded pair)."""
        return self.tableau is not None and self.tableau.adaptive


FAMILIES: dict[str, Family] = {
    family.name: family
    for family in (
        ChartFamily(MATRIX),  # leaves SO(3)
        ChartFamily(QUAT, keeps=ON_SO3, columns=True),
        ChartFamily(LIE, keeps=ON_SO3, compiled_adaptive=True, columns=True),
        SplitFamily(),
        CrouchGrossmanFamily(),
    )
}
"""Every family of methods by name (:mod:`tumble.rigid.families`): a method's ``family``
names one."""

METHODS: dict[str, Method] = {
    method.name: method
    for method in (
        Method("euler", "matrix", EULER),
        Method("rk4-matrix", "matrix", RK4),
        Method("euler-quat", "quat", EULER),
        Method("rk4-quat", "quat", RK4),
        Method("lie-euler", "lie", EULER),
        Method("seed-rk4", "lie", RK4, dexpinv=False, order_override=2),
        Method("rkmk4", "lie", RK4),
        Method("rkmk8", "lie", DORMAND_PRINCE8),
        Method("rkmk45", "lie", FEHLBERG45),
        Method("rkmk-dopri5", "lie", DORMAND_PRINCE54),
        Method("split-axes", "split", flow="axes", order_override=2),
        Method("split-axes4", "split", flow="axes", weights=YOSHIDA4, order_override=4),
        Method("midpoint-lp", "split", flow="midpoint", order_override=2),
        Method("dmv", "split", flow="dmv", order_override=2),
        Method("exact", "split", flow="exact"),
        Method("strang", "split", flow="exact", order_override=2),
        Method("yoshida4", "split", flow="exact", weights=YOSHIDA4, order_override=4),
        Method("cg3", "cg", CG3),
        Method("cg4", "cg", CG4),
    )
}
"""Every rigid-body method by name."""


def get_method(name: str) -> Method:
    """The method called ``name``; a ValueError lists the known ones."""
    return METHODS[_checks.choice("method", name, METHODS, remedy="see tumble.rigid.METHODS")]
