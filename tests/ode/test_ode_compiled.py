"""solve's compiled loops give the Python path's result (``compiled=False``: every step in
Python), with a numba-compiled right-hand side called directly and with a Python one called
back (``RHS``: both).

The fixed-step runs differ only in the order of their stage sums: the compiled loop adds in
its own order, numpy's ``@`` in the order of the CPU's BLAS kernel (with or without FMA). Each
step's difference is then bounded by the round-off of its terms, and grows at most as much as
the problem amplifies a perturbation (:data:`KAPPA`): :func:`_bound`. The adaptive runs
agree to round-off amplified by the step controller: the error estimate ``h Σ e_i k_i`` is a
difference of O(1) stages that cancels to about rtol, so a round-off of eps in the sums moves
it by about eps / rtol relative, the next step by a fifth of that, and the times and states of
the run by as much (measured: 2e-11 at rtol = 1e-6 on Van der Pol, eps / rtol = 2e-10 a step
over 80 steps); the bound is 1e-8.
"""

import numba
import numpy as np
import pytest
from roundoff import EPS, run_bound, sum_bound

from tumble import solve
from tumble.ode import TABLEAUX
from tumble.ode.ivp import RungeKutta

MU = 2.0
ADAPTIVE_BOUND = 1e-8
KAPPA = 33.0
"""How much the Van der Pol orbit of these tests (μ = 2, from (2, 0) on [0, 11], past its
third zero at 10.5) amplifies a perturbation at most, max over s ≤ t of ‖∂y(t)/∂y(s)‖₂: 32.2,
from the variational equation (scipy, rtol 1e-10). A property of the problem, not of the
machine; so is JACOBIAN."""
JACOBIAN = 20.0
"""max ‖∂f/∂y‖₂ on that orbit (19.7)."""
EVENT_XTOL = 2 * 4 * EPS
"""Each path's brentq stops within ``4 eps (1 + |t|)`` of its own root (tumble.ode.events)."""


@numba.njit(cache=True)
def van_der_pol(t, y):
    return np.array([y[1], MU * (1 - y[0] ** 2) * y[1] - y[0]])


def van_der_pol_python(t, y):
    return np.array([y[1], MU * (1 - y[0] ** 2) * y[1] - y[0]])


@numba.njit(cache=True)
def blow_up(t, y):
    return y * y  # y = 1 / (1 - t): infinite at t = 1


RHS = pytest.mark.parametrize("rhs", ["numba", "python"])
"""The compiled runs: a numba ``fun``, and a Python one called back from the loops."""


def _fun(rhs):
    return van_der_pol if rhs == "numba" else van_der_pol_python


def _both(rhs):
    """(the compiled run's fun and compiled flag, the Python path's)."""
    return ((_fun(rhs), True), (van_der_pol_python, False))


def position(t, y):
    return y[0]


def _terminal(count):
    def event(t, y):
        return y[0]

    event.terminal = count
    return event


def _options(method):
    if TABLEAUX[method].adaptive:
        return dict(method=method, rtol=1e-6, atol=1e-6)
    return dict(method=method, h=0.01)


def _sizes(python) -> tuple[float, float, float]:
    """The run's largest |y|, largest |f| and longest step."""
    f = max(np.abs(van_der_pol_python(0.0, state)).max() for state in python.y.T)
    return np.abs(python.y).max(), f, np.diff(python.t).max()


def _bound(method, python) -> float:
    """How far the states of the compiled and the Python run of ``method`` may be apart.

    A fixed step rounds ``y + h Σ_j a_ij k_j`` and ``y + h Σ_i b_i k_i`` in chains of at most
    s + 2 roundings on terms ``|y| + h |f| Σ|a_ij|`` (tests/roundoff.py), and the orbit grows
    each step's difference at most KAPPA-fold.
    """
    tableau = TABLEAUX[method]
    y, f, h = _sizes(python)
    if tableau.adaptive:
        return ADAPTIVE_BOUND * y
    weights = max(np.abs(tableau.A).sum(axis=1).max(), np.abs(tableau.b).sum())
    return float(run_bound(python.n_steps, tableau.stages + 2, y + h * f * weights, KAPPA))


def _interpolant_bound(method, python, bound) -> float:
    """How far the two runs' interpolants may be apart between the nodes.

    A difference δy of the states reaches ``y + h Σ_i k_i P_i(θ)`` as δy + h J δy Σ_i P_i(θ)
    to first order, and Σ_i P_i(θ) = θ ≤ 1; each side then rounds its own sum, in chains of
    len(P) + q + 3 on terms up to ``|y| + h |f| Σ_ij |P_ij|`` (the cubic Hermite's: 11 |f|).
    """
    P = TABLEAUX[method].dense
    P = np.full((3, 3), 11 / 9) if P is None else P
    y, f, h = _sizes(python)
    chain = len(P) + P.shape[1] + 3
    return bound * (1 + h * JACOBIAN) + float(sum_bound(y + h * f * np.abs(P).sum(), chain))


