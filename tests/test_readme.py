"""The README as a new user follows it: `make demo`, then its command lines in order.

A fresh copy (the Makefile, pyproject.toml, examples/, and this environment as its .venv)
runs `make demo` as the README's first block says (the install step skipped: the environment
is there), then every line of the README's command-line block, top to bottom, each of which
must exit 0; then the README's Python blocks, which must leave the demo's folder alone. The
``tumble view`` line opens a browser through ``$BROWSER``, here a command that does nothing.
"""

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
LINE_SECONDS = 900
"""A line's time limit (``tumble report --quick`` takes about a minute; a loaded machine more)."""


def command_lines() -> list[str]:
    """The README's command-line block, one command a line, comments cut off."""
    section = README.split("## Quick start on the command line", 1)[1]
    block = re.search(r"```bash\n(.*?)```", section, re.DOTALL)
    assert block, "no bash block under 'Quick start on the command line'"
    lines = [line.split(" #", 1)[0].strip() for line in block.group(1).splitlines()]
    return [line for line in lines if line]


def python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README, re.DOTALL)


def test_the_command_block_is_the_one_of_the_quick_start():
    lines = command_lines()
    assert lines[0] == ".venv/bin/tumble list"
    assert all(line.startswith(".venv/bin/tumble ") for line in lines)
    assert any(" mass examples/" in line for line in lines)  # a mesh the checkout ships


@pytest.fixture(scope="module")
def fresh_copy(tmp_path_factory):
    """A folder laid out as a clone after `make demo`."""
    folder = tmp_path_factory.mktemp("clone")
    for name in ("Makefile", "pyproject.toml"):
        (folder / name).write_bytes((ROOT / name).read_bytes())
    (folder / "examples").symlink_to(ROOT / "examples")
    (folder / ".venv").symlink_to(Path(sys.executable).parents[1])
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "BROWSER": "true", "COLUMNS": "100"}
    made = subprocess.run(
        ["make", "-o", ".venv/.installed-dev", "demo"], cwd=folder, env=env,
        capture_output=True, text=True, timeout=LINE_SECONDS,
    )  # fmt: skip
    assert made.returncode == 0, made.stdout + made.stderr
    return folder, env


@pytest.mark.slow
def test_readme_command_lines_run_top_to_bottom_after_make_demo(fresh_copy):
    folder, env = fresh_copy
    demo = folder / "runs" / "t-handle"
    assert (demo / "animation.gif").is_file() and (demo / "view.html").is_file()
    for line in command_lines():
        done = subprocess.run(
            shlex.split(line), cwd=folder, env=env, capture_output=True, text=True,
            timeout=LINE_SECONDS,
        )  # fmt: skip
        assert done.returncode == 0, f"{line}\nexit {done.returncode}\n{done.stdout}{done.stderr}"
    assert (folder / "runs" / "flip-map.zarr" / "done").is_dir()
    assert (folder / "runs" / "report" / "report.html").is_file()


@pytest.mark.slow
def test_readme_python_blocks_leave_the_demo_folder_alone(fresh_copy, monkeypatch, capsys):
    folder, _ = fresh_copy
    demo = folder / "runs" / "t-handle"
    before = {path.name: path.stat().st_mtime_ns for path in demo.iterdir()}
    monkeypatch.chdir(folder)
    namespace: dict = {"__name__": "__readme__"}
    for k, code in enumerate(python_blocks(), start=1):
        exec(compile(code, f"README.md block {k}", "exec"), namespace)
    capsys.readouterr()
    assert {path.name: path.stat().st_mtime_ns for path in demo.iterdir()} == before


@pytest.mark.parametrize("method", ["rkmk45", "rkmk-dopri5"])
def test_rtol_sets_the_t_handles_attitude_error_as_the_readme_says(method):
    """README: on the T-handle's three spins over 100 s the largest attitude error is within
    5 x rtol, for rtol from 1e-4 to 1e-8."""
    from tumble import RigidBody, exact, mass, simulate, so3

    body = RigidBody.from_mass_properties(mass.t_handle())
    ratios = []
    for spin in [(1.0, 0.05, 0.0), (0.0, 1.0, 0.05), (0.05, 0.0, 1.0)]:
        for rtol in (1e-4, 1e-6, 1e-8):
            run = simulate(body, 100.0, method=method, rtol=rtol, omega0=spin)
            R = exact.free_body_rotation(body.inertia, spin, run.t)
            angles = [np.linalg.norm(so3.log(a.T @ b)) for a, b in zip(R, run.R, strict=True)]
            ratios.append(max(angles) / rtol)
    assert max(ratios) <= 5.0, [f"{r:.2g}" for r in ratios]
    assert "within 5× `rtol`, from 1e-4 to 1e-8" in " ".join(README.split())
