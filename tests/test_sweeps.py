"""tumble.sweep on a real LocalCluster of two worker processes: members, store, resume, refusals.

Every member is compared with the scenario run alone (``rigid_body.run``, which calls
``simulate``) with np.array_equal: bit for bit, not to a tolerance. That holds on any machine:
worker and test run the same numba loop (no fastmath: no FMA, no reassociation) on the same
numbers, and the same NumPy functions on its records.
"""

import json
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import tumble
from tumble.rigid.batch import FIXED_METHODS
from tumble.scenarios import rigid_body
from tumble.sweeps import make_plan
from tumble.sweeps.store import write_region, write_template
from tumble.sweeps.variables import SERIES, SUMMARY

EXAMPLES = Path(__file__).parents[1] / "examples"
BODY = {"shape": "box", "extents": [0.3, 0.2, 0.1], "mass": 2.0}
"""A box with three distinct moments: its spin about y (intermediate) flips."""


@pytest.fixture(scope="module")
def client():
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as dask_client,
    ):
        yield dask_client


def tiny(**options):
    """A free box spun near its intermediate axis for 0.6 s."""
    base = {"body": BODY, "initial": {"omega0": [0.1, 20.0, 0.1]}, "h": 0.01, "t_end": 0.6}
    return {**base, **options}


def alone(options: dict):
    """The member's options run as the scenario runs them: one simulate call."""
    return rigid_body.run(**options).data["trajectory"]


def assert_member_equals(ds: xr.Dataset, where: dict, options: dict) -> None:
    trajectory = alone(options)
    member = ds.sel(where)
    assert np.array_equal(ds["time"].values, trajectory.t)
    for name in SERIES:
        assert np.array_equal(member[name].values, getattr(trajectory, name)), (where, name)
    assert int(member["status"]) == trajectory.status
    assert int(member["n_steps"]) == trajectory.n_steps
    assert int(member["done"]) == 1


def test_members_equal_single_simulate_runs_bit_for_bit(client, tmp_path):
    spins = [0.05, 3.0]
    ds = tumble.sweep(
        tiny(), {"omega0.2": spins, "method": FIXED_METHODS}, client=client,
        store=tmp_path / "s.zarr", chunk=3,
    )  # fmt: skip
    for spin in spins:
        for method in FIXED_METHODS:
            options = tiny(method=method, initial={"omega0": [0.1, 20.0, spin]})
            assert_member_equals(ds, {"omega0.2": spin, "method": method}, options)


def test_members_with_an_impulse_equal_single_runs(client, tmp_path):
    """An impulse cannot be batched: the task runs each member through simulate."""
    kick = {"type": "impulse", "impulse": [0.0, 0.5, 6.0], "point": [0.05, 0.0, -0.05]}
    gravity = {"type": "gravity", "g": [0.0, 0.0, -9.81]}
    samples = {"impulse.impulse.2": [1.0, 4.0, 6.0], "method": ["rkmk4", "rkmk45", "rk4-quat"]}
    base = tiny(loads=[gravity, kick], initial={}, rtol=None)
    ds = tumble.sweep(base, samples=samples, client=client, store=tmp_path / "s.zarr")
    assert "time" not in ds.dims  # rkmk45's steps are its own: no shared time axis
    assert ds.attrs["series"].startswith("not stored")
    for k, (push, method) in enumerate(zip(*samples.values(), strict=True)):
        loads = [gravity, {**kick, "impulse": [0.0, 0.5, push]}]
        trajectory = alone({**base, "loads": loads, "method": method})
        member = ds.sel(member=k)
        assert int(member["n_steps"]) == trajectory.n_steps
        final = trajectory.energy[-1] / trajectory.energy[0] - 1
        assert float(member["energy_error"]) == abs(final)


