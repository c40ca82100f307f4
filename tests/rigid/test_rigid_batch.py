"""simulate_batch: the numbers of N single simulate runs, a body axis, and clear refusals."""

import re

import numba
import numpy as np
import pytest
from roundoff import sum_bound

from tumble import so3
from tumble.rigid import (
    METHODS,
    Force,
    Gravity,
    Impulse,
    MagneticDipole,
    RigidBody,
    Torque,
    simulate,
    simulate_batch,
    soa,
)
from tumble.rigid import batch as batch_module
from tumble.rigid.batch import FIXED_METHODS, SOA_FAMILIES, SOA_MIN_BODIES
from tumble.rigid.soa import BLOCK

FIXED = [name for name, method in METHODS.items() if not method.adaptive and not method.exact]
"""The fixed-step methods that take loads (the exact flow takes none: test_rigid_geometric)."""
LOADS = [
    Gravity(),
    Force((0.1, 0.2, 0.3), point=(0.1, 0.0, 0.05)),
    Force((0.0, -0.5, 0.0)),
    Torque((0.01, 0.0, -0.02)),
    MagneticDipole((0.2, -0.1, 0.3), (0.0, 0.5, 0.4)),
]
FIELDS = ["t", "x", "v", "R", "L_world", "q", "omega_body", "energy", "orthogonality_error"]
RNG = np.random.default_rng(7)
N = 3
OMEGA0, X0, V0 = RNG.normal(size=(N, 3)), RNG.normal(size=(N, 3)), RNG.normal(size=(N, 3))
R0 = so3.exp(RNG.normal(size=(N, 3)))


@pytest.fixture(scope="module")
def body():
    return RigidBody(2.0, [[2.0, 0.1, 0.0], [0.1, 1.5, 0.05], [0.0, 0.05, 1.0]])


@pytest.fixture(scope="module")
def bodies():
    return [
        RigidBody(1.0, [1.0, 2.0, 2.5]),
        RigidBody(3.0, [[2.0, 0.1, 0.0], [0.1, 1.5, 0.05], [0.0, 0.05, 1.0]]),
        RigidBody(0.5, [2.0, 1.0, 2.0 / 3.0], allow_unphysical=True),
    ]


def assert_same_as_single_runs(batch, single_runs):
    """Bit for bit: the batch runs the same compiled loop as simulate, on the same numbers.

    Portable: numba compiles both without fastmath, so neither contracts a multiply and an
    add into an FMA nor reassociates a sum, and vectorising a loop over bodies (SLP or loop
    vectoriser, SSE2 to AVX-512) repeats the same IEEE operations in each lane; the derived
    quantities are the same NumPy function of the same arrays on both sides. Checked under
    ``NUMBA_CPU_NAME=generic`` as on the host.
    """
    assert len(batch) == len(single_runs)
    for k, single in enumerate(single_runs):
        for name in FIELDS:
            np.testing.assert_array_equal(getattr(batch[k], name), getattr(single, name), name)
        assert batch[k].settings == single.settings
        assert (batch[k].n_steps, batch[k].status) == (single.n_steps, single.status)
        assert batch[k].message == single.message


@pytest.mark.parametrize("method", FIXED)
def test_one_body_from_n_states_matches_n_single_runs_under_all_loads(body, method):
    options = dict(method=method, h=0.03, forces=LOADS, record_every=4)  # 34 steps: end added
    batch = simulate_batch(body, 1.0, omega0=OMEGA0, x0=X0, v0=V0, R0=R0, **options)
    singles = [
        simulate(body, 1.0, omega0=OMEGA0[k], x0=X0[k], v0=V0[k], R0=R0[k], **options)
        for k in range(N)
    ]
    assert_same_as_single_runs(batch, singles)


@pytest.mark.parametrize("method", ["rkmk4", "rk4-quat"])
def test_different_bodies_match_single_runs_with_q0_and_l0(bodies, method):
    q0 = so3.quat_from_matrix(R0) * [[1.0], [2.0], [0.5]]  # not unit: normalised as simulate
    options = dict(method=method, h=0.05, forces=[Gravity(), Torque((0.0, 0.1, 0.0))])
    batch = simulate_batch(bodies, 2.0, q0=q0, L0=OMEGA0, t0=0.5, **options)
    singles = [
        simulate(bodies[k], 2.0, q0=q0[k], L0=OMEGA0[k], t0=0.5, **options) for k in range(N)
    ]
    assert_same_as_single_runs(batch, singles)


