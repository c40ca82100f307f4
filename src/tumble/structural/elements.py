"""The 2D Euler–Bernoulli frame element: stiffness, consistent mass, internal forces.

Pure functions on arrays of elements (shape ``(n_elements, ...)``), no assembly.

An element joins node *i* to node *j*; each node carries three degrees of freedom in
global axes, ``(u, v, θ)``: displacement along x and y [m] and rotation about z [rad],
counter-clockwise positive. The element's six DOFs are ordered ``(u_i, v_i, θ_i, u_j, v_j,
θ_j)``. With ``c = cos α``, ``s = sin α`` the direction of the element axis and ``h`` its
length, the element strains are described by three *natural deformations*

.. math::

    e = c\\,Δu + s\\,Δv, \\qquad
    ψ = (-s\\,Δu + c\\,Δv)/h, \\qquad
    a = θ_i - ψ, \\quad b = θ_j - ψ,

(``Δu = u_j − u_i``, ``Δv = v_j − v_i``): the elongation ``e`` [m] and the end rotations
``a``, ``b`` [rad] measured from the chord. They vanish exactly for the three rigid-body
motions. The element's axial force, end moments and shear are

.. math::

    N = \\frac{EA}{h} e, \\quad
    M_i = \\frac{EI}{h}(4a + 2b), \\quad
    M_j = \\frac{EI}{h}(2a + 4b), \\quad
    V = \\frac{M_i + M_j}{h},

and the stiffness matrix is ``K = Bᵀ D B`` with ``d = (e, a, b) = B x`` and
``D = diag(EA/h, EI/h [[4, 2], [2, 4]])`` — the classical Hermite-cubic beam plus a linear
bar (Przemieniecki 1968). Computing the forces from the differences first, element by
element, is what keeps them accurate on fine meshes where ``K x`` summed globally is swamped
by round-off (``κ(S) ∝ N⁴``).

References
----------
.. [1] J. S. Przemieniecki, *Theory of Matrix Structural Analysis*, McGraw-Hill, 1968,
   ch. 5 (stiffness) and ch. 11 (consistent mass).
.. [2] R. D. Cook, D. S. Malkus, M. E. Plesha, R. J. Witt, *Concepts and Applications of
   Finite Element Analysis*, 4th ed., Wiley, 2002, §2.3 and §11.3.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

DOFS_PER_NODE = 3
"""Degrees of freedom per node: u [m], v [m], θ [rad]."""

_BAR_MASS = np.array([[2.0, 1.0], [1.0, 2.0]])
_BEAM_MASS = np.array(
    [[156, 22, 54, -13], [22, 4, 13, -3], [54, 13, 156, -22], [-13, -3, -22, 4]], dtype=float
)
_BEAM_MASS_POWERS = np.array([[0, 1, 0, 1], [1, 2, 1, 2], [0, 1, 0, 1], [1, 2, 1, 2]])
"""Hermite-cubic consistent mass: ``ρAh/420 · _BEAM_MASS · h**_BEAM_MASS_POWERS``."""


def element_geometry(
    nodes: ArrayLike, connectivity: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Length and direction cosines of each element.

    Parameters
    ----------
    nodes : ndarray, shape (n_nodes, 2)
        Node coordinates [m].
    connectivity : ndarray of int, shape (n_elements, 2)
        Node indices ``(i, j)`` of each element.

    Returns
    -------
    length : ndarray, shape (n_elements,)
        Element lengths ``h`` [m].
    cos, sin : ndarray, shape (n_elements,)
        ``(x_j − x_i)/h`` and ``(y_j − y_i)/h``.

    Examples
    --------
    >>> h, c, s = element_geometry([[0, 0], [3, 4]], [[0, 1]])
    >>> float(h[0]), float(c[0]), float(s[0])
    (5.0, 0.6, 0.8)
    """
    nodes = np.asarray(nodes, dtype=float)
    connectivity = np.asarray(connectivity, dtype=np.intp)
    delta = nodes[connectivity[:, 1]] - nodes[connectivity[:, 0]]
    length = np.hypot(delta[:, 0], delta[:, 1])
    return length, delta[:, 0] / length, delta[:, 1] / length


