"""Run folders: every file written whole or not at all.

A run folder holds ``summary.json`` (the headline numbers) and the scenario's figures. Each file
is first written under a temporary name in the same folder and then renamed, so a crash never
leaves half a file behind.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Callable
from pathlib import Path

from tumble.scenarios._base import ScenarioResult

log = logging.getLogger(__name__)


def atomic_write(path: str | Path, writer: Callable[[Path], None]) -> Path:
    """Call ``writer(tmp)`` on a temporary sibling of ``path``, then rename it to ``path``.

    The temporary file keeps the suffix (writers such as matplotlib read the format from it)
    and is removed if ``writer`` raises.
    """
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.partial{path.suffix}")
    try:
        writer(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path


def write_json(path: str | Path, data: dict) -> Path:
    """Write ``data`` as indented JSON, atomically."""
    text = json.dumps(data, indent=2, sort_keys=False) + "\n"
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def prepare_folder(out: str | Path, *, force: bool = False) -> Path:
    """Create the run folder ``out``; refuse a non-empty one unless ``force``."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"out={str(out)!r} exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not force:
        raise ValueError(
            f"out={str(out)!r} already holds files; choose another folder or pass force=True "
            "(--force on the command line) to overwrite them"
        )
    out.mkdir(parents=True, exist_ok=True)
    return out


def write_run_folder(result: ScenarioResult, out: str | Path, *, force: bool = False) -> Path:
    """Write a scenario's ``summary.json`` and figures into the folder ``out``.

    Returns
    -------
    Path
        The folder.
    """
    out = prepare_folder(out, force=force)
    for name, writer in result.figures:
        log.info("writing %s", out / name)
        atomic_write(out / name, writer)
    write_json(out / "summary.json", result.summary)
    return out
