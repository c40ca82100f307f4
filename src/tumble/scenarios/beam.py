"""Seed 003: a steel cantilever under a step tip load, stepped by the seed's four schemes.

The 1 m cantilever with a 1 cm square steel section (E = 210 GPa, ρ = 7850 kg/m³) is
clamped at x = 0 and loaded at the tip by a constant force from t = 0, starting at rest.
The run computes its first four natural frequencies against the exact roots of
``cos βL cosh βL = −1``, steps the ``explicit``, ``semi-implicit``, ``implicit`` and
``midpoint`` schemes with one time step (``T₁/200`` by default, far above the
semi-implicit limit ``2/ω_max``), sweeps the time step across that limit, and keeps the
beam every 10 steps of the midpoint run as frames for an animation.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from tumble import _checks, structural
from tumble.io import FigureWriter, ScenarioResult
from tumble.scenarios._common import json_number
from tumble.scenarios.option_models import OptionRules
from tumble.viz import structural as viz

NAME = "beam"
SUMMARY = "Seed 003: steel cantilever under a step tip load, four time-stepping schemes"

BETA_L = np.array([1.87510406871196, 4.69409113297418, 7.85475743823761, 10.9955407348755])
"""The first roots of ``cos βL cosh βL = −1`` (clamped–free beam)."""

OPTION_RULES = OptionRules(
    positive=["length", "n_elements", "E", "rho", "width", "height", "steps_per_period",
              "n_steps", "sweep_steps", "frame_every"],
)  # fmt: skip
"""What :func:`run`'s options must be beyond its signature (the tip load takes any sign)."""

SWEEP_FACTORS = (0.25, 0.5, 0.9, 0.98, 1.02, 1.1, 2.0, 10.0, 100.0)
"""Sweep time steps, as multiples of the semi-implicit critical step."""

STEEL = {"length": 1.0, "E": 210e9, "rho": 7850.0, "width": 0.01, "height": 0.01, "tip_load": 1.0}
"""Seed 003's cantilever (the defaults of :func:`run`): 1 m long [m], E = 210 GPa [Pa],
ρ = 7850 kg/m³, a 1 cm × 1 cm section [m], a 1 N step load at the tip [N]."""


def steel_cantilever(n_elements: int = 20) -> structural.LinearSystem:
    """Seed 003's steel cantilever (:data:`STEEL`) in ``n_elements`` Euler–Bernoulli elements.

    The one beam of ``tumble run beam`` (its defaults), ``tumble stability`` (with and
    without ``--analyse``) and the report card's structural table
    (:func:`tumble.report_card.structural_rows`, 4 elements).

    Examples
    --------
    >>> beam = steel_cantilever(8)
    >>> beam.n_dofs, round(float(beam.natural_frequencies(1)[0]), 2)  # ω₁ [rad/s]
    (16, 52.5)
    """
    return structural.cantilever(STEEL["length"], n_elements, STEEL["E"], STEEL["rho"],
                                 STEEL["width"], STEEL["height"], STEEL["tip_load"])  # fmt: skip


