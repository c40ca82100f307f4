"""Run every benchmark (``make bench``); each prints its own table of ratios."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

BENCHMARKS = ["bench_ode"]


def main() -> None:
    quick = "--quick" in sys.argv
    for name in BENCHMARKS:
        module = importlib.import_module(name)
        module.main(quick=quick)
        print()


if __name__ == "__main__":
    main()
