"""How long ``import tumble`` takes, each time in a fresh interpreter.

Run: ``python benchmarks/bench_import.py [--quick]``. Every statement runs in a new process
(this checkout's ``src`` first on the path) that times it with ``perf_counter`` around the
statement only, so interpreter start-up is left out. One unrecorded run first writes the
bytecode caches; then medians (min–max) over 7 runs (3 with ``--quick``).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from _timing import machine, spread, table, verdict

SOURCE = Path(__file__).resolve().parents[1] / "src"
STATEMENTS = [
    ("import tumble", 0.3),
    ("from tumble import solve", None),
    ("import tumble.rigid", None),
    ("import numpy", None),  # for scale: what every path above pays at least once
]
"""Each statement and its target in seconds (None: measured, no target)."""

PROGRAM = "import time\nstart = time.perf_counter()\n{}\nprint(time.perf_counter() - start)"


def import_time(statement: str) -> float:
    """Seconds ``statement`` takes in a fresh interpreter."""
    path = os.pathsep.join(filter(None, [str(SOURCE), os.environ.get("PYTHONPATH")]))
    environment = {**os.environ, "PYTHONPATH": path}
    environment.pop("PYTHONDONTWRITEBYTECODE", None)  # bytecode cached, as installed
    result = subprocess.run(
        [sys.executable, "-c", PROGRAM.format(statement)],
        env=environment,
        capture_output=True,
        text=True,
        check=True,
    )
    return float(result.stdout.strip().splitlines()[-1])


def measure(statement: str, repeat: int) -> tuple[float, float, float]:
    import_time(statement)  # writes __pycache__ if missing; not recorded
    times = [import_time(statement) for _ in range(repeat)]
    return float(np.median(times)), float(np.min(times)), float(np.max(times))


def main(argv: list[str] | None = None) -> str:
    """Print the table and return it as a markdown section (heading, table, notes)."""
    argv = sys.argv[1:] if argv is None else argv
    repeat = 3 if "--quick" in argv else 7
    rows = []
    for statement, target in STATEMENTS:
        median, low, high = measure(statement, repeat)
        goal = "—" if target is None else f"≤ {target:g} s: {verdict(median <= target)}"
        rows.append((f"`{statement}`", spread(median, low, high, scale=1e3, digits=0), goal))
    markdown = "\n".join(
        [
            "## Import time (`benchmarks/bench_import.py`)",
            "",
            table(["statement", f"ms, median (min–max) of {repeat}", "target"], rows),
            "",
            f"Each run a fresh interpreter, start-up excluded. {machine()}.",
            "",
        ]
    )
    print(markdown)
    return markdown


if __name__ == "__main__":
    main()