def run(
    *,
    length: float = STEEL["length"],
    n_elements: int = 20,
    E: float = STEEL["E"],
    rho: float = STEEL["rho"],
    width: float = STEEL["width"],
    height: float = STEEL["height"],
    tip_load: float = STEEL["tip_load"],
    steps_per_period: int = 200,
    n_steps: int = 2000,
    sweep_steps: int = 1000,
    frame_every: int = 10,
) -> ScenarioResult:
    """Compute the scenario; pure (no files, no printing).

    Parameters
    ----------
    length, n_elements, E, rho, width, height, tip_load
        The cantilever (:func:`tumble.structural.cantilever`): [m], –, [Pa], [kg/m³],
        [m], [m], [N]; by default :func:`steel_cantilever`'s.
    steps_per_period : int
        Δt = T₁ / steps_per_period for the four scheme runs.
    n_steps : int
        Steps of each scheme run.
    sweep_steps : int
        Steps of each run in the stability sweep.
    frame_every : int
        Keep the midpoint beam every this many steps.

    Returns
    -------
    ScenarioResult
        ``summary``: frequencies and errors, Δt, the critical step, per-scheme energy
        and tip results, the sweep; ``data``: the system, the runs, the sweeps and the
        frames; ``figures``: energy per scheme, the sweep, the beam shapes; one dataset per
        scheme; ``animation.gif``: the midpoint run's beam, at most :data:`MAX_FRAMES` frames.
    """
    for name, value in (
        ("steps_per_period", steps_per_period),
        ("n_steps", n_steps),
        ("sweep_steps", sweep_steps),
        ("frame_every", frame_every),
    ):
        _checks.count(name, value)
    beam = structural.cantilever(length, n_elements, E, rho, width, height, tip_load)
    omega = beam.natural_frequencies(4)
    dt = 2 * np.pi / omega[0] / steps_per_period
    runs = {s: structural.integrate(beam, s, dt, n_steps=n_steps) for s in structural.SEED_SCHEMES}
    critical = structural.critical_dt(beam, "semi-implicit")
    dts = np.sort(np.r_[critical.dt * np.array(SWEEP_FACTORS), dt])
    sweeps = [
        structural.stability_sweep(beam, s, dts, sweep_steps) for s in structural.SEED_SCHEMES
    ]
    midpoint = runs["midpoint"]
    frames = {
        "t": midpoint.t[::frame_every],
        "x": beam.expand(midpoint.x[::frame_every]),
        "every": frame_every,
        "scheme": "midpoint",
        "nodes": beam.nodes,
    }
    settings = {
        "length": length, "n_elements": n_elements, "E": E, "rho": rho, "width": width,
        "height": height, "tip_load": tip_load, "steps_per_period": steps_per_period,
        "n_steps": n_steps, "sweep_steps": sweep_steps, "frame_every": frame_every,
    }  # fmt: skip
    scale = structural.energy_scale(beam)
    return ScenarioResult(
        NAME,
        _summary(settings, beam, omega, dt, critical, runs, sweeps, scale),
        data={"system": beam, "runs": runs, "sweeps": sweeps, "frames": frames},
        figures=_figures(beam, runs, sweeps, scale, frame_every),
        datasets={scheme: _dataset(response) for scheme, response in runs.items()},
        attrs={**settings, "dt": dt, "schemes": list(runs)},
        # the conditionally stable schemes diverging past their limit is what the run shows
        expected_stops=tuple(
            f"runs.{scheme}" for scheme in ("explicit", "semi-implicit") if scheme in runs
        ),
        animations=[("animation.gif", partial(_animate, beam, midpoint, frame_every))],
    )


MAX_FRAMES = 100
"""At most this many frames in ``animation.gif`` (``frame_every`` is raised to keep it so)."""


