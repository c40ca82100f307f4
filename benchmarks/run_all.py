"""Run every benchmark (``make bench``) and write ``benchmarks/results.md``.

Each ``benchmarks/bench_*.py`` has ``main(argv) -> str``: it prints its tables and returns a
markdown section (heading, table, notes). This script calls them in turn and writes a header
(CPU, date, versions, load) followed by each section. ``--quick`` (smaller sizes, fewer
repeats) prints only, unless ``--out`` names a file.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy loads OpenBLAS

import argparse  # noqa: E402
import datetime  # noqa: E402
import importlib  # noqa: E402
import sys  # noqa: E402
import traceback  # noqa: E402
from pathlib import Path  # noqa: E402

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))

from _timing import load, machine, versions  # noqa: E402

BENCHMARKS = [
    "bench_rigid",
    "bench_adaptive",
    "bench_geometric",
    "bench_published",
    "bench_heyoka",
    "bench_structural",
    "bench_ode",
    "bench_import",
    "bench_sweep",
    "bench_call",
    "bench_cold",
]


def section(name: str, argv: list[str]) -> str:
    """The markdown section of one benchmark; a note in its place if it fails or returns none."""
    try:
        module = importlib.import_module(name)
        result = module.main(argv)
    except Exception:  # noqa: BLE001 — one broken benchmark must not hide the others
        return f"## {name}\n\nFailed:\n\n```\n{traceback.format_exc()}```\n"
    if not isinstance(result, str):
        return (
            f"## {name}\n\n(`{name}.main` printed its tables but returned no markdown section; "
            "see the console output of `make bench`.)\n"
        )
    return result


def header(argv: list[str]) -> str:
    now = datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")
    return "\n".join(
        [
            "# tumble benchmarks",
            "",
            f"- date: {now}{' (`--quick`)' if '--quick' in argv else ''}",
            f"- machine: {machine()}",
            f"- versions: {versions()}",
            f"- OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}; "
            f"{load()} at the start",
            "",
            "Times are medians (min–max) over repeats, peers measured in the same process. "
            "The machine may be shared: read ratios rather than absolute times.",
            "",
        ]
    )


def main(argv: list[str] | None = None) -> str:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes, fewer repeats")
    parser.add_argument("--out", type=Path, help="where to write (default: results.md)")
    parser.add_argument("--only", nargs="*", default=BENCHMARKS, help="benchmark modules")
    args = parser.parse_args(argv)
    passed = ["--quick"] if args.quick else []
    parts = [header(passed)]
    for name in args.only:
        parts.append(section(name, passed).rstrip("\n") + "\n")
        print()
    parts.append(f"Finished with {load()}.\n")
    text = "\n".join(parts)
    out = args.out if args.out or args.quick else HERE / "results.md"
    if out:
        out.write_text(text)
        print(f"wrote {out}")
    return text


if __name__ == "__main__":
    main()
