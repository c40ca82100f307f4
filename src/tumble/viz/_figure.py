"""Shared matplotlib set-up: the Agg backend, imported only when a picture is drawn."""

from __future__ import annotations

from pathlib import Path


def new_figure(rows: int = 1, cols: int = 1, **kwargs):
    """A figure and its axes on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.subplots(rows, cols, **kwargs)


def save(fig, path: str | Path) -> None:
    """Write ``fig`` to ``path`` (format from the suffix) and free it."""
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
