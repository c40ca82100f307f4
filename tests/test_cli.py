"""The command line through typer's test runner: exit codes and messages."""

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from tumble.cli import app

runner = CliRunner()


def test_list_shows_the_projectile():
    result = runner.invoke(app, ["list"])
    assert result.exit_code == 0
    assert "projectile" in result.output


def test_run_projectile_writes_the_run_folder(tmp_path):
    out = tmp_path / "proj"
    result = runner.invoke(app, ["run", "projectile", "--out", str(out)])
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert abs(summary["range"] - 25484.1998) < 25484.1998 * 1e-6
    assert (out / "trajectory.png").stat().st_size > 10_000


def test_unknown_scenario_exits_2_naming_it():
    result = runner.invoke(app, ["run", "nope"])
    assert result.exit_code == 2
    assert "nope" in result.output and "projectile" in result.output


def test_existing_folder_exits_2_without_force(tmp_path):
    (tmp_path / "keep.txt").write_text("mine")
    result = runner.invoke(app, ["run", "projectile", "--out", str(tmp_path)])
    assert result.exit_code == 2
    assert "--force" in result.output
    assert (tmp_path / "keep.txt").read_text() == "mine"


def _summary(folder):
    return json.loads((folder / "summary.json").read_text())


def test_run_takes_method_h_and_t_end(tmp_path):
    out = tmp_path / "th"
    args = ["run", "t-handle", "--out", str(out), "--method", "rk4-quat", "--h", "0.02"]
    result = runner.invoke(app, [*args, "--t-end", "1.5", "--no-animation"])
    assert result.exit_code == 0, result.output
    summary = _summary(out)
    assert (summary["method"], summary["h"], summary["t_end"]) == ("rk4-quat", 0.02, 1.5)
    assert "animation.gif" not in summary["files"] and not (out / "view.html").exists()


def test_an_option_the_scenario_does_not_take_exits_2_naming_it(tmp_path):
    result = runner.invoke(app, ["run", "beam", "--h", "0.1", "--out", str(tmp_path / "b")])
    assert result.exit_code == 2
    assert "--h" in result.output and "beam" in result.output and "n_elements" in result.output


def test_a_bad_value_exits_2_naming_the_key_and_value(tmp_path):
    result = runner.invoke(app, ["run", "t-handle", "--h", "-0.01", "--out", str(tmp_path / "x")])
    assert result.exit_code == 2
    assert "h" in result.output and "-0.01" in result.output
    result = runner.invoke(app, ["run", "t-handle", "--method", "rk5", "--out", str(tmp_path)])
    assert result.exit_code == 2
    assert "rk5" in result.output and "rkmk4" in result.output


