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
======================  ========  ==========  =================================================
"""

from __future__ import annotations

from dataclasses import dataclass

from tumble import _checks
from tumble.ode.tableaux import DORMAND_PRINCE8, EULER, FEHLBERG45, RK4, ButcherTableau


@dataclass(frozen=True)
class Method:
    """A rigid-body integrator: how the attitude is carried, and the tableau that steps it.

    Attributes
    ----------
    name : str
        The name ``simulate`` takes.
    family : {"matrix", "quat", "lie"}
        ``matrix``: the nine entries of R in the state; ``quat``: a quaternion, renormalised
        after each step; ``lie``: RKMK in the local chart ``R = R_n exp(û)``.
    tableau : ButcherTableau
        The Runge–Kutta coefficients (the ODE core's).
    dexpinv : bool
        For the ``lie`` family: whether the stages are corrected by ``dexp⁻¹`` (True for a
        true RKMK method; False only for ``seed-rk4``).
    order_override : int, optional
        The method's order on a general body, when it differs from the tableau's
        (``seed-rk4``: 2). Tests measure it.
    """

    name: str
    family: str
    tableau: ButcherTableau
    dexpinv: bool = True
    order_override: int | None = None

    @property
    def order(self) -> int:
        """The convergence order the method claims (and the tests measure)."""
        return self.tableau.order if self.order_override is None else self.order_override

    @property
    def conserves(self) -> frozenset[str]:
        """The invariants kept to round-off on a torque-free body.

        ``"angular_momentum"``: every method steps ``L̇ = τ`` linearly, so without torque
        ``L`` is constant; ``"orthogonality"``: R stays a rotation (``lie`` and ``quat``
        families, which never leave SO(3) or renormalise onto it).
        """
        kept = {"angular_momentum"}
        if self.family in ("lie", "quat"):
            kept.add("orthogonality")
        return frozenset(kept)

    @property
    def adaptive(self) -> bool:
        """Whether the method chooses its own steps (an embedded pair)."""
        return self.tableau.adaptive


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
    )
}
"""Every rigid-body method by name."""


def get_method(name: str) -> Method:
    """The method called ``name``; a ValueError lists the known ones."""
    return METHODS[_checks.choice("method", name, METHODS, remedy="see tumble.rigid.METHODS")]
