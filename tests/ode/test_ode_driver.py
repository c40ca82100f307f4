"""The driver's contract (tumble.ode.driver), on steppers small enough to check by hand."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tumble.ode.control import fixed_step_count
from tumble.ode.driver import (
    EVENT_BLOCK,
    AdaptiveBlock,
    Block,
    Compiled,
    Control,
    Grid,
    Status,
    Stepper,
    Steps,
    Stops,
    march,
)


class Decay(Stepper):
    """Explicit Euler on y' = −y: y_{k+1} = (1 − h) y_k, exactly representable for h = 2⁻ᵏ."""

    def step(self, t, y, h):
        return y - h * y, None


class BlockDecay(Decay):
    """The same steps, marched in blocks by a compiled part (as the kernels are)."""

    def __init__(self, block_steps=None):
        self.block_steps, self.calls = block_steps, []

    @property
    def compiled(self):
        return Compiled(self.march_block, block_steps=self.block_steps)

    def march_block(self, y, grid, k0, k1, every, step0):
        self.calls.append((k0, k1, step0))
        times, samples = [], []
        for k in range(k0 + 1, k1 + 1):
            t_old = grid.time(k - 1)
            new, _ = self.step(t_old, y, grid.time(k) - t_old)
            if not np.all(np.isfinite(new)):
                return Block(np.array(times), (np.array(samples),), y, failed=k)
            y = new
            if (step0 + k) % every == 0:
                times.append(grid.time(k))
                samples.append(y)
        return Block(np.array(times), (np.array(samples).reshape(-1, y.size),), y)


class Blowup(Decay):
    """y' = y² by Euler: from y = 1 with h = 0.5 the state overflows after a few steps."""

    def step(self, t, y, h):
        return y + h * y * y * 1e100, None


def run(stepper, **options):
    options.setdefault("h", 0.25)
    return march(stepper, (0.0, 1.0), np.array([1.0]), **options)


def test_status_codes_are_scipys():
    assert (Status.SUCCESS, Status.TERMINAL_EVENT, Status.FAILED) == (0, 1, -1)
    assert Status.SUCCESS.success and Status.TERMINAL_EVENT.success
    assert not Status.FAILED.success


def test_fixed_steps_land_on_the_end_and_record_every_kth():
    out = run(Decay(), h=0.3, record_every=2)
    # steps end at 0.3, 0.6, 0.9, 1.0: recorded at the 2nd and 4th, and the start
    np.testing.assert_allclose(out.t, [0.0, 0.6, 1.0])
    assert out.t[-1] == 1.0 and out.n_steps == 4 and out.status == Status.SUCCESS
    expected = [1.0, 0.7**2, 0.7**3 * 0.9]
    # Three steps y − h y of two roundings each (the product's weighs h / (1 − h) < 1) and the
    # reference's own: ≤ 8 u = 4 eps < 1e-15 relative. Elementwise IEEE operations, each
    # correctly rounded, give these bits on every machine.
    np.testing.assert_allclose(out.records[0][:, 0], expected, rtol=1e-15)


@pytest.mark.parametrize("block_steps", [None, 1, 3])
@pytest.mark.parametrize("every", [1, 3, 7])
def test_blocks_give_the_python_paths_record(block_steps, every):
    python = march(Decay(), (0.0, 2.0), np.array([1.0]), h=0.1, record_every=every)
    stepper = BlockDecay(block_steps)
    blocks = march(stepper, (0.0, 2.0), np.array([1.0]), h=0.1, record_every=every)
    # the same elementwise IEEE operations in the same order: the same bits on any machine
    np.testing.assert_array_equal(blocks.t, python.t)
    np.testing.assert_array_equal(blocks.records[0], python.records[0])
    assert blocks.n_steps == python.n_steps == 20
    if block_steps is None:
        assert len(stepper.calls) == 1


def test_events_and_dense_output_take_the_python_path():
    stepper = BlockDecay()
    out = run(stepper, dense_output=True)
    assert stepper.calls == [] and len(out.interpolants) == out.n_steps == 4


