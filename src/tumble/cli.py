"""The ``tumble`` command: parse, call the library, report. Nothing else lives here.

Every command exits with 0 on success and 2 on bad input, printing a message that names the
option or key, the bad value and what is allowed (the library's ``ValueError``). ``tumble run``
exits with 3 when a run of the scenario stopped before its end (a state that stopped being
finite, an implicit solve that did not converge): the run folder is written, and the message
says which run stopped, when and why. Numerical warnings of the library stay off the terminal.
"""

from __future__ import annotations

import json
import logging
import warnings
import webbrowser
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn
from rich.table import Table

from tumble import scenarios
from tumble.io import write_run_folder
from tumble.scenarios import ScenarioResult


def _flags_take_no_value() -> None:
    """Show no type after a flag in ``--help`` (typer 0.29 prints ``--quick <bool>``, as if a
    flag took a value; ``--help`` itself too): options that are flags return no type."""
    option = getattr(getattr(typer, "core", None), "TyperOption", None)
    shown = getattr(option, "display_type_rich", None)
    if shown is None or getattr(shown, "flags_take_no_value", False):
        return

    def display_type_rich(self: Any, ctx: Any) -> str | None:
        return None if getattr(self, "is_flag", False) else shown(self, ctx)

    display_type_rich.flags_take_no_value = True  # type: ignore[attr-defined]
    option.display_type_rich = display_type_rich  # type: ignore[union-attr]


_flags_take_no_value()

app = typer.Typer(
    help="Simulate rigid bodies and vibrating structures; write run folders.",
    no_args_is_help=True,
    add_completion=False,
)
console = Console()
errors = Console(stderr=True)


@app.callback()
def _interruptible() -> None:
    # SIGTERM (kill, a job scheduler, a closed container) ends a run as Ctrl-C does: the files
    # being written are removed, and the command exits 130.
    import signal

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    try:
        signal.signal(signal.SIGTERM, interrupt)
    except ValueError:  # not the main thread (an embedding application): leave it alone
        pass


Out = Annotated[Path | None, typer.Option(help="Run folder (default: runs/<name>).")]
Force = Annotated[bool, typer.Option(help="Overwrite files in an existing folder.")]


def _fail(message: str) -> typer.Exit:
    # the message is plain text (it may hold "[options]"): no markup, no hard wrapping
    errors.print("error:", style="bold red", end=" ")
    errors.print(message, markup=False, highlight=False, soft_wrap=True)
    return typer.Exit(code=2)


@contextmanager
def _reported() -> Iterator[None]:
    """Turn the library's ValueError (bad input) into exit code 2 with its message."""
    try:
        yield
    except ValueError as error:
        raise _fail(str(error)) from None


@contextmanager
def _progress(title: str) -> Iterator[Callable[[str], None]]:
    """A progress display on a terminal (stages: the computation, then each file)."""
    progress = Progress(
        SpinnerColumn(),
        TextColumn("{task.description}"),
        BarColumn(),
        TimeElapsedColumn(),
        console=console,
        transient=True,
        disable=not console.is_terminal,
    )
    with progress:
        task = progress.add_task(title, total=None)

        def note(stage: str) -> None:
            progress.update(task, description=f"{title}: {stage}")

        with _status_from_log(note):
            yield note


class _StatusHandler(logging.Handler):
    """Shows the library's INFO messages (a kernel compiling) as the status line."""

    def __init__(self, note: Callable[[str], None]):
        super().__init__(logging.INFO)
        self.note = note

    def emit(self, record: logging.LogRecord) -> None:
        self.note(record.getMessage())


@contextmanager
def _status_from_log(note: Callable[[str], None]) -> Iterator[None]:
    library = logging.getLogger("tumble")
    handler, level = _StatusHandler(note), library.level
    library.addHandler(handler)
    library.setLevel(min(level or logging.WARNING, logging.INFO))
    try:
        yield
    finally:
        library.removeHandler(handler)
        library.setLevel(level)


def _write(
    result: ScenarioResult, out: Path, force: bool, animation: bool, note, mp4: bool = False
) -> Path:
    return write_run_folder(
        result, out, force=force, animation=animation, mp4=mp4,
        on_file=lambda name: note(f"writing {name}"),
    )  # fmt: skip


UNFINISHED = 3
"""``tumble run``'s exit code when a run of the scenario stopped before its end."""

MAX_ROWS = 40
"""The printed summary stops after this many numbers (summary.json has them all)."""