def _assert_same(method, compiled, python):
    bound = _bound(method, python)
    assert compiled.status == python.status
    assert (compiled.n_steps, compiled.n_rejected, compiled.nfev) == (
        python.n_steps,
        python.n_rejected,
        python.nfev,
    )
    np.testing.assert_allclose(compiled.t, python.t, rtol=0, atol=bound)
    np.testing.assert_allclose(compiled.y, python.y, rtol=0, atol=bound)
    # g = y_0 crosses zero at speed |y_1| on the interpolant: off by δg, the root moves δg/|y_1|
    near = _interpolant_bound(method, python, bound)
    for ours, theirs in zip(compiled.t_events, python.t_events, strict=True):
        speed = np.abs(python.sol(theirs)[1])
        assert np.all(np.abs(ours - theirs) <= EVENT_XTOL * (1 + np.abs(theirs)) + near / speed)


@RHS
@pytest.mark.parametrize("method", TABLEAUX)
def test_compiled_solve_equals_the_python_path_with_dense_output_and_events(method, rhs):
    runs = [
        solve(
            fun,
            (0, 8),
            [2, 0],
            events=position,
            dense_output=True,
            compiled=compiled,
            **_options(method),
        )  # fmt: skip
        for fun, compiled in _both(rhs)
    ]
    _assert_same(method, *runs)
    assert len(runs[0].t_events[0]) == 2  # Van der Pol crosses y = 0 at t ≈ 2.9 and 6.7
    between = np.linspace(0, runs[1].t[-1], 61)
    near = _interpolant_bound(method, runs[1], _bound(method, runs[1]))
    np.testing.assert_allclose(runs[0].sol(between), runs[1].sol(between), rtol=0, atol=near)


@RHS
@pytest.mark.parametrize("method", ["rk8", "dopri5"])
def test_compiled_solve_stops_at_a_terminal_event_as_the_python_path(method, rhs):
    runs = [
        solve(
            fun,
            (0, 100),
            [2, 0],
            events=_terminal(3),
            dense_output=True,
            compiled=compiled,
            **_options(method),
        )  # fmt: skip
        for fun, compiled in _both(rhs)
    ]
    _assert_same(method, *runs)
    assert runs[0].status == 1 and runs[0].y[0, -1] == pytest.approx(0.0, abs=1e-9)
    assert runs[0].sol.t_max == runs[0].t[-1] < 100


@RHS
def test_compiled_fixed_step_run_reports_a_non_finite_state_as_the_python_path(rhs):
    fun = blow_up if rhs == "numba" else blow_up.py_func
    runs = [solve(f, (0, 2), [1.0], method="rk4", h=0.125, compiled=compiled)
            for f, compiled in ((fun, True), (blow_up.py_func, False))]  # fmt: skip
    assert runs[0].status == -1 and runs[0].message == runs[1].message
    assert "non-finite" in runs[0].message
    np.testing.assert_array_equal(runs[0].t, runs[1].t)
    # Near the pole an rk4 step R(y) multiplies a relative difference by g = d ln R / d ln y
    # (up to 16: R is a polynomial of degree 16 in y), and each step adds the 6 roundings of
    # its stage sums (s + 2, on positive terms): d_{n+1} = g_n d_n + 6 eps.
    rtol = 0.0
    for y in runs[1].y[0, :-1]:
        up, down = (solve(blow_up.py_func, (0, 0.125), [y * (1 + d)], h=0.125,
                          compiled=False).y[0, -1]
                    for d in (1e-7, -1e-7))  # fmt: skip
        rtol = (np.log(up / down) / 2e-7) * rtol + 6 * EPS
    np.testing.assert_allclose(runs[0].y, runs[1].y, rtol=rtol, atol=0)


@RHS
def test_compiled_adaptive_run_stops_at_the_minimum_step_as_the_python_path(rhs):
    fun = blow_up if rhs == "numba" else blow_up.py_func
    runs = [solve(f, (0, 2), [1.0], method="dopri5", compiled=compiled)
            for f, compiled in ((fun, True), (blow_up.py_func, False))]  # fmt: skip
    assert runs[0].status == runs[1].status == -1
    assert "minimum" in runs[0].message and "minimum" in runs[1].message
    assert runs[0].n_steps == runs[1].n_steps
    assert runs[0].t[-1] == pytest.approx(1.0, abs=1e-3)  # the pole of 1 / (1 - t)


@RHS
@pytest.mark.parametrize("method", ["rk4", "dopri5"])
def test_compiled_run_stops_after_max_steps_as_the_python_path(method, rhs):
    runs = [
        solve(fun, (0, 6), [2, 0], max_steps=7, compiled=compiled, **_options(method))
        for fun, compiled in _both(rhs)
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
    options = _options(method)
    _python_steps_forbidden(monkeypatch)
    with pytest.raises(AssertionError, match="in Python"):  # the Python path steps there
        solve(van_der_pol_python, (0, 1), [2, 0], compiled=False, **options)
    for fun in (van_der_pol, van_der_pol_python):
        run = solve(fun, (0, 8), [2, 0], events=position, dense_output=True, **options)
        assert run.status == 0 and len(run.t_events[0]) == 2 and run.sol is not None