def deformation_matrices(length: ArrayLike, cos: ArrayLike, sin: ArrayLike) -> NDArray:
    """Matrices ``B`` mapping element DOFs to natural deformations, ``(e, a, b) = B x``.

    Parameters
    ----------
    length, cos, sin : ndarray, shape (n_elements,)
        From :func:`element_geometry`.

    Returns
    -------
    ndarray, shape (n_elements, 3, 6)
        Rows: elongation ``e`` [m], end rotations ``a`` and ``b`` [rad] from the chord.

    Examples
    --------
    >>> B = deformation_matrices([2.0], [1.0], [0.0])
    >>> B[0] @ [0, 0, 0, 0.1, 0.2, 0.3]   # stretch 0.1, lift 0.2, rotate θ_j = 0.3
    array([ 0.1, -0.1,  0.2])
    """
    h, c, s = (np.asarray(v, dtype=float) for v in (length, cos, sin))
    B = np.zeros((h.size, 3, 6))
    B[:, 0, [0, 1, 3, 4]] = np.stack([-c, -s, c, s], axis=1)
    chord = np.stack([-s / h, c / h], axis=1)  # dψ/d(u_j, v_j)
    for row, theta_column in ((1, 2), (2, 5)):
        B[:, row, [0, 1]] = chord
        B[:, row, [3, 4]] = -chord
        B[:, row, theta_column] = 1.0
    return B


def deformation_stiffness(length: ArrayLike, EA: ArrayLike, EI: ArrayLike) -> NDArray:
    """The 3 × 3 matrices ``D`` with ``(N, M_i, M_j) = D (e, a, b)``.

    Parameters
    ----------
    length : ndarray, shape (n_elements,)
        Element lengths [m].
    EA, EI : ndarray, shape (n_elements,)
        Axial stiffness [N] and bending stiffness [N m²].

    Returns
    -------
    ndarray, shape (n_elements, 3, 3)
        ``diag(EA/h, EI/h [[4, 2], [2, 4]])``.

    Examples
    --------
    >>> deformation_stiffness([1.0], [10.0], [1.0])[0]
    array([[10.,  0.,  0.],
           [ 0.,  4.,  2.],
           [ 0.,  2.,  4.]])
    """
    h, EA, EI = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (length, EA, EI)))
    D = np.zeros((h.size, 3, 3))
    D[:, 0, 0] = EA / h
    D[:, 1:, 1:] = (EI / h)[:, None, None] * np.array([[4.0, 2.0], [2.0, 4.0]])
    return D


def stiffness_matrices(
    length: ArrayLike, cos: ArrayLike, sin: ArrayLike, EA: ArrayLike, EI: ArrayLike
) -> NDArray:
    """Element stiffness matrices in global axes, ``K = Bᵀ D B``.

    Parameters
    ----------
    length, cos, sin : ndarray, shape (n_elements,)
        From :func:`element_geometry`.
    EA, EI : ndarray, shape (n_elements,)
        Axial stiffness [N] and bending stiffness [N m²].

    Returns
    -------
    ndarray, shape (n_elements, 6, 6)
        Symmetric positive semi-definite, null space = the three rigid-body motions
        [N/m, N, N m].

    Examples
    --------
    >>> K = stiffness_matrices([1.0], [1.0], [0.0], [1.0], [1.0])[0]
    >>> K[1, [1, 2, 4, 5]]   # 12, 6h, −12, 6h times EI/h³
    array([ 12.,   6., -12.,   6.])
    """
    B = deformation_matrices(length, cos, sin)
    D = deformation_stiffness(length, EA, EI)
    return np.einsum("eki,ekl,elj->eij", B, D, B)


