"""tumble._checks: one grammar for every input error, and inf refused wherever > 0 is asked."""

import inspect
import math

import numpy as np
import pytest

from tumble import _checks, mass, meshes, structural
from tumble.ode import solve
from tumble.rigid import RigidBody, simulate

INF, NAN = math.inf, math.nan


def _fail_method():
    raise _checks.fail("method", "rk5", "one of 'rk4', 'dopri5'")


# (function of _checks, a call that refuses, the name and the value the message must start with)
REFUSALS = [
    ("fail", _fail_method, "method", "rk5"),
    ("positive", lambda: _checks.positive("h", -0.1, "s"), "h", -0.1),
    ("positive", lambda: _checks.positive("h", 0.0, "s"), "h", 0.0),
    ("positive", lambda: _checks.positive("h", INF, "s"), "h", INF),
    ("positive", lambda: _checks.positive("h", NAN, "s"), "h", NAN),
    ("positive", lambda: _checks.positive("h", "0.1", "s"), "h", "0.1"),
    ("positive", lambda: _checks.positive("h", True, "s"), "h", True),
    ("non_negative", lambda: _checks.non_negative("atol", -1e-9), "atol", -1e-9),
    ("non_negative", lambda: _checks.non_negative("atol", INF), "atol", INF),
    ("finite", lambda: _checks.finite("t0", NAN, "s"), "t0", NAN),
    ("finite", lambda: _checks.finite("t0", None, "s"), "t0", None),
    ("count", lambda: _checks.count("record_every", 0), "record_every", 0),
    ("count", lambda: _checks.count("record_every", 2.0), "record_every", 2.0),
    ("count", lambda: _checks.count("record_every", True), "record_every", True),
    ("count", lambda: _checks.count("sections", 2, 3), "sections", 2),
    ("choice", lambda: _checks.choice("scheme", "rk4", ["midpoint"]), "scheme", "rk4"),
    ("choice", lambda: _checks.choice("scheme", 3, ["midpoint"]), "scheme", 3),
    ("array", lambda: _checks.array("x0", [0.0, 1.0], shape=(3,)), "x0", [0.0, 1.0]),
    ("array", lambda: _checks.array("x0", "abc", shape=(3,)), "x0", "abc"),
    ("array", lambda: _checks.array("x0", [0.0, NAN, 1.0], shape=(3,)), "x0[1]", NAN),
    ("array", lambda: _checks.array("E", [[1.0, -2.0]], positive=True), "E[0, 1]", -2.0),
    ("values", lambda: _checks.values("step_sizes", [0.1], minimum=2), "step_sizes", [0.1]),
    ("values", lambda: _checks.values("step_sizes", [[0.1, 0.2]]), "step_sizes", [[0.1, 0.2]]),
    ("values", lambda: _checks.values("errors", [1e-3, 0.0], positive=True), "errors[1]", 0.0),
    ("values", lambda: _checks.values("dts", [1e-3, INF], positive=True), "dts[1]", INF),
    ("flag", lambda: _checks.flag("progress", "yes"), "progress", "yes"),
    ("flag", lambda: _checks.flag("dense_output", 1), "dense_output", 1),
    ("callables", lambda: _checks.callables("events", 42), "events", 42),
    ("callables", lambda: _checks.callables("events", "g"), "events", "g"),
    ("callables", lambda: _checks.callables("events", [print, 3]), "events[1]", 3),
    ("count", lambda: _checks.count("sections", 10**9, 3, 2**16), "sections", 10**9),
    ("array", lambda: _checks.array("x0", [None, 0.0, 0.0], shape=(3,)), "x0", [None, 0.0, 0.0]),
    ("array", lambda: _checks.array("atol", True), "atol", True),
    ("array", lambda: _checks.array("atol", 1j), "atol", 1j),
    ("values", lambda: _checks.values("dts", ["1", "2"]), "dts", ["1", "2"]),
    ("optional_flag", lambda: _checks.optional_flag("compiled", "no"), "compiled", "no"),
    ("optional_flag", lambda: _checks.optional_flag("compiled", 1), "compiled", 1),
    ("function", lambda: _checks.function("run", None), "run", None),
    ("instance", lambda: _checks.instance("system", 1.0, dict, "a dict"), "system", 1.0),
    ("path", lambda: _checks.path("out", None), "out", None),
    ("path", lambda: _checks.path("out", ""), "out", ""),
    ("trailing", lambda: _checks.trailing("w", [1.0, 2.0], (3,), "vectors"), "w", [1.0, 2.0]),
    ("trailing", lambda: _checks.trailing("R", "abc", (3, 3), "matrices"), "R", "abc"),
    ("items", lambda: _checks.items("forces", 3, "a sequence of loads"), "forces", 3),
    ("items", lambda: _checks.items("forces", "g", "a sequence of loads"), "forces", "g"),
    ("sample_times", lambda: _checks.sample_times("t_eval", [0, 2, 1], 0, 3), "t_eval", [0, 2, 1]),
    ("sample_times", lambda: _checks.sample_times("t_eval", [0, 4], 0, 3), "t_eval[1]", 4.0),
    ("sample_times", lambda: _checks.sample_times("t_eval", [], 0, 3), "t_eval", []),
]


