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

    The file gets the mode an ordinary ``open(path, "w")`` would give it, ``0o666`` less the
    process umask (``mkstemp`` makes its temporary ``0o600``, which would keep colleagues and
    web servers from reading a run folder).

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
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path


def _umask() -> int:
    """The process umask (read by setting it and setting it back: POSIX has no getter)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask
