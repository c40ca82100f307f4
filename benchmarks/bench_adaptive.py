"""Adaptive Lie-group integration (issue 13): the compiled adaptive loop against the Python
path at the same steps, and work–precision of the adaptive methods on P1 against the best
fixed-step method and scipy's DOP853.

Run alone with ``python benchmarks/bench_adaptive.py [--quick]`` or through ``make bench``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

from _timing import machine, spread, table, timed, verdict  # noqa: E402
from bench_rigid import (  # noqa: E402
    RTOL_GRID,
    T_END,
    TARGET_ERRORS,
    WORK_PRECISION_METHODS,
    angle_error,
    problems,
    scipy_error,
    scipy_run,
    search,
    tumble_work_precision,
)

from tumble import simulate  # noqa: E402
from tumble.rigid import METHODS  # noqa: E402

ADAPTIVE = [name for name, method in METHODS.items() if method.adaptive]
FIXED_BASELINES = [m for m in WORK_PRECISION_METHODS if METHODS[m].flow != "exact"]
"""The fixed-step methods to beat: every one of the work–precision section except those on
the exact free-body flow (``exact``, ``strang``, ``yoshida4``: round-off at any h on a free
body, so not a fair baseline for a general integrator)."""


def adaptive_run(problem, method: str, rtol: float, compiled: bool | None = None):
    return simulate(problem.body, T_END, method=method, rtol=rtol, omega0=problem.omega0,
                    record_every=10**9, compiled=compiled)  # fmt: skip


def compiled_against_python(problem, repeat: int) -> tuple[list, dict]:
    """Section 1: µs per step of each adaptive method, compiled and in Python, same steps."""
    rows, ratios = [], {}
    for method in ADAPTIVE:
        adaptive_run(problem, method, 1e-3)  # compile outside the timing
        fast = timed(lambda m=method: adaptive_run(problem, m, 1e-8), repeat)
        slow = timed(lambda m=method: adaptive_run(problem, m, 1e-8, compiled=False), 3)
        steps_fast, steps_slow = fast[3].n_steps, slow[3].n_steps
        ratio = slow[0] / fast[0]
        ratios[method] = (ratio, slow[1] / fast[2], slow[2] / fast[1], steps_fast == steps_slow)
        rows.append([
            f"`{method}`", steps_fast, steps_slow, spread(*fast[:3], 1e6 / steps_fast),
            spread(*slow[:3], 1e6 / steps_slow), f"{ratio:.0f}× ({ratios[method][1]:.0f}–"
            f"{ratios[method][2]:.0f})",
        ])  # fmt: skip
    return rows, ratios


def work_precision(problem, repeat: int) -> tuple[list, dict]:
    """Section 2: at each target error, the loosest rtol of each adaptive method that meets
    it, the best fixed-step method, and DOP853, each timed."""
    rows, numbers = [], {}
    R_exact = problem.exact(T_END)
    for target in TARGET_ERRORS:
        best_adaptive = None
        for method in ADAPTIVE:
            rtol, error = search(RTOL_GRID, lambda r, m=method: adaptive_run(problem, m, r),
                                 lambda run: angle_error(run.R[-1], R_exact), target)  # fmt: skip
            if rtol is None:
                rows.append([f"{target:.0e}", f"`{method}`", "not reached", "", ""])
                continue
            med, lo, hi, run = timed(lambda r=rtol, m=method: adaptive_run(problem, m, r), repeat)
            rows.append([f"{target:.0e}", f"`{method}` (rtol {rtol:.1e})", run.n_steps,
                         f"{error:.1e}", spread(med, lo, hi, 1e3, 3)])  # fmt: skip
            if best_adaptive is None or med < best_adaptive[1]:
                best_adaptive = (method, med, lo, hi)
        found = tumble_work_precision(problem, target, repeat)
        fixed = {m: v for m, v in found.items() if m in FIXED_BASELINES}
        best_fixed = min(fixed, key=lambda m: fixed[m][2][0])
        h, error, (med_f, lo_f, hi_f) = fixed[best_fixed]
        rows.append(
            [
                f"{target:.0e}",
                f"best fixed step: `{best_fixed}` (h {h:g})",
                round(T_END / h),
                f"{error:.1e}",
                spread(med_f, lo_f, hi_f, 1e3, 3),
            ]
        )
        rtol, error = search(RTOL_GRID, lambda r: scipy_run(problem, "DOP853", r),
                             lambda sol: scipy_error(problem, sol), target)  # fmt: skip
        dop = None
        if rtol is not None:
            med_d, lo_d, hi_d, sol = timed(lambda r=rtol: scipy_run(problem, "DOP853", r), 3)
            dop = (med_d, lo_d, hi_d)
            rows.append([f"{target:.0e}", f"scipy DOP853 (rtol {rtol:.1e})", sol.t.size - 1,
                         f"{error:.1e}", spread(med_d, lo_d, hi_d, 1e3, 3)])  # fmt: skip
        numbers[target] = (best_adaptive, (best_fixed, med_f, lo_f, hi_f), dop)
    return rows, numbers


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    args, _ = parser.parse_known_args(argv)
    repeat = 3 if args.quick else 9
    p1 = problems()[0]
    out = ["## Adaptive Lie-group integration (`benchmarks/bench_adaptive.py`)", "",
           f"Machine: {machine()}. P1 (I = diag(2, 1, 2/3)), T = {T_END:g} s, "
           "free body; medians (min–max).", ""]  # fmt: skip

    rows, ratios = compiled_against_python(p1, repeat)
    header = ["method", "steps (compiled)", "steps (Python)", "µs/step compiled",
              "µs/step Python", "Python / compiled"]  # fmt: skip
    out += ["### 1. Compiled adaptive loop against the Python path (rtol 1e-8)", "",
            table(header, rows), ""]  # fmt: skip
    targets = [
        f"- compiled `{m}` ≥ 30× faster than the Python path at the same steps: "
        f"**{verdict(r[0] >= 30 and r[3])}** ({r[0]:.0f}×, {r[1]:.0f}–{r[2]:.0f}; same steps: "
        f"{r[3]})"
        for m, r in ratios.items()
    ]

    rows, numbers = work_precision(p1, repeat)
    header = ["target", "run", "steps", "error (rad)", "ms"]
    out += ["### 2. Work–precision on P1", "", table(header, rows), ""]
    for target, (adaptive, fixed, dop) in numbers.items():
        if adaptive is None:
            targets.append(f"- {target:.0e}: no adaptive method reached it: **NOT MET**")
            continue
        method, med, lo, hi = adaptive
        over_fixed = med / fixed[1]
        targets.append(
            f"- {target:.0e}: best adaptive `{method}` within 2× of the best fixed-step "
            f"`{fixed[0]}`: **{verdict(over_fixed <= 2)}** ({over_fixed:.2f}×, "
            f"{lo / fixed[3]:.2f}–{hi / fixed[2]:.2f})"
        )
        if dop is not None:
            speedup = dop[0] / med
            targets.append(
                f"- {target:.0e}: best adaptive ≥ 100× faster than scipy DOP853: "
                f"**{verdict(speedup >= 100)}** ({speedup:.0f}×, {dop[1] / hi:.0f}–"
                f"{dop[2] / lo:.0f})"
            )
    out += ["### Targets", "", *targets, ""]
    text = "\n".join(out)
    print(text)
    return text


if __name__ == "__main__":
    main()
