"""The package's layers, as pyproject.toml's import-linter contract states them.

Both tests run ``lint-imports`` in a fresh process on a source tree: the package under test,
and a copy of it with one import pointing up, to show the contract can be broken.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import tumble

PACKAGE = Path(tumble.__file__).parent
CONFIG = Path(__file__).parents[1] / "pyproject.toml"
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")


def lint_imports(source: Path, config: Path) -> subprocess.CompletedProcess[str]:
    """Run ``lint-imports`` with ``config`` on the ``tumble`` package in ``source`` (``src``).

    The config is found as ``pyproject.toml`` in the working folder, which every import-linter
    2.x reads (``--config`` is deprecated in the newest).
    """
    assert config.name == "pyproject.toml", config
    assert LINT_IMPORTS.is_file(), f"{LINT_IMPORTS} is missing: pip install -e '.[dev]'"
    env = {**os.environ, "PYTHONPATH": str(source), "COLUMNS": "200", "NO_COLOR": "1"}
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache"],
        cwd=config.parent,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_the_package_keeps_its_layers():
    result = lint_imports(PACKAGE.parent, CONFIG)
    output = result.stdout + result.stderr
    assert result.returncode == 0, output
    assert "0 broken" in output, output


def test_an_upward_import_breaks_the_layers(tmp_path):
    source = tmp_path / "src"
    shutil.copytree(PACKAGE, source / "tumble", ignore=shutil.ignore_patterns("__pycache__"))
    control = source / "tumble" / "ode" / "control.py"
    control.write_text(control.read_text() + "\nimport tumble.cli  # the lowest layer, the top\n")
    config = shutil.copy(CONFIG, tmp_path / "pyproject.toml")

    result = lint_imports(source, Path(config))

    output = result.stdout + result.stderr
    assert result.returncode != 0, output
    assert "tumble.ode is not allowed to import tumble.cli" in output, output
    assert "tumble.ode.control -> tumble.cli" in output, output
