"""The rigid-body scenario: bodies from parts or meshes, the initial state, loads, results."""

import inspect
import json
from pathlib import Path

import numpy as np
import pytest
from rigid_roundoff import invariant_bound

from tumble import mass, meshes, scenarios, so3
from tumble.scenarios import rigid_body
from tumble.scenarios.files import read

EXAMPLES = Path(__file__).parents[2] / "examples"
SPHERE = {"shape": "sphere", "radius": 0.1, "density": 1000.0}
BOX = {"shape": "box", "extents": [0.3, 0.2, 0.1], "mass": 2.0}


def body_of(options: dict) -> mass.MassProperties:
    """Mass properties of the body the options describe (as run() builds them)."""
    return rigid_body.OPTIONS.model_validate(options).body.mass_properties()


@pytest.fixture(scope="module")
def t_handle_file():
    return read(EXAMPLES / "t-handle-parts.toml")


def test_composite_t_handle_file_has_the_inertia_of_mass_t_handle(t_handle_file):
    composite, reference = body_of(t_handle_file.options), mass.t_handle()
    assert composite.mass == pytest.approx(reference.mass, rel=1e-12)
    # Same cylinders added in the same order: equal to round-off (1e-12 of the largest entry).
    scale = np.abs(reference.inertia).max()
    np.testing.assert_allclose(composite.inertia, reference.inertia, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(composite.com, 0.0, atol=1e-15)  # terms m c ≈ 1e-3: ≤ 6e-18


def test_composite_t_handle_file_moves_like_the_built_in(t_handle_file):
    options = {**t_handle_file.options, "t_end": 2.0}
    mine = scenarios.get("rigid-body").run(**options).data["trajectory"]
    omega0 = t_handle_file.options["initial"]["omega0"]
    built_in = scenarios.get("t-handle").run(t_end=2.0, spins=[omega0])
    reference = built_in.data["trajectories"][0]
    assert mine.method == reference.method == "rkmk4"
    # the same grid t0 + k h (two roundings at |t| ≤ 2); the same compiled run from inertias
    # equal to round-off, 1e-12 far above it
    np.testing.assert_allclose(mine.t, reference.t, rtol=0, atol=1e-14)
    np.testing.assert_allclose(mine.R[-1], reference.R[-1], rtol=0, atol=1e-12)


def test_a_part_without_density_takes_the_composite_density():
    parts = [
        {"shape": "sphere", "radius": 0.1},
        {"shape": "sphere", "radius": 0.1, "center": [1.0, 0.0, 0.0], "mass": 3.0},
    ]
    composite = body_of({"body": {"density": 500.0, "parts": parts}})
    first = mass.sphere(0.1, density=500.0)
    # a few scalar roundings a side (≤ 2.2e-15), the same bits on any machine
    assert composite.mass == pytest.approx(first.mass + 3.0, rel=1e-14)
    np.testing.assert_allclose(composite.com, [3.0 / composite.mass, 0.0, 0.0], rtol=1e-14)


def test_primitive_matches_the_mass_module_with_a_vector_axis():
    body = {"shape": "cylinder", "radius": 0.5, "length": 2.0, "mass": 3.0, "axis": [1, 1, 0]}
    reference = mass.cylinder(0.5, 2.0, mass=3.0, axis=[1.0, 1.0, 0.0])
    np.testing.assert_allclose(body_of({"body": body}).inertia, reference.inertia, rtol=1e-14)


def test_mesh_body_mass_uses_density_and_scale(tmp_path):
    meshes.save(meshes.box([0.1, 0.2, 0.3]), tmp_path / "brick.stl")
    body = {"mesh": str(tmp_path / "brick.stl"), "density": 1000.0, "scale": 2.0}
    # STL stores float32 vertices: the volume 0.006 m³ × 2³ holds to ~1e-7.
    assert body_of({"body": body}).mass == pytest.approx(1000.0 * 0.006 * 8, rel=1e-6)


def test_body_starts_where_its_description_puts_it():
    body = {**SPHERE, "center": [1.0, 2.0, 3.0]}
    result = rigid_body.run(body=body, t_end=0.1, h=0.05)
    np.testing.assert_allclose(result.data["trajectory"].x[0], [1.0, 2.0, 3.0])
    # The mesh is in body coordinates: centre of mass at the origin.
    np.testing.assert_allclose(result.data["mesh"].bounds.mean(axis=0), 0.0, atol=1e-12)


def test_initial_x0_overrides_the_description():
    result = rigid_body.run(body=SPHERE, initial={"x0": [0.0, 0.0, 5.0]}, t_end=0.1, h=0.05)
    np.testing.assert_allclose(result.data["trajectory"].x[0], [0.0, 0.0, 5.0])


@pytest.mark.parametrize(
    "attitude, R0",
    [
        ({"euler_zyx": [0.3, -0.2, 0.1]}, so3.matrix_from_euler_zyx([0.3, -0.2, 0.1])),
        ({"q0": [0.0, 0.0, 0.0, 2.0]}, np.diag([-1.0, -1.0, 1.0])),
        ({"R0": [[0, -1, 0], [1, 0, 0], [0, 0, 1]]}, np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]])),
    ],
    ids=["euler_zyx", "q0", "R0"],
)
def test_initial_attitude(attitude, R0):
    result = rigid_body.run(body=BOX, initial=attitude, t_end=0.1, h=0.05)
    # R0 as given or built once (numpy's SIMD sin and cos: ≤ 4 ulps of entries ≤ 1, 4.4e-16)
    np.testing.assert_allclose(result.data["trajectory"].R[0], R0, atol=1e-15)


