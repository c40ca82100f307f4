"""tumble against heyoka on five rigid-body problems (issue 27): the time to reach each error.

Run ``.venv/bin/python benchmarks/bench_heyoka.py [--quick]`` (``make bench`` runs it with the
others); it prints its markdown table to stdout, so that a rerun after a change of tumble's
kernels is one command. Every solver runs in this process.

The problems (T = 100 s unless noted):

1. **free body** P1 (Hairer–Lubich–Wanner): I = (2, 1, 2/3), L0 = (cos 1.1, 0, sin 1.1);
   reference the exact flow, :func:`tumble.exact.free_body_rotation`;
2. **dipole**: J = diag(3, 2, 1.5), :class:`~tumble.MagneticDipole` μ = (0.2, −0.1, 0.3),
   B = (0, 0, 0.5), ω0 = (0.3, 1, −0.2);
3. **heavy top** about a fixed tip (``simulate(..., pivot=tip)``): m = 1, I = diag(0.25,
   0.25, 0.1) at the centre of mass, the tip 0.5 below it, uniform gravity (0, 0, −9.81),
   tilted 0.3 rad about x, ω0 = (0.5, 0, 8) (the Lagrange top: it precesses and nods);
4. **gravity-gradient satellite**: :class:`~tumble.GravityGradient` with μ = 1 on a body of
   m = 1, I = diag(0.01, 0.02, 0.03), on a circular orbit of radius 1 (period 2π: 16 orbits),
   ω0 = (0.02, 0.03, 1.5) (near its major axis; about the middle axis the run is chaotic and
   no double-precision run agrees with another): the orbit and the attitude integrated
   together, coupled through the load's second-order force;
5. **SciML's RigidBody** ODE (``y₁' = −2 y₂y₃, y₂' = 1.25 y₁y₃,
   y₃' = −0.5 y₁y₂ + 0.25 sin²t``, ``y(0) = (1, 0, 0.9)``, [0, 10]) through
   :func:`tumble.solve` with a numba right-hand side (``bench_published``'s problem, its heyoka
   system and its reference).

The error of problems 1–4 is the attitude error at T, the angle of ``R R_refᵀ``; the
reference of 2–4 is heyoka in quadruple precision (``real128``, tol 1e-32). Problem 5's error
is the largest component of ``y(T) − y_ref(T)``, its reference heyoka in ``real128`` too.

heyoka's systems are written here: the quaternion ``q̇ = ½ q ⊗ (0, ω)`` (R read off q/|q|) and
Euler's equations ``I ω̇ = (I ω) × ω + τ_body`` with each load as tumble defines it
(:mod:`tumble.rigid.forces`): the dipole's ``μ × Rᵀ B``; the top about its tip with the inertia
there (:mod:`tumble.rigid.pivot`) and gravity's ``c × Rᵀ m g`` (c the centre of mass from the
tip); the gravity gradient's ``3μ/r⁵ s × I s`` (``s = Rᵀ r``) beside its force, the orbit in
the state. heyoka's one tolerance runs 1e-6 … 1e-16; its integrator is built once per
tolerance outside the timings. tumble: every method of ``METHODS``, a fixed-step method at
T/h = 1, 2, 5, 10, 20, 50, … steps, an adaptive one at rtol = 1e-4 … 1e-14, each sweep
stopped when a run exceeds the time cap (or its error stops falling at round-off). For each
target error, each side's fastest setting that reaches it is timed again with more repeats
(median and min–max, after a warm-up), and the ratio is tumble's median over heyoka's.

``--quick``: fewer repeats, a lower cap, the targets 1e-6, 1e-9 and 1e-12.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy loads OpenBLAS

import argparse  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from collections.abc import Callable  # noqa: E402
from dataclasses import dataclass, field  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))

import bench_published as published  # noqa: E402
from _timing import load, machine, spread, table, timed  # noqa: E402

import tumble  # noqa: E402
from tumble import RigidBody, exact, so3  # noqa: E402
from tumble.ode import TABLEAUX  # noqa: E402
from tumble.rigid import METHODS  # noqa: E402
from tumble.rigid.forces import Gravity, GravityGradient, MagneticDipole  # noqa: E402

TARGETS = tuple(10.0**-k for k in range(6, 14))
QUICK_TARGETS = (1e-6, 1e-9, 1e-12)
HEYOKA_TOLS = tuple(10.0**-k for k in range(6, 17))
STEP_COUNTS = (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10**4, 2 * 10**4,
               5 * 10**4, 10**5, 2 * 10**5)  # fmt: skip
RTOLS = (*(10.0**-k for k in range(4, 14)), 3e-14)
"""rtol of the adaptive sweeps (tumble refuses below 100 ε = 2.2e-14)."""
REFERENCE_TOL = 1e-32
G = 9.81


def angle(R: np.ndarray, R_ref: np.ndarray) -> float:
    """The angle of ``R R_refᵀ`` (rad): ``2 asin(‖R − R_ref‖_F / √8)``, exact for rotations
    and accurate at small angles (inf when R is not finite)."""
    with np.errstate(over="ignore", invalid="ignore"):
        d = float(np.linalg.norm(R - R_ref))
    if not math.isfinite(d):
        return math.inf
    return 2.0 * math.asin(min(1.0, d / math.sqrt(8.0)))


def quat_matrix(q) -> np.ndarray:
    q = np.array([float(v) for v in q])
    return so3.matrix_from_quat(q / np.linalg.norm(q))


# --- the problems ------------------------------------------------------------------------------


@dataclass(frozen=True)
class Rigid:
    """A rigid-body problem: how tumble's ``simulate`` starts it and how heyoka's system is
    built. ``moments`` are heyoka's (about the pivot for the top); ``load`` names the torque."""

    name: str
    body: RigidBody
    t_end: float
    options: dict  # simulate's start and loads
    moments: tuple[float, float, float]
    omega0: tuple[float, float, float]
    R0: np.ndarray
    load: str  # "none", "dipole", "top", "gradient"
    constants: dict = field(default_factory=dict)
    note: str = ""

    @property
    def exact_reference(self) -> bool:
        return self.load == "none"


