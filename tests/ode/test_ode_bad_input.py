"""Misuse of solve gets a ValueError naming the argument, the value and what is allowed."""

import numpy as np
import pytest

from tumble import solve


def decay(t, y):
    return -y


@pytest.mark.parametrize("h", [0.0, -0.1, np.nan, np.inf])
def test_bad_step_is_refused(h):
    with pytest.raises(ValueError, match=r"h=.*finite and > 0"):
        solve(decay, (0, 1), [1.0], h=h)


def test_missing_step_for_fixed_method_is_refused():
    with pytest.raises(ValueError, match="h=None.*'rk4'.*adaptive"):
        solve(decay, (0, 1), [1.0], method="rk4")


def test_unknown_method_lists_the_known_ones():
    with pytest.raises(ValueError, match=r"method='rk5'.*one of 'euler', 'heun'"):
        solve(decay, (0, 1), [1.0], method="rk5", h=0.1)


@pytest.mark.parametrize("rtol", [0.0, -1e-6, np.nan])
def test_non_positive_rtol_is_refused(rtol):
    with pytest.raises(ValueError, match="rtol="):
        solve(decay, (0, 1), [1.0], method="dopri5", rtol=rtol)


def test_rtol_below_round_off_is_refused():
    with pytest.raises(ValueError, match="rtol=1e-20"):
        solve(decay, (0, 1), [1.0], method="dopri5", rtol=1e-20)


def test_negative_atol_is_refused():
    with pytest.raises(ValueError, match="atol="):
        solve(decay, (0, 1), [1.0], method="dopri5", atol=-1.0)


@pytest.mark.parametrize("t_span", [(1, 0), (0, 0), (0, np.inf), (0,)])
def test_reversed_empty_or_bad_span_is_refused(t_span):
    with pytest.raises(ValueError, match="t_span="):
        solve(decay, t_span, [1.0], h=0.1)


@pytest.mark.parametrize("y0", [[np.nan], [1.0, np.inf], [], [[1.0]]])
def test_non_finite_or_malformed_initial_state_is_refused(y0):
    with pytest.raises(ValueError, match=r"y0(\[\d+\])?="):
        solve(decay, (0, 1), y0, h=0.1)


@pytest.mark.parametrize("max_steps", [0, -5, 2.5])
def test_bad_max_steps_is_refused(max_steps):
    with pytest.raises(ValueError, match="max_steps="):
        solve(decay, (0, 1), [1.0], h=0.1, max_steps=max_steps)


def test_non_callable_event_is_refused():
    with pytest.raises(ValueError, match=r"events\[0\]"):
        solve(decay, (0, 1), [1.0], h=0.1, events=[1.0])
