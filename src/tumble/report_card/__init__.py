"""The integrator report card: every rigid-body method measured the same way, peers beside it.

:func:`report` runs every method of :data:`tumble.rigid.METHODS` — it has no list of its own,
so a method added there appears here — and the peers (scipy's ``DOP853`` and ``RK45`` on
Euler's equations with a quaternion, MuJoCo's ``RK4`` and ``Euler`` when the ``bench`` extra
is installed) through one harness (:func:`tumble.exact.study`), on the same problems. Its
modules, each importing only those listed after it:

=====================  ====================================================================
module                 what lives there
=====================  ====================================================================
``write``              ``report.md`` (a function per section), ``report.html``, ``report.nc``
``card``               :class:`ReportCard`: everything measured for a row; the machine
``structural``         the structural schemes' table on a small cantilever
``cost``               warm µs per step; the first call's time in a fresh process
``measure``            order (fitted by :func:`tumble.exact.fit_order`), error at T,
                       invariants over a long run, and the contradictions
``peers``              the rows (tumble's methods and the peers) and one run of a row
``problems``           P1, the T-handle's spins, the near-separatrix spin, the forced body,
                       and their references
=====================  ====================================================================

For each method it measures

* the **order**: the slope ``p`` of log e against log h on P1 (or the forced body when P1
  is at round-off), fitted through the four finest runs in the asymptotic window; it agrees
  with the declared :attr:`~tumble.rigid.Method.order` when ``|p − order| ≤``
  :data:`ORDER_TOLERANCE` (an adaptive method: the formula it propagates, at fixed steps);
* the **error at T** on every problem at one setting;
* the **invariants over a long run**: the growth law of the energy error (:func:`growth_law`),
  the Casimir, ``max ‖RᵀR − I‖_F`` and ``max ||q| − 1|`` of a carried quaternion;
* the **cost**: warm µs per step, and the first call's time in a fresh process.

A method whose measurements contradict what it declares (order; symplectic, energy-, Casimir-
or SO(3)-preserving: :attr:`~tumble.rigid.Method.conserves`) is listed in
:attr:`ReportCard.contradictions`. :func:`write` writes ``report.md``, ``report.html``
(:mod:`tumble.viz.report_card`) and ``report.nc``, each atomically. The structural schemes
(:data:`tumble.structural.SCHEMES`) get a table of their own (:func:`structural_rows`).

References
----------
E. Hairer, C. Lubich, G. Wanner, Geometric Numerical Integration, 2nd ed., Springer 2006,
§IV.1, §VII.5 (P1), ch. IX (energy of symplectic methods).
"""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Sequence

from tumble import _checks
from tumble._progress import progress_bar
from tumble.report_card.card import ReportCard, RowResult, machine, measure_row
from tumble.report_card.cost import first_call_times, first_calls, warm_cost
from tumble.report_card.measure import (
    ASYMPTOTIC,
    BOUNDED_SLOPE,
    FIT_POINTS,
    FORCED_FLOOR,
    LONG_H,
    LONG_RTOL,
    LONG_SAMPLES,
    ORDER_TOLERANCE,
    ROUND_OFF,
    STANDARD_H,
    STANDARD_RTOL,
    STEP_COUNTS,
    TOLERANCES,
    Invariants,
    Order,
    Study,
    contradictions,
    growth_law,
    invariants,
    study_row,
)
from tumble.report_card.peers import (
    CLAIMS,
    Row,
    Sampled,
    method_row,
    rows,
    run_row,
    skipped_peers,
)
from tumble.report_card.problems import (
    PROBLEM_T,
    SWEEP_T,
    CardProblem,
    attitude_error,
    problems,
    reference,
)
from tumble.report_card.structural import StructuralRow, structural_rows
from tumble.report_card.write import datasets, markdown, plot_data, write

