"""Rigid bodies: tumble's compiled kernels against MuJoCo, scipy's solve_ivp and plain NumPy.

Run ``.venv/bin/python benchmarks/bench_rigid.py [--quick]``. Every peer runs in this process,
so the ratios compare like with like on a machine that other work may share; times are the
median (min–max) of repeats. Problems (torque-free, exact solution
:func:`tumble.exact.free_body_rotation`, error = rotation angle between computed and exact
attitude at T):

* P1: I = diag(2, 1, 2/3) (Hairer–Lubich–Wanner; not physical), L0 = (cos 1.1, 0, sin 1.1),
  R0 = I, T = 100;
* the T-handle (:func:`tumble.mass.t_handle`), ω0 = (1, 0.05, 0) rad/s, T = 100 (it flips).

Sections: 1. µs per step at h = 0.01 against MuJoCo; 2. work–precision against ``solve_ivp``
(tumble's best of ``rkmk4`` and ``rkmk8``); 3. many bodies (``simulate_batch``); 4.
``simulate``'s per-call overhead and a plain NumPy RK4 loop; then the issue's targets, each
MET or NOT MET with the number, and for those not met what bounds them. ``--quick``: fewer
repeats, N ≤ 10⁴ (``main`` returns the markdown).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy loads OpenBLAS

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass  # noqa: E402

import numpy as np  # noqa: E402
from _timing import spread, table, timed, verdict  # noqa: E402
from numba import njit  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

from tumble import RigidBody, exact, mass, simulate, simulate_batch, so3  # noqa: E402
from tumble.rigid import METHODS  # noqa: E402

H = 0.01
T_END = 100.0
H_GRID = (0.2, 0.1, 0.05, 0.04, 0.025, 0.02, 0.0125, 0.01, 0.005, 0.0025)
H_GRID_ORDER8 = (1.0, 0.8, 0.625, 0.5, 0.4, 0.3125, 0.25, 0.2, 0.1, 0.05)
"""``rkmk8``'s steps: T/h = 100, 125, 160, …, a factor of 1.25 apart, coarser than DOP853's
rtol grid (a factor √10 in rtol is about 1.14 in its steps)."""
H_GRID_ORDER2 = tuple(0.02 / 2**k for k in range(13))  # 0.02 … 4.8828125e-6
"""The order-2 methods' steps, halving: they need h ≈ 1e-3 … 1e-4 for 1e-6 at T = 100 and
h ≈ 2e-5 … 5e-6 (5·10⁶ … 2·10⁷ steps, a second or two) for 1e-9. The grid stops there: below
h ≈ 1e-5 round-off over 10⁷ steps takes over (``split-axes``: 3.0e-10 at h = 9.8e-6, 1.3e-9
at 4.9e-6), so a finer h would not help."""
H_GRID_EXACT = (10.0, 5.0, 2.0, 1.0)
"""The methods on the exact flow: round-off at any h, so the coarsest step wins."""
WORK_PRECISION_METHODS = {
    "rkmk4": H_GRID,
    "rkmk8": H_GRID_ORDER8,
    "split-axes": H_GRID_ORDER2,
    "split-axes4": H_GRID,
    "midpoint-lp": H_GRID_ORDER2,
    "dmv": H_GRID_ORDER2,
    "exact": H_GRID_EXACT,
    "strang": H_GRID_EXACT,
    "yoshida4": H_GRID_EXACT,
}
"""Each method of the work–precision section and its steps, loosest first (without loads
``strang`` and ``yoshida4`` are the exact flow, at one and three flows a step)."""
RTOL_GRID = tuple(10.0 ** (-k / 2) for k in range(6, 27))  # 1e-3 … 1e-13
TARGET_ERRORS = (1e-6, 1e-9)
SEARCH_LIMIT_S = 20.0  # a peer that needs longer than this for one run is reported as such


@dataclass(frozen=True)
class Problem:
    name: str
    body: RigidBody
    omega0: np.ndarray  # body frame, rad/s; R0 = I

    @property
    def inertia(self) -> np.ndarray:
        return np.diag(self.body.inertia)

    def exact(self, t: float, R0=None) -> np.ndarray:
        return exact.free_body_rotation(self.inertia, self.omega0, t, R0)


def problems() -> list[Problem]:
    inertia = np.array([2.0, 1.0, 2.0 / 3.0])
    L0 = np.array([math.cos(1.1), 0.0, math.sin(1.1)])
    p1 = Problem("P1", RigidBody(1.0, inertia, allow_unphysical=True), L0 / inertia)
    handle = RigidBody.from_mass_properties(mass.t_handle())
    return [p1, Problem("T-handle", handle, np.array([1.0, 0.05, 0.0]))]


def angle_error(R: np.ndarray, R_exact: np.ndarray) -> float:
    """The rotation angle of ``Rᵀ R_exact`` (rad), with R first projected onto SO(3)."""
    U, _, Vt = np.linalg.svd(R)
    return float(np.linalg.norm(so3.log((U @ Vt).T @ R_exact)))


# --- 1. per step against MuJoCo -------------------------------------------------------------


def tumble_run(problem: Problem, method: str, h: float, t_end: float = T_END):
    return simulate(
        problem.body, t_end, method=method, h=h, omega0=problem.omega0, record_every=10**9
    )


def mujoco_model(problem: Problem, integrator: str, h: float):
    """One free-joint body, gravity off. MuJoCo's compiler refuses P1's inertia (it breaks the
    triangle inequality), so the model is built with a placeholder and the inertia set after,
    with ``mj_setConst`` recomputing what depends on it."""
    import mujoco

    xml = f"""<mujoco><option gravity="0 0 0" integrator="{integrator}" timestep="{h}"/>
      <worldbody><body><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
      </body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    model.body_mass[1], model.body_inertia[1] = problem.body.mass, problem.inertia
    mujoco.mj_setConst(model, mujoco.MjData(model))
    return model


