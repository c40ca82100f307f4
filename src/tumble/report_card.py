"""The integrator report card: every rigid-body method measured the same way, peers beside it.

:func:`report` runs every method of :data:`tumble.rigid.METHODS` — it has no list of its own,
so a method added there appears here — and the peers (scipy's ``DOP853`` and ``RK45`` on
Euler's equations with a quaternion, MuJoCo's ``RK4`` and ``Euler`` when the ``bench`` extra
is installed) through one harness, on the same problems:

* ``P1``: Hairer–Lubich–Wanner's body I = diag(2, 1, 2/3) kg m², L₀ = (cos 1.1, 0, sin 1.1),
  R₀ = I (exact reference :func:`tumble.exact.free_body_rotation`);
* the T-handle's three spins (:data:`tumble.scenarios.t_handle.SPINS`) and a spin ten
  thousand times nearer its separatrix, ω₀ = (1, 10⁻⁴, 0) rad/s (exact reference);
* ``forced``: P1's body with a magnetic dipole μ = (1, 0.5, 0) A m² in B = (0, 0, 0.5) T
  (:class:`tumble.MagneticDipole`), against a tight scipy DOP853 reference (rtol = atol =
  10⁻¹³).

For each method it measures

* the **order**: the least-squares slope ``p`` of log e against log h
  (:func:`tumble.exact.observed_order`), e = ‖R(T) − R_ref(T)‖_F, through the four finest
  runs whose error lies in the asymptotic window (:data:`ASYMPTOTIC`), on P1 — or on the
  forced body when P1 leaves every error at round-off (the splittings on the exact flow);
  it agrees with the declared :attr:`~tumble.rigid.Method.order` when
  ``|p − order| ≤`` :data:`ORDER_TOLERANCE`. An adaptive method's order is that of the
  formula it propagates, measured at fixed steps (:func:`fixed_step_end`); through its
  controller, against the mean step T/steps, the slope wanders by up to an order with the
  tolerance (the step distribution changes with it), and is reported beside;
* the **error at T** on every problem at one setting (h = :data:`STANDARD_H`, or
  rtol = :data:`STANDARD_RTOL` for an adaptive method: tumble's scale atol with it, scipy's
  take atol = rtol);
* the **invariants over a long run** (h = :data:`LONG_H`, rtol = :data:`LONG_RTOL`): the
  growth law of the energy error, the slope ``s`` of log max_{τ≤t}|E(τ) − E₀| against log t
  over the last decade of t (0: bounded, 1: linear drift), the Casimir
  ``max ||RᵀL| − |L₀|| / |L₀|``, ``max ‖RᵀR − I‖_F`` and ``max ||q| − 1|`` of a carried
  quaternion;
* the **cost**: warm µs per step, and the first call's time in a fresh process.

A method whose measurements contradict what it declares (order; symplectic, energy-, Casimir-
or SO(3)-preserving: :attr:`~tumble.rigid.Method.conserves`) is listed in
:attr:`ReportCard.contradictions`. :func:`write` writes ``report.md``, ``report.html``
(:mod:`tumble.viz.report_card`) and ``report.nc``, each atomically. The structural schemes
(:data:`tumble.structural.SCHEMES`) get a table of their own (:func:`structural_rows`).

References
----------
E. Hairer, C. Lubich, G. Wanner, Geometric Numerical Integration, 2nd ed., Springer 2006,
§IV.1, §VII.5 (P1), ch. IX (energy of symplectic methods).
"""

from __future__ import annotations

import json
import logging
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tumble import _checks, exact, mass, so3
from tumble._atomic import atomic_write
from tumble._progress import progress_bar
from tumble._version import __version__
from tumble.rigid import METHODS, MagneticDipole, RigidBody, simulate
from tumble.rigid.methods import Method
from tumble.scenarios import convergence, t_handle

log = logging.getLogger(__name__)

ORDER_TOLERANCE = 0.3
"""A measured order agrees with the declared one within this (the slope of a least-squares
fit through the asymptotic window; the tests of single methods ask ±0.2 on chosen steps)."""
FIT_POINTS = 4
"""The order is fitted through the (up to) four finest runs inside the window: the nearest
to the asymptotic regime."""
ASYMPTOTIC = (1e-11, 1e-1)
"""Errors e = ‖R(T) − R_ref(T)‖_F fitted for the order on P1: below 1e-1 the runs are in
the asymptotic range, above 1e-11 they are truncation, not round-off (which reaches 1e-13
after 10⁵ steps)."""
FORCED_FLOOR = 1e-9
"""The forced body's reference (DOP853 at 1e-13) is good to about 1e-11: errors below this
are not fitted."""
STEP_COUNTS = (10, 13, 16, 20, 25, 32, 40, 50, 64, 80, 100, 200, 500, 1000, 2000, 5000, 10000,
               20000, 50000)  # fmt: skip
"""Steps over [0, T] of the fixed-step sweeps (T = 10 s: h = 1 … 2·10⁻⁴ s), dense at the
coarse end, where an eighth-order method's errors fall from 1e-7 to round-off."""
TOLERANCES = tuple(10.0**-k for k in range(3, 13))
"""rtol of the adaptive sweeps, 1e-3 … 1e-12 (tumble's methods scale atol with it, scipy's
take atol = rtol)."""
STANDARD_H = 0.01
"""The step (s) of the error-at-T table."""
STANDARD_RTOL = 1e-8
"""The tolerance of the error-at-T table for adaptive methods."""
LONG_H = 0.02
"""The step (s) of the long runs."""
LONG_RTOL = 1e-6
"""The tolerance of the long runs for adaptive methods."""
LONG_SAMPLES = 2000
"""Samples kept from a long run (the energy law is fitted through them)."""
ROUND_OFF = 1e-11
"""An invariant whose largest relative change stays below this is kept to round-off (10⁵
steps of 10⁻¹⁶ each, with three decades to spare)."""
BOUNDED_SLOPE = 0.5
"""An energy error whose running maximum grows over the last decade of t with a log–log
slope below this is bounded: a systematic drift has slope 1, a sum of independent errors
(a random walk) ½, and only an error that keeps returning grows slower. (``midpoint-lp`` with
the dipole: 0.38 over [100, 1000] s, 0.13 over [10³, 10⁴] s, at 6e-5 both times.)"""
SWEEP_T = 10.0
"""T (s) of the order sweeps."""
PROBLEM_T = 50.0
"""T (s) of the T-handle's runs (its flip takes 47 s)."""

P1_INERTIA = np.array(convergence.INERTIA)
P1_L0 = np.array(convergence.L0)
DIPOLE = MagneticDipole(moment=(1.0, 0.5, 0.0), field=(0.0, 0.0, 0.5))
"""The forced body's load: a compass needle, torque (Rμ) × B, potential −(Rμ)·B."""
SEPARATRIX_SPIN = (1.0, 1e-4, 0.0)
"""The T-handle spun about its middle axis x with a 10⁻⁴ wobble: near the separatrix."""


# --- the problems ----------------------------------------------------------------------------


