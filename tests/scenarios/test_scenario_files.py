"""Scenario files: every example reads, the built-in ones hold the defaults, and every kind of
mistake is a ValueError that names the key, the bad value and what is allowed."""

import inspect
import re
from pathlib import Path

import numpy as np
import pytest
import trimesh

from tumble import meshes, scenarios
from tumble.rigid import METHODS
from tumble.scenarios.files import check_options, options_model, read
from tumble.scenarios.option_models import THREE_VECTORS

EXAMPLES = Path(__file__).parents[2] / "examples"
TOML_FILES = sorted(EXAMPLES.glob("*.toml"))
BUILT_IN_FILES = [path for path in TOML_FILES if read(path).scenario != "rigid-body"]


def run_defaults(scenario: str) -> dict:
    """run()'s defaults as TOML can hold them: tuples as lists, None left out."""

    def plain(value):
        return [plain(item) for item in value] if isinstance(value, tuple | list) else value

    parameters = inspect.signature(scenarios.get(scenario).run).parameters.values()
    return {p.name: plain(p.default) for p in parameters if p.default is not None}


def write(tmp_path: Path, text: str, name: str = "scenario.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_there_are_example_files():
    assert len(TOML_FILES) >= 9


@pytest.mark.parametrize("path", TOML_FILES, ids=lambda path: path.name)
def test_every_example_file_reads_and_validates(path):
    scenario_file = read(path)
    assert scenario_file.scenario in scenarios.names()
    assert scenario_file.source == path.resolve()
    # read() hands back options already checked: checking them again changes nothing.
    assert check_options(scenario_file.scenario, scenario_file.options) == scenario_file.options


def test_every_built_in_scenario_has_an_example_file():
    covered = {read(path).scenario for path in BUILT_IN_FILES}
    assert covered == set(scenarios.names()) - {"rigid-body"}
    assert {path.stem for path in BUILT_IN_FILES} == covered


@pytest.mark.parametrize("path", BUILT_IN_FILES, ids=lambda path: path.name)
def test_built_in_example_sets_every_option_to_the_run_default(path):
    scenario_file = read(path)
    assert scenario_file.options == run_defaults(scenario_file.scenario)


def test_t_handle_file_gives_the_same_numbers_as_the_built_in():
    scenario_file = read(EXAMPLES / "t-handle.toml")
    short = {"t_end": 2.0}  # the CLI's --t-end, applied over the file's options
    from_file = check_options("t-handle", {**scenario_file.options, **short})
    built_in = scenarios.get("t-handle").run(**short)
    assert scenarios.get("t-handle").run(**from_file).summary == built_in.summary


@pytest.mark.parametrize("name", sorted(set(scenarios.names()) - {"rigid-body"}))
def test_derived_options_model_accepts_the_run_defaults(name):
    defaults = run_defaults(name)
    assert check_options(name, defaults) == defaults


def test_options_model_is_derived_from_the_run_signature():
    fields = sorted(options_model("t-handle").model_fields)
    assert fields == ["h", "method", "rtol", "spins", "t_end"]


def test_check_options_converts_integers_to_floats_and_keeps_only_given_options():
    checked = check_options("t-handle", {"t_end": 20, "spins": [[1, 0, 0]]})
    assert checked == {"t_end": 20.0, "spins": [[1.0, 0.0, 0.0]]}
    assert isinstance(checked["t_end"], float)


def test_outputs_animation_defaults_to_true(tmp_path):
    assert read(write(tmp_path, 'scenario = "t-handle"\n')).outputs.animation is True


def test_outputs_animation_false(tmp_path):
    path = write(tmp_path, 'scenario = "t-handle"\n[outputs]\nanimation = false\n')
    assert read(path).outputs.animation is False


def test_mesh_paths_are_relative_to_the_file(tmp_path, monkeypatch):
    folder = tmp_path / "bodies"
    folder.mkdir()
    meshes.save(meshes.box([0.1, 0.2, 0.3]), folder / "brick.stl")
    path = write(
        folder, 'scenario = "rigid-body"\n[options.body]\nmesh = "brick.stl"\ndensity = 1000.0\n'
    )
    monkeypatch.chdir(tmp_path)  # elsewhere: the name must not be read from here
    body = read(path).options["body"]
    assert Path(body["mesh"]) == (folder / "brick.stl").resolve()


# --- every kind of mistake names the key ---------------------------------------------------

T_HANDLE = 'scenario = "t-handle"\n'
RIGID = 'scenario = "rigid-body"\n'
CYLINDER = '[options.body]\nshape = "cylinder"\nradius = 0.01\nlength = 0.08\ndensity = 6700.0\n'

BAD_FILES = {
    "unknown scenario": (
        'scenario = "t-handel"\n',
        "scenario = 't-handel' is not known; allowed: beam, convergence, ",
    ),
    "missing scenario": ("[options]\nh = 0.01\n", "scenario is missing (required)"),
    "unknown top-level key": (
        T_HANDLE + "h = 0.01\n",
        "h is not a top-level key of a scenario file; allowed: description, options, "
        "outputs, scenario, sweep (a scenario's options go under [options])",
    ),
    "unknown option": (
        T_HANDLE + "[options]\nspinz = []\n",
        "options.spinz is not an option of scenario 't-handle'; allowed: h, method, rtol, "
        "spins, t_end",
    ),
    "wrong type": (T_HANDLE + '[options]\nh = "fast"\n', "options.h = 'fast': must be a number"),
    "bool for a number": (T_HANDLE + "[options]\nt_end = true\n", "options.t_end = True: must be"),
    "negative h": (T_HANDLE + "[options]\nh = -0.01\n", "options.h = -0.01: must be > 0"),
    "zero h": (T_HANDLE + "[options]\nh = 0.0\n", "options.h = 0.0: must be > 0"),
    "negative t_end": (T_HANDLE + "[options]\nt_end = -1\n", "options.t_end = -1: must be > 0"),
    "nan": (T_HANDLE + "[options]\nh = nan\n", "options.h = nan: must be a finite number"),
    "unknown method": (
        T_HANDLE + '[options]\nmethod = "rk5"\n',
        "options.method = 'rk5': must be one of " + ", ".join(METHODS),
    ),
    "unknown method in a list": (
        'scenario = "torus-spin"\n[options]\nmethods = ["rkmk4", "rk9"]\n',
        "options.methods = ['rkmk4', 'rk9']: must be one of",
    ),
    "unknown ODE method": (
        'scenario = "projectile"\n[options]\nmethod = "rkmk4"\n',
        "options.method = 'rkmk4': must be one of euler, heun, midpoint, rk4, rk8, rkf45, dopri5",
    ),
    "wrong type in a nested list": (
        T_HANDLE + '[options]\nspins = [[1.0, 0.0, "x"]]\n',
        "options.spins[0][2] = 'x': must be a number",
    ),
    "short spin": (
        T_HANDLE + "[options]\nspins = [[1.0, 0.0]]\n",
        "options.spins[0] = [1.0, 0.0]: must be a list of 3 numbers (got 2)",
    ),
    "long second spin": (
        T_HANDLE + "[options]\nspins = [[1.0, 0.0, 0.0], [1.0, 2.0, 3.0, 4.0]]\n",
        "options.spins[1] = [1.0, 2.0, 3.0, 4.0]: must be a list of 3 numbers (got 4)",
    ),
    "no spins": (T_HANDLE + "[options]\nspins = []\n", "options.spins = []: must have at least"),
    "short omega0": (
        'scenario = "torus-spin"\n[options]\nomega0 = [1.0, 1.0]\n',
        "options.omega0 = [1.0, 1.0]: must be a list of 3 numbers (got 2)",
    ),
    "short vertex": (
        'scenario = "prism-impulse"\n[options]\nvertex = [45.0, 18.7]\n',
        "options.vertex = [45.0, 18.7]: must be a list of 3 numbers (got 2)",
    ),
    "no methods": (
        'scenario = "convergence"\n[options]\nmethods = []\n',
        "options.methods = []: must have at least one item",
    ),
    "one distinct step count": (
        'scenario = "convergence"\n[options]\nstep_counts = [100, 100]\n',
        "options.step_counts = [100, 100]: must hold at least 2 distinct values",
    ),
    "adaptive method for an order": (
        'scenario = "convergence"\n[options]\nmethods = ["rkmk4", "rkmk45"]\n',
        "options.methods = ['rkmk4', 'rkmk45']: must be one of "
        + ", ".join(
            name
            for name, method in METHODS.items()
            if not method.adaptive and method.flow != "exact"  # those with an order in h
        ),
    ),
    "float for an integer": (
        'scenario = "beam"\n[options]\nn_elements = 20.5\n',
        "options.n_elements = 20.5: must be an integer",
    ),
    "options not a table": (T_HANDLE + "options = 3\n", "options = 3: must be a table"),
    "outputs wrong type": (
        T_HANDLE + '[outputs]\nanimation = "yes"\n',
        "outputs.animation = 'yes': must be true or false",
    ),
    "unknown outputs key": (
        T_HANDLE + "[outputs]\nmovie = true\n",
        "outputs.movie is not a key of [outputs]; allowed: animation",
    ),
    "rigid-body without a body": (RIGID + "[options]\nh = 0.01\n", "options.body is missing"),
    "unknown shape": (
        RIGID + '[options.body]\nshape = "cone"\n',
        "options.body.shape = 'cone': must be one of cylinder, box, sphere, torus, hex_prism",
    ),
    "body of no kind": (
        RIGID + "[options.body]\nradius = 1.0\n",
        "options.body: the body needs shape (a primitive), parts (a composite) or mesh",
    ),
    "missing dimension": (
        RIGID + '[options.body]\nshape = "cylinder"\nradius = 0.01\ndensity = 1.0\n',
        "options.body.length is missing (required)",
    ),
    "missing dimension of a part": (
        RIGID + "[options.body]\ndensity = 1.0\n"
        '[[options.body.parts]]\nshape = "sphere"\nradius = 0.01\n'
        '[[options.body.parts]]\nshape = "cylinder"\nradius = 0.01\n',
        "options.body.parts[1].length is missing (required)",
    ),
    "negative dimension of a part": (
        RIGID + "[options.body]\ndensity = 1.0\n"
        '[[options.body.parts]]\nshape = "sphere"\nradius = -0.01\n',
        "options.body.parts[0].radius = -0.01: must be > 0",
    ),
    "unknown key of a part": (
        RIGID + "[options.body]\ndensity = 1.0\n"
        '[[options.body.parts]]\nshape = "sphere"\nradius = 0.01\nradiuss = 2\n',
        "options.body.parts[0].radiuss is not a key of a sphere; allowed: center, density, "
        "mass, radius, shape",
    ),
    "zero density": (
        RIGID + CYLINDER.replace("6700.0", "0.0"),
        "options.body.density = 0.0: must be > 0",
    ),
    "neither density nor mass": (
        RIGID + CYLINDER.replace("density = 6700.0\n", ""),
        "options.body: a cylinder needs exactly one of density (kg/m³) or mass (kg); got neither",
    ),
    "both density and mass": (
        RIGID + CYLINDER + "mass = 1.0\n",
        "options.body: a cylinder needs exactly one of density (kg/m³) or mass (kg); got both",
    ),
    "bad axis": (RIGID + CYLINDER + 'axis = "w"\n', "options.body.axis = 'w': must be \"x\""),
    "short vector": (
        RIGID + CYLINDER + "center = [0.0, 1.0]\n",
        "options.body.center = [0.0, 1.0]: must be a list of 3 numbers (got 2)",
    ),
    "torus radii": (
        RIGID + '[options.body]\nshape = "torus"\nmajor_radius = 1.0\nminor_radius = 2.0\n'
        "density = 1.0\n",
        "options.body: minor_radius=2.0 is not allowed: must be less than major_radius=1.0",
    ),
    "mesh file not found": (
        RIGID + '[options.body]\nmesh = "missing.stl"\ndensity = 1000.0\n',
        "options.body.mesh = 'missing.stl': no such file (looked for ",
    ),
    "unknown initial key": (
        RIGID + CYLINDER + "[options.initial]\nomega = [1.0, 0.0, 0.0]\n",
        "options.initial.omega is not a key of [options.initial]; allowed: L0, R0, euler_zyx, "
        "omega0, q0, v0, x0",
    ),
    "two attitudes": (
        RIGID + CYLINDER + "[options.initial]\nq0 = [1.0, 0.0, 0.0, 0.0]\n"
        "euler_zyx = [0.0, 0.0, 0.0]\n",
        "options.initial: give at most one of R0, q0, euler_zyx",
    ),
    "R0 not a rotation": (
        RIGID + CYLINDER + "[options.initial]\nR0 = [[1.0, 0, 0], [0, 1.0, 0], [0, 0, -1.0]]\n",
        "options.initial: R0=[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]] is not allowed: "
        "must be a rotation matrix",
    ),
    "zero quaternion": (
        RIGID + CYLINDER + "[options.initial]\nq0 = [0.0, 0.0, 0.0, 0.0]\n",
        "options.initial: q0=",
    ),
    "unknown load type": (
        RIGID + CYLINDER + '[[options.loads]]\ntype = "spring"\n',
        "options.loads[0].type = 'spring': must be one of gravity, force, torque, "
        "magnetic-dipole, impulse",
    ),
    "load without type": (
        RIGID + CYLINDER + "[[options.loads]]\ng = [0.0, 0.0, -9.81]\n",
        "options.loads[0].type is missing (required)",
    ),
    "force without its vector": (
        RIGID + CYLINDER + '[[options.loads]]\ntype = "force"\npoint = [0.0, 0.0, 0.04]\n',
        "options.loads[0].force is missing (required)",
    ),
    "bad number in a force": (
        RIGID + CYLINDER + '[[options.loads]]\ntype = "force"\nforce = [0.0, "a", 0.0]\n',
        "options.loads[0].force[1] = 'a': must be a number",
    ),
    "impulse after the end": (
        RIGID + CYLINDER + "[options]\nt_end = 1.0\n"
        '[[options.loads]]\ntype = "impulse"\nimpulse = [1.0, 0, 0]\npoint = [0.0, 0, 0]\n'
        "time = 2.0\n",
        "options: loads[0].time = 2.0 is after t_end = 1.0",
    ),
    "tolerance for a fixed step": (
        RIGID + "[options]\nrtol = 1e-6\n" + CYLINDER,
        "options: rtol=1e-06 is not allowed: must be None for the fixed-step method 'rkmk4'; "
        "tolerances apply only to the adaptive methods ('rkmk45', 'rkmk-dopri5')",
    ),
}


@pytest.mark.parametrize("text, message", BAD_FILES.values(), ids=list(BAD_FILES))
def test_bad_file_names_the_key(tmp_path, text, message):
    path = write(tmp_path, text)
    with pytest.raises(ValueError, match=re.escape(message)) as raised:
        read(path)
    assert str(raised.value).startswith(f"{path}: ")


def test_toml_syntax_error_gives_line_and_column(tmp_path):
    path = write(tmp_path, T_HANDLE + "[options]\nh = = 0.01\n")
    with pytest.raises(ValueError, match=r"not valid TOML: .*\(at line 3, column 5\)") as raised:
        read(path)
    assert str(path) in str(raised.value)


def test_missing_file_is_named(tmp_path):
    path = tmp_path / "nowhere.toml"
    with pytest.raises(ValueError, match=re.escape(f"{str(path)!r} cannot be read: no such file")):
        read(path)


def test_folder_is_not_a_file(tmp_path):
    with pytest.raises(ValueError, match="cannot be read: it is a folder"):
        read(tmp_path)


def test_file_that_is_not_utf8_is_refused(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes('scenario = "t-handle"\ndescription = "caf\xe9"\n'.encode("latin-1"))
    with pytest.raises(ValueError, match="cannot be read: 'utf-8' codec"):
        read(path)


def test_every_mistake_is_reported_on_its_own_line(tmp_path):
    path = write(tmp_path, T_HANDLE + '[options]\nh = -1.0\nmethod = "rk5"\n')
    with pytest.raises(ValueError) as raised:
        read(path)
    lines = str(raised.value).splitlines()
    assert len(lines) == 2
    assert "options.h = -1.0: must be > 0" in lines[0] + lines[1]
    assert "options.method = 'rk5'" in lines[0] + lines[1]


def test_open_mesh_is_refused_with_the_key(tmp_path):
    open_box = meshes.box([1.0, 1.0, 1.0])
    open_box.update_faces(np.arange(len(open_box.faces)) != 0)  # drop one triangle
    open_box.export(tmp_path / "open.stl")
    path = write(tmp_path, RIGID + '[options.body]\nmesh = "open.stl"\ndensity = 1000.0\n')
    with pytest.raises(ValueError, match=r"options\.body\.mesh = 'open.stl': .*closed \(watert"):
        read(path)


def test_inside_out_mesh_is_refused_with_the_key(tmp_path):
    inside_out = meshes.box([1.0, 1.0, 1.0])
    inside_out.invert()
    inside_out.export(tmp_path / "inverted.stl")
    path = write(tmp_path, RIGID + '[options.body]\nmesh = "inverted.stl"\ndensity = 1.0\n')
    with pytest.raises(ValueError, match=r"options\.body\.mesh = 'inverted.stl': .*inside-out"):
        read(path)


def test_unknown_scenario_in_check_options_lists_the_known_ones():
    with pytest.raises(ValueError, match="allowed: beam, .*rigid-body.*torus-spin"):
        check_options("spinning-plate", {})


def test_check_options_refuses_options_that_are_not_a_table():
    with pytest.raises(ValueError, match=r"options = \[1\]: must be a table"):
        check_options("t-handle", [1])


def test_trimesh_writes_the_open_mesh_that_the_test_above_uses(tmp_path):
    # Guard for test_open_mesh_is_refused_with_the_key: the STL must really be open.
    open_box = meshes.box([1.0, 1.0, 1.0])
    open_box.update_faces(np.arange(len(open_box.faces)) != 0)
    open_box.export(tmp_path / "open.stl")
    assert not trimesh.load_mesh(tmp_path / "open.stl").is_watertight


DERIVED = sorted(set(scenarios.names()) - {"rigid-body"})


def three_vector_options() -> list[tuple[str, str]]:
    """``(scenario, option)`` for every derived option in THREE_VECTORS."""
    return [
        (name, option)
        for name in DERIVED
        for option in options_model(name).model_fields
        if option in THREE_VECTORS
    ]


def test_every_three_vector_name_is_an_option_of_a_built_in_scenario():
    assert {option for _, option in three_vector_options()} == THREE_VECTORS


@pytest.mark.parametrize("name", DERIVED)
def test_every_option_whose_default_is_made_of_3_vectors_is_listed(name):
    for parameter in inspect.signature(scenarios.get(name).run).parameters.values():
        default = np.asarray(parameter.default if parameter.default is not None else [])
        if default.dtype.kind == "f" and default.shape[-1:] == (3,):
            assert parameter.name in THREE_VECTORS, f"{name}: {parameter.name}"


@pytest.mark.parametrize(("name", "option"), three_vector_options())
def test_a_three_vector_option_of_two_numbers_is_refused_by_its_key_path(name, option):
    nested = option == "spins"  # a list of vectors
    value = [[1.0, 2.0]] if nested else [1.0, 2.0]
    path = f"options.{option}[0]" if nested else f"options.{option}"
    with pytest.raises(ValueError, match=re.escape(f"{path} = [1.0, 2.0]: must be a list of 3")):
        check_options(name, {option: value})


@pytest.mark.parametrize(("name", "option"), three_vector_options())
def test_a_three_vector_option_of_three_numbers_is_accepted(name, option):
    value = [[1, 2, 3]] if option == "spins" else [1, 2, 3]
    expected = [[1.0, 2.0, 3.0]] if option == "spins" else [1.0, 2.0, 3.0]
    assert check_options(name, {option: value}) == {option: expected}


@pytest.mark.parametrize(
    ("name", "option"),
    [("t-handle", "spins"), ("convergence", "methods"), ("convergence", "step_counts")]
    + [(name, "methods") for name in ("prism-impulse", "sphere-exact", "torus-spin")],
)
def test_an_empty_list_is_refused_where_the_default_is_not_empty(name, option):
    with pytest.raises(ValueError, match=re.escape(f"options.{option} = []: must have at least")):
        check_options(name, {option: []})


def test_convergence_lists_only_fixed_step_methods():
    from tumble.scenarios.convergence import FIXED_STEP_METHODS

    listed = re.escape(", ".join(FIXED_STEP_METHODS))
    with pytest.raises(ValueError, match=f"must be one of {listed}$"):
        check_options("convergence", {"methods": "rkmk45"})
    assert "rkmk45" not in FIXED_STEP_METHODS and "rkmk8" in FIXED_STEP_METHODS


def test_a_primitive_whose_mass_overflows_is_refused_with_the_key(tmp_path):
    # Issue 18, item 11: the TOML path raised the raw OverflowError of mass.sphere.
    body = '[options.body]\nshape = "sphere"\nradius = 1e200\ndensity = 1e200\n'
    path = write(tmp_path, RIGID + body)
    with pytest.raises(
        ValueError, match=r"options\.body: radius=1e\+200 is not allowed: .*finite"
    ):
        read(path)


def test_a_mesh_with_a_separate_inside_out_part_is_refused_with_the_key(tmp_path):
    # Issue 18, item 1: only the sign of the total volume was checked.
    small = meshes.box([0.5, 0.5, 0.5], center=(1.5, 0.0, 0.0))
    small.invert()
    trimesh.util.concatenate([meshes.box([2.0, 2.0, 2.0]), small]).export(tmp_path / "two.stl")
    path = write(tmp_path, RIGID + '[options.body]\nmesh = "two.stl"\ndensity = 1.0\n')
    with pytest.raises(
        ValueError,
        match=r"options\.body\.mesh = 'two.stl': .*part 2 of 2 .* is inside-out .*flip that "
        r"part and save the file again",
    ):
        read(path)


@pytest.mark.parametrize("name", DERIVED)
def test_every_option_rule_names_an_option_of_its_own_scenario(name):
    from tumble.scenarios.option_models import rules

    options = set(inspect.signature(scenarios.get(name).run).parameters)
    assert rules(name).names() <= options, rules(name).names() - options


@pytest.mark.parametrize("name", DERIVED)
def test_a_scenario_declares_its_own_three_vector_options(name):
    """THREE_VECTORS gathers the scenarios' rules: an option is a 3-vector where declared."""
    from tumble.scenarios.option_models import rules

    for parameter in inspect.signature(scenarios.get(name).run).parameters.values():
        default = np.asarray(parameter.default if parameter.default is not None else [])
        if default.dtype.kind == "f" and default.shape[-1:] == (3,):
            assert parameter.name in rules(name).three_vectors, f"{name}: {parameter.name}"


@pytest.mark.parametrize("name", DERIVED)
def test_declared_positive_options_refuse_zero(name):
    from tumble.scenarios.option_models import rules

    model = options_model(name)
    for option in sorted(rules(name).positive):
        value = [0, 1] if "list" in str(model.model_fields[option].annotation) else 0
        with pytest.raises(ValueError, match=rf"options.{option} = .*must be > 0"):
            check_options(name, {option: value})


def test_the_docs_table_of_loads_has_every_load_type():
    from tumble.scenarios.loads import LOADS

    page = (Path(__file__).parents[2] / "docs" / "scenario-files.md").read_text()
    table = page.split("### `[[options.loads]]`")[1].split("###")[0]
    listed = re.findall(r"^\| `([a-z-]+)` \|", table, flags=re.MULTILINE)
    assert listed[1:] == list(LOADS)  # after the header's `type`
