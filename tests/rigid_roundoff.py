"""How deep a rigid-body step's round-off goes: the bounds of the kernel-against-reference
tests and of the invariants a run keeps to round-off (tests/roundoff.py has the model).

The NumPy reference multiplies 3 × 3 matrices in the CPU's BLAS kernel and takes sin, cos and
norms from numpy's SIMD loops; the numba kernel writes the same formulas out in its own order.
Each is a chain of roundings from the exact step, and they drift apart as a random walk.
"""

import numpy as np
from roundoff import walk_bound

from tumble.rigid import METHODS

STAGE_CHAIN = 40
"""Roundings along the longest chain of one stage or one sub-flow: the map onto SO(3) (a
norm, sin and cos, 3-term products), dexp⁻¹ (two cross products and a coefficient), the
field (the inertia, cross products, the loads), the stage's sum; an implicit flow's Newton
stops within 4 eps of its root, as four more."""


def step_chain(method: str) -> int:
    """Roundings along the longest chain of one step of ``method``: its stages (a tableau's),
    or its sub-flows (five axis rotations for ``axes``, one flow otherwise, and the two
    kicks) times the terms of its composition."""
    declared = METHODS[method]
    if declared.tableau is not None:
        return STAGE_CHAIN * declared.tableau.stages
    flows = 5 if declared.flow == "axes" else 1
    return STAGE_CHAIN * (flows + 2) * len(declared.weights or (1.0,))


def kernel_bound(method: str, steps: int, magnitude: float, condition: float) -> float:
    """How far the kernel's and the reference's runs of ``steps`` steps may end apart, for
    state components of ``magnitude`` and a flow that grows a perturbation ``condition``-fold
    at most."""
    return float(walk_bound(steps, step_chain(method), magnitude, condition))


def invariant_bound(method: str, steps: int) -> float:
    """How far one run's round-off may carry a relative invariant (‖RᵀR − I‖, |L|, E/E₀):
    the random walk of its steps' chains of roundings, half of walk_bound's two runs."""
    return float(walk_bound(steps, step_chain(method), 1.0)) / 2


def assert_kernel_matches(kernel, reference, method: str, fields, condition: float) -> None:
    """Each of ``fields`` of the two runs within :func:`kernel_bound`, on terms of 3 × the
    field's largest entry (3-term products and sums of entries that size)."""
    steps = int(round((reference.t[-1] - reference.t[0]) / reference.settings["h"]))
    for name in fields:
        magnitude = 3 * np.abs(getattr(reference, name)).max()
        bound = kernel_bound(method, steps, magnitude, condition)
        np.testing.assert_allclose(getattr(kernel, name), getattr(reference, name), rtol=0,
                                   atol=bound, err_msg=name)  # fmt: skip
