"""Faults: a scheduler and two workers as separate processes on 127.0.0.1, killed mid-sweep.

* the client (``tumble sweep`` in its own process) killed with SIGKILL: ``--resume`` runs only
  the members not done, and every member ends done and equal to its serial run;
* one worker process killed with SIGKILL: the sweep completes on the other, every member
  equal to its serial run.

Every process started here is killed (its whole process group) when the module ends.
"""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import tumble
from tumble.scenarios import rigid_body

DASK = Path(sys.executable).with_name("dask")
TUMBLE = Path(sys.executable).with_name("tumble")
OPTIONS = {
    "body": {"shape": "box", "extents": [0.3, 0.2, 0.1], "mass": 2.0},
    "initial": {"omega0": [0.1, 20.0, 0.1]},
    "h": 0.001,
    "t_end": 8.0,
    "record_every": 400,
}
"""About 10 ms a member: long enough to be killed mid-sweep, short for the suite."""
SPINS = np.linspace(0.05, 1.0, 24).tolist()


def start(args: list, log: Path) -> subprocess.Popen:
    """A process in its own group (so that killing the group leaves nothing behind)."""
    with log.open("w") as out:  # the child keeps its own descriptor
        return subprocess.Popen(args, stdout=out, stderr=subprocess.STDOUT, start_new_session=True)


def kill(process: subprocess.Popen) -> None:
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGKILL)
    process.wait(timeout=10)


