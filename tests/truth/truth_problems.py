"""Hypothesis strategies of the truth suite: bodies, spins in every regime, loads.

A body is three principal moments ``(A, B, C)`` in any order of the body axes (so the middle
axis may be x, y or z), their ratio ``C/A`` from 1.001 to 100, the middle one anywhere
between, near-symmetric included (``B`` within 1e-3 of ``A`` or ``C``), and an overall scale
from 1e-4 kg m² (the T-handle) to 100.

A spin is drawn in one of three regimes:

- ``separatrix``: a signed distance ``d = (|L|² − 2E B)/|L|²`` from ±1e-1 down to ±1e-14,
  at any point of that orbit (from its closest approach to the middle axis to mid-flip);
- ``generic``: a momentum of any direction off the axes (each component at least 5 % of
  the largest);
- ``near-axis``: within 1e-8 … 1e-1 rad of the smallest or the largest axis.
"""

from __future__ import annotations

import math
import os

import numpy as np
from hypothesis import HealthCheck, Phase, settings
from hypothesis import strategies as st
from truth_reference import sorting_rotation

FINITE = {"allow_nan": False, "allow_infinity": False}


def _log_uniform(low: float, high: float) -> st.SearchStrategy:
    return st.floats(math.log10(low), math.log10(high), **FINITE).map(lambda e: 10.0**e)


@st.composite
def principal_moments(draw: st.DrawFn) -> tuple[float, float, float]:
    """Three distinct principal moments (kg m²), in a random order of the body axes."""
    scale = draw(_log_uniform(1e-4, 1e2))
    ratio = draw(_log_uniform(1.001, 100.0))
    split = draw(
        st.one_of(
            st.floats(1e-3, 1.0 - 1e-3, **FINITE),
            _log_uniform(1e-3, 1e-1),  # B near A
            _log_uniform(1e-3, 1e-1).map(lambda x: 1.0 - x),  # B near C
        )
    )
    A, C = scale, scale * ratio
    B = A + (C - A) * split
    order = draw(st.permutations([0, 1, 2]))
    return tuple(float(x) for x in np.array([A, B, C])[list(order)])


def _signs(draw: st.DrawFn) -> np.ndarray:
    return np.array(draw(st.tuples(*[st.sampled_from([-1.0, 1.0])] * 3)))


@st.composite
def separatrix_momentum(draw: st.DrawFn, moments: np.ndarray, size: float) -> np.ndarray:
    """A body momentum (sorted frame) of norm ``size`` at a drawn distance from the
    separatrix, at a drawn point of its orbit."""
    A, B, C = moments
    a, c = B / A - 1.0, 1.0 - B / C  # (M² − 2EB)/M² = c m₃² − a m₁² (unit m)
    side = draw(st.sampled_from([-1.0, 1.0]))
    reach = c if side > 0 else a  # the farthest an orbit on that side gets: a pure spin
    distance = side * min(draw(_log_uniform(1e-14, 1e-1)), 0.5 * reach)
    lowest = abs(distance) / reach * 1.01  # m₁ = 0 round C, m₃ = 0 round A: at most 0.505
    share = draw(st.floats(0.0, 1.0, **FINITE))
    # m₁² + m₃² = f |L|², from the orbit's closest approach to the middle axis (f = lowest)
    # to deep in the flip (f = 0.9: ω₂ at a third of its size, no flip at t = 0 to count)
    f = lowest * (0.9 / lowest) ** share
    m3 = max((distance + a * f) / (a + c), 0.0)
    m1 = max((c * f - distance) / (a + c), 0.0)
    m2 = max(1.0 - m1 - m3, 0.0)
    return size * np.sqrt([m1, m2, m3]) * _signs(draw)


@st.composite
def spins(draw: st.DrawFn, moments: tuple, regimes=("separatrix", "generic", "near-axis")):
    """A body angular velocity ω₀ (rad/s, body frame) for ``diag(moments)``, in one of
    ``regimes``: returns ``(regime, omega0)``."""
    regime = draw(st.sampled_from(regimes))
    Q = sorting_rotation(moments)
    sorted_moments = np.sort(moments)
    rate = draw(_log_uniform(0.1, 10.0))  # rad/s about the middle axis
    size = rate * sorted_moments[1]
    if regime == "separatrix":
        m = draw(separatrix_momentum(sorted_moments, size))
    elif regime == "generic":
        # every component at least 5 % of the largest: the near-axis and separatrix
        # regimes are the ones that go close to an axis
        direction = np.array(draw(st.tuples(*[st.floats(0.05, 1.0, **FINITE)] * 3)))
        m = size * direction / np.linalg.norm(direction) * _signs(draw)
    else:
        axis = draw(st.sampled_from([0, 2]))
        tilt = draw(_log_uniform(1e-8, 1e-1))
        off = np.array(draw(st.tuples(*[st.floats(0.1, 1.0, **FINITE)] * 3)))
        off[axis] = 0.0
        m = np.eye(3)[axis] + tilt * off / np.linalg.norm(off)
        m = size * m / np.linalg.norm(m) * _signs(draw)
    omega = Q.T @ (m / sorted_moments)
    return regime, tuple(float(w) for w in omega)


NIGHTLY = os.environ.get("HYPOTHESIS_PROFILE") == "thorough"
"""``HYPOTHESIS_PROFILE=thorough`` (the nightly run): random draws, many examples."""


def sample(default: int, nightly: int) -> settings:
    """Hypothesis settings: ``default`` examples drawn deterministically (the same ones on
    every run and machine: ``make test``) and reported as drawn, without shrinking (a
    failure's message names its problem; shrinking one costs minutes of mpmath), or
    ``nightly`` random ones, shrunk, under the thorough profile."""
    quiet = [HealthCheck.too_slow, HealthCheck.filter_too_much, HealthCheck.data_too_large]
    if NIGHTLY:
        return settings(max_examples=nightly, deadline=None, suppress_health_check=quiet)
    return settings(
        max_examples=default,
        derandomize=True,
        database=None,
        deadline=None,
        suppress_health_check=quiet,
        phases=(Phase.explicit, Phase.generate),
    )
