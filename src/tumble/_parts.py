"""The connected parts of a closed triangle mesh: their signed volumes and how they nest.

Pure NumPy on ``(n, 3, 3)`` triangle arrays, wound as trimesh winds them (counter-clockwise
seen from the side the normal points to). :func:`oriented` is what
:func:`tumble.meshes.from_mesh` uses to tell a cavity from an inside-out part.

A closed, consistently wound surface bounds a solid when every part is wound outward at even
nesting depth (a part, an island inside a cavity) and inward at odd depth (a cavity): the
rule of CGAL's ``orient_to_bound_a_volume``. Part ``i`` lies inside part ``j`` when ``j``'s
generalised winding number at ``i``'s vertices is ±1 (Jacobson, Kavan & Sorkine-Hornung,
*Robust inside-outside segmentation using generalized winding numbers*, 2013), each
triangle's solid angle from van Oosterom & Strackee (1983):

    tan(Ω/2) = a·(b × c) / (|a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|),   w = ΣΩ / 4π,

with ``a, b, c`` the corners relative to the point.

Examples
--------
>>> tetrahedron = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])[[[0, 2, 1], [0, 1, 3],
...     [0, 3, 2], [1, 2, 3]]]  # a tetrahedron, wound outward
>>> float(signed_volumes(tetrahedron, np.zeros(4, dtype=int))[0])  # 1/6
0.16666666666666666
>>> round(float(winding_number(np.array([0.1, 0.1, 0.1]), tetrahedron)), 12)
1.0
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tumble._checks import fail

SAMPLES = 8
"""Vertices of a part at which the winding number of a candidate enclosing part is taken;
the median decides, so a few vertices touching the other part's surface do not."""
FLAT_RTOL = 1e-12
"""A part whose |signed volume| is at most this times ``Σ|a·(b × c)|/6`` encloses no volume."""

Triangles = NDArray[np.float64]
Labels = NDArray[np.intp]