@dataclass(frozen=True)
class Problem:
    """One test problem: a body, its start (R₀ = I, ω₀ body frame), T and loads.

    ``dipole`` is None for a free body (exact reference) or the magnetic dipole.
    """

    name: str
    body: RigidBody
    omega0: np.ndarray
    t_end: float
    dipole: MagneticDipole | None = None

    @property
    def forced(self) -> bool:
        return self.dipole is not None

    def forces(self) -> list:
        return [] if self.dipole is None else [self.dipole]


def problems() -> list[Problem]:
    """P1, the T-handle's three spins, the near-separatrix spin and the forced body."""
    p1_body = RigidBody(1.0, P1_INERTIA, allow_unphysical=True)
    p1_omega = P1_L0 / P1_INERTIA
    handle = RigidBody.from_mass_properties(mass.t_handle())
    spins = [
        Problem(f"T-handle ω₀={tuple(spin)}", handle, np.array(spin, float), PROBLEM_T)
        for spin in t_handle.SPINS
    ]
    return [
        Problem("P1", p1_body, p1_omega, SWEEP_T),
        *spins,
        Problem("separatrix", handle, np.array(SEPARATRIX_SPIN), PROBLEM_T),
        Problem("forced", p1_body, p1_omega, SWEEP_T, DIPOLE),
    ]


# --- the rows: tumble's methods and the peers --------------------------------------------------


CLAIMS = ("symplectic", "energy", "casimir", "orthogonality")
"""What a row may claim: symplectic (energy bounded over long runs, with or without
conservative loads), and the invariants of :attr:`tumble.rigid.Method.conserves` kept to
round-off on the torque-free body."""


@dataclass(frozen=True)
class Row:
    """One integrator in the report: a tumble method or a peer.

    ``claims`` is a subset of :data:`CLAIMS`; ``order`` the declared order (``inf``: exact).
    """

    name: str
    source: str  # "tumble", "scipy", "MuJoCo"
    order: float
    adaptive: bool
    claims: frozenset[str]
    family: str
    takes_loads: bool = True


def method_row(method: Method) -> Row:
    """A tumble method's row: what it declares."""
    claims = set(method.conserves) & set(CLAIMS)
    if method.symplectic:
        claims.add("symplectic")
    return Row(method.name, "tumble", float(method.order), method.adaptive,
               frozenset(claims), method.family, takes_loads=not method.exact)  # fmt: skip


def mujoco_available() -> bool:
    """Whether MuJoCo (the ``bench`` extra) can be imported."""
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return False
    return True


def rows(methods: Iterable[str] | None = None, *, peers: bool = True) -> list[Row]:
    """Every method of :data:`tumble.rigid.METHODS` (or those named), then the peers."""
    names = list(METHODS) if methods is None else list(methods)
    found = [method_row(METHODS[_checks.choice("methods", name, METHODS)]) for name in names]
    if peers:
        found += [
            Row("scipy DOP853", "scipy", 8.0, True, frozenset(), "quat, unnormalised"),
            Row("scipy RK45", "scipy", 5.0, True, frozenset(), "quat, unnormalised"),
        ]
        if mujoco_available():
            found += [
                Row("MuJoCo RK4", "MuJoCo", 4.0, False, frozenset(), "quat", takes_loads=False),
                Row("MuJoCo Euler", "MuJoCo", 1.0, False, frozenset(), "quat", takes_loads=False),
            ]
    return found


# --- one run of one row ------------------------------------------------------------------------


@dataclass
class Sampled:
    """What one run left: samples of the attitude, the invariants, the cost.

    ``R_end`` is the attitude at T (projected onto SO(3) only where the integrator itself
    does); ``energy`` and ``casimir`` (|RᵀL|, body-frame momentum norm) are sampled along
    the run at ``t``; ``orthogonality`` is ``max ‖RᵀR − I‖_F``; ``quaternion`` is
    ``max ||q| − 1|`` of a carried quaternion (NaN when none is carried).
    """

    t: np.ndarray
    R_end: np.ndarray
    energy: np.ndarray
    casimir: np.ndarray
    orthogonality: float
    quaternion: float
    steps: int
    seconds: float
    ok: bool = True


