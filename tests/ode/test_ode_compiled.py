"""solve with a numba-compiled right-hand side runs compiled and gives the Python path's result.

The fixed-step runs agree to round-off in the stage sums (1e-13). The adaptive runs agree to
round-off amplified by the step controller: the error estimate ``h Σ e_i k_i`` is a
difference of O(1) stages that cancels to about rtol, so a round-off of 1e-16 in the sums
(the compiled loop adds in its own order, numpy's ``@`` in BLAS's) moves it by about
1e-16 / rtol relative, the next step by a fifth of that, and the times and states of the
run by as much (measured: 2e-11 at rtol = 1e-6 on Van der Pol); the bound is 1e-8.
"""

import numba
import numpy as np
import pytest

from tumble import solve
from tumble.ode import TABLEAUX
from tumble.ode.ivp import RungeKutta

MU = 2.0
ADAPTIVE_BOUND = 1e-8
FIXED_BOUND = 1e-13


@numba.njit(cache=True)
def van_der_pol(t, y):
    return np.array([y[1], MU * (1 - y[0] ** 2) * y[1] - y[0]])


def van_der_pol_python(t, y):
    return np.array([y[1], MU * (1 - y[0] ** 2) * y[1] - y[0]])


@numba.njit(cache=True)
def blow_up(t, y):
    return y * y  # y = 1 / (1 - t): infinite at t = 1


def position(t, y):
    return y[0]


def _terminal(count):
    def event(t, y):
        return y[0]

    event.terminal = count
    return event


def _options(method):
    if TABLEAUX[method].adaptive:
        return dict(method=method, rtol=1e-6, atol=1e-6), ADAPTIVE_BOUND
    return dict(method=method, h=0.01), FIXED_BOUND


def _assert_same(compiled, python, bound):
    assert compiled.status == python.status
    assert (compiled.n_steps, compiled.n_rejected, compiled.nfev) == (
        python.n_steps,
        python.n_rejected,
        python.nfev,
    )
    np.testing.assert_allclose(compiled.t, python.t, rtol=bound, atol=bound)
    np.testing.assert_allclose(compiled.y, python.y, rtol=0, atol=bound * np.abs(python.y).max())
    for ours, theirs in zip(compiled.t_events, python.t_events, strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=bound)


@pytest.mark.parametrize("method", TABLEAUX)
def test_compiled_solve_equals_the_python_path_with_dense_output_and_events(method):
    options, bound = _options(method)
    runs = [
        solve(fun, (0, 8), [2, 0], events=position, dense_output=True, **options)
        for fun in (van_der_pol, van_der_pol_python)
    ]
    _assert_same(*runs, bound)
    assert len(runs[0].t_events[0]) == 2  # Van der Pol crosses y = 0 at t ≈ 2.9 and 6.7
    between = np.linspace(0, runs[1].t[-1], 61)
    np.testing.assert_allclose(runs[0].sol(between), runs[1].sol(between), rtol=0,
                               atol=bound * 10)  # fmt: skip


@pytest.mark.parametrize("method", ["rk8", "dopri5"])
def test_compiled_solve_stops_at_a_terminal_event_as_the_python_path(method):
    options, bound = _options(method)
    runs = [
        solve(fun, (0, 100), [2, 0], events=_terminal(3), dense_output=True, **options)
        for fun in (van_der_pol, van_der_pol_python)
    ]
    _assert_same(*runs, bound)
    assert runs[0].status == 1 and runs[0].y[0, -1] == pytest.approx(0.0, abs=1e-9)
    assert runs[0].sol.t_max == runs[0].t[-1] < 100


def test_compiled_fixed_step_run_reports_a_non_finite_state_as_the_python_path():
    runs = [solve(fun, (0, 2), [1.0], method="rk4", h=0.125) for fun in (blow_up, blow_up.py_func)]
    assert runs[0].status == -1 and runs[0].message == runs[1].message
    assert "non-finite" in runs[0].message
    np.testing.assert_array_equal(runs[0].y, runs[1].y)


def test_compiled_adaptive_run_stops_at_the_minimum_step_as_the_python_path():
    runs = [solve(fun, (0, 2), [1.0], method="dopri5") for fun in (blow_up, blow_up.py_func)]
    assert runs[0].status == runs[1].status == -1
    assert "minimum" in runs[0].message and "minimum" in runs[1].message
    assert runs[0].n_steps == runs[1].n_steps
    assert runs[0].t[-1] == pytest.approx(1.0, abs=1e-3)  # the pole of 1 / (1 - t)


@pytest.mark.parametrize("method", ["rk4", "dopri5"])
def test_compiled_run_stops_after_max_steps_as_the_python_path(method):
    options, _ = _options(method)
    runs = [
        solve(fun, (0, 6), [2, 0], max_steps=7, **options)
        for fun in (van_der_pol, van_der_pol_python)
    ]
    assert runs[0].status == -1 and runs[0].n_steps == runs[1].n_steps == 7
    assert runs[0].message.split(" at t=")[0] == runs[1].message.split(" at t=")[0]
    assert "max_steps=7 reached" in runs[0].message


def _python_steps_forbidden(monkeypatch):
    """Make every per-step Python method of solve's stepper raise."""

    def forbidden(*args):
        raise AssertionError("a step was taken in Python")

    for name in ("step", "accept", "interpolant"):
        monkeypatch.setattr(RungeKutta, name, forbidden)


@pytest.mark.parametrize("method", TABLEAUX)
def test_compiled_solve_takes_no_step_in_python_with_events_and_dense_output(method, monkeypatch):
    options, _ = _options(method)
    _python_steps_forbidden(monkeypatch)
    with pytest.raises(AssertionError, match="in Python"):  # the Python path steps there
        solve(van_der_pol_python, (0, 1), [2, 0], **options)
    run = solve(van_der_pol, (0, 8), [2, 0], events=position, dense_output=True, **options)
    assert run.status == 0 and len(run.t_events[0]) == 2 and run.sol is not None
