"""Events located on the dense output: terminal, direction, several at once."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tumble import solve
from tumble.ode.events import SAMPLES_PER_STEP


def oscillator(t, y):
    return np.array([y[1], -y[0]])


def position(t, y):
    return y[0]


def _event(fun, terminal=False, direction=0):
    def event(t, y):
        return fun(t, y)

    event.terminal, event.direction = terminal, direction
    return event


ZEROS = np.pi / 2 + np.pi * np.arange(3)  # cos t crosses zero at π/2, 3π/2, 5π/2 in [0, 10]


@pytest.mark.parametrize(
    ("direction", "expected"), [(0, ZEROS), (1, ZEROS[1:2]), (-1, ZEROS[0::2])]
)
def test_non_terminal_event_finds_crossings_in_its_direction(direction, expected):
    event = _event(position, direction=direction)
    result = solve(oscillator, (0, 10), [1, 0], method="dopri5", rtol=1e-10, events=event)
    np.testing.assert_allclose(result.t_events[0], expected, atol=1e-8)
    assert result.status == 0 and result.t[-1] == 10.0


def test_event_states_lie_on_the_solution():
    event = _event(position)
    result = solve(oscillator, (0, 10), [1, 0], method="dopri5", rtol=1e-10, events=event)
    np.testing.assert_allclose(result.y_events[0][:, 0], 0.0, atol=1e-9)
    np.testing.assert_allclose(result.y_events[0][:, 1], -np.sin(ZEROS), atol=1e-8)


def test_terminal_event_stops_the_run_at_the_root():
    event = _event(position, terminal=True)
    result = solve(oscillator, (0, 10), [1, 0], h=0.01, events=event)
    assert result.status == 1
    assert result.t[-1] == pytest.approx(np.pi / 2, abs=1e-9)
    assert result.y[0, -1] == pytest.approx(0.0, abs=1e-9)


def test_terminal_count_stops_at_that_occurrence():
    event = _event(position, terminal=2)
    result = solve(oscillator, (0, 10), [1, 0], h=0.01, events=event)
    assert result.status == 1
    np.testing.assert_allclose(result.t_events[0], ZEROS[:2], atol=1e-8)
    assert result.t[-1] == pytest.approx(ZEROS[1], abs=1e-8)


def test_several_events_at_once_each_recorded_until_the_terminal_one():
    velocity = _event(lambda t, y: y[1])  # -sin t: zeros at π, 2π, 3π
    half = _event(lambda t, y: y[0] - 0.5, terminal=True, direction=1)  # cos t = ½ rising
    crossing = _event(position)
    result = solve(
        oscillator, (0, 10), [1, 0], method="dopri5", rtol=1e-10, events=[velocity, half, crossing]
    )
    t_stop = 2 * np.pi - np.pi / 3
    assert result.status == 1 and result.t[-1] == pytest.approx(t_stop, abs=1e-8)
    np.testing.assert_allclose(result.t_events[0], [np.pi], atol=1e-8)
    np.testing.assert_allclose(result.t_events[1], [t_stop], atol=1e-8)
    np.testing.assert_allclose(result.t_events[2], ZEROS[:2], atol=1e-8)


def test_event_starting_on_zero_does_not_fire_at_t0():
    ground = _event(lambda t, y: y[0], terminal=True, direction=-1)
    result = solve(lambda t, y: [y[1], -9.81], (0, 10), [0, 10], h=0.01, events=ground)
    assert result.t[-1] == pytest.approx(2 * 10 / 9.81, rel=1e-12)


def test_projectile_impact_is_located_by_the_event():
    # SPEC §4: 500 m/s at 45°, g = 9.81, rk4 h = 0.01: t = 72.080202 s, x = 25484.1998 m.
    # RK4 is exact for this polynomial motion, so the event sees the exact parabola.
    v = 500 / np.sqrt(2)
    ground = _event(lambda t, y: y[1], terminal=True, direction=-1)
    result = solve(
        lambda t, y: [y[2], y[3], 0, -9.81], (0, 100), [0, 0, v, v], h=0.01, events=ground
    )
    assert result.t_events[0][0] == pytest.approx(72.080202, rel=1e-6)
    assert result.y_events[0][0, 0] == pytest.approx(25484.1998, rel=1e-6)


def test_bad_terminal_attribute_is_refused():
    event = _event(position, terminal=-1)
    with pytest.raises(ValueError, match="terminal"):
        solve(oscillator, (0, 1), [1, 0], h=0.1, events=event)


def test_bad_direction_attribute_is_refused():
    event = _event(position, direction=2)
    with pytest.raises(ValueError, match="direction"):
        solve(oscillator, (0, 1), [1, 0], h=0.1, events=event)


def test_two_crossings_inside_one_step_are_both_found():
    # The case: rk4 with h = 4 on y'' = -y. Step [4, 8] holds two zeros of its own
    # dense output, with g of one sign at both ends; every zero of the interpolant is found.
    event = _event(position)
    result = solve(oscillator, (0, 12), [1, 0], method="rk4", h=4, events=event, dense_output=True)
    times = np.linspace(0, 12, 120_001)
    values = result.sol(times)[0]
    zeros = times[np.flatnonzero(np.diff(np.sign(values)))]
    assert len(result.t_events[0]) == len(zeros) == 3
    np.testing.assert_allclose(result.t_events[0], zeros, atol=1e-4)


@settings(max_examples=60, deadline=None)
@given(frequency=st.floats(0.5, 20.0), phase=st.floats(0.0, 2 * np.pi), steps=st.integers(1, 30))
def test_every_crossing_farther_apart_than_a_sub_interval_is_found(frequency, phase, steps):
    # g = sin(ωt + φ) has zeros π/ω apart; with h < SAMPLES_PER_STEP π/ω none may be missed.
    t_end = 10.0
    h = min(t_end / steps, 0.95 * SAMPLES_PER_STEP * np.pi / frequency)

    def g(t, y):
        return np.sin(frequency * t + phase)

    result = solve(lambda t, y: -y, (0, t_end), [1.0], h=h, events=g)
    k = np.arange(np.ceil(phase / np.pi), np.floor((frequency * t_end + phase) / np.pi) + 1)
    zeros = (k * np.pi - phase) / frequency
    inside = (zeros > 1e-6) & (zeros < t_end - 1e-6)  # g(0), g(t_end) may round to either sign
    found = np.asarray(result.t_events[0])
    found = found[(found > 1e-6) & (found < t_end - 1e-6)]
    np.testing.assert_allclose(found, zeros[inside], atol=1e-9)
