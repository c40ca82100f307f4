"""What a structural time-stepping scheme is: the contract every scheme of
:data:`~tumble.structural.SCHEMES` fulfils.

A scheme steps ``M ẍ + C ẋ + S x = f`` (``y = ẋ``) with a fixed ``Δt`` by solving with
constant matrices, factorised once. It declares everything the rest of the package asks
about, so that nothing outside the registry (:mod:`tumble.structural.schemes`) needs to
know which scheme it holds:

=========================== ============================================================
member                      what it gives
=========================== ============================================================
``name``                    its key in ``SCHEMES`` and in results
``label``                   how messages name it, with its parameters
``order``                   its declared order of accuracy (tests and the report card
                            measure it)
``carries_acceleration``    whether its state starts from ``a₀ = M⁻¹ r₀`` (the energy
                            watch then allows for ``½ Δt² a₀ᵀMa₀``)
``matrices(system, C, dt)`` the matrices its step solves with, ``A ≥ M`` first
``coefficients(dt)``        the numbers its step reads (``Δt`` first)
``start(…)``                its stepped state from ``(x₀, y₀)``
``step(…)``                 one step in NumPy, in place: the reference
``kernel``                  the same step compiled (a
                            :class:`~tumble.structural.kernels.StepKernel`), bound
                            into the one time loop
``amplification_matrix(Ω)`` ``G`` of one mode, ``zⁿ⁺¹ = G zⁿ``
``critical_omega()``        the largest stable ``Ω = ωΔt`` (0: never, ``inf``: always)
=========================== ============================================================

The last two have defaults here, derived from the others, so that what is analysed is what
runs: :meth:`Scheme.amplification_matrix` applies the scheme's own :meth:`~Scheme.step`
to each unit state of the oscillator ``ẍ + 2ξΩẋ + Ω²x = 0`` (``M = 1``, ``S = Ω²``,
``C = 2ξΩ``, ``Δt = 1``), and :meth:`Scheme.critical_omega` finds where the spectral radius
of that matrix first exceeds 1. A scheme with a closed form overrides them.

A new scheme family is one module: a frozen dataclass subclassing :class:`Scheme` (its
parameters checked in ``__post_init__``), its NumPy step, its compiled step (a
``@numba.njit(inline="always")`` function of :mod:`tumble.structural.kernels`' signature)
and its :class:`~tumble.structural.kernels.StepKernel`; and one line in
:data:`~tumble.structural.SCHEMES`.
"""

from __future__ import annotations

import functools
import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from tumble.structural.kernels import StepKernel
from tumble.structural.stepping import BeamState, Solve
from tumble.structural.system import LinearSystem

GROWTH_TOLERANCE = 1e-12
"""A spectral radius above ``1 + GROWTH_TOLERANCE`` is growth (the radius of a rotation
computed in double precision is 1 to about 1e-16)."""

OMEGA_RANGE = (1e-4, 1e16)
"""The ``Ω = ωΔt`` scanned by :meth:`Scheme.critical_omega`, 10 points a decade, before it
bisects between the last stable and the first unstable point."""


class Scheme(ABC):
    """A fixed-step scheme for ``M ẍ + C ẋ + S x = f`` (module docstring: the contract).

    Attributes
    ----------
    name : str
        Its key in :data:`~tumble.structural.SCHEMES`.
    order : int
        Its declared order of accuracy.
    carries_acceleration : bool
        Whether it starts from ``a₀ = M⁻¹ r₀``
        (:func:`~tumble.structural.stepping.initial_state`): its first steps move ``x`` by
        ``Δt² a₀`` terms, and the energy watch counts ``½ Δt² a₀ᵀM a₀`` in ``V₀``.
    kernel : StepKernel
        Its compiled step, bound into the one time loop.
    """

    name: str
    kernel: ClassVar[StepKernel]

    @property
    @abstractmethod
    def order(self) -> int:
        """The declared order of accuracy."""

    @property
    def carries_acceleration(self) -> bool:
        """Whether the scheme starts from ``a₀ = M⁻¹ r₀`` (by default not)."""
        return False

    @property
    def label(self) -> str:
        """How messages name the scheme: ``the implicit scheme``, or with its parameters."""
        return f"the {self.name} scheme"

    @abstractmethod
    def matrices(
        self, system: LinearSystem, C: sp.spmatrix | None, dt: float
    ) -> list[sp.spmatrix]:
        """The constant matrices the step solves with, each factorised once; the first is
        the step matrix ``A ≥ M`` (the energy watch's first bound solves with it)."""

    @abstractmethod
    def coefficients(self, dt: float) -> tuple[float, ...]:
        """The constants of one step of ``dt`` [s], ``dt`` first: what :meth:`step` and the
        compiled step read."""

    def start(
        self, system: LinearSystem, state: BeamState, C: sp.spmatrix | None, dt: float,
        acceleration: tuple[NDArray, NDArray] | None,
    ) -> BeamState:  # fmt: skip
        """The stepped state from ``state`` (``x₀, y₀, q₀ = f − S x₀, S y₀``).

        ``acceleration`` is ``(a₀, M a₀)`` for a scheme that carries it (``a₀ = M⁻¹ r₀``
        in a run; any ``a`` for the amplification matrix), else None. By default the state
        itself.
        """
        return state

    @abstractmethod
    def step(
        self, state: BeamState, system: LinearSystem, solves: list[Solve],
        C: sp.spmatrix | None, coefficients: tuple[float, ...],
    ) -> None:  # fmt: skip
        """One step in NumPy, updating ``state`` in place: the reference the compiled step
        must match to round-off. ``solves`` apply the inverses of :meth:`matrices`."""

    def amplification_matrix(self, omega: float, xi: float = 0.0) -> NDArray[np.float64]:
        """``G(Ω, ξ)``: one step on the oscillator ``ẍ + 2ξΩẋ + Ω²x = 0`` (``Δt = 1``), as a
        matrix on the :attr:`~tumble.structural.stepping.BeamState.MODAL` fields of the
        scheme's state (``(x, Δt y)``, or ``(x, Δt y, Δt² a)`` when it carries ``a``).

        Built column by column by the scheme's own :meth:`start` and :meth:`step` on each
        unit state: what is analysed is what runs.
        """
        system: Any = _Oscillator(omega, xi)
        C = system.C
        solves = [_divide_by(float(A[0, 0])) for A in self.matrices(system, C, 1.0)]
        coefficients = self.coefficients(1.0)
        columns = []
        for column, (x, y, a) in enumerate(np.eye(3)):
            acceleration = (np.array([a]), np.array([a])) if self.carries_acceleration else None
            start = BeamState.start(system, np.array([x]), np.array([y]))
            state = self.start(system, start, C, 1.0, acceleration)  # M = 1: M a = a
            if column == len(state.MODAL):  # a state without a: two columns
                break
            self.step(state, system, solves, C, coefficients)
            columns.append(state.modal())
        return np.array(columns).T

    def critical_omega(self) -> float:
        """The largest stable ``Ω = ωΔt``: where the spectral radius of
        :meth:`amplification_matrix` first exceeds ``1 +`` :data:`GROWTH_TOLERANCE`
        (0: unstable at every Ω; ``inf``: stable at every Ω of :data:`OMEGA_RANGE`).

        Scanned at 10 points a decade over :data:`OMEGA_RANGE`, then bisected (in
        ``log Ω``) to a relative 1e-15. A scheme with a closed form overrides it.
        """
        return _first_growth(self)


class _Oscillator:
    """The one-DOF system ``ẍ + 2ξΩ ẋ + Ω² x = 0`` (Δt = 1), duck-typed as a LinearSystem
    for the reference steps (they call ``internal_forces``, read ``f``, ``M``, ``S``)."""

    def __init__(self, omega: float, xi: float):
        self.stiffness = omega * omega
        self.M = sp.csr_matrix(np.ones((1, 1)))
        self.S = sp.csr_matrix(np.full((1, 1), self.stiffness))
        self.f = np.zeros(1)
        self.C = None if xi == 0 else sp.csr_matrix(np.full((1, 1), 2 * xi * omega))

    def internal_forces(self, x: NDArray, out: NDArray | None = None) -> NDArray:
        return self.stiffness * x


def _divide_by(pivot: float) -> Callable[[NDArray], NDArray]:
    """The solve with the 1 × 1 matrix ``[pivot]``."""
    return lambda b: b / pivot


def spectral_radius(scheme: Scheme, omega: float) -> float:
    """``max |λ|`` of the scheme's amplification matrix at ``Ω`` (undamped)."""
    return float(np.abs(np.linalg.eigvals(scheme.amplification_matrix(omega))).max())


@functools.lru_cache(maxsize=64)
def _first_growth(scheme: Scheme) -> float:
    """:meth:`Scheme.critical_omega`'s default, once per scheme (they are frozen)."""
    low, high = (math.log10(value) for value in OMEGA_RANGE)
    grid = np.logspace(low, high, round(10 * (high - low)) + 1)

    def grows(omega: float) -> bool:
        return spectral_radius(scheme, omega) > 1 + GROWTH_TOLERANCE

    unstable = [grows(float(omega)) for omega in grid]
    if not any(unstable):
        return math.inf
    first = unstable.index(True)
    if first == 0:
        return 0.0
    stable, growing = math.log(grid[first - 1]), math.log(grid[first])
    while growing - stable > 1e-15:
        middle = 0.5 * (stable + growing)
        if grows(math.exp(middle)):
            growing = middle
        else:
            stable = middle
    return math.exp(stable)
