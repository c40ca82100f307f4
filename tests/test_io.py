"""Files appear complete or not at all; run folders read back with their attributes."""

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import tumble
from tumble import io, scenarios
from tumble.io import ScenarioResult, atomic_write, write_json, write_run_folder
from tumble.rigid import Trajectory


def test_atomic_write_leaves_no_file_when_the_writer_crashes(tmp_path):
    def crash(path):
        path.write_text("half a fil")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        atomic_write(tmp_path / "data.json", crash)
    assert list(tmp_path.iterdir()) == []


def test_atomic_write_keeps_the_old_file_when_the_writer_crashes(tmp_path):
    write_json(tmp_path / "summary.json", {"a": 1})

    def crash(path):
        path.write_text("{")
        raise RuntimeError("killed")

    with pytest.raises(RuntimeError):
        atomic_write(tmp_path / "summary.json", crash)
    assert (tmp_path / "summary.json").read_text() == '{\n  "a": 1\n}\n'
    assert [p.name for p in tmp_path.iterdir()] == ["summary.json"]


def _t_handle(t_end=2.0):
    return scenarios.get("t-handle").run(t_end=t_end, spins=[(1.0, 0.05, 0.0)])


def test_data_nc_round_trips_with_its_attributes(tmp_path):
    result = _t_handle()
    io.write_run_folder(result, tmp_path, animation=False)
    run = io.load(tmp_path)
    assert run.groups == ["", "mesh"]  # one run: its data at the root
    assert run.attrs["scenario"] == "t-handle" and run.attrs["method"] == "rkmk4"
    assert run.attrs["h"] == 0.01 and run.attrs["t_end"] == 2.0
    body = result.data["body"]
    assert run.attrs["mass"] == body.mass
    np.testing.assert_array_equal(run.attrs["inertia"], np.ravel(body.inertia))
    assert run.attrs["tumble_version"] == tumble.__version__
    original = result.data["trajectories"][0]
    back = Trajectory.from_xarray(run.dataset())
    np.testing.assert_array_equal(back.t, original.t)
    np.testing.assert_array_equal(back.R, original.R)
    np.testing.assert_array_equal(back.L_world, original.L_world)
    assert run.dataset("")["energy"].attrs["units"] == "J"
    assert run.summary == json.loads(json.dumps({**result.summary, "files": run.summary["files"]}))


def test_summary_lists_every_file_written_and_is_written_last(tmp_path):
    io.write_run_folder(_t_handle(), tmp_path, animation=False)
    summary = json.loads((tmp_path / "summary.json").read_text())
    on_disk = {p.name for p in tmp_path.iterdir()} - {"summary.json"}
    assert set(summary["files"]) == on_disk
    assert summary["files"][-1] == "data.nc"


def test_a_crash_mid_write_leaves_only_whole_files(tmp_path):
    good = _t_handle()

    def crash(path):
        path.write_bytes(b"\x89PNG half")
        raise RuntimeError("killed while drawing")

    broken = ScenarioResult(good.name, good.summary, figures=[good.figures[0], ("b.png", crash)])
    with pytest.raises(RuntimeError, match="killed"):
        io.write_run_folder(broken, tmp_path)
    # the file written before the crash is whole; the crashed one and summary.json are absent
    assert [p.name for p in tmp_path.iterdir()] == [good.figures[0][0]]
    with pytest.raises(ValueError, match="summary.json is missing"):
        io.load(tmp_path)


def test_a_crash_while_writing_data_nc_leaves_no_partial_netcdf(tmp_path, monkeypatch):
    def fail(self, path, **kwargs):
        Path(path).write_bytes(b"\x89HDF half")
        raise OSError("disk full")

    monkeypatch.setattr(xr.DataTree, "to_netcdf", fail)
    with pytest.raises(OSError, match="disk full"):
        io.write_run_folder(_t_handle(), tmp_path, animation=False)
    names = {p.name for p in tmp_path.iterdir()}
    assert "data.nc" not in names and "summary.json" not in names
    assert not [n for n in names if "partial" in n]


def test_load_names_what_is_missing(tmp_path):
    with pytest.raises(ValueError, match="summary.json is missing"):
        io.load(tmp_path)
    (tmp_path / "summary.json").write_text('{"files": ["data.nc"]}')
    with pytest.raises(ValueError, match="data.nc is missing"):
        io.load(tmp_path)
    (tmp_path / "data.nc").write_bytes(b"not netcdf")
    with pytest.raises(ValueError, match="could not be read"):
        io.load(tmp_path / "data.nc")


