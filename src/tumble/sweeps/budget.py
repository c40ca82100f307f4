"""What a sweep will take, from its plan alone: the store on disk, the client's memory, a task's.

:func:`estimate` sizes a :class:`~tumble.sweeps.plan.Plan` before anything runs, and
:func:`check_fits` refuses one that cannot fit, naming the numbers and what to change (as
``tumble run --h 1e-9`` is refused by the size of its record):

* the store, every variable of every member uncompressed (Zarr compresses; the estimate is
  the most it can take), against the free space of the disk it goes to;
* the client, which holds each task's future and the scheduler's record of it (a local
  cluster's scheduler runs in the client's process), the members' done flags when it reads
  them, and a table of samples, against :data:`CLIENT_SHARE` of the machine's memory;
* one task, which holds its members' runs and their stored arrays at once
  (:data:`TASK_COPIES` copies of its output), against :data:`WORKER_SHARE` of the smallest
  worker's memory limit (checked once the cluster is known, still before any member runs).
"""

from __future__ import annotations

import math
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from tumble._checks import _byte_size as size
from tumble.sweeps.plan import RIGID, Plan
from tumble.sweeps.variables import VARIABLES, WALL_TIME, member_bytes

TASK_CLIENT_BYTES = 20_000
"""The client's memory per task (bytes): its future, its key and the scheduler's state for
it. Measured: 2000 and 20000 tasks added 16 and 13 kB a task to the resident memory of the
process that holds them and a local cluster's scheduler; rounded up."""
MEMBER_CLIENT_BYTES = 16
"""The client's memory per member (bytes): the done flags read on resume and at the end, as
uint8 and as booleans, and the summary the command line prints (status, int8)."""
SAMPLE_VALUE_BYTES = 40
"""A value of a table of samples, as a Python number in a list (bytes)."""
TASK_COPIES = 3
"""How many copies of its output a task holds at its peak: the runs' arrays, the member
rows they are copied into, and xarray's array as it writes the region."""
CLIENT_SHARE = 0.5
"""A sweep is refused when its client would need more than this share of the memory."""
WORKER_SHARE = 0.5
"""A task is refused when it would hold more than this share of a worker's memory limit
(a Dask worker is restarted at 95 % of it, and would fail again)."""


@dataclass(frozen=True)
class Estimate:
    """The sizes of a sweep, from its plan (bytes).

    Attributes
    ----------
    members, tasks : int
        The members and the tasks they are cut into.
    member : int
        One member's stored bytes (its series and summary variables).
    store : float
        The store, uncompressed: at most this much on disk.
    client : float
        The client's memory for the sweep (beyond its own start-up).
    task : float
        One task's memory at its peak.
    """

    members: int
    tasks: int
    member: int
    store: float
    client: float
    task: float

    def text(self) -> str:
        """One line for the terminal: members, tasks, store, client and task sizes."""
        return (
            f"{self.members} members in {self.tasks} tasks: a store of at most "
            f"{size(self.store)} ({size(self.member)} a member), about {size(self.client)} "
            f"on the client and {size(self.task)} a task"
        )


def estimate(plan: Plan) -> Estimate:
    """The sizes of ``plan``'s sweep (for a built-in whose summary's numbers are not named
    yet, one number a member: a lower bound, checked again once they are)."""
    if plan.scenario == RIGID:
        rows = VARIABLES
        per_member = member_bytes(None if plan.time is None else len(plan.time), rows)
    else:
        numbers = max(len(plan.outputs), 1)
        per_member = member_bytes(None, {WALL_TIME: VARIABLES[WALL_TIME]}) * (numbers + 1)
    per_member += 1  # the done flag
    tasks = math.prod(math.ceil(n / c) for n, c in zip(plan.shape, plan.chunks, strict=True))
    per_task = math.prod(plan.chunks)
    table = plan.size * len(plan.values) if plan.samples else sum(map(len, plan.values))
    return Estimate(
        members=plan.size,
        tasks=tasks,
        member=per_member,
        store=float(plan.size) * per_member,
        client=float(tasks) * TASK_CLIENT_BYTES
        + float(plan.size) * MEMBER_CLIENT_BYTES
        + float(table) * SAMPLE_VALUE_BYTES,
        task=float(per_task) * per_member * TASK_COPIES,
    )