def test_store_opens_as_one_dataset_with_the_documented_dimensions(client, tmp_path):
    grid = {"omega0.1": [18.0, 20.0, 22.0]}
    tumble.sweep(tiny(), grid, client=client, store=tmp_path / "s.zarr")
    ds = xr.open_zarr(tmp_path / "s.zarr")
    assert dict(ds.sizes) == {"omega0.1": 3, "time": 61, "axis": 3, "row": 3, "col": 3}
    assert ds["R"].dims == ("omega0.1", "time", "row", "col")
    assert ds["energy_error"].dims == ("omega0.1",)
    assert ds["omega0.1"].attrs["option_path"] == "initial.omega0.1"
    for name in [*SERIES, *SUMMARY]:
        assert {"units", "long_name"} <= set(ds[name].attrs), name
    assert json.loads(ds.attrs["grid"])["omega0.1"]["values"] == grid["omega0.1"]
    assert ds.attrs["tumble_version"] == tumble.__version__
    assert len(ds.attrs["scenario_sha256"]) == 64


def test_flip_period_is_the_exact_period(client, tmp_path):
    """The box spun near its intermediate axis: the measured period is the elliptic one."""
    options = tiny(t_end=3.0, h=0.002)
    spins = [0.2, 0.5]
    ds = tumble.sweep(options, {"omega0.0": spins}, client=client, store=tmp_path / "s.zarr")
    body = alone(options).body
    for spin in spins:
        exact = tumble.exact.free_body_period(body.inertia, [spin, 20.0, 0.1])
        measured = float(ds["flip_period"].sel({"omega0.0": spin}))
        assert abs(measured / exact - 1) < 1e-3, (spin, measured, exact)


def test_resume_redoes_a_half_written_task_and_skips_done_ones(client, tmp_path):
    store = tmp_path / "s.zarr"
    grid = {"omega0.2": [0.1, 0.2, 0.3, 0.4]}
    plan = make_plan(tiny(), grid, chunk=2)
    write_template(plan, store)
    first, second = plan.tasks()
    # task 1 done, but with a marked wall time; task 2 half-written: data, no done flag
    values = {name: np.full((2, 61, *(3,) * len(SERIES[name][0])), 7.0) for name in SERIES}
    summary = {"status": np.zeros(2, "int8"), "n_steps": np.zeros(2, "int64")}
    marked = {**values, **summary, "energy_error": np.zeros(2), "flip_period": np.zeros(2),
              "wall_time": np.full(2, -1.0)}  # fmt: skip
    write_region(plan, store, first, marked)
    xr.Dataset({"x": (("omega0.2", "time", "axis"), values["x"])}).to_zarr(
        store, region=plan.region(second), mode="r+"
    )
    ds = tumble.sweep(tiny(), grid, client=client, store=store, chunk=2, resume=True)
    assert (ds["wall_time"].values[:2] == -1.0).all()  # done: not run again
    for spin in grid["omega0.2"][2:]:
        options = tiny(initial={"omega0": [0.1, 20.0, spin]})
        assert_member_equals(ds, {"omega0.2": spin}, options)


@pytest.mark.parametrize(
    ("grid", "message"),
    [
        ({"omega9.1": [1.0]}, r"grid key 'omega9.1' is not an option path.*allowed: .*omega0"),
        ({"omega0.1": ["fast"]}, r"grid key 'omega0.1', value 'fast'.*must be a number"),
        ({"h": [-0.01]}, r"grid key 'h', value -0.01: options.h = -0.01: must be > 0"),
        ({"omega0.3": [1.0]}, r"has 3 entries, so index 3 is not allowed: must be 0 to 2"),
        ({"method": ["rk99"]}, r"value 'rk99'.*must be one of .*rkmk4"),
        ({}, r"grid=\{\} is not allowed: must be a mapping of at least one option path"),
        ({"h": []}, r"grid\['h'\]=\[\] is not allowed: must be a non-empty list"),
    ],
)
def test_bad_grids_are_refused_before_any_work(tmp_path, grid, message):
    store = tmp_path / "s.zarr"
    with pytest.raises(ValueError, match=message):
        tumble.sweep(tiny(), grid, client="tcp://127.0.0.1:1", store=store)
    assert not store.exists()