__all__ = [
    "ASYMPTOTIC",
    "BOUNDED_SLOPE",
    "CLAIMS",
    "FIT_POINTS",
    "FORCED_FLOOR",
    "LONG_H",
    "LONG_RTOL",
    "LONG_SAMPLES",
    "ORDER_TOLERANCE",
    "PROBLEM_T",
    "ROUND_OFF",
    "STANDARD_H",
    "STANDARD_RTOL",
    "STEP_COUNTS",
    "SWEEP_T",
    "TOLERANCES",
    "Invariants",
    "Order",
    "CardProblem",
    "ReportCard",
    "Row",
    "RowResult",
    "Sampled",
    "StructuralRow",
    "Study",
    "attitude_error",
    "contradictions",
    "datasets",
    "first_call_times",
    "first_calls",
    "growth_law",
    "invariants",
    "machine",
    "markdown",
    "method_row",
    "plot_data",
    "problems",
    "reference",
    "report",
    "rows",
    "run_row",
    "skipped_peers",
    "structural_rows",
    "study_row",
    "warm_cost",
    "write",
]


def report(
    out: str | os.PathLike[str] | None = None,
    *,
    quick: bool = False,
    methods: Sequence[str] | None = None,
    peers: bool = True,
    structural: bool = True,
    progress: bool = False,
) -> ReportCard:
    """Measure every rigid-body method (and the peers) and, with ``out``, write the report.

    Parameters
    ----------
    out : path, optional
        A folder (created if needed) for ``report.md``, ``report.html`` and ``report.nc``;
        None writes nothing.
    quick : bool
        Long runs of 1000 s instead of 10⁴ s, one timed run (after a warm-up) instead of
        the best of three, the first calls timed in one process (under a minute on a
        2-core machine; the full report takes about six).
    methods : sequence of str, optional
        Names from :data:`tumble.rigid.METHODS` (default: all of them).
    peers : bool
        Add scipy's DOP853 and RK45, and MuJoCo's RK4 and Euler when it is installed.
    structural : bool
        Add the structural schemes' table.
    progress : bool
        Show a progress bar (rich).

    Returns
    -------
    ReportCard
        ``contradictions`` lists each method whose measurements contradict its declaration.

    Examples
    --------
    >>> card = report(quick=True, methods=["rkmk4"], peers=False, structural=False)
    >>> result = card.results[0]
    >>> result.order.verdict, round(result.order.measured), card.contradictions
    ('agrees', 4, {})
    """
    started = time.perf_counter()
    quick = _checks.flag("quick", quick)
    chosen = rows(methods, peers=peers)
    long_t = 1000.0 if quick else 10000.0
    repeat = 1 if quick else 3
    tests = problems()
    tumble_names = [row.name for row in chosen if row.source == "tumble"]
    results = []
    timings = [tumble_names] if quick else [[name] for name in tumble_names]
    steps = 1 + len(timings) + len(chosen) + 1
    with progress_bar(progress, steps, "report card: the reference solutions") as update:
        references = {problem.name: reference(problem) for problem in tests}
        update(advance=1)
        first, note = {}, ""
        for k, names in enumerate(timings, start=1):
            what = f"{k} of {len(timings)}" if len(timings) > 1 else "all methods"
            update(description=f"report card: first calls in a fresh process, compiling "
                   f"({what})")  # fmt: skip
            times, note = first_call_times(names, separate=not quick)
            first.update(times)
            update(advance=1)
        with warnings.catch_warnings():  # coarse steps on purpose: their errors are measured
            warnings.simplefilter("ignore", _checks.LargeStepWarning)
            for row in chosen:
                update(description=f"report card: {row.name}")
                results.append(measure_row(row, tests, references, long_t, repeat, first))
                update(advance=1)
        update(description="report card: structural schemes")
        structural_table, setup = structural_rows(quick) if structural else ([], {})
        update(advance=1)
    card = ReportCard(results, structural_table, setup, machine(), quick, long_t,
                      time.perf_counter() - started, note,
                      [problem.name for problem in tests], skipped_peers(peers))  # fmt: skip
    if out is not None:
        write(card, out)
    return card