def test_arrays_have_a_leading_body_axis(body):
    batch = simulate_batch(body, 1.0, h=0.1, omega0=OMEGA0, record_every=5)
    assert len(batch) == N and batch.t.shape == (3,)  # t0, step 5, step 10
    assert batch.x.shape == batch.v.shape == batch.L_world.shape == (N, 3, 3)
    assert batch.R.shape == (N, 3, 3, 3) and batch.q.shape == (N, 3, 4)
    assert batch.energy.shape == batch.orthogonality_error.shape == (N, 3)
    assert np.all(batch.success) and list(batch.n_steps) == [10] * N


@pytest.mark.parametrize("name", ["q", "omega_body", "energy", "orthogonality_error"])
def test_derived_quantities_are_those_of_each_bodys_trajectory(bodies, name):
    batch = simulate_batch(bodies, 1.0, method="rk4-matrix", h=0.1, omega0=OMEGA0)
    expected = np.array([getattr(batch[k], name) for k in range(N)])
    # NumPy over all bodies at once or one body at a time (stacked or single products, in the
    # CPU's kernels): two evaluations of chains of at most 12 roundings on terms of 3 × the
    # entries (|R| ≤ 1 for q and RᵀR − I)
    magnitude = 3 * max(np.abs(expected).max(), 1.0)
    np.testing.assert_allclose(getattr(batch, name), expected, rtol=0,
                               atol=sum_bound(magnitude, 12))  # fmt: skip


def test_to_xarray_has_a_body_dimension_and_round_trips(bodies):
    batch = simulate_batch(bodies, 1.0, h=0.1, omega0=OMEGA0, x0=X0)
    ds = batch.to_xarray()
    assert ds["R"].dims == ("body", "time", "row", "col")
    assert ds["x"].dims == ("body", "time", "axis") and ds["energy"].dims == ("body", "time")
    np.testing.assert_array_equal(ds["body"].values, np.arange(N))
    np.testing.assert_array_equal(ds["time"].values, batch.t)
    for name in ["x", "v", "R", "q", "omega_body", "L_world", "energy"]:
        np.testing.assert_array_equal(ds[name].values, getattr(batch, name))
    np.testing.assert_array_equal(ds["mass"].values, [1.0, 3.0, 0.5])
    one = batch[1].to_xarray()
    assert ds["L_world"].attrs == one["L_world"].attrs
    np.testing.assert_array_equal(ds.sel(body=1)["energy"].values, one["energy"].values)
    assert ds.attrs["method"] == "rkmk4"


def test_a_body_that_blows_up_stops_alone(body):
    x0 = [[0.0, 0.0, 0.0], [1.79e308, 0.0, 0.0]]
    v0 = [[1.0, 0.0, 0.0], [8e307, 0.0, 0.0]]  # x + h v overflows in the first step
    batch = simulate_batch(body, 1.0, h=0.1, x0=x0, v0=v0)
    assert list(batch.status) == [0, -1] and list(batch.n_steps) == [10, 0]
    assert "non-finite" in batch.messages[1] and "t=0.0" in batch.messages[1]
    assert len(batch[1].t) == 1 and np.all(np.isnan(batch.x[1, 1:]))
    single = simulate(body, 1.0, h=0.1, x0=x0[0], v0=v0[0])
    np.testing.assert_array_equal(batch[0].R, single.R)


@pytest.mark.parametrize("record_every", [1, 3])
@pytest.mark.parametrize("method", FIXED)
def test_a_body_stopped_after_many_steps_ends_with_its_single_runs_last_finite_state(
    body, method, record_every
):
    # x grows by h v = 1e306 per step from 1e308: step 80 overflows (max 1.8e308), so the
    # last finite state is step 79, not a recorded one when record_every = 3.
    x0, v0 = [[0.0, 0.0, 0.0], [1e308, 0.0, 0.0]], [[1.0, 0.0, 0.0], [1e307, 0.0, 0.0]]
    options = dict(method=method, h=0.1, record_every=record_every)
    batch = simulate_batch(body, 10.0, x0=x0, v0=v0, omega0=OMEGA0[:2], **options)
    singles = [
        simulate(body, 10.0, x0=x0[k], v0=v0[k], omega0=OMEGA0[k], **options) for k in range(2)
    ]
    assert_same_as_single_runs(batch, singles)
    assert list(batch.status) == [0, -1] and list(batch.n_steps) == [100, 79]
    assert batch[1].t[-1] == batch.t_last[1] == pytest.approx(7.9, abs=1e-12)
    assert len(batch[1].t) == {1: 80, 3: 28}[record_every]  # t0, 26 or 79 samples, step 79
    assert np.all(np.isnan(batch.x[1, len(batch[1].t) :]))


