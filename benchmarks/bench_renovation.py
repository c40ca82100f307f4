"""The renovation (issue 25) costs no speed: today's code against the code before it, in one
process.

Run ``.venv/bin/python benchmarks/bench_renovation.py [--against COMMIT] [--repeat N]``. The
package as it was at ``COMMIT`` (default: the last commit before the renovation) is taken
from git into ``$TMPDIR/tumble-COMMIT`` as ``tumble_old`` (its imports renamed), so both run
in this process on the same numba and the same machine, alternating, each case warmed up first. The
cases are the issue's: ``rkmk4``, ``split-axes`` (fixed steps), ``rkmk-dopri5`` (adaptive),
``simulate_batch`` and one beam run. Each row gives both medians (min–max) and new/old; the
issue asks for every ratio within 1.05. Short calls are left out: in one process the copy's
compiled loops take numba's slow dispatch path at every call (about 400 µs of a 100-step
``simulate``, seen with cProfile in ``_compile_for_args``), which the code at that commit
does not in a process of its own; measured in separate processes, alternating, a 100-step
``rkmk4`` call takes about 100 µs before and after.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy loads OpenBLAS

import argparse  # noqa: E402
import importlib  # noqa: E402
import re  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tarfile  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from io import BytesIO  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from _timing import machine, spread, table  # noqa: E402

BEFORE = "75320d1"
"""The last commit of main before the renovation."""

ROOT = Path(__file__).resolve().parents[1]


def old_package(commit: str, folder: Path) -> object:
    """``tumble`` as it was at ``commit``, importable as ``tumble_old`` from ``folder`` (kept
    between runs, so that numba's cache beside it spares the old kernels' compilation)."""
    if not (folder / "tumble_old").exists():
        _extract(commit, folder)
    sys.path.insert(0, str(folder))
    return importlib.import_module("tumble_old")


def _extract(commit: str, folder: Path) -> None:
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", commit, "src/tumble"],
        check=True, capture_output=True,
    ).stdout  # fmt: skip
    with tarfile.open(fileobj=BytesIO(archive)) as tar:
        tar.extractall(folder, filter="data")
    (folder / "src" / "tumble").rename(folder / "tumble_old")
    for path in (folder / "tumble_old").rglob("*.py"):
        text = path.read_text()
        text = re.sub(r"\btumble\.", "tumble_old.", text)
        text = re.sub(r"from tumble import", "from tumble_old import", text)
        path.write_text(text)


def cases(package) -> dict:
    """The timed calls of one package: name -> a function of no arguments."""
    body = package.RigidBody(mass=1.0, inertia=np.diag([3.0, 2.0, 1.5]))
    omega = np.array([0.3, 1.0, 0.2])

    def fixed(method: str, n: int):
        return lambda: package.simulate(body, n * 0.01, method=method, h=0.01,
                                        omega0=omega, record_every=n)  # fmt: skip

    def adaptive():
        return package.simulate(body, 100.0, method="rkmk-dopri5", rtol=1e-8,
                                atol=1e-10, omega0=omega)  # fmt: skip

    spins = np.random.default_rng(1).normal(size=(1000, 3))

    def batch(method: str):
        return lambda: package.simulate_batch(body, 10.0, method=method, h=0.01,
                                              omega0=spins, record_every=1000)  # fmt: skip

    structural = package.structural
    beam = structural.cantilever(1.0, 100, 70e9, 2700.0, 0.01, 0.01, tip_load=1.0)
    dt = 2 * np.pi / beam.natural_frequencies(1)[0] / 200
    scheme = structural.Newmark()

    def beam_run():
        return structural.integrate(beam, scheme, dt, n_steps=10_000, record_every=10_000)

    return {
        "rkmk4, 10⁵ steps": fixed("rkmk4", 100_000),
        "split-axes, 10⁵ steps": fixed("split-axes", 100_000),
        "rkmk-dopri5, 100 s, rtol 1e-8": adaptive,
        "simulate_batch rkmk4, 1000 bodies × 1000 steps": batch("rkmk4"),
        "simulate_batch split-axes, 1000 bodies × 1000 steps": batch("split-axes"),
        "beam, Newmark, 100 elements, 10⁴ steps": beam_run,
    }


def compare(new: dict, old: dict, repeat: int) -> list[list[str]]:
    rows = []
    for name in new:
        new[name](), old[name]()  # warm up: compile or load from the cache
        times: dict[str, list[float]] = {"new": [], "old": []}
        for _ in range(repeat):  # alternate, so that drifts of the machine hit both
            for key, fn in (("new", new[name]), ("old", old[name])):
                start = time.perf_counter()
                fn()
                times[key].append(time.perf_counter() - start)
        n, o = np.array(times["new"]), np.array(times["old"])
        scale, unit = (1e3, "ms") if np.median(o) > 1e-3 else (1e6, "µs")
        rows.append([
            name,
            f"{spread(np.median(n), n.min(), n.max(), scale)} {unit}",
            f"{spread(np.median(o), o.min(), o.max(), scale)} {unit}",
            f"{np.median(n) / np.median(o):.3f}",
        ])  # fmt: skip
    return rows


def main() -> str:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--against", default=BEFORE, help="the commit to compare with")
    parser.add_argument("--repeat", type=int, default=9)
    args = parser.parse_args()
    import tumble

    old = old_package(args.against, Path(tempfile.gettempdir()) / f"tumble-{args.against}")
    rows = compare(cases(tumble), cases(old), args.repeat)
    text = "\n".join([
        f"## The renovation against {args.against} (median (min–max) of {args.repeat})",
        "",
        table(["case", "now", f"at {args.against}", "now/then"], rows),
        "",
        machine(),
    ])  # fmt: skip
    print(text)
    return text


if __name__ == "__main__":
    main()
