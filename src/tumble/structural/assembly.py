"""Assembled linear systems ``M ẍ = f − S x`` for 2D frames, and the cantilever.

:func:`build_frame` takes nodes, elements, sections, supports and nodal loads and returns a
:class:`LinearSystem` with sparse ``M`` and ``S`` on the free degrees of freedom only (the
supported ones are removed, as the seed's "frozen" DOFs). :func:`cantilever` is the seed's
beam: clamped at x = 0, loaded at the tip.

Conditioning. ``κ(S)`` of a beam grows like ``N⁴`` with the element count (2.3e9, 2.3e13,
2.0e17 at N = 100, 1000, 10000 on the 1 m steel cantilever, measured), so in double
precision a static solve loses about ``log10 κ`` digits: with SuperLU's default ordering
the tip deflection was good to 2e-10 at N = 100, 5e-7 at N = 1000 and 15 % off at
N = 10000 (0.3 % with :func:`~tumble.structural.factorization.factorize`'s symmetric ordering).
The builder estimates ``κ(S)`` and warns with :class:`IllConditionedWarning` when
``ε κ(S) > 1`` (from about 3700 elements on this beam), i.e. when round-off alone can
exceed the displacement itself; at N = 10⁵ even the time stepping blows up.

References
----------
.. [1] Ł. Łaniewski-Wołłk, *Metody Numeryczne, Instrukcja 5: Równania ruchu* (seed 003).
.. [2] R. D. Cook et al., *Concepts and Applications of Finite Element Analysis*, 4th ed.,
   Wiley, 2002, §2.5 (assembly), §9.3 (ill-conditioning).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from tumble import _checks
from tumble.structural import elements
from tumble.structural.factorization import factorize
from tumble.structural.system import FrameElements, LinearSystem

SUPPORT_KINDS: dict[str, tuple[bool, bool, bool]] = {
    "clamped": (True, True, True),
    "pinned": (True, True, False),
    "roller-x": (False, True, False),
    "roller-y": (True, False, False),
}
"""Named supports: which of ``(u, v, θ)`` they fix. ``roller-x`` rolls along x."""

CONDITION_LIMIT = 1.0
"""Warn when ``ε κ(S)`` exceeds this: round-off can then exceed the displacement."""

INVERSE_ITERATIONS = 6
"""Inverse-iteration steps for ``λ_min(S)``; the beam's λ₂/λ₁ ≈ 40 makes 6 plenty."""


class IllConditionedWarning(UserWarning):
    """The stiffness matrix is so ill-conditioned that results lose all accuracy."""