def test_load_refuses_a_folder_missing_a_file_its_summary_lists(tmp_path):
    io.write_run_folder(scenarios.get("projectile").run(), tmp_path)
    (tmp_path / "trajectory.png").unlink()
    with pytest.raises(ValueError, match=r"lists \['trajectory.png'\], which are not there"):
        io.load(tmp_path)


@pytest.mark.parametrize("text", ["{}", "[1, 2]", '{"files": "data.nc"}', '{"files": ["../x"]}'])
def test_load_refuses_a_summary_that_is_not_a_run_summary(tmp_path, text):
    io.write_run_folder(scenarios.get("projectile").run(), tmp_path)
    (tmp_path / "summary.json").write_text(text)
    with pytest.raises(ValueError, match="not a tumble run summary"):
        io.load(tmp_path)


def test_load_of_a_damaged_data_nc_says_so_without_the_hdf5_error_class(tmp_path):
    # A bad object header: h5py raises KeyError deep inside xarray.
    io.write_run_folder(scenarios.get("projectile").run(), tmp_path)
    raw = bytearray((tmp_path / "data.nc").read_bytes())
    header = raw.find(b"OHDR", 200)
    raw[header : header + 40] = b"\xab" * 40
    (tmp_path / "data.nc").write_bytes(raw)
    with pytest.raises(ValueError, match="data.nc could not be read.*damaged"):
        io.load(tmp_path)


def test_dataset_needs_a_name_when_there_are_several(tmp_path):
    result = scenarios.get("t-handle").run(t_end=1.0, spins=[(1.0, 0.05, 0.0), (0.0, 1.0, 0.05)])
    io.write_run_folder(result, tmp_path, animation=False)
    run = io.load(tmp_path)
    with pytest.raises(ValueError, match=r"ambiguous.*spin1"):
        run.dataset()
    with pytest.raises(ValueError, match="spin9"):
        run.dataset("spin9")


def test_netcdf_attrs_keep_numbers_and_encode_the_rest():
    attrs = io.netcdf_attrs({"h": 0.1, "ok": True, "skip": None, "v": [1, 2], "m": ["a", "b"]})
    assert attrs["h"] == 0.1 and attrs["ok"] == 1 and "skip" not in attrs
    np.testing.assert_array_equal(attrs["v"], [1, 2])
    assert json.loads(attrs["m"]) == ["a", "b"]


def test_summary_json_is_strict_json_with_null_for_non_finite_numbers(tmp_path):
    path = write_json(tmp_path / "s.json", {"a": float("nan"), "b": [1.0, float("inf")], "c": 2})
    assert json.loads(path.read_text(), parse_constant=pytest.fail) == {
        "a": None,
        "b": [1.0, None],
        "c": 2,
    }


def test_atomic_writes_of_one_target_use_distinct_temporary_names(tmp_path):
    seen = []
    atomic_write(tmp_path / "x.png", lambda tmp: (seen.append(tmp), tmp.write_text("1")))
    atomic_write(tmp_path / "x.png", lambda tmp: (seen.append(tmp), tmp.write_text("2")))
    assert seen[0] != seen[1] and all(p.suffix == ".png" for p in seen)
    assert [p.name for p in tmp_path.iterdir()] == ["x.png"]


def test_a_figure_that_fails_to_draw_leaves_no_file(tmp_path):
    from tumble.viz._figure import new_figure, save

    fig, axes = new_figure()
    axes.plot([1, 2], [3, 4])
    with pytest.raises(ValueError):
        save(fig, tmp_path / "plot.nosuchformat")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("umask", [0o022, 0o077, 0o002])
def test_atomic_write_gives_the_mode_an_ordinary_write_gives(tmp_path, umask):
    # Issue 18: run-folder files came out 0600 (mkstemp's mode) whatever the umask.
    import os
    import stat

    previous = os.umask(umask)
    try:
        atomic_write(tmp_path / "view.html", lambda tmp: tmp.write_text("<html></html>"))
        with open(tmp_path / "plain.txt", "w") as handle:
            handle.write("x")
    finally:
        os.umask(previous)
    mode = stat.S_IMODE((tmp_path / "view.html").stat().st_mode)
    assert mode == stat.S_IMODE((tmp_path / "plain.txt").stat().st_mode) == 0o666 & ~umask


