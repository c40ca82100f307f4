"""tumble.solve against scipy's solve_ivp on the same problems, at equal final error.

Run: ``python benchmarks/bench_ode.py [--quick]``. Prints medians (min–max) and the ratio
scipy / tumble (> 1 means tumble is faster), measured in this process.
"""

from __future__ import annotations

import sys

import numpy as np
import scipy
from _timing import machine, timed
from scipy.integrate import solve_ivp

from tumble import solve

MU = 2.0


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
        ]
    )
    print(markdown)
    return markdown


if __name__ == "__main__":
    main()