def mujoco_data(model, omega0, R0=None):
    import mujoco

    data = mujoco.MjData(model)
    if R0 is not None:
        data.qpos[3:7] = so3.quat_from_matrix(R0)
    data.qvel[3:6] = omega0  # a free joint's angular velocity is in the body frame
    mujoco.mj_forward(model, data)
    return data


def mujoco_loop(model, omega0, n: int, R0=None):
    """``mj_step`` in a Python loop; returns the final data."""
    import mujoco

    data = mujoco_data(model, omega0, R0)
    for _ in range(n):
        mujoco.mj_step(model, data)
    return data


def mujoco_rollout(model, omega0, n: int):
    """``mujoco.rollout``: the n steps in C; returns the final data."""
    import mujoco
    from mujoco import rollout

    data, spec = mujoco_data(model, omega0), mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    states, _ = rollout.rollout(model, data, state[None], nstep=n)
    mujoco.mj_setState(model, data, states[0, -1], spec)
    return data


def mujoco_attitude(data) -> np.ndarray:
    return so3.matrix_from_quat(data.qpos[3:7])


def per_step_rows(problem: Problem, repeat: int, methods) -> tuple[list, dict]:
    """Rows of section 1 for one problem and the numbers the targets need."""
    n = round(T_END / H)
    R_exact = problem.exact(T_END)
    rows, numbers = [], {}
    for method in methods:
        med, lo, hi, run = timed(lambda m=method: tumble_run(problem, m, H), repeat)
        error = angle_error(run.R[-1], R_exact)
        numbers[method] = (med / n, lo / n, hi / n, error)
        rows.append(
            [f"tumble `{method}`", spread(med / n, lo / n, hi / n, 1e6, 3), f"{error:.1e}"]
        )
    try:
        import mujoco  # noqa: F401
    except ImportError as exc:
        rows.append(["MuJoCo", f"not available ({exc})", ""])
        return rows, numbers
    E0 = 0.5 * problem.omega0 @ (problem.inertia * problem.omega0)
    for integrator in ("RK4", "Euler", "implicitfast"):
        model = mujoco_model(problem, integrator, H)
        runners = {"rollout": mujoco_rollout, "mj_step loop": mujoco_loop}
        for how, runner in runners.items():
            r = repeat if integrator == "RK4" else max(1, repeat // 2)
            med, lo, hi, data = timed(lambda f=runner, m=model: f(m, problem.omega0, n), r)
            error = angle_error(mujoco_attitude(data), R_exact)
            omega = data.qvel[3:6]
            energy = abs(0.5 * omega @ (problem.inertia * omega) / E0 - 1)
            numbers[f"MuJoCo {integrator} {how}"] = (med / n, lo / n, hi / n, error)
            label = f"MuJoCo {integrator}, {how}"
            rows.append(
                [
                    label,
                    spread(med / n, lo / n, hi / n, 1e6, 3),
                    f"{error:.1e} (energy off {energy:.1e})",
                ]
            )
    return rows, numbers


def mujoco_frame_check(problem: Problem) -> str:
    """Evidence that MuJoCo's free-joint angular velocity is body-frame (R0 ≠ I)."""
    R0, t_end = so3.exp([0.3, -0.5, 0.8]), 10.0
    data = mujoco_loop(mujoco_model(problem, "RK4", 1e-3), problem.omega0, 10_000, R0)
    as_body = angle_error(mujoco_attitude(data), problem.exact(t_end, R0))
    world = exact.free_body_rotation(problem.inertia, R0.T @ problem.omega0, t_end, R0)
    as_world = angle_error(mujoco_attitude(data), world)
    return (
        f"MuJoCo's free joint takes its angular velocity in the body frame: started at R0 ≠ I "
        f"with qvel[3:6] = ω0, it matches the exact solution for body-frame ω0 to "
        f"{as_body:.1e} rad at T = 10 (h = 1e-3), and misses the world-frame reading by "
        f"{as_world:.2f} rad."
    )


# --- 2. work–precision against solve_ivp ------------------------------------------------------


def euler_quaternion_rhs(inertia):
    """Euler's equations and ``q̇ = ½ q ⊗ (0, ω)`` for ``y = (ω, q)``, as a user would write."""
    A, B, C = inertia

    def f(t, y):
        w1, w2, w3, q0, q1, q2, q3 = y
        return np.array(
            [
                (B - C) * w2 * w3 / A,
                (C - A) * w3 * w1 / B,
                (A - B) * w1 * w2 / C,
                0.5 * (-q1 * w1 - q2 * w2 - q3 * w3),
                0.5 * (q0 * w1 + q2 * w3 - q3 * w2),
                0.5 * (q0 * w2 + q3 * w1 - q1 * w3),
                0.5 * (q0 * w3 + q1 * w2 - q2 * w1),
            ]
        )

    return f


def scipy_run(problem: Problem, method: str, rtol: float):
    y0 = np.concatenate([problem.omega0, [1.0, 0.0, 0.0, 0.0]])
    fun = euler_quaternion_rhs(problem.inertia)
    return solve_ivp(fun, (0.0, T_END), y0, method=method, rtol=rtol, atol=rtol * 1e-3)


def scipy_error(problem: Problem, solution) -> float:
    q = solution.y[3:, -1]
    return angle_error(so3.matrix_from_quat(q / np.linalg.norm(q)), problem.exact(T_END))


def search(settings, run, error, target):
    """The first setting (loosest first) whose run meets ``target``: (setting, error)."""
    for setting in settings:
        start = time.perf_counter()
        result = run(setting)
        if error(result) <= target:
            return setting, error(result)
        if time.perf_counter() - start > SEARCH_LIMIT_S:
            break
    return None, math.nan


def kernel_run(problem: Problem, method: str, h: float) -> np.ndarray:
    """``method``'s steps alone: the ``lie``-family kernel called directly, without
    ``simulate``'s checks, initial state and trajectory (the floor of a ``simulate`` call);
    returns R(T)."""
    from tumble.ode.driver import Grid
    from tumble.rigid._compiled import base, charts
    from tumble.rigid.charts import LIE
    from tumble.rigid.methods import METHODS

    tableau = METHODS[method].tableau
    n, zero, none = round(T_END / h), np.zeros(3), np.zeros((0, 3))
    z, Rn = LIE.pack(np.eye(3), np.concatenate([zero, zero, problem.omega0 * problem.inertia]))
    data = base.KernelProblem(True, tableau.A, tableau.b, problem.body.inertia_inverse,
                           problem.body.mass, zero, zero, none, none, np.eye(3),
                           np.ones(3))  # fmt: skip
    record = base.Records(np.empty(1), np.empty((1, 3, 3)), np.empty((1, 4)), np.empty((1, 9)))
    charts.COMPILED["lie"].loop(data, Grid(0.0, T_END, h, n), (z, Rn), 0, n, 10**9, 0, record)
    return Rn


def tumble_work_precision(problem: Problem, target: float, repeat: int) -> dict:
    """Each of tumble's methods at the largest h of its grid that meets ``target``:
    ``{method: (h, error, (median, min, max) s)}``."""
    R_exact, found = problem.exact(T_END), {}
    for method, grid in WORK_PRECISION_METHODS.items():
        h, err = search(
            grid,
            lambda h, m=method: tumble_run(problem, m, h),
            lambda run: angle_error(run.R[-1], R_exact),
            target,
        )
        if h is not None:
            found[method] = (
                h,
                err,
                timed(lambda h=h, m=method: tumble_run(problem, m, h), repeat)[:3],
            )
    return found


def work_precision_rows(problem: Problem, repeat: int) -> tuple[list, dict]:
    """Rows of section 2: tumble's methods, DOP853 and RK45 at each target error, the time
    over tumble's best; ``numbers`` keeps what the targets and floor notes need."""
    rows, numbers = [], {}
    for target in TARGET_ERRORS:
        found = tumble_work_precision(problem, target, repeat)
        for method in WORK_PRECISION_METHODS:
            if method not in found:
                rows.append([f"{target:.0e}", f"tumble `{method}`", "not reached", *[""] * 4])
        if not found:
            continue
        best = min(found, key=lambda method: found[method][2][0])
        h, _, (med, lo, hi) = found[best]
        numbers[("tumble", target)] = (med, lo, hi)
        numbers[("tumble", target, "best")] = (best, h, round(T_END / h))
        for method, (h_m, err, times) in found.items():
            rows.append(
                [
                    f"{target:.0e}",
                    f"tumble `{method}`" + (" (best)" if method == best else ""),
                    f"h = {h_m:g}",
                    f"{round(T_END / h_m)}",
                    spread(*times, 1e3, 3),
                    f"{err:.1e}",
                    f"{times[0] / med:.2g}",
                ]
            )
        for method in ("DOP853", "RK45"):
            rtol, err = search(
                RTOL_GRID,
                lambda r, m=method: scipy_run(problem, m, r),
                lambda s: scipy_error(problem, s),
                target,
            )
            if rtol is None:
                rows.append(
                    [f"{target:.0e}", f"solve_ivp {method}", "not reached", "", "", "", ""]
                )
                continue
            r = max(1, repeat // 3)
            med_s, lo_s, hi_s, sol = timed(lambda m=method, t=rtol: scipy_run(problem, m, t), r)
            numbers[(method, target)] = (med_s, lo_s, hi_s)
            numbers[(method, target, "steps")] = (sol.t.size - 1, sol.nfev)
            rows.append(
                [
                    f"{target:.0e}",
                    f"solve_ivp {method}",
                    f"rtol = {rtol:.1e}",
                    f"{sol.t.size - 1} ({sol.nfev} f)",
                    spread(med_s, lo_s, hi_s, 1e3, 1),
                    f"{err:.1e}",
                    f"{med_s / med:.0f}",
                ]
            )
        if METHODS[best].family != "lie":  # the context row calls the lie chart's loop
            continue
        med_k, lo_k, hi_k, _ = timed(lambda m=best, h=h: kernel_run(problem, m, h), repeat)
        numbers[("kernel", target)] = med_k
        rows.append(
            [
                f"{target:.0e}",
                f"(context) `{best}` steps alone, no `simulate` call",
                f"h = {h:g}",
                f"{round(T_END / h)}",
                spread(med_k, lo_k, hi_k, 1e3, 3),
                "same",
                f"{med_k / med:.2f}",
            ]
        )
    med_i, lo_i, hi_i, sol = timed(lambda: scipy_run(problem, "DOP853", 1e-9), 1)
    rows.append(
        [
            "—",
            "solve_ivp DOP853 (the issue's setting)",
            "rtol = 1e-9",
            f"{sol.t.size - 1} ({sol.nfev} f)",
            spread(med_i, lo_i, hi_i, 1e3, 1),
            f"{scipy_error(problem, sol):.1e}",
            "",
        ]
    )
    return rows, numbers


# --- 3. many bodies -------------------------------------------------------------------------


def batch_rows(problem: Problem, sizes, repeat: int, budget: int) -> tuple[list, dict]:
    """``budget``: body-steps per size (2·10⁷ is about 1 s at the target rate). Each size is
    timed with the structure-of-arrays loops (:mod:`tumble.rigid.soa`, the default) and with
    the one-body-per-thread loops they replaced (``tumble.rigid.batch.SOA_FAMILIES`` emptied
    for the run), in the same process."""
    from tumble.rigid import batch as batch_module

    rng, rows, numbers = np.random.default_rng(0), [], {}
    soa_families = batch_module.SOA_FAMILIES
    for n_bodies in sizes:
        n_steps = max(10, min(100_000, budget // n_bodies))
        omega0 = problem.omega0 + 0.1 * rng.standard_normal((n_bodies, 3))
        t_end = n_steps * H

        def batch(omega0=omega0, t_end=t_end):
            return simulate_batch(
                problem.body, t_end, method="rkmk4", h=H, omega0=omega0, record_every=10**9
            )

        med, lo, hi, _ = timed(batch, repeat)
        try:
            batch_module.SOA_FAMILIES = ()
            batch()  # the AoS batch loop's compile (or load) outside the timing
            aos = timed(batch, repeat)
        finally:
            batch_module.SOA_FAMILIES = soa_families
        rate = n_bodies * n_steps / med
        numbers[n_bodies] = (rate, n_bodies * n_steps / hi, n_bodies * n_steps / lo)
        numbers[(n_bodies, "aos")] = n_bodies * n_steps / aos[0]
        singles = ""
        if n_bodies == 1000:  # the loop a user would write: simulate once per body
            sample = 20

            def singles_loop(t_end=t_end, sample=sample):
                return [tumble_run(problem, "rkmk4", H, t_end) for _ in range(sample)]

            s_med = timed(singles_loop, max(1, repeat // 2))[0]
            singles = f"{n_bodies * n_steps / (s_med * n_bodies / sample):.2e}"
            numbers["singles"] = n_bodies * n_steps / (s_med * n_bodies / sample)
        rows.append(
            [
                f"{n_bodies:,}",
                f"{n_steps:,}",
                spread(med, lo, hi, 1e3, 1),
                f"{rate:.2e} ({numbers[n_bodies][1]:.2e}–{numbers[n_bodies][2]:.2e})",
                f"{numbers[(n_bodies, 'aos')]:.2e}",
                f"{aos[0] / med:.2f}",
                singles,
            ]
        )
    return rows, numbers


# --- 4. simulate's overhead, 5. plain NumPy RK4 ---------------------------------------------


def overhead(problem: Problem, repeat: int, method: str = "rkmk4") -> tuple[float, float, float]:
    """A 10-step ``simulate`` call (the steps themselves cost a few µs)."""
    times = [timed(lambda: tumble_run(problem, method, H, 10 * H), 1)[0] for _ in range(repeat)]
    return float(np.median(times)), float(np.min(times)), float(np.max(times))


def numpy_rk4_step_time(problem: Problem, n: int, repeat: int) -> tuple[float, float, float]:
    """Classical RK4 on the 12 numbers of (R, ω) with NumPy arrays, one step per iteration."""
    inertia, inverse = np.diag(problem.inertia), np.diag(1 / problem.inertia)

    def f(R, w):
        return R @ so3.hat(w), inverse @ np.cross(inertia @ w, w)

    def run():
        R, w = np.eye(3), problem.omega0.copy()
        for _ in range(n):
            k1 = f(R, w)
            k2 = f(R + H / 2 * k1[0], w + H / 2 * k1[1])
            k3 = f(R + H / 2 * k2[0], w + H / 2 * k2[1])
            k4 = f(R + H * k3[0], w + H * k3[1])
            R = R + H / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            w = w + H / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        return R

    med, lo, hi, _ = timed(run, repeat)
    return med / n, lo / n, hi / n


# --- report -----------------------------------------------------------------------------------


def targets(per_step: dict, wp: dict, batch: dict, over: tuple, tumble_numpy: float) -> list:
    rows = []
    rk = per_step["rkmk4"]
    rows.append(
        [
            "`rkmk4` ≤ 0.3 µs per step (P1)",
            spread(*rk[:3], 1e6, 3) + " µs",
            verdict(rk[0] <= 0.3e-6),
        ]
    )
    peer = per_step.get("MuJoCo RK4 rollout")
    if peer is None:
        rows.append(["≥ 20× faster than MuJoCo RK4, error ≤", "MuJoCo not available", "—"])
    else:
        ratio = peer[0] / rk[0]
        rows.append(
            [
                "≥ 20× faster per step than MuJoCo RK4 (rollout), error ≤ MuJoCo's",
                f"{ratio:.1f}× ({peer[1] / rk[2]:.1f}–{peer[2] / rk[1]:.1f}); error "
                f"{rk[3]:.1e} vs {peer[3]:.1e}",
                verdict(ratio >= 20 and rk[3] <= peer[3]),
            ]
        )
    for target in TARGET_ERRORS:
        if ("DOP853", target) in wp and ("tumble", target) in wp:
            (peer, peer_lo, peer_hi), (ours, ours_lo, ours_hi) = (
                wp[("DOP853", target)],
                wp[("tumble", target)],
            )
            best = wp[("tumble", target, "best")][0]
            rows.append(
                [
                    f"≥ 100× less time than DOP853 to error {target:.0e}",
                    f"{peer / ours:.1f}× ({peer_lo / ours_hi:.1f}–{peer_hi / ours_lo:.1f}), "
                    f"tumble `{best}`",
                    verdict(peer / ours >= 100),
                ]
            )
    if 100_000 in batch:
        rate = batch[100_000]
        rows.append(
            [
                "≥ 3·10⁷ body-steps/s at N = 10⁵ (issue 17)",
                f"{rate[0]:.2e} ({rate[1]:.2e}–{rate[2]:.2e}); "
                f"{rate[0] / batch[(100_000, 'aos')]:.2f}× the AoS loop",
                verdict(rate[0] >= 3e7),
            ]
        )
    split, marginal = per_step.get("split-axes"), per_step.get("split-axes marginal")
    if split is not None:
        steps_alone = "" if marginal is None else (
            f"; the steps alone (a 10⁵-step run less a 10⁴-step one) {spread(*marginal, 1e6, 3)}"
        )  # fmt: skip
        rows.append(
            [
                "`split-axes` ≤ 0.1 µs per step on P1, less than `rkmk4`",
                f"{spread(*split[:3], 1e6, 3)} µs (section 1) against `rkmk4`'s "
                f"{spread(*rk[:3], 1e6, 3)}: {rk[0] / split[0]:.2f}× less time "
                f"({rk[1] / split[2]:.2f}–{rk[2] / split[1]:.2f}){steps_alone}",
                verdict(split_axes_met(per_step)),
            ]
        )
    rows.append(
        [
            "`simulate` overhead < 1 ms per call",
            spread(*over, 1e6, 1) + " µs",
            verdict(over[0] < 1e-3),
        ]
    )
    rows.append(
        [
            "(context) plain NumPy RK4 loop / tumble `rkmk4`, per step",
            f"{tumble_numpy / rk[0]:.0f}×",
            "—",
        ]
    )
    return rows


def split_axes_met(per_step: dict) -> bool:
    """Issue #12's target, on section 1's measure (the same as ``rkmk4``'s target): a whole
    ``simulate`` call of 10⁴ steps divided by its steps."""
    split, rk = per_step["split-axes"], per_step["rkmk4"]
    return split[0] <= 0.1e-6 and split[0] < rk[0]


def marginal_step(problem: Problem, method: str, repeat: int) -> tuple[float, float, float]:
    """Seconds a step adds, median (min–max) over ``repeat`` pairs: a 10⁵-step run less the
    10⁴-step run timed right after it, over 9·10⁴ steps, so that ``simulate``'s fixed cost
    drops out."""

    def run(t_end: float):
        return simulate(problem.body, t_end, method=method, h=H, omega0=problem.omega0,
                        record_every=10**9)  # fmt: skip

    steps = [
        (timed(lambda: run(1000.0), 1)[0] - timed(lambda: run(100.0), 1)[0]) / 90_000
        for _ in range(repeat)
    ]
    return float(np.median(steps)), float(np.min(steps)), float(np.max(steps))


@njit(cache=True)
def sin_cos_chain(n: int, pairs: int, angle: float) -> float:
    """``n`` steps of ``pairs`` plane rotations of m by ``math.cos``/``math.sin``, each
    angle taken from the m the rotation before left (``split-axes``' turns: the angle
    ``h m_i/I_i`` waits for the previous turn), and nothing else."""
    m1, m2 = 0.45, 0.89
    for _ in range(n):
        for _ in range(pairs):
            c, s = math.cos(angle), math.sin(angle)
            m1, m2 = c * m1 + s * m2, c * m2 - s * m1
            angle = 0.01 * m1
    return m1 + m2


@njit(cache=True)
def sin_cos_free(n: int, pairs: int, angle: float) -> float:
    """``n`` steps of ``pairs`` sin/cos pairs whose angles do not depend on each other (the
    processor may overlap them): what the pairs cost when nothing waits."""
    total = 0.0
    for i in range(n):
        for k in range(pairs):
            a = angle + 1e-12 * (i * pairs + k)
            total += math.cos(a) + math.sin(a)
    return total


def split_axes_floors(steps: int = 1_000_000) -> dict[str, float]:
    """Seconds per step, medians of 5: ``chain5`` and ``chain4``, :func:`sin_cos_chain` with
    five sin/cos pairs (a Strang step 1, 2, 3, 2, 1) and four (what the compiled loop does
    without loads: the last half turn about axis 1 merged with the next step's first);
    ``free5``, :func:`sin_cos_free` with five; ``alone``, the kernels' axes flow called as the
    loop calls it between records (four turns: the merged one by h, none at the end), in a
    compiled loop without the driver around it."""
    from tumble.rigid._compiled import exact_flow, flows

    flow = flows._axes_flow

    @njit
    def flows(n, Rp, L, moments, h, work):
        for _ in range(n):
            flow(Rp, L[0], L[1], L[2], moments, h, work, 2.0 * h, 0.0)
        return Rp

    L, moments = np.array([0.45, 0.0, 0.89]), np.array([2.0 / 3.0, 1.0, 2.0])
    work = np.empty(exact_flow.WORK_SIZE)
    floors = {
        "chain5": lambda: sin_cos_chain(steps, 5, 0.01),
        "chain4": lambda: sin_cos_chain(steps, 4, 0.01),
        "free5": lambda: sin_cos_free(steps, 5, 0.01),
        "alone": lambda: flows(steps, np.eye(3), L, moments, H, work),
    }
    sin_cos_chain(10, 5, 0.01), sin_cos_free(10, 5, 0.01)  # compile outside the timings
    flows(10, np.eye(3), L, moments, H, work)
    return {name: timed(fn, 5)[0] / steps for name, fn in floors.items()}


def floor_notes(wp: dict, batch: dict) -> list[str]:
    """For each target not met: what bounds it, from this run's numbers."""
    from tumble.rigid.methods import METHODS

    notes = []
    for target in TARGET_ERRORS:
        if ("DOP853", target) not in wp or ("tumble", target) not in wp:
            continue
        peer, ours = wp[("DOP853", target)][0], wp[("tumble", target)][0]
        if peer >= 100 * ours:
            continue
        if ("kernel", target) not in wp:
            continue  # a split method was best: no context row to split the time with
        steps, nfev = wp[("DOP853", target, "steps")]
        (best, h, n), kernel = wp[("tumble", target, "best")], wp[("kernel", target)]
        tableau = METHODS[best].tableau
        per_step = kernel / n
        if kernel <= peer / 100:
            bound = (
                f"the steps alone would meet it ({peer / kernel:.0f}×): what is left is the "
                "call's fixed cost"
            )
        else:
            bound = (
                f"the steps alone give {peer / kernel:.0f}×, so a lighter call is not enough. "
                "An explicit order-8 Runge–Kutta method needs at least 11 stages (Butcher), "
                "so what is left is a cheaper stage: each evaluates an exponential's "
                "coefficients (sin and cos above 0.25 rad), a Rodrigues rotation and dexp⁻¹, "
                "and the stage sums run over all 12 numbers of (u, x, p, L), the translational "
                "half included"
            )
        notes.append(
            f"DOP853 to {target:.0e}: {steps} steps ({nfev} evaluations, "
            f"{peer / nfev * 1e6:.1f} µs each with the Python right-hand side), "
            f"{peer * 1e3:.1f} ms, so 100× means {peer / 100 * 1e6:.0f} µs. tumble's best, "
            f"`{best}` (order {tableau.order}, {tableau.stages} stages), takes {n} steps "
            f"(h = {h:g}) in {ours * 1e6:.0f} µs: the steps {kernel * 1e6:.0f} µs "
            f"({per_step * 1e9:.0f} ns each, {per_step / tableau.stages * 1e9:.0f} ns per "
            f"stage) and the `simulate` call {(ours - kernel) * 1e6:.0f} µs (checks, initial "
            f"state, trajectory). Bound: {bound}."
        )
    if 100_000 in batch and batch[100_000][0] < 3e7:
        rate = batch[100_000][0]
        threads = int(os.environ.get("NUMBA_NUM_THREADS", os.cpu_count()))
        notes.append(
            f"Batch at N = 10⁵: {rate:.2e} body-steps/s is {threads / rate * 1e9:.0f} ns per "
            f"body-step per thread ({threads} threads); 3·10⁷ needs "
            f"≤ {threads / 3e7 * 1e9:.0f} ns. The structure-of-arrays loops are "
            f"{rate / batch[(100_000, 'aos')]:.2f}× the AoS ones here. They run in AVX2 (4 "
            "doubles a vector: LLVM chooses 256-bit vectors on this CPU although it has "
            "AVX-512) with no fused multiply-add (no fastmath: every body must keep the "
            "one-body loop's numbers bit for bit), and an RKMK4 body-step is about 500 "
            "flops (four stages of a Taylor exp, two Rodrigues rotations, dexp⁻¹, the "
            "12-number stage sums) plus the K array's loads and stores; the machine is "
            "shared, so the rate moves with the other sessions' load (the header's load "
            "average)."
        )
    return notes


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats, N ≤ 10⁴")
    args, _ = parser.parse_known_args(argv)
    repeat = 3 if args.quick else 9
    sizes = [1, 1000, 10_000] if args.quick else [1, 1000, 100_000]
    p1, handle = problems()
    methods = ["rkmk4", "rk4-quat", "rkmk8"]
    if not args.quick:
        methods += ["seed-rk4", "rk4-matrix", "lie-euler", "euler"]
    methods += [name for name, method in METHODS.items() if method.family == "split"]
    for method in methods:  # compile (or load) each method's kernels outside the timings
        tumble_run(p1, method, H, 1.0)
    simulate_batch(p1.body, 0.1, h=H, omega0=p1.omega0[None])
    out = ["## Rigid bodies (`benchmarks/bench_rigid.py`)", ""]

    out += [f"### 1. µs per step at h = {H}, T = {T_END:g} (free body, gravity off)", ""]
    numbers = {}
    for problem in (p1, handle):
        rows, found = per_step_rows(problem, repeat, methods if problem is p1 else methods[:2])
        numbers[problem.name] = found
        header = ["", "µs per step", "error at T (rad)"]
        out += [f"**{problem.name}**", "", table(header, rows), ""]
    numbers["P1"]["split-axes marginal"] = marginal_step(p1, "split-axes", repeat)
    notes = [
        "Error: the angle of R_computedᵀ R_exact at T. tumble's time is a whole `simulate` "
        f"call over {round(T_END / H)} steps (`record_every` large) divided by the steps.",
        "MuJoCo `rollout` runs the steps in C (no Python per step): the fair comparison. "
        "MuJoCo's Euler and implicitfast are cheaper but wrong by radians at this h.",
    ]
    try:
        notes.append(mujoco_frame_check(p1))
    except ImportError:
        pass
    out += [" ".join(notes), ""]

    out += ["### 2. Work–precision on P1: wall time to reach an orientation error", ""]
    wp_rows, wp = work_precision_rows(p1, repeat)
    cost_8_4 = numbers["P1"]["rkmk8"][0] / numbers["P1"]["rkmk4"][0]
    out += [
        table(
            ["error ≤", "solver", "setting", "steps", "ms", "error", "time / tumble's best"],
            wp_rows,
        ),
        "",
        "h: the largest of the method's grid that meets the error (`rkmk4`, `split-axes4`: "
        "0.2 … 0.0025; `rkmk8`: T/h = 100, 125, 160, 200, … a factor 1.25 apart; the order-2 "
        "`split-axes`, `midpoint-lp`, `dmv`: 0.02 halved down to 4.9e-6, T/h up to 2·10⁷, "
        "past which round-off grows faster than the error falls); rtol: the loosest of "
        "10^(−k/2) that does (atol = rtol·1e-3), about 1.14 apart in DOP853's steps. The "
        "last column divides by tumble's best time at that error. solve_ivp integrates "
        "Euler's equations + the quaternion with a lean Python right-hand side (f: its "
        "evaluations). `rkmk8` is RKMK with DOP853's own 12 stages and eighth-order weights "
        f"(no error estimate, fixed h): a step costs {cost_8_4:.1f}× one of `rkmk4` "
        "(section 1), and it needs far fewer. The context rows call the compiled loop "
        "directly, without `simulate`'s checks, initial state and trajectory: the floor of a "
        "call.",
        "",
    ]

    out += [f"### 3. Many bodies: `simulate_batch`, `rkmk4`, P1-like spins, h = {H}", ""]
    batch_table, batch = batch_rows(
        p1, sizes, max(1, repeat // 3), 2 * 10**6 if args.quick else 2 * 10**7
    )
    out += [
        table(
            [
                "N",
                "steps",
                "ms per call",
                "body-steps/s",
                "AoS body-steps/s",
                "SoA/AoS",
                "N `simulate` calls",
            ],
            batch_table,
        ),  # fmt: skip
        "",
        f"Numba threads: {os.environ.get('NUMBA_NUM_THREADS', os.cpu_count())}. "
        "body-steps/s: the structure-of-arrays loops (`tumble/rigid/soa.py`: bodies as "
        "columns, blocks of 256 bodies per thread, the loops over bodies in packed AVX2 "
        "instructions); AoS: the one-body loop per body they replaced, timed in the same run. "
        "The time is the whole call: checks, initial states, the parallel kernel, the (body, "
        "time) arrays. Last column: the same work as a loop of single `simulate` calls (20 "
        "timed, extrapolated).",
        "",
    ]

    over = overhead(p1, 50 if args.quick else 200)
    per_numpy = numpy_rk4_step_time(p1, 500 if args.quick else 2000, max(1, repeat // 3))
    out += [
        "### 4. `simulate` overhead and a plain NumPy loop",
        "",
        table(
            ["", "µs", ""],
            [
                ["`simulate` call of 10 steps", spread(*over, 1e6, 1), "per call"],
                [
                    "NumPy RK4 on (R, ω), one step",
                    spread(*per_numpy, 1e6, 1),
                    "the issue's baseline",
                ],
            ],
        ),
        "",
    ]

    out += [
        "### Targets (issues #7 and #12)",
        "",
        table(
            ["target", "measured, median (min–max)", ""],
            targets(numbers["P1"], wp, batch, over, per_numpy[0]),
        ),
        "",
    ]
    notes = floor_notes(wp, batch)
    split = numbers["P1"].get("split-axes")
    if split is not None and not split_axes_met(numbers["P1"]):
        marginal = numbers["P1"]["split-axes marginal"]
        call = overhead(p1, 50 if args.quick else 200, "split-axes")
        floors = split_axes_floors(200_000 if args.quick else 1_000_000)
        notes.append(
            f"`split-axes` at {split[0] * 1e9:.0f} ns a step over a 10⁴-step `simulate` call "
            f"(issue #12: ≤ 100 ns). The steps alone cost {marginal[0] * 1e9:.0f} ns "
            f"({marginal[1] * 1e9:.0f}–{marginal[2] * 1e9:.0f}); the call's fixed cost, a "
            f"10-step `split-axes` call, is {spread(*call, 1e6, 0)} µs, "
            f"{call[0] * 1e5:.0f} ns a step over 10⁴ steps. Floor of the steps: a "
            "compiled loop doing nothing but split-axes' sin/cos pairs, each angle waiting for "
            f"the rotation before it as h m_i/I_i does, takes {floors['chain5'] * 1e9:.0f} ns a "
            f"step for five pairs (a Strang step 1, 2, 3, 2, 1) and "
            f"{floors['chain4'] * 1e9:.0f} ns for four (what the loop does without loads: the "
            "last half turn about axis 1 merged with the next step's first); the same five "
            f"pairs free of each other take {floors['free5'] * 1e9:.0f} ns. The axes flow "
            f"alone, called as the loop calls it, takes {floors['alone'] * 1e9:.0f} ns (beyond "
            "the chain: m = R_pᵀ L at the step's start, each angle's division by I_i, R_p's "
            "columns turned), and the driver's loop around it (the state kept for a failed "
            "step, the finiteness check, the record countdown) "
            f"{(marginal[0] - floors['alone']) * 1e9:.0f} ns."
        )
    if notes:
        out += ["Targets not met, and what bounds them:", ""] + [f"- {n}" for n in notes] + [""]
    markdown = "\n".join(out)
    print(markdown)
    return markdown


if __name__ == "__main__":
    main()
