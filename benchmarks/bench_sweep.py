"""What Dask and Zarr cost a sweep: ``tumble.sweep`` against ``simulate_batch``, 1 vs 2 workers.

Run: ``python benchmarks/bench_sweep.py [--quick]``. The baseline is ``simulate_batch`` of the
same free bodies (the T-handle, ``rkmk4``, one ``omega0`` per member, every step's record
thinned to the first and last state) in this process, with numba's threads on every core.
The sweep runs the same members as ``samples=`` on a ``LocalCluster`` of worker processes (one
thread each; each worker's numba loop still uses every core) and writes them to a Zarr store:
template, one region per task of 4096 members, the completion flags. Both are timed from call
to return, after one warm-up (the kernels compiled and loaded in every process); the cluster's
start is left out. Body-steps per second = members × steps / wall time; medians (min–max).

The cluster's own numbers: the time its workers spent computing tasks (Dask's task stream),
beside the wall time of the sweep.

Target (issue 15): the sweep reaches ≥ 70 % of ``simulate_batch``'s body-steps per second.
Each sweep is paired with a baseline run just before it, and the ratio is taken per pair, so
a machine shared with other work moves both.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _timing import machine, spread, table, verdict

from tumble import RigidBody, mass, simulate_batch
from tumble.sweeps import sweep

TARGET = 0.70
H, T_END = 0.01, 3.0
STEPS = round(T_END / H)
OPTIONS = {
    "body": {
        "density": 6700.0,
        "parts": [
            {"shape": "cylinder", "radius": 0.01, "length": 0.08, "axis": "y",
             "center": [-0.01, 0.0, 0.0]},
            {"shape": "cylinder", "radius": 0.01, "length": 0.04, "axis": "x",
             "center": [0.02, 0.0, 0.0]},
        ],
    },
    "initial": {"omega0": [1.0, 0.05, 0.0]},
    "method": "rkmk4",
    "h": H,
    "t_end": T_END,
    "record_every": STEPS,
}  # fmt: skip
"""The T-handle of examples/t-handle-parts.toml; only the first and last states kept."""


def spins(n: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    return np.column_stack([np.ones(n), rng.uniform(0.0, 0.1, n), rng.uniform(0.0, 0.1, n)])


def baseline(omega0: np.ndarray):
    body = RigidBody.from_mass_properties(mass.t_handle())
    return lambda: simulate_batch(body, T_END, h=H, omega0=omega0, record_every=STEPS)


def paired(client, run, omega0: np.ndarray, folder: Path, repeat: int):
    """``repeat`` pairs (baseline, sweep) timed back to back, so both see the same load.

    Returns the baseline's and the sweep's wall times (s) and the workers' compute time of
    the sweeps (s, Dask's task stream, summed over the pairs).
    """
    from distributed import get_task_stream

    samples = {f"omega0.{k}": omega0[:, k] for k in range(3)}
    base, swept, compute = [], [], 0.0
    for k in range(repeat):
        start = time.perf_counter()
        run()
        base.append(time.perf_counter() - start)
        store = folder / f"sweep{k}.zarr"
        with get_task_stream(client) as stream:
            start = time.perf_counter()
            sweep(OPTIONS, samples=samples, client=client, store=store)
            swept.append(time.perf_counter() - start)
        compute += sum(
            part["stop"] - part["start"]
            for task in stream.data
            for part in task["startstops"]
            if part["action"] == "compute"
        )
        shutil.rmtree(store)
    return np.array(base), np.array(swept), compute / repeat


def main(argv: list[str] | None = None) -> str:
    """Print the table and return it as a markdown section."""
    from distributed import Client, LocalCluster

    argv = sys.argv[1:] if argv is None else argv
    quick = "--quick" in argv
    n, repeat = (10_000, 2) if quick else (100_000, 5)
    omega0 = spins(n)
    body_steps = n * STEPS
    run = baseline(omega0)
    run()  # compile
    rows, ratios, speeds = [], {}, {}
    folder = Path(tempfile.mkdtemp())
    try:
        for workers in (1, 2):
            with (
                LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                             dashboard_address=":0") as cluster,
                Client(cluster) as client,
            ):  # fmt: skip
                sweep(OPTIONS, samples={"omega0.1": [0.01, 0.02]}, client=client,
                      store=folder / "warm.zarr")  # fmt: skip
                shutil.rmtree(folder / "warm.zarr")
                base, swept, compute = paired(client, run, omega0, folder, repeat)
            ratio = base / swept
            ratios[workers] = float(np.median(ratio))
            speeds[workers] = body_steps / float(np.median(swept))
            b_rate = body_steps / float(np.median(base))
            rows.append((f"`simulate_batch`, paired with {workers} worker(s)", "—",
                         spread(np.median(base), base.min(), base.max()),
                         f"{b_rate / 1e6:.2f}", "1", "—"))  # fmt: skip
            rows.append((f"`tumble.sweep`, {workers} worker(s)", f"{compute:.2f}",
                         spread(np.median(swept), swept.min(), swept.max()),
                         f"{speeds[workers] / 1e6:.2f}",
                         spread(ratios[workers], ratio.min(), ratio.max()),
                         verdict(ratios[workers] >= TARGET)))  # fmt: skip
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    scaling = speeds[2] / speeds[1]
    markdown = "\n".join(
        [
            "## Sweeps on Dask (`benchmarks/bench_sweep.py`)",
            "",
            f"{n:,} free T-handles, `rkmk4`, h = {H} s, {STEPS} steps each "
            f"({body_steps:.0e} body-steps), median (min–max) of {repeat}.",
            "",
            table(
                [
                    "run",
                    "workers' compute (s)",
                    "wall (s)",
                    "M body-steps/s",
                    "ratio to simulate_batch",
                    f"target ≥ {TARGET:.0%}",
                ],
                rows,
            ),  # fmt: skip
            "",
            f"Scaling from 1 to 2 workers: {scaling:.2f}× the body-steps per second (medians). "
            "A worker's numba loop uses the worker's one thread (one worker a core), while "
            "`simulate_batch` here uses every core; the ratio is per pair (baseline, sweep) "
            f"timed back to back, median (min–max). {machine()}.",
            "",
        ]
    )
    print(markdown)
    return markdown


if __name__ == "__main__":
    main()
