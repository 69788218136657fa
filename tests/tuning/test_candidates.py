"""Candidates differ from the designed controller in the searched gains only; presets hold every field; vector gains."""
from __future__ import annotations

import math

import pytest

from auvtrack.benchmark.suite import load_suite, tracking_kinds
from auvtrack.control import gain_presets
from auvtrack.control.registry import ControllerParams, tunable
from auvtrack.scenario import load_scenario
from auvtrack.tuning.objective import candidate_table, split_specs
from auvtrack.tuning.outputs import preset_text
from auvtrack.tuning.space import field_values, search_space, searched_fields
from auvtrack.tuning.study import TuneResult, _params_model, designed_base, untuned_gains


@pytest.fixture(scope="module")
def v2():
    return load_suite("auv-track-v2", check=False)


def _bare(suite, kind):
    spec = split_specs(suite, {"kind": kind}, "training")[0]
    return spec, load_scenario(spec.raw, spec.overrides).to_dict()["controller"]


@pytest.mark.parametrize("kind", tracking_kinds())
def test_a_candidates_unsearched_fields_are_the_designed_controllers(v2, kind):
    spec, designed = _bare(v2, kind)
    space = search_space(_params_model({"kind": kind}))
    base = designed_base(spec, {"kind": kind}, space)
    unsearched = {k: v for k, v in designed.items() if k not in searched_fields(space)}
    assert {k: base[k] for k in unsearched} == unsearched and set(base) == set(unsearched)
    # any candidate of the space keeps them: its resolved controller differs in the searched fields only
    point = {n: d.low if i % 2 else d.high for i, (n, d) in enumerate(space.items())}
    table = candidate_table(base, field_values(space, point))
    resolved = load_scenario(split_specs(v2, table, "training")[0].raw, spec.overrides).to_dict()["controller"]
    assert {k: resolved[k] for k in unsearched} == unsearched


@pytest.mark.parametrize("kind", ["sta", "pid", "backstepping", "ppc"])
def test_the_untuned_candidate_is_the_designed_controller(v2, kind):
    spec, designed = _bare(v2, kind)
    space = search_space(_params_model({"kind": kind}))
    gains = untuned_gains(spec, space)
    assert all(d.contains(gains[n]) for n, d in space.items())
    table = candidate_table(designed_base(spec, {"kind": kind}, space), field_values(space, gains))
    resolved = load_scenario(split_specs(v2, table, "training")[0].raw, spec.overrides).to_dict()["controller"]
    assert resolved == designed
    assert designed.get("saturation") == "compensated"


def test_a_preset_reproduces_the_tuned_controller_with_its_non_numeric_fields(v2, tmp_path, monkeypatch):
    spec, designed = _bare(v2, "ppc")
    space = search_space(_params_model({"kind": "ppc"}))
    best = {n: math.sqrt(d.low * d.high) for n, d in space.items()}
    table = candidate_table(designed_base(spec, {"kind": "ppc"}, space), field_values(space, best))
    res = TuneResult(controller={"kind": "ppc"}, suite="auv-track-v2", suite_version=1, split="training",
                     trials=1, best_params=best, table=table)
    (tmp_path / "ppc_x.toml").write_text(preset_text(res, {"tool": "auvtrack tune"}))
    monkeypatch.setattr(gain_presets, "_gains_root", lambda: tmp_path)
    preset = gain_presets.get_gain_preset("ppc_x")
    assert preset.gains["saturation"] == "compensated" and preset.gains["rho0"] == list(designed["rho0"])
    with_preset = split_specs(v2, {"kind": "ppc", "preset": "ppc_x"}, "training")[0]
    from_preset = load_scenario(with_preset.raw, with_preset.overrides)
    from_table = load_scenario(split_specs(v2, table, "training")[0].raw, spec.overrides)
    assert from_preset.controller == from_table.controller
    assert list(from_preset.controller.rho_inf) == [best["rho_inf"]] * 3


def test_a_preset_value_of_another_type_is_one_line(tmp_path, monkeypatch):
    (tmp_path / "bad.toml").write_text('kind = "pid"\n[gains]\nkp = [1.0, "a"]\n')
    monkeypatch.setattr(gain_presets, "_gains_root", lambda: tmp_path)
    with pytest.raises(ValueError, match=r"gains.kp must be a number, string, boolean, list of numbers"):
        gain_presets.get_gain_preset("bad")


class _Vec(ControllerParams):
    shared: tuple[float, float, float] = tunable((0.1, 0.2, 0.3), 0.01, 1.0, log=True)
    each: tuple[float, float] = tunable((2.0, 3.0), 1.0, 5.0, per_item=True)
    k: float = tunable(1.0, 0.5, 2.0)


def test_a_vector_gain_is_one_shared_dimension_or_one_per_item():
    space = search_space(_Vec)
    assert list(space) == ["shared", "each[0]", "each[1]", "k"]
    assert (space["shared"].size, space["shared"].item, space["shared"].log) == (3, None, True)
    assert space["shared"].default == pytest.approx(0.2)  # the mean of the items
    assert [space[f"each[{i}]"].default for i in (0, 1)] == [2.0, 3.0] and space["each[1]"].target == "each"
    values = field_values(space, {"shared": 0.5, "each[0]": 1.5, "each[1]": 4.5, "k": 0.7})
    assert values == {"shared": [0.5, 0.5, 0.5], "each": [1.5, 4.5], "k": 0.7}
    assert _Vec(**values).each == (1.5, 4.5)
    assert searched_fields(space) == {"shared", "each", "k"}


def test_the_ppc_searches_its_envelope_floor_as_one_value():
    space = search_space(_params_model({"kind": "ppc"}))
    d = space["rho_inf"]
    assert (d.low, d.high, d.log, d.size) == (0.005, 1.0, True, 3) and "rho0" not in space