def _message(call) -> str:
    with pytest.raises(ValueError) as raised:
        call()
    return str(raised.value)


@pytest.mark.parametrize(
    ("function", "call", "name", "value"),
    REFUSALS,
    ids=[f"{function}-{name}={value!r}" for function, _, name, value in REFUSALS],
)
def test_every_check_names_the_argument_the_value_and_what_is_allowed(function, call, name, value):
    message = _message(call)
    assert message.startswith(f"{name}={value!r} is not allowed: must be "), message


def test_every_function_of_checks_is_pinned_above():
    functions = {
        name
        for name, value in vars(_checks).items()
        if inspect.isfunction(value) and value.__module__ == _checks.__name__
        if not name.startswith("_")
    }
    assert functions - {"memory"} == {function for function, *_ in REFUSALS}


def test_the_unit_comes_in_brackets_and_the_remedy_after_a_semicolon():
    message = str(_checks.fail("h", -1, "finite and > 0", "s", "halve it"))
    assert message == "h=-1 is not allowed: must be finite and > 0 (s); halve it"


def test_accepted_values_come_back_converted():
    assert _checks.positive("h", 1) == 1.0 and isinstance(_checks.positive("h", 1), float)
    assert _checks.count("n", np.int64(3)) == 3 and type(_checks.count("n", np.int64(3))) is int
    given = [1.0, 2.0]
    checked = _checks.values("h", given, positive=True)
    assert checked.tolist() == given and checked.dtype == float


def _beam(**changes):
    arguments = dict(length=1.0, n_elements=2, E=210e9, rho=7850.0, width=0.01, height=0.01)
    return structural.cantilever(**{**arguments, "tip_load": 1.0, **changes})


BODY = RigidBody(1.0, [1.0, 2.0, 2.5])

# Each call passes inf where a quantity must be > 0; the name it must be refused under.
INFINITE = {
    "simulate h": (lambda: simulate(BODY, 1.0, h=INF), "h"),
    "simulate rtol": (lambda: simulate(BODY, 1.0, method="rkmk45", rtol=INF), "rtol"),
    "solve h": (lambda: solve(lambda t, y: -y, (0.0, 1.0), [1.0], h=INF), "h"),
    "solve rtol": (
        lambda: solve(lambda t, y: -y, (0.0, 1.0), [1.0], method="dopri5", rtol=INF),
        "rtol",
    ),
    "rigid body mass": (lambda: RigidBody(INF, np.eye(3)), "mass"),
    "mass properties mass": (lambda: mass.MassProperties(INF, np.zeros(3), np.eye(3)), "mass"),
    "cylinder mass": (lambda: mass.cylinder(1.0, 1.0, mass=INF), "mass"),
    "cylinder density": (lambda: mass.cylinder(1.0, 1.0, density=INF), "density"),
    "mesh density": (lambda: meshes.from_mesh(meshes.box([1, 1, 1]), density=INF), "density"),
    "beam density": (lambda: _beam(rho=INF), "rho"),
    "integrate dt": (lambda: structural.integrate(_beam(), "midpoint", INF, n_steps=1), "dt"),
    "sweep dt": (lambda: structural.stability_sweep(_beam(), "midpoint", [INF], 1), "dts[0]"),
}


@pytest.mark.parametrize(("call", "name"), INFINITE.values(), ids=list(INFINITE))
def test_inf_is_refused_where_a_positive_number_is_asked(call, name):
    assert _message(call).startswith(f"{name}=inf is not allowed"), _message(call)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda: _checks.array("y0", ["a", "b"]),
            "y0=['a', 'b'] is not allowed: must be an array of numbers, every entry finite",
        ),
        (
            lambda: _checks.array("x0", [0.0, NAN, 1.0], shape=(3,), unit="m"),
            "x0[1]=nan is not allowed: must be finite (m)",
        ),
        (
            lambda: _checks.array("E", [[1.0, -2.0]], positive=True),
            "E[0, 1]=-2.0 is not allowed: must be finite and > 0",
        ),
    ],
    ids=["strings", "one-entry", "one-entry-positive"],
)
def test_array_says_what_it_wants_of_the_whole_and_of_one_entry(call, message):
    # Issue 18, item 11: string entries in y0 read "must be every entry finite"; one bad
    # entry read "x0[1]=nan ... must be of shape (3,), finite", the shape of the whole.
    assert _message(call) == message
