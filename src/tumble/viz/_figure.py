"""Shared matplotlib set-up: figures on the Agg canvas, without pyplot's global state.

matplotlib is imported only when a picture is drawn, and no backend is switched: each figure
gets its own Agg canvas, so drawing works headless and leaves the caller's pyplot alone.
"""

from __future__ import annotations

from pathlib import Path

from tumble._atomic import atomic_write

DPI = 110


def new_figure(rows: int = 1, cols: int = 1, *, figsize=None, layout=None, **kwargs):
    """A figure on its own Agg canvas and its axes (``Figure.subplots(rows, cols, **kwargs)``)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout=layout)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(rows, cols, **kwargs)


def save(fig, path: str | Path, *, dpi: int = DPI, tight: bool = True) -> None:
    """Write ``fig`` to ``path`` (format from the suffix), whole or not at all."""
    bbox = "tight" if tight else None
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=dpi, bbox_inches=bbox))
