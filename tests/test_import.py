"""``import tumble`` is light: the heavy dependencies load only when a name needs them.

Each check runs in a fresh interpreter, since this test session has long imported them all.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import tumble

HEAVY = ("numba", "trimesh", "xarray", "plotly", "matplotlib")
SOURCE = Path(tumble.__file__).parents[1]


def fresh(code: str) -> subprocess.CompletedProcess[str]:
    """Run ``code`` in a new interpreter that imports this checkout's tumble."""
    return subprocess.run(
        [sys.executable, "-c", code],
        cwd=SOURCE,
        env={**os.environ, "PYTHONPATH": str(SOURCE)},
        capture_output=True,
        text=True,
        timeout=120,
    )


def heavy_modules_after(statement: str) -> list[str]:
    result = fresh(
        f"import json, sys\n{statement}\n"
        f"print(json.dumps(sorted(set({HEAVY!r}) & set(sys.modules))))"
    )
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


@pytest.mark.parametrize(
    "statement",
    [
        "import tumble",
        "from tumble import solve",
        "import tumble.io",
        "import tumble.mass",
        "import tumble.meshes",
        "import tumble.exact",
        "import tumble.scenarios",
        "import tumble.cli",
    ],
)
def test_import_loads_none_of_the_heavy_dependencies(statement):
    assert heavy_modules_after(statement) == []


def test_the_heavy_dependencies_load_when_a_name_needs_them():
    # the check above can fail: a compiled run loads the kernels (and numba) on first use
    run = "import tumble\ntumble.simulate(tumble.RigidBody(1.0, [1, 1, 1]), 0.1, h=0.1)"
    assert "numba" not in heavy_modules_after("import tumble\ntumble.simulate_batch")
    assert "numba" in heavy_modules_after(run)


def test_scipy_special_loads_only_where_the_elliptic_functions_need_it():
    # 0.18 s of import: simulate and simulate_batch do not need it, the exact references do
    loaded = "print('scipy.special' in sys.modules)"
    names = "import sys\nfrom tumble import RigidBody, simulate, simulate_batch, exact\n"
    period = "exact.free_body_period([1.0, 2.0, 3.0], [0.1, 1.0, 0.05])\n"
    assert fresh(names + loaded).stdout.split() == ["False"]
    assert fresh(names + period + loaded).stdout.split() == ["True"]


def test_the_package_is_this_checkout():
    result = fresh("import tumble; print(tumble.__file__)")
    assert Path(result.stdout.strip()) == Path(tumble.__file__)


@pytest.mark.parametrize("name", tumble.__all__)
def test_every_public_name_resolves_to_its_module_object(name):
    value = getattr(tumble, name)
    origin = (
        "tumble.ode"
        if name in {"ButcherTableau", "OdeResult", "Status", "solve"}
        else "tumble.sweeps"
        if name == "sweep"
        else "tumble.report_card"
        if name == "report"
        else "tumble.rigid"
    )
    if name in {"exact", "mass", "meshes", "so3", "structural"}:
        assert value is sys.modules[f"tumble.{name}"]
    else:
        assert value is getattr(sys.modules[origin], name)


def test_dir_lists_the_names_before_they_are_imported():
    result = fresh(
        "import sys, tumble\n"
        "names = dir(tumble)\n"
        "print(all(n in names for n in tumble.__all__), 'tumble.rigid' in sys.modules)"
    )
    assert result.stdout.split() == ["True", "False"], result.stderr


def test_version_is_the_installed_metadata():
    from importlib.metadata import version

    assert tumble.__version__ == version("tumble")


def test_an_unknown_name_raises_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'simulat'"):
        tumble.simulat  # noqa: B018


def test_a_kernels_first_call_is_announced_once(caplog):
    import logging

    from numba import njit

    from tumble._progress import announce_compilation

    @njit(cache=False)
    def kernel(x):
        return x + 1

    with caplog.at_level(logging.INFO, logger="tumble"):
        announce_compilation(kernel, "the test kernel")
        kernel(1.0)
        announce_compilation(kernel, "the test kernel")
    messages = [r.getMessage() for r in caplog.records if r.name == "tumble.compile"]
    assert len(messages) == 1 and "compiled on the first call after installation" in messages[0]
    assert messages[0].startswith("preparing the test kernel (numba: ")  # one article
