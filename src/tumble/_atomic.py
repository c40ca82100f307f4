"""Files written whole or not at all: write a temporary sibling, then rename it."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from os import PathLike
from pathlib import Path


def atomic_write(path: str | PathLike[str], writer: Callable[[Path], object]) -> Path:
    """Call ``writer(tmp)`` on a temporary sibling of ``path``, then rename it to ``path``.

    The temporary file (``.NAME.XXXX.partial.SUFFIX`` in the same folder, unique per call, so
    two writers of one target do not clobber each other) keeps the suffix — writers such as
    matplotlib read the format from it — and is removed if ``writer`` raises. ``os.replace``
    is atomic on POSIX: readers see the old file or the new one, never half of one.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    handle, name = tempfile.mkstemp(
        dir=path.parent, prefix=f".{path.stem}.", suffix=f".partial{path.suffix}"
    )
    os.close(handle)
    tmp = Path(name)
    try:
        writer(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path