def check_fits(plan: Plan, store: str | Path, memory: float | None = None) -> Estimate:
    """Refuse a sweep whose store cannot fit on its disk or whose client cannot fit in memory.

    Parameters
    ----------
    plan : Plan
    store : str or Path
        Where the store goes (its disk's free space is measured at its nearest existing
        folder).
    memory : float, optional
        The memory the client may use (bytes); default: the machine's.

    Returns
    -------
    Estimate

    Raises
    ------
    ValueError
        Naming the sizes, the room there is and what to change.
    """
    found = estimate(plan)
    free = free_space(store)
    shape = " x ".join(map(str, plan.shape))
    if found.store > free:
        raise ValueError(
            f"the sweep's store would take up to {size(found.store)}: {found.members} members "
            f"({shape}) of {size(found.member)} each, more than the {size(free)} free at "
            f"{nearest_folder(store)}; sweep fewer members, store fewer samples a member "
            "(a larger record_every or h, a shorter t_end), or write the store elsewhere "
            "(--out)"
        )
    allowed = CLIENT_SHARE * (machine_memory() if memory is None else memory)
    if found.client > allowed:
        raise ValueError(
            f"the sweep's client would need about {size(found.client)} for {found.tasks} "
            f"tasks of {found.members} members ({shape}), more than the {size(allowed)} "
            f"(half of this machine's memory) it may use; sweep fewer members, or give larger "
            "tasks (chunk, --chunk)"
        )
    return found


def check_task(plan: Plan, worker_memory: float) -> None:
    """Refuse tasks that would hold more than :data:`WORKER_SHARE` of ``worker_memory``."""
    found = estimate(plan)
    allowed = WORKER_SHARE * worker_memory
    if found.task <= allowed:
        return
    members = math.prod(plan.chunks)
    fitting = math.floor(allowed / (found.member * TASK_COPIES))
    remedy = (
        f"give smaller tasks: chunk (--chunk) at most {fitting}"
        if fitting >= 1
        else "one member alone is too large: store fewer samples a member (a larger "
        "record_every or h, a shorter t_end)"
    )
    raise ValueError(
        f"a task of {members} members would hold about {size(found.task)} "
        f"({size(found.member)} a member, {TASK_COPIES} copies), more than the "
        f"{size(allowed)} (half of a worker's memory limit, {size(worker_memory)}) it may "
        f"use; {remedy}"
    )


def nearest_folder(path: str | Path) -> Path:
    """``path`` or its nearest ancestor that exists."""
    folder = Path(path).absolute()
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    return folder


def free_space(path: str | Path) -> float:
    """Free bytes on the disk that ``path`` is (or would be) on; inf if the system does not
    say."""
    try:
        return float(shutil.disk_usage(nearest_folder(path)).free)
    except OSError:
        return math.inf


def machine_memory() -> float:
    """The memory this process may use: the machine's, or a container's limit (bytes)."""
    from distributed.system import MEMORY_LIMIT

    return float(MEMORY_LIMIT)


def store_path(store: object) -> Path:
    """The store as a path: a non-empty str or path (None, a number… are refused)."""
    from tumble import _checks

    if not isinstance(store, str | os.PathLike) or not str(store):
        raise _checks.fail("store", store, "a path (str or pathlib.Path) of a folder to write",
                           remedy="for example store='runs/sweep.zarr'")  # fmt: skip
    return Path(store)


def check_writable(path: Path) -> None:
    """Refuse a store whose folder cannot be made, with the system's reason (its parent is
    made, and a folder is made and removed in it)."""
    from tumble import _checks

    parent = path.absolute().parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        probe = parent / f".{path.name}.tumble-write-check"
        probe.mkdir()
        probe.rmdir()
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise _checks.fail(
            "store", str(path), "a folder that can be created",
            remedy=f"{parent} cannot hold it ({reason}); choose another place",
        ) from None  # fmt: skip
