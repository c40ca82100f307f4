"""Each built-in scenario, run short, writes every file it promises, and reads back."""

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tumble import io, scenarios

SHORT = {
    "projectile": {"h": 0.5},
    "torus-spin": {"t_end": 2.0, "methods": ["rk4-matrix", "rkmk4"]},
    "prism-impulse": {"t_end": 1.0, "methods": ["rkmk4"]},
    "sphere-exact": {"methods": ["euler", "rkmk4"]},
    "t-handle": {"t_end": 2.0, "spins": [[1.0, 0.05, 0.0]]},
    "convergence": {"step_counts": [50, 100], "methods": ["rkmk4"]},
    "beam": {"n_elements": 8, "n_steps": 200, "sweep_steps": 100},
    "spinning-top": {"t_end": 0.5},
    "detumble": {"threshold": 0.1, "h": 2.0, "record_every": 10},
}
RIGID = {"animation.gif", "view.html", "data.nc"}
PROMISED = {
    "projectile": {"trajectory.png", "data.nc"},
    "torus-spin": {"drift.png", "error_vs_exact.png", "rotation_grid.png"} | RIGID,
    "prism-impulse": {"snapshots.png", "drift.png", "rotation_grid.png"} | RIGID,
    "sphere-exact": {"error_vs_exact.png", "rotation_grid.png", "drift.png"} | RIGID,
    "t-handle": {
        "rotation_grid_spin1.png", "euler_angles_spin1.png", "angular_velocity.png", "drift.png"
    } | RIGID,
    "convergence": {"convergence.png", "data.nc"},
    "beam": {f"energy_{s}.png" for s in ("explicit", "semi-implicit", "implicit", "midpoint")}
    | {"stability_sweep.png", "beam_shapes.png", "animation.gif", "data.nc"},
    "spinning-top": {"top.png", "invariants.png"} | RIGID,
    "detumble": {"detumble.png"} | RIGID,
}  # fmt: skip


def test_every_built_in_scenario_is_covered():
    assert set(SHORT) == set(PROMISED) == set(scenarios.names()) - {"rigid-body"}


@pytest.mark.parametrize("name", sorted(SHORT))
def test_scenario_writes_every_promised_file(name, tmp_path):
    result = scenarios.get(name).run(**SHORT[name])
    io.write_run_folder(result, tmp_path)
    written = {p.name for p in tmp_path.iterdir()}
    assert written == PROMISED[name] | {"summary.json"}
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert set(summary["files"]) == PROMISED[name]
    for png in tmp_path.glob("*.png"):
        with Image.open(png) as image:
            assert image.format == "PNG" and min(image.size) > 200
    if "animation.gif" in written:
        with Image.open(tmp_path / "animation.gif") as gif:
            assert gif.format == "GIF" and gif.n_frames >= 10
    if "view.html" in written:
        assert "Plotly" in (tmp_path / "view.html").read_text(encoding="utf-8")
    run = io.load(tmp_path)
    assert run.attrs["scenario"] == name
    for group in run.groups:
        dataset = run.dataset(group)
        assert dataset.data_vars and all(
            np.isfinite(dataset[v].values).any() for v in dataset.data_vars if v != "method"
        )


EXAMPLES = sorted((Path(__file__).parents[2] / "examples").glob("*.toml"))
SHORTER = {"t_end": 0.5}


def test_there_is_an_example_file_for_every_scenario():
    from tumble.scenarios import files

    assert {files.read(path).scenario for path in EXAMPLES} == set(scenarios.names())


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_file_runs_and_writes_every_file(path, tmp_path):
    from tumble.scenarios import files

    spec = files.read(path)
    options = {**spec.options, **SHORT.get(spec.scenario, {})}
    if spec.scenario == "rigid-body":
        options.update(SHORTER)
    result = scenarios.get(spec.scenario).run(**files.check_options(spec.scenario, options))
    io.write_run_folder(result, tmp_path, animation=spec.outputs.animation)
    promised = {name for name, _ in result.figures} | {"data.nc", "summary.json"}
    if spec.outputs.animation:
        promised |= {name for name, _ in result.animations}
    assert {p.name for p in tmp_path.iterdir()} == promised
    sizes = {name: (tmp_path / name).stat().st_size for name in promised - {"summary.json"}}
    assert min(sizes.values()) > 1000, sizes


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_view_draws_again_the_page_the_run_wrote(path, tmp_path):
    """tumble view on a folder written without view.html: the run's own page, byte for byte
    (the title, the shown run and the impulse arrows come back from data.nc's mesh group)."""
    from tumble.scenarios import files

    spec = files.read(path)
    options = {**spec.options, **SHORT.get(spec.scenario, {})}
    if spec.scenario == "rigid-body":
        options.update(SHORTER)
    result = scenarios.get(spec.scenario).run(**files.check_options(spec.scenario, options))
    io.write_run_folder(dataclasses.replace(result, figures=[]), tmp_path, animation=False)
    writers = dict(result.animations)
    if "view.html" not in writers:  # no moving body to show
        with pytest.raises(ValueError, match="holds no body mesh"):
            scenarios.view_page(tmp_path)
        return
    writers["view.html"](tmp_path / "written.html")
    page = scenarios.view_page(tmp_path)
    assert page == tmp_path / "view.html"
    assert page.read_bytes() == (tmp_path / "written.html").read_bytes()