def _animate(beam, response, frame_every: int, path) -> None:
    every = max(frame_every, -(-len(response.t) // MAX_FRAMES))
    title = f"{NAME} — tip-loaded cantilever, every {every} steps"
    viz.beam_animation(beam, response, path, every=every, title=title)


def _dataset(response):
    """One scheme's run as an ``xarray.Dataset``: free-DOF state, energy and tip against time."""
    import xarray as xr

    state = ("time", "dof")
    data_vars = {
        "x": (state, response.x, {"units": "m or rad", "long_name": "free-DOF displacement"}),
        "y": (state, response.y, {"units": "m/s or rad/s", "long_name": "free-DOF velocity"}),
        "energy": ("time", response.energy, {"units": "J", "long_name": "total energy"}),
        "tip": ("time", response.tip_displacement, {"units": "m", "long_name": "tip deflection"}),
    }
    attrs = {"scheme": response.scheme, "dt": response.dt, "status": response.status}
    coords = {"time": ("time", response.t, {"units": "s"})}
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def exact_frequencies(
    length: float, E: float, rho: float, width: float, height: float
) -> np.ndarray:
    """``ω_k = (β_k L)² sqrt(EI/(ρ A L⁴))`` [rad/s] of the first four clamped–free modes."""
    EI, rho_A = E * width * height**3 / 12, rho * width * height
    return BETA_L**2 * np.sqrt(EI / (rho_A * length**4))


def _summary(settings, beam, omega, dt, critical, runs, sweeps, scale) -> dict[str, Any]:
    """Headline numbers, JSON-serialisable (inf and NaN become None)."""
    keys = ("length", "E", "rho", "width", "height")
    exact = exact_frequencies(*(settings[k] for k in keys))
    EI = settings["E"] * settings["width"] * settings["height"] ** 3 / 12
    static_tip = settings["tip_load"] * settings["length"] ** 3 / (3 * EI)
    per_scheme = {
        scheme: _scheme_summary(response, scale, static_tip) for scheme, response in runs.items()
    }
    return {
        **settings,
        "n_dofs": beam.n_dofs,
        "omega": omega.tolist(),
        "omega_exact": exact.tolist(),
        "omega_relative_error": (omega / exact - 1).tolist(),
        "dt": dt,
        "critical_dt_semi_implicit": critical.dt,
        "critical_mode": critical.mode,
        "omega_max": critical.omega,
        "static_tip_deflection": static_tip,
        "energy_scale": scale,
        "schemes": per_scheme,
        "sweep": {
            sweep.scheme: {
                "dt": sweep.dt.tolist(),
                "energy_growth": [json_number(g) for g in sweep.energy_growth],
                "stable": sweep.stable.tolist(),
            }
            for sweep in sweeps
        },
    }


def _scheme_summary(response, scale: float, static_tip: float) -> dict[str, Any]:
    """Energy and tip numbers of one run, relative to the energy scale and static tip."""
    with np.errstate(over="ignore", invalid="ignore"):
        change = (response.energy - response.energy[0]) / scale
    tip = response.tip_displacement / static_tip
    return {
        "status": response.status,
        "message": response.message,
        "energy_change_max": json_number(np.max(np.abs(change))),
        "energy_change_final": json_number(change[-1]),
        "tip_mean_over_static": json_number(tip.mean()) if response.success else None,
        "tip_max_over_static": json_number(tip.max()) if response.success else None,
    }


def _figures(beam, runs, sweeps, scale, every) -> list:
    figures = [
        (
            f"energy_{scheme}.png",
            viz.figure_writer(
                viz.energy_figure, response, scale=scale, title=f"{NAME} — {scheme}: total energy"
            ),
        )
        for scheme, response in runs.items()
    ]
    figures.append(
        (
            "stability_sweep.png",
            viz.figure_writer(viz.stability_figure, sweeps, title=f"{NAME} — stability sweep"),
        )
    )
    midpoint = runs["midpoint"]
    period = slice(0, min(len(midpoint.t), 10 * every + 1))  # the first ten frames
    figures.append(
        (
            "beam_shapes.png",
            viz.figure_writer(
                viz.beam_figure,
                beam,
                midpoint.t[period],
                midpoint.x[period],
                every=every,
                title=f"{NAME} — midpoint, every {every} steps",
            ),
        )
    )
    return figures


def stability(
    *,
    n_elements: int = 20,
    sweep_steps: int = 1000,
    schemes: tuple[str, ...] = tuple(structural.SCHEMES),
    factors: tuple[float, ...] = SWEEP_FACTORS,
) -> ScenarioResult:
    """The cantilever's Δt sweep on its own (``tumble stability``): which schemes stay bounded.

    By default every scheme of :data:`tumble.structural.SCHEMES` (the seed's four, Newmark,
    HHT, generalized-α, Bathe, Wilson-θ).

    Each scheme runs ``sweep_steps`` steps from rest under the tip load at
    ``Δt = factor × 2/ω_max`` for each factor (:func:`tumble.structural.stability_sweep`);
    the energy growth ``max (E − E₀)`` over the energy scale tells stable (< 1) from not.

    Returns
    -------
    ScenarioResult
        ``summary``: the critical step and its mode, and per scheme the growth and the
        verdict at each Δt; figure ``stability_sweep.png``; dataset with ``energy_growth``
        against (scheme, dt).

    Examples
    --------
    >>> result = stability(n_elements=8, sweep_steps=500, schemes=("semi-implicit",),
    ...                    factors=(0.9, 1.1))
    >>> result.summary["schemes"]["semi-implicit"]["stable"]
    [True, False]
    """
    _checks.count("sweep_steps", sweep_steps)
    if not schemes:
        raise _checks.fail(
            "schemes", schemes, f"at least one of {', '.join(map(repr, structural.SCHEMES))}"
        )
    beam = steel_cantilever(n_elements)
    critical = structural.critical_dt(beam, "semi-implicit")
    dts = critical.dt * np.asarray(factors, dtype=float)
    sweeps = [structural.stability_sweep(beam, s, dts, sweep_steps) for s in schemes]
    summary = {
        "scenario": "stability",
        "n_elements": n_elements,
        "sweep_steps": sweep_steps,
        "critical_dt_semi_implicit": critical.dt,
        "critical_mode": critical.mode,
        "factors": list(factors),
        "dt": dts.tolist(),
        "schemes": {
            sweep.scheme: {
                "energy_growth": [json_number(g) for g in sweep.energy_growth],
                "stable": sweep.stable.tolist(),
            }
            for sweep in sweeps
        },
    }
    title = f"{NAME} — stability sweep, {n_elements} elements, {sweep_steps} steps"
    return ScenarioResult(
        "stability",
        summary,
        data={"system": beam, "sweeps": sweeps},
        figures=[
            ("stability_sweep.png", viz.figure_writer(viz.stability_figure, sweeps, title=title))
        ],
        datasets={"": _sweep_dataset(sweeps)},
        attrs={"n_elements": n_elements, "sweep_steps": sweep_steps, "critical_dt": critical.dt},
    )


def _sweep_dataset(sweeps):
    """Energy growth against (scheme, dt) as an ``xarray.Dataset``."""
    import xarray as xr

    growth = np.array([sweep.energy_growth for sweep in sweeps])
    return xr.Dataset(
        {"energy_growth": (("scheme", "dt"), growth, {"units": "1"})},
        coords={"scheme": [s.scheme for s in sweeps], "dt": ("dt", sweeps[0].dt, {"units": "s"})},
    )


# --- the time-step analyser (``tumble stability --analyse``) ----------------------------------

ANALYSIS_OMEGA = 2 * np.pi * np.logspace(-2, 3, 241)
"""The frequencies (rad/s) of the amplification picture: Δt/T from 10⁻² to 10³ at Δt = 1 s."""
COMPARISON_STEPS = 500
"""Steps of each scheme's run against the exact response, at Δt = T₁/100 (five periods)."""


@dataclass(frozen=True)
class StepAnalysis:
    """What :func:`analyse_steps` finds: the beam's modes under each scheme, and the pictures.

    Attributes
    ----------
    system : tumble.structural.LinearSystem
        The cantilever (:func:`steel_cantilever`).
    n_elements : int
        Its elements.
    dt : float
        The step of the mode table [s].
    table : tumble.structural.ModeTable
        Each mode under each scheme at ``dt``: ω, spectral radius, damping, period error.
    figures : list of (str, callable)
        ``amplification.png`` and ``schemes_vs_exact.png`` with their writers
        (:func:`tumble.io.write_figures` writes them).
    """

    system: structural.LinearSystem
    n_elements: int
    dt: float
    table: structural.ModeTable
    figures: list[tuple[str, FigureWriter]]


def analyse_steps(n_elements: int = 20, dt: float | None = None) -> StepAnalysis:
    """The time-step analyser on :func:`steel_cantilever`: pure (no files, no printing).

    Every scheme of :data:`tumble.structural.SCHEMES` with its defaults: its amplification
    on ẍ + ω²x = 0 against Δt/T (:func:`tumble.structural.amplification`), the beam's modes
    under it at ``dt`` (:func:`tumble.structural.mode_table`), and its run from rest under
    the tip load at Δt = T₁/100 against :func:`tumble.structural.exact_response` (schemes
    whose critical step is below T₁/100 are left out).

    Parameters
    ----------
    n_elements : int
        Beam elements.
    dt : float, optional
        Step of the mode table [s]; default T₁/20.

    Returns
    -------
    StepAnalysis

    Raises
    ------
    ValueError
        For a ``dt`` that is not finite and > 0.

    Examples
    --------
    >>> analysis = analyse_steps(2, dt=1e-3)
    >>> [name for name, _ in analysis.figures], len(analysis.table.omega)
    (['amplification.png', 'schemes_vs_exact.png'], 4)
    """
    from tumble.viz._figure import save
    from tumble.viz.amplification import amplification_figure, comparison_figure

    system = steel_cantilever(n_elements)
    step = dt if dt is not None else 2 * np.pi / system.natural_frequencies(1)[0] / 20
    table = structural.mode_table(system, step)
    analyses = [structural.amplification(s, ANALYSIS_OMEGA) for s in structural.SCHEMES.values()]
    period = 2 * np.pi / table.omega[0]
    runs = {name: structural.integrate(system, s, period / 100, n_steps=COMPARISON_STEPS,
                                       record_every=2)
            for name, s in structural.SCHEMES.items()
            if structural.critical_dt(system, s).dt > period / 100}  # fmt: skip
    exact = structural.exact_response(system, next(iter(runs.values())).t)
    amplification_title = "amplification on ẍ + ω²x = 0 (SCHEMES' defaults)"
    comparison_title = (f"{n_elements}-element cantilever, 1 N step load from rest, "
                        "Δt = T₁/100, against exact_response")  # fmt: skip

    def amplification(path: Path) -> None:
        save(amplification_figure(analyses, title=amplification_title), path, dpi=110)

    def comparison(path: Path) -> None:
        save(comparison_figure(system, runs, exact, title=comparison_title), path, dpi=110)

    figures: list[tuple[str, FigureWriter]] = [
        ("amplification.png", amplification),
        ("schemes_vs_exact.png", comparison),
    ]
    return StepAnalysis(system, n_elements, step, table, figures)