def part_labels(faces: NDArray[np.integer]) -> Labels:
    """Label of each face's connected part (faces sharing an edge are connected).

    Parameters
    ----------
    faces : ndarray of int, shape (n, 3)
        Vertex indices of each triangle.

    Returns
    -------
    ndarray of int, shape (n,)
        0, 1, ... numbered in the order of each part's first face.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    faces = np.asarray(faces, dtype=np.int64)
    n = len(faces)
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, edge = np.unique(edges[:, 0] * (int(faces.max()) + 1) + edges[:, 1], return_inverse=True)
    nodes = n + int(edge.max()) + 1  # a graph of faces and edges, each face joined to its 3
    joins = (np.repeat(np.arange(n), 3), n + edge.ravel())
    graph = coo_matrix((np.ones(3 * n), joins), shape=(nodes, nodes))
    _, labels = connected_components(graph, directed=False)
    _, first, inverse = np.unique(labels[:n], return_index=True, return_inverse=True)
    rank = np.empty(len(first), dtype=np.intp)
    rank[np.argsort(first)] = np.arange(len(first))
    return rank[inverse.ravel()]


def _triples(triangles: Triangles, labels: Labels) -> NDArray[np.float64]:
    """``a·(b × c)`` of each triangle, its corners taken relative to its part's first corner
    (6 × the signed volume of the tetrahedron it spans with that corner)."""
    first = np.unique(labels, return_index=True)[1]
    a, b, c = np.moveaxis(triangles - triangles[first, 0][labels][:, None, :], 1, 0)
    return np.einsum("ij,ij->i", a, np.cross(b, c))


def signed_volumes(triangles: Triangles, labels: Labels) -> NDArray[np.float64]:
    """Signed volume of each part (> 0 wound outward), by the divergence theorem
    ``V = Σ a·(b × c) / 6``; each part is taken relative to its own first corner (the sum is
    translation-invariant for a closed part, and smaller terms round off less)."""
    return np.bincount(labels, _triples(triangles, labels), int(labels.max()) + 1) / 6


def swept_volumes(triangles: Triangles, labels: Labels) -> NDArray[np.float64]:
    """``Σ |a·(b × c)| / 6`` per part, as in :func:`signed_volumes`: the scale of its round-off
    (a flat closed part has signed volume 0 to round-off of this)."""
    return np.bincount(labels, np.abs(_triples(triangles, labels)), int(labels.max()) + 1) / 6


def winding_number(point: NDArray[np.float64], triangles: Triangles) -> float:
    """Generalised winding number of the surface ``triangles`` at ``point`` (module
    docstring): 1 inside an outward closed surface, −1 inside an inward one, 0 outside."""
    a, b, c = (triangles[:, k] - point for k in range(3))
    la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
    numerator = np.einsum("ij,ij->i", a, np.cross(b, c))
    dot = lambda u, v: np.einsum("ij,ij->i", u, v)  # noqa: E731
    denominator = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la
    return float(np.sum(np.arctan2(numerator, denominator)) / (2 * np.pi))


def enclosing(triangles: Triangles, labels: Labels) -> list[list[int]]:
    """For each part, the parts it lies inside (winding number of ±1 at its vertices).

    Only parts whose bounding box holds the part's bounding box are tested. Coordinates are
    scaled to the mesh's size first, so the test holds at any scale.
    """
    low, high = triangles.min(axis=(0, 1)), triangles.max(axis=(0, 1))
    size = float(np.max(high - low)) or 1.0
    scaled = (triangles - (low + high) / 2) / size
    count = int(labels.max()) + 1
    order = np.argsort(labels, kind="stable")
    members = np.split(scaled[order], np.cumsum(np.bincount(labels, minlength=count))[:-1])
    lows = np.array([part.min(axis=(0, 1)) for part in members])
    highs = np.array([part.max(axis=(0, 1)) for part in members])
    held = np.all(lows[None, :] <= lows[:, None], axis=2)  # [i, j]: i's box inside j's
    held &= np.all(highs[:, None] <= highs[None, :], axis=2)
    np.fill_diagonal(held, False)
    inside: list[list[int]] = [[] for _ in range(count)]
    for i in np.flatnonzero(held.any(axis=1)):
        corners = np.unique(members[i].reshape(-1, 3), axis=0)
        samples = corners[np.linspace(0, len(corners) - 1, SAMPLES).astype(int)]
        for j in np.flatnonzero(held[i]):
            winding = [abs(winding_number(point, members[j])) for point in samples]
            if np.median(winding) > 0.5:
                inside[i].append(int(j))
    return inside


def _describe(part: int, count: int, triangles: Triangles, labels: Labels, volume: float) -> str:
    """``part 2 of 3 (12 faces from face 12, volume -0.125 m³, centred at [1.5, 0, 0] m)``."""
    faces = np.flatnonzero(labels == part)
    corners = triangles[faces].reshape(-1, 3)
    centre = ", ".join(f"{x + 0.0:.6g}" for x in (corners.min(0) + corners.max(0)) / 2)
    return (
        f"part {part + 1} of {count} ({len(faces)} faces from face {faces[0]}, "
        f"volume {volume + 0.0:.6g} m³, centred at [{centre}] m)"
    )


def oriented(
    triangles: ArrayLike,
    faces: NDArray[np.integer],
    *,
    name: str,
    value: object,
    fix_inside_out: bool = False,
    fix_hint: str = ", or pass fix_inside_out=True",
) -> Triangles:
    """The mesh's triangles, each part wound to bound a solid (module docstring): outward
    at even nesting depth, inward (a cavity) at odd depth.

    A part wound the other way is refused (the ValueError names ``name``, ``value``, the part
    and how to flip it, then ``fix_hint``), or flipped with a warning if ``fix_inside_out``.
    A part that encloses no volume is refused.
    """
    triangles = np.array(triangles, dtype=float)
    labels = part_labels(faces)
    size = np.max(np.ptp(triangles.reshape(-1, 3), axis=0)) or np.float64(1.0)
    unit = (triangles - triangles[0, 0]) / size  # at any scale, without overflow
    signed = signed_volumes(unit, labels)
    with np.errstate(over="ignore"):
        volumes = signed * size**3  # in m³, for the messages
    count = len(volumes)
    flat = np.abs(signed) <= FLAT_RTOL * swept_volumes(unit, labels)
    if np.any(flat):
        part = int(np.argmax(flat))
        where = "it" if count == 1 else "its " + _describe(part, count, triangles, labels, 0.0)
        raise fail(
            name, value, "a solid of nonzero volume",
            remedy=f"{where} encloses no volume ({volumes[part] + 0.0:.3g} m³: its faces "
            "lie in one plane, or fold onto each other)",
        )  # fmt: skip
    inside = enclosing(unit, labels) if count > 1 else [[]]
    wrong = [k for k in range(count) if (signed[k] > 0) != (len(inside[k]) % 2 == 0)]
    if not wrong:
        return triangles
    if count == 1:
        reasons = [f"is inside-out (volume {volumes[0]:.6g} < 0)"]
    else:
        reasons = [
            f"{_describe(k, count, triangles, labels, volumes[k])} {_wrong_way(inside[k])}"
            for k in wrong
        ]
    if not fix_inside_out:
        raise fail(
            name, value,
            "outward-oriented" + ("" if count == 1 else " (parts wound outward, cavities inward)"),
            remedy=("it " if count == 1 else "its ") + reasons[0] + "; flip "
            + ("it with mesh.invert()" if count == 1 else "that part") + fix_hint,
        )  # fmt: skip
    warnings.warn(f"mesh {'; '.join(reasons)}: flipped", UserWarning, 3)
    for k in wrong:
        triangles[labels == k] = triangles[labels == k][:, ::-1]
    return triangles


def _wrong_way(inside: list[int]) -> str:
    """Why a part at nesting depth ``len(inside)`` is wound the wrong way."""
    depth = len(inside)
    if depth == 0:
        return "is inside-out and lies inside no other part, so it is not a cavity"
    named = [str(j + 1) for j in inside[:3]] + ["..."] * (depth > 3)
    parts = f"part {named[0]}" if depth == 1 else f"{depth} parts ({', '.join(named)})"
    if depth % 2:
        return f"lies inside {parts} but is wound outward; there it is a cavity, wound inward"
    return f"lies inside {parts} but is wound inward; there it is an island, wound outward"