def _scalars(value: Any, key: str = "") -> Iterator[tuple[str, str]]:
    """``(dotted key, text)`` for every number or string in a nested summary."""
    if isinstance(value, dict):
        for name, item in value.items():
            yield from _scalars(item, f"{key}.{name}" if key else str(name))
    elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        for k, item in enumerate(value, start=1):
            yield from _scalars(item, f"{key}[{k}]")
    elif isinstance(value, float):
        yield key, f"{value:.6g}"
    elif isinstance(value, str):
        yield key, value
    elif isinstance(value, list) and value and all(isinstance(v, float) for v in value):
        yield key, "[" + ", ".join(f"{v:.6g}" for v in value) + "]"
    elif key != "files":
        yield key, json.dumps(value)


def _show_summary(title: str, summary: dict, folder: Path) -> None:
    table = Table(title=f"{title}: {folder}", box=None, show_header=False)
    rows = list(_scalars(summary))
    for key, text in rows[:MAX_ROWS]:
        table.add_row(key, text if len(text) < 60 else text[:57] + "…")
    console.print(table)
    more = f" ({len(rows) - MAX_ROWS} more numbers)" if len(rows) > MAX_ROWS else ""
    console.print(f"full summary{more}: {folder / 'summary.json'}", highlight=False)


@app.command("list")
def list_scenarios() -> None:
    """List the built-in scenarios, one line each."""
    table = Table("scenario", "what it shows", box=None)
    for name in scenarios.names():
        table.add_row(name, scenarios.get(name).SUMMARY)
    console.print(table)


