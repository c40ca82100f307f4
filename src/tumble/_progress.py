"""Feedback on long work: a transient progress bar (rich), and word of a kernel compiling."""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any


@contextmanager
def progress_bar(enabled: bool, total: float, description: str) -> Iterator[Callable[..., None]]:
    """Yield ``update(completed=…, advance=…)``, moving a bar towards ``total`` when ``enabled``.

    ``completed`` sets how much is done, ``advance`` adds to it (rich's ``Progress.update``);
    when not ``enabled`` the update does nothing and rich is not imported.
    """
    if not enabled:
        yield lambda **_: None
        return
    from rich.progress import Progress

    with Progress(transient=True) as bar:
        task = bar.add_task(description, total=total)
        yield lambda **done: bar.update(task, **done)


log = logging.getLogger("tumble")


def announce_compilation(kernel: Any, what: str) -> None:
    """Log, at INFO, that ``kernel``'s first call in this process will compile it.

    A numba dispatcher with no signatures yet compiles on its first call: about 10 s the first
    time after installation, then a fraction of a second to load it from numba's cache
    (``cache=True``). The command line shows the message as its status line.
    """
    if not getattr(kernel, "signatures", True):
        log.info(
            "preparing %s, compiled by numba (about 10 s the first time; later runs load it "
            "from its cache)",
            what,
        )
