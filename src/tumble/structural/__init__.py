"""Linear structural dynamics: 2D Euler–Bernoulli frames, ``M ẍ = f − S x`` (seed 003).

Model
    :func:`cantilever` — the seed's beam, clamped at x = 0 with a tip load;
    :func:`build_frame` — any 2D frame from nodes, elements, supports and nodal loads;
    both return a :class:`LinearSystem` (sparse ``M``, ``S`` on the free DOFs, ``f``,
    ``natural_frequencies``, ``expand``); :class:`RayleighDamping` gives ``C = αM + βS``;
    :class:`IllConditionedWarning` when the mesh is too fine for double precision.
Time stepping
    :func:`integrate` with a scheme from :data:`SCHEMES` — ``explicit``,
    ``semi-implicit``, ``implicit``, ``midpoint`` (the seed's four) and ``newmark``
    (:class:`Newmark`, average acceleration by default) — returns a :class:`Response`
    (``t``, ``x``, ``y``, ``energy``, ``tip_displacement``). The step matrix is factorised
    once, banded Cholesky or sparse LU by its band (:mod:`tumble.structural.factorization`),
    and the loop runs compiled (:mod:`tumble.structural.stepping`).
Exact reference
    :func:`exact_response` — the motion of a linear system by modal superposition
    (:class:`ModalSolution`), at any time, with Rayleigh damping: the yardstick of every
    scheme's error.
Stability
    :func:`critical_dt` (a :class:`CriticalStep`: the step, ``ω_max`` and whether that mode
    is axial or bending), :func:`stability_sweep` (energy growth per dt),
    :func:`energy_scale`.
Time-step analysis
    :func:`amplification` — each scheme's amplification matrix on the oscillator against
    ``Ω = ωΔt``: spectral radius, algorithmic damping, period elongation, critical Ω
    (:class:`Amplification`); :func:`mode_table` — every mode of a system at one Δt
    (:class:`ModeTable`).
Elements
    :mod:`tumble.structural.elements` — element stiffness, consistent mass and internal
    forces as pure functions.

Units are SI: m, kg, s, N, Pa, rad. Each node carries ``(u, v, θ)``; supported DOFs are
removed from the system and restored as zeros by :meth:`LinearSystem.expand`.

Examples
--------
>>> from tumble import structural
>>> beam = structural.cantilever(1.0, 20, E=210e9, rho=7850, width=0.01, height=0.01,
...                              tip_load=1.0)
>>> beam.natural_frequencies(1).round(4)
array([52.4971])
>>> run = structural.integrate(beam, "midpoint", dt=6e-4, n_steps=2000)
>>> round(float(run.tip_displacement.max() / (1.0 / (3 * 175.0))), 2)   # / (F L³/(3EI))
1.99
"""

from tumble.structural import elements
from tumble.structural.alpha import HHT, Bathe, GeneralizedAlpha
from tumble.structural.amplification import Amplification, ModeTable, amplification, mode_table
from tumble.structural.assembly import (
    SUPPORT_KINDS,
    IllConditionedWarning,
    build_frame,
    cantilever,
    condition_estimate,
)
from tumble.structural.modal import ModalSolution, exact_response, modal_energies
from tumble.structural.schemes import (
    EXPLICIT,
    IMPLICIT,
    MIDPOINT,
    NEWMARK,
    SCHEMES,
    SEED_SCHEMES,
    SEMI_IMPLICIT,
    Newmark,
    Response,
    ThetaScheme,
    integrate,
)
from tumble.structural.stability import (
    CriticalStep,
    StabilitySweep,
    critical_dt,
    energy_scale,
    stability_sweep,
)
from tumble.structural.system import FrameElements, LinearSystem, RayleighDamping

__all__ = [
    "Amplification",
    "ModeTable",
    "amplification",
    "mode_table",
    "EXPLICIT",
    "IMPLICIT",
    "MIDPOINT",
    "NEWMARK",
    "SCHEMES",
    "SEED_SCHEMES",
    "SEMI_IMPLICIT",
    "SUPPORT_KINDS",
    "Bathe",
    "CriticalStep",
    "FrameElements",
    "GeneralizedAlpha",
    "HHT",
    "IllConditionedWarning",
    "LinearSystem",
    "ModalSolution",
    "Newmark",
    "RayleighDamping",
    "Response",
    "StabilitySweep",
    "ThetaScheme",
    "build_frame",
    "cantilever",
    "condition_estimate",
    "critical_dt",
    "elements",
    "energy_scale",
    "exact_response",
    "integrate",
    "modal_energies",
    "stability_sweep",
]
