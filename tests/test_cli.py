"""The command line through typer's test runner: exit codes and messages."""

import json

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
