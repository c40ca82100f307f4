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


log = logging.getLogger("tumble.compile")
"""Where the word of a kernel compiling goes: at INFO, shown on stderr unless the program has
handlers of its own (:class:`Notice`). ``logging.getLogger("tumble.compile").setLevel(
logging.WARNING)`` silences it."""


class Notice(logging.Handler):
    """Writes a record to the current ``sys.stderr`` when no other handler would take it.

    What :data:`logging.lastResort` does for warnings, for the compile notices: a script, a
    REPL or a notebook (whose cells show ``sys.stderr``) sees one line, ``tumble: preparing
    …``; a program that configured logging (a handler on ``tumble`` or the root, as the
    command line's status line or pytest) gets the record through its own handlers only
    (``tumble``'s own :class:`logging.NullHandler` does not count).
    """

    def emit(self, record: logging.LogRecord) -> None:
        logger: logging.Logger | None = logging.getLogger(record.name)
        while logger is not None:
            if any(
                handler is not self and not isinstance(handler, logging.NullHandler)
                for handler in logger.handlers
            ):
                return
            if not logger.propagate:
                break
            logger = logger.parent
        import sys

        try:
            print(f"tumble: {record.getMessage()}", file=sys.stderr, flush=True)
        except (OSError, ValueError):  # a closed stderr: nothing to tell
            pass


if not any(isinstance(handler, Notice) for handler in log.handlers):
    log.addHandler(Notice())
if log.level == logging.NOTSET:
    log.setLevel(logging.INFO)


def announce_compilation(kernel: Any, what: str) -> None:
    """Say, at INFO on ``tumble.compile``, that ``kernel``'s first call in this process will
    compile it or load it from numba's cache.

    A numba dispatcher with no signatures yet compiles on its first call: seconds to tens of
    seconds the first time after installation (15 s measured for ``simulate_batch``'s loop
    of ``rkmk4`` on a shared 2-core machine), then one to two seconds in a new process to
    load it from numba's cache (``cache=True``). Shown on stderr by default (:class:`Notice`);
    the command line shows it as its status line. The test is the dispatcher's ``overloads``
    dict, not ``signatures`` (which builds a list of types at every call: 5.6 µs measured, a
    tenth of a short run).
    """
    if not getattr(kernel, "overloads", True):
        log.info(
            "preparing %s (numba: compiled on the first call after installation, 5-30 s; "
            "loaded from its cache after, about 2 s)",
            what,
        )
