"""Time-stepping schemes for ``M ẏ = f − S x − C y``, ``ẋ = y``, and one driver.

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
same kind of step. Every scheme is written *in increments* (:mod:`tumble.structural.stepping`):
the out-of-balance force ``f − S x`` is carried along and updated by ``S Δx`` computed
element by element, never recomputed from the global matrix. On fine meshes
(``κ(S) ∝ N⁴``) that keeps the midpoint tip deflection within 1.1e-4 (of ``F L³/3EI``) of
a converged 100-element run over 2000 steps at N = 10000, where the seed's plain form
(``b = M y + Δt (f − S x)`` each step) is off by 195 % and increments with a global
``S Δx`` by 193 % (measured).

:func:`integrate` factorises the constant matrix once — banded Cholesky when its band is
narrow (every beam, and every frame numbered along its members or renumbered by reverse
Cuthill–McKee), sparse LU otherwise (:mod:`tumble.structural.factorization`) — and with the
banded factor runs the whole time loop compiled (:func:`tumble.structural.kernels.run_steps`).

Three schemes with controllable numerical damping join them in :data:`SCHEMES`, written in
the same increments with their own compiled loops (:mod:`tumble.structural.alpha`):
``hht`` (:class:`~tumble.structural.alpha.HHT`), ``generalized-alpha``
(:class:`~tumble.structural.alpha.GeneralizedAlpha`, by ρ∞) and ``bathe``
(:class:`~tumble.structural.alpha.Bathe`, the ρ∞-Bathe composite). Every scheme declares its
``order`` (the tests measure it against :func:`~tumble.structural.exact_response`).

References
----------
.. [1] Ł. Łaniewski-Wołłk, *Metody Numeryczne, Instrukcja 5: Równania ruchu* (seed 003).
.. [2] N. M. Newmark, "A method of computation for structural dynamics", *J. Eng. Mech.
   Div. ASCE* 85 (EM3), 67–94, 1959.
.. [3] T. J. R. Hughes, *The Finite Element Method*, Dover, 2000, §9.1–9.3.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from tumble import _checks
from tumble._progress import progress_bar
from tumble.ode.driver import Status, march
from tumble.structural import stepping
from tumble.structural.alpha import HHT, AlphaScheme, Bathe, GeneralizedAlpha
from tumble.structural.divergence import likely_cause
from tumble.structural.factorization import (
    MAX_BANDWIDTH,
    BandedCholesky,
    band_structure,
    banded_cholesky,
)
from tumble.structural.stepping import Increments, State
from tumble.structural.system import LinearSystem, RayleighDamping

PROGRESS_UPDATES = 200
"""A progress bar is advanced about this many times per run."""

BLOCK_WORK = 2**24
"""Without a progress bar the compiled loop takes about this many DOF-steps per call."""


@dataclass(frozen=True)
class ThetaScheme:
    """A seed scheme: which of old/new ``x`` (θ_x) and ``y`` (θ_y) the step uses.

    See the module docstring for the equations. Instances: :data:`EXPLICIT`,
    :data:`SEMI_IMPLICIT`, :data:`IMPLICIT`, :data:`MIDPOINT`.
    """

    name: str
    theta_x: float
    theta_y: float
    seed_name: str

    @property
    def order(self) -> int:
        """Order of accuracy: 2 for θ_x = θ_y = ½ (midpoint), else 1."""
        return 2 if self.theta_x == self.theta_y == 0.5 else 1

    def matrix(self, system: LinearSystem, C: sp.spmatrix | None, dt: float) -> sp.spmatrix:
        """The constant matrix ``M + θ_y Δt C + θ_x θ_y Δt² S``."""
        A = system.M + (self.theta_x * self.theta_y * dt * dt) * system.S
        return A if C is None else A + (self.theta_y * dt) * C

    def increments(self, dt: float) -> Increments:
        """``k_g = θ_x Δt``, ``k_dy = θ_y Δt``: ``Δx = Δt (yⁿ + θ_y Δy)``."""
        return Increments(dt, self.theta_x * dt, self.theta_y * dt)


@dataclass(frozen=True)
class Newmark:
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
    def label(self) -> str:
        """The scheme with its parameters, as messages name it: ``Newmark β=1/6, γ=1/2``."""
        return f"Newmark β={_fraction(self.beta)}, γ={_fraction(self.gamma)}"

    def matrix(self, system: LinearSystem, C: sp.spmatrix | None, dt: float) -> sp.spmatrix:
        """The constant matrix ``M + γ Δt C + β Δt² S``."""
        A = system.M + (self.beta * dt * dt) * system.S
        return A if C is None else A + (self.gamma * dt) * C

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


EXPLICIT = ThetaScheme("explicit", 0.0, 0.0, "almost explicit")
SEMI_IMPLICIT = ThetaScheme("semi-implicit", 0.0, 1.0, "semi-implicit")
IMPLICIT = ThetaScheme("implicit", 1.0, 1.0, "fully implicit")
MIDPOINT = ThetaScheme("midpoint", 0.5, 0.5, "midpoint (quarter steps)")
NEWMARK = Newmark()
HHT_ALPHA = HHT()
GENERALIZED_ALPHA = GeneralizedAlpha()
BATHE = Bathe()

Scheme = ThetaScheme | Newmark | AlphaScheme | Bathe

SCHEMES: dict[str, Scheme] = {
    s.name: s
    for s in (EXPLICIT, SEMI_IMPLICIT, IMPLICIT, MIDPOINT, NEWMARK, HHT_ALPHA, GENERALIZED_ALPHA,
              BATHE)
}  # fmt: skip
"""The schemes by name, with their default parameters: ``newmark`` β = ¼, γ = ½; ``hht``
α = −0.05; ``generalized-alpha`` ρ∞ = 0.8; ``bathe`` ρ∞ = 0 (the original Bathe method).
Pass :class:`Newmark`, :class:`~tumble.structural.alpha.HHT`,
:class:`~tumble.structural.alpha.GeneralizedAlpha` or :class:`~tumble.structural.alpha.Bathe`
to change them."""

SEED_SCHEMES = ("explicit", "semi-implicit", "implicit", "midpoint")
"""The four schemes of seed 003, in its order."""


@dataclass(frozen=True, eq=False)
class Response:
    """The recorded motion of a :class:`LinearSystem` under one scheme.

    Attributes
    ----------
    t : ndarray, shape (n_records,)
        Times [s] of the records: every ``record_every`` steps, and the last step.
    x, y : ndarray, shape (n_records, n_dofs)
        Free-DOF displacements [m, rad] and velocities [m/s, rad/s].
    energy : ndarray, shape (n_records,)
        ``E = ½ yᵀ M y + ½ xᵀ S x − fᵀ x`` [J].
    scheme : str
        The scheme's name.
    dt : float
        Time step [s].
    tip_dof : int
        The system's monitored DOF.
    status : Status
        ``Status.SUCCESS``, or ``Status.FAILED`` if the state became non-finite (inf or
        NaN), or its energy did (a state past 1e150 overflows ``½ xᵀ S x``), or its energy
        grew past a million times what its start and its loads can supply
        (:mod:`~tumble.structural.divergence`: the run diverged); the records end with the
        last state before.
    message : str
        What happened, naming the step's times on failure, and then the likely cause
        (the step against the scheme's critical step, with the numbers).
    solver : str
        How the steps were solved: ``"banded-cholesky"`` (the compiled loop) or
        ``"sparse-lu"`` (the NumPy reference loop); see :func:`integrate`. Empty if
        unknown (a response built elsewhere).
    """

    t: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    energy: NDArray[np.float64]
    scheme: str
    dt: float
    tip_dof: int
    status: Status
    message: str
    solver: str = ""

    @property
    def tip_displacement(self) -> NDArray[np.float64]:
        """``x[:, tip_dof]`` [m], shape (n_records,)."""
        return self.x[:, self.tip_dof]

    @property
    def success(self) -> bool:
        """True unless the run diverged."""
        return self.status.success


def resolve_scheme(scheme: str | Scheme) -> Scheme:
    """A scheme object from its name (one of :data:`SCHEMES`) or the object itself."""
    if isinstance(scheme, ThetaScheme | Newmark | AlphaScheme | Bathe):
        return scheme
    return SCHEMES[_checks.choice("scheme", scheme, SCHEMES)]


def integrate(
    system: LinearSystem,
    scheme: str | Scheme,
    dt: float,
    *,
    n_steps: int | None = None,
    t_end: float | None = None,
    x0: ArrayLike | None = None,
    y0: ArrayLike | None = None,
    damping: RayleighDamping | None = None,
    record_every: int = 1,
    progress: bool = False,
    compiled: bool | None = None,
) -> Response:
    """Step ``M ẍ + C ẋ + S x = f`` from ``(x0, y0)`` with a fixed time step.

    The scheme's constant matrix is factorised once, by its structure
    (:func:`~tumble.structural.factorization.band_structure`): banded Cholesky when the
    band is narrow, and then the whole loop runs compiled
    (:func:`~tumble.structural.kernels.run_steps`), a step costing one banded solve and
    one pass over the elements; otherwise SuperLU and the NumPy reference loop
    (:mod:`tumble.structural.stepping`).

    Parameters
    ----------
    system : LinearSystem
        From :func:`~tumble.structural.cantilever` or :func:`~tumble.structural.build_frame`.
    scheme : str or scheme object
        A name from :data:`SCHEMES` (``"explicit"``, ``"semi-implicit"``, ``"implicit"``,
        ``"midpoint"``, ``"newmark"``, ``"hht"``, ``"generalized-alpha"``, ``"bathe"``), or
        a scheme with its parameters, e.g. ``Newmark(beta=0.3025, gamma=0.6)``,
        ``GeneralizedAlpha(rho_inf=0.5)`` (:mod:`tumble.structural.alpha`).
    dt : float
        Time step [s], > 0.
    n_steps, t_end : int or float
        Give exactly one: the number of steps, or the end time [s]
        (``n_steps = ceil(t_end/dt)``).
    x0, y0 : ndarray, shape (n_dofs,), optional
        Initial displacement [m, rad] and velocity [m/s, rad/s]; zero (rest) by default.
    damping : RayleighDamping, optional
        ``C = α M + β S``; none by default.
    record_every : int, optional
        Record every this many steps (the last step is always recorded); memory is
        ``2 n_dofs`` numbers per record.
    progress : bool, optional
        Show a ``rich`` progress bar.
    compiled : bool, optional
        Force (True) or forbid (False) the banded Cholesky and the compiled loop; by
        default they run when the band is narrow and the Cholesky completes (it can
        break down when ``κ(A) > 1/ε``, e.g. a 10⁵-element cantilever; SuperLU then
        steps). ``False`` runs the NumPy reference.

    Returns
    -------
    Response
        ``status == Status.FAILED`` if the state became non-finite, or its energy grew past
        a million times what the initial state and the loads can supply (checked every 64
        steps and at the last, :mod:`~tumble.structural.divergence`); the run stops there,
        with the last state before as its last record, and the message names the time, the
        growth and the likely cause. ``solver`` says which path ran.

    Examples
    --------
    >>> from tumble.structural import cantilever
    >>> beam = cantilever(1.0, 10, E=210e9, rho=7850, width=0.01, height=0.01, tip_load=1.0)
    >>> run = integrate(beam, "midpoint", dt=1e-4, n_steps=1000)
    >>> run.x.shape, bool(np.abs(run.energy).max() < 1e-12 * 0.5 * 1.0 / (3 * 175))
    ((1001, 20), True)
    >>> run.solver
    'banded-cholesky'
    """
    scheme = resolve_scheme(scheme)
    dt = _checks.positive("dt", dt, "s")
    n_steps = _step_count(n_steps, t_end, dt)
    record_every = _checks.count("record_every", record_every)
    state = _initial_state(system, x0, y0)
    C = None if damping is None else damping.matrix(system)
    block = min(
        max(1, n_steps // PROGRESS_UPDATES) if progress else n_steps,
        max(1, BLOCK_WORK // system.n_dofs),
    )  # Ctrl-C is seen between blocks; fmt: skip
    stepper, solver = _choose_stepper(system, scheme, dt, C, compiled, block)
    if isinstance(scheme, AlphaScheme | Bathe):
        state = scheme.start(system, state, C, dt)
    start = stepper.start(state)
    stepper.watch.final = n_steps  # checked at the last step too
    with progress_bar(progress, n_steps, scheme.name) as update, _quiet_overflow():

        def advance(t: float) -> None:
            update(completed=round(t / dt))

        out = march(stepper, (0.0, n_steps * dt), start, h=dt, record_every=record_every,
                    progress=advance if progress else None)  # fmt: skip
        energy = system.energy(*out.records)
    xs, ys = out.records
    t, status, message = out.t, out.status, out.message
    overflowed = ~np.isfinite(energy)
    if overflowed.any():  # a finite state whose energy is not: the run ends before it
        first = max(int(np.argmax(overflowed)), 1)
        size = float(np.max(np.abs(xs[first])))
        status = Status.FAILED
        message = (
            f"the energy stopped being finite at t={float(t[first])!r} (the displacements "
            f"reach {size:.3g}, finite, but ½ xᵀ S x overflows); the run ends with the last "
            f"record whose energy is finite, t={float(t[first - 1])!r}"
        )
        t, xs, ys, energy = t[:first], xs[:first], ys[:first], energy[:first]
    if not status.success:
        message = f"{message}; likely cause: {likely_cause(system, scheme, dt)}"
    return Response(t, xs, ys, energy, scheme.name, dt, system.tip_dof, status, message,
                    solver)  # fmt: skip


def _choose_stepper(
    system: LinearSystem, scheme: Scheme, dt: float, C, compiled: bool | None, block: int
) -> tuple[stepping.Watched, str]:
    """The compiled stepper with banded Cholesky factors of the step matrices, or the
    reference stepper with SuperLU; and the solver's name."""
    if isinstance(scheme, AlphaScheme | Bathe):
        matrices = scheme.matrices(system, C, dt)
    else:
        matrices = [scheme.matrix(system, C, dt)]
    factors = _banded_factors(matrices, compiled)
    if factors is None:
        if isinstance(scheme, AlphaScheme | Bathe):
            return scheme.reference(system, C, dt, matrices), "sparse-lu"
        return stepping.ReferenceStepper(
            system, scheme.increments(dt), matrices[0], C
        ), "sparse-lu"
    if isinstance(scheme, AlphaScheme | Bathe):
        return scheme.compiled(system, C, dt, factors, block), "banded-cholesky"
    stepper = stepping.CompiledStepper(system, scheme.increments(dt), factors[0], C, block)
    return stepper, "banded-cholesky"


def _banded_factors(matrices: list, compiled: bool | None) -> list[BandedCholesky] | None:
    """Banded Cholesky factors of ``matrices``, all in one DOF order (the first's), or None
    when the band is not narrow (or ``compiled=False``) and the caller should use SuperLU."""
    structure = band_structure(matrices[0])
    if not (structure.narrow if compiled is None else compiled):
        return None
    if structure.bandwidth > MAX_BANDWIDTH:
        raise _checks.fail(
            "compiled",
            compiled,
            f"None or False for a step matrix of half-bandwidth > {MAX_BANDWIDTH}",
            remedy=f"this one has {structure.bandwidth} even after reverse Cuthill–McKee; "
            "leave compiled=None to use the sparse LU",
        )
    try:
        first = banded_cholesky(matrices[0], structure.order)
        return [first] + [BandedCholesky.from_matrix(A, first.order) for A in matrices[1:]]
    except np.linalg.LinAlgError:  # κ(A) beyond 1/ε: a pivot came out <= 0
        if compiled:
            raise
        return None


def _step_count(n_steps: int | None, t_end: float | None, dt: float) -> int:
    one = "give exactly one of n_steps and t_end"
    if n_steps is None and t_end is None:
        raise _checks.fail("n_steps", None, "an integer >= 1 when t_end is not given", remedy=one)
    if n_steps is not None and t_end is not None:
        raise _checks.fail("t_end", t_end, "None when n_steps is given", remedy=one)
    if n_steps is not None:
        return _checks.count("n_steps", n_steps)
    t_end = _checks.positive("t_end", t_end, "s")
    return max(1, math.ceil(t_end / dt * (1 - 1e-12)))


def _initial_state(system: LinearSystem, x0: ArrayLike | None, y0: ArrayLike | None) -> State:
    start = []
    shape = (system.n_dofs,)
    for name, value, unit in (("x0", x0, "m, rad"), ("y0", y0, "m/s, rad/s")):
        if value is None:
            start.append(np.zeros(shape))
        else:
            start.append(_checks.array(name, value, shape=shape, unit=unit))
    return State.start(system, *start)


def _quiet_overflow() -> contextlib.AbstractContextManager:
    """Diverging schemes overflow by design; the driver reports it as a status."""
    return np.errstate(over="ignore", invalid="ignore")


def _fraction(value: float) -> str:
    """``1/6`` for a simple fraction, else 4 digits."""
    fraction = Fraction(value).limit_denominator(64)
    if abs(float(fraction) - value) <= 1e-12 * abs(value):
        return str(fraction)
    return f"{value:.4g}"