def test_a_spin_that_overflows_between_recorded_samples_keeps_its_last_finite_state(body):
    omega0 = [[0.1, 0.2, 0.3], [1e154, 1e154, 1e154]]  # euler: R overflows in step 2
    options = dict(method="euler", h=0.1, record_every=3)
    batch = simulate_batch(body, 1.0, omega0=omega0, **options)
    singles = [simulate(body, 1.0, omega0=omega0[k], **options) for k in range(2)]
    assert_same_as_single_runs(batch, singles)
    np.testing.assert_array_equal(batch[1].t, [0.0, 0.1])
    np.testing.assert_array_equal(batch.t_last, [1.0, 0.1])
    np.testing.assert_array_equal(batch.to_xarray()["t_last"].values, [1.0, 0.1])


def test_adaptive_method_is_refused_with_the_fixed_ones_listed(body):
    with pytest.raises(ValueError, match="method='rkmk45'.*fixed-step.*'rkmk4'.*adaptive"):
        simulate_batch(body, 1.0, method="rkmk45", h=0.1, omega0=OMEGA0)


@pytest.mark.parametrize(
    "forces",
    [[Impulse((0, 0, 0), (1, 0, 0), time=0.5)], [Torque(lambda t, state: (0.0, 0.0, t))]],
    ids=["impulse", "callable"],
)
def test_impulses_and_callable_loads_are_refused_naming_what_is_supported(body, forces):
    with pytest.raises(ValueError, match="constant loads only.*Gravity"):
        simulate_batch(body, 1.0, h=0.1, omega0=OMEGA0, forces=forces)


def test_events_are_refused(body):
    with pytest.raises(ValueError, match="events"):
        simulate_batch(body, 1.0, h=0.1, omega0=OMEGA0, events=[lambda t, s: s.x[2]])


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (
            dict(omega0=(1.0, 0.0, 0.0)),
            r"omega0.shape=\(3,\) is not allowed: must be \(N, 3\)",
        ),
        (
            dict(omega0=OMEGA0, R0=R0[:2]),
            r"R0.shape=\(2, 3, 3\) is not allowed: must be \(3, 3, 3\)",
        ),
        (
            dict(omega0=OMEGA0, x0=np.zeros((3, 2))),
            r"x0.shape=\(3, 2\) is not allowed: must be \(3, 3\)",
        ),
        (
            dict(q0=np.zeros((3, 4))),
            r"q0\[0\]=\[0.0, 0.0, 0.0, 0.0\] is not allowed: .*non-zero norm",
        ),
        (dict(R0=2 * R0), r"R0\[0\]=.* is not allowed: must be a rotation matrix"),
        (dict(omega0=OMEGA0, L0=OMEGA0), "at most one of omega0"),
        (
            dict(v0=[[0, 0, 0], [np.nan, 0, 0], [0, 0, 0]]),
            r"v0\[1\]=\[nan, 0.0, 0.0\] is not allowed: must be every entry finite",
        ),
        (dict(omega0=OMEGA0, h=-0.1), "h=-0.1"),
        (dict(omega0=OMEGA0, record_every=0), "record_every=0"),
        (dict(omega0=OMEGA0, progress="x"), r"progress='x' is not allowed: must be True or"),
    ],
    ids=lambda value: None if isinstance(value, dict) else value[:24],
)
def test_bad_per_body_input_names_the_argument_and_shapes(body, arguments, message):
    arguments = {"h": 0.1, **arguments}
    with pytest.raises(ValueError, match=message):
        simulate_batch(body, 1.0, **arguments)


def test_bodies_are_counted_and_checked(bodies):
    with pytest.raises(
        ValueError, match=r"omega0.shape=\(2, 3\) is not allowed: must be \(3, 3\).*3 bodies"
    ):
        simulate_batch(bodies, 1.0, h=0.1, omega0=OMEGA0[:2])
    with pytest.raises(ValueError, match=r"body_or_bodies\[1\]"):
        simulate_batch([bodies[0], "body"], 1.0, h=0.1)


SOA = [name for name in FIXED if METHODS[name].family in SOA_FAMILIES]
"""The fixed-step methods whose batches run in the structure-of-arrays loops."""


