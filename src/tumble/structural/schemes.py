"""The registry of structural schemes, :data:`SCHEMES`, and :func:`integrate`, which runs one.

Every scheme is a :class:`~tumble.structural.scheme.Scheme` (the contract: its matrices,
start, NumPy and compiled step, amplification matrix, critical step, order and label), and
each family lives in one module:

- :mod:`~tumble.structural.increments`: the seed's four (:class:`ThetaScheme`:
  ``explicit``, ``semi-implicit``, ``implicit``, ``midpoint``) and ``newmark``
  (:class:`Newmark`, average acceleration by default);
- :mod:`~tumble.structural.alpha`: ``hht``, ``generalized-alpha`` (by ρ∞) and ``bathe``
  (the ρ∞-Bathe composite), with controllable numerical damping;
- :mod:`~tumble.structural.wilson`: ``wilson`` (Wilson-θ, θ = 1.4 by default).

:data:`SCHEMES` is the one list of them: the tests, ``tumble stability --analyse``, the
report card and the docs iterate over it, and nothing else names a scheme class. Adding a
family is its module and one line here.

:func:`integrate` factorises the scheme's matrices once — banded Cholesky when their band
is narrow (every beam, and every frame numbered along its members or renumbered by reverse
Cuthill–McKee), sparse LU otherwise (:mod:`tumble.structural.factorization`) — and with
the banded factors runs the whole time loop compiled
(:class:`~tumble.structural.stepping.CompiledBeamStepper`: the scheme's compiled step inside
the one loop of :func:`tumble.structural.kernels.time_loop`), else the NumPy reference
(:class:`~tumble.structural.stepping.ReferenceBeamStepper`). Both are steppers of the
driver, :func:`tumble.ode.driver.march`. Every scheme is written *in increments*: the
out-of-balance force ``f − S x`` is carried and updated by ``S Δx`` computed element by
element, never recomputed from the global matrix (:mod:`~tumble.structural.increments`:
why, with the numbers).

References
----------
.. [1] Ł. Łaniewski-Wołłk, *Metody Numeryczne, Instrukcja 5: Równania ruchu* (seed 003).
.. [2] T. J. R. Hughes, *The Finite Element Method*, Dover, 2000, §9.1–9.3.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tumble import _checks
from tumble._progress import progress_bar
from tumble.ode.driver import Status, march
from tumble.structural.alpha import HHT, Bathe, GeneralizedAlpha
from tumble.structural.divergence import likely_cause
from tumble.structural.factorization import (
    MAX_BANDWIDTH,
    BandedCholesky,
    band_structure,
    banded_cholesky,
)
from tumble.structural.increments import Newmark, ThetaScheme
from tumble.structural.scheme import Scheme
from tumble.structural.stepping import (
    BeamState,
    CompiledBeamStepper,
    ReferenceBeamStepper,
    Watched,
    initial_state,
)
from tumble.structural.system import (
    LinearSystem,
    RayleighDamping,
    checked_damping,
    checked_system,
)
from tumble.structural.wilson import WilsonTheta

PROGRESS_UPDATES = 200
"""A progress bar is advanced about this many times per run."""

BLOCK_WORK = 2**24
"""Without a progress bar the compiled loop takes about this many DOF-steps per call."""

EXPLICIT = ThetaScheme("explicit", 0.0, 0.0, "almost explicit")
SEMI_IMPLICIT = ThetaScheme("semi-implicit", 0.0, 1.0, "semi-implicit")
IMPLICIT = ThetaScheme("implicit", 1.0, 1.0, "fully implicit")
MIDPOINT = ThetaScheme("midpoint", 0.5, 0.5, "midpoint (quarter steps)")
NEWMARK = Newmark()
HHT_ALPHA = HHT()
GENERALIZED_ALPHA = GeneralizedAlpha()
BATHE = Bathe()

SCHEMES: dict[str, Scheme] = {
    s.name: s
    for s in (EXPLICIT, SEMI_IMPLICIT, IMPLICIT, MIDPOINT, NEWMARK, HHT_ALPHA, GENERALIZED_ALPHA,
              BATHE, WilsonTheta())
}  # fmt: skip
"""The schemes by name, with their default parameters: ``newmark`` β = ¼, γ = ½; ``hht``
α = −0.05; ``generalized-alpha`` ρ∞ = 0.8; ``bathe`` ρ∞ = 0 (the original Bathe method);
``wilson`` θ = 1.4. Pass :class:`Newmark`, :class:`~tumble.structural.alpha.HHT`,
:class:`~tumble.structural.alpha.GeneralizedAlpha`, :class:`~tumble.structural.alpha.Bathe`
or :class:`~tumble.structural.wilson.WilsonTheta` to change them."""

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


def resolve_scheme(scheme: str | Scheme, name: str = "scheme") -> Scheme:
    """A scheme object from its name (one of :data:`SCHEMES`) or the object itself; the
    ValueError for anything else names ``name``."""
    if isinstance(scheme, Scheme):
        return scheme
    example = "or a scheme object, e.g. tumble.structural.Newmark(beta=0.3025, gamma=0.6)"
    return SCHEMES[_checks.choice(name, scheme, SCHEMES, remedy=example)]


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

    The scheme's constant matrices are factorised once, by their structure
    (:func:`~tumble.structural.factorization.band_structure`): banded Cholesky when the
    band is narrow, and then the whole loop runs compiled
    (:func:`~tumble.structural.kernels.time_loop`), a step costing one banded solve and
    one pass over the elements (two of each for Bathe); otherwise SuperLU and the NumPy
    reference (:mod:`tumble.structural.stepping`).

    Parameters
    ----------
    system : LinearSystem
        From :func:`~tumble.structural.cantilever` or :func:`~tumble.structural.build_frame`.
    scheme : str or scheme object
        A name from :data:`SCHEMES` (``"explicit"``, ``"semi-implicit"``, ``"implicit"``,
        ``"midpoint"``, ``"newmark"``, ``"hht"``, ``"generalized-alpha"``, ``"bathe"``,
        ``"wilson"``), or a scheme with its parameters, e.g.
        ``Newmark(beta=0.3025, gamma=0.6)``, ``GeneralizedAlpha(rho_inf=0.5)``
        (:mod:`tumble.structural.alpha`), ``WilsonTheta(theta=1.5)``.
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
    system = checked_system(system)
    scheme = resolve_scheme(scheme)
    dt = _checks.positive("dt", dt, "s")
    n_steps = _step_count(n_steps, t_end, dt)
    record_every = min(_checks.count("record_every", record_every), MAX_STEPS)
    progress = _checks.flag("progress", progress)
    compiled = _checks.optional_flag("compiled", compiled)
    _check_record_size(system, n_steps, record_every)
    state = _initial_state(system, x0, y0)
    damping = checked_damping(damping)
    C = None if damping is None else damping.matrix(system)
    block = min(
        max(1, n_steps // PROGRESS_UPDATES) if progress else n_steps,
        max(1, BLOCK_WORK // system.n_dofs),
    )  # Ctrl-C is seen between blocks; fmt: skip
    stepper, solver = _choose_stepper(system, scheme, dt, C, compiled, block)
    state, acceleration_energy = initial_state(scheme, system, state, C, dt)
    start = stepper.start(state, acceleration_energy)
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
) -> tuple[Watched, str]:
    """The compiled stepper with banded Cholesky factors of the step matrices, or the
    reference stepper with SuperLU; and the solver's name."""
    with np.errstate(over="ignore", invalid="ignore"):
        matrices = scheme.matrices(system, C, dt)
    for A in matrices:  # dt² S past 1.8e308: LAPACK, SuperLU would refuse it in their words
        if np.count_nonzero(np.isfinite(A.data)) != A.data.size:
            raise _checks.fail(
                "dt", dt, "a step whose step matrices are finite", "s",
                remedy=f"the {scheme.name} step's matrix (M, C dt and S dt² combined) overflows "
                "past 1.8e308; take a smaller dt",
            )  # fmt: skip
    factors = _banded_factors(matrices, compiled)
    if factors is None:
        return ReferenceBeamStepper(system, scheme, C, dt, matrices), "sparse-lu"
    return CompiledBeamStepper(system, scheme, C, dt, factors, block), "banded-cholesky"


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
        return _checks.count("n_steps", n_steps, 1, MAX_STEPS, remedy="a run this long never ends")
    t_end = _checks.positive("t_end", t_end, "s")
    steps = t_end / dt * (1 - 1e-12)
    if not steps <= MAX_STEPS:
        raise _checks.fail("t_end", t_end, f"at most {MAX_STEPS:.3g} steps of dt={dt!r} s", "s",
                           remedy=f"that is {steps:.3g} steps, a run that never ends")  # fmt: skip
    return max(1, math.ceil(steps))