def test_an_atomic_write_inside_an_atomic_write_uses_one_temporary(tmp_path):
    # A run folder's figure: write_run_folder's atomic write around the figure's own save.
    seen = []

    def inner(tmp):
        seen.extend(f.name for f in tmp_path.iterdir())
        tmp.write_text("figure")

    atomic_write(tmp_path / "drift.png", lambda tmp: atomic_write(tmp, inner))
    assert len(seen) == 1 and seen[0].count(".partial") == 1, seen
    assert sorted(f.name for f in tmp_path.iterdir()) == ["drift.png"]


def test_run_folder_figures_are_written_through_one_temporary_each(tmp_path, monkeypatch):
    from tumble import _atomic

    temporaries = []
    original = _atomic.tempfile.mkstemp

    def counting(*args, **kwargs):
        handle, name = original(*args, **kwargs)
        temporaries.append(Path(name).name)
        return handle, name

    monkeypatch.setattr(_atomic.tempfile, "mkstemp", counting)
    result = scenarios.get("projectile").run()
    write_run_folder(result, tmp_path / "run")
    assert all(name.count(".partial") == 1 and not name.startswith("..") for name in temporaries)
    assert (
        len(temporaries)
        == len(json.loads((tmp_path / "run/summary.json").read_text())["files"]) + 1
    )


def test_a_reused_folder_loses_the_partials_a_killed_run_left(tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    stale = [out / ".drift.k2j1x.partial.png", out / ".data.abc.partial.nc"]
    for path in stale:
        path.write_bytes(b"")
    (out / ".hidden-but-mine").write_text("keep")
    write_run_folder(scenarios.get("projectile").run(), out, force=True)
    assert not any(path.exists() for path in stale)
    assert (out / ".hidden-but-mine").read_text() == "keep"


def test_a_folder_holding_only_stale_partials_counts_as_empty(tmp_path):
    (tmp_path / ".trajectory.x1.partial.png").write_bytes(b"")
    write_run_folder(scenarios.get("projectile").run(), tmp_path)  # no force needed
    assert (tmp_path / "summary.json").is_file()


@pytest.mark.parametrize("where", ["file", "proc"])
def test_a_run_folder_that_cannot_be_created_is_refused_by_name(tmp_path, where):
    if where == "file":
        (tmp_path / "plain").write_text("x")
        out = tmp_path / "plain" / "run"
    else:
        out = Path("/proc/tumble-run")
    with pytest.raises(ValueError, match=r"out='.*run' cannot be created"):
        write_run_folder(scenarios.get("projectile").run(), out)


def test_atomic_write_into_a_missing_folder_is_refused_with_the_path(tmp_path):
    target = tmp_path / "missing" / "box.stl"
    with pytest.raises(ValueError, match=r"cannot write '.*box.stl'.*folder must exist"):
        atomic_write(target, lambda tmp: tmp.write_text("x"))


def test_open_dataset_on_a_single_run_shows_its_data_at_the_root(tmp_path):
    io.write_run_folder(_t_handle(), tmp_path, animation=False)
    with xr.open_dataset(tmp_path / "data.nc", engine="h5netcdf") as data:
        assert {"R", "omega_body", "energy"} <= set(data.data_vars)
        assert data.sizes["time"] == 201 and data.attrs["scenario"] == "t-handle"


def test_a_multi_run_root_lists_its_groups_and_how_to_open_them(tmp_path):
    result = scenarios.get("t-handle").run(t_end=1.0, spins=[(1.0, 0.05, 0.0), (0.0, 1.0, 0.05)])
    io.write_run_folder(result, tmp_path, animation=False)
    with xr.open_dataset(tmp_path / "data.nc", engine="h5netcdf") as root:
        assert root.attrs["groups"] == "spin1, spin2, mesh"
        assert "open_datatree" in root.attrs["comment"]
    with xr.open_dataset(tmp_path / "data.nc", engine="h5netcdf", group="spin2") as spin:
        assert spin.sizes["time"] == 101


def test_write_figures_refuses_an_existing_file_unless_forced(tmp_path):
    from tumble.io import write_figures

    def writer(text):
        return lambda path: path.write_text(text)

    figures = [("a.txt", writer("one")), ("b.txt", writer("two"))]
    paths = write_figures(tmp_path / "new", figures)
    assert [p.read_text() for p in paths] == ["one", "two"]
    (paths[1]).write_text("kept")
    with pytest.raises(FileExistsError) as refused:
        write_figures(tmp_path / "new", [("a.txt", writer("three")), ("b.txt", writer("x"))])
    assert refused.value.filename == str(paths[0])
    assert paths[0].read_text() == "one"  # nothing written when one file is refused
    write_figures(tmp_path / "new", [("a.txt", writer("three"))], force=True)
    assert paths[0].read_text() == "three" and paths[1].read_text() == "kept"
