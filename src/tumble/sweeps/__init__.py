"""Sweeps: one scenario over a grid (or a table) of options, on Dask, into one Zarr store.

==============================  ==============================================================
:func:`sweep`                   run the members on a Dask cluster; return the dataset
:func:`make_plan`               check the grid before any work; the members' tasks
:class:`Plan`                   a checked sweep
:class:`Interrupted`            Ctrl-C during a sweep: the members done (a KeyboardInterrupt)
:mod:`tumble.sweeps.budget`     the store's size, the client's and a task's memory, checked
:mod:`tumble.sweeps.store`      the store's layout, the template, regions, completion flags
:mod:`tumble.sweeps.members`    how a task runs its members (``simulate_batch`` where it can)
==============================  ==============================================================

Dask and Zarr are imported only when a sweep runs.
"""

from __future__ import annotations

from tumble.sweeps.plan import Plan, make_plan
from tumble.sweeps.run import Interrupted, sweep

__all__ = ["Interrupted", "Plan", "make_plan", "sweep"]
