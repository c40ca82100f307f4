"""Work–precision comparison of the rigid-body methods on a scenario's free body.

``tumble compare NAME --methods a,b,c`` runs each method at several step sizes (``rkmk45`` at
several tolerances) on the torque-free body of the scenario ``NAME``, measures the wall time
and the final attitude error ``‖R(T) − R_exact(T)‖_F`` against the elliptic-function solution
(:func:`tumble.exact.free_body_rotation`), and draws error against cost
(:func:`tumble.viz.work_precision.work_precision_figure`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict

import numpy as np

from tumble import _checks
from tumble.io import ScenarioResult
from tumble.rigid.methods import METHODS
from tumble.scenarios import registry

FREE_BODY_SCENARIOS = ("convergence", "sphere-exact", "t-handle", "torus-spin")
"""Scenarios whose body is torque-free with an exact solution (they define ``free_body()``)."""
LEFT_OUT = ("euler",)
"""Methods not compared by default: explicit Euler leaves SO(3) too fast to be worth a line."""
DEFAULT_METHODS = tuple(name for name in METHODS if name not in LEFT_OUT)
"""Methods compared by default: every one of :data:`tumble.rigid.METHODS` but :data:`LEFT_OUT`."""
STEPS = (100, 200, 400, 800, 1600, 3200)
"""Numbers of steps over [0, T] for the fixed-step methods."""
TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10)
"""Relative tolerances for the adaptive method."""


def run(
    scenario: str,
    *,
    methods: Sequence[str] = DEFAULT_METHODS,
    t_end: float = 10.0,
    steps: Sequence[int] = STEPS,
    tolerances: Sequence[float] = TOLERANCES,
    repeat: int = 3,
) -> ScenarioResult:
    """Measure error against wall time and steps for each method on ``scenario``'s body.

    Parameters
    ----------
    scenario : str
        One of :data:`FREE_BODY_SCENARIOS`.
    methods : sequence of str
        Names from :data:`tumble.rigid.METHODS`.
    t_end : float
        T (s), > 0.
    steps, tolerances : sequence
        Step counts (fixed-step methods) and ``rtol`` values (``rkmk45``).
    repeat : int
        Timing repeats; the best is kept.

    Returns
    -------
    ScenarioResult
        ``summary["points"]``: one row per run (method, setting, steps, seconds, error);
        ``summary["best"]``: per method the smallest error reached and its time; figure
        ``work_precision.png``; the points as the dataset.
    """
    _checks.choice(
        "scenario", scenario, FREE_BODY_SCENARIOS, "the others have no torque-free body to compare"
    )
    methods = [methods] if isinstance(methods, str) else list(methods)
    unknown = [m for m in methods if m not in METHODS]
    if not methods or unknown:
        raise _checks.fail("methods", methods, f"one or more of {sorted(METHODS)}")
    _checks.positive("t_end", t_end, "s")
    from tumble.rigid.work_precision import work_precision

    body, omega0 = registry.get(scenario).free_body()
    points = work_precision(
        body,
        t_end,
        methods,
        omega0=omega0,
        steps=tuple(steps),
        tolerances=tuple(tolerances),
        repeat=repeat,
    )
    rows = [asdict(point) for point in points]
    summary = {
        "scenario": scenario,
        "t_end": t_end,
        "omega0": np.asarray(omega0).tolist(),
        "methods": methods,
        "points": rows,
        "best": _best(rows),
    }
    title = f"{scenario} — work–precision, T = {t_end:g} s"
    return ScenarioResult(
        f"compare-{scenario}",
        summary,
        data={"points": points, "body": body},
        figures=[("work_precision.png", lambda path: _draw(points, path, title))],
        datasets={"": _dataset(rows)},
        attrs={"scenario": scenario, "t_end": t_end, "methods": methods},
    )


def _best(rows: list[dict]) -> dict:
    best: dict[str, dict] = {}
    for row in rows:
        if not np.isfinite(row["error"]):
            continue
        known = best.get(row["method"])
        if known is None or row["error"] < known["error"]:
            best[row["method"]] = {k: row[k] for k in ("setting", "steps", "seconds", "error")}
    return best


def _draw(points, path, title: str) -> None:
    from tumble.viz.work_precision import work_precision_figure

    work_precision_figure(points, path, title=title)


def _dataset(rows: list[dict]):
    import xarray as xr

    return xr.Dataset(
        {
            "method": ("run", [row["method"] for row in rows]),
            "setting": (
                "run",
                [float(row["setting"]) for row in rows],
                {"long_name": "h or rtol"},
            ),
            "steps": ("run", [int(row["steps"]) for row in rows]),
            "seconds": ("run", [float(row["seconds"]) for row in rows], {"units": "s"}),
            "error": ("run", [float(row["error"]) for row in rows], {"units": "1"}),
        }
    )