@pytest.mark.filterwarnings("ignore:h=.* turns the body:UserWarning")
@pytest.mark.parametrize("method", SOA)
def test_columns_of_bodies_across_blocks_match_single_runs_bit_for_bit(body, method):
    """More bodies than a block (the last one partial), spins up to 60 rad/s so that many
    stage angles pass SERIES_ANGLE (the loops' scalar branch). (A body that stops alone:
    test_a_body_that_blows_up_stops_alone and the two after it, which run these loops.)"""
    n = BLOCK + 37  # >= SOA_MIN_BODIES
    rng = np.random.default_rng(3)
    omega0 = rng.normal(size=(n, 3)) * np.geomspace(0.1, 60.0, n)[:, None]
    batch = simulate_batch(body, 0.05, method=method, h=0.01, omega0=omega0, forces=LOADS)
    assert np.all(batch.status == 0)
    for k in range(n):  # bit for bit on any machine: see assert_same_as_single_runs
        single = simulate(body, 0.05, method=method, h=0.01, omega0=omega0[k], forces=LOADS)
        for name in ("t", "R", "L_world", "x", "v"):
            np.testing.assert_array_equal(getattr(batch[k], name), getattr(single, name), name)


@pytest.mark.parametrize(
    "loop",
    [
        "_lie_field_soa",
        "_quat_field_soa",
        "_lie_turn_soa",
        "_combine",
        "_coefficients",
        "_loads_soa",
    ],
)
def test_structure_of_arrays_loops_compile_to_packed_instructions(loop):
    """Each loop over bodies is vectorised: compiled afresh (cached code cannot be
    inspected), its assembly multiplies or divides doubles in the widest registers that numba
    packs a plain loop into on this target (vmulpd, vdivpd on ymm or zmm with AVX; mulpd on
    xmm under NUMBA_CPU_NAME=generic)."""
    n, rng = 16, np.random.default_rng(0)
    loads = (np.ones(n), rng.normal(size=(3, n)), rng.normal(size=3))  # m, F, tau
    arguments = {
        "_lie_field_soa": (True, rng.normal(size=(12, n)), rng.normal(size=(9, n)),
                           rng.normal(size=(9, n)), *loads, np.empty((3, n)),
                           np.empty((4, 12, n)), 1),
        "_quat_field_soa": (rng.normal(size=(13, n)), np.empty((9, n)), rng.normal(size=(9, n)),
                            *loads, np.empty((4, 13, n)), 1),
        "_lie_turn_soa": (rng.normal(size=(12, n)), rng.normal(size=(9, n)), np.empty((3, n)),
                          np.ones(n, dtype=bool)),
        "_combine": ((np.ones((1, 4)), np.arange(4)[None], np.array([4])), 0, 0.1,
                     rng.normal(size=(12, n)), rng.normal(size=(4, 12, n)), 2, np.empty((12, n))),
        "_coefficients": (rng.normal(size=(3, n)), np.empty((3, n)), True),
        "_loads_soa": (3, rng.normal(size=(12, n)), *loads, np.empty((4, 12, n)), 1),
    }[loop]  # fmt: skip
    fresh = numba.njit(error_model="numpy")(getattr(soa, loop).py_func)
    fresh(*arguments)
    assembly = "".join(fresh.inspect_asm().values())
    packed = re.findall(rf"\bv?(?:mul|div)pd\s+[^\n]*%{_widest_register()}mm", assembly)
    assert len(packed) >= 3, f"{loop}: {len(packed)} packed multiplies or divides"


def _widest_register() -> str:
    """``x``, ``y`` or ``z``: the widest registers of a plain loop's packed multiplies."""

    def plain(a, b):
        for i in range(a.size):
            b[i] = a[i] * a[i] / (1.0 + a[i])

    fresh = numba.njit(error_model="numpy")(plain)
    fresh(np.ones(64), np.empty(64))
    assembly = "".join(fresh.inspect_asm().values())
    return max(re.findall(r"\bv?(?:mul|div)pd\s+[^\n]*%([xyz])mm", assembly))


@pytest.mark.parametrize("record_every", [1, 3])
@pytest.mark.parametrize("method", SOA)
def test_a_body_stopped_among_columns_ends_as_its_single_run(body, method, record_every):
    """As test_a_body_stopped_after_many_steps_..., with enough bodies for the columns:
    body 1 overflows in step 80 and keeps its step-79 state, the others go on."""
    n = SOA_MIN_BODIES + 3
    x0, v0 = np.zeros((n, 3)), np.tile([1.0, 0.0, 0.0], (n, 1))
    x0[1], v0[1] = [1e308, 0.0, 0.0], [1e307, 0.0, 0.0]
    omega0 = np.resize(OMEGA0, (n, 3))
    options = dict(method=method, h=0.1, record_every=record_every)
    batch = simulate_batch(body, 10.0, x0=x0, v0=v0, omega0=omega0, **options)
    assert list(batch.status[:3]) == [0, -1, 0] and list(batch.n_steps[:3]) == [100, 79, 100]
    for k in (0, 1, 2):
        single = simulate(body, 10.0, x0=x0[k], v0=v0[k], omega0=omega0[k], **options)
        for name in FIELDS:
            np.testing.assert_array_equal(getattr(batch[k], name), getattr(single, name), name)
        assert batch[k].message == single.message


