"""Cold start: the first simulate, simulate_batch and compiled solve in a fresh process.

Run: ``python benchmarks/bench_cold.py [--quick]``. Each case runs in a new interpreter with
``NUMBA_CACHE_DIR`` pointing at a temporary folder: first empty (as right after
installation: every kernel is compiled), then again with the cache that run left (warm: the
kernels are loaded from disk). Python's bytecode caches are read and written as by default
(``PYTHONDONTWRITEBYTECODE`` is cleared for these processes), so a warm run, like a user's
second run, does not compile tumble's sources again. The time is the first call
alone (``import tumble`` and the case's other imports done before it, so it includes
importing numba); the import time is given beside it. Prints medians (min–max) over fresh
processes, wall-clock and CPU time (the main thread's, where the first call runs: steadier
than wall-clock time on a shared machine, and free of the idle spinning of OpenBLAS's threads).

The baseline, run the same way: numba alone, the first call of a one-line cached function
in a fresh process that has imported NumPy. It is what any first compiled call costs before
tumble's share (importing numba and scipy, which numba imports for its version and BLAS
checks; initialising numba's compiler context; loading the function). A second table
splits a warm first ``simulate`` into those phases.

Numba keys a function that receives another compiled function by that function's identity,
so the loop of a compiled ``solve`` (:mod:`tumble.ode.compiled`) is compiled in every
process, warm or cold, for each right-hand side: its warm time is that compile.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from _timing import machine, spread, table, verdict

TARGET_WARM_SIMULATE = 0.2
"""Issue 17: a warm first simulate in a fresh process takes at most this many seconds."""

BASELINE = "numba alone (a cached one-line function)"
SIMULATE = "simulate (rkmk4, 10 steps)"
CASES = {
    BASELINE: (
        "import numpy as np\nimport sys\nsys.path.insert(0, {folder!r})",
        "import numba\nimport one_line\none_line.add_one(1.0)",
    ),
    SIMULATE: (
        "import numpy as np\nfrom tumble import RigidBody, simulate\n"
        "body = RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))",
        "simulate(body, 0.1, method='rkmk4', h=0.01, omega0=[0.1, 1.0, 0.05])",
    ),
    "simulate_batch (rkmk4, 1000 bodies, 10 steps)": (
        "import numpy as np\nfrom tumble import RigidBody, simulate_batch\n"
        "body = RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))\n"
        "omega0 = np.tile([0.1, 1.0, 0.05], (1000, 1))",
        "simulate_batch(body, 0.1, method='rkmk4', h=0.01, omega0=omega0)",
    ),
    "compiled solve (dopri5, Van der Pol)": (
        "import numba\nimport numpy as np\nfrom tumble import solve\n"
        "fun = numba.njit(lambda t, y: np.array([y[1], 2.0 * (1 - y[0] ** 2) * y[1] - y[0]]))",
        "solve(fun, (0.0, 10.0), [2.0, 0.0], method='dopri5')",
    ),
}
ONE_LINE = "from numba import njit\n\n\n@njit(cache=True)\ndef add_one(x):\n    return x + 1.0\n"
"""The baseline's module (numba caches only functions defined in files)."""

PROGRAM = """
import time
clock = lambda: (time.perf_counter(), time.thread_time())
start = clock()
{setup}
imported = clock()
{call}
done = clock()
print(json.dumps({{"import": imported[0] - start[0], "first": done[0] - imported[0],
                  "first_cpu": done[1] - imported[1]}}))
"""

PHASES = """
import time
import numpy as np
from tumble import RigidBody, simulate
body = RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))
marks = [time.thread_time()]
import numba
marks.append(time.thread_time())
import tumble.rigid._compiled.flows
marks.append(time.thread_time())
from numba.core.registry import cpu_target
cpu_target.target_context.refresh()
marks.append(time.thread_time())
simulate(body, 0.1, method='rkmk4', h=0.01, omega0=[0.1, 1.0, 0.05])
marks.append(time.thread_time())
print(json.dumps([b - a for a, b in zip(marks, marks[1:])]))
"""
PHASE_NAMES = (
    "import numba (and scipy, for its version check)",
    "import tumble.rigid._compiled.flows (define the dispatchers)",
    "numba's compiler context (its registries, scipy.linalg for BLAS, its runtime)",
    "simulate: load the cached loop, link it, run",
)


