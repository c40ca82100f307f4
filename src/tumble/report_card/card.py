"""The card: everything measured for each row, the structural table and the machine."""

from __future__ import annotations

import logging
import math
import os
import platform
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tumble._version import __version__
from tumble.report_card.cost import fixed_cost, warm_cost
from tumble.report_card.measure import (
    Invariants,
    Order,
    Study,
    adaptive_order,
    contradictions,
    error_at,
    invariants,
    measured_order,
    study_row,
)
from tumble.report_card.peers import Row
from tumble.report_card.problems import CardProblem
from tumble.report_card.structural import StructuralRow

log = logging.getLogger(__name__)


@dataclass
class RowResult:
    """Everything measured for one row."""

    row: Row
    order: Order
    sweeps: dict[str, Study]
    errors: dict[str, float]  # problem -> error at T at the standard setting
    free: Invariants
    forced: Invariants | None
    cost_us: float
    first_call_s: float
    contradictions: list[str]
    fixed_us: float = math.nan  # the fixed cost of one call, µs (a run of one step)


@dataclass
class ReportCard:
    """The report: the rows, the structural table, the machine, and the flagged methods."""

    results: list[RowResult]
    structural: list[StructuralRow]
    structural_setup: dict
    machine: dict
    quick: bool
    long_t: float
    seconds: float
    first_call_note: str
    problems: list[str]
    skipped: dict[str, str] = field(default_factory=dict)  # peer rows left out, and why

    @property
    def contradictions(self) -> dict[str, list[str]]:
        """Each flagged row's contradictions, by name."""
        return {r.row.name: r.contradictions for r in self.results if r.contradictions}

    @property
    def title(self) -> str:
        """``tumble report card``, with ``(quick)`` for a quick one."""
        return f"tumble report card{' (quick)' if self.quick else ''}"


def measure_row(row: Row, tests: list[CardProblem], references: dict[str, np.ndarray],
                long_t: float, repeat: int, first: dict[str, float]) -> RowResult:  # fmt: skip
    """Measure ``row`` on ``tests`` (P1 first, the forced body last) against ``references``:
    its sweeps, order, errors at T, long-run invariants, cost and contradictions."""
    log.info("report card: measuring %s", row.name)
    p1, forced = tests[0], tests[-1]
    fixed = fixed_cost(row, p1)
    free_sweep = study_row(row, p1, references[p1.name], repeat, fixed)
    assert free_sweep is not None
    forced_sweep = study_row(row, forced, references[forced.name], repeat, fixed)
    sweeps = {data.problem: data for data in (free_sweep, forced_sweep) if data is not None}
    if row.adaptive:  # the order of the formula it propagates, at fixed steps
        order = adaptive_order(row, free_sweep, references[p1.name], p1)
    else:
        order = measured_order(row, free_sweep, forced_sweep)
    errors = {problem.name: error_at(row, problem, references[problem.name])
              for problem in tests}  # fmt: skip
    free_inv = invariants(row, p1, long_t)
    assert free_inv is not None
    forced_inv = invariants(row, forced, long_t)
    cost = warm_cost(row, p1, repeat)
    found = contradictions(row, order, free_inv, forced_inv)
    return RowResult(row, order, sweeps, errors, free_inv, forced_inv, cost,
                     float(first.get(row.name, math.nan)), found, fixed * 1e6)  # fmt: skip


def machine() -> dict:
    """Where the report ran: CPU, cores, Python, numpy, numba, tumble, date."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    import numba
    import scipy

    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "system": f"{platform.system()} {platform.release()}",
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "numba": numba.__version__,
        "tumble": __version__,
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
    }
