"""Published rigid-body benchmarks, reproduced (issue 27), and what an exact step costs.

Run ``.venv/bin/python benchmarks/bench_published.py [--quick]`` (``make bench`` runs it with
the others). Every solver runs in this process, each timing the median (min–max) of repeats
after a warm-up call (compilation outside the timings); the figures go to ``docs/img``.

1. **SciMLBenchmarks' "RigidBody"** work–precision: Euler's equations for I = (0.5, 2, 3),
   ``y₁' = −2 y₂y₃, y₂' = 1.25 y₁y₃, y₃' = −0.5 y₁y₂ + 0.25 sin²t``, ``y(0) = (1, 0, 0.9)`` on
   [0, 10], and Hairer–Nørsett–Wanner's EULR (the torque only for 3π ≤ t ≤ 4π, on [0, 20]),
   on SciML's grid ``abstol = 10⁻⁶ … 10⁻¹³`` paired with ``reltol = 10⁻³ … 10⁻¹⁰``. Error: the
   largest component of ``y(T) − y_ref(T)``; the reference is heyoka's Taylor integrator in
   quadruple precision (``real128``, tol 1e-32), checked against mpmath's ``odefun`` at 25
   digits (full runs).
2. **DETEST B5** (MATLAB's ``rigidode``): ``y' = (y₂y₃, −y₁y₃, −0.51 y₁y₂)``, ``y(0) = (0, 1,
   1)`` on [0, 20]: ``y = (sn, cn, dn)(t | 0.51)``, taken from tumble's closed form of the free
   body I = (2, 3, 1), ω = (√1.53 y₁, √0.51 y₂, √3 y₃) (checked against mpmath's
   ``ellipfun``). Each solver's largest error over its own steps, against its tolerance.
3. **Hairer–Lubich–Wanner's free body** (GeometricProblems.jl's test): I = (2, 1, 2/3),
   L0 = (cos 1.1, 0, sin 1.1), h = 0.1, T = 100 and 10⁴: every method of ``METHODS``, its
   largest energy error and Casimir (``|m|²``) error.
4. **MuJoCo's single free body at equal dt**: a 0.1 × 0.2 × 0.3 m box of 1 kg, ω0 = (0.1, 0.2,
   0.3) rad/s, dt = 0.01, 10⁶ steps, against every integrator of the installed MuJoCo: energy
   and ``|L|`` drift, attitude error against the exact flow, sampled every 1000 steps.
5. **The exact step's cost**, part by part (AGM-free Jacobi functions, Carlson's R_F and R_J,
   the rotation), and ``exact``, ``strang``, ``yoshida4`` per step on P1 and the dipole.

``--quick``: fewer repeats, settings and steps (10⁵ for MuJoCo's body), no mpmath check.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy loads OpenBLAS

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from collections.abc import Callable  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402

import numba  # noqa: E402
import numpy as np  # noqa: E402
from _timing import machine, spread, table, timed  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

import tumble  # noqa: E402
from tumble import RigidBody, exact, so3  # noqa: E402
from tumble.ode import TABLEAUX  # noqa: E402
from tumble.rigid import METHODS  # noqa: E402

IMG = Path(__file__).resolve().parents[1] / "docs" / "img"
ABSTOLS = tuple(10.0**-k for k in range(6, 14))
RELTOLS = tuple(10.0**-k for k in range(3, 11))
"""SciMLBenchmarks' grid: ``abstols = 1 ./ 10 .^ (6:13)`` with ``reltols = 1 ./ 10 .^ (3:10)``."""
HEYOKA_TOLS = tuple(10.0**-k for k in range(6, 16))
"""heyoka has one tolerance (absolute and relative): SciML's abstols, then two beyond."""
TARGETS = tuple(10.0**-k for k in range(6, 14))
THREE_PI, FOUR_PI = 3.0 * math.pi, 4.0 * math.pi
B5_M = 0.51
B5_BODY = (2.0, 3.0, 1.0)
B5_SCALE = (math.sqrt(1.53), math.sqrt(0.51), math.sqrt(3.0))
"""DETEST B5 as a free body: with I = (2, 3, 1) Euler's equations are ``ω₁' = ω₂ω₃``,
``ω₂' = −ω₃ω₁/3``, ``ω₃' = −ω₁ω₂``, and ``ω = (c₁y₁, c₂y₂, c₃y₃)`` turns them into B5's when
``c₂c₃/c₁ = 1``, ``c₁c₃/c₂ = 3``, ``c₁c₂/c₃ = 0.51``."""


# --- the right-hand sides, as each peer takes them -----------------------------------------


@numba.njit(cache=True)
def sciml_rhs(t, y):
    out = np.empty(3)
    s = math.sin(t)
    out[0] = -2.0 * y[1] * y[2]
    out[1] = 1.25 * y[0] * y[2]
    out[2] = -0.5 * y[0] * y[1] + 0.25 * s * s
    return out


@numba.njit(cache=True)
def free_rhs(t, y):
    """SciML's body without its torque (EULR outside 3π ≤ t ≤ 4π)."""
    out = np.empty(3)
    out[0] = -2.0 * y[1] * y[2]
    out[1] = 1.25 * y[0] * y[2]
    out[2] = -0.5 * y[0] * y[1]
    return out


@numba.njit(cache=True)
def b5_rhs(t, y):
    out = np.empty(3)
    out[0] = y[1] * y[2]
    out[1] = -y[0] * y[2]
    out[2] = -B5_M * y[0] * y[1]
    return out


def into(rhs: Callable) -> Callable:
    """``rhs`` in CyRK ``pysolve_ivp``'s form ``f(dy, t, y)`` (a plain Python function)."""
    python = rhs.py_func

    def f(dy, t, y):
        dy[:] = python(t, y)

    return f


@dataclass(frozen=True)
class Problem:
    name: str
    t_end: float
    y0: tuple[float, float, float]
    rhs: Callable  # numba f(t, y): tumble.solve and CyRK's nbsolve_ivp
    torque: str  # "always", "window" or "none": heyoka's system and the rigid-body load

    @property
    def start(self) -> np.ndarray:
        return np.array(self.y0)

    @property
    def legs(self) -> list[tuple[float, float, Callable]]:
        """``(t0, t1, rhs)`` of each smooth leg: EULR's torque switches on at 3π and off at
        4π, where every solver restarts (heyoka's Taylor series could not step across)."""
        if self.torque != "window":
            return [(0.0, self.t_end, self.rhs)]
        return [
            (0.0, THREE_PI, free_rhs),
            (THREE_PI, FOUR_PI, sciml_rhs),
            (FOUR_PI, self.t_end, free_rhs),
        ]


SCIML = Problem("SciML RigidBody", 10.0, (1.0, 0.0, 0.9), sciml_rhs, "always")
EULR = Problem("EULR (HNW)", 20.0, (1.0, 0.0, 0.9), sciml_rhs, "window")
B5 = Problem("DETEST B5", 20.0, (0.0, 1.0, 1.0), b5_rhs, "none")


def by_legs(problem: Problem, solve: Callable) -> tuple[np.ndarray, np.ndarray]:
    """``solve(rhs, (t0, t1), y0) -> (t, y)`` leg after leg, joined; y of shape (n, 3)."""
    y, times, states = problem.start, [], []
    for t0, t1, rhs in problem.legs:
        t, Y = solve(rhs, (t0, t1), y)
        times.append(t if not times else t[1:])
        states.append(Y if not states else Y[1:])
        y = Y[-1]
    return np.concatenate(times), np.concatenate(states)


# --- the peers: each returns (t, y) of its steps, y of shape (n, 3) ---------------------------


def heyoka_system(problem: Problem):
    import heyoka as hy

    x, y, z = hy.make_vars("x", "y", "z")
    if problem.torque == "none":
        return [(x, y * z), (y, -x * z), (z, -B5_M * x * y)]
    forcing = 0.25 * hy.sin(hy.time) ** 2 * (hy.par[0] if problem.torque == "window" else 1.0)
    return [(x, -2.0 * y * z), (y, 1.25 * x * z), (z, -0.5 * x * y + forcing)]


def heyoka_integrator(problem: Problem, tol: float, fp_type=float):
    """A ``taylor_adaptive`` for ``problem`` (built once: LLVM compiles it) and a function
    running it from y0: ``run(steps)`` returns y(T), or with ``steps`` every step's (t, y)."""
    import heyoka as hy

    cast = (lambda v: hy.real128(v)) if fp_type is not float else float
    y0 = np.array(
        [cast(v) for v in problem.y0], dtype=hy.real128 if fp_type is not float else float
    )
    extra = {"pars": [0.0]} if problem.torque == "window" else {}
    if fp_type is not float:
        extra = {"pars": np.array([cast(0.0)], dtype=hy.real128)} if extra else {}
        extra |= {"fp_type": hy.real128}
    ta = hy.taylor_adaptive(heyoka_system(problem), y0, tol=cast(tol), **extra)
    switches = [(THREE_PI, 1.0), (FOUR_PI, 0.0)] if problem.torque == "window" else []
    legs = [*switches, (problem.t_end, None)]

    def run(steps: bool = False):
        ta.time, ta.state[:] = cast(0.0), y0
        if switches:
            ta.pars[0] = cast(0.0)
        times, states = [0.0], [np.array(problem.y0)]
        for end, switch in legs:
            if steps:
                while float(ta.time) < end:
                    ta.step(max_delta_t=cast(end) - ta.time)
                    times.append(float(ta.time))
                    states.append(np.array([float(v) for v in ta.state]))
            else:
                ta.propagate_until(cast(end))
            if switch is not None:
                ta.pars[0] = cast(switch)
        if steps:
            return np.array(times), np.array(states)
        return np.array([float(v) for v in ta.state])

    run.integrator = ta
    return run


def reference(problem: Problem) -> list[str]:
    """y(T) by heyoka in quadruple precision (the same switch times as every peer's), each
    component to its 36 digits."""
    run = heyoka_integrator(problem, 1e-32, "real128")
    run()
    return [str(v) for v in run.integrator.state]


def mpmath_check(problem: Problem, y_ref: list[str], digits: int = 25) -> float:
    """The largest difference of ``y_ref`` from y(T) by mpmath's Taylor-series ``odefun`` at
    ``digits``, leg by leg."""
    import mpmath as mp

    with mp.workdps(digits):
        y = [mp.mpf(v) for v in problem.y0]
        legs = [(0.0, THREE_PI, 0), (THREE_PI, FOUR_PI, 1), (FOUR_PI, problem.t_end, 0)]
        if problem.torque == "always":
            legs = [(0.0, problem.t_end, 1)]
        for start, end, on in legs:

            def f(t, v, on=on):
                return [
                    -2 * v[1] * v[2],
                    mp.mpf(1.25) * v[0] * v[2],
                    -mp.mpf(0.5) * v[0] * v[1] + on * mp.mpf(0.25) * mp.sin(t) ** 2,
                ]

            y = mp.odefun(f, mp.mpf(start), y)(mp.mpf(end))
        return float(max(abs(mp.mpf(a) - b) for a, b in zip(y_ref, y, strict=True)))


def tumble_solve(problem: Problem, method: str, setting):
    def leg(rhs, span, y0):
        if TABLEAUX[method].b_hat is None:
            steps = max(1, round(setting * (span[1] - span[0]) / problem.t_end))
            result = tumble.solve(rhs, span, y0, method=method, h=(span[1] - span[0]) / steps)
        else:
            result = tumble.solve(rhs, span, y0, method=method, rtol=setting[1], atol=setting[0])
        return result.t, result.y.T

    return by_legs(problem, leg)


def scipy_solve(problem: Problem, method: str, setting):
    def leg(rhs, span, y0):
        result = solve_ivp(rhs.py_func, span, y0, method=method, rtol=setting[1], atol=setting[0])
        return result.t, result.y.T

    return by_legs(problem, leg)


def cyrk_py(problem: Problem, method: str, setting, cache: dict = {}):  # noqa: B006
    from CyRK import pysolve_ivp

    def leg(rhs, span, y0):
        f = cache.setdefault(rhs, into(rhs))
        result = pysolve_ivp(
            f, span, y0, method=method, rtol=setting[1], atol=setting[0], pass_dy_as_arg=True
        )
        return result.t, result.y.T

    return by_legs(problem, leg)


def cyrk_nb(problem: Problem, method: str, setting):
    from CyRK import nbsolve_ivp

    def leg(rhs, span, y0):
        result = nbsolve_ivp(
            rhs,
            span,
            y0,
            rtol=setting[1],
            atol=setting[0],
            rk_method={"RK45": 1, "DOP853": 2}[method],
            warnings=False,
        )
        return result.t, result.y.T

    return by_legs(problem, leg)


def body_torque(problem: Problem):
    """SciML's forcing as a rigid-body load: ``τ₃/I₃ = 0.25 sin²t`` in the body frame, so
    ``τ = R (0, 0, 0.75 sin²t)`` in the world (``Torque`` takes world vectors)."""

    def torque(t, state):
        on = problem.torque == "always" or THREE_PI <= t <= FOUR_PI
        return state.R @ np.array([0.0, 0.0, 0.75 * math.sin(t) ** 2 if on else 0.0])

    return tumble.rigid.forces.Torque(torque)


def tumble_simulate(problem: Problem, method: str, setting):
    """The rigid body behind the problem (``RigidBody`` I = (0.5, 2, 3), ω0 = y0; DETEST B5 on
    its body I = (2, 3, 1), ω0 = c y0), through ``simulate``; y from ``omega_body``."""
    if problem.torque == "none":
        body, scale, forces = RigidBody(1.0, B5_BODY), np.array(B5_SCALE), []
    else:
        body = RigidBody(1.0, [0.5, 2.0, 3.0], allow_unphysical=True)
        scale, forces = np.ones(3), [body_torque(problem)]
    options = (
        {"h": problem.t_end / setting}
        if isinstance(setting, int)
        else {"rtol": setting[1], "atol": setting[0]}
    )
    run = simulate_quiet(body, problem.t_end, method, problem.start * scale, forces, options)
    return run.t, run.omega_body / scale


def simulate_quiet(body, t_end, method, omega0, forces, options):
    return tumble.simulate(body, t_end, method=method, omega0=omega0, forces=forces, **options)


def heyoka_solve(problem: Problem, method: str, setting, steps: bool = False, cache: dict = {}):  # noqa: B006
    """heyoka at ``tol = setting`` (each integrator built once and kept): y(T), or every
    step with ``steps``."""
    key = (problem.name, setting)
    if key not in cache:
        cache[key] = heyoka_integrator(problem, setting)
    if steps:
        return cache[key](True)
    return np.array([problem.t_end]), cache[key]()[None]


@dataclass(frozen=True)
class Solver:
    label: str
    run: Callable  # run(problem, method, setting) -> (t, y)
    method: str
    settings: tuple  # tolerance pairs (atol, rtol), step counts, or heyoka tolerances
    repeat: int = 5

    @property
    def adaptive(self) -> bool:
        return not isinstance(self.settings[0], int)

    def trajectory(self, problem: Problem, setting):
        """Every step's (t, y), for the errors along the way."""
        if self.run is heyoka_solve:
            return heyoka_solve(problem, self.method, setting, steps=True)
        return self.run(problem, self.method, setting)


def solvers(quick: bool) -> list[Solver]:
    """Every solver of the comparison and its settings (fewer with ``quick``)."""
    pairs = tuple(zip(ABSTOLS, RELTOLS, strict=True))
    steps = tuple(int(10 * 2**k) for k in range(0, 13, 2 if quick else 1))
    out = []
    for name, tableau in TABLEAUX.items():
        if tableau.b_hat is not None:
            out.append(Solver(f"tumble solve {name}", tumble_solve, name, pairs))
        elif tableau.order >= 4:
            out.append(Solver(f"tumble solve {name}", tumble_solve, name, steps))
    eights = (40, 160) if quick else (40, 160, 640)
    out += [
        Solver("tumble simulate rkmk-dopri5", tumble_simulate, "rkmk-dopri5", pairs[1::3], 1),
        Solver("tumble simulate rkmk8", tumble_simulate, "rkmk8", eights, 1),
    ]
    for method in ("RK45", "DOP853"):
        out.append(Solver(f"scipy {method}", scipy_solve, method, pairs, 3))
        out.append(Solver(f"CyRK pysolve_ivp {method}", cyrk_py, method, pairs, 3))
        out.append(Solver(f"CyRK nbsolve_ivp {method}", cyrk_nb, method, pairs, 5))
    out.append(Solver("heyoka", heyoka_solve, "", HEYOKA_TOLS, 5))
    return out


def describe(setting) -> str:
    if isinstance(setting, int):
        return f"{setting} steps"
    if isinstance(setting, float):
        return f"tol {setting:.0e}"
    return f"rtol {setting[1]:.0e}"


# --- 1. SciML RigidBody and EULR --------------------------------------------------------------

TIME_LIMIT_S = 30.0
"""A solver's settings stop at the first run that takes longer than this."""


def work_precision(problem: Problem, solver: Solver, y_ref: np.ndarray, repeat: int) -> list:
    """``[(setting, error, (median, min, max) s)]`` of ``solver``: the error of y(T)."""
    found = []
    for k, setting in enumerate(solver.settings):
        if k == 0 or solver.run is heyoka_solve:
            solver.run(problem, solver.method, setting)  # compile or build outside the timing
        med, lo, hi, (t, y) = timed(
            lambda s=setting: solver.run(problem, solver.method, s), min(repeat, solver.repeat)
        )
        reached = abs(t[-1] - problem.t_end) <= 1e-9 * problem.t_end
        error = float(np.abs(y[-1] - y_ref).max()) if reached else math.inf
        found.append((setting, error, (med, lo, hi)))
        if med > TIME_LIMIT_S:
            break
    return found


def fastest(found: list, target: float):
    """The fastest ``(setting, error, times)`` of ``found`` whose error is at most target."""
    good = [entry for entry in found if entry[1] <= target]
    return min(good, key=lambda entry: entry[2][0]) if good else None


def target_rows(results: dict) -> list:
    """Per solver: the time (ms) to reach each target error and the ratio to heyoka's."""
    rows = []
    for label, found in results.items():
        row = [label]
        for target in TARGETS:
            best, peer = fastest(found, target), fastest(results.get("heyoka", []), target)
            if best is None:
                row.append("—")
            elif peer is None or label == "heyoka":
                row.append(f"{best[2][0] * 1e3:.3g}")
            else:
                row.append(f"{best[2][0] * 1e3:.3g} ({best[2][0] / peer[2][0]:.2g}×)")
        rows.append(row)
    row = ["**tumble's fastest / heyoka's**"]
    for target in TARGETS:
        ours = [(fastest(found, target), label) for label, found in results.items()
                if label.startswith("tumble")]  # fmt: skip
        ours = [(best[2][0], label) for best, label in ours if best is not None]
        peer = fastest(results.get("heyoka", []), target)
        if not ours or peer is None:
            row.append("—")
            continue
        seconds, label = min(ours)
        row.append(f"**{seconds / peer[2][0]:.2g}×** ({label.split()[-1]})")
    return [*rows, row]