def _part(**given):
    def march_block(*args):
        raise AssertionError

    return Compiled(march_block, **given)


@pytest.mark.parametrize(
    ("given", "takes"),
    [
        (dict(), {(False, False)}),
        (dict(steps=True), {(False, False), (False, True)}),
        (dict(march_adaptive=print), {(False, False), (True, False)}),
        (dict(march_adaptive=print, steps=True), {(a, f) for a in (0, 1) for f in (0, 1)}),
    ],
    ids=["fixed", "fixed-with-steps", "adaptive", "adaptive-with-steps"],
)
def test_a_compiled_part_takes_the_runs_its_blocks_can_march(given, takes):
    part = _part(**given)
    for adaptive in (False, True):
        for follows in (False, True):
            assert part.takes(adaptive, follows) == ((adaptive, follows) in takes)


class SettlingDecay(BlockDecay):
    """Euler on y' = −y whose blocks, as the axes flow's loop, owe the factors (1 − h) of the
    steps since the last recorded one and apply them as one product only where the state is
    recorded or handed back: the numbers then depend on where the blocks end."""

    def march_block(self, y, grid, k0, k1, every, step0):
        self.calls.append((k0, k1, step0))
        times, samples, owed = [], [], 1.0
        for k in range(k0 + 1, k1 + 1):
            owed *= 1 - (grid.time(k) - grid.time(k - 1))
            if (step0 + k) % every == 0 or k == k1:
                y, owed = y * owed, 1.0
            if (step0 + k) % every == 0:
                times.append(grid.time(k))
                samples.append(y)
        return Block(np.array(times), (np.array(samples).reshape(-1, y.size),), y)


@pytest.mark.parametrize("block_steps", [3, 4, 5, 7, "progress"])
def test_blocks_end_on_recorded_steps_so_that_their_sizes_change_no_number(block_steps):
    y0, every, times = np.array([1 / 3]), 3, []
    one = march(SettlingDecay(), (0.0, 20.0), y0, h=0.1, record_every=every)
    if block_steps == "progress":  # about PROGRESS_BLOCKS blocks of whole samples: 4 steps
        stepper = SettlingDecay()
        out = march(stepper, (0.0, 20.0), y0, h=0.1, record_every=every, progress=times.append)
        assert len(stepper.calls) == 34 and times[-1] == 20.0
    else:
        stepper = SettlingDecay(block_steps)
        out = march(stepper, (0.0, 20.0), y0, h=0.1, record_every=every)
    for k0, k1, step0 in stepper.calls:  # each ends on a recorded step, or at the grid's end
        assert k1 == 200 or (step0 + k1) % every == 0
        assert block_steps == "progress" or k1 - k0 <= block_steps
    np.testing.assert_array_equal(out.records[0], one.records[0])
    np.testing.assert_array_equal(out.state, one.state)
    # the owed product settled at step 5, not a recorded step, changes the bits
    grid = Grid(0.0, 20.0, 0.1, 200)
    first = stepper.march_block(y0, grid, 0, 5, every, 0).state
    settled = stepper.march_block(first, grid, 5, 200, every, 0).records[0]
    assert not np.array_equal(settled, one.records[0][2:])


def test_block_steps_bounds_every_block_which_ends_early_on_a_recorded_step():
    stepper = BlockDecay(block_steps=2)  # a bound on the work of a call: never exceeded
    march(stepper, (0.0, 1.0), np.array([1.0]), h=0.1, record_every=5)
    # (4, 6] holds step 5, recorded: that block ends there; (0, 2] and (2, 4] hold none
    blocks = [(k0, k1) for k0, k1, _ in stepper.calls]
    assert blocks == [(0, 2), (2, 4), (4, 5), (5, 7), (7, 9), (9, 10)]