def test_impulse_from_rest_gives_the_closed_form_kick():
    J, point = np.array([0.0, 0.5, 6.0]), np.array([0.05, 0.0, -0.05])
    impulse = {"type": "impulse", "impulse": J.tolist(), "point": point.tolist()}
    run = rigid_body.run(body=BOX, loads=[impulse], t_end=0.1, h=0.01).data["trajectory"]
    # Body at rest with x0 = com = 0: Δv = J/m, ΔL = (point − x) × J, exactly (the same IEEE
    # operations in the kernel and here: the same bits on any machine).
    np.testing.assert_allclose(run.v[0], J / 2.0, rtol=1e-15)
    np.testing.assert_allclose(run.L_world[0], np.cross(point, J), rtol=1e-15)


def test_gravity_drops_the_centre_of_mass_on_a_parabola():
    gravity = {"type": "gravity", "g": [0.0, 0.0, -9.81]}
    initial = {"v0": [1.0, 0.0, 2.0], "omega0": [0.0, 3.0, 0.1]}
    result = rigid_body.run(body=BOX, initial=initial, loads=[gravity], t_end=1.0, h=0.1)
    run = result.data["trajectory"]
    exact = np.outer(run.t, [1.0, 0.0, 2.0]) + np.outer(0.5 * run.t**2, [0.0, 0.0, -9.81])
    np.testing.assert_allclose(run.x, exact, rtol=0, atol=1e-12)  # RK4 is exact on quadratics
    # T + V is kept (gravity has a potential), L too (no torque about the centre of mass)
    assert result.summary["conserved"] == {"energy": True, "angular_momentum": True}
    assert result.summary["momentum_drift"] < 1e-14  # no torque: L += h·0 is exact (0)


def test_force_point_is_given_in_the_description_coordinates():
    # A sphere centred at c, pushed at c + (0, 0, 0.1) along x: torque (0, 0.1, 0) × … about c.
    body = {**SPHERE, "center": [1.0, 2.0, 3.0]}
    force = {"type": "force", "force": [1.0, 0.0, 0.0], "point": [1.0, 2.0, 3.1]}
    options = rigid_body.OPTIONS.model_validate({"body": body, "loads": [force]})
    load = options.loads[0].build(np.array([1.0, 2.0, 3.0]))
    np.testing.assert_allclose(load.point, [0.0, 0.0, 0.1], atol=1e-15)
    run = rigid_body.run(body=body, loads=[force], t_end=1e-3, h=1e-4).data["trajectory"]
    # dL/dt = r × F = (0, 0.1, 0) N m while the sphere has barely turned.
    np.testing.assert_allclose(run.L_world[-1] / 1e-3, [0.0, 0.1, 0.0], atol=1e-6)


def test_free_body_conserves_and_says_so():
    result = rigid_body.run(body=BOX, initial={"omega0": [0.1, 3.0, 0.1]}, t_end=2.0, h=0.01)
    summary = result.summary
    assert summary["conserved"] == {"energy": True, "angular_momentum": True}
    assert summary["momentum_drift"] < 1e-14  # L is stepped linearly: exact without torque
    assert summary["energy_drift"] < 1e-6  # rkmk4 at h = 0.01 over 2 s (measured ~1e-9)
    assert summary["max_orthogonality_error"] < invariant_bound("rkmk4", 200)  # 1.6e-13


