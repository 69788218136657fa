"""Scenario keys of the 6-DOF truth plants: plant.*, initial.phi/p, sim.phi_limit, bad input."""
from __future__ import annotations

from pathlib import Path

import pytest

from auvtrack.scenario import ScenarioError, load_scenario
from auvtrack.scenario.overrides import parse_value

ROOT = Path(__file__).resolve().parents[2]
REMUS = ROOT / "scenarios" / "remus100.toml"


def test_bare_word_starting_with_a_digit_is_a_string():
    assert parse_value("6dof") == "6dof" and parse_value("5dof") == "5dof"
    assert parse_value("1e5") == 1e5 and parse_value("12") == 12  # TOML values stay values
    with pytest.raises(ValueError, match="not a TOML value"):
        parse_value("1.2.3")


def test_plant_model_6dof_as_typed_defaults_to_prestero():
    sc = load_scenario(REMUS, ["plant.model=6dof"])
    assert sc.plant.model == "6dof" and sc.plant.preset == "remus100_prestero"
    assert sc.plant.actuator_limits()["n_max"] == 1525.0
    assert load_scenario(sc.to_dict()) == sc
    sc = load_scenario(REMUS, ["plant.model=6dof", "plant.preset=remus100_fossen", "plant.delta_rate_max=inf",
                               "plant.T_delta=0.2", "initial.phi=0.1", "initial.p=-0.2", "sim.phi_limit=45"])
    assert sc.plant.actuator_limits()["T_delta"] == 0.2 and sc.initial.phi == 0.1 and sc.sim.phi_limit == 45
    assert load_scenario(sc.to_dict()) == sc
    assert "preset" not in load_scenario({}).to_dict()["plant"]  # the 5-DOF default writes model only


@pytest.mark.parametrize("sets, message", [
    (["plant.model=7dof"], r"plant.model: unknown model \(allowed: '5dof', '6dof', 'plugin'\) \(got '7dof'\)"),
    (["plant.model=6dof", "plant.preset=remus200"], r"plant.preset: unknown 6-DOF preset \(allowed: remus100_fossen, remus100_prestero, remus600 or a vehicle file .toml\)"),
    (["plant.preset=remus100_fossen"], r"plant.preset: only for plant.model = \"6dof\""),
    (["plant.n_max=1000"], r"plant.n_max: only for plant.model = \"6dof\""),
    (["plant.model=6dof", "plant.n_max=-5"], r"plant.n_max: must be > 0 \(got -5\)"),
    (["plant.model=6dof", "plant.delta_max=2.0"], r"plant.delta_max: must be <= 1.57"),
    (["plant.model=6dof", "uncertainty.M=0.2"], r"uncertainty.M: scales the 5-DOF plant only"),
    (["plant.model=6dof", "actuator.tau_max=[10, 1, 1]"], r"actuator.tau_max: limits the 5-DOF input only"),
    (["initial.phi=0.1"], r"initial.phi: roll exists only with plant.model = \"6dof\""),
    (["plant.model=6dof", "initial.phi=2.0"], r"initial.phi: must be < 1.57"),
    (["plant.model=6dof", "sim.phi_limit=0"], r"sim.phi_limit: must be > 0"),
])
def test_bad_plant_input_is_one_line_naming_the_field(sets, message):
    with pytest.raises(ScenarioError, match=message) as err:
        load_scenario(REMUS, sets)
    assert "\n" not in str(err.value)