class StepsDecay(BlockDecay):
    """BlockDecay whose blocks also return their steps and interpolants (Block.steps)."""

    def __init__(self):
        super().__init__()
        self.steps, self.rewound = 0, None

    @property
    def compiled(self):
        return Compiled(self.march_block, rewind=self.rewind, steps=True)

    def march_block(self, y, grid, k0, k1, every, step0):
        times = [grid.time(k) for k in range(k0, k1 + 1)]
        states = [y]
        for i in range(k1 - k0):
            states.append(self.step(times[i], states[-1], times[i + 1] - times[i])[0])
        self.steps += k1 - k0
        block = super().march_block(y, grid, k0, k1, every, step0)
        sols = [
            self.interpolant(times[i], states[i], times[i + 1], states[i + 1])
            for i in range(k1 - k0)
        ]
        block.steps = Steps(np.array(times[1:]), states[1:], sols)
        return block

    def rewind(self, block, index):
        self.rewound = (block.steps.t[index], self.steps - len(block.steps.t) + index + 1)


def _crossing(terminal):
    def below_tenth(t, y):
        return y[0] - 0.1

    below_tenth.terminal = terminal
    return below_tenth


@pytest.mark.parametrize(
    "options",
    [
        dict(events=[_crossing(False)], record_every=3),
        dict(events=[_crossing(True)], record_every=3),
        dict(events=[_crossing(True)], dense_output=True),
        dict(dense_output=True),
        dict(t_eval=np.linspace(0.05, 4.0, 33)),
    ],
    ids=["event", "terminal-event", "terminal-event-dense", "dense", "t_eval"],
)
def test_blocks_with_steps_give_the_python_paths_events_dense_output_and_t_eval(options):
    python = march(Decay(), (0.0, 5.0), np.array([1.0]), h=1 / 128, **options)
    stepper = StepsDecay()
    blocks = march(stepper, (0.0, 5.0), np.array([1.0]), h=1 / 128, **options)
    assert stepper.calls  # marched in blocks, not in Python
    assert (blocks.status, blocks.n_steps) == (python.status, python.n_steps)
    # Both march Decay's Python steps (elementwise IEEE operations, no BLAS, no SIMD maths) and
    # its interpolant on the same times: the same bits on any machine (equal, measured).
    np.testing.assert_array_equal(blocks.t, python.t)
    np.testing.assert_allclose(blocks.records[0], python.records[0], rtol=1e-15)
    np.testing.assert_array_equal(blocks.t_events, python.t_events)
    if python.step_times is not None:
        np.testing.assert_array_equal(blocks.step_times, python.step_times)
        middles = (np.array(python.step_times[:-1]) + python.step_times[1:]) / 2
        for ours, theirs, t in zip(blocks.interpolants, python.interpolants, middles,
                                   strict=True):  # fmt: skip
            assert ours(t) == theirs(t)


def test_a_terminal_event_in_a_block_ends_the_run_there_with_that_steps_counters():
    stepper = StepsDecay()
    out = march(stepper, (0.0, 5.0), np.array([1.0]), h=1 / 128, events=[_crossing(True)])
    # (1 − 1/128)^k falls below 0.1 in step k = 294: the second block of EVENT_BLOCK steps
    k = int(np.ceil(np.log(0.1) / np.log(1 - 1 / 128)))
    assert out.status == Status.TERMINAL_EVENT and out.n_steps == k == 294
    assert stepper.steps == 2 * EVENT_BLOCK  # the blocks stop at EVENT_BLOCK steps with events
    assert stepper.rewound == (k / 128, k)
    assert (k - 1) / 128 < out.t[-1] == out.t_events[0][0] < k / 128


@pytest.mark.parametrize("make", [Blowup, lambda: type("B", (BlockDecay, Blowup), {})()])
def test_a_non_finite_step_fails_and_keeps_the_last_finite_state(make):
    with np.errstate(over="ignore"):
        out = march(make(), (0.0, 10.0), np.array([1.0]), h=0.5)
    assert out.status == Status.FAILED
    assert np.all(np.isfinite(out.records[0])) and np.isfinite(out.state).all()
    t_last = float(out.t[-1])
    assert out.message.startswith("the state became non-finite")
    assert f"from t={t_last!r} to t={t_last + 0.5!r}" in out.message


