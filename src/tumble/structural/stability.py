"""For which time steps each scheme is stable: the critical step and a dt sweep.

Each scheme knows the largest ``Ω = ωΔt`` at which one mode stays bounded
(:meth:`~tumble.structural.scheme.Scheme.critical_omega`: a closed form for the seed's
schemes and Newmark, :mod:`tumble.structural.increments`; ``inf`` for the damped families,
which refuse parameters that are not unconditionally stable; by default, where the
spectral radius of its amplification matrix first exceeds 1). :func:`critical_dt`
turns it into a time step with the system's highest mode, ``Δt_crit = Ω_crit/ω_max``, and
says whether that mode is axial or bending. These are the undamped limits; Rayleigh damping
only enlarges them here. :func:`stability_sweep` measures it: runs at a range of Δt and the
energy's growth in each.

References
----------
.. [1] T. J. R. Hughes, *The Finite Element Method*, Dover, 2000, §9.1.2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse.linalg as spla
from numpy.typing import ArrayLike, NDArray

from tumble import _checks
from tumble.structural.scheme import Scheme
from tumble.structural.schemes import MAX_STEPS, integrate, resolve_scheme
from tumble.structural.system import DENSE_EIGEN_LIMIT, LinearSystem, checked_system

STABLE_GROWTH = 1.0
"""A run counts as stable if its energy never rose above the start by this many scales."""

MAX_SWEEP_RECORDS = 2000
"""A sweep run records at most about this many states (energy is checked on those)."""


@dataclass(frozen=True)
class CriticalStep:
    """The largest stable time step of a scheme on a system.

    Attributes
    ----------
    scheme : str
        The scheme's name.
    dt : float
        Stable for ``Δt < dt`` [s]; ``0.0`` means unstable for every Δt, ``inf`` means
        unconditionally stable.
    omega : float or None
        The angular frequency that sets the limit, ``ω_max`` [rad/s]; None if no mode does.
    mode : str or None
        Whether that mode is mostly ``"axial"`` or ``"bending"`` (by its strain energy).
    """

    scheme: str
    dt: float
    omega: float | None = None
    mode: str | None = None

    def __float__(self) -> float:
        return self.dt


def critical_dt(system: LinearSystem, scheme: str | Scheme) -> CriticalStep:
    """The critical time step ``Ω_crit/ω_max``: ``2/ω_max`` for ``semi-implicit``, 0 for
    ``explicit``.

    ``Ω_crit`` is the scheme's :meth:`~tumble.structural.scheme.Scheme.critical_omega`.
    ``explicit`` is unstable for every ``dt > 0`` (each mode is amplified by
    ``sqrt(1 + ω²Δt²)`` per step), so its critical step is 0. ``implicit``, ``midpoint``,
    ``newmark`` with ``2β ≥ γ ≥ ½`` and the damped families are unconditionally stable:
    ``inf``. Where a limit exists it is set
    by the highest mode ``ω_max`` of ``S φ = ω² M φ``, reported with whether that mode is
    axial or bending: on a coarse frame with axial DOFs it is often axial, and a transverse
    load never excites it, so a run can survive above the limit.

    Parameters
    ----------
    system : LinearSystem
    scheme : str or Scheme
        A name from :data:`~tumble.structural.SCHEMES` or a scheme with its parameters.

    Returns
    -------
    CriticalStep
        ``float(result)`` is the step [s].

    Examples
    --------
    >>> from tumble.structural import cantilever
    >>> beam = cantilever(1.0, 20, E=210e9, rho=7850, width=0.01, height=0.01)
    >>> step = critical_dt(beam, "semi-implicit")
    >>> f"{step.dt:.3e} s", step.mode, critical_dt(beam, "midpoint").dt
    ('5.593e-06 s', 'bending', inf)
    """
    system = checked_system(system)
    scheme = resolve_scheme(scheme)
    z_max = scheme.critical_omega()
    if z_max == 0.0 or math.isinf(z_max):
        return CriticalStep(scheme.name, z_max)
    omega, shape = highest_mode(system)
    return CriticalStep(scheme.name, z_max / omega, omega, mode_kind(system, shape))


def highest_mode(system: LinearSystem) -> tuple[float, NDArray]:
    """``ω_max`` [rad/s] and its mode shape (n_dofs,): dense, or ARPACK for large systems."""
    n = system.n_dofs
    if n <= DENSE_EIGEN_LIMIT:
        lam, shape = scipy.linalg.eigh(
            system.S.toarray(), system.M.toarray(), subset_by_index=(n - 1, n - 1)
        )
    else:
        lam, shape = spla.eigsh(system.S, k=1, M=system.M, which="LA")
    return math.sqrt(lam[0]), shape[:, 0]


def mode_kind(system: LinearSystem, shape: ArrayLike) -> str:
    """``"axial"`` or ``"bending"``: which part of the mode's strain energy is larger."""
    axial, bending = system.elements.strain_energy(shape).sum(axis=0)
    return "axial" if axial > bending else "bending"