def problems() -> list[Rigid]:
    p1 = RigidBody(1.0, published.HLW_INERTIA, allow_unphysical=True)
    free = Rigid("free body P1", p1, 100.0, {"L0": published.HLW_L0},
                 tuple(published.HLW_INERTIA),
                 tuple(published.HLW_L0 / published.HLW_INERTIA), np.eye(3), "none")  # fmt: skip
    mu, B = (0.2, -0.1, 0.3), (0.0, 0.0, 0.5)
    omega = (0.3, 1.0, -0.2)
    dipole = Rigid("dipole", RigidBody(1.0, [3.0, 2.0, 1.5]), 100.0,
                   {"omega0": omega, "forces": [MagneticDipole(moment=mu, field=B)]},
                   (3.0, 2.0, 1.5), omega, np.eye(3), "dipole", {"mu": mu, "B": B})  # fmt: skip
    top_body, tip = RigidBody(1.0, [0.25, 0.25, 0.1]), np.array([0.0, 0.0, -0.5])
    R_top = so3.exp([0.3, 0.0, 0.0])
    top_omega = (0.5, 0.0, 8.0)
    ell2 = float(tip @ tip)
    top = Rigid("heavy top", top_body, 100.0,
                {"omega0": top_omega, "R0": R_top, "pivot": tip,
                 "forces": [Gravity((0.0, 0.0, -G))]},
                (0.25 + ell2, 0.25 + ell2, 0.1), top_omega, R_top, "top",
                {"c": tuple(-tip), "mg": (0.0, 0.0, -G)})  # fmt: skip
    inertia = (0.01, 0.02, 0.03)
    sat_omega = (0.02, 0.03, 1.5)
    gradient = Rigid("gravity gradient", RigidBody(1.0, list(inertia)), 100.0,
                     {"omega0": sat_omega, "x0": (1.0, 0.0, 0.0), "v0": (0.0, 1.0, 0.0),
                      "forces": [GravityGradient(mu=1.0)]},
                     inertia, sat_omega, np.eye(3), "gradient",
                     {"mu": 1.0, "x0": (1.0, 0.0, 0.0), "v0": (0.0, 1.0, 0.0)})  # fmt: skip
    return [free, dipole, top, gradient]


# --- heyoka --------------------------------------------------------------------------------


