"""Cold start: the first simulate, simulate_batch and compiled solve in a fresh process.

Run: ``python benchmarks/bench_cold.py [--quick]``. Each case runs in a new interpreter with
``NUMBA_CACHE_DIR`` pointing at a temporary folder: first empty (as right after
installation: every kernel is compiled), then again with the cache that run left (warm: the
kernels are loaded from disk). The time is the first call alone (``import tumble`` and the
case's other imports done before it); the import time is given beside it. Prints medians
(min–max) over fresh processes.

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

CASES = {
    "simulate (rkmk4, 10 steps)": (
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

PROGRAM = """
import time
start = time.perf_counter()
{setup}
imported = time.perf_counter()
{call}
done = time.perf_counter()
print(json.dumps({{"import": imported - start, "first": done - imported}}))
"""


def fresh(setup: str, call: str, cache: Path) -> dict[str, float]:
    """Run ``setup`` then ``call`` in a new interpreter with ``cache`` as numba's cache."""
    code = "import json\n" + PROGRAM.format(setup=setup, call=call)
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    result = subprocess.run(
        [sys.executable, "-c", code], env=environment, capture_output=True, text=True,
        timeout=900, check=True,
    )  # fmt: skip
    return json.loads(result.stdout.strip().splitlines()[-1])


def _spread(values: list[float]) -> str:
    return spread(float(np.median(values)), min(values), max(values), 1.0, 2)


def main(argv: list[str] | None = None) -> str:
    """Print the table and return it as a markdown section."""
    argv = sys.argv[1:] if argv is None else argv
    cold_runs, warm_runs = (1, 3) if "--quick" in argv else (2, 5)
    rows, warm_simulate = [], None
    for name, (setup, call) in CASES.items():
        cold, warm, imports = [], [], []
        for _ in range(cold_runs):
            with tempfile.TemporaryDirectory() as cache:
                first = fresh(setup, call, Path(cache))
                cold.append(first["first"])
                for _ in range(warm_runs if not warm else 0):
                    again = fresh(setup, call, Path(cache))
                    warm.append(again["first"])
                    imports.append(again["import"])
        if name.startswith("simulate ("):
            warm_simulate = float(np.median(warm))
        rows.append([name, _spread(cold), _spread(warm), _spread(imports)])
        print(rows[-1])
    assert warm_simulate is not None
    markdown = "\n".join(
        [
            "## Cold start (`benchmarks/bench_cold.py`)",
            "",
            table(
                [
                    "first call in a fresh process",
                    "cold cache, s",
                    "warm cache, s",
                    "import before it (warm), s",
                ],
                rows,
            ),  # fmt: skip
            "",
            f"Cold: `NUMBA_CACHE_DIR` an empty folder ({cold_runs} fresh processes, each with its "
            f"own); warm: the folder a cold run filled ({warm_runs} processes). Target: a warm "
            f"first `simulate` ≤ {TARGET_WARM_SIMULATE} s: "
            f"{verdict(warm_simulate <= TARGET_WARM_SIMULATE)} ({warm_simulate:.2f} s). The "
            "compiled solve's warm time is the compile of its loop for that right-hand side "
            "(numba cannot cache a function that receives another; the kernels it calls are "
            f"cached). {machine()}.",
            "",
        ]
    )
    print(markdown)
    return markdown


if __name__ == "__main__":
    main()