def energy_scale(
    system: LinearSystem, x0: ArrayLike | None = None, y0: ArrayLike | None = None
) -> float:
    """The energy a run exchanges: ``½ fᵀ S⁻¹ f + ½ y0ᵀ M y0 + ½ x0ᵀ S x0`` [J].

    For a step load from rest, ``½ fᵀ x_static`` is the strain energy at the static
    deflection, and ``E(t)`` of the exact motion stays 0 while kinetic and strain energy
    trade up to that much.

    Examples
    --------
    >>> from tumble.structural import cantilever
    >>> beam = cantilever(1.0, 4, E=210e9, rho=7850, width=0.01, height=0.01, tip_load=1.0)
    >>> round(energy_scale(beam) / (0.5 * 1.0 / (3 * 175.0)), 9)   # ½ F · F L³/(3EI)
    1.0
    """
    system = checked_system(system)
    scale = 0.5 * float(system.f @ system.static_displacement())
    shape = (system.n_dofs,)
    x0 = None if x0 is None else _checks.array("x0", x0, shape=shape, unit="m, rad")
    y0 = None if y0 is None else _checks.array("y0", y0, shape=shape, unit="m/s, rad/s")
    with np.errstate(over="ignore", invalid="ignore"):  # refused below, by name
        if x0 is not None:
            scale += float(system.strain_energy(x0))
        if y0 is not None:
            scale += float(system.kinetic_energy(y0))
    if not np.isfinite(scale):
        raise _checks.fail("x0" if x0 is not None else "system", "<the initial state>",
                           "a state whose energy is finite", "J",
                           remedy="½ xᵀ S x + ½ yᵀ M y overflows past 1.8e308")  # fmt: skip
    if not scale > 0:
        raise _checks.fail(
            "x0",
            x0,
            "non-zero (or y0 non-zero) when the system has no load",
            "m, rad",
            "with no load and no initial state there is nothing to measure",
        )
    return scale


@dataclass(frozen=True, eq=False)
class StabilitySweep:
    """Energy growth of one scheme over a range of time steps.

    Attributes
    ----------
    scheme : str
    dt : ndarray, shape (n,)
        The time steps [s].
    energy_growth : ndarray, shape (n,)
        ``max_t (E(t) − E(0)) / energy_scale`` per dt; ``inf`` if the run diverged.
    stable : ndarray of bool, shape (n,)
        ``energy_growth < STABLE_GROWTH``.
    critical : CriticalStep
    energy_scale : float
        [J], from :func:`energy_scale`.
    n_steps : int
    """

    scheme: str
    dt: NDArray[np.float64]
    energy_growth: NDArray[np.float64]
    stable: NDArray[np.bool_]
    critical: CriticalStep
    energy_scale: float
    n_steps: int


def stability_sweep(
    system: LinearSystem,
    scheme: str | Scheme,
    dts: ArrayLike,
    n_steps: int,
    *,
    x0: ArrayLike | None = None,
    y0: ArrayLike | None = None,
) -> StabilitySweep:
    """Run ``n_steps`` at each time step in ``dts`` and measure how much energy grows.

    From ``(x0, y0)`` (rest by default) under the system's loads, the growth is the
    largest rise of ``E = ½yᵀMy + ½xᵀSx − fᵀx`` above its start, in units of
    :func:`energy_scale`: near 0 for a stable energy-keeping run, at most 0 for a
    dissipating one, ``inf`` for one that diverged.

    Examples
    --------
    >>> from tumble.structural import cantilever
    >>> beam = cantilever(1.0, 8, E=210e9, rho=7850, width=0.01, height=0.01, tip_load=1.0)
    >>> limit = critical_dt(beam, "semi-implicit").dt
    >>> sweep = stability_sweep(beam, "semi-implicit", [0.9 * limit, 1.1 * limit], 2000)
    >>> sweep.stable.tolist()
    [True, False]
    """
    system = checked_system(system)
    scheme = resolve_scheme(scheme)
    given, dts = dts, np.atleast_1d(_checks.array("dts", dts, unit="s", positive=True))
    if dts.ndim != 1 or dts.size == 0:
        raise _checks.fail("dts", given, "a step or a 1-D array of them (at least one), each "
                           "finite and > 0", "s")  # fmt: skip
    n_steps = _checks.count("n_steps", n_steps, 1, MAX_STEPS, remedy="a run this long never ends")
    scale = energy_scale(system, x0, y0)
    record_every = max(1, n_steps // MAX_SWEEP_RECORDS)
    growth = np.empty(dts.size)
    for i, dt in enumerate(dts):
        run = integrate(
            system, scheme, float(dt), n_steps=n_steps, x0=x0, y0=y0, record_every=record_every
        )
        with np.errstate(over="ignore"):  # a diverging run's energy can reach 1e300
            rise = np.max(run.energy - run.energy[0]) / scale
        growth[i] = rise if run.success and np.isfinite(rise) else np.inf
    critical = critical_dt(system, scheme)
    return StabilitySweep(
        scheme.name, dts, growth, growth < STABLE_GROWTH, critical, scale, n_steps
    )