@pytest.mark.parametrize("stepper", [Decay(), BlockDecay()], ids=["python", "blocks"])
def test_max_steps_ends_the_run_with_a_failure_naming_t(stepper):
    out = run(stepper, h=0.1, max_steps=4)
    assert out.status == Status.FAILED and out.n_steps == 4
    assert "max_steps=4" in out.message and f"t={float(out.t[-1])!r}" in out.message
    assert out.t[-1] == pytest.approx(0.4)


def test_a_jump_lands_a_step_and_replaces_the_sample_before_it():
    def double(y):
        return 2 * y

    out = run(Decay(), h=0.25, jumps=[(0.5, double), (1.0, double)])
    np.testing.assert_allclose(out.t, [0.0, 0.25, 0.5, 0.75, 1.0])
    # 0.75² before the jump at 0.5, doubled; the jump at the end applies after the last step
    np.testing.assert_allclose(out.records[0][:, 0], [1, 0.75, 1.125, 0.84375, 1.265625])


def test_a_jump_at_the_start_replaces_the_initial_sample():
    out = run(Decay(), jumps=[(0.0, lambda y: 3 * y)])
    assert out.t[0] == 0.0 and out.t[1] == 0.25
    assert out.records[0][0, 0] == 3.0


def test_a_terminal_event_stops_the_run_where_it_crossed():
    def below_half(t, y):
        return y[0] - 0.5

    below_half.terminal = True
    out = march(Decay(), (0.0, 5.0), np.array([1.0]), h=0.25, events=[below_half])
    assert out.status == Status.TERMINAL_EVENT and out.message == "A terminal event occurred."
    # the default interpolant is a step of the stepper from the last state: (1 − τ) y
    (t_root,) = out.t_events[0]
    y_old = 0.75**2
    assert t_root == pytest.approx(0.5 + (1 - 0.5 / y_old), abs=1e-12)
    assert out.t[-1] == t_root and out.records[0][-1, 0] == pytest.approx(0.5, abs=1e-12)


class Controlled(Stepper):
    """Euler with the Heun estimate on y' = −y: error order 1."""

    error_order = 1

    def step(self, t, y, h):
        euler = y - h * y
        heun = y - 0.5 * h * (y + euler)
        return heun, heun - euler


def test_adaptive_control_reaches_the_end_within_tolerance():
    out = march(Controlled(), (0.0, 2.0), np.array([1.0]), h=0.1, control=Control(1e-6, 1e-9))
    assert out.status == Status.SUCCESS and out.t[-1] == 2.0
    assert out.records[0][-1, 0] == pytest.approx(np.exp(-2.0), rel=1e-4)
    assert out.n_rejected >= 0 and out.n_steps > 10


class ControlledBlowup(Controlled):
    """The same pair on y' = y², whose solution 1/(1 − t) blows up at t = 1."""

    def step(self, t, y, h):
        euler = y + h * y * y
        heun = y + 0.5 * h * (y * y + euler * euler)
        return heun, heun - euler


def test_adaptive_control_fails_below_the_minimum_step():
    with np.errstate(over="ignore", invalid="ignore"):
        out = march(ControlledBlowup(), (0.0, 2.0), np.array([1.0]), h=0.1,
                    control=Control(1e-3, 1e-6), max_steps=10**5)  # fmt: skip
    assert out.status == Status.FAILED and "minimum" in out.message, out.message
    assert abs(out.t[-1] - 1.0) < 1e-2  # where y = 1/(1 − t) blows up


