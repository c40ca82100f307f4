"""The report card's rows: tumble's methods and the peers, and one run of a row.

A row is a tumble method of :data:`tumble.rigid.METHODS` (what it declares, read from its
:class:`~tumble.rigid.Method`) or a peer: scipy's ``DOP853`` and ``RK45`` on Euler's equations
with a quaternion, MuJoCo's ``RK4`` and ``Euler`` and heyoka's Taylor integrator (Euler's
equations with a quaternion, compiled by LLVM) when the ``bench`` extra is installed.
:func:`run_row` runs any of them on a problem and returns what it left (:class:`Sampled`).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from tumble import _checks, so3
from tumble.report_card.problems import CardProblem, rhs, y0
from tumble.rigid import METHODS, simulate
from tumble.rigid.methods import Method

log = logging.getLogger(__name__)


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
    source: str  # "tumble", "scipy", "MuJoCo", "heyoka"
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


MUJOCO_ROWS = ("MuJoCo RK4", "MuJoCo Euler")
"""The peer rows MuJoCo gives when it is installed."""


def heyoka_available() -> bool:
    """Whether heyoka (the ``bench`` extra) can be imported."""
    try:
        import heyoka  # noqa: F401
    except ImportError:
        return False
    return True


HEYOKA_ROW = "heyoka"
"""The peer row heyoka gives when it is installed."""
HEYOKA_FIXED_TOL = 1e-4
"""heyoka's tolerance where the card measures its order (at fixed steps,
:func:`fixed_step_end`), where its Taylor order is
:func:`taylor_order` (6); its own steps there are longer than the card's finer fixed ones."""


def taylor_order(tol: float) -> int:
    """The order heyoka gives its Taylor method at tolerance ``tol``: ``⌈−ln(tol)/2 + 1⌉``
    (Jorba–Zou's choice, which heyoka's ``taylor_adaptive.order`` reports)."""
    return math.ceil(-math.log(tol) / 2.0 + 1.0)


def skipped_peers(peers: bool = True) -> dict[str, str]:
    """The peer rows :func:`rows` leaves out, each with why (MuJoCo or heyoka not installed)."""
    if not peers:
        return {}
    skipped: dict[str, str] = {}
    if not mujoco_available():
        why = (
            "not installed: rows skipped (MuJoCo is in the bench extra: pip install -e '.[bench]')"
        )
        skipped |= dict.fromkeys(MUJOCO_ROWS, why)
    if not heyoka_available():
        skipped[HEYOKA_ROW] = ("not installed: row skipped (heyoka is in the bench extra: "
                               "pip install -e '.[bench]')")  # fmt: skip
    return skipped


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
        if heyoka_available():
            found.append(Row(HEYOKA_ROW, "heyoka", float(taylor_order(HEYOKA_FIXED_TOL)), True,
                             frozenset(), "quat, Taylor (LLVM)"))  # fmt: skip
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


def _tumble_run(row: Row, problem: CardProblem, setting: float, t_end: float, samples: int):
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


def _peer_energy(problem: CardProblem, omega: np.ndarray, R: np.ndarray) -> np.ndarray:
    inertia = problem.body.inertia.diagonal()
    kinetic = 0.5 * np.einsum("ni,ni->n", omega, omega * inertia)
    if problem.dipole is None:
        return kinetic
    return kinetic - np.einsum("nij,j,i->n", R, problem.dipole.moment, problem.dipole.field)


