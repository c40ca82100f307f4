"""The ``tumble`` command: parse, call the library, report. Nothing else lives here."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from tumble import scenarios
from tumble.io import write_run_folder

app = typer.Typer(
    help="Simulate rigid bodies and vibrating structures; write run folders.",
    no_args_is_help=True,
    add_completion=False,
)
console = Console()
errors = Console(stderr=True)


def _fail(message: str) -> typer.Exit:
    errors.print(f"[bold red]error:[/] {message}", highlight=False)
    return typer.Exit(code=2)


@app.command("list")
def list_scenarios() -> None:
    """List the built-in scenarios, one line each."""
    table = Table("scenario", "what it shows", box=None)
    for name in scenarios.names():
        table.add_row(name, scenarios.get(name).SUMMARY)
    console.print(table)


@app.command()
def run(
    name: Annotated[str, typer.Argument(help="A built-in scenario (see `tumble list`).")],
    out: Annotated[Path | None, typer.Option(help="Run folder (default: runs/NAME).")] = None,
    force: Annotated[bool, typer.Option(help="Overwrite files in an existing folder.")] = False,
) -> None:
    """Run a scenario and write its run folder (summary.json and pictures)."""
    try:
        scenario = scenarios.get(name)
        result = scenario.run()
        folder = write_run_folder(result, out or Path("runs") / name, force=force)
    except ValueError as error:
        raise _fail(str(error)) from None
    table = Table(title=f"{name}: {folder}", box=None, show_header=False)
    for key, value in result.summary.items():
        if isinstance(value, str | int | float | bool) or value is None:
            table.add_row(key, value if isinstance(value, str) else json.dumps(value))
    console.print(table)
    console.print(f"full summary: {folder / 'summary.json'}", highlight=False)


def main() -> None:  # pragma: no cover - console-script entry
    app()
