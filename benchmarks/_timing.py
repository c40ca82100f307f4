"""Timing helpers shared by the benchmarks: medians over repeats, min–max beside them, tables."""

from __future__ import annotations

import os
import platform
import time
from collections.abc import Callable, Sequence
from importlib import metadata

import numpy as np

PACKAGES = ("numpy", "numba", "scipy", "mujoco", "openseespy")


def timed(fn: Callable[[], object], repeat: int = 7) -> tuple[float, float, float, object]:
    """Run ``fn`` ``repeat`` times; return (median, min, max) seconds and the last result."""
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return float(np.median(times)), float(np.min(times)), float(np.max(times)), result


def spread(median: float, low: float, high: float, scale: float = 1.0, digits: int = 2) -> str:
    """``"median (min–max)"`` of seconds times ``scale`` (1e6 for µs)."""
    m, lo, hi = (value * scale for value in (median, low, high))
    return f"{m:.{digits}f} ({lo:.{digits}f}–{hi:.{digits}f})"


def table(header: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """A markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(cell) for cell in row) + " |" for row in rows]
    return "\n".join(lines)


def verdict(met: bool) -> str:
    return "MET" if met else "NOT MET"


def machine() -> str:
    """One line naming the CPU, its core count and Python."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if "model name" in line)
    except (OSError, StopIteration):
        pass
    return f"{cpu}, {os.cpu_count()} cores; Python {platform.python_version()}"


def versions() -> str:
    """``name version`` of each peer and dependency that is installed."""
    found = []
    for name in PACKAGES:
        try:
            found.append(f"{name} {metadata.version(name)}")
        except metadata.PackageNotFoundError:
            found.append(f"{name} (not installed)")
    return ", ".join(found)


def load() -> str:
    """The 1-, 5- and 15-minute load averages (other processes share the CPU)."""
    try:
        return "load average {:.2f}, {:.2f}, {:.2f}".format(*os.getloadavg())
    except OSError:
        return "load average unknown"