TUMBLE_COLOURS = (
    "tab:blue",
    "tab:orange",
    "tab:green",
    "tab:red",
    "tab:purple",
    "tab:cyan",
    "tab:pink",
    "tab:olive",
    "navy",
    "teal",
    "tab:brown",
    "goldenrod",
)
MUJOCO_STYLES = {
    "Euler": ("black", "--"),
    "RK4": ("tab:red", "--"),
    "implicit": ("0.4", (0, (6, 2))),
    "implicitfast": ("0.6", (0, (2, 2))),
    "discrete": ("tab:brown", (0, (1, 1.5))),
}


def line_style(labels: list) -> dict:
    """``{label: plot keywords}``: tumble's lines solid, each its colour; heyoka black and
    thick; scipy and CyRK coloured by method (RK45 grey, DOP853 magenta) and dashed, dotted or
    dash-dotted by implementation; MuJoCo's integrators dashed in greys, black, red, brown."""
    styles, k = {}, 0
    for label in labels:
        if label == "heyoka":
            styles[label] = dict(color="black", ls="-", lw=2.4, marker="o", ms=3)
        elif label.startswith("MuJoCo"):
            colour, dashes = MUJOCO_STYLES.get(label.split()[-1], ("0.3", "--"))
            styles[label] = dict(color=colour, ls=dashes, lw=1.6)
        elif label.startswith("tumble"):
            marker = "D" if "simulate" in label else "o"
            styles[label] = dict(
                color=TUMBLE_COLOURS[k % len(TUMBLE_COLOURS)],
                ls="-",
                lw=1.4,
                marker=marker,
                ms=3.5,
            )
            k += 1
        else:
            colour = "0.5" if "RK45" in label else "darkmagenta"
            ls, marker = (
                (":", "^")
                if "pysolve" in label
                else ("-.", "v")
                if "nbsolve" in label
                else ("--", "s")
            )
            styles[label] = dict(color=colour, ls=ls, lw=1.2, marker=marker, ms=3.5)
    return styles