def _tumble_run(row: Row, problem: Problem, setting: float, t_end: float, samples: int):
    tolerance = setting if row.adaptive else None
    n_guess = samples if row.adaptive else max(1, round(t_end / setting))
    record = max(1, n_guess // samples) if samples else 2**62
    start = time.perf_counter()
    run = simulate(problem.body, t_end, method=row.name, omega0=problem.omega0,
                   forces=problem.forces(), record_every=record,
                   h=None if row.adaptive else setting, rtol=tolerance)  # fmt: skip
    seconds = time.perf_counter() - start
    with np.errstate(over="ignore", invalid="ignore"):
        body_L = np.einsum("nji,nj->ni", run.R, run.L_world)
        casimir = np.linalg.norm(body_L, axis=1)
        quaternion = (
            float(np.max(np.abs(run.quaternion_norm_error))) if run.q_raw is not None else math.nan
        )
    orthogonality = run.orthogonality_drift  # a blown-up matrix run: inf, the run failed
    return Sampled(run.t, run.R[-1], run.energy, casimir, orthogonality, quaternion,
                   run.n_steps, seconds, run.success and math.isfinite(orthogonality))  # fmt: skip


def _rhs(problem: Problem):
    """Euler's equations and ``q̇ = ½ q ⊗ (0, ω)`` for ``y = (ω, q)`` (the peers' way), with
    the dipole's body torque ``μ × (Rᵀ B)``."""
    A, B, C = problem.body.inertia.diagonal()
    inertia = np.array([A, B, C])
    dipole = problem.dipole

    def f(t, y):
        w1, w2, w3, q0, q1, q2, q3 = y
        torque = np.zeros(3)
        if dipole is not None:
            R = so3.matrix_from_quat(y[3:])
            torque = np.cross(dipole.moment, R.T @ dipole.field) / inertia
        return np.array(
            [
                (B - C) * w2 * w3 / A + torque[0],
                (C - A) * w3 * w1 / B + torque[1],
                (A - B) * w1 * w2 / C + torque[2],
                0.5 * (-q1 * w1 - q2 * w2 - q3 * w3),
                0.5 * (q0 * w1 + q2 * w3 - q3 * w2),
                0.5 * (q0 * w2 + q3 * w1 - q1 * w3),
                0.5 * (q0 * w3 + q1 * w2 - q2 * w1),
            ]
        )

    return f


def _peer_energy(problem: Problem, omega: np.ndarray, R: np.ndarray) -> np.ndarray:
    inertia = problem.body.inertia.diagonal()
    kinetic = 0.5 * np.einsum("ni,ni->n", omega, omega * inertia)
    if problem.dipole is None:
        return kinetic
    return kinetic - np.einsum("nij,j,i->n", R, problem.dipole.moment, problem.dipole.field)


def _scipy_run(method: str, problem: Problem, rtol: float, t_end: float) -> Sampled:
    """solve_ivp on :func:`_rhs`; its samples are its accepted steps."""
    from scipy.integrate import solve_ivp

    y0 = np.concatenate([problem.omega0, [1.0, 0.0, 0.0, 0.0]])
    start = time.perf_counter()
    solution = solve_ivp(_rhs(problem), (0.0, t_end), y0, method=method, rtol=rtol,
                         atol=rtol)  # fmt: skip
    seconds = time.perf_counter() - start
    y = solution.y.T
    q = y[:, 3:]
    R = so3.matrix_from_quat(q)  # normalised: the peers read the attitude off q/|q|
    omega = y[:, :3]
    casimir = np.linalg.norm(omega * problem.body.inertia.diagonal(), axis=1)
    return Sampled(solution.t, R[-1], _peer_energy(problem, omega, R), casimir, 0.0,
                   float(np.max(np.abs(np.linalg.norm(q, axis=1) - 1.0))),
                   int(solution.t.size - 1), seconds, bool(solution.success))  # fmt: skip


def _mujoco_model(problem: Problem, integrator: str, h: float):
    """One free-joint body, gravity off; the inertia set after compiling (MuJoCo's compiler
    refuses P1's, which breaks the triangle inequality), as in benchmarks/bench_rigid.py."""
    import mujoco

    xml = f"""<mujoco><option gravity="0 0 0" integrator="{integrator}" timestep="{h}"/>
      <worldbody><body><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
      </body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    model.body_mass[1] = problem.body.mass
    model.body_inertia[1] = problem.body.inertia.diagonal()
    mujoco.mj_setConst(model, mujoco.MjData(model))
    return model


def _mujoco_run(integrator: str, problem: Problem, h: float, t_end: float,
                samples: int) -> Sampled:  # fmt: skip
    import mujoco

    n = max(1, round(t_end / h))
    model = _mujoco_model(problem, integrator, t_end / n)
    data = mujoco.MjData(model)
    data.qvel[3:6] = problem.omega0  # a free joint's angular velocity is in the body frame
    mujoco.mj_forward(model, data)
    every = max(1, n // samples) if samples else n
    t, q, omega = [0.0], [data.qpos[3:7].copy()], [data.qvel[3:6].copy()]
    # MuJoCo prints its warnings (a diverging Euler run) to the terminal: log them instead
    mujoco.set_mju_user_warning(lambda message: log.info("MuJoCo: %s", message))
    start = time.perf_counter()
    bad = int(mujoco.mjtWarning.mjWARN_BADQACC)
    for k in range(1, n + 1):
        mujoco.mj_step(model, data)
        if data.warning[bad].number:  # MuJoCo has reset the body to rest: the run failed here
            break
        if k % every == 0 or k == n:
            t.append(k * t_end / n)
            q.append(data.qpos[3:7].copy())
            omega.append(data.qvel[3:6].copy())
    seconds = time.perf_counter() - start
    q_all, omega_all = np.array(q), np.array(omega)
    R = so3.matrix_from_quat(q_all)
    casimir = np.linalg.norm(omega_all * problem.body.inertia.diagonal(), axis=1)
    return Sampled(np.array(t), R[-1], _peer_energy(problem, omega_all, R), casimir, 0.0,
                   float(np.max(np.abs(np.linalg.norm(q_all, axis=1) - 1.0))), k, seconds,
                   not data.warning[bad].number)  # fmt: skip


def run_row(row: Row, problem: Problem, setting: float, *, t_end: float | None = None,
            samples: int = 0) -> Sampled | None:  # fmt: skip
    """Run ``row`` on ``problem`` with ``setting`` (h, or rtol), keeping about
    ``samples`` samples (0: only the ends). None when the row takes no loads and the problem
    has some."""
    t_end = problem.t_end if t_end is None else t_end
    if problem.forced and not row.takes_loads:
        return None
    with np.errstate(over="ignore", invalid="ignore"):
        if row.source == "tumble":
            return _tumble_run(row, problem, setting, t_end, samples)
        if row.source == "scipy":
            return _scipy_run(row.name.split()[-1], problem, setting, t_end)
        return _mujoco_run(row.name.split()[-1], problem, setting, t_end, samples)


# --- references ------------------------------------------------------------------------------


def reference(problem: Problem, t_end: float | None = None) -> np.ndarray:
    """R(T): exact for a free body, scipy DOP853 at rtol = atol = 1e-13 for the forced one."""
    t_end = problem.t_end if t_end is None else t_end
    if not problem.forced:
        return exact.free_body_rotation(problem.body.inertia, problem.omega0, t_end)
    return _scipy_run("DOP853", problem, 1e-13, t_end).R_end


def attitude_error(R: np.ndarray, R_ref: np.ndarray) -> float:
    """``‖R − R_ref‖_F`` (inf when R is not finite)."""
    with np.errstate(over="ignore", invalid="ignore"):
        error = float(np.linalg.norm(R - R_ref))
    return error if math.isfinite(error) else math.inf


# --- order -----------------------------------------------------------------------------------


@dataclass
class Sweep:
    """One row's runs over its settings on one problem: the work–precision points.

    ``mean_step`` is h for a fixed-step row, T / accepted steps for an adaptive one."""

    problem: str
    settings: list[float] = field(default_factory=list)
    mean_step: list[float] = field(default_factory=list)
    steps: list[int] = field(default_factory=list)
    seconds: list[float] = field(default_factory=list)
    error: list[float] = field(default_factory=list)
    energy_error: list[float] = field(default_factory=list)


@dataclass
class Order:
    """The measured order of a row: the slope, the fit range of h̄, the problem, the verdict."""

    measured: float
    h_min: float
    h_max: float
    points: int
    problem: str
    verdict: str  # "agrees", "contradicts", "exact"
    against_mean_step: float = math.nan  # an adaptive row: the slope against T/steps


def sweep(row: Row, problem: Problem, R_ref: np.ndarray, repeat: int = 1) -> Sweep | None:
    """Run ``row`` over :data:`STEP_COUNTS` (or :data:`TOLERANCES`) on ``problem``; each
    run's time is the best of ``repeat``, after one warm-up run (numba's dispatch, the first
    call's imports)."""
    if problem.forced and not row.takes_loads:
        return None
    out = Sweep(problem.name)
    settings = TOLERANCES if row.adaptive else [problem.t_end / n for n in STEP_COUNTS]
    run_row(row, problem, settings[0], t_end=0.01 if row.adaptive else 2 * settings[0])
    for setting in settings:
        runs = [run_row(row, problem, setting, samples=200) for _ in range(repeat)]
        run = min(runs, key=lambda sampled: math.inf if sampled is None else sampled.seconds)
        assert run is not None
        error = attitude_error(run.R_end, R_ref) if run.ok else math.inf
        E0 = abs(run.energy[0])
        with np.errstate(over="ignore", invalid="ignore"):
            energy = float(np.max(np.abs(run.energy - run.energy[0])) / E0)
        out.settings.append(float(setting))
        out.mean_step.append(problem.t_end / max(run.steps, 1) if row.adaptive else setting)
        out.steps.append(int(run.steps))
        out.seconds.append(float(run.seconds))
        out.error.append(error)
        out.energy_error.append(energy if math.isfinite(energy) else math.inf)
    return out


def fit_order(row: Row, data: Sweep, window: tuple[float, float]) -> Order | None:
    """The slope of log e against log h̄ through the errors inside ``window``; None when
    fewer than three are."""
    h = np.array(data.mean_step)
    e = np.array(data.error)
    inside = (e > window[0]) & (e < window[1]) & np.isfinite(e)
    finest = np.argsort(h)[np.isin(np.argsort(h), np.flatnonzero(inside))][:FIT_POINTS]
    inside = np.zeros_like(inside)
    inside[finest] = True
    if np.count_nonzero(inside) < 3 or np.unique(h[inside]).size < 3:
        return None
    slope = exact.observed_order(h[inside], e[inside])
    agrees = abs(slope - row.order) <= ORDER_TOLERANCE
    return Order(slope, float(h[inside].min()), float(h[inside].max()),
                 int(np.count_nonzero(inside)), data.problem,
                 "agrees" if agrees else "contradicts")  # fmt: skip


def fixed_step_end(row: Row, problem: Problem, h: float) -> np.ndarray:
    """R(T) of an adaptive row's formula stepped at a fixed ``h``, without its controller.

    A tumble method: its own stepper (:func:`tumble.rigid.simulation.stepper_for`, what
    ``simulate`` builds) handed to :func:`tumble.ode.driver.march` with no
    :class:`~tumble.ode.driver.Control`, so every step is taken at ``h``; scipy: ``solve_ivp``
    with ``first_step = max_step = h`` and tolerances too loose to reject a step.
    """
    if row.source == "scipy":
        from scipy.integrate import solve_ivp

        y0 = np.concatenate([problem.omega0, [1.0, 0.0, 0.0, 0.0]])
        with np.errstate(over="ignore", invalid="ignore"):
            solution = solve_ivp(_rhs(problem), (0.0, problem.t_end), y0,
                                 method=row.name.split()[-1], first_step=h, max_step=h,
                                 rtol=1e10, atol=1e10)  # fmt: skip
        return so3.matrix_from_quat(solution.y[3:, -1])
    from tumble.ode.driver import march
    from tumble.rigid import initial
    from tumble.rigid.forces import compiled_loads
    from tumble.rigid.simulation import stepper_for

    R, Y = initial.initial_state(problem.body, None, None, None, None, problem.omega0, None)
    loads = problem.forces()  # the compiled stepper where the loads allow, as simulate does
    kernel_loads = compiled_loads(loads, problem.body.mass)
    stepper = stepper_for(METHODS[row.name], problem.body, loads, kernel_loads)
    with np.errstate(over="ignore", invalid="ignore"):
        out = march(stepper, (0.0, problem.t_end), stepper.start((R, Y)), h=h,
                    record_every=2**62)  # fmt: skip
    return out.records[0][-1]


def fixed_step_sweep(row: Row, problem: Problem, R_ref: np.ndarray) -> Sweep:
    """An adaptive row's errors at the fixed steps of :data:`STEP_COUNTS` (no timing), up to
    the second error at round-off (finer steps add nothing to the fit)."""
    out = Sweep(problem.name)
    for n in STEP_COUNTS:
        h = problem.t_end / n
        out.settings.append(h)
        out.mean_step.append(h)
        out.steps.append(n)
        out.error.append(attitude_error(fixed_step_end(row, problem, h), R_ref))
        if sum(error <= ASYMPTOTIC[0] for error in out.error) >= 2:
            break
    return out


def measure_order(row: Row, free: Sweep, forced: Sweep | None) -> Order:
    """The order on P1, else on the forced body; an exact method at round-off on P1 is
    ``exact``; a row with no fit anywhere is ``no fit`` (a contradiction if it declares a
    finite order)."""
    found = fit_order(row, free, ASYMPTOTIC)
    if found is not None:
        return found
    at_round_off = all(e <= ASYMPTOTIC[0] for e in free.error)
    if at_round_off and math.isinf(row.order):
        return Order(math.inf, math.nan, math.nan, 0, free.problem, "exact")
    if forced is not None:
        found = fit_order(row, forced, (FORCED_FLOOR, ASYMPTOTIC[1]))
        if found is not None:
            return found
    return Order(math.nan, math.nan, math.nan, 0, free.problem, "contradicts")


# --- invariants over a long run ------------------------------------------------------------


@dataclass
class Invariants:
    """A long run's invariants: energy law (slope, largest relative change, verdict), the
    Casimir's largest relative change, orthogonality and quaternion-norm defects."""

    problem: str
    t_end: float
    energy_slope: float
    energy_max: float
    energy_law: str  # "round-off", "bounded", "drift", "grows", "failed"
    casimir_slope: float
    casimir_max: float
    casimir_law: str
    orthogonality_max: float
    quaternion_max: float
    steps: int


def growth_law(t: np.ndarray, energy: np.ndarray) -> tuple[float, float, str]:
    """``(slope, max |ΔE|/|E₀|, verdict)`` of a sampled invariant E (the energy, |L|).

    The running maximum m(t) = max_{τ≤t} |E(τ) − E₀| / |E₀| is fitted as m ∝ t^s over
    the last decade, t ∈ [T/10, T]: bounded below :data:`BOUNDED_SLOPE`, a drift up to
    1.3 (linear: s = 1), above it grows. Below :data:`ROUND_OFF` the
    error is round-off, whatever its slope (round-off random-walks, s ≈ ½).
    """
    with np.errstate(over="ignore", invalid="ignore"):
        error = np.abs(energy - energy[0]) / abs(energy[0])
    if not np.all(np.isfinite(error)):
        return math.nan, math.inf, "failed"
    running = np.maximum.accumulate(error)
    largest = float(running[-1])
    if largest <= ROUND_OFF:
        return math.nan, largest, "round-off"
    late = (t >= t[-1] / 10) & (running > 0)
    slope = float(np.polyfit(np.log(t[late]), np.log(running[late]), 1)[0])
    if slope < BOUNDED_SLOPE:
        verdict = "bounded"
    elif slope <= 1.3:
        verdict = "drift"
    else:
        verdict = "grows"
    return slope, largest, verdict


def invariants(row: Row, problem: Problem, t_end: float) -> Invariants | None:
    """Run ``row`` for ``t_end`` on ``problem`` at :data:`LONG_H` (:data:`LONG_RTOL`)."""
    run = run_row(row, problem, LONG_RTOL if row.adaptive else LONG_H, t_end=t_end,
                  samples=LONG_SAMPLES)  # fmt: skip
    if run is None:
        return None
    slope, largest, law = growth_law(run.t, run.energy)
    casimir_slope, casimir, casimir_law = growth_law(run.t, run.casimir)
    if not run.ok:  # stopped before T (non-finite, or MuJoCo's reset of an unstable body)
        law = casimir_law = "failed"
    return Invariants(problem.name, t_end, slope, largest, law, casimir_slope, casimir,
                      casimir_law, run.orthogonality, run.quaternion, run.steps)  # fmt: skip


# --- verdicts ---------------------------------------------------------------------------------


def contradictions(row: Row, order: Order, free: Invariants, forced: Invariants | None) -> list:
    """What ``row`` declares and its measurements contradict, one sentence each."""
    found = []
    if order.verdict == "contradicts":
        measured = "no fit" if math.isnan(order.measured) else f"{order.measured:.2f}"
        found.append(f"order: declared {row.order:g}, measured {measured} on {order.problem}")
    if "energy" in row.claims and free.energy_law != "round-off":
        found.append(
            f"energy-preserving: max |ΔE|/E₀ = {free.energy_max:.1e} over {free.t_end:g} s "
            f"on {free.problem} (round-off is ≤ {ROUND_OFF:g})"
        )
    if "symplectic" in row.claims:
        for inv in (free, forced):
            if inv is not None and inv.energy_law not in ("round-off", "bounded"):
                found.append(
                    f"symplectic: the energy error's law is {inv.energy_law} (slope "
                    f"{inv.energy_slope:.2f}) over {inv.t_end:g} s on {inv.problem}"
                )
    if "casimir" in row.claims and free.casimir_law != "round-off":
        found.append(f"Casimir |L|: max relative change {free.casimir_max:.1e} on {free.problem}")
    if "orthogonality" in row.claims and not free.orthogonality_max <= ROUND_OFF:
        found.append(f"stays on SO(3): max ‖RᵀR − I‖ = {free.orthogonality_max:.1e}")
    return found


# --- cost --------------------------------------------------------------------------------------


_FIRST_CALL = """
import json, sys, time
start = time.perf_counter()
from tumble.report_card import first_calls
print(json.dumps(first_calls(sys.argv[1:], start)))
"""


def first_calls(names: Sequence[str], started: float) -> dict[str, float]:
    """The first ``simulate`` call of each method in this process, s (two steps on P1);
    ``"import"``: the time since ``started`` to import tumble (used in a fresh process)."""
    body = RigidBody(1.0, P1_INERTIA, allow_unphysical=True)
    out = {"import": time.perf_counter() - started}
    for name in names:
        adaptive = METHODS[name].adaptive
        start = time.perf_counter()
        simulate(body, 2e-3, method=name, L0=P1_L0, h=None if adaptive else 1e-3,
                 rtol=1e-3 if adaptive else None)  # fmt: skip
        out[name] = time.perf_counter() - start
    return out


def first_call_times(names: Sequence[str], *, separate: bool) -> tuple[dict[str, float], str]:
    """Time each method's first call in a fresh Python process.

    ``separate``: one process per method with an empty numba cache (the compile time a new
    installation pays); otherwise one process for all, with the cache as it is (the methods
    of one family share a compiled kernel, so only the first of each pays). Returns the
    times and a sentence saying which.
    """
    if not names:
        return {}, ""
    if not separate:
        return _fresh_process(names, None), (
            "first call: one fresh process for all methods in turn, numba's cache as installed "
            "(a method sharing a family kernel with an earlier one pays nothing)"
        )
    times = {}
    for name in names:
        with tempfile.TemporaryDirectory(prefix="tumble-numba-") as cache:
            times.update(_fresh_process([name], cache))
    return times, "first call: a fresh process per method with an empty numba cache (compiles)"


def _fresh_process(names: Sequence[str], cache: str | None) -> dict[str, float]:
    env = dict(os.environ)
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = cache
    done = subprocess.run([sys.executable, "-c", _FIRST_CALL, *names], capture_output=True,
                          text=True, env=env, timeout=600, check=False)  # fmt: skip
    if done.returncode != 0:
        log.warning("timing the first calls failed: %s", done.stderr.strip()[-500:])
        return dict.fromkeys(names, math.nan)
    return json.loads(done.stdout.strip().splitlines()[-1])


def warm_cost(row: Row, problem: Problem, repeat: int) -> float:
    """µs per accepted step at the standard setting on ``problem``, best of ``repeat``."""
    setting = STANDARD_RTOL if row.adaptive else STANDARD_H
    run_row(row, problem, setting, t_end=0.1)  # warm
    best = math.inf
    for _ in range(repeat):
        run = run_row(row, problem, setting)
        assert run is not None
        best = min(best, run.seconds / max(run.steps, 1))
    return best * 1e6


# --- the structural schemes ---------------------------------------------------------------------


@dataclass
class StructuralRow:
    """One structural scheme: energy behaviour, order, critical step."""

    scheme: str
    energy_law: str
    energy_slope: float
    energy_max: float
    order_expected: float
    order_measured: float
    order_fit: str
    critical_dt: float


def structural_rows(quick: bool) -> tuple[list[StructuralRow], dict]:
    """Every scheme of :data:`tumble.structural.SCHEMES` on a small cantilever.

    The beam: 1 m steel, 4 elements, 1 cm square, a 1 N tip load from rest. Energy: a run of
    :math:`200` (quick: 50) fundamental periods at h = ½ Δt_crit of the semi-implicit
    scheme, the energy error ``E − E₀`` relative to :func:`~tumble.structural.energy_scale`
    with :func:`growth_law`'s verdict. Order: the tip displacement at T = a quarter period
    against :func:`tumble.structural.exact_response` (modal superposition), steps halving
    from ¼ Δt_crit, compared with the order the scheme declares (its ``order``).
    """
    from tumble import structural

    beam = structural.cantilever(1.0, 4, E=210e9, rho=7850, width=0.01, height=0.01,
                                 tip_load=1.0)  # fmt: skip
    omega1 = float(beam.natural_frequencies(1)[0]) * 2 * math.pi
    period = 2 * math.pi / omega1
    dt_semi = structural.critical_dt(beam, "semi-implicit").dt
    n = beam.n_dofs
    T = period / 4
    tip_exact = float(structural.exact_response(beam, [T]).tip_displacement[0])
    scale = structural.energy_scale(beam)
    periods = 50 if quick else 200
    out = []
    for name, scheme in structural.SCHEMES.items():
        dt = 0.5 * dt_semi
        steps = round(periods * period / dt)
        response = structural.integrate(beam, name, dt, n_steps=steps,
                                        record_every=max(1, steps // LONG_SAMPLES))  # fmt: skip
        t, E = response.t, response.energy
        with np.errstate(over="ignore", invalid="ignore"):
            law_energy = (E - E[0]) / scale + 1.0  # relative to the scale, about 1
        slope, largest, law = growth_law(t[1:], law_energy[1:]) if response.success else (
            math.nan, math.inf, "grows")  # fmt: skip
        if response.success and np.mean(E[len(E) // 2 :] - E[0]) < -0.05 * scale:
            law = "dissipates"
        if not response.success or largest > 10:
            law = "grows"
        errors, dts = [], []
        for k in range(5):
            dt_k = T / math.ceil(T / (0.25 * dt_semi)) / 2**k
            run = structural.integrate(beam, name, dt_k, n_steps=round(T / dt_k),
                                       record_every=10**9)  # fmt: skip
            errors.append(abs(float(run.tip_displacement[-1]) - tip_exact) / abs(tip_exact))
            dts.append(dt_k)
        e, d = np.array(errors), np.array(dts)
        good = np.isfinite(e) & (e > 1e-12) & (e < 0.5)
        critical = structural.critical_dt(beam, scheme).dt
        if critical == 0:  # unstable at every Δt: the growth, not the truncation, sets e
            good[:] = False
        measured = exact.observed_order(d[good], e[good]) if good.sum() >= 2 else math.nan
        expected = float(scheme.order)
        fit = f"Δt = {d[good].min():.2g} … {d[good].max():.2g} s" if good.sum() >= 2 else "—"
        out.append(StructuralRow(name, law, slope, largest, expected, measured, fit, critical))
    setup = {"omega1": omega1, "period": period, "dt_crit_semi_implicit": dt_semi,
             "periods": periods, "T_order": T, "n_dofs": n}  # fmt: skip
    return out, setup


# --- the card --------------------------------------------------------------------------------


@dataclass
class RowResult:
    """Everything measured for one row."""

    row: Row
    order: Order
    sweeps: dict[str, Sweep]
    errors: dict[str, float]  # problem -> error at T at the standard setting
    free: Invariants
    forced: Invariants | None
    cost_us: float
    first_call_s: float
    contradictions: list[str]


@dataclass
class ReportCard:
    """The report: the rows, the structural table, the machine, and the flagged methods."""

    results: list[RowResult]
    structural: list[StructuralRow]
    structural_setup: dict
    machine: dict
    quick: bool
    long_t: float
    seconds: float
    first_call_note: str
    problems: list[str]

    @property
    def contradictions(self) -> dict[str, list[str]]:
        """Each flagged row's contradictions, by name."""
        return {r.row.name: r.contradictions for r in self.results if r.contradictions}


def machine() -> dict:
    """Where the report ran: CPU, cores, Python, numpy, numba, tumble, date."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    import numba
    import scipy

    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "system": f"{platform.system()} {platform.release()}",
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "numba": numba.__version__,
        "tumble": __version__,
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
    }


def report(
    out: str | os.PathLike[str] | None = None,
    *,
    quick: bool = False,
    methods: Sequence[str] | None = None,
    peers: bool = True,
    structural: bool = True,
    progress: bool = False,
) -> ReportCard:
    """Measure every rigid-body method (and the peers) and, with ``out``, write the report.

    Parameters
    ----------
    out : path, optional
        A folder (created if needed) for ``report.md``, ``report.html`` and ``report.nc``;
        None writes nothing.
    quick : bool
        Long runs of 1000 s instead of 10⁴ s, one timed run (after a warm-up) instead of
        the best of three, the first calls timed in one process (under a minute on a
        2-core machine; the full report takes about six).
    methods : sequence of str, optional
        Names from :data:`tumble.rigid.METHODS` (default: all of them).
    peers : bool
        Add scipy's DOP853 and RK45, and MuJoCo's RK4 and Euler when it is installed.
    structural : bool
        Add the structural schemes' table.
    progress : bool
        Show a progress bar (rich).

    Returns
    -------
    ReportCard
        ``contradictions`` lists each method whose measurements contradict its declaration.

    Examples
    --------
    >>> card = report(quick=True, methods=["rkmk4"], peers=False, structural=False)
    >>> result = card.results[0]
    >>> result.order.verdict, round(result.order.measured), card.contradictions
    ('agrees', 4, {})
    """
    started = time.perf_counter()
    quick = _checks.flag("quick", quick)
    chosen = rows(methods, peers=peers)
    long_t = 1000.0 if quick else 10000.0
    repeat = 1 if quick else 3
    tests = problems()
    references = {problem.name: reference(problem) for problem in tests}
    tumble_names = [row.name for row in chosen if row.source == "tumble"]
    results = []
    timings = [tumble_names] if quick else [[name] for name in tumble_names]
    with progress_bar(progress, len(timings) + len(chosen) + 1, "report card") as update:
        first, note = {}, ""
        for names in timings:
            times, note = first_call_times(names, separate=not quick)
            first.update(times)
            update(advance=1)
        for row in chosen:
            update(description=f"report card: {row.name}")
            results.append(_measure(row, tests, references, long_t, repeat, first))
            update(advance=1)
        update(description="report card: structural schemes")
        structural_table, setup = structural_rows(quick) if structural else ([], {})
        update(advance=1)
    card = ReportCard(results, structural_table, setup, machine(), quick, long_t,
                      time.perf_counter() - started, note,
                      [problem.name for problem in tests])  # fmt: skip
    if out is not None:
        write(card, out)
    return card


def _measure(row: Row, tests: list[Problem], references: dict, long_t: float, repeat: int,
             first: dict) -> RowResult:  # fmt: skip
    log.info("report card: measuring %s", row.name)
    p1, forced = tests[0], tests[-1]
    sweeps = {}
    free_sweep = sweep(row, p1, references[p1.name], repeat)
    assert free_sweep is not None
    sweeps[p1.name] = free_sweep
    forced_sweep = sweep(row, forced, references[forced.name], repeat)
    if forced_sweep is not None:
        sweeps[forced.name] = forced_sweep
    if row.adaptive:  # the order of the formula it propagates, at fixed steps
        fixed = fixed_step_sweep(row, p1, references[p1.name])
        order = measure_order(row, fixed, None)
        adaptive = fit_order(row, free_sweep, ASYMPTOTIC)
        order.against_mean_step = math.nan if adaptive is None else adaptive.measured
    else:
        order = measure_order(row, free_sweep, forced_sweep)
    errors = {}
    for problem in tests:
        run = run_row(row, problem, STANDARD_RTOL if row.adaptive else STANDARD_H)
        errors[problem.name] = (
            math.nan if run is None else
            attitude_error(run.R_end, references[problem.name]) if run.ok else math.inf
        )  # fmt: skip
    free_inv = invariants(row, p1, long_t)
    assert free_inv is not None
    forced_inv = invariants(row, forced, long_t)
    cost = warm_cost(row, p1, repeat)
    found = contradictions(row, order, free_inv, forced_inv)
    return RowResult(row, order, sweeps, errors, free_inv, forced_inv, cost,
                     float(first.get(row.name, math.nan)), found)  # fmt: skip


# --- writing ---------------------------------------------------------------------------------


def write(card: ReportCard, out: str | os.PathLike[str]) -> Path:
    """Write ``report.md``, ``report.html`` and ``report.nc`` into ``out``, each atomically."""
    from tumble.io import write_dataset
    from tumble.viz.report_card import write_html

    folder = Path(out)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise _checks.fail("out", str(out), "a folder that can be created",
                           remedy=str(error.strerror or error)) from None  # fmt: skip
    text = markdown(card)
    atomic_write(folder / "report.md", lambda tmp: tmp.write_text(text, encoding="utf-8"))
    write_html(folder / "report.html", plot_data(card), title=_title(card))
    write_dataset(folder / "report.nc", datasets(card), {"title": _title(card), **card.machine})
    return folder


def _title(card: ReportCard) -> str:
    return f"tumble report card{' (quick)' if card.quick else ''}"


def plot_data(card: ReportCard) -> list[dict]:
    """One dict per row for the HTML page: name, setting name, flagged, and per problem the
    work (s), orientation error, energy error and settings."""
    out = []
    for result in card.results:
        out.append(
            {
                "name": result.row.name,
                "setting": "rtol" if result.row.adaptive else "h",
                "flagged": bool(result.contradictions),
                "why": result.contradictions,
                "sweeps": {
                    name: {
                        "seconds": data.seconds,
                        "error": data.error,
                        "energy": data.energy_error,
                        "settings": data.settings,
                        "steps": data.steps,
                    }
                    for name, data in result.sweeps.items()
                },
            }
        )
    return out


def datasets(card: ReportCard) -> dict:
    """The raw numbers as xarray Datasets: ``methods`` (per row), ``errors`` (row × problem),
    ``sweeps`` (row × problem × setting index), ``structural`` (per scheme)."""
    import xarray as xr

    names = [r.row.name for r in card.results]

    def column(get) -> np.ndarray:
        return np.array([get(r) for r in card.results], dtype=float)

    per_row = xr.Dataset(
        {
            "order_declared": ("method", column(lambda r: r.row.order)),
            "order_measured": ("method", column(lambda r: r.order.measured)),
            "order_h_min": ("method", column(lambda r: r.order.h_min), {"units": "s"}),
            "order_h_max": ("method", column(lambda r: r.order.h_max), {"units": "s"}),
            "order_verdict": ("method", [r.order.verdict for r in card.results]),
            "order_problem": ("method", [r.order.problem for r in card.results]),
            "order_against_mean_step": ("method", column(lambda r: r.order.against_mean_step)),
            "energy_slope": ("method", column(lambda r: r.free.energy_slope)),
            "energy_max": ("method", column(lambda r: r.free.energy_max)),
            "energy_law": ("method", [r.free.energy_law for r in card.results]),
            "forced_energy_slope": (
                "method", column(lambda r: r.forced.energy_slope if r.forced else math.nan)),
            "forced_energy_law": (
                "method", [r.forced.energy_law if r.forced else "" for r in card.results]),
            "casimir_max": ("method", column(lambda r: r.free.casimir_max)),
            "casimir_slope": ("method", column(lambda r: r.free.casimir_slope)),
            "casimir_law": ("method", [r.free.casimir_law for r in card.results]),
            "orthogonality_max": ("method", column(lambda r: r.free.orthogonality_max)),
            "quaternion_max": ("method", column(lambda r: r.free.quaternion_max)),
            "cost_us_per_step": ("method", column(lambda r: r.cost_us), {"units": "µs"}),
            "first_call_s": ("method", column(lambda r: r.first_call_s), {"units": "s"}),
            "contradictions": ("method", ["; ".join(r.contradictions) for r in card.results]),
            "claims": ("method", [", ".join(sorted(r.row.claims)) for r in card.results]),
        },
        coords={"method": names},
        attrs={"long_run_s": card.long_t, "first_call": card.first_call_note},
    )  # fmt: skip
    errors = xr.Dataset(
        {"error": (("method", "problem"),
                   np.array([[r.errors[p] for p in card.problems] for r in card.results]),
                   {"long_name": "‖R(T) − R_ref(T)‖_F at h = 0.01 s or rtol = 1e-8"})},
        coords={"method": names, "problem": card.problems},
    )  # fmt: skip
    groups = {"methods": per_row, "errors": errors}
    width = max(len(STEP_COUNTS), len(TOLERANCES))
    for problem in ("P1", "forced"):
        shape = (len(names), width)
        fields = {key: np.full(shape, np.nan) for key in
                  ("setting", "steps", "seconds", "error", "energy_error")}  # fmt: skip
        for i, r in enumerate(card.results):
            data = r.sweeps.get(problem)
            if data is None:
                continue
            k = len(data.settings)
            fields["setting"][i, :k] = data.settings
            fields["steps"][i, :k] = data.steps
            fields["seconds"][i, :k] = data.seconds
            fields["error"][i, :k] = data.error
            fields["energy_error"][i, :k] = data.energy_error
        groups[f"sweep_{problem}"] = xr.Dataset(
            {key: (("method", "run"), value) for key, value in fields.items()},
            coords={"method": names},
        )
    if card.structural:
        s = card.structural
        groups["structural"] = xr.Dataset(
            {
                "energy_law": ("scheme", [x.energy_law for x in s]),
                "energy_slope": ("scheme", [x.energy_slope for x in s]),
                "energy_max": ("scheme", [x.energy_max for x in s]),
                "order_expected": ("scheme", [x.order_expected for x in s]),
                "order_measured": ("scheme", [x.order_measured for x in s]),
                "critical_dt": ("scheme", [x.critical_dt for x in s], {"units": "s"}),
            },
            coords={"scheme": [x.scheme for x in s]},
            attrs={key: value for key, value in card.structural_setup.items()},
        )
    return groups


def _number(value: float, digits: int = 2) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    if math.isinf(value):
        return "∞" if value > 0 else "−∞"
    if abs(value) >= 100:
        return f"{value:.0f}"
    return f"{value:.{digits}g}" if abs(value) >= 1e-3 or value == 0 else f"{value:.1e}"


def _law(law: str, slope: float) -> str:
    """``drift (0.99)``: a law with its slope; round-off and failed runs have none."""
    return law if law in ("round-off", "failed") else f"{law} ({_number(slope)})"


def _sci(value: float) -> str:
    if value is None or math.isnan(value):
        return "—"
    if math.isinf(value):
        return "∞"
    return f"{value:.1e}"


def markdown(card: ReportCard) -> str:
    """The report as markdown: the contradictions first, then the tables."""
    m = card.machine
    lines = [
        f"# {_title(card)}",
        "",
        "Generated by `tumble report` (`make report`); every number below is measured, every "
        "verdict computed against what the method declares in `tumble.rigid.METHODS`.",
        "",
        f"Machine: {m['cpu']}, {m['cores']} cores, {m['system']}; Python {m['python']}, "
        f"numpy {m['numpy']}, scipy {m['scipy']}, numba {m['numba']}, tumble {m['tumble']}; "
        f"{m['date']}; the report took {card.seconds:.0f} s. Other work shared the machine, "
        "so the times are indicative.",
        "",
        "## Contradictions",
        "",
    ]
    flagged = card.contradictions
    if not flagged:
        lines.append("None: every method's measured order and invariants agree with what it "
                     "declares.")  # fmt: skip
    for name, why in flagged.items():
        for sentence in why:
            lines.append(f"- **{name}** — {sentence}")
    lines += [
        "",
        "## Order",
        "",
        f"Slope of log ‖R(T) − R_ref(T)‖_F against log h (T = {SWEEP_T:g} s), fitted through "
        f"the {FIT_POINTS} finest runs with errors in ({ASYMPTOTIC[0]:g}, {ASYMPTOTIC[1]:g}) on "
        "P1, or on the forced body when P1 is at round-off; it agrees when within "
        f"±{ORDER_TOLERANCE} of the declared order. Adaptive methods: the formula they "
        "propagate at fixed steps (the order they declare); the last column is the slope of "
        "their tolerance sweep against the mean step h̄ = T/steps, which the step controller "
        "bends away from it.",
        "",
        "| method | family | declared | measured | fit range h (s) | runs | problem | verdict "
        "| adaptive: vs h̄ |",
        "| --- | --- | ---: | ---: | --- | ---: | --- | --- | ---: |",
    ]
    for r in card.results:
        o = r.order
        fit = "—" if math.isnan(o.h_min) else f"{o.h_min:.2g} … {o.h_max:.2g}"
        verdict = "**contradicts**" if o.verdict == "contradicts" else o.verdict
        lines.append(
            f"| {r.row.name} | {r.row.family} | {_number(r.row.order)} | "
            f"{'round-off' if o.verdict == 'exact' else _number(o.measured, 3)} | {fit} | "
            f"{o.points} | {o.problem} | {verdict} | {_number(o.against_mean_step, 3)} |"
        )
    problems_header = " | ".join(card.problems)
    lines += [
        "",
        "## Orientation error at T",
        "",
        f"‖R(T) − R_ref(T)‖_F at h = {STANDARD_H:g} s (adaptive: rtol = "
        f"{STANDARD_RTOL:g}). P1 and forced: T = {SWEEP_T:g} s; the T-handle: T = "
        f"{PROBLEM_T:g} s. Reference: the exact solution, or for the forced body (magnetic "
        "dipole) scipy DOP853 at rtol = atol = 1e-13. — : the method takes no loads.",
        "",
        f"| method | {problems_header} |",
        "| --- |" + " ---: |" * len(card.problems),
    ]
    for r in card.results:
        cells = " | ".join(_sci(r.errors[p]) for p in card.problems)
        lines.append(f"| {r.row.name} | {cells} |")
    lines += [
        "",
        "## Invariants over a long run",
        "",
        f"T = {card.long_t:g} s at h = {LONG_H:g} s (adaptive: rtol = {LONG_RTOL:g}). "
        "Law of an invariant E (the energy; the Casimir ‖RᵀL‖, the body momentum's norm): "
        "the slope s of log max_{τ≤t} ΔE(τ) against log t over [T/10, T], ΔE = "
        f"abs(E − E₀)/abs(E₀): round-off (max ΔE ≤ {ROUND_OFF:g}), bounded "
        f"(s < {BOUNDED_SLOPE}), drift (s ≈ 1), grows (s > 1.3); failed: the run stopped. "
        "Claims: S symplectic (energy bounded, also with the dipole's conservative torque), "
        "E energy, C Casimir, O stays on SO(3); a claim the measurement contradicts is in "
        "bold. The forced body's ‖RᵀL‖ changes by the torque: not an invariant there. "
        "Δ‖q‖: how far a carried quaternion leaves the unit sphere in a step (— : none "
        "carried; the peers' q is never renormalised, MuJoCo renormalises it).",
        "",
        "| method | claims | P1 energy: law (s) | max ΔE | forced energy: law (s) | "
        "P1 ‖RᵀL‖: law (s) | max Δ‖RᵀL‖ | max ‖RᵀR − I‖ | max Δ‖q‖ |",
        "| --- | --- | --- | ---: | --- | --- | ---: | ---: | ---: |",
    ]
    letters = {"symplectic": "S", "energy": "E", "casimir": "C", "orthogonality": "O"}
    for r in card.results:
        claims = "".join(
            f"**{letters[c]}**" if any(c_word(c) in s for s in r.contradictions) else letters[c]
            for c in CLAIMS
            if c in r.row.claims
        )
        forced = "—" if r.forced is None else _law(r.forced.energy_law, r.forced.energy_slope)
        lines.append(
            f"| {r.row.name} | {claims or '—'} | "
            f"{_law(r.free.energy_law, r.free.energy_slope)} | {_sci(r.free.energy_max)} | "
            f"{forced} | {_law(r.free.casimir_law, r.free.casimir_slope)} | "
            f"{_sci(r.free.casimir_max)} | {_sci(r.free.orthogonality_max)} | "
            f"{_sci(r.free.quaternion_max)} |"
        )
    lines += [
        "",
        "## Cost",
        "",
        f"Warm µs per accepted step on P1 (h = {STANDARD_H:g} s, adaptive rtol = "
        f"{STANDARD_RTOL:g}; best of {1 if card.quick else 3}); {card.first_call_note}. "
        "tumble's methods run compiled wherever their loads allow (as `simulate` chooses), "
        "scipy in Python, MuJoCo in C called step by step from Python. An adaptive method's "
        "cost per step includes `simulate`'s per-call work spread over few steps.",
        "",
        "| method | µs/step | first call (s) |",
        "| --- | ---: | ---: |",
    ]
    for r in card.results:
        lines.append(f"| {r.row.name} | {_number(r.cost_us, 3)} | {_number(r.first_call_s)} |")
    if card.structural:
        s = card.structural_setup
        lines += [
            "",
            "## Structural schemes",
            "",
            f"A 4-element steel cantilever ({s['n_dofs']} DOFs, ω₁ = {s['omega1']:.4g} rad/s) "
            "under a 1 N tip load from rest. Energy over "
            f"{s['periods']} periods at h = ½ Δt_crit(semi-implicit) = "
            f"{s['dt_crit_semi_implicit'] / 2:.3g} s, relative to the energy exchanged; order: "
            f"the tip displacement at T = {s['T_order']:.3g} s against the exact response "
            "(modal superposition, `tumble.structural.exact_response`); the scheme declares "
            "its order.",
            "",
            "| scheme | energy | max ΔE / scale | order declared | measured | fit range | "
            "critical Δt (s) |",
            "| --- | --- | ---: | ---: | ---: | --- | ---: |",
        ]
        for x in card.structural:
            lines.append(
                f"| {x.scheme} | {x.energy_law} | {_sci(x.energy_max)} | "
                f"{_number(x.order_expected)} | {_number(x.order_measured, 3)} | {x.order_fit} "
                f"| {_critical(x.critical_dt)} |"
            )
    lines += [
        "",
        "The interactive work–precision diagrams (orientation and energy error against wall "
        "time, the Pareto front marked) are in `report.html`, the raw numbers in `report.nc`, "
        "both written beside `report.md` by `tumble report` (`make report` keeps them in "
        "`runs/report/` and copies this page to `docs/report.md`).",
        "",
    ]
    return "\n".join(lines)


def c_word(claim: str) -> str:
    """The word a contradiction sentence of ``claim`` starts with."""
    return {"symplectic": "symplectic", "energy": "energy-preserving", "casimir": "Casimir",
            "orthogonality": "SO(3)"}[claim]  # fmt: skip


def _critical(dt: float) -> str:
    if dt == 0:
        return "0 (never stable)"
    if math.isinf(dt):
        return "∞ (unconditional)"
    return f"{dt:.3g}"