def test_a_bad_toml_file_exits_2_naming_the_key(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('scenario = "t-handle"\n[options]\nspinz = [[1.0, 0.0, 0.0]]\n')
    result = runner.invoke(app, ["run", str(path), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "spinz" in result.output
    missing = runner.invoke(app, ["run", str(tmp_path / "nowhere.toml")])
    assert missing.exit_code == 2 and "nowhere.toml" in missing.output


def test_the_example_file_gives_the_same_numbers_as_the_built_in(tmp_path):
    short = ["--t-end", "3", "--no-animation"]
    by_name = runner.invoke(app, ["run", "t-handle", "--out", str(tmp_path / "a"), *short])
    example = Path(__file__).parent.parent / "examples" / "t-handle.toml"
    by_file = runner.invoke(app, ["run", str(example), "--out", str(tmp_path / "b"), *short])
    assert by_name.exit_code == 0 and by_file.exit_code == 0, by_file.output
    assert _summary(tmp_path / "a") == _summary(tmp_path / "b")


def test_compare_writes_a_work_precision_table_and_plot(tmp_path):
    out = tmp_path / "cmp"
    result = runner.invoke(
        app,
        ["compare", "t-handle", "--methods", "lie-euler,rkmk4", "--t-end", "1", "--out", str(out)],
    )
    assert result.exit_code == 0, result.output
    summary = _summary(out)
    assert set(summary["best"]) == {"lie-euler", "rkmk4"}
    assert summary["best"]["rkmk4"]["error"] < summary["best"]["lie-euler"]["error"]
    assert (out / "work_precision.png").stat().st_size > 10_000
    assert "rkmk4" in result.output and "lie-euler" in result.output


def test_compare_refuses_a_scenario_without_a_free_body():
    result = runner.invoke(app, ["compare", "beam"])
    assert result.exit_code == 2
    assert "beam" in result.output and "t-handle" in result.output
    result = runner.invoke(app, ["compare", "t-handle", "--methods", "rkmk4,nope"])
    assert result.exit_code == 2 and "nope" in result.output


def test_stability_prints_the_sweep_and_writes_its_plot(tmp_path):
    out = tmp_path / "st"
    result = runner.invoke(
        app, ["stability", "--n-elements", "8", "--steps", "300", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    stable = _summary(out)["schemes"]["semi-implicit"]["stable"]
    factors = _summary(out)["factors"]
    # the semi-implicit scheme is stable below 2/ω_max and not well above it
    assert all(stable[k] for k, f in enumerate(factors) if f <= 0.9)
    assert not any(stable[k] for k, f in enumerate(factors) if f >= 2)
    assert (out / "stability_sweep.png").is_file()
    assert "grows" in result.output and "stable" in result.output


def test_view_draws_view_html_again_from_data_nc(tmp_path):
    out = tmp_path / "run"
    args = ["run", "t-handle", "--t-end", "1", "--no-animation", "--out", str(out)]
    assert runner.invoke(app, args).exit_code == 0
    assert not (out / "view.html").exists()
    result = runner.invoke(app, ["view", str(out), "--no-open"])
    assert result.exit_code == 0, result.output
    page = (out / "view.html").read_text()
    assert "plotly" in page.lower() and "t-handle" in page


def test_view_refuses_a_run_without_a_body(tmp_path):
    out = tmp_path / "proj"
    assert runner.invoke(app, ["run", "projectile", "--out", str(out)]).exit_code == 0
    result = runner.invoke(app, ["view", str(out), "--no-open"])
    assert result.exit_code == 2 and "mesh" in result.output
    result = runner.invoke(app, ["view", str(tmp_path / "none"), "--no-open"])
    assert result.exit_code == 2 and "summary.json" in result.output


def test_mass_of_a_torus_mesh(tmp_path):
    from tumble import meshes

    mesh = meshes.torus(1.0, 0.5, 64, minor_sections=32)
    path = meshes.save(mesh, tmp_path / "torus.stl")
    result = runner.invoke(app, ["mass", str(path), "--density", "2"])
    assert result.exit_code == 0, result.output
    mass = float(result.output.split(" kg ")[1].split()[0])
    assert abs(mass / (2 * mesh.volume) - 1) < 1e-5  # printed to 6 digits
    assert abs(mass / (2 * 4.934802) - 1) < 0.01  # 2π²Rr² ρ; the polyhedron is a little smaller


def test_mass_of_the_example_bracket_is_its_closed_form():
    """examples/bracket.stl, the README's mesh: an L of 40 x 5 and 5 x 25 mm, 20 mm wide."""
    bracket = Path(__file__).parents[1] / "examples" / "bracket.stl"
    result = runner.invoke(app, ["mass", str(bracket), "--density", "7850"])
    assert result.exit_code == 0, result.output
    volume = (40 * 5 + 5 * 25) * 20 * 1e-9  # m³
    com = np.array([(200 * 20 + 125 * 2.5) / 325, (200 * 2.5 + 125 * 17.5) / 325, 10]) / 1e3
    rows = {line.split()[0]: line.split() for line in result.output.splitlines() if line}
    assert float(rows["volume"][2]) == pytest.approx(volume, rel=1e-6)  # printed to 6 digits
    assert float(rows["mass"][2]) == pytest.approx(7850 * volume, rel=1e-6)
    np.testing.assert_allclose([float(v) for v in rows["centre"][4:7]], com, rtol=1e-5)


def test_mass_rejects_bad_density_and_missing_files(tmp_path):
    from tumble import meshes

    path = meshes.save(meshes.box((1.0, 2.0, 3.0)), tmp_path / "box.stl")
    result = runner.invoke(app, ["mass", str(path), "--density", "-1"])
    assert result.exit_code == 2 and "density" in result.output and "-1" in result.output
    result = runner.invoke(app, ["mass", str(tmp_path / "no.stl"), "--density", "1"])
    assert result.exit_code == 2 and "no.stl" in result.output


def test_every_command_has_help():
    for command in ("list", "run", "compare", "stability", "view", "mass"):
        result = runner.invoke(app, [command, "--help"])
        assert result.exit_code == 0 and "Usage" in result.output


def test_flags_show_no_value_in_the_help():
    """A flag takes no value: its help line shows none (typer would print `--quick <bool>`)."""
    import typer.main

    for name in [c.name for c in typer.main.get_command(app).commands.values()]:
        result = runner.invoke(app, [name, "--help"], terminal_width=120)
        assert result.exit_code == 0, name
        assert "<bool>" not in result.output, (name, result.output)
    assert "<path>" in runner.invoke(app, ["report", "--help"], terminal_width=120).output


BAD_FILES = {
    "syntax": ('scenario = "t-handle"\n[options\n', "line 2"),
    "scenario": ('scenario = "t-handel"\n', "t-handel"),
    "top-level key": ('scenario = "t-handle"\nsteps = 3\n', "steps"),
    "type": ('scenario = "t-handle"\n[options]\nh = "fast"\n', "options.h"),
    "value": ('scenario = "beam"\n[options]\nn_elements = 0\n', "options.n_elements"),
    "shape": (
        'scenario = "rigid-body"\n[options.body]\nshape = "cone"\nmass = 1.0\n',
        "options.body",
    ),
    "dimension": (
        'scenario = "rigid-body"\n[options.body]\nshape = "cylinder"\nmass = 1.0\nradius = 0.1\n',
        "length",
    ),
}


@pytest.mark.parametrize("kind", sorted(BAD_FILES))
def test_each_kind_of_bad_file_exits_2_naming_the_key(kind, tmp_path):
    text, named = BAD_FILES[kind]
    path = tmp_path / f"{kind.replace(' ', '-')}.toml"
    path.write_text(text)
    result = runner.invoke(app, ["run", str(path), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2, result.output
    assert named in result.output and path.name in result.output
    assert not (tmp_path / "out").exists()


def test_force_replaces_the_previous_run_and_view_draws_the_new_one(tmp_path):
    out = tmp_path / "run"
    first = ["run", "t-handle", "--t-end", "1", "--out", str(out)]
    assert runner.invoke(app, first).exit_code == 0
    old_page = (out / "view.html").read_text()
    again = ["run", "t-handle", "--t-end", "2", "--no-animation", "--force", "--out", str(out)]
    assert runner.invoke(app, again).exit_code == 0
    assert not (out / "animation.gif").exists() and not (out / "view.html").exists()
    assert {p.name for p in out.iterdir()} == set(_summary(out)["files"]) | {"summary.json"}
    assert runner.invoke(app, ["view", str(out), "--no-open"]).exit_code == 0
    assert (out / "view.html").read_text() != old_page


def test_mass_names_the_command_line_option_for_an_inside_out_mesh(tmp_path):
    from tumble import meshes

    mesh = meshes.box((1.0, 2.0, 3.0))
    mesh.invert()
    path = meshes.save(mesh, tmp_path / "inside.stl")
    result = runner.invoke(app, ["mass", str(path), "--density", "1"])
    assert result.exit_code == 2 and "--fix-inside-out" in result.output
    assert "inside.stl" in result.output and "Trimesh" not in result.output  # the file, by name
    fixed = runner.invoke(app, ["mass", str(path), "--density", "1", "--fix-inside-out"])
    assert fixed.exit_code == 0 and "note:" in fixed.output
    assert float(fixed.output.split(" kg ")[1].split()[0]) == pytest.approx(6.0)


def test_rigid_body_without_a_file_says_to_use_one():
    result = runner.invoke(app, ["run", "rigid-body"])
    assert result.exit_code == 2 and "TOML" in result.output


def test_a_value_refused_by_the_scenario_names_the_file(tmp_path):
    path = tmp_path / "fat.toml"
    path.write_text('scenario = "torus-spin"\n[options]\nminor_radius = 2.0\n')
    result = runner.invoke(app, ["run", str(path), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert "fat.toml" in result.output and "minor_radius" in result.output


def test_a_run_that_stops_early_exits_3_and_says_why_without_warnings(tmp_path):
    # Issue 18: omega0 = [1e300, 0, 0] overflowed in the first step; the CLI exited 0 with
    # numpy's RuntimeWarnings on the terminal. It writes the folder, says which run stopped,
    # when and why, and exits 3.
    toml = tmp_path / "spin.toml"
    toml.write_text(
        'scenario = "torus-spin"\n[options]\nt_end = 2.0\nomega0 = [1e300, 0.0, 0.0]\n'
        'methods = ["rkmk4"]\n[outputs]\nanimation = false\n'
    )
    result = runner.invoke(app, ["run", str(toml), "--out", str(tmp_path / "out")])
    assert result.exit_code == 3, result.output
    assert "trajectories.rkmk4 did not reach its end" in result.output
    assert "non-finite" in result.output and "t=0.0" in result.output
    assert "Warning" not in result.output
    assert (tmp_path / "out" / "summary.json").exists()


def test_a_scenario_whose_stops_are_the_point_exits_0(tmp_path):
    # The beam shows the conditionally stable schemes diverging past their step limit.
    out = tmp_path / "beam"
    options = ["--out", str(out), "--no-animation"]
    result = runner.invoke(app, ["run", "beam", *options])
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["schemes"]["explicit"]["status"] == -1


def test_run_with_mp4_adds_animation_mp4(tmp_path):
    # Issue 18 item 14: MP4 through imageio-ffmpeg's own binary, on every machine.
    out = tmp_path / "spin"
    result = runner.invoke(app, ["run", "t-handle", "--t-end", "2", "--mp4", "--out", str(out)])
    assert result.exit_code == 0, result.output
    with open(out / "animation.mp4", "rb") as file:
        assert file.read(12)[4:8] == b"ftyp"
    assert (out / "animation.gif").exists()
    assert "animation.mp4" in json.loads((out / "summary.json").read_text())["files"]


def test_mp4_without_the_animation_writes_the_mp4_alone(tmp_path):
    out = tmp_path / "spin"
    args = ["run", "t-handle", "--t-end", "2", "--mp4", "--no-animation", "--out", str(out)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    files = json.loads((out / "summary.json").read_text())["files"]
    assert "animation.mp4" in files
    assert "animation.gif" not in files and "view.html" not in files
    assert (out / "animation.mp4").stat().st_size > 1000


def test_mp4_for_a_scenario_without_an_animation_exits_2_before_writing(tmp_path):
    out = tmp_path / "p"
    result = runner.invoke(app, ["run", "projectile", "--mp4", "--out", str(out)])
    assert result.exit_code == 2
    assert (
        "mp4=True is not allowed: must be given only for a result with an animation; "
        "'projectile' draws none; leave out --mp4" in " ".join(result.output.split())
    )
    assert not out.exists()


@pytest.mark.parametrize("signal_name", ["SIGTERM", "SIGINT"])
def test_a_killed_run_exits_130_and_leaves_no_partial_files(tmp_path, signal_name):
    # Wait until a file is being written, then stop the run as a scheduler or Ctrl-C would.
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "run"
    command = [str(Path(sys.executable).with_name("tumble")), "run", "t-handle", "--out", str(out)]
    # SIGINT as at a terminal even where the tests themselves were started with it ignored
    # (a background job of a non-interactive shell inherits SIG_IGN, and Python then keeps it)
    process = subprocess.Popen(
        command,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and process.poll() is None:
        if out.is_dir() and any(".partial" in f.name for f in out.iterdir()):
            break
        time.sleep(0.002)
    process.send_signal(getattr(signal, signal_name))
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr.decode()
    assert "Traceback" not in stderr.decode()
    assert not [f.name for f in out.iterdir() if ".partial" in f.name]


def test_out_under_a_regular_file_exits_2_naming_it(tmp_path):
    (tmp_path / "plain").write_text("x")
    out = tmp_path / "plain" / "run"
    result = runner.invoke(app, ["run", "projectile", "--out", str(out)])
    assert result.exit_code == 2
    assert "cannot be created" in result.output and "Traceback" not in result.output


def test_view_of_a_damaged_run_exits_2_in_one_line(tmp_path):
    runner.invoke(app, ["run", "projectile", "--out", str(tmp_path)])
    raw = bytearray((tmp_path / "data.nc").read_bytes())
    header = raw.find(b"OHDR", 200)
    raw[header : header + 40] = b"\xab" * 40
    (tmp_path / "data.nc").write_bytes(raw)
    result = runner.invoke(app, ["view", str(tmp_path), "--no-open"])
    assert result.exit_code == 2
    assert "damaged" in result.output and "Traceback" not in result.output


def test_a_step_too_small_for_memory_exits_2_with_the_size(tmp_path):
    result = runner.invoke(app, ["run", "t-handle", "--h", "1e-9", "--out", str(tmp_path / "r")])
    assert result.exit_code == 2
    assert "1e+11 samples" in result.output and "Traceback" not in result.output


def test_library_messages_become_the_status_line_while_a_command_runs():
    import logging

    from tumble.cli import _status_from_log

    seen = []
    with _status_from_log(seen.append):
        logging.getLogger("tumble.rigid").info("preparing the compiled %s", "loop")
        logging.getLogger("tumble").debug("too fine to show")
    logging.getLogger("tumble").info("after the command")
    assert seen == ["preparing the compiled loop"]
