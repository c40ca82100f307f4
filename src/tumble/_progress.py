"""A transient progress bar (rich) for long runs, or nothing."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager


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
