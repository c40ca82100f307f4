"""Round-off bounds for the tests: derived from the computation, never from one CPU.

Which results may differ between machines:

- numpy's ``@``, ``dot`` and ``linalg`` call BLAS and LAPACK, whose kernels (their order of
  summation, their use of FMA) are chosen for the CPU at run time;
- numpy's ``sin``, ``cos``, ``exp``, ``arctan2``… dispatch to SIMD loops (AVX2, AVX-512) that
  differ from libm, and from each other, by a few ulps (at most 4);
- numba compiles without fastmath: no FMA contraction and no reassociation, so its scalar code
  performs the same IEEE operations on every x86-64 (``NUMBA_CPU_NAME=generic`` gives the same
  bits), except in a kernel that asks for ``fastmath={"contract"}``; the same compiled function
  called twice on the same inputs gives the same bits everywhere.

A sum of n terms ``x_i``, in any order, with or without FMA, lies within ``γ_n Σ|x_i|`` of the
exact sum, ``γ_n = n u / (1 − n u)`` with ``u = eps / 2`` (Higham, *Accuracy and Stability of
Numerical Algorithms*, 2nd ed., 2002, §3.1); more generally, a result computed in a chain of
at most n roundings lies within about ``n u Σ|terms|`` of its exact value: :func:`error_bound`.
Two evaluations therefore differ by at most ``n eps Σ|x_i|``: :func:`sum_bound`. A run of N
steps, each rounding terms of magnitude S in at most n operations, whose flow amplifies a
perturbation by at most κ, ends within ``κ N n eps S`` of the same run rounded otherwise:
:func:`run_bound`.

Over long runs that worst case, every rounding the largest possible and all of one sign, is
far from what happens and too loose to test anything. Roundings behave as independent
random errors of mean zero and at most ``u |x|`` each; then a chain of n of them stays within
``λ √n u Σ|x|`` with probability at least ``1 − 2n exp(−λ²(1 − u)²/2)`` (Higham and Mary,
"A new approach to probabilistic rounding error analysis", SIAM J. Sci. Comput. 41(5),
A2815–A2835, 2019, Theorem 2.4): :func:`walk_bound`, with λ chosen for a failure probability
of 1e-6.
"""

import numpy as np

EPS = float(np.finfo(float).eps)
"""The spacing of doubles at 1, 2⁻⁵² (twice the unit round-off u)."""


def error_bound(magnitude, operations: float):
    """How far one evaluation may lie from the exact value, on any IEEE-754 machine:
    ``operations · u · magnitude`` (``u = eps / 2``), for ``operations`` roundings along the
    longest chain of the evaluation (inputs rounded to doubles count one each) on terms whose
    magnitudes add to ``magnitude``."""
    return operations * (EPS / 2) * np.asarray(magnitude, dtype=float)


def sum_bound(magnitude, operations: int):
    """How far two evaluations of one sum may differ, on any IEEE-754 machine.

    Parameters
    ----------
    magnitude : float or ndarray
        ``Σ|x_i|``, the sum of the magnitudes of the terms (elementwise for an array).
    operations : int
        The roundings along the longest chain of the evaluation (``n`` terms: ``n``).

    Returns
    -------
    float or ndarray
        ``operations · eps · magnitude`` (each evaluation lies within half of it of the exact
        sum).
    """
    return 2 * error_bound(magnitude, operations)


def run_bound(steps: int, operations: int, magnitude, condition: float = 1.0):
    """How far two runs of ``steps`` steps that round differently may end apart.

    Each step is a :func:`sum_bound` of ``operations`` roundings on terms of ``magnitude``, and
    the flow amplifies each step's difference by at most ``condition`` (κ) by the run's end.
    """
    return condition * steps * sum_bound(magnitude, operations)


def walk_bound(steps: int, operations: int, magnitude, condition: float = 1.0):
    """How far two runs that round differently may drift apart, with probability 1 − 1e-6.

    Each run's ``steps × operations`` roundings on terms of ``magnitude`` random-walk
    (module docstring): ``λ √(N n) u S`` with ``2 N n exp(−λ²/2) = 1e-6``; twice that for
    the two runs, grown at most ``condition`` (κ) by the end.
    """
    n = steps * operations
    sigmas = np.sqrt(2 * np.log(2 * n / 1e-6))
    return condition * 2 * error_bound(magnitude, sigmas * np.sqrt(n))