def _scipy_run(method: str, problem: CardProblem, rtol: float, t_end: float) -> Sampled:
    """solve_ivp on :func:`~tumble.report_card.problems.rhs`; its samples are its accepted
    steps."""
    from scipy.integrate import solve_ivp

    start = time.perf_counter()
    solution = solve_ivp(rhs(problem), (0.0, t_end), y0(problem), method=method, rtol=rtol,
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


_HEYOKA_INTEGRATORS: dict = {}
"""heyoka's integrators by (problem, tol): each is compiled by LLVM once (0.1–0.5 s), outside
the timed runs, as a user keeps one."""


def _heyoka_integrator(problem: CardProblem, tol: float):
    """``taylor_adaptive`` for Euler's equations and the quaternion of :func:`rhs` (the
    dipole's body torque ``μ × Rᵀ B``), built once per problem and tolerance."""
    key = (problem.name, tol)
    if key in _HEYOKA_INTEGRATORS:
        return _HEYOKA_INTEGRATORS[key]
    import heyoka as hy

    w1, w2, w3, q0, q1, q2, q3 = hy.make_vars("w1", "w2", "w3", "q0", "q1", "q2", "q3")
    A, B, C = problem.body.inertia.diagonal()
    torque = [0.0, 0.0, 0.0]
    if problem.dipole is not None:
        mu, field = problem.dipole.moment, problem.dipole.field
        R = [
            [1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
            [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
            [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)],
        ]
        b = [sum(R[i][j] * float(field[i]) for i in range(3) if field[i] != 0.0)
             for j in range(3)]  # Rᵀ B  # fmt: skip
        m = [float(v) for v in mu]
        torque = [m[1] * b[2] - m[2] * b[1], m[2] * b[0] - m[0] * b[2], m[0] * b[1] - m[1] * b[0]]
    system = [
        (w1, ((B - C) * w2 * w3 + torque[0]) / A),
        (w2, ((C - A) * w3 * w1 + torque[1]) / B),
        (w3, ((A - B) * w1 * w2 + torque[2]) / C),
        (q0, 0.5 * (-q1 * w1 - q2 * w2 - q3 * w3)),
        (q1, 0.5 * (q0 * w1 + q2 * w3 - q3 * w2)),
        (q2, 0.5 * (q0 * w2 + q3 * w1 - q1 * w3)),
        (q3, 0.5 * (q0 * w3 + q1 * w2 - q2 * w1)),
    ]
    ta = hy.taylor_adaptive(system, y0(problem), tol=tol)
    _HEYOKA_INTEGRATORS[key] = ta
    return ta


def _heyoka_run(problem: CardProblem, tol: float, t_end: float, samples: int) -> Sampled:
    """heyoka's ``taylor_adaptive`` at ``tol`` (its one tolerance, absolute and relative);
    samples by ``propagate_grid``, the ends alone by ``propagate_until``."""
    import heyoka as hy

    ta = _heyoka_integrator(problem, tol)
    ta.time = 0.0
    ta.state[:] = y0(problem)
    start = time.perf_counter()
    if samples:
        t = np.linspace(0.0, t_end, samples + 1)
        outcome, _, _, steps, *_, states = ta.propagate_grid(t)
    else:
        outcome, _, _, steps, *_ = ta.propagate_until(t_end)
        t, states = np.array([0.0, t_end]), np.array([y0(problem), ta.state.copy()])
    seconds = time.perf_counter() - start
    ok = outcome == hy.taylor_outcome.time_limit and bool(np.all(np.isfinite(states)))
    q, omega = states[:, 3:], states[:, :3]
    R = so3.matrix_from_quat(q)  # normalised, as scipy's rows are read
    casimir = np.linalg.norm(omega * problem.body.inertia.diagonal(), axis=1)
    return Sampled(t, R[-1], _peer_energy(problem, omega, R), casimir, 0.0,
                   float(np.max(np.abs(np.linalg.norm(q, axis=1) - 1.0))), int(steps), seconds,
                   ok)  # fmt: skip


def _heyoka_fixed_end(problem: CardProblem, h: float) -> np.ndarray:
    """R(T) of heyoka's Taylor method of order :func:`taylor_order` (at
    :data:`HEYOKA_FIXED_TOL`) stepped at ``h``: each ``step(max_delta_t)`` takes the smaller of
    ``h`` and its own step (larger than the card's finer steps)."""
    ta = _heyoka_integrator(problem, HEYOKA_FIXED_TOL)
    ta.time = 0.0
    ta.state[:] = y0(problem)
    n = max(1, round(problem.t_end / h))
    for k in range(1, n + 1):
        ta.step(max_delta_t=k * problem.t_end / n - ta.time)
    return so3.matrix_from_quat(ta.state[3:])


def _mujoco_model(problem: CardProblem, integrator: str, h: float):
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


def _mujoco_run(integrator: str, problem: CardProblem, h: float, t_end: float,
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


def run_row(row: Row, problem: CardProblem, setting: float, *, t_end: float | None = None,
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
        if row.source == "heyoka":
            return _heyoka_run(problem, setting, t_end, samples)
        return _mujoco_run(row.name.split()[-1], problem, setting, t_end, samples)


def fixed_step_end(row: Row, problem: CardProblem, h: float) -> np.ndarray:
    """R(T) of an adaptive row's formula stepped at a fixed ``h``, without its controller.

    A tumble method: its own stepper (what ``simulate`` builds, :func:`_fixed_step_stepper`)
    handed to :func:`tumble.ode.march` with no :class:`~tumble.ode.driver.Control`, so every
    step is taken at ``h``; scipy: ``solve_ivp`` with ``first_step = max_step = h`` and
    tolerances too loose to reject a step; heyoka: :func:`_heyoka_fixed_end`.
    """
    if row.source == "heyoka":
        return _heyoka_fixed_end(problem, h)
    if row.source == "scipy":
        from scipy.integrate import solve_ivp

        with np.errstate(over="ignore", invalid="ignore"):
            solution = solve_ivp(rhs(problem), (0.0, problem.t_end), y0(problem),
                                 method=row.name.split()[-1], first_step=h, max_step=h,
                                 rtol=1e10, atol=1e10)  # fmt: skip
        return so3.matrix_from_quat(solution.y[3:, -1])
    from tumble.ode import march

    stepper, state = _fixed_step_stepper(row, problem)
    with np.errstate(over="ignore", invalid="ignore"):
        out = march(stepper, (0.0, problem.t_end), state, h=h, record_every=2**62)
    return out.records[0][-1]


def _fixed_step_stepper(row: Row, problem: CardProblem):
    """The stepper ``simulate`` builds for ``row`` on ``problem`` (compiled where the loads
    allow), and its start.

    The one place the report card reaches into :mod:`tumble.rigid`'s internals:
    ``simulate`` has no public way to step an adaptive method's formula at a fixed ``h``.
    """
    from tumble.rigid import initial
    from tumble.rigid.forces import compiled_loads
    from tumble.rigid.simulation import stepper_for

    R, Y = initial.initial_state(problem.body, None, None, None, None, problem.omega0, None)
    loads = problem.forces()
    kernel_loads = compiled_loads(loads, problem.body.mass)
    stepper = stepper_for(METHODS[row.name], problem.body, loads, kernel_loads)
    return stepper, stepper.start((R, Y))
