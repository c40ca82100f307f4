"""Timing helpers shared by the benchmarks: medians over repeats, min–max beside them."""

from __future__ import annotations

import platform
import time
from collections.abc import Callable

import numpy as np


def timed(fn: Callable[[], object], repeat: int = 7) -> tuple[float, float, float, object]:
    """Run ``fn`` ``repeat`` times; return (median, min, max) seconds and the last result."""
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return float(np.median(times)), float(np.min(times)), float(np.max(times)), result


def machine() -> str:
    """One line naming the CPU and Python."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if "model name" in line)
    except (OSError, StopIteration):
        pass
    return f"{cpu}; Python {platform.python_version()}"