def test_samples_as_rows_columns_or_a_table_give_one_plan():
    columns = {"omega0.1": [18.0, 19.0, 21.0], "method": ["rkmk4", "lie-euler", "rkmk4"]}
    rows = [dict(zip(columns, row, strict=True)) for row in zip(*columns.values(), strict=True)]
    by_columns, by_rows = make_plan(tiny(), samples=columns), make_plan(tiny(), samples=rows)
    assert by_columns.values == by_rows.values == (columns["omega0.1"], columns["method"])
    assert by_columns.dims == ("member",) and by_columns.shape == (3,)
    assert by_columns.paths == (("initial", "omega0", 1), ("method",))


@pytest.mark.parametrize(
    ("samples", "message"),
    [
        ({"h": [0.01, 0.02], "omega0.1": [1.0]}, r"samples=\{'h': 2, 'omega0.1': 1\} is not "
         r"allowed: must be columns of one length"),
        ([{"h": 0.01}, {"t_end": 1.0}], r"samples\[1\]=\{'t_end': 1.0\} is not allowed: must "
         r"be a row with keys \['h'\]"),
        ({"h": [0.01, float("nan")]}, r"grid key 'h', value nan: options.h = nan: must be a "
         r"finite number"),
        # a long column of floats is checked at once: the bad value is still named
        ({"omega0.1": np.r_[np.linspace(0.0, 1.0, 999), np.inf]}, r"grid key 'omega0.1', "
         r"value inf: options.initial.omega0\[1\] = inf: must be a finite number"),
    ],
)  # fmt: skip
def test_bad_samples_are_refused(samples, message):
    with pytest.raises(ValueError, match=message):
        make_plan(tiny(), samples=samples)


def test_tasks_are_blocks_of_the_grid_that_cover_every_member_once():
    plan = make_plan(tiny(), {"omega0.1": [1.0, 2.0, 3.0], "method": FIXED_METHODS}, chunk=4)
    covered = np.zeros(plan.shape, dtype=int)
    for task in plan.tasks():
        covered[tuple(plan.region(task).values())] += 1
    assert (covered == 1).all()
    assert plan.chunks == (1, 4)  # whole trailing rows first, then cut


def test_a_built_in_scenario_sweeps_its_summary_numbers(client, tmp_path):
    """A built-in by name: each member is run(**options), its summary's numbers stored."""
    from tumble.scenarios import t_handle

    grid = {"spins.0.1": [0.05, 0.1], "method": ["rkmk4", "split-axes"]}
    base = {"spins": [[1.0, 0.05, 0.0]], "t_end": 100.0, "h": 0.02}
    ds = tumble.sweep("t-handle", {**grid, "t_end": [100.0], "h": [0.02]}, client=client,
                      store=tmp_path / "s.zarr")  # fmt: skip
    assert ds.attrs["scenario"] == "t-handle"
    assert ds["spins.0.period_measured"].dims == ("spins.0.1", "method", "t_end", "h")
    for spin in grid["spins.0.1"]:
        for method in grid["method"]:
            options = {**base, "method": method, "spins": [[1.0, spin, 0.0]]}
            expected = t_handle.run(**options).summary["spins"][0]
            member = ds.sel({"spins.0.1": spin, "method": method, "t_end": 100.0, "h": 0.02})
            for name in ("period_measured", "energy_drift", "error_vs_exact"):
                assert float(member[f"spins.0.{name}"]) == expected[name], (spin, method, name)


def test_a_built_in_scenario_refuses_an_unknown_path(tmp_path):
    with pytest.raises(
        ValueError,
        match=r"grid key 'spinz.0' is not an option path of "
        r"scenario 't-handle'; allowed: h, method, rtol, spins, t_end",
    ):
        tumble.sweep("t-handle", {"spinz.0": [1.0]}, store=tmp_path / "s")
    assert not (tmp_path / "s").exists()


def test_an_existing_store_without_resume_is_refused(tmp_path):
    store = tmp_path / "s.zarr"
    store.mkdir()
    with pytest.raises(ValueError, match=r"store=.* must be a path that does not exist yet; "
                       r"pass resume=True"):  # fmt: skip
        tumble.sweep(tiny(), {"h": [0.01]}, client="tcp://127.0.0.1:1", store=store)


def test_a_silent_scheduler_address_is_refused_within_the_timeout(tmp_path):
    start = time.perf_counter()
    with pytest.raises(
        ValueError,
        match=r"scheduler='tcp://127.0.0.1:1' is not allowed: must "
        r"be the address of a running Dask scheduler; none answered within 2 s",
    ):
        tumble.sweep(tiny(), {"h": [0.01]}, client="tcp://127.0.0.1:1", store=tmp_path / "s",
                     timeout=2.0)  # fmt: skip
    assert time.perf_counter() - start < 2.0 + 3.0  # the timeout and the client's start
    assert not (tmp_path / "s").exists()


# ---------------------------------------------------------------------------------------
# The command line.


def scenario_file(folder: Path) -> Path:
    path = folder / "box.toml"
    path.write_text(
        'scenario = "rigid-body"\n[options]\nh = 0.01\nt_end = 0.6\n'
        '[options.body]\nshape = "box"\nextents = [0.3, 0.2, 0.1]\nmass = 2.0\n'
        "[options.initial]\nomega0 = [0.1, 20.0, 0.1]\n"
        '[sweep.grid]\nomega0.0 = "0.1:0.3:3"\nmethod = ["rkmk4", "lie-euler"]\n'
    )
    return path


def test_cli_sweeps_the_file_grid_and_draws_the_map(client, tmp_path):
    from typer.testing import CliRunner

    from tumble.cli import app

    out = tmp_path / "runs" / "box.zarr"
    args = ["sweep", str(scenario_file(tmp_path)), "--out", str(out), "--map", "energy_error"]
    result = CliRunner().invoke(app, [*args, "--scheduler", client.scheduler.address])
    assert result.exit_code == 0, result.output
    assert "members                   6 (3 x 2)" in result.output
    ds = xr.open_zarr(out)
    assert ds["done"].values.all()
    assert list(ds["method"].values) == ["rkmk4", "lie-euler"]
    options = tiny(method="lie-euler", initial={"omega0": [0.2, 20.0, 0.1]})
    assert_member_equals(ds, {"omega0.0": 0.2, "method": "lie-euler"}, options)
    assert (tmp_path / "runs" / "box-energy_error.png").stat().st_size > 10_000
    again = CliRunner().invoke(app, [*args, "--scheduler", client.scheduler.address])
    assert again.exit_code == 2
    assert "must be a path that does not exist yet; pass resume=True (--resume)" in again.output


@pytest.mark.parametrize(
    ("grid", "message"),
    [
        ("h", "--grid 'h': must be PATH=VALUES"),
        ("h=0.01:0.1", "grid h='0.01:0.1' is not allowed: must be start:stop:count"),
        ("omega0.x=1", "grid key 'omega0.x'"),
    ],
)
def test_cli_refuses_a_bad_grid_with_exit_code_2(tmp_path, grid, message):
    from typer.testing import CliRunner

    from tumble.cli import app

    args = ["sweep", str(scenario_file(tmp_path)), "--grid", grid, "--out", str(tmp_path / "s")]
    result = CliRunner().invoke(app, [*args, "--scheduler", "tcp://127.0.0.1:1"])
    assert result.exit_code == 2
    assert message in result.output
    assert not (tmp_path / "s").exists()


def test_flip_map_example_agrees_with_the_exact_period(client, tmp_path):
    """examples/flip_map.py: every measured period within 1e-6 of 4K(m)/λ (measured: 8e-8
    on 24 x 24; the crossings are located between samples 0.1 s apart)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("flip_map", EXAMPLES / "flip_map.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    numbers = module.run(tmp_path / "s.zarr", tmp_path / "map.png", size=3, client=client)
    assert numbers["members"] == 9
    assert numbers["largest_relative_difference"] < 1e-6
    assert np.isfinite(numbers["measured"]).all()
    assert (tmp_path / "map.png").stat().st_size > 20_000


def test_swept_attitude_under_gravity_equals_single_runs(client, tmp_path):
    """Each member's attitude from its own table; gravity is constant, so one batch."""
    gravity = [{"type": "gravity", "g": [0.0, 0.0, -9.81]}]
    start = {"euler_zyx": [0.0, 0.0, 0.0], "omega0": [1.0, 5.0, 0.1], "v0": [0.0, 0.0, 1.0]}
    base = tiny(loads=gravity, initial=start)
    grid = {"euler_zyx.2": [0.0, 0.3, 1.2], "v0.1": [0.0, 2.0]}
    ds = tumble.sweep(base, grid, client=client, store=tmp_path / "s.zarr")
    for angle in grid["euler_zyx.2"]:
        for speed in grid["v0.1"]:
            initial = {**base["initial"], "euler_zyx": [0.0, 0.0, angle], "v0": [0.0, speed, 1.0]}
            where = {"euler_zyx.2": angle, "v0.1": speed}
            assert_member_equals(ds, where, {**base, "initial": initial})


def test_batched_periods_equal_the_scenario_measure():
    """t_handle.measured_periods (telescoped, vectorised) is measured_period of each run."""
    from tumble import RigidBody, mass, simulate_batch
    from tumble.scenarios.t_handle import measured_period
    from tumble.scenarios.t_handle import measured_periods as periods

    body = RigidBody.from_mass_properties(mass.t_handle())
    spins = [[1.0, 0.05, 0.0], [1.0, 0.01, 0.08], [0.05, 0.0, 1.0], [0.0, 1.0, 0.05]]
    batch = simulate_batch(body, 100.0, h=0.05, omega0=spins)
    found = periods(batch.t, batch.omega_body)
    for k in range(len(spins)):
        expected, _, _ = measured_period(batch.t, batch.omega_body[k])
        assert found[k] == pytest.approx(expected, rel=1e-12)
    short = simulate_batch(body, 10.0, h=0.05, omega0=spins[:1])  # under one crossing pair
    assert np.isnan(periods(short.t, short.omega_body)).all()


# ---------------------------------------------------------------------------------------
# A built-in whose summary's keys depend on a swept option; sizes and places refused first.

TOP = {"t_end": [0.05]}
"""The spinning top over 50 steps: its summary's numbers, quickly."""


def test_a_swept_option_that_changes_the_summarys_keys_stores_every_members_numbers(
    client, tmp_path
):
    """The methods name the summary's keys (results.<method>.…): the store's variables are
    every member's, and each member holds the numbers of its own run."""
    from tumble.scenarios import spinning_top
    from tumble.sweeps.members import summary_numbers

    grid = {"tilt": [0.2, 0.3], "methods": [["yoshida4"], ["split-axes"]], **TOP}
    ds = tumble.sweep("spinning-top", grid, client=client, store=tmp_path / "s.zarr")
    for tilt in grid["tilt"]:
        for methods in grid["methods"]:
            where = {"tilt": tilt, "methods": json.dumps(methods), "t_end": 0.05}
            member = ds.sel(where)
            numbers = summary_numbers(spinning_top.run(tilt=tilt, methods=methods,
                                                       t_end=0.05).summary)  # fmt: skip
            for name, value in numbers.items():
                if name in ds.data_vars:
                    assert float(member[name]) == value or np.isnan(value), (where, name)
            method = methods[0]
            assert (
                float(member[f"results.{method}.energy_drift"])
                == numbers[f"results.{method}.energy_drift"]
            )
            other = {"yoshida4": "split-axes", "split-axes": "yoshida4"}[method]
            assert np.isnan(float(member[f"results.{other}.energy_drift"]))  # not its method
            assert int(member["done"]) == 1


def test_a_member_with_numbers_the_store_does_not_name_writes_nothing():
    """A task's member whose summary has keys no probe saw fails its task (no done flag)."""
    import dataclasses

    from tumble.sweeps.members import run_summaries

    plan = make_plan("spinning-top", {"methods": [["yoshida4"]], **TOP})
    partial = dataclasses.replace(plan, outputs=("mass",))
    with pytest.raises(ValueError, match=r"member \(methods=\['yoshida4'\], t_end=0.05\) of "
                       r"the sweep of 'spinning-top' has summary numbers the store has no "
                       r"variable for: .*results\.yoshida4\.t_reached"):  # fmt: skip
        run_summaries(partial, [(0, 0)])


def test_probes_run_one_member_per_combination_of_the_values_that_are_not_real_numbers():
    from tumble.sweeps.members import MAX_PROBES, probes

    grid = {"tilt": [0.2, 0.3, 0.4], "methods": [["rkmk4"], ["yoshida4"], ["rkmk4"]],
            "h": [0.001, 0.002]}  # fmt: skip
    assert probes(make_plan("spinning-top", grid)) == [(0, 0, 0), (0, 1, 0)]
    rows = {"tilt": [0.2, 0.3, 0.4], "methods": [["rkmk4"], ["yoshida4"], ["rkmk4"]]}
    assert probes(make_plan("spinning-top", samples=rows)) == [(0,), (1,)]
    many = {"methods": [[m] for m in ("rkmk4", "yoshida4", "strang")], "spin": [1, 2, 3]}
    assert len(probes(make_plan("spinning-top", many))) == 9  # integers may shape, too
    huge = {"spin": list(range(1, MAX_PROBES + 2))}
    with pytest.raises(ValueError, match=rf"this sweep has {MAX_PROBES + 1}, more than "
                       rf"{MAX_PROBES}; sweep fewer of them at a time"):  # fmt: skip
        probes(make_plan("spinning-top", huge))


def test_the_store_estimate_is_the_stores_uncompressed_size(client, tmp_path):
    from tumble.sweeps.budget import estimate

    grid = {"omega0.1": [18.0, 20.0, 22.0], "method": ["rkmk4", "lie-euler"]}
    plan = make_plan(tiny(), grid, chunk=2)
    ds = tumble.sweep(tiny(), grid, client=client, store=tmp_path / "s.zarr", chunk=2)
    found = estimate(plan)
    assert found.store == sum(ds[name].nbytes for name in ds.data_vars)
    assert (found.members, found.tasks) == (6, 3)


def test_a_store_larger_than_the_free_disk_is_refused_before_any_work(tmp_path):
    """1e10 members: refused from the plan (no cluster, no store, no member run)."""
    from tumble.sweeps.budget import free_space, size

    axis = np.linspace(0.0, 1.0, 100_000)
    with pytest.raises(ValueError) as refused:
        tumble.sweep(tiny(), {"omega0.1": axis, "omega0.2": axis},
                     client="tcp://127.0.0.1:1", store=tmp_path / "s.zarr")  # fmt: skip
    message = str(refused.value)
    per_member = 61 * 176 + 34  # 61 samples of the series, 33 B of summary, the flag
    assert message.startswith(
        f"the sweep's store would take up to {size(1e10 * per_member)}: 10000000000 members "
        f"(100000 x 100000) of {size(per_member)} each, more than the "
    )
    assert f"free at {tmp_path}; sweep fewer members, store fewer samples" in message
    assert free_space(tmp_path) < 1e10 * per_member
    assert not (tmp_path / "s.zarr").exists()


def test_a_client_too_large_for_memory_and_a_task_too_large_for_a_worker_are_refused():
    from tumble.sweeps.budget import TASK_CLIENT_BYTES, check_fits, check_task

    plan = make_plan(tiny(), {"omega0.1": np.linspace(0.0, 1.0, 1000)}, chunk=1)
    with pytest.raises(ValueError, match=r"client would need about 1[89]\.\d MiB for 1000 "
                       r"tasks of 1000 members \(1000\), more than the 5 MiB \(half of this "
                       r"machine's memory\).*give larger tasks \(chunk, --chunk\)"):  # fmt: skip
        check_fits(plan, ".", memory=10 * 2**20)
    check_fits(plan, ".", memory=4 * 1000 * TASK_CLIENT_BYTES)  # room enough: no error
    with pytest.raises(ValueError, match=r"a task of 1 members would hold about 31\.\d KiB "
                       r".*one member alone is too large: store fewer samples"):  # fmt: skip
        check_task(plan, 2**10)
    wide = make_plan(tiny(), {"omega0.1": np.linspace(0.0, 1.0, 1000)}, chunk=500)
    with pytest.raises(ValueError, match=r"give smaller tasks: chunk \(--chunk\) at most 9\b"):
        check_task(wide, 2 * 9.5 * 3 * 10786)


