"""Your own loads against the built-in ones: µs per step, the same physics, one process.

Run: ``python benchmarks/bench_loads.py [--quick]``. The same ``rkmk4`` run of the detumble
scenario's cubesat (``tumble.scenarios.detumble``: 400 km, 51.6°, tumbling at 15.4 °/s,
``h`` = 1 s, no events, one sample kept) under

* the scenario's B-dot law, a :class:`~tumble.Torque` callable, as Python and compiled by
  ``numba.njit`` (both beside the built-in :class:`~tumble.GravityGradient`, which integrates
  the orbit);
* a magnetic dipole in a uniform field written by the user, ``τ = (R μ) × B``, as Python and
  under ``numba.njit``, against the built-in :class:`~tumble.MagneticDipole`, the same
  torque (the issue's comparison of "a user-written dipole against MagneticDipole");
* the built-in loads of about the B-dot law's work, ``MagneticDipole`` and
  ``GravityGradient`` together, in the compiled kernel.

Today a callable load makes ``simulate`` step in Python, njit or not, so the numbers show what
compiled user loads (issue 26, items 1 and 2) have to win. Medians (min–max) over repeats of
whole runs, divided by their steps; the first call of the njit law (numba compiling it) is
timed apart. The same numbers come back from both forms of each law (checked here).
"""

from __future__ import annotations

import sys
import time

import numba
import numpy as np
from _timing import load, machine, spread, table, timed

from tumble import GravityGradient, MagneticDipole, Torque, simulate
from tumble.rigid import State
from tumble.scenarios.detumble import DipoleField, bdot_controller, circular_orbit, cubesat

H = 1.0
MOMENT, FIELD = np.array([0.05, -0.02, 0.08]), np.array([2e-5, -1e-5, 3e-5])
"""The user's dipole (A m², body axes) and the uniform field (T), those of MagneticDipole."""


def dipole_torque(t, state):
    """A user's magnetic dipole: ``τ = (R μ) × B`` (N m, world)."""
    return np.cross(state.R @ MOMENT, FIELD)


def cases() -> dict[str, tuple[list, bool]]:
    """Each case's loads and whether it runs compiled (the built-in ones)."""
    body, _ = cubesat()
    law = bdot_controller(DipoleField.igrf(), body, gain=3.0e4, max_dipole=0.1)
    return {
        "B-dot law, Python (+ GravityGradient)": ([GravityGradient(), Torque(law)], False),
        "B-dot law, numba.njit (+ GravityGradient)": (
            [GravityGradient(), Torque(numba.njit(law))],
            False,
        ),
        "user's dipole, Python": ([Torque(dipole_torque)], False),
        "user's dipole, numba.njit": ([Torque(numba.njit(dipole_torque))], False),
        "MagneticDipole, built-in": ([MagneticDipole(MOMENT, FIELD)], True),
        "MagneticDipole + GravityGradient, built-in": (
            [MagneticDipole(MOMENT, FIELD), GravityGradient()],
            True,
        ),
    }


def run(forces, steps: int):
    """The cubesat for ``steps`` steps of ``rkmk4`` under ``forces``, one sample kept."""
    body, _ = cubesat()
    x0, v0, _ = circular_orbit(400.0, 51.6)
    return simulate(body, steps * H, method="rkmk4", h=H, x0=x0, v0=v0,
                    omega0=(0.1, -0.15, 0.2), forces=forces, record_every=10**9)  # fmt: skip


def first_call() -> float:
    """Seconds of the njit law's first call (numba compiling it; no cache for a closure)."""
    body, _ = cubesat()
    law = numba.njit(bdot_controller(DipoleField.igrf(), body, gain=3.0e4, max_dipole=0.1))
    x0, v0, _ = circular_orbit(400.0, 51.6)
    start = time.perf_counter()
    law(0.0, State(x0, np.eye(3), body.mass * v0, np.array([0.004, -0.006, 0.0013])))
    return time.perf_counter() - start


def main(argv: list[str] | None = None) -> str:
    """Print the table and return it as a markdown section."""
    argv = sys.argv[1:] if argv is None else argv
    quick = "--quick" in argv
    python_steps, compiled_steps, repeat = (200, 20_000, 3) if quick else (2000, 200_000, 7)
    compile_s = first_call()
    rows, per_step, ends = [], {}, {}
    for name, (forces, compiled) in cases().items():
        steps = compiled_steps if compiled else python_steps
        run(forces, 2)  # numba compiles the njit loads and the kernels outside the timing
        median, low, high, result = timed(lambda f=forces, n=steps: run(f, n), repeat)
        assert result.settings["compiled"] is compiled, name
        per_step[name] = median / steps
        ends[name] = result
        rows.append([name, "compiled kernel" if compiled else "Python steps", steps,
                     spread(median / steps, low / steps, high / steps, 1e6, 1)])  # fmt: skip
    baseline = per_step["MagneticDipole + GravityGradient, built-in"]
    for row, name in zip(rows, per_step, strict=True):
        row.append(f"{per_step[name] / baseline:.0f}×")
    same = {
        "B-dot": _difference(
            ends,
            "B-dot law, Python (+ GravityGradient)",
            "B-dot law, numba.njit (+ GravityGradient)",
        ),  # fmt: skip
        "dipole": _difference(ends, "user's dipole, Python", "user's dipole, numba.njit"),
    }
    dipole_ratio = per_step["user's dipole, numba.njit"] / per_step["MagneticDipole, built-in"]
    markdown = "\n".join(
        [
            "## Your own loads against the built-in ones (`benchmarks/bench_loads.py`)",
            "",
            table(
                [
                    "the detumble cubesat, `rkmk4`, h = 1 s",
                    "runs",
                    "steps",
                    "µs a step, median (min–max)",
                    "× the built-ins' kernel",
                ],
                rows,
            ),  # fmt: skip
            "",
            f"The njit B-dot law's first call (numba compiling it): {compile_s:.2f} s. "
            f"The same numbers from both forms: the B-dot runs' states end "
            f"{same['B-dot']:.1e} apart, the dipole runs' {same['dipole']:.1e} (relative). "
            "A callable load runs the whole step in Python, compiled or not: the njit law "
            "saves only its own arithmetic. Issue 26's target for compiled user loads, at "
            "most 2× the built-in load of similar work a step: the user's njit dipole takes "
            f"{dipole_ratio:.0f}× `MagneticDipole`'s step today. "
            f"{machine()} (shared with other jobs: {load()}).",
            "",
        ]
    )
    print(markdown)
    return markdown


def _difference(ends, a: str, b: str) -> float:
    """The largest relative difference of two runs' last states (R, x, L)."""
    worst = 0.0
    for name in ("R", "x", "L_world"):
        first, second = getattr(ends[a], name)[-1], getattr(ends[b], name)[-1]
        worst = max(worst, float(np.abs(first - second).max() / np.abs(first).max()))
    return worst


if __name__ == "__main__":
    main()
