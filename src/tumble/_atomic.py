"""Files written whole or not at all: write a temporary sibling, then rename it."""

from __future__ import annotations

import os
import signal
import tempfile
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from os import PathLike
from pathlib import Path

PARTIAL = ".partial"
"""Marks a temporary file: ``.NAME.XXXX.partial.SUFFIX``."""

_writing = threading.local()  # the temporary files this thread's atomic_write calls are filling


def atomic_write(path: str | PathLike[str], writer: Callable[[Path], object]) -> Path:
    """Call ``writer(tmp)`` on a temporary sibling of ``path``, then rename it to ``path``.

    The temporary file (``.NAME.XXXX.partial.SUFFIX`` in the same folder, unique per call, so
    two writers of one target do not clobber each other) keeps the suffix — writers such as
    matplotlib read the format from it — and is removed if ``writer`` raises. ``os.replace``
    is atomic on POSIX: readers see the old file or the new one, never half of one.

    One file gets one temporary: a ``writer`` that itself writes atomically to the ``tmp`` it
    was given (a figure's ``save``) writes straight into it.

    The file gets the mode an ordinary ``open(path, "w")`` would give it, ``0o666`` less the
    process umask (``mkstemp`` makes its temporary ``0o600``, which would keep colleagues and
    web servers from reading a run folder).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        If the folder of ``path`` does not exist or cannot be written.
    """
    path = Path(path)
    active: set[Path] = _active()
    if path in active:
        writer(path)  # already the temporary of an outer atomic_write
        return path
    with _signals_held():  # a Ctrl-C between mkstemp and the try below would leave the file
        try:
            handle, name = tempfile.mkstemp(
                dir=path.parent, prefix=f".{path.stem}.", suffix=f"{PARTIAL}{path.suffix}"
            )
        except OSError as error:
            raise ValueError(
                f"cannot write {str(path)!r}: {error.strerror or error} (its folder must exist "
                "and be writable)"
            ) from None
        os.close(handle)
        tmp = Path(name)
        active.add(tmp)
    try:
        writer(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    finally:
        with _signals_held():
            active.discard(tmp)
            tmp.unlink(missing_ok=True)
    return path


_HELD = {signal.SIGINT, signal.SIGTERM}


@contextmanager
def _signals_held() -> Iterator[None]:
    """Ctrl-C and SIGTERM wait (blocked, then delivered) while the block runs, in the main
    thread on POSIX; elsewhere the block runs as it is."""
    held = (
        hasattr(signal, "pthread_sigmask")
        and threading.current_thread() is threading.main_thread()
    )
    if held:
        before = signal.pthread_sigmask(signal.SIG_BLOCK, _HELD)
    try:
        yield
    finally:
        if held:
            signal.pthread_sigmask(signal.SIG_SETMASK, before)


def stale_partials(folder: Path) -> Iterator[Path]:
    """The temporary files that a killed writer left in ``folder`` (``.NAME.XXXX.partial.*``)."""
    for entry in folder.iterdir():
        if entry.name.startswith(".") and PARTIAL + "." in entry.name + "." and entry.is_file():
            yield entry


def _active() -> set[Path]:
    if not hasattr(_writing, "files"):
        _writing.files = set()
    return _writing.files


def _umask() -> int:
    """The process umask (read by setting it and setting it back: POSIX has no getter)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask
