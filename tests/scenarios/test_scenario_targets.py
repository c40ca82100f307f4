"""What ``tumble run NAME|FILE.toml`` runs: the scenario, its options, its folder."""

import dataclasses
import re
from pathlib import Path

import pytest

from tumble.scenarios import registry
from tumble.scenarios.files import read, read_target, with_overrides

EXAMPLES = Path(__file__).parents[2] / "examples"


def test_a_built_in_name_runs_its_defaults_with_the_overrides():
    target = read_target("t-handle", h=0.02, t_end=20.0)
    assert (target.scenario, target.folder, target.source) == ("t-handle", "t-handle", None)
    assert target.options == {"h": 0.02, "t_end": 20.0} and target.animation


def test_a_file_gives_its_options_its_stem_and_its_outputs():
    path = EXAMPLES / "t-handle.toml"
    target = read_target(str(path), t_end=5.0)
    assert target.options == {**read(path).options, "t_end": 5.0}
    assert (target.folder, target.source) == ("t-handle", str(path))


@pytest.mark.parametrize("name", [n for n in registry.names() if n != "rigid-body"])
def test_method_reaches_every_scenario_that_takes_one_or_several(name):
    from inspect import signature

    parameters = signature(registry.get(name).run).parameters
    if "method" not in parameters and "methods" not in parameters:
        with pytest.raises(ValueError, match=rf"--method='rkmk4' does not apply to scenario "
                           rf"'{name}'; its options are \["):  # fmt: skip
            with_overrides(name, {}, method="rkmk4")
        return
    options = with_overrides(name, {}, method="rkmk4")
    assert options == ({"method": "rkmk4"} if "method" in parameters else {"methods": ["rkmk4"]})


def test_rigid_body_by_name_is_refused_with_the_remedy():
    with pytest.raises(ValueError, match=r"run it from a TOML file \(tumble run FILE.toml"):
        read_target("rigid-body")


def test_an_unknown_name_lists_the_known_ones():
    with pytest.raises(ValueError, match=r"scenario='t-handel' is not allowed.*t-handle"):
        read_target("t-handel")


def test_a_bad_value_found_by_the_scenario_names_the_file(tmp_path):
    """The schema takes any minor radius > 0; the torus refuses one past its major radius."""
    path = tmp_path / "ring.toml"
    path.write_text('scenario = "torus-spin"\n[options]\nminor_radius = 5.0\n')
    target = read_target(str(path))
    with pytest.raises(
        ValueError, match=rf"^{re.escape(str(path))}: \[options\] minor_radius=5.0"
    ):
        target.run()


def test_a_bad_value_of_a_built_in_name_keeps_the_scenario_message():
    target = dataclasses.replace(read_target("torus-spin"), options={"minor_radius": 5.0})
    with pytest.raises(ValueError, match=r"^minor_radius=5.0 is not allowed"):
        target.run()
