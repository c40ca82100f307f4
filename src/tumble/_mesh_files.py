"""Mesh files: what trimesh's readers need checked before and done after.

:func:`tumble.meshes.load` reads with trimesh, but first refuses a file that is not of its
format in words (trimesh would raise a parser's error, or an ImportError of an optional
module it uses to guess a text encoding), and afterwards merges the repeated vertices itself
(trimesh's merge overflows past about 9e10 m and collapses the mesh).
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tumble._checks import fail

if TYPE_CHECKING:
    import trimesh


def merged(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """``mesh`` with vertices closer than trimesh's ``tol.merge`` (1e-8 m) per coordinate merged.

    trimesh's own merge rounds ``vertex / tol.merge`` to int64, which overflows past about
    9e10 m and collapses the mesh to one vertex; rounding in floating point does not (past
    that size the rounding is a no-op and equal vertices merge exactly).
    """
    import trimesh

    with np.errstate(over="ignore"):
        scaled = mesh.vertices / trimesh.tol.merge
    keys = np.where(np.isfinite(scaled), np.round(scaled), mesh.vertices) + 0.0  # -0.0 -> 0.0
    order = np.lexsort(keys.T[::-1])  # np.unique(axis=0) does this 4x slower
    ordered = keys[order]
    new = np.r_[True, np.any(ordered[1:] != ordered[:-1], axis=1)]
    inverse = np.empty(len(keys), dtype=np.int64)
    inverse[order] = np.cumsum(new) - 1
    return trimesh.Trimesh(mesh.vertices[order[new]], inverse[mesh.faces], process=False)


def check_text(file: Path, path: str | PathLike[str], file_type: str) -> None:
    """Refuse a file of a text format whose bytes are not UTF-8 (trimesh would guess the
    encoding with an optional module, and fail for want of it)."""
    try:
        file.read_bytes().decode("utf-8")
    except UnicodeDecodeError as error:
        byte = error.object[error.start]
        raise fail(
            "path", str(path), f"a text {file_type} file",
            remedy=f"its byte {error.start} (0x{byte:02x}) is not UTF-8 text, which "
            f"{file_type} files are",
        ) from None  # fmt: skip


def check_stl(file: Path, path: str | PathLike[str]) -> None:
    """Refuse a file that is neither ASCII STL (text starting ``solid``) nor binary STL (an
    80-byte header, a triangle count n, then 50 bytes per triangle: 84 + 50 n bytes)."""
    size = file.stat().st_size
    with open(file, "rb") as handle:
        head = handle.read(84)
    if head[:5].lower() == b"solid":
        try:
            head.decode("ascii")
            return
        except UnicodeDecodeError:
            pass  # a binary file whose header starts with "solid": check it as binary
    count = int.from_bytes(head[80:84], "little") if len(head) == 84 else -1
    if count >= 0 and size == 84 + 50 * count:
        return
    raise fail(
        "path", str(path), "an STL file",
        remedy=f"it is neither ASCII STL (text starting 'solid') nor binary STL (84 + 50 n "
        f"bytes for n triangles: this file has {size} bytes and its header says n = {count})",
    )  # fmt: skip