def wait_for(condition, seconds: float, what: str) -> None:
    end = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > end:
            raise AssertionError(f"{what}: not within {seconds} s")
        time.sleep(0.05)


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """``dask scheduler`` and two ``dask worker`` processes (no nanny), on 127.0.0.1."""
    folder = tmp_path_factory.mktemp("cluster")
    address_file = folder / "scheduler.json"
    processes = [
        start([DASK, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
               "--scheduler-file", address_file], folder / "scheduler.log")
    ]  # fmt: skip
    try:
        wait_for(address_file.exists, 30, "the scheduler's address file")
        address = json.loads(address_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for k in range(2):
            processes.append(
                start([DASK, "worker", address, "--nthreads", "1", "--no-nanny",
                       "--host", "127.0.0.1", "--no-dashboard"], folder / f"worker{k}.log")
            )  # fmt: skip
        from distributed import Client

        with Client(address, timeout=30) as client:
            client.wait_for_workers(2, timeout=30)
        yield address, processes[1:]
    finally:
        for process in processes:
            kill(process)


def serial(spin: float):
    return rigid_body.run(**{**OPTIONS, "initial": {"omega0": [0.1, 20.0, spin]}}).data[
        "trajectory"
    ]


def assert_every_member_is_its_serial_run(ds: xr.Dataset) -> None:
    assert ds["done"].values.all()
    for spin in SPINS:
        member, trajectory = ds.sel({"omega0.2": spin}), serial(spin)
        for name in ("R", "L_world", "x", "omega_body"):
            assert np.array_equal(member[name].values, getattr(trajectory, name)), (spin, name)


def test_killed_client_is_resumed_without_losing_or_redoing_members(cluster, tmp_path):
    address, _ = cluster
    scenario = tmp_path / "box.toml"
    scenario.write_text(
        'scenario = "rigid-body"\n[options]\nh = 0.001\nt_end = 8.0\nrecord_every = 400\n'
        '[options.body]\nshape = "box"\nextents = [0.3, 0.2, 0.1]\nmass = 2.0\n'
        "[options.initial]\nomega0 = [0.1, 20.0, 0.1]\n"
    )
    store = tmp_path / "s.zarr"
    grid = ["--grid", "omega0.2=" + ",".join(map(repr, SPINS))]
    args = [TUMBLE, "sweep", scenario, *grid, "--out", store, "--scheduler", address,
            "--chunk", "1"]  # fmt: skip
    client = start(args, tmp_path / "client.log")
    try:
        flags = store / "done"
        wait_for(lambda: len(list(flags.glob("[0-9]*"))) >= 3, 60, "three members done")
    finally:
        kill(client)
    assert client.returncode == -signal.SIGKILL
    time.sleep(1.0)  # tasks already running on the workers finish (their writes are whole)
    before = xr.open_zarr(store).load()
    done = before["done"].values.astype(bool)
    assert 3 <= done.sum() < len(SPINS), done.sum()  # killed mid-sweep
    resumed = subprocess.run([*args, "--resume"], capture_output=True, text=True, timeout=120)
    assert resumed.returncode == 0, resumed.stdout + resumed.stderr
    after = xr.open_zarr(store)
    # members done before the kill were not run again: their wall times are unchanged
    assert np.array_equal(after["wall_time"].values[done], before["wall_time"].values[done])
    assert_every_member_is_its_serial_run(after)


def test_killed_worker_leaves_the_sweep_to_the_other(cluster, tmp_path):
    address, workers = cluster
    killed: list[int] = []

    def progress(done: int, total: int) -> None:
        if done >= 2 and not killed:
            os.killpg(workers[0].pid, signal.SIGKILL)
            killed.append(done)

    ds = tumble.sweep(OPTIONS, {"omega0.2": SPINS}, client=address, store=tmp_path / "s.zarr",
                      chunk=1, progress=progress)  # fmt: skip
    assert killed and killed[0] < len(SPINS)
    assert workers[0].wait(timeout=10) == -signal.SIGKILL
    from distributed import Client

    with Client(address, timeout=10) as client:
        assert len(client.scheduler_info()["workers"]) == 1
    assert_every_member_is_its_serial_run(ds)


def test_output_larger_than_the_worker_memory_limit_completes(tmp_path):
    """One worker limited to 800 MB writes 845 MB of members: each task writes its region
    and forgets it, so the worker is never restarted (same process before and after).

    The limit leaves room for a worker that compiles the kernels itself (a fresh clone: about
    330 MB resident before any member), and pausing is off: a paused worker that holds no
    data never resumes, and the sweep would wait for ever. Terminating at 95 % stays on."""
    import dask
    from distributed import Client, LocalCluster

    limit = 800e6
    members = 2400  # x 2001 samples x 176 bytes: 845 MB
    options = {**OPTIONS, "h": 0.005, "t_end": 10.0, "record_every": 1}
    with (
        dask.config.set({"distributed.worker.memory.pause": False}),
        LocalCluster(n_workers=1, threads_per_worker=1, memory_limit=limit,
                     dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):  # fmt: skip
        before = client.run(os.getpid)
        spins = np.linspace(0.0, 1.0, members)
        ds = tumble.sweep(options, {"omega0.2": spins}, client=client, store=tmp_path / "s.zarr")
        assert client.run(os.getpid) == before
    assert ds.nbytes > limit
    assert ds["done"].values.all()
    trajectory = rigid_body.run(**{**options, "initial": {"omega0": [0.1, 20.0, 1.0]}}).data[
        "trajectory"
    ]
    assert np.array_equal(ds["R"].isel({"omega0.2": -1}).values, trajectory.R)


def test_ctrl_c_says_what_is_done_and_exits_130_without_a_traceback(tmp_path):
    """SIGINT to the command's whole process group, as Ctrl-C at a terminal sends it (to the
    client and the local cluster's workers): one line says how many members are done, exit
    130, and nothing else on stderr (no worker's traceback, no Dask log line, no leaked
    semaphore); the count is the store's."""
    scenario = tmp_path / "box.toml"
    scenario.write_text(
        'scenario = "rigid-body"\n[options]\nh = 0.001\nt_end = 8.0\nrecord_every = 400\n'
        '[options.body]\nshape = "box"\nextents = [0.3, 0.2, 0.1]\nmass = 2.0\n'
        "[options.initial]\nomega0 = [0.1, 20.0, 0.1]\n"
    )
    store = tmp_path / "s.zarr"
    args = [TUMBLE, "sweep", scenario, "--grid", "omega0.2=0:1:400", "--out", store,
            "--chunk", "1"]  # fmt: skip
    process = subprocess.Popen(
        args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True,
        # SIGINT as at a terminal even where the tests were started with it ignored
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )  # fmt: skip
    try:
        flags = store / "done"
        wait_for(lambda: len(list(flags.glob("[0-9]*"))) >= 3, 120, "three members done")
        os.killpg(process.pid, signal.SIGINT)
        out, err = process.communicate(timeout=60)
    finally:
        kill(process)
    done = int(xr.open_zarr(store)["done"].sum())
    assert 3 <= done < 400
    assert process.returncode == 130, err.decode()
    assert err.decode().strip() == (
        f"interrupted: {done} of 400 members done; complete with `--resume`"
    )
    assert "Traceback" not in out.decode()
