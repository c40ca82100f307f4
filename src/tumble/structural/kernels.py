"""Compiled kernel for the assembled internal-force vector ``S x``, element by element.

The algorithm is :func:`tumble.structural.elements.element_forces` (the readable NumPy
reference, which a test checks this against to round-off) fused with the scatter into the
free-DOF vector, so that one call does no allocation and no Python work per element.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray


@numba.njit(cache=True, nogil=True)
def assemble_internal_forces(
    x: NDArray[np.float64],
    dof_map: NDArray[np.int64],
    length: NDArray[np.float64],
    cos: NDArray[np.float64],
    sin: NDArray[np.float64],
    EA: NDArray[np.float64],
    EI: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None:
    """Write ``out = S x`` computed from each element's natural deformations.

    Parameters
    ----------
    x : ndarray, shape (n_dofs,)
        Free-DOF vector (displacements [m, rad], or velocities, or increments).
    dof_map : ndarray of int64, shape (n_elements, 6)
        Free-DOF index of each element DOF, ``-1`` where the DOF is fixed (value 0).
    length, cos, sin, EA, EI : ndarray, shape (n_elements,)
        Element geometry and stiffness, as in :mod:`tumble.structural.elements`.
    out : ndarray, shape (n_dofs,)
        Overwritten with the internal forces [N, N m].
    """
    out[:] = 0.0
    xe = np.empty(6)
    fe = np.empty(6)
    for e in range(dof_map.shape[0]):
        for k in range(6):
            index = dof_map[e, k]
            xe[k] = x[index] if index >= 0 else 0.0
        h, c, s = length[e], cos[e], sin[e]
        du = xe[3] - xe[0]
        dv = xe[4] - xe[1]
        psi = (c * dv - s * du) / h
        a = xe[2] - psi
        b = xe[5] - psi
        axial = EA[e] / h * (c * du + s * dv)
        moment_i = EI[e] / h * (4.0 * a + 2.0 * b)
        moment_j = EI[e] / h * (2.0 * a + 4.0 * b)
        shear = (moment_i + moment_j) / h
        fe[0] = -c * axial - s * shear
        fe[1] = -s * axial + c * shear
        fe[2] = moment_i
        fe[3] = -fe[0]
        fe[4] = -fe[1]
        fe[5] = moment_j
        for k in range(6):
            index = dof_map[e, k]
            if index >= 0:
                out[index] += fe[k]


@numba.njit(cache=True, nogil=True)
def all_finite(x: NDArray[np.float64], y: NDArray[np.float64]) -> bool:
    """True if every entry of ``x`` and ``y`` is finite (a loop: no BLAS threads, no copy)."""
    for i in range(x.size):
        if not (np.isfinite(x[i]) and np.isfinite(y[i])):
            return False
    return True
