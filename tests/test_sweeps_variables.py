"""The stored variables of a rigid-body sweep: one row each, the same for a batch and a run.

No Dask here: the members run in this process (:func:`run_members`) and the store is written
with the functions a task uses.
"""

import itertools

import numpy as np
import pytest
import xarray as xr

from tumble.rigid import RigidBody, simulate, simulate_batch
from tumble.scenarios import rigid_body
from tumble.sweeps import make_plan
from tumble.sweeps.members import run_members
from tumble.sweeps.plan import CHUNK_BYTES, MAX_CHUNK
from tumble.sweeps.store import write_region, write_template
from tumble.sweeps.variables import SERIES, SUMMARY, VARIABLES, Runs, member_bytes

BODY = {"shape": "box", "extents": [0.3, 0.2, 0.1], "mass": 2.0}
BASE = {"body": BODY, "initial": {"omega0": [0.1, 20.0, 0.1]}, "h": 0.01, "t_end": 0.6}


def all_members(plan) -> list[tuple[int, ...]]:
    return list(itertools.product(*map(range, plan.shape)))


@pytest.mark.parametrize("method", ["rkmk4", "rkmk45"])
def test_member_bytes_are_the_bytes_of_a_written_store(tmp_path, method):
    """rkmk4: series and summary; rkmk45 (steps of its own): the summary alone."""
    options = {**BASE, "method": method, "h": 0.01 if method == "rkmk4" else None}
    plan = make_plan(options, {"omega0.2": [0.1, 0.2, 0.3]})
    store = tmp_path / "s.zarr"
    write_template(plan, store)
    for task in plan.tasks():
        region = plan.region(task)
        indices = list(itertools.product(*(range(s.start, s.stop) for s in region.values())))
        write_region(plan, store, task, run_members(plan, indices))
    with xr.open_zarr(store) as ds:
        stored = sum(ds[name].nbytes for name in VARIABLES if name in ds.data_vars)
        assert set(ds.data_vars) - {"done"} == set(VARIABLES if plan.time is not None else SUMMARY)
    n_times = None if plan.time is None else len(plan.time)
    assert stored == plan.size * member_bytes(n_times)


def test_default_chunk_is_the_chunk_bytes_over_a_members_bytes():
    plan = make_plan({**BASE, "t_end": 30.0}, {"omega0.2": list(np.linspace(0.0, 1.0, 5000))})
    assert len(plan.time) == 3001
    expected = CHUNK_BYTES // member_bytes(3001)
    assert 1 < expected < MAX_CHUNK and plan.chunks == (expected,)


def test_a_swept_step_stores_no_series_and_sizes_the_chunk_by_the_summary():
    plan = make_plan(BASE, {"h": [0.01, 0.02]})
    assert plan.time is None
    assert member_bytes(None) == sum(row.sample_bytes() for row in SUMMARY.values())


def test_a_run_is_a_batch_of_one():
    """Every row of a simulate run equals its row of the simulate_batch of the same starts."""
    body = RigidBody(1.0, [1.0, 2.0, 3.0])
    spins = np.array([[0.1, 2.0, 0.05], [2.0, 0.1, 0.05]])
    batch = Runs.from_batch(simulate_batch(body, 20.0, h=0.01, omega0=spins))
    for k, spin in enumerate(spins):
        alone = Runs.from_trajectory(simulate(body, 20.0, h=0.01, omega0=spin))
        for name, row in VARIABLES.items():
            if row.compute is None:
                continue
            np.testing.assert_allclose(row.compute(alone)[0], row.compute(batch)[k],
                                       rtol=1e-12, err_msg=name)  # fmt: skip
    assert np.isfinite(VARIABLES["flip_period"].compute(batch)).all()


@pytest.mark.parametrize("name", sorted(VARIABLES))
def test_each_row_computes_its_declared_shape_and_dtype(name):
    row = VARIABLES[name]
    body = RigidBody(1.0, [1.0, 2.0, 3.0])
    batch = simulate_batch(body, 1.0, h=0.1, omega0=[[0.0, 1.0, 0.1]] * 2)
    if row.compute is None:  # the task's clock
        assert name == "wall_time"
        return
    values = np.asarray(row.compute(Runs.from_batch(batch)))
    extra = tuple(3 for _ in row.extra)
    assert values.shape == ((2, len(batch.t), *extra) if row.series else (2, *extra))
    assert np.can_cast(values.dtype, row.dtype, casting="same_kind"), (values.dtype, row.dtype)


def test_series_are_the_runs_own_arrays():
    assert set(SERIES) == {"x", "v", "R", "L_world", "omega_body", "energy"}
    assert not set(SERIES) & set(SUMMARY)


def test_a_member_run_alone_stores_the_scenarios_own_numbers():
    """An impulse stops batching: each member runs alone and fills its own samples."""
    kick = {"type": "impulse", "impulse": [0.0, 0.5, 4.0], "point": [0.05, 0.0, -0.05]}
    options = {**BASE, "loads": [kick]}
    plan = make_plan(options, {"impulse.impulse.2": [1.0, 4.0]})
    values = run_members(plan, all_members(plan))
    for k, push in enumerate([1.0, 4.0]):
        loads = [{**kick, "impulse": [0.0, 0.5, push]}]
        trajectory = rigid_body.run(**{**options, "loads": loads}).data["trajectory"]
        n = len(trajectory.t)
        assert np.array_equal(values["R"][k, :n], trajectory.R)
        assert values["energy_error"][k] == abs(trajectory.energy[-1] / trajectory.energy[0] - 1)
