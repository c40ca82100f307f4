"""Where a short ``simulate`` call spends its time: the fixed cost, part by part.

Run: ``python benchmarks/bench_call.py [--quick]``. A 10-step ``rkmk4`` run of a free body
(``record_every`` large) is timed whole, then each part of it alone, called as ``simulate``
calls it: the checks and the initial state, the compiled stepper's construction, the driver
(``march``), inside it one compiled block (``march_block``), inside that the numba dispatch of
the loop (the loop called through numba's dispatcher, and through the compiled entry point of
the same overload, which skips typing the ``Problem`` and ``Records`` named tuples), and the
``Trajectory``. Medians (min–max) in µs over repeats of many calls.
"""

from __future__ import annotations

import sys
import timeit

import numba
import numpy as np
from _timing import machine, table

from tumble import RigidBody, simulate, solve
from tumble.ode.driver import Grid, march
from tumble.rigid import initial, simulation
from tumble.rigid.forces import compiled_loads, split_loads
from tumble.rigid.methods import get_method
from tumble.rigid.steppers import _records
from tumble.rigid.trajectory import Trajectory

TARGET = 10e-6
"""Issue 17: simulate's fixed cost for a 10-step run, s."""

H, STEPS = 0.01, 10


@numba.njit(cache=True)
def van_der_pol(t, y):
    return np.array([y[1], 2.0 * (1 - y[0] ** 2) * y[1] - y[0]])


def _micro(fn, repeat: int, number: int) -> tuple[float, float, float]:
    times = np.array(timeit.repeat(fn, number=number, repeat=repeat)) / number
    return float(np.median(times)), float(times.min()), float(times.max())


def parts() -> dict[str, object]:
    """The callables timed: the whole call and each part, on the same body and state."""
    body = RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))
    omega0 = np.array([0.1, 1.0, 0.05])
    spec = get_method("rkmk4")
    loads, _ = split_loads(())
    stepper = simulation.stepper_for(spec, body, loads, compiled_loads(loads, body.mass))
    state = stepper.start(initial.initial_state(body, None, None, None, None, omega0, None))
    grid = Grid(0.0, STEPS * H, H, STEPS)
    z, Rn = stepper.chart.pack(*state)
    records = _records(1)
    loop = stepper.loop
    args = (stepper.problem, grid, z, Rn, 0, STEPS, 10**9, 0, records)
    loop(*args)
    entry = next(iter(loop.overloads.values())).entry_point
    out = march(stepper, (0.0, STEPS * H), state, h=H, record_every=10**9)
    R_s, Y_s, _ = out.records

    def checks():
        initial.check_times(0.0, STEPS * H)
        initial.check_steps(spec, H, None, None)
        initial.initial_state(body, None, None, None, None, omega0, None)

    return {
        "whole `simulate` call": lambda: simulate(
            body, STEPS * H, method="rkmk4", h=H, omega0=omega0, record_every=10**9
        ),
        "checks and initial state": checks,
        "compiled stepper built (`stepper_for`)": lambda: simulation.stepper_for(
            spec, body, loads, compiled_loads(loads, body.mass)
        ),
        "driver, whole (`march`)": lambda: march(
            stepper, (0.0, STEPS * H), state, h=H, record_every=10**9
        ),
        "… one compiled block (`march_block`)": lambda: stepper.march_block(
            state, grid, 0, STEPS, 10**9, 0
        ),
        "… … the loop through numba's dispatcher": lambda: loop(*args),
        "… … the loop through its entry point": lambda: entry(*args),
        "`Trajectory` built": lambda: Trajectory(
            t=out.t,
            x=Y_s[:, :3],
            v=Y_s[:, 3:6],
            R=R_s,
            L_world=Y_s[:, 6:],
            body=body,
            method="rkmk4",
            settings={},
            status=out.status,
            message=out.message,
            n_steps=STEPS,
            n_rejected=0,
            t_events=[],
            q_raw=None,
            potential_energy=np.zeros(len(out.t)),
            sol=None,
        ),  # fmt: skip
    }


def solve_parts() -> dict[str, object]:
    """A compiled ``solve`` of one step: its fixed cost (the step is a few evaluations)."""
    y0 = np.array([2.0, 0.0])
    solve(van_der_pol, (0.0, 1.0), y0, method="dopri5")  # compile outside the timing
    return {
        "compiled `solve`, one `dopri5` step, h given": lambda: solve(
            van_der_pol, (0.0, H), y0, method="dopri5", h=H
        ),
        "compiled `solve`, one `rk4` step": lambda: solve(
            van_der_pol, (0.0, H), y0, method="rk4", h=H
        ),
    }


def main(argv: list[str] | None = None) -> str:
    """Print the table and return it as a markdown section."""
    argv = sys.argv[1:] if argv is None else argv
    repeat, number = (5, 300) if "--quick" in argv else (9, 2000)
    timings = {name: _micro(fn, repeat, number) for name, fn in parts().items()}
    solves = {name: _micro(fn, repeat, number) for name, fn in solve_parts().items()}
    rows = [
        [name, f"{m * 1e6:.1f} ({lo * 1e6:.1f}–{hi * 1e6:.1f})"]
        for name, (m, lo, hi) in timings.items()
    ]
    whole = timings["whole `simulate` call"][0]
    dispatch = timings["… … the loop through numba's dispatcher"][0]
    entry = timings["… … the loop through its entry point"][0]
    top = ("checks and initial state", "compiled stepper built (`stepper_for`)",
           "driver, whole (`march`)", "`Trajectory` built")  # fmt: skip
    summed = sum(timings[name][0] for name in top)
    markdown = "\n".join(
        [
            "## A short `simulate` call, part by part (`benchmarks/bench_call.py`)",
            "",
            table(["10-step `rkmk4` run", "µs, median (min–max)"], rows),
            "",
            table(
                ["compiled `solve` (issue 17: its fixed cost ≤ 10 µs too)", "µs"],
                [
                    [name, f"{m * 1e6:.1f} ({lo * 1e6:.1f}–{hi * 1e6:.1f})"]
                    for name, (m, lo, hi) in solves.items()
                ],
            ),  # fmt: skip
            "",
            f"Target (issue 17): the fixed cost ≤ {TARGET * 1e6:.0f} µs: "
            f"{'MET' if whole <= TARGET else 'NOT MET'} ({whole * 1e6:.0f} µs). The ten steps "
            f"themselves are the entry-point call, {entry * 1e6:.1f} µs; numba's dispatch adds "
            f"{(dispatch - entry) * 1e6:.1f} µs (typing the named tuples at every call). The "
            "rest is Python spread thin: the checks and initial state, the stepper, the "
            "driver's bookkeeping (its run state, the record-size check, the first and last "
            "samples, the record concatenated) and the result, each a few µs. Timed alone, "
            f"the four top-level parts add up to {summed * 1e6:.0f} µs of the whole call's "
            f"{whole * 1e6:.0f}: a part repeated in a tight loop keeps its code and data in "
            "the CPU's caches, the whole call does not. Reaching 10 µs would take a call "
            "path of a handful of NumPy operations: no driver, no per-call stepper. "
            "A compiled `solve` call spends its fixed cost in the argument checks, the first "
            "evaluation from Python, the driver's bookkeeping, the result's assembly and the "
            "loop's entry-point call (about 1 µs). "
            f"{machine()}.",
            "",
        ]
    )
    print(markdown)
    return markdown


if __name__ == "__main__":
    main()
