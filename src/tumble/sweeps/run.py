"""``sweep``: check, connect, write the template, run the tasks on Dask, return the dataset."""

from __future__ import annotations

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
from tumble.sweeps import budget
from tumble.sweeps.budget import Estimate
from tumble.sweeps.members import echoes, probes, run_members, summary_names
from tumble.sweeps.plan import RIGID, Plan, make_plan
from tumble.sweeps.store import (
    check_existing,
    done_flags,
    pending_tasks,
    write_region,
    write_template,
)

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


def _probe(plan: Plan, index: tuple[int, ...]) -> list[str]:
    """A first run's summary numbers (:func:`~tumble.sweeps.members.summary_names`), as a
    Dask worker runs it."""
    with _threads():
        return summary_names(plan, index)


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
    # the client says what the sweep is doing: a worker's word of its kernels compiling
    # would scroll over the client's bar (the workers share its terminal)
    logging.getLogger("tumble.compile").setLevel(logging.WARNING)
    before = numba.get_num_threads()
    numba.set_num_threads(max(1, min(wanted, numba.config.NUMBA_NUM_THREADS)))
    try:
        yield
    finally:
        numba.set_num_threads(before)


class Interrupted(KeyboardInterrupt):
    """A sweep stopped by Ctrl-C (or SIGTERM, on the command line): what the store holds.

    A :class:`KeyboardInterrupt`, so it stops a program as one does; the members done are in
    the store, whole (a member's ``done`` flag is written after its data), and ``resume=True``
    runs the others.

    Attributes
    ----------
    done, total : int
        Members done, and in the sweep.
    store : str
        The store.
    written : bool
        Whether the store was written (False: stopped before it was, nothing to resume).
    """

    def __init__(self, done: int, total: int, store: str, written: bool = True) -> None:
        said = (
            f"interrupted: {done} of {total} members done; complete with resume=True"
            if written
            else "interrupted before the store was written: nothing to resume"
        )
        super().__init__(said)  # fmt: skip
        self.done, self.total, self.store, self.written = done, total, store, written


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
    on_plan: Callable[[Plan, Estimate], None] | None = None,
):
    """Run a scenario over a grid (or a table) of options on Dask, into one Zarr store.

    Each member is the scenario run with its options, :func:`tumble.rigid.simulate`'s
    numbers bit for bit (members that differ only in their initial state run together through
    :func:`tumble.rigid.simulate_batch`). The members are cut into tasks of ``chunk``
    members; each task writes its own region of the store, then its completion flags
    (:mod:`tumble.sweeps.store`).

    Everything is checked before any member runs: the grid, the store's place, its size
    against the disk's free space, the client's and a task's memory
    (:mod:`tumble.sweeps.budget`), and for a built-in scenario the numbers its summary has,
    named by a first run of each combination of the swept values that are not real numbers
    (:func:`~tumble.sweeps.members.probes`): the store's variables are those of every
    member, and a member marked done holds its numbers.

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
        ``progress(members_done, members_total)`` before the first task and after each.
    on_plan : callable, optional
        ``on_plan(plan, estimate)`` as soon as the store's variables are known, before any
        member of the sweep runs (:class:`~tumble.sweeps.budget.Estimate`: the sizes): for a
        ``rigid-body`` sweep before the cluster starts, for a built-in after its first runs
        have named its numbers. A :class:`ValueError` it raises refuses the sweep, with
        nothing written.

    Returns
    -------
    xarray.Dataset
        The store, opened with ``xr.open_zarr`` (lazy).

    Raises
    ------
    ValueError
        Before any work: an unknown option path, a bad value, an empty grid, a store that
        cannot be made, an existing store without ``resume`` (or of another sweep), a sweep
        too large for the disk or the memory, a scheduler address that does not answer
        within ``timeout``.
    Interrupted
        On Ctrl-C: with the members done (a :class:`KeyboardInterrupt`).
    """
    path = budget.store_path(store)
    resume = _checks.flag("resume", resume)
    for name, hook in (("progress", progress), ("on_plan", on_plan)):
        if hook is not None and not callable(hook):
            raise _checks.fail(name, hook, "a callable or None")
    if client is not None and not isinstance(client, str) and not hasattr(client, "submit"):
        raise _checks.fail("client", client, "a distributed.Client, a scheduler's address "
                           "(str) or None (a local cluster)")  # fmt: skip
    seconds = _checks.positive("timeout", timeout, "s")
    plan = make_plan(scenario, grid, samples, chunk=chunk)
    exists = path.exists()
    if exists and not resume:
        raise _checks.fail(
            "store", str(store), "a path that does not exist yet",
            remedy="pass resume=True (--resume) to complete it, or choose another store",
        )  # fmt: skip
    if exists:
        check_existing(plan, path)
    else:
        budget.check_writable(path)
    found = budget.check_fits(plan, path)
    if plan.scenario == RIGID and on_plan is not None:  # its variables are known: say so now
        on_plan(plan, found)
    try:
        with _client(client, seconds) as dask_client:
            budget.check_task(plan, _worker_memory(dask_client))
            if plan.scenario != RIGID:
                plan = _named(plan, dask_client)
                found = budget.check_fits(plan, path)
                if on_plan is not None:
                    on_plan(plan, found)
            log.info("sweep: %s", found.text())
            _run(plan, str(path), dask_client, exists, progress)
    except KeyboardInterrupt:
        written = (path / "done").exists()
        done = int(done_flags(path).sum()) if written else 0
        raise Interrupted(done, plan.size, str(path), written) from None
    import xarray as xr

    return xr.open_zarr(path)