@pytest.mark.parametrize(
    ("store", "message"),
    [
        (None, r"store=None is not allowed: must be a path \(str or pathlib.Path\)"),
        ("", r"store='' is not allowed"),
        ("/proc/x.zarr", r"store='/proc/x.zarr' is not allowed: must be a folder that can be "
         r"created; /proc cannot hold it \(No such file or directory\)"),
    ],
)  # fmt: skip
def test_a_store_that_cannot_be_written_is_refused_before_any_work(store, message):
    with pytest.raises(ValueError, match=message):
        tumble.sweep(tiny(), {"h": [0.01]}, client="tcp://127.0.0.1:1", store=store)
    assert not Path("None").exists()


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (["--map", "nosuch"], "--map='nosuch' is not allowed: must be one of 'status', "
         "'n_steps', 'energy_error', 'flip_period', 'wall_time'"),
        (["--map", "energy_error", "--grid", "h=0.01"], "--map='energy_error' is not "
         "allowed: must be drawn over exactly two swept dimensions; this sweep has 1: "
         "omega0.0"),
        (["--out", "/proc/x.zarr"], "store='/proc/x.zarr' is not allowed: must be a folder "
         "that can be created"),
        (["--grid", "omega0.1=0:1:100000", "--grid", "omega0.2=0:1:100000"], "the sweep's "
         "store would take up to"),
    ],
)  # fmt: skip
def test_cli_refuses_what_cannot_work_before_any_member_runs(tmp_path, option, message):
    """No cluster is reached (the scheduler address answers nothing): each is found first."""
    from typer.testing import CliRunner

    from tumble.cli import app

    file = scenario_file(tmp_path)
    out = ["--out", str(tmp_path / "s.zarr")] if "--out" not in option else []
    grid = ["--grid", "omega0.0=0.1,0.2"] if option[-1] == "h=0.01" else []
    args = ["sweep", str(file), *out, *grid, *option, "--scheduler", "tcp://127.0.0.1:1"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split()), result.output
    assert not (tmp_path / "s.zarr").exists()


def test_cli_help_of_sweep_names_built_in_scenarios():
    from typer.testing import CliRunner

    from tumble.cli import app

    result = CliRunner().invoke(app, ["sweep", "--help"], terminal_width=100)
    assert "NAME|FILE.toml" in result.output
    assert "built-in scenario's name" in " ".join(result.output.split())


def test_cli_bar_counts_members_from_its_first_count(monkeypatch):
    """The terminal shows what the sweep is doing, then n/N members: never 0/None."""
    import io

    from rich.console import Console

    from tumble import cli

    screen = io.StringIO()
    monkeypatch.setattr(cli, "console", Console(file=screen, force_terminal=True, width=100))
    with cli._members_bar() as progress:
        progress(0, 4)
        progress(4, 4)
    assert "None" not in screen.getvalue()
    assert "4/4 members" in screen.getvalue()


@pytest.mark.parametrize(
    ("dim", "path", "label"),
    [
        ("omega0.1", "initial.omega0.1", "ω_y (rad/s)"),
        ("L0.2", "initial.L0.2", "L_z (kg m²/s)"),
        ("spins.0.1", "spins.0.1", "ω_y of spins[0] (rad/s)"),
        ("h", "h", "h (s)"),
        ("method", "method", "method"),
        ("body.density", "body.density", "body.density"),
    ],
)
def test_sweep_maps_label_their_axes_with_a_short_name_and_unit(dim, path, label):
    from tumble.sweeps.picture import axis_label

    dataset = xr.Dataset(coords={dim: (dim, [1.0, 2.0], {"option_path": path})})
    assert axis_label(dataset, dim) == label


def test_the_gallery_card_of_the_flip_map_shows_its_picture():
    """flip_map.py is not run by the gallery (a cluster): its thumbnail and its page show
    docs/img/flip_map.png, the picture it draws."""
    source = (EXAMPLES / "flip_map.py").read_text(encoding="utf-8")
    assert '# sphinx_gallery_thumbnail_path = "img/flip_map.png"' in source
    assert ".. image:: /img/flip_map.png" in source
    assert (EXAMPLES.parent / "docs" / "img" / "flip_map.png").stat().st_size > 20_000