def mass_matrices(length: ArrayLike, cos: ArrayLike, sin: ArrayLike, rho_A: ArrayLike) -> NDArray:
    """Consistent element mass matrices in global axes, ``M = Tᵀ m T``.

    In local axes the axial DOFs get the linear bar's ``ρAh/6 [[2, 1], [1, 2]]`` and the
    transverse DOFs ``(v_i, θ_i, v_j, θ_j)`` the Hermite-cubic
    ``ρAh/420 [[156, 22h, 54, −13h], [22h, 4h², 13h, −3h²], [54, 13h, 156, −22h],
    [−13h, −3h², −22h, 4h²]]``; ``T`` rotates ``(u, v)`` of each node into the element axes.

    Parameters
    ----------
    length, cos, sin : ndarray, shape (n_elements,)
        From :func:`element_geometry`.
    rho_A : ndarray, shape (n_elements,)
        Mass per unit length ``ρA`` [kg/m].

    Returns
    -------
    ndarray, shape (n_elements, 6, 6)
        Symmetric positive definite [kg, kg m, kg m²].

    Examples
    --------
    >>> m = mass_matrices([2.0], [1.0], [0.0], [3.0])[0]
    >>> float(m[np.ix_([0, 3], [0, 3])].sum()), float(m[np.ix_([1, 4], [1, 4])].sum())
    (6.0, 6.0)
    """
    h, c, s, rho_A = np.broadcast_arrays(
        *(np.asarray(v, dtype=float) for v in (length, cos, sin, rho_A))
    )
    scale = (rho_A * h)[:, None, None]
    H = h[:, None, None]
    local = np.zeros((h.size, 6, 6))
    axial, transverse = np.array([0, 3]), np.array([1, 2, 4, 5])
    local[:, axial[:, None], axial] = scale / 6 * _BAR_MASS
    local[:, transverse[:, None], transverse] = scale / 420 * _BEAM_MASS * H**_BEAM_MASS_POWERS
    T = rotation_matrices(c, s)
    return np.einsum("eki,ekl,elj->eij", T, local, T)


def rotation_matrices(cos: ArrayLike, sin: ArrayLike) -> NDArray:
    """Global-to-local rotations ``T = blockdiag(R, R)``.

    ``R = [[c, s, 0], [−s, c, 0], [0, 0, 1]]`` for each node.

    Parameters
    ----------
    cos, sin : ndarray, shape (n_elements,)
        Direction cosines of the element axes.

    Returns
    -------
    ndarray, shape (n_elements, 6, 6)
        Orthogonal matrices; local DOFs = ``T @`` global DOFs.

    Examples
    --------
    >>> T = rotation_matrices([0.0], [1.0])[0]
    >>> T[:3, :3] @ [0.0, 1.0, 0.0]   # global +y is the local axial direction
    array([1., 0., 0.])
    """
    c, s = np.broadcast_arrays(np.asarray(cos, dtype=float), np.asarray(sin, dtype=float))
    T = np.zeros((c.size, 6, 6))
    for offset in (0, 3):
        T[:, offset, offset] = c
        T[:, offset, offset + 1] = s
        T[:, offset + 1, offset] = -s
        T[:, offset + 1, offset + 1] = c
        T[:, offset + 2, offset + 2] = 1.0
    return T


def element_forces(
    x_element: ArrayLike,
    length: ArrayLike,
    cos: ArrayLike,
    sin: ArrayLike,
    EA: ArrayLike,
    EI: ArrayLike,
) -> NDArray:
    """Internal nodal forces ``K x`` of each element, computed from differences.

    The same algorithm as the compiled kernel in :mod:`tumble.structural.kernels` (which
    a test checks against this reference): natural deformations first (module docstring),
    then ``N``, ``M_i``, ``M_j``, ``V``, then the local end forces ``(−N, V, M_i)`` and
    ``(N, −V, M_j)`` rotated to global axes.

    Parameters
    ----------
    x_element : ndarray, shape (..., n_elements, 6)
        Element DOFs ``(u_i, v_i, θ_i, u_j, v_j, θ_j)`` [m, m, rad, m, m, rad].
    length, cos, sin : ndarray, shape (n_elements,)
        From :func:`element_geometry`.
    EA, EI : ndarray, shape (n_elements,)
        Axial stiffness [N] and bending stiffness [N m²].

    Returns
    -------
    ndarray, shape (..., n_elements, 6)
        The element's resisting forces at its nodes (the forces that hold it in the
        deformed shape), ``(F_xi, F_yi, M_i, F_xj, F_yj, M_j)`` [N, N, N m, N, N, N m];
        equal to ``K @ x_element`` up to round-off.

    Examples
    --------
    >>> x = np.array([[0.0, 0.0, 0.0, 0.0, 1e-3, 0.0]])   # pull node j up by 1 mm
    >>> element_forces(x, [1.0], [1.0], [0.0], [1.0], [1.0])[0] + 0.0   # 12 EI/h³ · 1 mm
    array([ 0.   , -0.012, -0.006,  0.   ,  0.012, -0.006])
    """
    h, c, s, EA, EI = (np.asarray(v, dtype=float) for v in (length, cos, sin, EA, EI))
    elongation, a, b = np.moveaxis(natural_deformations(x_element, h, c, s), -1, 0)
    axial = EA / h * elongation
    moment_i = EI / h * (4.0 * a + 2.0 * b)
    moment_j = EI / h * (2.0 * a + 4.0 * b)
    shear = (moment_i + moment_j) / h
    fx = -c * axial - s * shear
    fy = -s * axial + c * shear
    return np.stack([fx, fy, moment_i, -fx, -fy, moment_j], axis=-1)


def natural_deformations(
    x_element: ArrayLike, length: ArrayLike, cos: ArrayLike, sin: ArrayLike
) -> NDArray:
    """Elongation and chord-relative end rotations ``(e, a, b)``, from differences.

    Parameters
    ----------
    x_element : ndarray, shape (..., n_elements, 6)
        Element DOFs ``(u_i, v_i, θ_i, u_j, v_j, θ_j)`` [m, m, rad, m, m, rad].
    length, cos, sin : ndarray, shape (n_elements,)
        From :func:`element_geometry`.

    Returns
    -------
    ndarray, shape (..., n_elements, 3)
        ``e = c Δu + s Δv`` [m], ``a = θ_i − ψ``, ``b = θ_j − ψ`` [rad] with the chord
        rotation ``ψ = (c Δv − s Δu)/h``; zero for rigid-body motions.

    Examples
    --------
    >>> rigid = [[0.0, 0.0, 0.1, 0.0, 0.1, 0.1]]   # rotate the unit element by 0.1 rad
    >>> natural_deformations(rigid, [1.0], [1.0], [0.0])
    array([[0., 0., 0.]])
    """
    x = np.asarray(x_element, dtype=float)
    h, c, s = (np.asarray(v, dtype=float) for v in (length, cos, sin))
    du = x[..., 3] - x[..., 0]
    dv = x[..., 4] - x[..., 1]
    psi = (c * dv - s * du) / h
    return np.stack([c * du + s * dv, x[..., 2] - psi, x[..., 5] - psi], axis=-1)


def strain_energy(
    x_element: ArrayLike,
    length: ArrayLike,
    cos: ArrayLike,
    sin: ArrayLike,
    EA: ArrayLike,
    EI: ArrayLike,
) -> NDArray:
    """Strain energy ``½ xᵀ K x = ½ dᵀ D d`` of each element, from natural deformations.

    Parameters
    ----------
    x_element : ndarray, shape (..., n_elements, 6)
        Element DOFs [m, m, rad, m, m, rad].
    length, cos, sin : ndarray, shape (n_elements,)
        From :func:`element_geometry`.
    EA, EI : ndarray, shape (n_elements,)
        Axial stiffness [N] and bending stiffness [N m²].

    Returns
    -------
    ndarray, shape (..., n_elements, 2)
        Axial part ``½ EA/h e²`` and bending part ``EI/h (2a² + 2ab + 2b²)`` [J]; each is
        non-negative by construction.

    Examples
    --------
    >>> strain_energy([[0.0, 0.0, 0.0, 1e-3, 0.0, 0.0]], [1.0], [1.0], [0.0], [2e3], [1.0])
    array([[0.001, 0.   ]])
    """
    h, EA, EI = (np.asarray(v, dtype=float) for v in (length, EA, EI))
    elongation, a, b = np.moveaxis(natural_deformations(x_element, h, cos, sin), -1, 0)
    axial = 0.5 * EA / h * elongation**2
    bending = EI / h * (2.0 * a * a + 2.0 * a * b + 2.0 * b * b)
    return np.stack([axial, bending], axis=-1)
