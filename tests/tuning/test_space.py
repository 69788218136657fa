"""Search spaces read from the controllers' ``Params`` models, and the set-up conditions as constraints."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from optuna.distributions import FloatDistribution

from auvtrack.control import BUILTIN_NAMES, CONTROLLERS
from auvtrack.control.plugin import load as load_plugin
from auvtrack.control.registry import ControllerParams, tunable
from auvtrack.scenario.loader import load_scenario, paper_scenario_path
from auvtrack.tuning import constraint_violations, distributions, search_space
from auvtrack.tuning.space import field_values

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "plugin_controller.py"
TRACKING = sorted(n for n in BUILTIN_NAMES if CONTROLLERS[n].tracks)  # a learned policy has no gains


def _scenario(kind: str, **gains):
    body = ", ".join([f'kind="{kind}"'] + [f"{k}={v!r}" for k, v in gains.items()])
    return load_scenario(paper_scenario_path(), [f"controller={{{body}}}", "sim.duration=1"])


@pytest.mark.parametrize("kind", TRACKING)
def test_every_tracking_builtin_declares_a_space_inside_its_admissible_range(kind):
    params = CONTROLLERS[kind].params
    space = search_space(params)
    assert space, f"{kind} declares no tunable gain"
    for name, dim in space.items():
        assert dim.contains(dim.default), (kind, name)
        assert dim.low < dim.high and (not dim.log or dim.low > 0)
        for value in (dim.low, dim.high):  # both ends are gains the model accepts
            params(**field_values({name: dim}, {name: value}))


def test_ranges_and_scales_are_the_declared_ones():
    pid = search_space(CONTROLLERS["pid"].params)
    assert list(pid) == ["kp", "ki", "kd", "kaw"]
    assert (pid["kp"].low, pid["kp"].high, pid["kp"].log, pid["kp"].default) == (0.01, 30.0, True, 3.0)
    ftsmc = search_space(CONTROLLERS["ftsmc"].params)
    assert (ftsmc["gamma"].low, ftsmc["gamma"].high, ftsmc["gamma"].log) == (1.05, 1.95, False)


def test_model_assumptions_and_form_switches_are_not_searched():
    assert "L" not in search_space(CONTROLLERS["sta"].params)
    fx = search_space(CONTROLLERS["fxtntsmc"].params)
    assert not {"sigma", "varsigma1", "z_switch", "z_floor", "surface", "saturation"} & set(fx)
    assert "rho0" not in search_space(CONTROLLERS["ppc"].params)


def test_a_plugin_declares_its_space_the_same_way():
    _, spec = load_plugin(str(EXAMPLE))
    space = search_space(spec.params)
    assert set(space) == {"kp", "kd"}
    assert (space["kp"].low, space["kp"].high, space["kp"].log) == (0.01, 100.0, True)


def test_a_model_without_tunable_fields_has_an_empty_space():
    class Plain(ControllerParams):
        k: float = 1.0

    assert search_space(Plain) == {}


def test_tunable_refuses_an_empty_or_nonpositive_log_range():
    with pytest.raises(ValueError, match="low < high"):
        tunable(1.0, 2.0, 1.0)
    with pytest.raises(ValueError, match="log scale"):
        tunable(1.0, 0.0, 2.0, log=True)


def test_distributions_carry_range_and_log_flag():
    d = distributions(search_space(CONTROLLERS["ftsmc"].params))
    assert d["gamma"] == FloatDistribution(1.05, 1.95, log=False)
    assert d["k1"] == FloatDistribution(1e-4, 1.0, log=True)


@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_any_point_of_a_space_is_a_valid_params(data):
    kind = data.draw(st.sampled_from(TRACKING))
    params = CONTROLLERS[kind].params
    point = {n: data.draw(st.floats(d.low, d.high)) for n, d in search_space(params).items()}
    values = field_values(search_space(params), point)
    dumped = params(**values).model_dump()
    assert all(list(dumped[k]) == v if isinstance(v, list) else dumped[k] == v for k, v in values.items())


@pytest.mark.parametrize("kind", TRACKING)
def test_package_defaults_meet_their_constraints(kind):
    assert constraint_violations(_scenario(kind)) == []


@pytest.mark.parametrize("kind, gains, field", [
    ("pid", {"kp": 1.0, "kd": 1.0, "ki": 2.0}, "controller.ki"),                            # Routh-Hurwitz
    ("sta", {"gain_condition": "levant", "L": 0.5, "k2": 0.4}, "controller.k2"),            # Levant (S4)
    ("sta", {"gain_condition": "moreno_osorio", "L": 0.5, "k1": 0.1, "k2": 0.6}, "controller.k2"),  # (S5)
    ("fxtntsmc", {"kappa3": 0.4}, "controller.kappa3"),                                     # Theorem 1
])
def test_broken_setup_conditions_are_reported_as_violations(kind, gains, field):
    problems = constraint_violations(_scenario(kind, **gains))
    assert problems and any(field in p for p in problems), problems