def _run(plan: Plan, store: str, dask_client: Any, exists: bool, progress) -> None:
    """Write the template (a new store) and run the pending tasks, each once."""
    from distributed import as_completed

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
        dask_client.submit(run_task, shared, store, task, key=_key(token, task)) for task in tasks
    ]
    try:
        for future in as_completed(futures):
            done += future.result()
            future.release()
            if progress is not None:
                progress(done, plan.size)
    except BaseException:
        dask_client.cancel(futures)  # a remote cluster keeps no work of this client
        raise


def _worker_memory(dask_client: Any) -> float:
    """The smallest memory limit of the cluster's workers (bytes; the machine's when they
    set none)."""
    limits = [w.get("memory_limit") or 0 for w in dask_client.scheduler_info()["workers"].values()]
    known = [limit for limit in limits if limit > 0]
    return float(min(known)) if known else budget.machine_memory()


def _named(plan: Plan, dask_client: Any) -> Plan:
    """A built-in's plan with its outputs: every number of its members' summaries.

    The members of :func:`~tumble.sweeps.members.probes` (one per combination of the swept
    values that may change the summary's keys) run first, on the cluster, before the
    template is written; their tasks run them again.
    """
    first = probes(plan)
    log.info("sweep: running %d first member(s) to name the summary's numbers", len(first))
    shared = dask_client.scatter(plan, broadcast=True)
    futures = [dask_client.submit(_probe, shared, index, pure=False) for index in first]
    skipped = echoes(plan)
    names: dict[str, None] = {}
    for found in dask_client.gather(futures):
        names.update(dict.fromkeys(name for name in found if name not in skipped))
    return dataclasses.replace(plan, outputs=tuple(names))


def _key(token: str, task: tuple[int, ...]) -> str:
    """The task's name on the dashboard: ``tumble-sweep-<run>-<block index>``."""
    return f"tumble-sweep-{token}-" + "-".join(map(str, task))


def _members(plan: Plan, task: tuple[int, ...]) -> int:
    size = 1
    for part in plan.region(task).values():
        size *= part.stop - part.start
    return size


@contextmanager
def _workers_ignore_interrupts():
    """SIGINT ignored while a local cluster starts its worker processes, which inherit it.

    Ctrl-C at a terminal goes to every process of the foreground group: the workers would
    each print a traceback. Ignoring it, they leave it to the client, which stops them and
    says what the store holds (:class:`Interrupted`). A Ctrl-C during the start itself is
    lost (a second or two); off the main thread, signals are left alone.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


@contextmanager
def _client(client: Any, timeout: float):
    """The Dask client to use: the one given, one connected to an address, or a local one."""
    from distributed import Client, LocalCluster

    if client is not None and not isinstance(client, str):
        yield client
        return
    if client is None:
        workers = os.cpu_count() or 1
        with _workers_ignore_interrupts():
            cluster = LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0"
            )
        with cluster, Client(cluster) as local:
            yield local
        return
    seconds = timeout
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
