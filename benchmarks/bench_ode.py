"""tumble.solve against scipy's solve_ivp on the same problems, at equal final error.

Run: ``python benchmarks/bench_ode.py [--quick]``. Prints medians (min–max) and the ratio
scipy / tumble (> 1 means tumble is faster), measured in this process.

Two parts: the Python path (a plain Python right-hand side, both loop in Python), and the
compiled path (a ``numba.njit`` right-hand side: ``tumble.solve`` runs the whole integration
compiled) against ``solve_ivp`` at equal final error: for each scipy tolerance, tumble's
loosest tolerance (or, for a fixed-step method, largest step) on a grid of quarter decades
whose final error is at most scipy's. scipy gets the same compiled right-hand side and the
plain NumPy one; the ratio is against the faster of the two. NumbaLSODA (the second peer of
issue 17) is timed if it is installed.
"""

from __future__ import annotations

import sys
from functools import partial

import numba
import numpy as np
import scipy
from _timing import machine, spread, table, timed, verdict
from scipy.integrate import solve_ivp

from tumble import solve

MU = 2.0
SIGMA, RHO, BETA = 10.0, 28.0, 8.0 / 3.0
LORENZ_END = 5.0
TARGET = 30.0
"""Compiled solve must be at least this many times faster than solve_ivp (issue 17)."""


@numba.njit(cache=True)
def van_der_pol_compiled(t, y):
    return np.array([y[1], MU * (1 - y[0] ** 2) * y[1] - y[0]])


def lorenz(t, y):
    return np.array([SIGMA * (y[1] - y[0]), y[0] * (RHO - y[2]) - y[1], y[0] * y[1] - BETA * y[2]])


lorenz_compiled = numba.njit(cache=True)(lorenz)


def van_der_pol(t, y):
    return np.array([y[1], MU * (1 - y[0] ** 2) * y[1] - y[0]])


def flight(t, y):
    return np.array([y[2], y[3], 0.0, -9.81])


def ground(t, y):
    return y[1]


ground.terminal, ground.direction = True, -1


def _row(name, tumble_case, scipy_case, error, repeat):
    t_med, t_min, t_max, ours = timed(tumble_case, repeat)
    s_med, s_min, s_max, theirs = timed(scipy_case, repeat)
    e_ours, e_theirs = error(ours), error(theirs)
    return (
        f"| {name} | {t_med * 1e3:.2f} ({t_min * 1e3:.2f}–{t_max * 1e3:.2f}) | {e_ours:.1e} "
        f"| {s_med * 1e3:.2f} ({s_min * 1e3:.2f}–{s_max * 1e3:.2f}) | {e_theirs:.1e} "
        f"| {s_med / t_med:.2f} |"
    )


TOLERANCES = 10.0 ** (-np.arange(16, 113) / 8)  # rtol: 1e-2 … 1e-14, eighth decades
STEPS = 10.0 ** (-np.arange(4, 49) / 8)  # h: 0.32 … 1e-6


def _loosest(run, error, bound, settings):
    """The first setting (loosest first) whose run's error is at most ``bound``."""
    for setting in settings:
        with np.errstate(all="ignore"):  # a step too large for the problem diverges
            result = run(setting)
        if result.success and error(result) <= bound:
            return setting
    return settings[-1]


def _numbalsoda_row(problem, y0, t1, y_ref, rtol, repeat):
    """NumbaLSODA's time and error at ``rtol``, or None when it is not installed."""
    try:
        from numbalsoda import lsoda, lsoda_sig
    except ImportError:
        return None
    rhs = problem

    @numba.cfunc(lsoda_sig)
    def lsoda_rhs(t, u, du, p):
        y = numba.carray(u, len(y0))
        f = rhs(t, y)
        for i in range(len(y0)):
            du[i] = f[i]

    address = lsoda_rhs.address
    t_eval = np.array([0.0, t1])
    med, low, high, (usol, _) = timed(
        lambda: lsoda(address, np.array(y0, dtype=float), t_eval, rtol=rtol, atol=rtol), repeat
    )
    return med, low, high, float(np.abs(usol[-1] - y_ref).max())


def _peer(fun, t1, y0, method, rtol):
    return solve_ivp(fun, (0, t1), y0, method=method, rtol=rtol, atol=rtol)


def _ours(fun, t1, y0, method, adaptive, setting):
    if adaptive:
        return solve(fun, (0, t1), y0, method=method, rtol=setting, atol=setting)
    return solve(fun, (0, t1), y0, method=method, h=setting)


def _final_error(result, y_ref):
    return float(np.abs(result.y[:, -1] - y_ref).max())


def _cases():
    """(name, NumPy fun, compiled fun, y0, T, reference y(T), scipy method, tumble methods)."""
    vdp_ref = solve_ivp(van_der_pol, (0, 10), [2, 0], method="DOP853", rtol=1e-13, atol=1e-13)
    y0_lorenz = [1.0, 1.0, 1.0]
    lorenz_ref = solve(lorenz_compiled, (0, LORENZ_END), y0_lorenz, method="rk8", h=1e-4)
    return [
        ("Van der Pol μ=2, T=10", van_der_pol, van_der_pol_compiled, [2.0, 0.0], 10.0,
         vdp_ref.y[:, -1], "RK45", [("dopri5", True)]),
        (f"Lorenz, T={LORENZ_END:g}", lorenz, lorenz_compiled, y0_lorenz, LORENZ_END,
         lorenz_ref.y[:, -1], "DOP853", [("rk8", False), ("dopri5", True)]),
    ]  # fmt: skip


