"""Run every benchmark (``make bench``); each prints its own table of ratios."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

BENCHMARKS = ["bench_ode", "bench_structural"]


def main() -> None:
    for name in BENCHMARKS:
        module = importlib.import_module(name)
        module.main(sys.argv[1:])
        print()


if __name__ == "__main__":
    main()