MAX_STEPS = 2**62
"""The most steps (and the largest ``record_every``) :func:`integrate` takes: the compiled
loop counts them in int64 (at 10 ns a step, 1500 years)."""


def _check_record_size(system: LinearSystem, n_steps: int, record_every: int) -> None:
    """Refuse, before any work, a run whose records would not fit in half the memory."""
    records = n_steps // record_every + 2
    need = records * (2 * system.n_dofs + 2) * 8.0
    allowed = 0.5 * _checks.memory()
    if need > allowed:
        every = math.ceil(n_steps * (2 * system.n_dofs + 2) * 8.0 / allowed)
        raise _checks.fail(
            "n_steps", n_steps, f"a run whose {records:.3g} records fit in half the memory "
            f"({allowed / 2**30:.3g} GiB; they need {need / 2**30:.3g} GiB)",
            remedy=f"record fewer with record_every >= {every}, or take fewer steps",
        )  # fmt: skip


def _initial_state(system: LinearSystem, x0: ArrayLike | None, y0: ArrayLike | None) -> BeamState:
    start = []
    shape = (system.n_dofs,)
    for name, value, unit in (("x0", x0, "m, rad"), ("y0", y0, "m/s, rad/s")):
        if value is None:
            start.append(np.zeros(shape))
        else:
            start.append(_checks.array(name, value, shape=shape, unit=unit))
    return BeamState.start(system, *start)


def _quiet_overflow() -> contextlib.AbstractContextManager:
    """Diverging schemes overflow by design; the driver reports it as a status."""
    return np.errstate(over="ignore", invalid="ignore")
