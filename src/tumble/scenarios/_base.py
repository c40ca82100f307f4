"""What a scenario is: a function that computes, and a result that knows how to be written.

A built-in scenario is a module in :mod:`tumble.scenarios` with

* ``NAME`` — the name used on the command line (``tumble run NAME``),
* ``SUMMARY`` — one line for ``tumble list``,
* ``run(**options) -> ScenarioResult`` — pure computation, no files, no printing.

The result carries the headline numbers (``summary``, JSON-serialisable), the arrays a
reader may want (``data``), and the figures as ``(file name, writer)`` pairs; a writer is a
callable that takes a path and draws one file there (the drawing lives in :mod:`tumble.viz`).
:func:`tumble.io.write_run_folder` turns a result into a run folder.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

FigureWriter = Callable[[Path], None]


@dataclass
class ScenarioResult:
    """The outcome of one scenario run.

    Attributes
    ----------
    name : str
        The scenario's name.
    summary : dict
        Headline numbers and settings, JSON-serialisable (written to ``summary.json``).
    data : dict
        Arrays and objects (trajectories, datasets) for further use; not written as-is.
    figures : list of (str, callable)
        ``(file_name, writer)`` pairs; ``writer(path)`` draws the file at ``path``.
    """

    name: str
    summary: dict[str, Any]
    data: dict[str, Any] = field(default_factory=dict)
    figures: list[tuple[str, FigureWriter]] = field(default_factory=list)
