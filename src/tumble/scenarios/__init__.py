"""Built-in scenarios that reproduce the seeds, by name.

Each scenario is a module with ``NAME``, ``SUMMARY`` and ``run(**options) -> ScenarioResult``
(see :mod:`tumble.scenarios._base`; :class:`ScenarioResult` is :class:`tumble.io.ScenarioResult`).
``tumble run NAME`` runs one and writes its run folder. :func:`names` and :func:`get` are
:mod:`tumble.scenarios.registry`'s; :func:`view_page` (``tumble view``) draws a rigid-body
run's ``view.html`` again from its run folder.
"""

from __future__ import annotations

from tumble.io import ScenarioResult
from tumble.scenarios._base import view_page
from tumble.scenarios.registry import get, names

__all__ = ["ScenarioResult", "get", "names", "view_page"]