def _compiled_rows(repeat: int) -> tuple[list[list[str]], dict]:
    """Compiled solve against solve_ivp at equal final error; the rows, and per problem and
    tolerance the best tumble method's ratio."""
    rows, ratios = [], {}
    for name, python_fun, compiled_fun, y0, t1, y_ref, peer, methods in _cases():
        error = partial(_final_error, y_ref=y_ref)
        for rtol in (1e-6, 1e-9):
            theirs = [
                timed(partial(_peer, fun, t1, y0, peer, rtol), repeat)
                for fun in (python_fun, compiled_fun)
            ]
            best = min(theirs, key=lambda timing: timing[0])
            bound = error(best[3])
            for method, adaptive in methods:
                run = partial(_ours, compiled_fun, t1, y0, method, adaptive)
                setting = _loosest(run, error, bound, TOLERANCES if adaptive else STEPS)
                med, low, high, ours = timed(partial(run, setting), repeat * 10)
                key = (name, rtol)
                ratios[key] = max(ratios.get(key, 0.0), best[0] / med)
                label = f"rtol={setting:.2g}" if adaptive else f"h={setting:.2g}"
                rows.append([f"{name}, {method} ({label}) vs {peer} rtol={rtol:g}",
                             spread(med, low, high, 1e6), f"{error(ours):.1e}",
                             spread(*theirs[0][:3], 1e6, 0), spread(*theirs[1][:3], 1e6, 0),
                             f"{bound:.1e}", f"{best[0] / med:.0f}"])  # fmt: skip
            lsoda = _numbalsoda_row(compiled_fun, y0, t1, y_ref, rtol, repeat)
            if lsoda is not None:
                cells = [spread(*lsoda[:3], 1e6), f"{lsoda[3]:.1e}", "", "", ""]
                rows.append([f"{name}, NumbaLSODA rtol={rtol:g}", *cells,
                             f"{best[0] / lsoda[0]:.0f}"])  # fmt: skip
    return rows, ratios


def compiled_section(repeat: int) -> str:
    """The compiled path against solve_ivp, as a markdown section."""
    rows, best = _compiled_rows(repeat)
    smallest = min(best.values())
    header = ["problem", "tumble compiled µs", "error", "scipy µs (NumPy fun)",
              "scipy µs (njit fun)", "scipy error", "scipy/tumble"]  # fmt: skip
    try:
        import numbalsoda  # noqa: F401

        lsoda_note = "NumbaLSODA rows: LSODA compiled, its rtol = atol = scipy's."
    except ImportError:
        lsoda_note = (
            "NumbaLSODA is not timed: `pip install numbalsoda` fails here (no wheel for this "
            "Python; building needs a Fortran compiler, which this machine lacks)."
        )
    return "\n".join(
        [
            "### Compiled right-hand side: `solve` runs compiled (issue 17)",
            "",
            table(header, rows),
            "",
            f"Target ≥ {TARGET:g}× at equal final error, for each problem and tolerance with "
            f"tumble's best method there: {verdict(smallest >= TARGET)} (smallest "
            f"{smallest:.0f}×; "
            + ", ".join(
                f"{name} rtol={rtol:g}: {ratio:.0f}×" for (name, rtol), ratio in best.items()
            )
            + "). Each tumble setting is the loosest on a grid of eighth decades whose final "
            "error is at most scipy's; the ratio is against the faster scipy variant. The tumble "
            "time includes the whole `solve` call (checks, first step, result; about 25 µs "
            "with no step, `benchmarks/bench_call.py`). The Lorenz reference is tumble's rk8 "
            "with h = 1e-4. " + lsoda_note,
            "",
        ]
    )


def main(argv: list[str] | None = None) -> str:
    """Print the table and return it as a markdown section (heading, table, notes)."""
    argv = sys.argv[1:] if argv is None else argv
    repeat = 3 if "--quick" in argv else 9
    v = 500 / np.sqrt(2)
    exact_range = 2 * v * v / 9.81
    reference = solve_ivp(van_der_pol, (0, 10), [2, 0], method="DOP853", rtol=1e-13, atol=1e-13)
    y_ref = reference.y[:, -1]
    rows = [
        _row(
            "projectile, dopri5 vs RK45, rtol=1e-10 (event)",
            lambda: solve(
                flight,
                (0, 100),
                [0, 0, v, v],
                method="dopri5",
                rtol=1e-10,
                atol=1e-10,
                events=ground,
            ),
            lambda: solve_ivp(
                flight, (0, 100), [0, 0, v, v], rtol=1e-10, atol=1e-10, events=ground
            ),
            lambda r: abs(r.y_events[0][0, 0] - exact_range) / exact_range,
            repeat,
        ),
    ]
    for rtol in (1e-6, 1e-9):
        rows.append(
            _row(
                f"Van der Pol μ=2, dopri5 vs RK45, rtol={rtol:g}",
                lambda rtol=rtol: solve(
                    van_der_pol, (0, 10), [2, 0], method="dopri5", rtol=rtol, atol=rtol
                ),
                lambda rtol=rtol: solve_ivp(
                    van_der_pol, (0, 10), [2, 0], method="RK45", rtol=rtol, atol=rtol
                ),
                lambda r: float(np.abs(r.y[:, -1] - y_ref).max()),
                repeat,
            )
        )
    markdown = "\n".join(
        [
            "## ODE core (`benchmarks/bench_ode.py`)",
            "",
            "| problem | tumble ms, median (min–max) | error | scipy ms | error | scipy/tumble |",
            "|---|---|---|---|---|---|",
            *rows,
            "",
            f"Same tolerances for both; ratio > 1: tumble faster. {machine()}; numpy "
            f"{np.__version__}, scipy {scipy.__version__}.",
            "",
            compiled_section(repeat),
        ]
    )
    print(markdown)
    return markdown


if __name__ == "__main__":
    main()
