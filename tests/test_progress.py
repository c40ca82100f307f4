"""Word of a kernel compiling reaches a user who set nothing up: one line on stderr.

Each test runs a fresh Python (a kernel's first call is a process's first), with logging as
a script, a REPL or a notebook leaves it: unconfigured.
"""

import subprocess
import sys
from pathlib import Path

SRC = str(Path(__file__).parents[1] / "src")


def fresh(code: str) -> subprocess.CompletedProcess:
    env = {"PYTHONPATH": SRC, "PATH": "/usr/bin:/bin"}
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=600, env=env
    )


def test_a_first_simulate_batch_call_says_what_it_is_doing_on_stderr():
    done = fresh(
        "import tumble\n"
        "body = tumble.RigidBody.from_mass_properties(tumble.mass.t_handle())\n"
        "tumble.simulate_batch(body, 0.02, h=0.01, omega0=[[1.0, 0.05, 0.0]] * 2)\n"
        "tumble.simulate_batch(body, 0.02, h=0.01, omega0=[[1.0, 0.05, 0.0]] * 2)\n"
    )
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    assert lines == [
        "tumble: preparing the batch loop of rkmk4 (numba: compiled on the first call after "
        "installation, 5-30 s; loaded from its cache after, about 2 s)"
    ]  # once: the second call has its kernel
    assert done.stdout == ""  # the library prints nothing to stdout


FAKE = "import types\nfrom tumble._progress import announce_compilation\n"
KERNEL = "announce_compilation(types.SimpleNamespace(overloads={}), 'a kernel')\n"


def test_the_notice_is_silenced_through_its_logger():
    quiet = fresh(
        FAKE + "import logging\n"
        "logging.getLogger('tumble.compile').setLevel(logging.WARNING)\n" + KERNEL
    )
    assert quiet.returncode == 0 and quiet.stderr == ""  # fmt: skip


def test_a_program_that_configured_logging_gets_the_notice_through_its_own_handlers():
    configured = fresh(FAKE + "import logging, sys\n"
                       "logging.basicConfig(stream=sys.stdout, format='%(name)s %(message)s')\n"
                       + KERNEL)  # fmt: skip
    assert configured.returncode == 0 and configured.stderr == ""
    assert configured.stdout.startswith("tumble.compile preparing a kernel (numba: ")