def build_frame(
    nodes: ArrayLike,
    connectivity: ArrayLike,
    *,
    E: ArrayLike,
    rho: ArrayLike,
    area: ArrayLike,
    second_moment: ArrayLike,
    supports: Mapping[int, str | Sequence[bool]],
    loads: Mapping[int, Sequence[float]] | None = None,
    monitor: tuple[int, int] | None = None,
) -> LinearSystem:
    """Assemble a 2D Euler–Bernoulli frame into ``M ẍ = f − S x`` on its free DOFs.

    Every node has DOFs ``(u, v, θ)`` [m, m, rad]; elements are the Hermite beam plus a
    linear bar with consistent mass (:mod:`tumble.structural.elements`). Supported DOFs
    are removed; a load on a supported DOF goes into the support and is dropped.

    Parameters
    ----------
    nodes : ndarray, shape (n_nodes, 2)
        Node coordinates [m].
    connectivity : ndarray of int, shape (n_elements, 2)
        Node indices of each element.
    E, rho, area, second_moment : float or ndarray, shape (n_elements,)
        Young's modulus [Pa], density [kg/m³], cross-section area [m²] and second moment
        of area about the bending axis [m⁴]; each > 0.
    supports : mapping of node index to str or three bools
        A name from :data:`SUPPORT_KINDS` or which of ``(u, v, θ)`` are fixed.
    loads : mapping of node index to three floats, optional
        Nodal loads ``(F_x [N], F_y [N], M_z [N m])``, a step applied at t = 0.
    monitor : (node, component), optional
        The DOF reported as ``tip_dof`` (component 0, 1, 2 for u, v, θ); by default the
        free DOF with the largest load, else the last free DOF.

    Returns
    -------
    LinearSystem

    Warns
    -----
    IllConditionedWarning
        When ``ε κ(S) > 1``: refine less.

    Examples
    --------
    A simply supported 2 m steel beam, pinned at the left and on a roller at the right:

    >>> nodes = np.column_stack([np.linspace(0, 2, 11), np.zeros(11)])
    >>> frame = build_frame(nodes, np.column_stack([np.arange(10), np.arange(1, 11)]),
    ...     E=210e9, rho=7850, area=1e-4, second_moment=1e-4 ** 2 / 12,
    ...     supports={0: "pinned", 10: "roller-x"})
    >>> frame.n_dofs, frame.natural_frequencies(1).round(2)   # exact: π² sqrt(EI/(ρAL⁴))
    (30, array([36.84]))
    """
    nodes, connectivity = _checked_mesh(nodes, connectivity)
    n_nodes, n_elements = nodes.shape[0], connectivity.shape[0]
    section = {
        name: _section(name, value, unit, n_elements)
        for name, value, unit in (
            ("E", E, "Pa"),
            ("rho", rho, "kg/m³"),
            ("area", area, "m²"),
            ("second_moment", second_moment, "m⁴"),
        )
    }
    length, cos, sin = elements.element_geometry(nodes, connectivity)
    _check_scales(section, length)
    supports = _checks.instance("supports", supports, Mapping, "a mapping of node index to a "
                                "support (e.g. {0: 'clamped'})")  # fmt: skip
    fixed = _fixed_dofs(supports, n_nodes)
    free = np.flatnonzero(~fixed.ravel())
    position = np.full(fixed.size, -1, dtype=np.int64)
    position[free] = np.arange(free.size)
    dof_map = position[(3 * connectivity[:, :, None] + np.arange(3)).reshape(n_elements, 6)]
    frame = FrameElements(
        connectivity,
        length,
        cos,
        sin,
        EA=section["E"] * section["area"],
        EI=section["E"] * section["second_moment"],
        rho_A=section["rho"] * section["area"],
        dof_map=dof_map,
    )
    S = _assemble(elements.stiffness_matrices(length, cos, sin, frame.EA, frame.EI), dof_map)
    M = _assemble(elements.mass_matrices(length, cos, sin, frame.rho_A), dof_map)
    f = _nodal_loads(loads, n_nodes)[free]
    tip = _monitor_dof(monitor, position, f, n_nodes)
    _warn_if_ill_conditioned(S, supports)
    return LinearSystem(M, S, f, nodes, frame, free, tip)


def cantilever(
    length: float,
    n_elements: int,
    E: float,
    rho: float,
    width: float,
    height: float,
    tip_load: float = 0.0,
    *,
    axial: bool = False,
) -> LinearSystem:
    """The seed's beam: clamped at x = 0, free at x = ``length``, a step load at the tip.

    ``n_elements`` equal Euler–Bernoulli elements along x; a ``width`` × ``height``
    rectangular section bending in the plane of ``height``, ``A = width·height`` and
    ``I = width·height³/12``. By default the axial DOFs are fixed, leaving ``(v, θ)`` at
    nodes 1…N (``n_dofs = 2N``, ordered ``v₁, θ₁, v₂, θ₂, …``): a transverse load on a
    straight beam never excites them, and without them ``ω_max`` is a bending mode, so the
    semi-implicit scheme's limit ``2/ω_max`` is sharp. ``axial=True`` keeps them
    (``n_dofs = 3N``).

    Parameters
    ----------
    length : float
        Beam length L [m], > 0.
    n_elements : int
        Number of elements N, >= 1.
    E, rho : float
        Young's modulus [Pa] and density [kg/m³], > 0.
    width, height : float
        Section size [m], > 0.
    tip_load : float, optional
        Transverse tip force F [N], +y; the static tip deflection is ``F L³/(3EI)``.
    axial : bool, optional
        Keep the axial DOFs (default False).

    Returns
    -------
    LinearSystem
        With ``tip_dof`` the tip's transverse displacement.

    References
    ----------
    .. [1] R. D. Blevins, *Formulas for Natural Frequency and Mode Shape*, Van Nostrand,
       1979, table 8-1: ``ω_k = (β_k L)² sqrt(EI/(ρ A L⁴))``, ``cos βL cosh βL = −1``.

    Examples
    --------
    >>> beam = cantilever(1.0, 20, E=210e9, rho=7850, width=0.01, height=0.01, tip_load=1.0)
    >>> beam.n_dofs, round(float(beam.static_displacement()[beam.tip_dof] * 3 * 175), 9)
    (40, 1.0)
    """
    length = _checks.positive("length", length, "m")
    n_elements = _checks.count("n_elements", n_elements, 1, max_elements(),
                               remedy="the model would not fit in half the memory")  # fmt: skip
    width = _checks.positive("width", width, "m")
    height = _checks.positive("height", height, "m")
    tip_load = _checks.finite("tip_load", tip_load, "N")
    sizes = {"length": (length, "m"), "E": (_checks.positive("E", E, "Pa"), "Pa"),
             "rho": (_checks.positive("rho", rho, "kg/m³"), "kg/m³"), "width": (width, "m"),
             "height": (height, "m")}  # fmt: skip
    area, second_moment = _representable(sizes, lambda: _section_of(width, height))
    ell = length / n_elements
    _representable(sizes, lambda: _element_scales(ell, E, rho, area, second_moment))
    x = np.linspace(0.0, length, n_elements + 1)
    nodes = np.column_stack([x, np.zeros_like(x)])
    connectivity = np.column_stack([np.arange(n_elements), np.arange(1, n_elements + 1)])
    supports: dict[int, str | Sequence[bool]] = {0: "clamped"}
    if not _checks.flag("axial", axial):
        supports |= {node: (True, False, False) for node in range(1, n_elements + 1)}
    return build_frame(
        nodes,
        connectivity,
        E=E,
        rho=rho,
        area=area,
        second_moment=second_moment,
        supports=supports,
        loads={n_elements: (0.0, tip_load, 0.0)},
        monitor=(n_elements, 1),
    )


