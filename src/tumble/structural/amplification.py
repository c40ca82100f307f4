"""What a time step does to one mode: the amplification matrix and what it tells.

Applied to the single-DOF oscillator ``ẍ + 2ξω ẋ + ω² x = 0`` with ``Ω = ωΔt``, every
scheme of :data:`~tumble.structural.SCHEMES` is a linear map of its state,
``zⁿ⁺¹ = G(Ω, ξ) zⁿ`` (``z = (x, Δt y)``, plus ``Δt² a`` for a scheme whose state carries
the acceleration, e.g. the generalized-α family). :func:`amplification` asks the scheme for
``G`` (:meth:`~tumble.structural.scheme.Scheme.amplification_matrix`), which builds it
column by column by running the scheme's *own* NumPy reference step on a one-DOF system
with ``M = 1``, ``S = Ω²``, ``C = 2ξΩ``, ``Δt = 1``; so what is analysed is what runs.
From its eigenvalues (Hughes 2000, §9.2; Chung & Hulbert 1993):

- the spectral radius ``ρ = max |λ|``: stable where ``ρ ≤ 1``;
- the principal pair ``λ = A ± iB = exp(Ω̄(−ξ̄ ± i))``: the algorithmic damping ratio
  ``ξ̄ = −ln(A² + B²)/(2Ω̄)`` and the relative period elongation ``(T̄ − T)/T = Ω/Ω̄ − 1``
  with ``Ω̄ = atan2(B, A)``. Where the principal roots are real (a scheme that kills the
  mode within a step, e.g. Bathe or generalized-α with ρ∞ = 0 at large Ω) there is no
  period, and both are NaN;
- the critical ``Ω`` above which ``ρ > 1``, the scheme's
  :meth:`~tumble.structural.scheme.Scheme.critical_omega` (``2`` for ``semi-implicit``,
  ``0`` for ``explicit``, ``1/√(γ/2 − β)`` for Newmark with ``2β < γ``, ``inf`` for the
  unconditionally stable).

:func:`mode_table` applies it to every mode of a beam at a chosen ``Δt``: which modes
the step resolves and which it damps away.

References
----------
.. [1] T. J. R. Hughes, *The Finite Element Method*, Dover, 2000, §9.2–9.3.
.. [2] J. Chung, G. M. Hulbert, *J. Appl. Mech.* 60, 371–375, 1993, §3 and Figs. 1–3.
.. [3] G. Noh, K. J. Bathe, *Comput. Struct.* 212, 299–310, 2019, §3.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tumble import _checks
from tumble.structural.scheme import Scheme
from tumble.structural.schemes import resolve_scheme
from tumble.structural.system import LinearSystem, checked_system


@dataclass(frozen=True, eq=False)
class Amplification:
    """A scheme's amplification on the oscillator, against ``Ω = ωΔt`` (module docstring).

    Attributes
    ----------
    scheme : str
    omega : ndarray, shape (n,)
        ``Ω = ωΔt`` [rad].
    xi : float
        The oscillator's physical damping ratio ξ.
    matrix : ndarray, shape (n, k, k)
        ``G(Ω)`` acting on ``(x, Δt y)`` (k = 2) or ``(x, Δt y, Δt² a)`` (k = 3).
    spectral_radius : ndarray, shape (n,)
    damping_ratio : ndarray, shape (n,)
        Algorithmic damping ratio ξ̄ (NaN where the principal roots are real).
    period_elongation : ndarray, shape (n,)
        ``(T̄ − T)/T`` (NaN where the principal roots are real).
    critical_omega : float
        ``Ω`` above which ``ρ > 1``: 0 never stable, ``inf`` always.
    """

    scheme: str
    omega: NDArray[np.float64]
    xi: float
    matrix: NDArray[np.float64]
    spectral_radius: NDArray[np.float64]
    damping_ratio: NDArray[np.float64]
    period_elongation: NDArray[np.float64]
    critical_omega: float


def amplification(scheme: str | Scheme, omega: ArrayLike, xi: float = 0.0) -> Amplification:
    """The amplification matrix of ``scheme`` at each ``Ω = ωΔt``, and what follows from it.

    Parameters
    ----------
    scheme : str or scheme object
        A name from :data:`~tumble.structural.SCHEMES` or a scheme with its parameters.
    omega : array_like, shape (n,)
        ``Ω = ωΔt`` [rad], > 0.
    xi : float, optional
        Physical damping ratio ξ ∈ [0, 1) of the oscillator (Rayleigh damping of one mode).

    Returns
    -------
    Amplification

    Examples
    --------
    >>> out = amplification("newmark", [0.1, 1.0, 1e6])
    >>> out.spectral_radius.round(12), bool(np.all(np.abs(out.damping_ratio) < 1e-12))
    (array([1., 1., 1.]), True)
    >>> float(out.period_elongation[1].round(6))   # Ω/(2 atan(Ω/2)) − 1
    0.078405
    >>> amplification("semi-implicit", [1.0]).critical_omega
    2.0
    """
    scheme = resolve_scheme(scheme)
    given, omega = omega, np.atleast_1d(_checks.array("omega", omega, unit="rad", positive=True))
    if omega.ndim != 1 or omega.size == 0:
        raise _checks.fail("omega", given, "a number or a 1-D array of them (at least one), "
                           "each finite and > 0", "rad")  # fmt: skip
    xi = _checks.non_negative("xi", xi)
    if not xi < 1:
        raise _checks.fail("xi", xi, "in [0, 1): an underdamped oscillator")
    with np.errstate(over="ignore", invalid="ignore"):
        G = np.array([scheme.amplification_matrix(float(w), xi) for w in omega])
    finite = np.isfinite(G).reshape(len(G), -1).all(axis=1)
    if not finite.all():  # Ω² past 1.8e308 (Ω ~ 1e154): LAPACK refuses the inf
        index = int(np.argmin(finite))
        raise _checks.fail(
            f"omega[{index}]", float(omega[index]), "a value whose amplification matrix is "
            "finite", "rad", remedy="Ω² overflows; as Ω → ∞ the spectral radius tends to the "
            "scheme's ρ∞ (e.g. 1e6 shows it)",
        )  # fmt: skip
    eigenvalues = np.linalg.eigvals(G)
    radius = np.abs(eigenvalues).max(axis=1)
    principal = np.take_along_axis(eigenvalues, np.argmax(eigenvalues.imag, axis=1)[:, None], 1)
    principal = principal[:, 0]
    oscillating = principal.imag > 0
    omega_bar = np.where(oscillating, np.angle(principal), np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        damping = -np.log(np.abs(principal) ** 2) / (2 * omega_bar)
        elongation = omega / omega_bar - 1
    return Amplification(scheme.name, omega, xi, G, radius, damping, elongation,
                         float(scheme.critical_omega()))  # fmt: skip


@dataclass(frozen=True, eq=False)
class ModeTable:
    """Each mode of a system under each scheme at one ``Δt`` (:func:`mode_table`).

    Attributes
    ----------
    dt : float
        Time step [s].
    omega : ndarray, shape (n_modes,)
        Natural frequencies ω [rad/s]; ``Ω = omega · dt``.
    schemes : tuple of str
    spectral_radius, damping_ratio, period_elongation : ndarray, shape (n_schemes, n_modes)
        As :class:`Amplification`, per scheme and mode.
    """

    dt: float
    omega: NDArray[np.float64]
    schemes: tuple[str, ...]
    spectral_radius: NDArray[np.float64]
    damping_ratio: NDArray[np.float64]
    period_elongation: NDArray[np.float64]


def mode_table(
    system: LinearSystem,
    dt: float,
    schemes: tuple[str | Scheme, ...] | None = None,
    n_modes: int | None = None,
) -> ModeTable:
    """For a time step ``dt``: each mode's ``Ω = ωΔt`` and its fate under each scheme.

    Parameters
    ----------
    system : LinearSystem
    dt : float
        Time step [s], > 0.
    schemes : tuple, optional
        Names or scheme objects; every scheme of :data:`~tumble.structural.SCHEMES` by
        default.
    n_modes : int, optional
        The lowest this many modes (all by default).

    Examples
    --------
    >>> from tumble.structural import cantilever
    >>> beam = cantilever(1.0, 4, E=210e9, rho=7850, width=0.01, height=0.01)
    >>> table = mode_table(beam, 1e-3, ("newmark", "bathe"), n_modes=2)
    >>> (table.omega * table.dt).round(3)
    array([0.052, 0.329])
    >>> bool(abs(table.damping_ratio[0, 1]) < 1e-12), bool(table.damping_ratio[1, 1] > 0)
    (True, True)
    """
    from tumble.structural.schemes import SCHEMES

    system = checked_system(system)
    dt = _checks.positive("dt", dt, "s")
    n = system.n_dofs if n_modes is None else _checks.count("n_modes", n_modes, 1, system.n_dofs)
    if schemes is None:
        chosen = tuple(SCHEMES.values())
    else:
        listed = _checks.items("schemes", schemes, "a sequence of scheme names or objects")
        if not listed:
            raise _checks.fail("schemes", schemes, "at least one scheme, or None for all")
        chosen = tuple(resolve_scheme(s, f"schemes[{i}]") for i, s in enumerate(listed))
    omega = system.natural_frequencies(n)
    with np.errstate(over="ignore"):
        phase = omega[-1] * dt
    if not np.isfinite(phase):
        raise _checks.fail("dt", dt, f"a step with ω_max dt finite (ω_max = {omega[-1]:.3g} "
                           "rad/s)", "s")  # fmt: skip
    analyses = [amplification(s, omega * dt) for s in chosen]
    return ModeTable(
        dt,
        omega,
        tuple(s.name for s in chosen),
        np.array([a.spectral_radius for a in analyses]),
        np.array([a.damping_ratio for a in analyses]),
        np.array([a.period_elongation for a in analyses]),
    )
