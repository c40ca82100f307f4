"""Triangle meshes (trimesh) of the primitive solids, and mesh files in and out.

Every generator returns a closed (watertight), consistently and outward-wound
``trimesh.Trimesh`` whose vertices lie on the exact surface, so its mass properties
(:func:`from_mesh`) converge to the closed forms of :mod:`tumble.mass` as the section count
grows, with error ∝ 1/sections². They replace the seeds' ``torus.stl`` and
``Prism_hexagon.stl``, which are not available. ``axis`` and ``center`` mean what they mean
in :mod:`tumble.mass`. trimesh is imported inside the functions, on first use.
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from tumble import _checks, _mesh_files, _parts
from tumble._atomic import atomic_write
from tumble.mass import (
    MassProperties,
    axis_vector,
    rotation_matrix,
    validate_point,
    validate_torus_radii,
)

if TYPE_CHECKING:
    import trimesh

DEFAULT_SECTIONS = 64
"""Default number of sections around a circle (torus both ways, cylinder)."""
LOAD_FORMATS = ("glb", "gltf", "obj", "off", "ply", "stl")
"""File extensions :func:`load` accepts (trimesh's triangle-mesh readers)."""
SAVE_FORMATS = ("glb", "obj", "off", "ply", "stl")
"""File extensions :func:`save` writes (trimesh's mesh exporters)."""
TEXT_FORMATS = ("gltf", "obj", "off")
"""Formats that are text: a file of one whose bytes are not UTF-8 is refused as such."""
FACE_BYTES = 256
"""Memory a generated triangle takes, with margin: trimesh's peak resident memory measured
127–132 bytes a face for a 1.3·10⁶-face icosphere and a 2·10⁶-face torus."""


def _max_faces() -> int:
    """The most triangles a generator makes: what fits in half this machine's memory."""
    return int(0.5 * _checks.memory() / FACE_BYTES)


def _faces(name: str, value: object, minimum: int, faces_per_unit: int, other: int = 1) -> int:
    """A section count checked: an integer >= ``minimum`` whose mesh of about
    ``faces_per_unit · value · other`` triangles fits in memory (:func:`_max_faces`)."""
    limit = max(minimum, _max_faces() // (faces_per_unit * other))
    return _checks.count(name, value, minimum, limit,
                         remedy=f"more would need over {_max_faces():.3g} triangles")  # fmt: skip


def _finite_mesh(mesh: trimesh.Trimesh, sizes: dict[str, float]) -> trimesh.Trimesh:
    """``mesh``, or the ValueError naming the size (of ``sizes``) furthest from 1 when a
    vertex coordinate overflowed (or an edge underflowed to a point)."""
    with np.errstate(all="ignore"):
        extents = mesh.extents  # None for a mesh whose vertices all merged
        good = np.count_nonzero(np.isfinite(mesh.vertices)) == mesh.vertices.size
        good = good and extents is not None and bool(np.all(extents > 0)) and mesh.is_watertight
    if good:
        return mesh
    name = max(sizes, key=lambda key: abs(np.log10(sizes[key])))
    raise _checks.fail(name, sizes[name], "a size whose mesh has finite, distinct vertices", "m",
                       remedy="past ~1e154 m (or below ~1e-154 m) the vertices overflow or "
                       "collapse; give the body in other units")  # fmt: skip


def _placement(axis: str | ArrayLike, center: ArrayLike) -> np.ndarray:
    """4×4 transform taking the mesh's local z axis to ``axis`` and its origin to ``center``."""
    import trimesh

    transform = trimesh.geometry.align_vectors([0.0, 0.0, 1.0], axis_vector(axis))
    transform[:3, 3] = validate_point(center, name="center")
    return transform


def torus(
    major_radius: float,
    minor_radius: float,
    sections: int = DEFAULT_SECTIONS,
    *,
    minor_sections: int | None = None,
    axis: str | ArrayLike = "z",
    center: ArrayLike = (0.0, 0.0, 0.0),
) -> trimesh.Trimesh:
    """Ring torus: ``sections`` around the axis, ``minor_sections`` around the tube.

    Parameters
    ----------
    major_radius, minor_radius : float
        ``R`` and ``r`` (m), ``0 < r < R``.
    sections : int
        Sections around the symmetry axis, >= 3.
    minor_sections : int, optional
        Sections around the tube; defaults to ``sections``.
    axis, center
        Symmetry axis and centre (m), as in :func:`tumble.mass.torus`.

    Returns
    -------
    trimesh.Trimesh
        ``2 · sections · minor_sections`` triangles.

    Examples
    --------
    >>> round(float(torus(1.0, 0.5, 64).volume), 4)  # exact 2π²Rr² = 4.9348
    4.919
    """
    import trimesh

    R, r = validate_torus_radii(major_radius, minor_radius)
    n = _faces("sections", sections, 3, 2, 3)
    k = n if minor_sections is None else _faces("minor_sections", minor_sections, 3, 2, n)
    if minor_sections is None and 2 * n * n > _max_faces():
        raise _checks.fail("sections", sections, f"at most {int((_max_faces() / 2) ** 0.5)} "
                           "when minor_sections is None (n² triangles)")  # fmt: skip
    with np.errstate(all="ignore"):
        mesh = trimesh.creation.torus(
            R, r, major_sections=n, minor_sections=k, transform=_placement(axis, center)
        )
    return _finite_mesh(mesh, {"major_radius": R, "minor_radius": r})


def cylinder(
    radius: float,
    length: float,
    sections: int = DEFAULT_SECTIONS,
    *,
    axis: str | ArrayLike = "z",
    center: ArrayLike = (0.0, 0.0, 0.0),
) -> trimesh.Trimesh:
    """Solid cylinder as a prism with ``sections`` sides inscribed in the circle.

    Examples
    --------
    >>> mesh = cylinder(1.0, 2.0, 8, axis="x")
    >>> mesh.is_watertight, mesh.extents.round(6).tolist()
    (True, [2.0, 2.0, 2.0])
    """
    import trimesh

    a = _checks.positive("radius", radius, "m")
    L = _checks.positive("length", length, "m")
    n = _faces("sections", sections, 3, 4)
    with np.errstate(all="ignore"):
        mesh = trimesh.creation.cylinder(
            radius=a, height=L, sections=n, transform=_placement(axis, center)
        )
    return _finite_mesh(mesh, {"radius": a, "length": L})


def hex_prism(
    circumradius: float,
    length: float,
    *,
    axis: str | ArrayLike = "z",
    center: ArrayLike = (0.0, 0.0, 0.0),
) -> trimesh.Trimesh:
    """Regular hexagonal prism (exact): a six-sided :func:`cylinder`, one vertex on local x.

    Examples
    --------
    >>> bool(np.isclose(hex_prism(1.0, 1.0).volume, 1.5 * np.sqrt(3.0), rtol=1e-14))
    True
    """
    a = _checks.positive("circumradius", circumradius, "m")
    L = _checks.positive("length", length, "m")
    try:
        return cylinder(a, L, 6, axis=axis, center=center)
    except ValueError as error:  # named as the cylinder's radius: name it as given here
        raise ValueError(str(error).replace("radius=", "circumradius=", 1)) from None


def box(
    extents: ArrayLike,
    *,
    rotation: ArrayLike | None = None,
    center: ArrayLike = (0.0, 0.0, 0.0),
) -> trimesh.Trimesh:
    """Rectangular box (exact) of edge lengths ``extents`` (m), turned by ``rotation``.

    Examples
    --------
    >>> round(float(box([1.0, 2.0, 3.0]).volume), 12)
    6.0
    """
    import trimesh

    sides = _checks.array("extents", extents, shape=(3,), unit="m", positive=True)
    transform = np.eye(4)
    if rotation is not None:
        transform[:3, :3] = rotation_matrix(rotation, "rotation")
    transform[:3, 3] = validate_point(center, name="center")
    with np.errstate(all="ignore"):
        mesh = trimesh.creation.box(extents=sides, transform=transform)
    return _finite_mesh(mesh, {f"extents[{i}]": float(side) for i, side in enumerate(sides)})


def sphere(
    radius: float, subdivisions: int = 4, *, center: ArrayLike = (0.0, 0.0, 0.0)
) -> trimesh.Trimesh:
    """Icosphere: an icosahedron subdivided ``subdivisions`` times (20·4^s triangles).

    Examples
    --------
    >>> len(sphere(1.0, 2).faces)
    320
    """
    import trimesh

    a = _checks.positive("radius", radius, "m")
    most = max(0, int(np.log(max(_max_faces() / 20, 1)) / np.log(4)))  # 20·4^s triangles
    subdivisions = _checks.count("subdivisions", subdivisions, 0, most,
                                 remedy=f"{most + 1} would make over {_max_faces():.3g} "
                                 "triangles")  # fmt: skip
    with np.errstate(all="ignore"):
        mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=a)
        mesh = mesh.apply_translation(validate_point(center, name="center"))
    return _finite_mesh(mesh, {"radius": a})


def t_handle(sections: int = DEFAULT_SECTIONS) -> trimesh.Trimesh:
    """Seed 002's T-handle (:func:`tumble.mass.t_handle` defaults) as two cylinder meshes.

    The handle (R = 1 cm, L = 8 cm, axis y, centre x = −1 cm) and the shaft (R = 1 cm,
    L = 4 cm, axis x, centre x = +2 cm) touch along a line at x = 0 without overlapping, so
    the two closed parts are kept as one mesh of two bodies (no boolean union); its mass
    properties are the sum of the parts'.

    Examples
    --------
    >>> mesh = t_handle(16)
    >>> mesh.is_watertight, mesh.body_count
    (True, 2)
    """
    import trimesh

    sections = _faces("sections", sections, 3, 8)
    handle = cylinder(0.01, 0.08, sections, axis="y", center=(-0.01, 0.0, 0.0))
    shaft = cylinder(0.01, 0.04, sections, axis="x", center=(0.02, 0.0, 0.0))
    return trimesh.util.concatenate([handle, shaft])  # type: ignore[return-value]  # annotated Geometry


def validate_solid(mesh: object, *, name: str = "mesh") -> trimesh.Trimesh:
    """Return ``mesh`` if it is a closed, consistently wound triangle mesh.

    Closed means watertight (every edge shared by exactly two faces); consistent winding
    means neighbouring faces agree on which side is out. Orientation (outward or inside-out,
    the sign of ``mesh.volume``) is left to the caller.

    Raises
    ------
    ValueError
        Naming ``name``, what is wrong and a trimesh repair to try.

    Examples
    --------
    >>> validate_solid(box([1.0, 1.0, 1.0])).is_watertight
    True
    """
    import trimesh

    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise _checks.fail(name, mesh, "a trimesh.Trimesh with faces or a mesh file path")
    _check_finite(mesh, name, mesh, "a mesh with finite vertex coordinates")
    if not mesh.is_watertight:
        distinct = 1 + np.count_nonzero(np.diff(np.sort(mesh.faces, axis=1)), axis=1)
        collapsed = np.flatnonzero(distinct < 3)
        remedy = "it is open; repair it, e.g. trimesh.repair.fill_holes(mesh)"
        if len(collapsed):
            k = collapsed[0]
            remedy = (
                f"face {k} has {distinct[k]} distinct vertices ({len(collapsed)} faces "
                "collapsed): trimesh's merge collapses vertices past about 9e10 m; build the "
                "mesh with trimesh.Trimesh(vertices, faces, process=False), or in other units"
            )
        raise _checks.fail(name, mesh, "a closed (watertight) surface", remedy=remedy)
    if not mesh.is_winding_consistent:
        raise _checks.fail(
            name,
            mesh,
            "a mesh with consistently wound faces",
            remedy="repair it, e.g. trimesh.repair.fix_winding(mesh)",
        )
    return mesh


def _suffix(path: Path, formats: tuple[str, ...], name: str) -> str:
    suffix = path.suffix.lower().lstrip(".")
    if suffix not in formats:
        raise _checks.fail(
            name, str(path), f"a file name ending in one of {', '.join('.' + f for f in formats)}"
        )
    return suffix


def load(path: str | PathLike[str]) -> trimesh.Trimesh:
    """Read a triangle mesh from a file (STL, OBJ, PLY, OFF, GLB, ... as trimesh reads).

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    trimesh.Trimesh
        Vertices closer than 1e-8 m merged (as trimesh's ``process=True`` merges them, but
        without its integer overflow past 9e10 m), so a closed STL is watertight.

    Raises
    ------
    ValueError
        If the file does not exist, has an unknown extension, cannot be parsed, holds no
        triangles, or has a NaN or infinite coordinate; the message names ``path`` and what
        is allowed.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = pathlib.Path(folder) / "box.stl"
    ...     _ = save(box([1.0, 2.0, 3.0]), path)
    ...     print(round(float(load(path).volume), 9))
    6.0
    """
    return _load(path, "path")


def _load(path: str | PathLike[str], name: str) -> trimesh.Trimesh:
    """:func:`load`, its messages naming the argument ``name``."""
    import trimesh

    file = _checks.path(name, path, "a mesh file")
    if not file.is_file():
        raise _checks.fail(name, str(path), "an existing mesh file", remedy="not found")
    file_type = _suffix(file, LOAD_FORMATS, name)
    try:
        if file_type == "stl":
            _mesh_files.check_stl(file, path)
        elif file_type in TEXT_FORMATS:
            _mesh_files.check_text(file, path, file_type)
    except ValueError as error:  # _mesh_files names the file "path"
        raise ValueError(str(error).replace("path=", f"{name}=", 1)) from None
    try:
        mesh = trimesh.load_mesh(file, file_type=file_type, process=False)
    except Exception as error:  # trimesh raises many types for a bad file
        cause = (
            "the reader needs an optional module that is missing"  # never an ImportError
            if isinstance(error, ImportError)
            else str(error)
        )
        raise _checks.fail(
            name, str(path), f"a readable {file_type} mesh file", remedy=f"reading it: {cause}"
        ) from error
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise _checks.fail(
            name,
            str(path),
            "a mesh file with triangles",
            remedy=f"it has none (empty or not a {file_type} file)",
        )
    _check_finite(mesh, name, str(path), "a mesh file with finite vertex coordinates")
    return _mesh_files.merged(mesh)


def _check_finite(mesh: trimesh.Trimesh, name: str, value: object, allowed: str) -> None:
    """Refuse a mesh with a NaN or infinite coordinate, naming the first such vertex."""
    bad = ~np.all(np.isfinite(mesh.vertices), axis=1)
    if np.any(bad):
        index = int(np.argmax(bad))
        corner = ", ".join(f"{x:g}" for x in mesh.vertices[index])
        raise _checks.fail(name, value, allowed, remedy=f"vertex {index} is [{corner}]")


def save(mesh: trimesh.Trimesh, path: str | PathLike[str]) -> Path:
    """Write ``mesh`` to ``path``; the format follows the extension (.stl, .obj, .ply, ...).

    The file is written to a temporary name in the same folder and then renamed, so it
    appears complete or not at all.

    Returns
    -------
    pathlib.Path
        The path written.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     print(save(box([1.0, 1.0, 1.0]), pathlib.Path(folder) / "cube.stl").name)
    cube.stl
    """
    import trimesh

    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise _checks.fail("mesh", mesh, "a trimesh.Trimesh with faces")
    file = _checks.path("path", path, "a mesh file to write")
    file_type = _suffix(file, SAVE_FORMATS, "path")
    if not file.parent.is_dir():
        raise _checks.fail("path", str(path), "a file in an existing folder")
    return atomic_write(file, lambda temporary: mesh.export(temporary, file_type=file_type))


def from_mesh(
    mesh_or_path: trimesh.Trimesh | str | PathLike[str],
    *,
    density: float,
    fix_inside_out: bool = False,
) -> MassProperties:
    """Mass properties of a closed triangle mesh of uniform ``density`` (kg/m³).

    Uses trimesh's exact polyhedral integrals (Eberly, *Polyhedral Mass Properties*); the
    inertia is about the centre of mass, in the mesh's axes. The mesh must be closed
    (watertight) and consistently wound, enclose a nonzero volume, and its mass properties
    must be finite floats.

    A mesh may have several connected parts. Each is checked by its signed volume and its
    nesting (``tumble._parts``): a part wound inward that lies inside another is a cavity,
    and its volume is subtracted; a part wound outward inside a cavity is an island. A part
    wound the other way (an inside-out part lying inside no other, or a cavity wound outward)
    is refused, naming it, unless ``fix_inside_out=True``: then its faces are flipped (on a
    copy) with a ``UserWarning``.

    Parameters
    ----------
    mesh_or_path : trimesh.Trimesh or path
        A mesh, or a file that :func:`load` reads (STL, OBJ, PLY, ...).
    density : float
        Density (kg/m³), > 0.
    fix_inside_out : bool
        Flip an inside-out mesh instead of refusing it.

    Returns
    -------
    MassProperties

    Examples
    --------
    >>> round(from_mesh(box([1.0, 2.0, 3.0]), density=2.0).mass, 12)
    12.0
    """
    import trimesh

    rho = _checks.positive("density", density, "kg/m³")
    fix_inside_out = _checks.flag("fix_inside_out", fix_inside_out)
    given = str(mesh_or_path) if isinstance(mesh_or_path, PathLike) else mesh_or_path
    if isinstance(mesh_or_path, (str, PathLike)):
        mesh_or_path = _load(mesh_or_path, "mesh_or_path")
    mesh = validate_solid(mesh_or_path, name="mesh_or_path")
    triangles = _parts.oriented(
        mesh.triangles, mesh.faces, name="mesh_or_path", value=given, fix_inside_out=fix_inside_out
    )
    with np.errstate(all="ignore"):  # an overflow is refused below, by name
        props = trimesh.triangles.mass_properties(triangles, density=rho)
    inertia = np.asarray(props.inertia)
    if not (np.isfinite(props.mass) and np.all(np.isfinite(inertia))):
        raise _checks.fail(
            "mesh_or_path", given, "a mesh whose mass properties are finite floats",
            remedy=f"with density={rho:g} kg/m³ and coordinates up to "
            f"{np.max(np.abs(triangles)):.3g} m they overflow; give it in other units",
        )  # fmt: skip
    return MassProperties(props.mass, props.center_mass, inertia)