ELEMENT_BYTES = 4096
"""About what one element takes while a cantilever is assembled and stepped (its element
matrices, the sparse matrices' entries, the factors and the workspaces; the peak resident
memory measured 2.1 kB an element to build 2·10⁴ and 10⁵ elements, and 2.1–4.1 kB with two
steps of ``integrate``): :func:`max_elements` divides half the memory by it."""


def max_elements() -> int:
    """The most elements a cantilever may have: what fits in half this machine's memory."""
    return int(0.5 * _checks.memory() / ELEMENT_BYTES)


def _section_of(width: float, height: float) -> tuple[float, ...]:
    """``(A, I) = (w h, w h³/12)`` of a rectangular section."""
    return width * height, width * height**3 / 12


def _element_scales(ell, E, rho, area, second_moment) -> tuple[float, ...]:
    """The sizes every entry of an element's matrices and the frequencies are made of: the
    bar's ``EA/ℓ``, the beam's ``12 EI/ℓ³``, the mass ``ρAℓ`` and ``ω² ~ EI/(ρA ℓ⁴)``."""
    EA, EI, mass = E * area, E * second_moment, rho * area * ell
    return EA / ell, 12 * EI / ell**3, EI / ell, mass, mass * ell * ell, EI / (rho * area * ell**4)


SECTION_UNITS = {"E": "Pa", "rho": "kg/m³", "area": "m²", "second_moment": "m⁴"}
"""The units of :func:`build_frame`'s section properties."""


def _check_scales(section: Mapping[str, NDArray], length: NDArray) -> None:
    """:func:`_representable` for a frame: each property by its value furthest from 1."""

    def extreme(values: NDArray) -> float:
        with np.errstate(divide="ignore"):
            return float(values[np.argmax(np.abs(np.log10(values)))])

    sizes = {name: (extreme(section[name]), SECTION_UNITS[name]) for name in section}
    sizes["nodes"] = (extreme(length), "m")
    E, rho, area, second_moment = (section[name] for name in SECTION_UNITS)
    _representable(sizes, lambda: _element_scales(length, E, rho, area, second_moment))


def _representable(sizes: Mapping[str, tuple[float, str]], compute) -> tuple:
    """``compute()``'s quantities, each refused unless a normal float (finite, and not so
    small that it has lost digits or its inverse overflows): the ValueError names the
    argument of ``sizes`` furthest from 1 (by orders of magnitude), with the others."""
    tiny = np.finfo(float).tiny  # 2.2e-308
    try:
        with np.errstate(all="ignore"):
            values = compute()
    except (OverflowError, ZeroDivisionError):  # a float ** past 1.8e308, or / 0.0
        values = (math.inf,)
    if all(np.all((tiny <= np.abs(v)) & (np.abs(v) < math.inf)) for v in values):
        return values
    name = max(sizes, key=lambda key: abs(math.log10(sizes[key][0])))
    others = ", ".join(f"{key}={value!r} {unit}" for key, (value, unit) in sizes.items()
                       if key != name)  # fmt: skip
    raise _checks.fail(
        name, sizes[name][0], "such that the section, the stiffness, the mass and the "
        "frequencies are normal floats (between 2.2e-308 and 1.8e308)", sizes[name][1],
        remedy=f"with {others} they are not; give the beam in other units",
    )  # fmt: skip


