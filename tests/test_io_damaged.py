"""A damaged data.nc is refused in one message, with nothing else on stderr (issue 18, item 11).

h5netcdf leaves a half-opened file behind when the root group's header is damaged; when it
was collected Python printed "Exception ignored in: <function File.close ...>" and a
traceback after tumble's own message. The check runs in a fresh interpreter, because the noise
comes at garbage collection, where pytest would catch it as a warning of some later test.
"""

import subprocess
import sys

from tumble import io, scenarios


def test_a_damaged_root_header_gives_one_message_and_no_noise(tmp_path):
    io.write_run_folder(scenarios.get("projectile").run(), tmp_path)
    raw = bytearray((tmp_path / "data.nc").read_bytes())
    root = raw.find(b"OHDR")  # the first object header is the root group's
    raw[root : root + 40] = b"\xab" * 40
    (tmp_path / "data.nc").write_bytes(raw)
    script = (
        "import sys, tumble.io\n"
        "try:\n    tumble.io.load(sys.argv[1])\n"
        "except ValueError as error:\n    print(error)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script, str(tmp_path)], capture_output=True, text=True, timeout=120
    )
    assert "data.nc could not be read" in done.stdout and "damaged" in done.stdout
    assert done.stderr == ""
