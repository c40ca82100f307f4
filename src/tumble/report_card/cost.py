"""What a row costs: warm µs per step, and the first call's time in a fresh process."""

from __future__ import annotations

import json
import logging
import math
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence

from tumble import exact
from tumble.report_card.measure import STANDARD_H, sampled, standard_setting
from tumble.report_card.peers import Row, run_row
from tumble.report_card.problems import P1_L0, CardProblem, p1_body
from tumble.rigid import METHODS, simulate

log = logging.getLogger(__name__)

_FIRST_CALL = """
import json, sys, time
start = time.perf_counter()
from tumble.report_card.cost import first_calls
print(json.dumps(first_calls(sys.argv[1:], start)))
"""


def first_calls(names: Sequence[str], started: float) -> dict[str, float]:
    """The first ``simulate`` call of each method in this process, s (two steps on P1);
    ``"import"``: the time since ``started`` to import tumble (used in a fresh process)."""
    body = p1_body()
    out = {"import": time.perf_counter() - started}
    for name in names:
        adaptive = METHODS[name].adaptive
        start = time.perf_counter()
        simulate(body, 2e-3, method=name, L0=P1_L0, h=None if adaptive else 1e-3,
                 rtol=1e-3 if adaptive else None)  # fmt: skip
        out[name] = time.perf_counter() - start
    return out


def first_call_times(names: Sequence[str], *, separate: bool) -> tuple[dict[str, float], str]:
    """Time each method's first call in a fresh Python process.

    ``separate``: one process per method with an empty numba cache (the compile time a new
    installation pays); otherwise one process for all, with the cache as it is (the methods
    of one family share a compiled kernel, so only the first of each pays). Returns the
    times and a sentence saying which.
    """
    if not names:
        return {}, ""
    if not separate:
        return _fresh_process(names, None), (
            "first call: one fresh process for all methods in turn, numba's cache as installed "
            "(a method sharing a family kernel with an earlier one pays nothing)"
        )
    times = {}
    for name in names:
        with tempfile.TemporaryDirectory(prefix="tumble-numba-") as cache:
            times.update(_fresh_process([name], cache))
    return times, "first call: a fresh process per method with an empty numba cache (compiles)"


def _fresh_process(names: Sequence[str], cache: str | None) -> dict[str, float]:
    env = dict(os.environ)
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = cache
    done = subprocess.run([sys.executable, "-c", _FIRST_CALL, *names], capture_output=True,
                          text=True, env=env, timeout=600, check=False)  # fmt: skip
    if done.returncode != 0:
        log.warning("timing the first calls failed: %s", done.stderr.strip()[-500:])
        return dict.fromkeys(names, math.nan)
    return json.loads(done.stdout.strip().splitlines()[-1])


FIXED_TRIALS = 5
"""The fixed cost of a call is the best of this many one-step calls."""


def fixed_cost(row: Row, problem: CardProblem) -> float:
    """The fixed cost of one call, s: the best of :data:`FIXED_TRIALS` runs of one step of
    :data:`~tumble.report_card.measure.STANDARD_H` (a few steps for an adaptive row), after a
    warm-up: what a run costs before its steps (checks, set-up, the record)."""
    setting = standard_setting(row)
    run_row(row, problem, setting, t_end=STANDARD_H)
    return min(sampled(row, problem, setting, t_end=STANDARD_H).seconds
               for _ in range(FIXED_TRIALS))  # fmt: skip


def warm_cost(row: Row, problem: CardProblem, repeat: int) -> float:
    """µs per accepted step at the standard setting on ``problem``, best of ``repeat``, after
    a warm-up run of 0.1 s."""
    setting = standard_setting(row)
    (trial,) = exact.study(
        lambda setting: sampled(row, problem, setting),
        [setting],
        repeat=repeat,
        warm_up=lambda: run_row(row, problem, setting, t_end=0.1),
        seconds=lambda run: run.seconds / max(run.steps, 1),
    )
    return trial.seconds * 1e6
