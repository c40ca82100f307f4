"""Feedback on long work: a transient progress bar (rich), and word of a kernel compiling."""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager, nullcontext
from typing import Any


def progress_bar(
    enabled: bool, total: float, description: str
) -> AbstractContextManager[Callable[..., None]]:
    """A context yielding ``update(completed=…, advance=…)``, moving a bar towards ``total``
    when ``enabled``.

    ``completed`` sets how much is done, ``advance`` adds to it (rich's ``Progress.update``);
    when not ``enabled`` the update does nothing, rich is not imported and the context costs
    no more than :class:`contextlib.nullcontext` (a short run pays nothing for its bar).
    """
    if not enabled:
        return nullcontext(_ignore)
    return _bar(total, description)


def _ignore(**_: Any) -> None:
    """The update of a disabled bar."""


@contextmanager
def _bar(total: float, description: str) -> Iterator[Callable[..., None]]:
    from rich.progress import Progress

    with Progress(transient=True) as bar:
        task = bar.add_task(description, total=total)
        yield lambda **done: bar.update(task, **done)


log = logging.getLogger("tumble")


def announce_compilation(kernel: Any, what: str) -> None:
    """Log, at INFO, that ``kernel``'s first call in this process will compile it.

    A numba dispatcher with no signatures yet compiles on its first call: seconds the first
    time after installation (1.8 s for ``simulate``'s loop, more for the batch loops), then a
    fraction of a second to load it from numba's cache
    (``cache=True``). The command line shows the message as its status line. The test is
    the dispatcher's ``overloads`` dict, not ``signatures`` (which builds a list of types at
    every call: 5.6 µs measured, a tenth of a short run).
    """
    if not getattr(kernel, "overloads", True):
        log.info(
            "preparing %s, compiled by numba (a few seconds the first time; later runs load it "
            "from its cache)",
            what,
        )