def condition_estimate(S: sp.spmatrix) -> float:
    """Estimate the 2-norm condition number ``κ(S) = λ_max/λ_min`` of an SPD matrix.

    ``λ_max`` by Gershgorin (an upper bound, within a factor ~2 for FE matrices) and
    ``λ_min`` by a few steps of inverse iteration with a sparse LU factor.

    Examples
    --------
    >>> beam = cantilever(1.0, 100, E=210e9, rho=7850, width=0.01, height=0.01)
    >>> f"{condition_estimate(beam.S):.1e}"   # grows like N⁴
    '2.3e+09'
    """
    if not sp.issparse(S) or S.ndim != 2 or S.shape[0] != S.shape[1] or S.shape[0] == 0:
        raise _checks.fail("S", S, "a square scipy.sparse matrix (LinearSystem.S)")
    try:
        return _estimate(S)
    except RuntimeError:  # SuperLU: "Factor is exactly singular"
        raise _checks.fail("S", S, "a nonsingular matrix", remedy="its LU factor is exactly "
                           "singular: κ = inf") from None  # fmt: skip
    except ValueError as error:
        raise _checks.fail("S", S, "a matrix with finite entries, not all zero",
                           remedy=str(error)) from None  # fmt: skip


def _estimate(S: sp.spmatrix) -> float:
    """:func:`condition_estimate`; a RuntimeError from SuperLU for a singular ``S``."""
    lam_max = float(abs(S).sum(axis=1).max())
    if not 0 < lam_max < math.inf:
        raise ValueError(f"the largest row sum of |S| is {lam_max:g}")
    S = S / lam_max  # κ is scale-free; at scale 1 no norm below underflows
    solve = factorize(S)
    v = np.random.default_rng(0).standard_normal(S.shape[0])
    for _ in range(INVERSE_ITERATIONS):
        v = solve(v / np.linalg.norm(v))
    lam_min = 1.0 / float(np.linalg.norm(v))
    return float(abs(S).sum(axis=1).max()) / lam_min


def _warn_if_ill_conditioned(S: sp.spmatrix, supports: Mapping) -> None:
    try:
        kappa = _estimate(S)
    except RuntimeError as error:  # SuperLU: "Factor is exactly singular"
        raise _checks.fail(
            "supports",
            dict(supports),
            "supports that leave no mechanism (no rigid motion of any part free)",
            remedy="the stiffness matrix is singular; fix more DOFs",
        ) from error
    bound = np.finfo(float).eps * kappa
    if bound > CONDITION_LIMIT:
        warnings.warn(
            f"the stiffness matrix has condition number ~{kappa:.1e}, so round-off "
            f"(ε κ ≈ {bound:.0e}) can exceed the displacements themselves; use fewer "
            "elements (κ grows like N⁴ along a member) or check that the supports leave "
            "no mechanism",
            IllConditionedWarning,
            stacklevel=3,
        )


def _assemble(blocks: NDArray, dof_map: NDArray) -> sp.csr_matrix:
    n = int(dof_map.max()) + 1
    rows = np.broadcast_to(dof_map[:, :, None], blocks.shape)
    cols = np.broadcast_to(dof_map[:, None, :], blocks.shape)
    keep = (rows >= 0) & (cols >= 0)
    return sp.coo_matrix((blocks[keep], (rows[keep], cols[keep])), shape=(n, n)).tocsr()


def _section(name: str, value: ArrayLike, unit: str, n_elements: int) -> NDArray:
    """A section property [unit] per element, from one number > 0 or one per element."""
    if np.ndim(value) == 0 and not isinstance(value, np.ndarray):
        return np.full(n_elements, _checks.positive(name, value, unit))
    array = _checks.array(name, value, unit=unit, positive=True)
    if array.shape not in ((), (1,), (n_elements,)):
        raise _checks.fail(name, value, f"a number or {n_elements} numbers, one per element", unit)
    return np.broadcast_to(array, (n_elements,)).astype(float)