@given(
    n=st.integers(min_value=1, max_value=60),
    every=st.integers(min_value=1, max_value=9),
    block=st.integers(min_value=1, max_value=25),
)
def test_record_times_are_every_kth_grid_time_and_the_end(n, every, block):
    h = 1.0 / n
    out = march(BlockDecay(block), (0.0, 1.0), np.array([1.0]), h=h, record_every=every)
    grid = Grid(0.0, 1.0, h, fixed_step_count(0.0, 1.0, h))
    expected = [0.0] + [grid.time(k) for k in range(every, grid.n + 1, every)]
    if expected[-1] != 1.0:
        expected.append(1.0)
    np.testing.assert_array_equal(out.t, expected)  # both from grid_time: t0 + k h, or t1


def test_a_record_too_large_for_memory_is_refused_before_allocating():
    import tumble

    body = tumble.RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))
    with pytest.raises(
        ValueError, match=r"record 1e\+10 samples of \d+ bytes \(1.\d+ TiB\).*record_every >= "
    ):
        tumble.simulate(body, 1e4, h=1e-6, omega0=[1, 0, 0])
    with pytest.raises(ValueError, match="would never finish: raise h"):
        tumble.simulate(body, 1.0, h=1e-300, omega0=[1, 0, 0])


def test_the_suggested_record_every_makes_the_run_fit(monkeypatch):
    import re

    import tumble
    from tumble.ode import driver

    monkeypatch.setattr(driver, "_memory", lambda: 1e6)  # a 1 MB machine: 0.5 MB for records
    body = tumble.RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))
    with pytest.raises(ValueError, match="record_every >= ") as refused:
        tumble.simulate(body, 10.0, h=1e-3, omega0=[1, 0, 0])
    every = int(re.search(r"record_every >= (\d+)", str(refused.value)).group(1))
    run = tumble.simulate(body, 10.0, h=1e-3, omega0=[1, 0, 0], record_every=every)
    assert run.status == 0 and run.t[-1] == 10.0
    with pytest.raises(ValueError, match="record_every >= "):
        tumble.simulate(body, 10.0, h=1e-3, omega0=[1, 0, 0], record_every=every // 2)


def test_only_a_compiled_part_with_adaptive_blocks_may_be_left_to_choose_the_first_step():
    with pytest.raises(TypeError, match="march needs h"):
        march(Controlled(), (0.0, 1.0), np.array([1.0]), h=None, control=Control(1e-6, 1e-9))
    with pytest.raises(TypeError, match="march needs h"):
        march(BlockDecay(), (0.0, 1.0), np.array([1.0]), h=None)


class GivesUp(Controlled):
    """Controlled whose ``accept`` refuses the steps ending after t = 0.5, finite as they are
    (as an implicit stepper refuses a step whose solve did not converge)."""

    def accept(self, t_old, old, t_new, new):
        if t_new > 0.5:
            return f"gave up from t={t_old} to t={t_new}"
        return super().accept(t_old, old, t_new, new)


@pytest.mark.parametrize(
    ("control", "t_old", "t_new"),
    [(None, 0.5, 0.75), (Control(1.0, 1.0), 0.25, 1.0)],
    ids=["fixed", "adaptive"],
)
def test_a_refused_step_fails_the_run_with_the_steppers_reason_and_the_state_before(
    control, t_old, t_new
):
    # Heun's step multiplies by 1 − h + h²/2 = 25/32 at h = 1/4, exactly; the adaptive run's
    # second step, 0.9 · (norm 1/64)^(−1/2) = 7.2 times the first, is cut at t1 = 1
    out = run(GivesUp(), control=control)
    assert out.status == Status.FAILED and out.message == f"gave up from t={t_old} to t={t_new}"
    assert out.t[-1] == t_old and out.state[0] == out.records[0][-1, 0] == (25 / 32) ** (4 * t_old)


class BlockGivesUp(BlockDecay):
    """BlockDecay whose blocks refuse grid step 3, saying why (``Block.message``)."""

    def march_block(self, y, grid, k0, k1, every, step0):
        if k0 < 3 <= k1:
            block = super().march_block(y, grid, k0, 2, every, step0)
            return Block(block.t, block.records, block.state, failed=3, message="step 3: no")
        return super().march_block(y, grid, k0, k1, every, step0)


def test_a_blocks_failure_ends_the_run_with_its_message_and_the_state_before():
    out = run(BlockGivesUp(block_steps=2))
    assert out.status == Status.FAILED and out.message == "step 3: no"
    assert out.n_steps == 2 and out.t[-1] == 0.5 and out.state[0] == 0.75**2


class CannedAdaptive(Controlled):
    """A compiled adaptive part that hands the driver canned blocks: 3 steps to t = 0.3 (one
    rejected), then 2 to 0.7 (two rejected), then the failure ``ending``."""

    def __init__(self, ending, finite=True):
        self.ending, self.finite, self.calls = ending, finite, []

    @property
    def compiled(self):
        return Compiled(print, march_adaptive=self.march_adaptive)

    def march_adaptive(self, y, t, t1, h, control, every, step0, max_steps):
        self.calls.append((t, h, step0))
        if t == 0.0:
            return AdaptiveBlock(np.array([0.3]), (np.array([[3.0]]),), y, 0.3, 0.2, 3, 1)
        if t == 0.3:
            return AdaptiveBlock(np.array([0.7]), (np.array([[7.0]]),), y, 0.7, 0.1, 2, 2)
        return AdaptiveBlock(np.empty(0), (np.empty((0, 1)),), y, 0.7, 0.0, 0, 5,
                             failure=self.ending, t_failed=0.8, finite=self.finite)  # fmt: skip


@pytest.mark.parametrize(
    ("ending", "finite", "message"),
    [
        ("non-finite", True, "non-finite (nan or inf) in the step from t=0.7 to t=0.8"),
        ("minimum-step", True, "step size fell below the minimum 1.11e-15 at t=0.7"),  # 10 ulp
        ("minimum-step", False, "non-finite (nan or inf) in every step tried from t=0.7"),
    ],
)
def test_adaptive_blocks_add_up_their_counters_and_end_with_their_failure(ending, finite,
                                                                          message):  # fmt: skip
    stepper = CannedAdaptive(ending, finite)
    out = run(stepper, h=0.05, control=Control(1e-6, 1e-9))
    # each block starts where the last ended, with its proposed step and the steps so far
    assert stepper.calls == [(0.0, 0.05, 0), (0.3, 0.2, 3), (0.7, 0.1, 5)]
    assert (out.n_steps, out.n_rejected, out.status) == (5, 8, Status.FAILED)
    assert message in out.message
    np.testing.assert_array_equal(out.t, [0.0, 0.3, 0.7])
    np.testing.assert_array_equal(out.records[0][:, 0], [1.0, 3.0, 7.0])


class Decays(Stepper):
    """N members of y' = −y by Euler, marched at once by a compiled part (members first in
    the records): member 1 overflows in grid step 7, member 2's step 12 is refused ("gave
    up"); a member that stopped is not marched again."""

    time_axis = 1

    def __init__(self, n, block_steps=None):
        self.failed, self.block_steps = np.full(n, -1), block_steps

    @property
    def compiled(self):
        return Compiled(self.march_block, block_steps=self.block_steps)

    def record(self, y):
        return (y[:, None],)

    def march_block(self, y, grid, k0, k1, every, step0):
        y, n = y.copy(), len(y)
        recorded_steps = [k for k in range(k0 + 1, k1 + 1) if (step0 + k) % every == 0]
        samples = np.full((n, len(recorded_steps)), -1.0)  # what a stopped member leaves
        recorded, failed, messages = np.zeros(n, dtype=int), np.full(n, -1), {}
        for m in np.flatnonzero(self.failed < 0):
            for k in range(k0 + 1, k1 + 1):
                h = grid.time(k) - grid.time(k - 1)
                new = np.inf if (m, k) == (1, 7) else y[m] * (1 - h)
                if not np.isfinite(new) or (m, k) == (2, 12):
                    failed[m] = self.failed[m] = k
                    if m == 2:
                        messages[m] = "member 2 gave up"
                    break
                y[m] = new
                if (step0 + k) % every == 0:
                    samples[m, recorded[m]] = new
                    recorded[m] += 1
        times = np.array([grid.time(k) for k in recorded_steps])
        return Block(times, (samples,), y, stops=Stops(recorded, failed, messages))


def test_members_stop_alone_and_the_outcome_says_how_each_ended():
    out = march(Decays(4), (0.0, 5.0), np.ones(4), h=0.25, record_every=3)
    np.testing.assert_array_equal(out.t, [0.0, 0.75, 1.5, 2.25, 3.0, 3.75, 4.5, 5.0])
    members = out.members
    assert out.status == Status.SUCCESS and out.n_steps == 20
    np.testing.assert_array_equal(members.status, [0, -1, -1, 0])
    np.testing.assert_array_equal(members.n_steps, [20, 6, 11, 20])
    np.testing.assert_array_equal(members.t_last, [5.0, 1.5, 2.75, 5.0])
    np.testing.assert_array_equal(members.n_recorded, [8, 3, 5, 8])
    assert members.messages[0] == members.messages[3] == Status.SUCCESS.message
    assert members.messages[1].startswith(
        "the state became non-finite (nan or inf) in the step from t=1.5 to t=1.75"
    )
    assert members.messages[2] == "member 2 gave up"
    # 0.75^k exactly: the samples of steps 0, 3, 6, …; member 1 ends at step 6 (recorded),
    # member 2 with its last finite state, step 11, after its samples; NaN after
    powers = 0.75 ** np.array([0, 3, 6, 9, 12, 15, 18, 20])
    expected = np.array([powers, powers, powers, powers])
    expected[1, 3:] = np.nan
    expected[2, 4], expected[2, 5:] = 0.75**11, np.nan
    np.testing.assert_array_equal(out.records[0], expected)
    np.testing.assert_array_equal(out.state, [0.75**20, 0.75**6, 0.75**11, 0.75**20])


@pytest.mark.parametrize("block_steps", [1, 2, 3, 5, 8])
@pytest.mark.parametrize("every", [1, 3])
def test_members_have_the_same_outcome_in_one_block_or_many(block_steps, every):
    one = march(Decays(4), (0.0, 5.0), np.ones(4), h=0.25, record_every=every)
    many = march(Decays(4, block_steps), (0.0, 5.0), np.ones(4), h=0.25, record_every=every)
    np.testing.assert_array_equal(many.t, one.t)
    np.testing.assert_array_equal(many.records[0], one.records[0])
    for name in ("status", "n_steps", "n_recorded", "t_last"):
        np.testing.assert_array_equal(getattr(many.members, name), getattr(one.members, name))
    assert many.members.messages == one.members.messages


def test_a_run_of_one_member_has_no_members():
    assert run(Decay()).members is None and run(BlockDecay()).members is None


class Judged(Controlled):
    """Controlled whose own norm says every error is 0: the controller then grows each step
    by its largest factor (MAX_FACTOR = 10)."""

    def __init__(self):
        self.seen = []

    def norm(self, error, old, new, control):
        self.seen.append((error[0], old[0], new[0]))
        return 0.0


def test_the_steppers_norm_is_what_the_controller_judges():
    stepper = Judged()
    out = march(stepper, (0.0, 2.0), np.array([1.0]), h=0.01, control=Control(1e-6, 1e-9))
    # steps of 0.01, 0.1 and 1, the last cut to land on t1 (the default norm would reject)
    np.testing.assert_allclose(out.t, [0.0, 0.01, 0.11, 1.11, 2.0], rtol=1e-15)
    assert out.n_rejected == 0 and len(stepper.seen) == 4
    for (error, old, new), t_old, t_new, y_old in zip(
        stepper.seen, out.t[:-1], out.t[1:], out.records[0][:-1, 0], strict=True
    ):  # each call: the step's error estimate, its start and its end
        new_state, estimate = Controlled().step(t_old, np.array([y_old]), t_new - t_old)
        assert (error, old, new) == (estimate[0], y_old, new_state[0])