def test_drift_is_none_for_a_body_at_rest():
    summary = rigid_body.run(body=SPHERE, t_end=0.1, h=0.05).summary
    assert summary["energy_drift"] is None and summary["momentum_drift"] is None


def test_adaptive_method_takes_tolerances():
    result = rigid_body.run(
        body=BOX, initial={"omega0": [0.1, 3.0, 0.1]}, method="rkmk45", rtol=1e-8, t_end=1.0
    )
    assert result.summary["rtol"] == 1e-8
    assert result.data["trajectory"].success


def test_python_call_names_the_key_without_the_options_prefix():
    with pytest.raises(ValueError, match=r"^body\.radius = -1: must be > 0$"):
        rigid_body.run(body={"shape": "sphere", "radius": -1, "density": 1.0})


def test_python_call_accepts_tuples_and_arrays():
    result = rigid_body.run(
        body={**BOX, "center": (0.0, 0.0, 1.0)},
        initial={"omega0": np.array([0.0, 1.0, 0.0])},
        t_end=0.1,
        h=0.05,
    )
    np.testing.assert_allclose(result.data["trajectory"].omega_body[0], [0.0, 1.0, 0.0])


def test_run_defaults_match_the_options_model():
    fields = rigid_body.OPTIONS.model_fields
    for name, parameter in inspect.signature(rigid_body.run).parameters.items():
        if name == "body":
            assert fields[name].is_required()
        elif name == "initial":
            assert fields[name].default == rigid_body.Initial()
        elif name == "loads":
            assert fields[name].default == [] and parameter.default == ()
        else:
            assert fields[name].default == parameter.default, name


def test_result_carries_figures_data_and_animations():
    result = rigid_body.run(body=BOX, initial={"omega0": [0.0, 1.0, 0.1]}, t_end=0.2, h=0.1)
    assert [name for name, _ in result.figures] == [
        "rotation_grid.png",
        "euler_angles.png",
        "angular_velocity.png",
        "drift.png",
        "snapshots.png",
    ]
    assert [name for name, _ in result.animations] == ["animation.gif", "view.html"]
    assert sorted(result.datasets) == ["", "mesh"]  # one run: data.nc's root group
    assert result.attrs["mass"] == 2.0 and len(result.attrs["inertia"]) == 9
    assert result.attrs["method"] == "rkmk4" and result.attrs["h"] == 0.1
    json.dumps(result.summary)  # written to summary.json


def test_figures_draw(tmp_path):
    result = rigid_body.run(body=BOX, initial={"omega0": [0.0, 1.0, 0.1]}, t_end=0.2, h=0.1)
    for name, writer in result.figures:
        writer(tmp_path / name)
        assert (tmp_path / name).stat().st_size > 1000, name


def test_box_example_file_runs():
    scenario_file = read(EXAMPLES / "box-impulse.toml")
    options = {**scenario_file.options, "t_end": 0.1}
    summary = scenarios.get(scenario_file.scenario).run(**options).summary
    assert summary["loads"] == ["gravity", "impulse"]
    assert summary["status"] == 0


def test_run_simulates_the_prepared_run_bit_for_bit():
    options = {"body": BOX, "initial": {"omega0": [0.1, 3.0, 0.1], "euler_zyx": [0.1, 0.2, 0.3]},
               "loads": [{"type": "gravity"}], "t_end": 1.0}  # fmt: skip
    ready = rigid_body.prepare(rigid_body.OPTIONS.model_validate(options))
    trajectory = rigid_body.run(**options).data["trajectory"]
    again = ready.simulate()
    assert np.array_equal(trajectory.R, again.R) and np.array_equal(trajectory.x, again.x)
    np.testing.assert_array_equal(ready.start["R0"], so3.matrix_from_euler_zyx([0.1, 0.2, 0.3]))


def test_prepared_start_puts_the_body_where_its_description_does():
    off_centre = {**SPHERE, "center": [0.5, -0.25, 1.0]}
    ready = rigid_body.prepare(rigid_body.OPTIONS.model_validate({"body": off_centre}))
    assert ready.start["x0"].tolist() == [0.5, -0.25, 1.0] == ready.com.tolist()
    assert ready.start["v0"] is None and ready.start["omega0"] is None