def fresh(program: str, cache: Path) -> dict | list:
    """Run ``program`` in a new interpreter with ``cache`` as numba's cache."""
    code = "import json\n" + program.replace("{folder!r}", repr(str(cache)))
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    environment.pop("PYTHONDONTWRITEBYTECODE", None)  # as a default installation
    result = subprocess.run(
        [sys.executable, "-c", code], env=environment, capture_output=True, text=True,
        timeout=900, check=True,
    )  # fmt: skip
    return json.loads(result.stdout.strip().splitlines()[-1])


def _spread(values: list[float]) -> str:
    return spread(float(np.median(values)), min(values), max(values), 1.0, 2)


def _case(setup: str, call: str, cold_runs: int, warm_runs: int) -> dict[str, list[float]]:
    runs: dict[str, list[float]] = {"cold": [], "first": [], "first_cpu": [], "import": []}
    program = PROGRAM.format(setup=setup, call=call)
    for _ in range(cold_runs):
        with tempfile.TemporaryDirectory() as folder:
            cache = Path(folder)
            (cache / "one_line.py").write_text(ONE_LINE)
            runs["cold"].append(fresh(program, cache)["first"])
            for _ in range(warm_runs if not runs["first"] else 0):
                warm = fresh(program, cache)
                for key in ("first", "first_cpu", "import"):
                    runs[key].append(warm[key])
    return runs


def breakdown(runs: int) -> str:
    """A warm first ``simulate`` split into phases: CPU seconds, medians (min–max)."""
    phases = []
    with tempfile.TemporaryDirectory() as folder:
        fresh(PHASES, Path(folder))  # fills the cache
        phases = [fresh(PHASES, Path(folder)) for _ in range(runs)]
    rows = [[name, _spread([p[i] for p in phases])] for i, name in enumerate(PHASE_NAMES)]
    rows.append(["total", _spread([sum(p) for p in phases])])
    return table(["warm first `simulate`, phase", "CPU s"], rows)


def main(argv: list[str] | None = None) -> str:
    """Print the table and return it as a markdown section."""
    argv = sys.argv[1:] if argv is None else argv
    cold_runs, warm_runs = (1, 3) if "--quick" in argv else (2, 5)
    rows, results = [], {}
    for name, (setup, call) in CASES.items():
        results[name] = runs = _case(setup, call, cold_runs, warm_runs)
        ratio = np.median(runs["first_cpu"]) / np.median(results[BASELINE]["first_cpu"])
        spreads = [_spread(runs[key]) for key in ("cold", "first", "first_cpu", "import")]
        rows.append([name, *spreads[:3], f"{ratio:.2f}", spreads[3]])
        print(rows[-1])
    warm_simulate = float(np.median(results[SIMULATE]["first"]))
    floor = float(np.median(results[BASELINE]["first_cpu"]))
    share = float(np.median(results[SIMULATE]["first_cpu"])) - floor
    header = ["first call in a fresh process", "cold cache, s", "warm cache, s",
              "warm, CPU s", "warm CPU ÷ numba alone", "import before it (warm), s"]  # fmt: skip
    sections = ["## Cold start (`benchmarks/bench_cold.py`)", "", table(header, rows), ""]
    sections += [breakdown(warm_runs), ""]
    sections += [
        f"Cold: `NUMBA_CACHE_DIR` an empty folder ({cold_runs} fresh processes, each with its "
        f"own); warm: the folder a cold run filled ({warm_runs} processes); Python's bytecode "
        f"caches as by default. Target: a warm first `simulate` ≤ {TARGET_WARM_SIMULATE} s: "
        f"{verdict(warm_simulate <= TARGET_WARM_SIMULATE)} ({warm_simulate:.2f} s). The "
        "first row is the floor of any first compiled call in this environment "
        f"({floor:.2f} s of CPU): importing numba and the scipy it imports (scipy for its "
        "version check, scipy.linalg for its BLAS check, which imports scipy's array-API "
        "layer and with it numpy.testing and numpy.f2py) and building numba's compiler "
        "context (its implementation registries, its extensions' entry points, its compiled "
        f"runtime). tumble's own share of a warm first `simulate` is {share:+.2f} s of CPU "
        "above that floor (the kernels module, one cached loop loaded): the target lies "
        "below numba's floor. The compiled solve's warm time is the compile of its loop for "
        "that right-hand side (numba cannot cache a function that receives another; the "
        f"kernels it calls are cached). {machine()}.",
        "",
    ]
    markdown = "\n".join(sections)
    print(markdown)
    return markdown


if __name__ == "__main__":
    main()