def heyoka_system(problem: Rigid):
    """``(variables, equations)``: q (4), ω (3), and for the gravity gradient x, v (6)."""
    import heyoka as hy

    q0, q1, q2, q3, w1, w2, w3 = hy.make_vars("q0", "q1", "q2", "q3", "w1", "w2", "w3")
    A, B, C = problem.moments
    # R(q) for a unit q (body → world); the exact solution keeps |q| = 1
    R = [
        [1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
        [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
        [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)],
    ]

    def body(v):  # Rᵀ v for a constant world vector
        return [sum(R[i][j] * v[i] for i in range(3) if v[i] != 0.0) for j in range(3)]

    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

    tau: list = [0.0, 0.0, 0.0]
    extra: list = []
    k = problem.constants
    if problem.load == "dipole":
        tau = cross(list(k["mu"]), body(k["B"]))
    elif problem.load == "top":
        tau = cross(list(k["c"]), body(k["mg"]))  # m = 1
    elif problem.load == "gradient":
        x, y, z, vx, vy, vz = hy.make_vars("x", "y", "z", "vx", "vy", "vz")
        r = [x, y, z]
        s = [R[0][j] * x + R[1][j] * y + R[2][j] * z for j in range(3)]  # Rᵀ r
        Is = [A * s[0], B * s[1], C * s[2]]
        r2 = x * x + y * y + z * z
        inv_r = r2**-0.5
        inv_r3 = inv_r / r2
        k5 = 3.0 * k["mu"] * inv_r3 / r2  # 3μ/r⁵
        tau = [k5 * t for t in cross(s, Is)]
        sIs = s[0] * Is[0] + s[1] * Is[1] + s[2] * Is[2]
        radial = 0.5 * (A + B + C) - 2.5 * sIs / r2
        w = [R[i][0] * Is[0] + R[i][1] * Is[1] + R[i][2] * Is[2] for i in range(3)]  # I_w r
        force = [-k["mu"] * inv_r3 * r[i] - k5 * (radial * r[i] + w[i]) for i in range(3)]
        extra = [(x, vx), (y, vy), (z, vz), (vx, force[0]), (vy, force[1]), (vz, force[2])]
    equations = [
        (q0, 0.5 * (-q1 * w1 - q2 * w2 - q3 * w3)),
        (q1, 0.5 * (q0 * w1 + q2 * w3 - q3 * w2)),
        (q2, 0.5 * (q0 * w2 + q3 * w1 - q1 * w3)),
        (q3, 0.5 * (q0 * w3 + q1 * w2 - q2 * w1)),
        (w1, ((B - C) * w2 * w3 + tau[0]) / A),
        (w2, ((C - A) * w3 * w1 + tau[1]) / B),
        (w3, ((A - B) * w1 * w2 + tau[2]) / C),
    ]
    return equations + extra


def heyoka_start(problem: Rigid) -> list[float]:
    q = so3.quat_from_matrix(problem.R0)
    start = [*map(float, q), *problem.omega0]
    if problem.load == "gradient":
        start += [*problem.constants["x0"], *problem.constants["v0"]]
    return start


def heyoka_rigid(problem: Rigid, tol: float, quad: bool = False) -> Callable[[], np.ndarray]:
    """heyoka's integrator for ``problem`` (built once); ``run()`` returns R(T)."""
    import heyoka as hy

    cast = hy.real128 if quad else float
    dtype = hy.real128 if quad else float
    start = np.array([cast(v) for v in heyoka_start(problem)], dtype=dtype)
    extra = {"fp_type": hy.real128} if quad else {}
    ta = hy.taylor_adaptive(heyoka_system(problem), start, tol=cast(tol), **extra)
    end = cast(problem.t_end)

    def run() -> np.ndarray:
        ta.time = cast(0.0)
        ta.state[:] = start
        ta.propagate_until(end)
        return quat_matrix(ta.state[:4])

    return run


# --- tumble --------------------------------------------------------------------------------


def tumble_rigid(problem: Rigid, method: str, setting) -> Callable[[], np.ndarray]:
    """``run()`` of ``simulate`` at ``setting`` (steps over T, or rtol): R(T)."""
    adaptive = METHODS[method].adaptive
    options = {"rtol": setting} if adaptive else {"h": problem.t_end / setting}

    def run() -> np.ndarray:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with np.errstate(all="ignore"):
                out = tumble.simulate(
                    problem.body, problem.t_end, method=method, record_every=2**62,
                    **options, **problem.options,
                )  # fmt: skip
        return out.R[-1] if out.success else np.full((3, 3), np.nan)

    return run


def takes(problem: Rigid, method: str) -> bool:
    return problem.load == "none" or not METHODS[method].exact


# --- the sweeps ------------------------------------------------------------------------------


@dataclass
class Point:
    label: str  # "heyoka" or the tumble method
    setting: object  # tol, steps or rtol
    error: float
    times: tuple[float, float, float]
    run: Callable[[], object]

    def describe(self) -> str:
        if self.label == "heyoka":
            return f"tol {self.setting:.0e}"
        if isinstance(self.setting, float):
            return f"`{self.label}` rtol {self.setting:.0e}"
        return f"`{self.label}` h={self.t_end_over(self.setting)}"

    t_end: float = 100.0

    def t_end_over(self, steps) -> str:
        return f"{self.t_end / steps:.3g}"


def sweep(label: str, settings, make: Callable, error_of: Callable, repeat: int, cap: float,
          t_end: float) -> list[Point]:  # fmt: skip
    """Each setting's error and time (``repeat`` runs after a warm-up) until a run takes
    longer than ``cap`` s, or two in a row no longer improve an error below 1e-11."""
    found: list[Point] = []
    stalled = 0
    for setting in settings:
        run = make(setting)
        result = run()  # warm-up: compilation, dispatch
        error = error_of(result)
        med, lo, hi, _ = timed(run, repeat)
        found.append(Point(label, setting, error, (med, lo, hi), run, t_end))
        if med > cap:
            break
        best = min(p.error for p in found[:-1]) if len(found) > 1 else math.inf
        stalled = stalled + 1 if error < 1e-11 and error >= 0.5 * best else 0
        if stalled >= 2:
            break
    return found


def fastest(points: list[Point], target: float, among: int = 1) -> list[Point]:
    good = sorted((p for p in points if p.error <= target), key=lambda p: p.times[0])
    return good[:among]


def retime(candidates: list[Point], repeat: int) -> Point | None:
    """The fastest of ``candidates`` after timing each again with ``repeat`` runs."""
    best = None
    for point in candidates:
        point.run()
        med, lo, hi, _ = timed(point.run, repeat)
        point = Point(point.label, point.setting, point.error, (med, lo, hi), point.run,
                      point.t_end)  # fmt: skip
        if best is None or med < best.times[0]:
            best = point
    return best


@dataclass
class Outcome:
    problem: str
    reference: str
    rows: list  # (target, heyoka Point | None, tumble Point | None)
    floors: tuple[float, float]  # smallest error reached: heyoka, tumble
    check: str = ""


def compare(name: str, reference: str, heyoka: list[Point], ours: dict[str, list[Point]],
            targets, repeat: int, check: str = "") -> Outcome:  # fmt: skip
    everything = [p for points in ours.values() for p in points]
    rows = []
    for target in targets:
        peer = retime(fastest(heyoka, target, 2), repeat)
        mine = retime(fastest(everything, target, 3), repeat)
        rows.append((target, peer, mine))
    floors = (min((p.error for p in heyoka), default=math.inf),
              min((p.error for p in everything), default=math.inf))  # fmt: skip
    return Outcome(name, reference, rows, floors, check)


def rigid_outcome(problem: Rigid, targets, repeat: int, cap: float, quick: bool) -> Outcome:
    if problem.exact_reference:
        R_ref = exact.free_body_rotation(problem.moments, problem.omega0, problem.t_end)
        reference = "exact flow (`tumble.exact.free_body_rotation`)"
    else:
        start = time.perf_counter()
        R_ref = heyoka_rigid(problem, REFERENCE_TOL, quad=True)()
        reference = f"heyoka real128, tol 1e-32 ({time.perf_counter() - start:.1f} s)"
    error_of = lambda R: angle(R, R_ref)  # noqa: E731
    heyoka = sweep("heyoka", HEYOKA_TOLS, lambda tol: heyoka_rigid(problem, tol), error_of,
                   repeat, math.inf, problem.t_end)  # fmt: skip
    check = ""
    if problem.exact_reference:  # the reference checked against heyoka in quadruple precision
        quad = heyoka_rigid(problem, REFERENCE_TOL, quad=True)()
        check = f"heyoka real128 differs from the exact flow by {angle(quad, R_ref):.1e} rad"
    ours = {}
    for method in METHODS:
        if not takes(problem, method):
            continue
        settings = RTOLS if METHODS[method].adaptive else STEP_COUNTS
        ours[method] = sweep(method, settings, lambda s, m=method: tumble_rigid(problem, m, s),
                             error_of, max(1, repeat // 2), cap, problem.t_end)  # fmt: skip
        print(f"  {problem.name}: {method} down to {min(p.error for p in ours[method]):.1e}",
              flush=True)  # fmt: skip
    return compare(problem.name, reference, heyoka, ours, targets, repeat, check)


def sciml_outcome(targets, repeat: int, cap: float) -> Outcome:
    """SciML's RigidBody through ``solve``: every tableau, fixed steps or (atol = rtol)."""
    problem = published.SCIML
    y_ref = np.array([float(v) for v in published.reference(problem)])
    error_of = lambda y: float(np.abs(y - y_ref).max())  # noqa: E731

    def heyoka_make(tol):
        run = published.heyoka_integrator(problem, tol)
        return run

    heyoka = sweep("heyoka", HEYOKA_TOLS, heyoka_make, error_of, repeat, math.inf,
                   problem.t_end)  # fmt: skip
    ours = {}
    for name, tableau in TABLEAUX.items():
        if tableau.b_hat is None:
            settings = STEP_COUNTS[3:]

            def make(n, name=name):
                return lambda: tumble.solve(problem.rhs, (0.0, problem.t_end), problem.start,
                                            method=name, h=problem.t_end / n).y[:, -1]  # fmt: skip
        else:
            settings = RTOLS

            def make(tol, name=name):
                return lambda: tumble.solve(problem.rhs, (0.0, problem.t_end), problem.start,
                                            method=name, rtol=tol, atol=tol).y[:, -1]  # fmt: skip

        ours[name] = sweep(name, settings, make, error_of, max(1, repeat // 2), cap,
                           problem.t_end)  # fmt: skip
        print(f"  SciML: {name} down to {min(p.error for p in ours[name]):.1e}", flush=True)
    return compare("SciML RigidBody (`solve`, T = 10)", "heyoka real128, tol 1e-32 "
                   "(`bench_published.reference`)", heyoka, ours, targets, repeat)  # fmt: skip


# --- the table ---------------------------------------------------------------------------------


def cell(point: Point | None) -> str:
    if point is None:
        return "—"
    return f"{point.describe()}: {spread(*point.times, 1e3, 3)} ms"


def outcome_rows(outcome: Outcome) -> list:
    rows = []
    for target, peer, mine in outcome.rows:
        if peer is None and mine is None:
            ratio, met = "— (neither reaches it: the floors below)", "—"
        elif peer is None or mine is None:
            ratio = "— (not reached)" if mine is None else "— (heyoka does not reach it)"
            met = "NOT MET" if mine is None else "MET"
        else:
            value = mine.times[0] / peer.times[0]
            ratio, met = f"**{value:.2f}×**", "MET" if value <= 1.0 else "NOT MET"
        rows.append([outcome.problem, f"{target:.0e}", cell(peer), cell(mine), ratio, met])
    return rows


def markdown(outcomes: list[Outcome], quick: bool, seconds: float) -> str:
    header = ["problem", "error ≤", "heyoka: fastest tol, ms", "tumble: fastest method and "
              "setting, ms", "tumble / heyoka", "goal (≤ 1×)"]  # fmt: skip
    rows = [row for outcome in outcomes for row in outcome_rows(outcome)]
    notes = []
    for outcome in outcomes:
        heyoka_floor, tumble_floor = outcome.floors
        notes.append(
            f"- {outcome.problem}: reference {outcome.reference}; smallest error reached: "
            f"heyoka {heyoka_floor:.1e}, tumble {tumble_floor:.1e}"
            + (f"; {outcome.check}" if outcome.check else "")
            + "."
        )
    met = sum(1 for row in rows if row[-1] == "MET")
    rows_counted = sum(1 for row in rows if row[-1] != "—")
    return "\n".join(
        [
            "## tumble against heyoka on five rigid-body problems (`benchmarks/bench_heyoka.py`)",
            "",
            f"Machine: {machine()}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; "
            f"{load()}{' (`--quick`)' if quick else ''}; the run took {seconds:.0f} s.",
            "",
            table(header, rows),
            "",
            f"The goal (tumble's fastest no slower than heyoka's fastest) is met in {met} of "
            f"{rows_counted} cells that either side reaches. "
            "Times: median (min–max) of repeated runs after a warm-up, "
            "each side's fastest setting timed again in the same process; heyoka's "
            "integrator built outside the timing. Errors: the attitude angle of R R_refᵀ at T "
            "(SciML: the largest component of y(T) − y_ref). The problems are in the module "
            "docstring of `benchmarks/bench_heyoka.py`.",
            "",
            *notes,
            "",
        ]
    )


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats and targets")
    parser.add_argument("--only", nargs="*", type=int, default=[1, 2, 3, 4, 5],
                        help="problems to run (1-5)")  # fmt: skip
    args, _ = parser.parse_known_args(argv)
    try:
        import heyoka  # noqa: F401
    except ImportError:
        text = "## tumble against heyoka\n\nSkipped: heyoka is not installed (the bench extra).\n"
        print(text)
        return text
    started = time.perf_counter()
    targets = QUICK_TARGETS if args.quick else TARGETS
    repeat, cap = (5, 0.01) if args.quick else (15, 0.05)
    outcomes = []
    for number, problem in enumerate(problems(), start=1):
        if number in args.only:
            outcomes.append(rigid_outcome(problem, targets, repeat, cap, args.quick))
    if 5 in args.only:
        outcomes.append(sciml_outcome(targets, repeat, cap))
    text = markdown(outcomes, args.quick, time.perf_counter() - started)
    print(text, flush=True)
    return text


if __name__ == "__main__":
    main()