@pytest.mark.parametrize(
    ("changes", "batchable"),
    [
        ({}, True),
        ({"loads": [{"type": "gravity"}, {"type": "torque", "torque": [0.0, 0.0, 1.0]}]}, True),
        ({"method": "rkmk45", "h": None}, False),
        ({"loads": [{"type": "impulse", "impulse": [0.0, 0.0, 1.0], "point": [0, 0, 0]}]}, False),
    ],
)
def test_runs_batch_with_a_fixed_step_under_constant_loads(changes, batchable):
    options = rigid_body.OPTIONS.model_validate({"body": BOX, **changes})
    assert rigid_body.prepare(options).batchable is batchable


def test_every_load_class_of_the_library_is_a_load_type_of_the_files():
    """A new load class in tumble.rigid.forces needs its row in scenarios.loads.LOADS."""
    import typing

    from tumble.rigid import forces
    from tumble.scenarios.loads import LOADS

    classes = {*typing.get_args(forces.Load), forces.Impulse}
    assert classes == {row.load for row in LOADS.values()}


def test_a_magnetic_dipole_in_a_file_is_the_library_load():
    """A compass needle: the file's load is MagneticDipole(moment, field), bit for bit, and
    it keeps T + V but turns L."""
    from tumble.rigid import MagneticDipole, simulate

    needle = {"type": "magnetic-dipole", "moment": [0.2, 0.0, 0.0], "field": [0.0, 1e-3, 0.0]}
    initial = {"omega0": [0.0, 0.0, 0.5]}
    result = rigid_body.run(body=BOX, initial=initial, loads=[needle], t_end=1.0, h=0.01)
    trajectory = result.data["trajectory"]
    alone = simulate(trajectory.body, 1.0, h=0.01, omega0=[0.0, 0.0, 0.5],
                     forces=[MagneticDipole((0.2, 0.0, 0.0), (0.0, 1e-3, 0.0))])  # fmt: skip
    assert np.array_equal(trajectory.R, alone.R)
    assert np.array_equal(trajectory.potential_energy, alone.potential_energy)
    assert result.summary["conserved"] == {"energy": True, "angular_momentum": False}


def test_a_load_key_the_type_does_not_take_is_named_with_the_allowed_ones():
    needle = {"type": "magnetic-dipole", "moment": [0.2, 0.0, 0.0], "feild": [0.0, 1.0, 0.0]}
    with pytest.raises(ValueError, match=r"loads\[0\]\.feild is not a key of a "
                       r"magnetic-dipole load; allowed: field, moment, type"):  # fmt: skip
        rigid_body.run(body=BOX, loads=[needle])


def test_a_gravity_gradient_in_a_file_is_the_library_load_with_the_body_inertia():
    """A cubesat on a circular orbit: the file's gravity-gradient load is
    GravityGradient(mu) given the body's inertia by simulate, bit for bit; the file takes no
    inertia key (the body's is the one that must be used) and refuses a mu <= 0."""
    from tumble.rigid import GravityGradient, simulate
    from tumble.scenarios.loads import SECTIONS

    assert "inertia" not in SECTIONS["gravity-gradient"].model_fields
    r, mu = 7.0e6, 3.986004418e14
    initial = {"x0": [r, 0.0, 0.0], "v0": [0.0, (mu / r) ** 0.5, 0.0], "omega0": [0.01, 0.0, 0.02]}
    load = {"type": "gravity-gradient", "mu": mu}
    result = rigid_body.run(body=BOX, initial=initial, loads=[load], t_end=10.0, h=1.0)
    trajectory = result.data["trajectory"]
    alone = simulate(trajectory.body, 10.0, h=1.0, x0=initial["x0"], v0=initial["v0"],
                     omega0=initial["omega0"], forces=[GravityGradient(mu=mu)])  # fmt: skip
    assert np.array_equal(trajectory.R, alone.R)
    assert np.array_equal(trajectory.x, alone.x)
    assert result.summary["conserved"] == {"energy": True, "angular_momentum": False}
    with pytest.raises(ValueError, match="mu"):
        rigid_body.run(body=BOX, initial=initial, loads=[{**load, "mu": -1.0}], t_end=1.0, h=1.0)