@app.command()
def run(
    target: Annotated[
        str, typer.Argument(metavar="NAME|FILE.toml", help="A built-in scenario or a TOML file.")
    ],
    out: Out = None,
    method: Annotated[str | None, typer.Option(help="Integration method.")] = None,
    h: Annotated[float | None, typer.Option("--h", help="Time step (s).")] = None,
    t_end: Annotated[float | None, typer.Option(help="End time (s).")] = None,
    animation: Annotated[
        bool, typer.Option(help="Write animation.gif and view.html (slower).")
    ] = True,
    force: Force = False,
    mp4: Annotated[
        bool,
        typer.Option(
            "--mp4",
            help="Also write animation.mp4 (H.264): beside the GIF, or alone with --no-animation.",
        ),
    ] = False,
) -> None:
    """Run a scenario and write its run folder (data.nc, summary.json, pictures)."""
    from tumble.scenarios import files

    with _reported():
        chosen = files.read_target(target, method=method, h=h, t_end=t_end)
        with _progress(f"running {chosen.scenario}") as note, warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # overflow, nan: said in words below
            result = chosen.run()
            folder = _write(
                result, out or Path("runs") / chosen.folder, force,
                animation and chosen.animation, note, mp4,
            )  # fmt: skip
    _show_summary(chosen.scenario, result.summary, folder)
    stopped = result.unfinished()
    if stopped:
        for where, message in stopped:
            errors.print(f"error: {where} did not reach its end:", style="bold red", end=" ")
            errors.print(message, markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(code=UNFINISHED)


@app.command()
def compare(
    name: Annotated[str, typer.Argument(help="A scenario with a torque-free body.")],
    methods: Annotated[
        str | None, typer.Option(help="Comma-separated methods (default: all but euler).")
    ] = None,
    t_end: Annotated[float, typer.Option(help="End time (s).")] = 10.0,
    out: Out = None,
    force: Force = False,
) -> None:
    """Work–precision: error against wall time and steps for several methods."""
    from tumble.scenarios import compare as comparison

    chosen = comparison.DEFAULT_METHODS if methods is None else _split(methods)
    with _reported(), _progress(f"comparing on {name}") as note:
        result = comparison.run(name, methods=chosen, t_end=t_end)
        folder = _write(result, out or Path("runs") / f"{name}-compare", force, False, note)
    table = Table(title=f"{name}: work–precision, T = {t_end:g} s", box=None)
    for column in ("method", "h or rtol", "steps", "ms", "error |R − R_exact|"):
        table.add_column(column, justify="left" if column == "method" else "right")
    for row in result.summary["points"]:
        table.add_row(
            row["method"],
            f"{row['setting']:.3g}",
            str(row["steps"]),
            f"{row['seconds'] * 1e3:.3f}",
            f"{row['error']:.2e}",
        )
    console.print(table)
    console.print(f"plot: {folder / 'work_precision.png'}", highlight=False)


def _split(methods: str) -> list[str]:
    return [m.strip() for m in methods.split(",") if m.strip()]


@app.command()
def stability(
    n_elements: Annotated[int, typer.Option(help="Beam elements.")] = 20,
    steps: Annotated[int, typer.Option(help="Steps per run of the sweep.")] = 1000,
    out: Out = None,
    force: Force = False,
    analyse: Annotated[
        bool,
        typer.Option(
            "--analyse",
            help="Instead of the sweep, the time-step analyser: amplification.png (spectral "
            "radius, algorithmic damping and period error against Δt/T for every scheme) and "
            "the beam's modes at --dt under each scheme.",
        ),
    ] = False,
    dt: Annotated[
        float | None,
        typer.Option(help="Time step in s of --analyse's mode table (default T₁/20)."),
    ] = None,
) -> None:
    """The cantilever's time-step sweep: which scheme stays bounded at which Δt (with
    --analyse: each scheme's amplification against Δt/T and the beam's modes under it)."""
    from tumble.scenarios import beam

    if analyse:
        _analyse_steps(n_elements, dt, out or Path("runs") / "stability-analysis", force)
        return
    with _reported(), _progress("stability sweep") as note:
        result = beam.stability(n_elements=n_elements, sweep_steps=steps)
        folder = _write(result, out or Path("runs") / "stability", force, False, note)
    summary = result.summary
    # a row per scheme, a column per step: every scheme of SCHEMES in 80 columns
    table = Table(
        title=f"Δt / Δt_crit, Δt_crit = {summary['critical_dt_semi_implicit']:.4g} s "
        f"(semi-implicit, {summary['critical_mode']} mode)",
        box=None, collapse_padding=True, pad_edge=False,
    )  # fmt: skip
    table.add_column("scheme")
    for factor in summary["factors"]:
        table.add_column(f"{factor:g}", justify="right")
    for scheme, verdict in summary["schemes"].items():
        cells = ["stable" if stable else "[red]grows[/]" for stable in verdict["stable"]]
        table.add_row(scheme, *cells)
    console.print(table)
    console.print(f"plot: {folder / 'stability_sweep.png'}", highlight=False)


def _mode_cell(radius: float, value: float) -> str:
    """A cell of the per-mode table: 'grows' where ρ > 1, '—' where there is no period."""
    if radius > 1 + 1e-12:
        return "[red]grows[/]"
    return "—" if value != value else f"{abs(value) if abs(value) < 5e-4 else value:.3f}"


def _analyse_steps(n_elements: int, dt: float | None, folder: Path, force: bool) -> None:
    """``tumble stability --analyse``: the amplification picture and the per-mode tables."""
    from tumble.io import write_figures
    from tumble.scenarios import beam

    with _reported():
        analysis = beam.analyse_steps(n_elements, dt)
        try:
            path, comparison = write_figures(folder, analysis.figures, force=force)
        except FileExistsError as error:
            raise _fail(f"{error.filename} exists; pass --force to overwrite it") from None
    table, step = analysis.table, analysis.dt
    for name, values in (("algorithmic damping ratio ξ̄", table.damping_ratio),
                         ("period elongation (T̄ − T)/T", table.period_elongation)):  # fmt: skip
        # one space between the columns: every scheme of SCHEMES fits in 80 columns
        grid = Table(title=f"{name}, cantilever with {n_elements} elements, Δt = {step:.4g} s "
                     "(—: no period, the mode is damped out within a step)", box=None,
                     collapse_padding=True, pad_edge=False)  # fmt: skip
        for column in ("mode", "ω [rad/s]", "Ω = ωΔt", *table.schemes):
            grid.add_column(column.replace("-", "- "), justify="right", overflow="fold")
        for k, w in enumerate(table.omega):
            cells = [
                _mode_cell(radius[k], v[k])
                for radius, v in zip(table.spectral_radius, values, strict=True)
            ]
            # ω without an exponent, so the column stays narrow
            frequency = f"{w:.0f}" if w >= 100 else f"{w:.4g}"
            grid.add_row(str(k + 1), frequency, f"{w * step:.3g}", *cells)
        console.print(grid)
    console.print(f"plots: {path}, {comparison}", highlight=False)


Grid = Annotated[
    list[str] | None,
    typer.Option(
        "--grid",
        help="PATH=start:stop:count or PATH=a,b,c (repeat; the values multiply). "
        "Default: the file's sweep.grid table.",
    ),
]


@app.command()
def sweep(
    scenario: Annotated[
        str,
        typer.Argument(
            metavar="NAME|FILE.toml",
            help="A scenario file (.toml; rigid-body or a built-in's) or a built-in scenario's "
            "name (tumble list; its summary's numbers are stored per member).",
        ),
    ],
    grid: Grid = None,
    out: Annotated[Path, typer.Option(help="The Zarr store to write (a folder).")] = Path(
        "runs/sweep.zarr"
    ),
    scheduler: Annotated[
        str | None, typer.Option(help="A Dask scheduler's address (default: a local cluster).")
    ] = None,
    resume: Annotated[
        bool, typer.Option("--resume", help="Complete an existing store of this sweep.")
    ] = False,
    chunk: Annotated[int | None, typer.Option(help="Members per task.")] = None,
    timeout: Annotated[float, typer.Option(help="Seconds to wait for --scheduler.")] = 10.0,
    draw: Annotated[
        str | None,
        typer.Option(
            "--map",
            help="Draw this summary variable over the two swept dimensions: flip_period "
            "(default), energy_error, wall_time, status, n_steps; for a built-in, a number of "
            "its summary.",
        ),
    ] = None,
    verbose: Annotated[
        bool, typer.Option("--verbose", help="Show Dask's own log lines (quiet by default).")
    ] = False,
) -> None:
    """Run a scenario over a grid of options on Dask, into one Zarr store (and draw a map)."""
    from tumble.sweeps import Interrupted
    from tumble.sweeps import sweep as run_sweep
    from tumble.sweeps.picture import check_map
    from tumble.sweeps.text import grid_from_arguments

    def on_plan(plan, estimate) -> None:
        if draw:
            check_map(plan, draw, "--map")
        console.print(f"sweep: {estimate.text()}", highlight=False, soft_wrap=True)

    with _reported(), _dask_quiet(verbose):
        values = grid_from_arguments(grid or [])
        try:
            with _members_bar() as progress:
                run_sweep(
                    scenario, values, client=scheduler, store=out, chunk=chunk, resume=resume,
                    timeout=timeout, progress=progress, on_plan=on_plan,
                )  # fmt: skip
        except Interrupted as stopped:  # after the bar is gone
            errors.print(str(stopped).replace("resume=True", "`--resume`"),
                         markup=False, highlight=False, soft_wrap=True)  # fmt: skip
            raise typer.Exit(code=130) from None
        _show_sweep(out, draw)


@contextmanager
def _members_bar() -> Iterator[Callable[[int, int], None]]:
    """The sweep's display: what it is doing (the library's status messages), then its bar
    of members, counted from the first count on (never "0/None members")."""
    bar = Progress(SpinnerColumn(), TextColumn("{task.description}"), BarColumn(),
                   TextColumn("{task.fields[counts]}"), TimeElapsedColumn(), console=console,
                   transient=True, disable=not console.is_terminal)  # fmt: skip
    with bar:
        task = bar.add_task("sweep: checking the plan", total=None, counts="")
        started: list[bool] = []

        def progress(done: int, total: int) -> None:
            started.append(True)
            bar.update(task, description="sweep", completed=done, total=total,
                       counts=f"{done}/{total} members")  # fmt: skip

        def note(stage: str) -> None:
            if not started:  # then the bar says it all
                bar.update(task, description=f"sweep: {stage.removeprefix('sweep: ')}")

        with _status_from_log(note):
            yield progress


@contextmanager
def _dask_quiet(verbose: bool) -> Iterator[None]:
    """Dask's log lines off (a recovered worker is not an error to the user) unless
    ``verbose``: in this process, and in the local workers it starts (they read the level
    from the environment when they import distributed)."""
    import os

    if verbose:
        yield
        return
    loggers = [logging.getLogger(name) for name in ("distributed", "tornado", "bokeh")]
    levels = [logger.level for logger in loggers]
    before = os.environ.get("DASK_LOGGING__DISTRIBUTED")
    os.environ["DASK_LOGGING__DISTRIBUTED"] = "critical"
    for logger in loggers:
        logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for logger, level in zip(loggers, levels, strict=True):
            logger.setLevel(level)
        if before is None:
            os.environ.pop("DASK_LOGGING__DISTRIBUTED", None)
        else:
            os.environ["DASK_LOGGING__DISTRIBUTED"] = before


def _show_sweep(out: Path, draw: str | None) -> None:
    """The sweep's table (members, how they ended, their time) and its map."""
    import xarray as xr

    from tumble.sweeps.picture import draw_map, map_variable

    dataset = xr.open_zarr(out, chunks=None)  # numpy, not dask: one read per variable
    done = dataset["done"].values
    table = Table(title=f"sweep: {out}", box=None, show_header=False)
    table.add_row("members", f"{done.size} ({' x '.join(map(str, done.shape))})")
    if "status" in dataset:
        status = dataset["status"].values
        table.add_row("reached t_end", str(int((status == 0).sum())))
        table.add_row("stopped (failed)", str(int((status < 0).sum())))
    table.add_row("wall time of the members", f"{float(dataset['wall_time'].sum()):.3g} s")
    console.print(table)
    name, note = map_variable(dataset, draw)
    if note:
        console.print(note)
    if name is not None:
        picture = draw_map(dataset, name, out.with_name(f"{out.stem}-{name}.png"))
        console.print(f"map: {picture}", highlight=False)


@app.command()
def view(
    run_dir: Annotated[Path, typer.Argument(help="A run folder written by `tumble run`.")],
    open_browser: Annotated[
        bool, typer.Option("--open/--no-open", help="Open the page in a web browser.")
    ] = True,
) -> None:
    """Write (if missing) and open the run's interactive viewer, view.html."""
    with _reported():
        page = scenarios.view_page(run_dir)
    console.print(f"viewer: {page}", highlight=False)
    if open_browser and not webbrowser.open(page.resolve().as_uri()):
        console.print("no web browser found; open the file above yourself")


@app.command("mass")
def mass_properties(
    mesh_file: Annotated[Path, typer.Argument(help="A closed triangle mesh (STL, OBJ, PLY…).")],
    density: Annotated[float, typer.Option(help="Density (kg/m³).")],
    fix_inside_out: Annotated[
        bool, typer.Option(help="Flip an inside-out mesh instead of refusing it.")
    ] = False,
) -> None:
    """Mass, centre of mass, inertia and principal axes of a mesh of uniform density."""
    from tumble import meshes

    with _reported(), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            properties = meshes.from_mesh(  # a refusal names the file, as given
                mesh_file, density=density, fix_inside_out=fix_inside_out
            )
        except ValueError as error:  # name the command-line option, not the argument
            message = str(error).replace("fix_inside_out=True", "--fix-inside-out")
            raise ValueError(message) from None
        moments, axes = properties.principal()
    for warning in caught:
        console.print(f"note: {warning.message}", highlight=False, markup=False)
    table = Table(title=f"{mesh_file} at ρ = {density:g} kg/m³", box=None)
    table.add_column("quantity")
    table.add_column("unit")
    table.add_column("value", no_wrap=True)
    table.add_row("volume", "m³", f"{properties.mass / density:.6g}")
    table.add_row("mass", "kg", f"{properties.mass:.6g}")
    table.add_row("centre of mass", "m", _vector(properties.com))
    for k, row in enumerate(properties.inertia):
        table.add_row("inertia (COM)" if k == 0 else "", "kg m²" if k == 0 else "", _vector(row))
    table.add_row("principal moments", "kg m²", _vector(moments))
    for k, column in enumerate(axes.T):
        table.add_row(f"principal axis {k + 1}", "", _vector(column))
    console.print(table)


def _vector(values) -> str:
    return " ".join(f"{v: .5e}" for v in values)


@app.command("report")
def report_card(
    quick: Annotated[
        bool, typer.Option("--quick", help="Shorter long runs, one timing: under a minute.")
    ] = False,
    out: Annotated[Path, typer.Option(help="Folder for report.md, .html, .nc.")] = Path(
        "runs/report"
    ),
) -> None:
    """The integrator report card: every method measured on the same problems, peers beside."""
    from tumble.report_card import report

    # the bar names the compiling phase; the kernels' own notices would scroll past it
    with _reported(), _status_from_log(lambda stage: None):
        card = report(out, quick=quick, progress=console.is_terminal)
    table = Table(title=f"report card: {len(card.results)} methods in {card.seconds:.0f} s",
                  box=None)  # fmt: skip
    for column in ("method", "order declared", "measured", "energy (P1)", "declaration"):
        table.add_column(column)
    for result in card.results:
        table.add_row(
            result.row.name, f"{result.row.order:g}", f"{result.order.measured:.2f}",
            result.free.energy_law,
            "[red]contradicted[/]" if result.contradictions else "agrees",
        )  # fmt: skip
    console.print(table)
    skipped: dict[str, list[str]] = {}
    for peer, reason in card.skipped.items():
        skipped.setdefault(reason, []).append(peer)
    for reason, peers in skipped.items():
        console.print(f"{', '.join(peers)}: {reason}", highlight=False)
    for name, why in card.contradictions.items():
        errors.print(f"contradiction: {name}:", style="bold red", end=" ")
        errors.print("; ".join(why), markup=False, highlight=False, soft_wrap=True)
    for name in ("report.md", "report.html", "report.nc"):
        console.print(f"{name}: {Path(out) / name}", highlight=False)


def main() -> None:  # pragma: no cover - console-script entry
    app()