def _checked_mesh(nodes: ArrayLike, connectivity: ArrayLike) -> tuple[NDArray, NDArray]:
    nodes = _checks.array("nodes", nodes, unit="m")
    if nodes.ndim != 2 or nodes.shape[1] != 2 or nodes.shape[0] < 2:
        raise _checks.fail(
            "nodes", nodes, "of shape (n_nodes >= 2, 2)", "m", f"it has shape {nodes.shape}"
        )
    connectivity = np.asarray(connectivity)
    if (
        connectivity.ndim != 2
        or connectivity.shape[1] != 2
        or connectivity.shape[0] < 1
        or not np.issubdtype(connectivity.dtype, np.integer)
    ):
        raise _checks.fail(
            "connectivity",
            connectivity,
            "integers of shape (n_elements >= 1, 2)",
            remedy=f"it has dtype {connectivity.dtype} and shape {connectivity.shape}",
        )
    if connectivity.min() < 0 or connectivity.max() >= nodes.shape[0]:
        raise _checks.fail(
            "connectivity",
            connectivity,
            f"node indices 0..{nodes.shape[0] - 1}",
            remedy=f"it holds {connectivity.min()}..{connectivity.max()}",
        )
    delta = nodes[connectivity[:, 1]] - nodes[connectivity[:, 0]]
    coincident = np.flatnonzero(np.hypot(delta[:, 0], delta[:, 1]) == 0)
    if coincident.size:
        bad = int(coincident[0])
        raise _checks.fail(
            f"connectivity[{bad}]",
            connectivity[bad].tolist(),
            "two distinct nodes",
            remedy="it joins coincident nodes; elements need length > 0",
        )
    return nodes, connectivity.astype(np.intp)


def _fixed_dofs(supports: Mapping[int, str | Sequence[bool]], n_nodes: int) -> NDArray:
    fixed = np.zeros((n_nodes, 3), dtype=bool)
    for node, kind in supports.items():
        _check_node("supports", node, n_nodes)
        if isinstance(kind, str):
            fixed[node] = SUPPORT_KINDS[_checks.choice(f"supports[{node}]", kind, SUPPORT_KINDS)]
        elif len(kind) == 3 and all(isinstance(k, bool | np.bool_) for k in kind):
            fixed[node] = kind
        else:
            raise _checks.fail(
                f"supports[{node}]",
                kind,
                f"one of {', '.join(map(repr, SUPPORT_KINDS))} or three bools (u, v, θ fixed)",
            )
    if fixed.all():
        raise _checks.fail(
            "supports",
            dict(supports),
            "supports that leave some DOF free",
            remedy="these fix every DOF; nothing is left to move",
        )
    return fixed


def _nodal_loads(loads: Mapping[int, Sequence[float]] | None, n_nodes: int) -> NDArray:
    f = np.zeros((n_nodes, 3))
    if loads is not None:
        _checks.instance("loads", loads, Mapping, "None or a mapping of node index to "
                         "(F_x, F_y, M_z)")  # fmt: skip
    for node, load in (loads or {}).items():
        _check_node("loads", node, n_nodes)
        f[node] += _checks.array(
            f"loads[{node}]", load, shape=(3,), unit="F_x, F_y in N, M_z in N m"
        )
    return f.ravel()


def _monitor_dof(
    monitor: tuple[int, int] | None, position: NDArray, f: NDArray, n_nodes: int
) -> int:
    if monitor is None:
        return int(np.argmax(np.abs(f))) if np.any(f) else f.size - 1
    if not isinstance(monitor, tuple | list) or len(monitor) != 2:
        raise _checks.fail("monitor", monitor, "None or a pair (node, component 0|1|2 for "
                           "u|v|θ)")  # fmt: skip
    node, component = monitor
    _check_node("monitor", node, n_nodes)
    index = position[3 * node + component] if component in (0, 1, 2) else -1
    if index < 0:
        raise _checks.fail("monitor", monitor, "a free DOF (node, component 0|1|2 for u|v|θ)")
    return int(index)


def _check_node(name: str, node: object, n_nodes: int) -> None:
    if isinstance(node, bool) or not isinstance(node, int | np.integer) or not 0 <= node < n_nodes:
        raise _checks.fail(f"{name} key", node, f"a node index 0..{n_nodes - 1}")