@pytest.mark.parametrize("method", SOA)
def test_stage_terms_leave_out_zero_weights_only_when_no_b_is_zero(method):
    """soa._terms: stage i's terms are the a_il in order (row s: every b_i); a zero a_il is
    left out exactly when every b_i is non-zero (a non-finite k_l then stops the body in
    both loops), else kept (0·inf = nan must reach the new state as in the one-body loop)."""
    tableau = METHODS[method].tableau
    A, b = np.asarray(tableau.A, dtype=float), np.asarray(tableau.b, dtype=float)
    w, terms, count = soa._terms(A, b)
    s = len(b)
    for i in range(s + 1):
        weights = A[i, :i] if i < s else b
        kept = [l for l in range(len(weights)) if weights[l] != 0 or i == s or not b.all()]
        np.testing.assert_array_equal(terms[i, : count[i]], kept)
        np.testing.assert_array_equal(w[i, : count[i]], weights[kept])


def _stopping(n: int) -> dict:
    """``n`` bodies of which body 1 overflows in step 80 and body 2 in step 40 (x grows by
    h v from 1e308 up to 1.8e308), the others spinning on."""
    x0, v0 = np.zeros((n, 3)), np.tile([1.0, 0.0, 0.0], (n, 1))
    x0[1:3], v0[1], v0[2] = [1e308, 0.0, 0.0], [1e307, 0.0, 0.0], [2e307, 0.0, 0.0]
    return dict(x0=x0, v0=v0, omega0=np.resize(OMEGA0, (n, 3)))


@pytest.mark.parametrize("n", [4, SOA_MIN_BODIES + 3], ids=["few", "columns"])
@pytest.mark.parametrize("method", FIXED_METHODS)
def test_a_batch_in_many_blocks_has_the_numbers_of_one_block_bit_for_bit(
    body, method, n, monkeypatch
):
    """The driver marches the batch in blocks that end on recorded steps and keeps each
    body's account over them (its status, message, steps and last finite state): in one
    block, in blocks of one sample (3 steps) and in the progress bar's, the same numbers."""
    options = dict(method=method, h=0.1, record_every=3, **_stopping(n))
    one = simulate_batch(body, 10.0, **options)
    shown = simulate_batch(body, 10.0, progress=True, **options)
    monkeypatch.setattr(batch_module, "BLOCK_BYTES", 1)  # one sample of each body a block
    many = simulate_batch(body, 10.0, **options)
    assert list(one.status[:4]) == [0, -1, -1, 0] and list(one.n_steps[:4]) == [100, 79, 39, 100]
    for other in (shown, many):
        for name in ("t", "x", "v", "R", "L_world", "q", "n_steps", "n_recorded", "t_last"):
            np.testing.assert_array_equal(getattr(other, name), getattr(one, name), name)
        np.testing.assert_array_equal(other.status, one.status)
        assert other.messages == one.messages


def test_a_batch_marches_in_blocks_of_bounded_records(body, monkeypatch):
    """BLOCK_BYTES bounds a block's records: blocks of whole samples of every body."""
    calls = []
    march_block = batch_module.BatchStepper._march_block

    def counted(self, state, grid, k0, k1, every, step0):
        calls.append((k0, k1))
        return march_block(self, state, grid, k0, k1, every, step0)

    monkeypatch.setattr(batch_module.BatchStepper, "_march_block", counted)
    monkeypatch.setattr(batch_module, "BLOCK_BYTES", 2 * N * batch_module.SAMPLE_BYTES)
    simulate_batch(body, 1.0, h=0.1, omega0=OMEGA0, record_every=3)  # 10 steps
    assert calls == [(0, 6), (6, 10)]  # two samples of every body a block, then the rest


@pytest.mark.parametrize("method", FIXED_METHODS)
def test_a_single_run_in_the_progress_bars_blocks_has_the_numbers_of_one_block(body, method):
    """What a batch's body is compared with: ``simulate`` marches in blocks too with a
    progress bar, and they end on recorded steps and go on from the loop's own arrays, so
    the axes flow's merged half turns and the quat chart's normalisation do not see them."""
    options = dict(method=method, h=0.01, omega0=OMEGA0[0], record_every=7)
    one = simulate(body, 3.0, **options)
    shown = simulate(body, 3.0, progress=True, **options)
    for name in ("t", "R", "L_world", "x", "q"):
        np.testing.assert_array_equal(getattr(shown, name), getattr(one, name), name)
