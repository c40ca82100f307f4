"""A progress bar over simulated time (rich), or nothing."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager


@contextmanager
def progress_bar(enabled: bool, t0: float, t_end: float) -> Iterator[Callable[[float], None]]:
    """Yield ``advance(t)``, which moves a bar from ``t0`` to ``t_end`` when ``enabled``."""
    if not enabled:
        yield lambda t: None
        return
    from rich.progress import Progress

    with Progress(transient=True) as bar:
        task = bar.add_task("simulating", total=t_end - t0)
        yield lambda t: bar.update(task, completed=t - t0)