def draw_work_precision(panels: list, path: Path) -> None:
    """Error against time, one panel per problem, one line per solver."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(panels), figsize=(6.2 * len(panels), 5.6), sharey=True)
    styles = line_style(list(panels[0][1]))
    for ax, (title, results) in zip(np.atleast_1d(axes), panels, strict=True):
        for label, style in styles.items():
            points = [(e, times[0]) for _, e, times in results[label] if 0 < e <= 1.0]
            if not points:
                continue
            error, seconds = np.array(points).T
            ax.loglog(error, seconds * 1e3, label=label, **style)
        ax.set_title(title)
        ax.set_xlabel("error of y(T), largest component (runs off by more than 1 left out)")
        ax.grid(True, which="major", alpha=0.3)
        ax.set_xlim(3.0, 3e-16)
    np.atleast_1d(axes)[0].set_ylabel("time per solve (ms)")
    handles, names = np.atleast_1d(axes)[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.17, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def sciml_section(quick: bool, repeat: int) -> str:
    out = ["### 1. SciMLBenchmarks' RigidBody and Hairer–Nørsett–Wanner's EULR", ""]
    build = timed(lambda: heyoka_integrator(SCIML, 1e-10), 1)[0]  # the process's first
    panels, checks = [], []
    for problem in (SCIML, EULR):
        digits = reference(problem)
        y_ref = np.array([float(v) for v in digits])
        if not quick:
            difference = mpmath_check(problem, digits)
            checks.append(
                f"{problem.name} within {difference:.0e}"
                if difference
                else f"{problem.name} to all 25 digits"
            )
        results = {}
        for solver in solvers(quick):
            results[solver.label] = work_precision(problem, solver, y_ref, repeat)
        panels.append((f"{problem.name}, T = {problem.t_end:g}", results))
        header = ["solver", *[f"≤ {t:.0e}" for t in TARGETS]]
        out += [
            f"**{problem.name}** (ms to reach each error; × heyoka's fastest there)",
            "",
            table(header, target_rows(results)),
            "",
        ]
    draw_work_precision(panels, IMG / "bench_sciml.png")
    out += [
        "Each cell: the fastest setting of the solver whose y(T) is within the error, in ms "
        "(median of repeats), and its time over heyoka's fastest at that error. tumble "
        "`solve`, scipy and CyRK take SciML's (abstol, reltol) pairs; fixed-step methods "
        "T/h = 10 · 2ᵏ steps; heyoka its one tolerance 1e-6 … 1e-15, its integrator built "
        f"once per tolerance outside the timing (a build, LLVM compiling it: {build:.2f} s in "
        "this process, heyoka keeping compiled code between runs; about 0.5 s cold). "
        "EULR's torque switches at 3π and 4π: every solver restarts there (three calls; "
        "heyoka's Taylor series cannot step across, and a Runge–Kutta pair stepping across "
        "the kink in sin² · step stalls near 1e-7). `simulate` runs the rigid body "
        "(I = (0.5, 2, 3), ω0 = y0, the torque R(0, 0, 0.75 sin²t) a Python callable, so "
        "on its Python path, in one call). The reference: heyoka in quadruple precision "
        "(tol 1e-32), switched at the same double 3π and 4π"
        + (
            f"; mpmath's odefun at 25 digits agrees with it: {', '.join(checks)}."
            if checks
            else "."
        ),
        "Figure: `docs/img/bench_sciml.png`.",
        "",
    ]
    return "\n".join(out)


# --- 2. DETEST B5 -----------------------------------------------------------------------------


def b5_exact(t: np.ndarray) -> np.ndarray:
    """B5's solution (n, 3) from tumble's closed form of its free body (module constants)."""
    scale = np.array(B5_SCALE)
    return exact.free_body(B5_BODY, scale * np.array(B5.y0), np.atleast_1d(t)) / scale


def b5_check() -> float:
    """The closed form against ``(sn, cn, dn)(t | 0.51)`` by mpmath at 30 digits."""
    import mpmath as mp

    t = np.linspace(0.0, B5.t_end, 41)
    with mp.workdps(30):
        truth = np.array(
            [
                [float(mp.ellipfun(k, mp.mpf(v), mp.mpf(B5_M))) for k in ("sn", "cn", "dn")]
                for v in t
            ]
        )
    return float(np.abs(b5_exact(t) - truth).max())


def b5_rows(quick: bool, repeat: int) -> tuple[list, dict]:
    """For each adaptive solver and tolerance: its largest error over its own steps."""
    found = {}
    for solver in solvers(quick):
        if not solver.adaptive:
            continue
        entries = []
        for k, setting in enumerate(solver.settings):
            if k == 0 or solver.run is heyoka_solve:
                solver.run(B5, solver.method, setting)
            med, lo, hi, _ = timed(
                lambda s=setting, f=solver: f.run(B5, f.method, s), min(repeat, solver.repeat)
            )
            t, y = solver.trajectory(B5, setting)
            error = float(np.abs(y - b5_exact(t)).max())
            entries.append((setting, error, (med, lo, hi), len(t) - 1))
        found[solver.label] = entries
    rows = []
    for label, entries in found.items():
        cells = {}
        for setting, error, _, _ in entries:
            grid = setting if isinstance(setting, tuple) else (setting, None)
            tol = grid[1] if grid[1] is not None else grid[0]
            cells[grid[0]] = f"{error:.1e} ({error / tol:.2g})"
        rows.append([label, *[cells.get(atol, "—") for atol in ABSTOLS]])
    return rows, found


def draw_b5(found: dict, exact_error: float, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(12.4, 5.6))
    styles = line_style(list(found))
    for label, entries in found.items():
        tol = [s if isinstance(s, float) else s[1] for s, *_ in entries]
        error = [e for _, e, _, _ in entries]
        seconds = [times[0] * 1e3 for _, _, times, _ in entries]
        left.loglog(tol, error, label=label, **styles[label])
        right.loglog(error, seconds, **styles[label])
    grid = np.array([1e-15, 1e-2])
    left.loglog(grid, grid, color="0.5", lw=0.8)
    left.text(2e-10, 4e-10, "error = tolerance", color="0.4", rotation=38, fontsize=8)
    left.axhline(exact_error, color="k", lw=0.8, ls=":")
    left.text(1e-9, exact_error * 1.6, "tumble `exact` (no tolerance)", fontsize=8)
    left.set(
        xlabel="tolerance (rtol; heyoka: tol)",
        ylabel="largest error over the steps",
        title="DETEST B5: error against tolerance",
    )
    right.set(
        xlabel="largest error over the steps",
        ylabel="time per solve (ms)",
        title="DETEST B5: work–precision",
    )
    right.invert_xaxis()
    for ax in (left, right):
        ax.grid(True, alpha=0.3)
    fig.legend(
        *left.get_legend_handles_labels(), loc="lower center", ncol=4, fontsize=8, frameon=False
    )
    fig.tight_layout(rect=(0, 0.15, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def b5_section(quick: bool, repeat: int) -> str:
    check = b5_check()
    rows, found = b5_rows(quick, repeat)
    scale = np.array(B5_SCALE)
    run = tumble.simulate(
        RigidBody(1.0, B5_BODY), B5.t_end, method="exact", h=1.0, omega0=scale * B5.start
    )
    exact_error = float(np.abs(run.omega_body / scale - b5_exact(run.t)).max())
    draw_b5(found, exact_error, IMG / "bench_detest_b5.png")
    header = ["solver", *[f"{a:.0e}, {r:.0e}" for a, r in zip(ABSTOLS, RELTOLS, strict=True)]]
    return "\n".join(
        [
            "### 2. DETEST B5 (MATLAB's `rigidode`): the error each tolerance really gives",
            "",
            table(header, rows),
            "",
            "Columns: SciML's (abstol, reltol) pairs. Each cell: the largest error (any "
            "component) over the solver's own steps, against the closed form, and in brackets "
            "that error over the reltol asked (heyoka, whose one tolerance is the column's "
            "abstol: over that tol). The closed form is tumble's exact free body "
            "(`tumble.exact.free_body` on I = (2, 3, 1)); against mpmath's `ellipfun` (sn, cn, "
            f"dn at m = 0.51, 30 digits, 41 times in [0, 20]) it differs by {check:.1e}. "
            f"`simulate` with `exact` (h = 1, 20 steps) errs by {exact_error:.1e}. "
            "`simulate`'s rkmk-dopri5 holds the attitude to rtol in radians and the momentum "
            "to atol + rtol|L| (its own norm), not y's components. Figure: "
            "`docs/img/bench_detest_b5.png`.",
            "",
        ]
    )


# --- 3. Hairer–Lubich–Wanner's free body ------------------------------------------------------

HLW_INERTIA = np.array([2.0, 1.0, 2.0 / 3.0])
HLW_L0 = np.array([math.cos(1.1), 0.0, math.sin(1.1)])


def invariants(run, inertia: np.ndarray) -> tuple[float, float]:
    """Largest ``|E/E0 − 1|`` and ``||m|²/|m0|² − 1|`` over the records, m = I ω_body."""
    m = run.omega_body * inertia
    with np.errstate(over="ignore", invalid="ignore"):  # euler's runs overflow: inf, shown
        energy = 0.5 * np.sum(m * m / inertia, axis=1)
        casimir = np.sum(m * m, axis=1)
    return (
        float(np.abs(energy / energy[0] - 1).max()),
        float(np.abs(casimir / casimir[0] - 1).max()),
    )


def hlw_runs(quick: bool) -> dict:
    """``{method: {T: (energy, casimir, attitude error, seconds, status)}}``, h = 0.1."""
    body = RigidBody(1.0, HLW_INERTIA, allow_unphysical=True)
    ends = (100.0, 1e3 if quick else 1e4)
    found = {}
    for name in METHODS:
        found[name] = {}
        for t_end in ends:
            every = max(1, round(t_end / 0.1 / 1000))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                start = time.perf_counter()
                run = tumble.simulate(
                    body, t_end, method=name, h=0.1, L0=HLW_L0, record_every=every
                )
                seconds = time.perf_counter() - start
            energy, casimir = invariants(run, HLW_INERTIA)
            R_exact = exact.free_body_rotation(HLW_INERTIA, HLW_L0 / HLW_INERTIA, run.t[-1])
            attitude = angle(run.R[-1], R_exact)
            found[name][t_end] = (energy, casimir, attitude, seconds, run.status, run.n_steps)
    return found


def angle(R: np.ndarray, R_exact: np.ndarray) -> float:
    """The rotation angle of ``Rᵀ R_exact`` (R first projected onto SO(3)), rad."""
    if not np.all(np.isfinite(R)):
        return math.inf
    U, _, Vt = np.linalg.svd(R)
    return float(np.linalg.norm(so3.log((U @ Vt).T @ R_exact)))


def draw_hlw(found: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(found)
    ends = list(next(iter(found.values())))
    fig, axes = plt.subplots(1, 2, figsize=(12.4, 0.32 * len(names) + 1.6), sharey=True)
    y = np.arange(len(names))
    for ax, index, title in zip(
        axes, (0, 1), ("energy |E/E0 − 1|", "Casimir ||m|²/|m0|² − 1|"), strict=True
    ):
        for k, (t_end, colour) in enumerate(zip(ends, ("tab:blue", "tab:orange"), strict=True)):
            values = np.array([found[n][t_end][index] for n in names])
            values = np.clip(np.nan_to_num(values, nan=1e3, posinf=1e3), 1e-17, 1e3)
            ax.barh(
                y + (k - 0.5) * 0.38,
                values,
                height=0.38,
                color=colour,
                log=True,
                left=1e-17,
                label=f"T = {t_end:g}",
            )
        ax.set_xlim(1e-17, 1e3)
        ax.set_title(f"largest {title}, h = 0.1")
        ax.grid(True, axis="x", alpha=0.3)
    axes[0].set_yticks(y, names)
    axes[0].invert_yaxis()
    axes[1].legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def hlw_section(quick: bool) -> str:
    found = hlw_runs(quick)
    draw_hlw(found, IMG / "bench_hlw.png")
    ends = list(next(iter(found.values())))
    header = [
        "method",
        *[f"{what}, T = {t:g}" for t in ends for what in ("energy", "Casimir", "attitude (rad)")],
        "µs per step (T long)",
    ]
    rows = []
    for name, by_end in found.items():
        row = [f"`{name}`"]
        for t_end in ends:
            energy, casimir, attitude, _, status, _ = by_end[t_end]
            note = "" if status == 0 else f" (status {int(status)})"
            row += [f"{energy:.1e}{note}", f"{casimir:.1e}", f"{attitude:.1e}"]
        seconds, steps = by_end[ends[-1]][3], by_end[ends[-1]][5]
        row.append(f"{seconds / max(steps, 1) * 1e6:.2f}")
        rows.append(row)
    return "\n".join(
        [
            "### 3. Hairer–Lubich–Wanner's free body: energy and Casimir, h = 0.1",
            "",
            table(header, rows),
            "",
            "I = (2, 1, 2/3), L0 = (cos 1.1, 0, sin 1.1) (GeometricProblems.jl's rigid body), "
            "h = 0.1 for every method of `METHODS` (the adaptive ones take it as their first "
            "step, at their default tolerance). Energy and Casimir: the largest relative error "
            "over the records (about 1000 a run); attitude: the angle to the closed form at T. "
            "The time is one `simulate` call over its steps. Figure: `docs/img/bench_hlw.png`.",
            "",
        ]
    )


# --- 4. MuJoCo's single free body at equal dt -------------------------------------------------

BOX = (0.1, 0.2, 0.3)
BOX_OMEGA0 = np.array([0.1, 0.2, 0.3])
BOX_DT = 0.01
SAMPLE_EVERY = 1000
MUJOCO_NAMES = {
    "mjINT_EULER": "Euler",
    "mjINT_RK4": "RK4",
    "mjINT_IMPLICIT": "implicit",
    "mjINT_IMPLICITFAST": "implicitfast",
    "mjINT_DISCRETE": "discrete",
    "mjINT_MIDPOINT": "midpoint",
}
"""MuJoCo's integrators by enum name, as its XML spells them (those the installed version
has are run; it is asked, not assumed)."""


def box_body() -> RigidBody:
    a, b, c = BOX
    return RigidBody(1.0, np.array([b * b + c * c, a * a + c * c, a * a + b * b]) / 12.0)


def drifts(t, R, omega, inertia) -> dict:
    """Energy and ``|L|`` drift (largest relative change) and the attitude error (rad) against
    the exact flow, at each sample: ``{"energy", "momentum", "attitude"}`` of shape (n,)."""
    m = omega * inertia
    energy = 0.5 * np.sum(m * omega, axis=1)
    momentum = np.linalg.norm(m, axis=1)
    R_exact = exact.free_body_rotation(inertia, BOX_OMEGA0, t)
    return {
        "energy": np.abs(energy / energy[0] - 1),
        "momentum": np.abs(momentum / momentum[0] - 1),
        "attitude": np.array([angle(a, b) for a, b in zip(R, R_exact, strict=True)]),
    }


def mujoco_run(integrator: str, steps: int) -> tuple[float, dict] | None:
    """MuJoCo ``rollout`` in chunks, the state sampled every SAMPLE_EVERY steps: (seconds, drifts);
    the model is bench_rigid's (one free joint, gravity off)."""
    import bench_rigid
    import mujoco
    from mujoco import rollout

    body = box_body()
    model = bench_rigid.mujoco_model(
        bench_rigid.Problem("box", body, BOX_OMEGA0), integrator, BOX_DT
    )
    data = bench_rigid.mujoco_data(model, BOX_OMEGA0)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    qpos = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_TIME)
    qvel = qpos + model.nq
    samples, chunk = [state.copy()], SAMPLE_EVERY * 10
    start = time.perf_counter()
    for _ in range(steps // chunk):
        states, _ = rollout.rollout(model, data, state[None], nstep=chunk)
        state = states[0, -1]
        samples.extend(states[0, SAMPLE_EVERY - 1 :: SAMPLE_EVERY])
    seconds = time.perf_counter() - start
    samples = np.array(samples)
    t = np.arange(len(samples)) * SAMPLE_EVERY * BOX_DT
    R = np.array(
        [so3.matrix_from_quat(q / np.linalg.norm(q)) for q in samples[:, qpos + 3 : qpos + 7]]
    )
    return seconds, drifts(t, R, samples[:, qvel + 3 : qvel + 6], np.diag(body.inertia))


def box_runs(quick: bool) -> dict:
    """``{label: (seconds per step, drifts)}``: MuJoCo's integrators and tumble's fixed-step
    methods at dt = 0.01."""
    steps = 10**5 if quick else 10**6
    found = {}
    try:
        import mujoco

        present = [n for n in MUJOCO_NAMES if hasattr(mujoco.mjtIntegrator, n)]
    except ImportError:
        present = []
    for name in present:
        seconds, drift = mujoco_run(MUJOCO_NAMES[name], steps)
        found[f"MuJoCo {MUJOCO_NAMES[name]}"] = (seconds / steps, drift)
    body = box_body()
    inertia = np.diag(body.inertia)
    for name, method in METHODS.items():
        if method.adaptive:
            continue
        tumble.simulate(body, 10 * BOX_DT, method=name, h=BOX_DT, omega0=BOX_OMEGA0)  # compile
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            start = time.perf_counter()
            run = tumble.simulate(
                body,
                steps * BOX_DT,
                method=name,
                h=BOX_DT,
                omega0=BOX_OMEGA0,
                record_every=SAMPLE_EVERY,
            )
            seconds = time.perf_counter() - start
        found[f"tumble {name}"] = (seconds / steps, drifts(run.t, run.R, run.omega_body, inertia))
    return found


def draw_box(found: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shown = [k for k in found if k.startswith("MuJoCo")] + [
        f"tumble {n}"
        for n in (
            "rk4-quat",
            "rkmk4",
            "split-axes",
            "midpoint-lp",
            "dmv",
            "split-axes4",
            "yoshida4",
            "exact",
        )
        if f"tumble {n}" in found
    ]
    fig, axes = plt.subplots(1, 3, figsize=(15, 5.2), sharex=True)
    styles = line_style(shown)
    t = np.arange(len(next(iter(found.values()))[1]["energy"])) * SAMPLE_EVERY * BOX_DT
    for label in shown:
        drift = found[label][1]
        style = {k: v for k, v in styles[label].items() if k not in ("marker", "ms")}
        for ax, key in zip(axes, ("energy", "momentum", "attitude"), strict=True):
            values = np.clip(drift[key][1:], 1e-17, None)
            ax.loglog(t[1:], values, label=label, **style)
    titles = (
        "energy |E/E0 − 1|",
        "|L| drift ||L|/|L0| − 1|",
        "attitude error against the exact flow (rad)",
    )
    for ax, title in zip(axes, titles, strict=True):
        ax.set(title=title, xlabel="t (s)")
        ax.grid(True, alpha=0.3)
    fig.legend(
        *axes[0].get_legend_handles_labels(), loc="lower center", ncol=7, fontsize=8, frameon=False
    )
    fig.suptitle("A 0.1 × 0.2 × 0.3 m box of 1 kg, ω0 = (0.1, 0.2, 0.3) rad/s, dt = 0.01")
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def box_section(quick: bool) -> str:
    found = box_runs(quick)
    draw_box(found, IMG / "bench_mujoco.png")
    rows = []
    for label, (per_step, drift) in found.items():
        rows.append(
            [
                label,
                f"{per_step * 1e6:.3f}",
                f"{drift['energy'].max():.1e}",
                f"{drift['momentum'].max():.1e}",
                f"{drift['attitude'][-1]:.1e}",
                f"{drift['attitude'].max():.1e}",
            ]
        )
    import mujoco

    missing = [MUJOCO_NAMES[n] for n in MUJOCO_NAMES if not hasattr(mujoco.mjtIntegrator, n)]
    steps = 10**5 if quick else 10**6
    return "\n".join(
        [
            f"### 4. MuJoCo's single free body at equal dt ({steps:.0e} steps of 0.01 s)",
            "",
            table(
                [
                    "integrator",
                    "µs per step",
                    "energy drift",
                    "|L| drift",
                    "attitude error at T",
                    "largest attitude error",
                ],
                rows,
            ),
            "",
            "A box 0.1 × 0.2 × 0.3 m of 1 kg (I = diag(0.01083, 0.00833, 0.00417) kg m²), ω0 = "
            "(0.1, 0.2, 0.3) rad/s in the body frame, gravity off. Drifts: the largest relative "
            "change of the kinetic energy and of |L| = |I ω| over samples every 1000 steps; the "
            "attitude error is the angle to the exact flow (`tumble.exact.free_body_rotation`) at "
            "the same times. MuJoCo: `rollout` in chunks of 10⁴ steps (its model from "
            "`bench_rigid.mujoco_model`), every integrator the installed version has"
            + (f" (it has no {', '.join(missing)})" if missing else "")
            + "; tumble: one "
            "`simulate` call per fixed-step method, records every 1000 steps. Figure: "
            "`docs/img/bench_mujoco.png`.",
            "",
        ]
    )


# --- 5. the exact step, part by part -------------------------------------------------------

TINY = 1e-300
"""Each timed part takes its input from the previous call's output times TINY: the calls
form a chain, as a step's parts do, and nothing is hoisted out of the loop."""


def part_timers():
    """Compiled loops, each timing one part of the exact step on P1's orbit (its regime A:
    pole A, m = 0.26, ν = 1), as ``(label, loop, arguments)``."""
    from tumble.rigid._compiled import exact_flow as ef

    def chained(part):
        @numba.njit
        def loop(n, a, b, c, d):
            acc = 0.0
            for _ in range(n):
                acc = TINY * part(a + acc, b, c, d)
            return acc

        return loop

    @numba.njit(inline="always")
    def quarter(m1, m, nu, _):
        return ef._quarter_periods(m, m1)[0]

    @numba.njit(inline="always")
    def complete(m1, m, nu, _):
        return ef._complete_part(nu, m, m1)

    @numba.njit(inline="always")
    def start(s, m1, nu, m):
        first, part = ef._legendre_integrals(s, 1 - s * s, 1 - s * s + m1 * s * s, nu, m)
        return first + part

    @numba.njit(inline="always")
    def end(s, m1, nu, m):
        return ef._legendre_part(s, 1 - s * s, 1 - s * s + m1 * s * s, nu, m)

    @numba.njit(inline="always")
    def functions(r, m1, m, quarter):
        sn, cn, dn = ef._jacobi_reduced(r, m, m1, quarter, math.inf, np.empty(0))
        return sn + cn + dn

    @numba.njit(inline="always")
    def first_kind(s, m1, _, __):  # the θ-form's set-up: F of the shift, one R_F
        return s * ef._carlson_rf(1 - s * s, 1 - s * s + m1 * s * s, 1.0)

    @numba.njit(inline="always")
    def rotation(phi, l0, l1, l2):
        Rp = np.eye(3)
        ef._times_permuted(Rp, 0, *ef._pole_frame_product(l0, l1, l2, phi, l0, l1, l2))
        ef._orthonormalise(Rp)
        return Rp[0, 0] + Rp[1, 1]

    @numba.njit(inline="always")
    def circular(v, _, __, ___):  # the θ-form per evaluation: sin, cos, then an argument
        return math.atan2(math.sin(v), 1.0 + 0.3 * math.cos(v))

    m, m1, nu = 0.25904853215064316, 0.7409514678493567, 1.0
    K = ef._quarter_periods(m, m1)[0]
    return [
        (
            "K = (π/2) θ₃(0)² by the nome (was R_F(0, 1 − m, 1))",
            chained(quarter),
            (m1, m, nu, 0.0),
        ),
        (
            "complete P: R_J(0, 1 − m, 1, 1 + ν), only when a step passes a half period",
            chained(complete),
            (m1, m, nu, 0.0),
        ),
        (
            "start: F and P from the state, R_F and R_J by one duplication",
            chained(start),
            (0.5, m1, nu, m),
        ),
        ("end: P alone, R_J", chained(end), (0.5, m1, nu, m)),
        (
            "sn, cn, dn by the nome's θ-series (was the AGM and 5 asin/sin)",
            chained(functions),
            (0.3 * K, m1, m, K),
        ),
        (
            "rotation R_p ← R_p P M(l)ᵀ Rz(φ) M(k) Pᵀ and the polar step",
            chained(rotation),
            (0.3, 0.6, 0.0, 0.8),
        ),
        (
            "(θ-form set-up) F of the shift β: one incomplete R_F",
            chained(first_kind),
            (0.5, m1, 0.0, 0.0),
        ),
        ("(θ-form per evaluation) sin, cos and one atan2", chained(circular), (0.4, 0, 0, 0)),
    ]


def step_timers():
    """``(label, loop, arguments)``: whole flows chained through R_p (the loop of flows.py
    without its records), on P1's orbit and on one near the separatrix (1 − m < 1/9)."""
    from tumble.rigid._compiled import exact_flow as ef

    flow = ef._exact_flow

    @numba.njit
    def loop(n, Rp, L, moments, h):
        work = np.empty(ef.WORK_SIZE)
        for _ in range(n):
            flow(Rp, L[0], L[1], L[2], moments, h, work, h, h)
        return Rp

    p1 = (np.array([2.0 / 3.0, 1.0, 2.0]), np.array([math.sin(1.1), 0.0, math.cos(1.1)]))
    near = (np.array([1.5, 2.0, 3.0]), np.array([1.5e-4, 2.0, 1.5e-4]))
    return [
        ("one exact flow, P1, h = 0.01", loop, (np.eye(3), p1[1], p1[0], 0.01)),
        ("one exact flow, P1, h = 1", loop, (np.eye(3), p1[1], p1[0], 1.0)),
        (
            "one exact flow near the separatrix (1 − m = 2e-8), h = 0.1",
            loop,
            (np.eye(3), near[1], near[0], 0.1),
        ),
    ]


def chain_rows(timers, repeat: int, calls: int) -> list:
    for _, loop, arguments in timers:
        loop(10, *arguments)
    rows = []
    for label, loop, arguments in timers:
        med, lo, hi, _ = timed(lambda f=loop, a=arguments: f(calls, *a), repeat)
        rows.append([label, spread(med / calls, lo / calls, hi / calls, 1e9, 0)])
    return rows


def splitting_rows(repeat: int) -> list:
    """µs per step of the three methods on the exact flow: P1 free, the issue's dipole."""
    from tumble.rigid.forces import MagneticDipole

    p1 = RigidBody(1.0, HLW_INERTIA, allow_unphysical=True)
    dipole = RigidBody(1.0, [3.0, 2.0, 1.5])
    load = [MagneticDipole(moment=(0.2, -0.1, 0.3), field=(0.0, 0.0, 0.5))]
    cases = [
        ("P1, free", p1, {"L0": HLW_L0}),
        ("dipole", dipole, {"omega0": (0.3, 1.0, -0.2), "forces": load}),
    ]
    rows = []
    for name in ("exact", "strang", "yoshida4"):
        row = [f"`{name}`"]
        for _, body, options in cases:
            if name == "exact" and "forces" in options:
                row.append("— (no loads)")
                continue
            tumble.simulate(body, 0.1, method=name, h=0.01, **options)
            med, lo, hi, run = timed(
                lambda b=body, o=options, n=name: tumble.simulate(
                    b, 100.0, method=n, h=0.01, record_every=10**9, **o
                ),
                repeat,
            )
            row.append(spread(med / 1e4, lo / 1e4, hi / 1e4, 1e6, 3))
        rows.append(row)
    return rows


def exact_cost_section(quick: bool, repeat: int) -> str:
    calls = 20_000 if quick else 100_000
    parts = chain_rows(part_timers(), repeat, calls)
    steps = chain_rows(step_timers(), repeat, calls)
    split = splitting_rows(repeat)
    return "\n".join(
        [
            "### 5. The exact step, part by part",
            "",
            table(["part (P1's orbit: regime A, m = 0.26, ν = 1)", "ns per call"], parts + steps),
            "",
            table(
                ["method, h = 0.01, T = 100", "P1 free: µs per step", "dipole: µs per step"], split
            ),
            "",
            "Each part runs in a compiled loop whose every call takes its input from the last "
            "call's output (a chain, as in a step), median (min–max) of repeats; the flows are "
            "`_exact_flow` chained through R_p, as the split loop calls it between records. The "
            "last part is what van Zon–Schofield's θ-form would add to every flow as a set-up "
            "(F of the third-kind integral's shift; with the nome and sin/cos it replaces the "
            "two R_J). The dipole: J = diag(3, 2, 1.5), μ = (0.2, −0.1, 0.3) A m², B = (0, 0, "
            "0.5) T, ω0 = (0.3, 1, −0.2); per step a whole `simulate` call over its 10⁴ steps "
            "(`strang` one flow and two kicks, `yoshida4` three flows).",
            "",
        ]
    )


def stamp() -> str:
    return time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())


# --- report -----------------------------------------------------------------------------------


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats and settings")
    parser.add_argument(
        "--only", nargs="*", type=int, default=[1, 2, 3, 4, 5], help="sections to run"
    )
    args, _ = parser.parse_known_args(argv)
    repeat = 3 if args.quick else 7
    IMG.mkdir(parents=True, exist_ok=True)
    sections = {
        1: lambda: sciml_section(args.quick, repeat),
        2: lambda: b5_section(args.quick, repeat),
        3: lambda: hlw_section(args.quick),
        4: lambda: box_section(args.quick),
        5: lambda: exact_cost_section(args.quick, repeat),
    }
    out = [
        "## Published benchmarks, reproduced (`benchmarks/bench_published.py`)",
        "",
        f"Machine: {machine()} (shared with other work: read ratios); {stamp()}.",
        "",
    ]
    for number in args.only:
        out.append(sections[number]())
        print(out[-1], flush=True)
    markdown = "\n".join(out)
    return markdown


if __name__ == "__main__":
    main()
