"""Measured orders of convergence: the log–log slope of the global error against h."""

import numpy as np
import pytest

from tumble import solve
from tumble.ode import TABLEAUX

# y' = -2 t y², y(0) = 1 has the exact solution y = 1 / (1 + t²): nonlinear, non-autonomous.
T_END = 2.0
EXACT = 1.0 / (1.0 + T_END**2)


def _rhs(t, y):
    return -2.0 * t * y**2


def _global_error(method, h):
    result = solve(_rhs, (0.0, T_END), [1.0], method=method, h=h)
    return abs(result.y[0, -1] - EXACT)


FIXED = [name for name, tableau in TABLEAUX.items() if not tableau.adaptive]
ADAPTIVE = [name for name, tableau in TABLEAUX.items() if tableau.adaptive]


def order_steps(order: int) -> list[int]:
    """Step counts on [0, 2] where a tableau of ``order`` shows its slope. Order 8: errors
    1.7e-11 … 6.2e-14, slope 8.13; coarser steps (6 and fewer) are pre-asymptotic (7.3 with
    6), finer ones reach round-off (1.4e-16 at 32)."""
    return {1: [40, 80, 160, 320], 2: [20, 40, 80, 160], 4: [10, 20, 40, 80]}.get(
        order, [8, 10, 12, 16]
    )


@pytest.mark.parametrize("method", FIXED)
def test_fixed_step_method_converges_at_its_order(method):
    order = TABLEAUX[method].order
    h = T_END / np.array(order_steps(order))
    errors = np.array([_global_error(method, hi) for hi in h])
    slope = np.polyfit(np.log(h), np.log(errors), 1)[0]
    assert abs(slope - order) < 0.2, f"{method}: measured order {slope:.3f}, claimed {order}"


def test_rk4_finest_error_is_small():
    # 80 steps on [0, 2]: measured 2.4e-9 (C h^4 with C ~ 6e-3); bound with a 4x margin.
    assert _global_error("rk4", T_END / 80) < 1e-8


def test_rk8_finest_error_is_small():
    # 16 steps on [0, 2]: measured 6.2e-14; bound with a 4x margin. The error is truncation:
    # the run's round-off, which differs from CPU to CPU, is ~1e-16 (1.4e-16 measured at 32
    # steps, where truncation is 2.4e-16; u √(N s) |terms| ~ 1e-15 as a random walk).
    assert _global_error("rk8", T_END / 16) < 2.5e-13


@pytest.mark.parametrize("method", ADAPTIVE)
def test_adaptive_method_fixed_step_order_through_tolerance(method):
    # Global error must fall at least ~100x when rtol falls 1000x (tolerance proportionality).
    errors = []
    for rtol in (1e-5, 1e-8):
        result = solve(_rhs, (0.0, T_END), [1.0], method=method, rtol=rtol, atol=rtol)
        errors.append(abs(result.y[0, -1] - EXACT))
    assert errors[1] < errors[0] / 100
