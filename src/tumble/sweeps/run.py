"""``sweep``: check, connect, write the template, run the tasks on Dask, return the dataset."""

from __future__ import annotations

import copy
import dataclasses
import itertools
import logging
import os
import uuid
from collections.abc import Callable, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from tumble import _checks
from tumble.scenarios import registry
from tumble.scenarios.files import check_options
from tumble.sweeps.members import run_members, summary_numbers
from tumble.sweeps.plan import RIGID, Plan, make_plan, set_path
from tumble.sweeps.store import check_existing, pending_tasks, write_region, write_template

log = logging.getLogger(__name__)

CONNECT_TIMEOUT = 10.0
"""Seconds to wait for a scheduler address to answer before giving up (``timeout``)."""


def run_task(plan: Plan, store: str, task: tuple[int, ...]) -> int:
    """Run one task's members and write its region (what a Dask worker runs).

    Returns the number of members written. Writing the same task twice writes the same
    numbers (a task is rerun when its worker dies), so a retried task is harmless.
    """
    region = plan.region(task)
    indices = list(itertools.product(*(range(s.start, s.stop) for s in region.values())))
    with _threads():
        values = run_members(plan, indices)
    write_region(plan, store, task, values)
    return len(indices)


@contextmanager
def _threads():
    """Numba's threads on a Dask worker: the worker's own (one worker a core), not every core."""
    import numba
    from distributed import get_worker

    try:
        wanted = get_worker().state.nthreads
    except ValueError:  # not on a worker (called directly): leave numba's default
        yield
        return
    before = numba.get_num_threads()
    numba.set_num_threads(max(1, min(wanted, numba.config.NUMBA_NUM_THREADS)))
    try:
        yield
    finally:
        numba.set_num_threads(before)


def sweep(
    scenario: Any,
    grid: Mapping[str, Sequence] | None = None,
    samples: Any = None,
    *,
    client: Any = None,
    store: str | Path,
    chunk: int | None = None,
    resume: bool = False,
    timeout: float = CONNECT_TIMEOUT,
    progress: Callable[[int, int], None] | None = None,
):
    """Run a scenario over a grid (or a table) of options on Dask, into one Zarr store.

    Each member is the scenario run with its options, :func:`tumble.rigid.simulate`'s
    numbers bit for bit (members that differ only in their initial state run together through
    :func:`tumble.rigid.simulate_batch`). The members are cut into tasks of ``chunk``
    members; each task writes its own region of the store, then its completion flags
    (:mod:`tumble.sweeps.store`).

    Parameters
    ----------
    scenario : str, Path, mapping or tumble.scenarios.rigid_body.Options
        A scenario file (``.toml``), a built-in scenario's name (``"t-handle"``), or the
        ``rigid-body`` options. A ``rigid-body`` member stores its trajectory and summary
        variables; a built-in's its summary's numbers (:mod:`tumble.sweeps.store`).
    grid : mapping of str to sequence, optional
        Dotted option path → values (``{"omega0.1": [0.01, 0.02], "method": ["rkmk4"]}``);
        the values multiply and each path is a dimension of the output
        (:mod:`tumble.sweeps.plan`).
    samples : mapping of str to sequence, rows, or DataFrame, optional
        One member per row along a ``member`` dimension (a Monte Carlo), instead of ``grid``.
    client : distributed.Client, str or None
        A client; a scheduler's address (``"tcp://127.0.0.1:8786"``); or None for a
        ``LocalCluster`` of one single-threaded worker process per core.
    store : str or Path
        The Zarr store (a folder) to write.
    chunk : int, optional
        Members per task (default: about 16 MB of output, at most 16384 members).
    resume : bool
        Complete an existing store of the same sweep: members already done are skipped. An
        existing store without ``resume`` is refused.
    timeout : float
        Seconds to wait for a scheduler address to answer.
    progress : callable, optional
        ``progress(members_done, members_total)`` after each task.

    Returns
    -------
    xarray.Dataset
        The store, opened with ``xr.open_zarr`` (lazy).

    Raises
    ------
    ValueError
        Before any work: an unknown option path, a bad value, an empty grid, an existing store
        without ``resume`` (or of another sweep), a scheduler address that does not answer
        within ``timeout``.
    """
    import xarray as xr
    from distributed import as_completed

    plan = _probed(make_plan(scenario, grid, samples, chunk=chunk))
    store = str(store)
    exists = Path(store).exists()
    if exists and not resume:
        raise _checks.fail(
            "store", store, "a path that does not exist yet",
            remedy="pass resume=True (--resume) to complete it, or choose another store",
        )  # fmt: skip
    if exists:
        check_existing(plan, store)
    with _client(client, timeout) as dask_client:
        if not exists:
            write_template(plan, store)
        tasks = pending_tasks(plan, store) if exists else plan.tasks()
        done = plan.size - sum(_members(plan, task) for task in tasks)
        log.info("sweep: %d members in %d tasks to run, %d done", plan.size - done,
                 len(tasks), done)  # fmt: skip
        if progress is not None:
            progress(done, plan.size)
        shared = dask_client.scatter(plan, broadcast=True)
        token = uuid.uuid4().hex[:8]  # a new key each run: a resumed sweep never gets old results
        futures = [
            dask_client.submit(run_task, shared, store, task, key=_key(token, task))
            for task in tasks
        ]
        for future in as_completed(futures):
            done += future.result()
            future.release()
            if progress is not None:
                progress(done, plan.size)
    return xr.open_zarr(store)


def _probed(plan: Plan) -> Plan:
    """A built-in's plan with its outputs: the numbers of its first member's summary.

    The first member runs once here, before the template is written (the store's variables
    are the summary's numbers); its task runs it again on a worker.
    """
    if plan.scenario == RIGID:
        return plan
    log.info("sweep: running the first member here to name the summary's numbers")
    options = copy.deepcopy(plan.options)
    for path, values in zip(plan.paths, plan.values, strict=True):
        set_path(options, path, values[0])
    summary = registry.get(plan.scenario).run(**check_options(plan.scenario, options)).summary
    taken = {*plan.dims, *plan.names, "member", "done", "wall_time"}  # a swept option's echo
    numbers = [name for name in summary_numbers(summary) if name not in taken]
    return dataclasses.replace(plan, outputs=tuple(numbers))


def _key(token: str, task: tuple[int, ...]) -> str:
    """The task's name on the dashboard: ``tumble-sweep-<run>-<block index>``."""
    return f"tumble-sweep-{token}-" + "-".join(map(str, task))


def _members(plan: Plan, task: tuple[int, ...]) -> int:
    size = 1
    for part in plan.region(task).values():
        size *= part.stop - part.start
    return size


@contextmanager
def _client(client: Any, timeout: float):
    """The Dask client to use: the one given, one connected to an address, or a local one."""
    from distributed import Client, LocalCluster

    if client is not None and not isinstance(client, str):
        yield client
        return
    if client is None:
        workers = os.cpu_count() or 1
        with (
            LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0"
            ) as cluster,
            Client(cluster) as local,
        ):
            yield local
        return
    seconds = _checks.positive("timeout", timeout, "s")
    try:
        connected = Client(client, timeout=seconds)
    except (OSError, TimeoutError) as error:
        raise _checks.fail(
            "scheduler", client, "the address of a running Dask scheduler",
            remedy=f"none answered within {seconds:g} s ({type(error).__name__}); start one "
            "with `dask scheduler` and its workers with `dask worker ADDRESS`",
        ) from None  # fmt: skip
    with connected:
        yield connected
