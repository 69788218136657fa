"""Suite files are validated at load like scenarios: every refusal one line naming the file and the
task or tier; what loads runs what it says (the controller of its row, the seed it records)."""
from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.benchmark import leaderboard
from auvtrack.benchmark.suite import (CRITERIA, ELL_KEYS, MAX_WEIGHT, MIN_WEIGHT, NORMAL_PROBE_STD, RUN_KEYS,
                                      START_AXES, SuiteError, load_suite, resolve_controllers)
from auvtrack.cli import EXIT_BAD_INPUT, main
from auvtrack.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = (ROOT / "auvtrack" / "data" / "benchmarks" / "auv-track-v1.toml").read_text()

TINY = """
name = "tiny"
version = 1
seed = 5
seeds = 3
bootstrap_resamples = 200
[base]
"vehicle.preset" = "remus100"
"sim.dt" = 0.002
"disturbance" = []
[tasks.helix]
duration = 3.0
reference = { kind = "helix", radius = 10.0, omega = 0.1, climb = -0.25, center = [0.0, 0.0, 20.0] }
[tasks.line]
duration = 2.0
reference = { kind = "line", start = [0.0, 0.0, 5.0], velocity = [1.0, 0.0, 0.0] }
[tiers.calm]
start = { lateral = 0.3 }
[tiers.calm.set]
"uncertainty.C" = 0.1
[tiers.model]
start = { lateral = 1.0, heading = 0.2 }
[tiers.model.random]
"uncertainty.M" = { dist = "uniform", low = -0.2, high = 0.2 }
"""


def _load(tmp_path: Path, text: str, name: str = "s.toml"):
    path = tmp_path / name
    path.write_text(text)
    return load_suite(path)


def _refused(tmp_path: Path, text: str) -> str:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(SuiteError) as info:
        load_suite(path)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith(f"{path}: "), msg
    return msg[len(f"{path}: "):]


def _edit(old: str, new: str, text: str = SHIPPED) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


# --- the items of the hardening issue, on the shipped suite ------------------------------------

HELIX = 'duration = 60.0\nreference = { kind = "helix"'
MODEL_START = 'start = { along = 2.0, lateral = 2.0, vertical = 1.0, heading = 0.3, speed = 0.2 }'
UNC_M = '"uncertainty.M" = { dist = "uniform", low = -0.2, high = 0.2 }'
CIRCLE = 'reference = { kind = "circle", radius = 40.0, omega = 0.025, depth = 10.0 }'


@pytest.mark.parametrize("old, new, expect", [
    (HELIX, HELIX.replace("60.0", "1e300"), "tasks.helix.duration: under tier 'ideal' the scenario refuses it: "
                                            "sim.duration: sim.duration / sim.dt = 1e+300 s"),
    (MODEL_START, MODEL_START.replace("along = 2.0", "along = 1e300"),
     "tiers.model.start: on task 'helix' the start offsets can put initial.eta."),
    (MODEL_START, MODEL_START.replace("heading = 0.3", "heading = 30.0"), "tiers.model.start.heading: must be <= "),
    (UNC_M, '"uncertainty.M" = { dist = "normal", mean = 0.0, std = 1e6 }',
     "tiers.model.random.uncertainty.M: on task 'helix' mean - 3 std -3e+06 is refused: uncertainty.M: "
     "must be >= -0.9"),
    ("failure = 3.0", "failure = 1e308", "scoring.failure: must be 0 or in [1e-06, 1e+06]"),
    ('gain_preset = "{kind}_tuned"', 'gain_preset = "{kind}_{}"', "gain_preset: must be a preset name with {kind}"),
    ('gain_preset = "{kind}_tuned"', 'gain_preset = "{kind}_{bogus}"', "gain_preset: must be a preset name"),
    ('[base]', '[base]\n"controller.kind" = "ftsmc"', "base: 'controller.kind' would overwrite controller, which the "
                                                     "comparison sets for every run"),
    ('[base]', '[base]\n"seed" = 5', "base: 'seed' would overwrite seed"),
    ('"sim.dt" = 0.002', '"sim.dt" = 1e-9', "tiers.ideal.set on task 'helix': the scenario refuses it: sim.dt: "
                                             "sim.duration / sim.dt = 60 s / 1e-09 s"),
    ('tau = 60.0 }', 'tau = 60.0, sample_dt = 1e-7 }', "tiers.ocean.set on task 'helix': the scenario refuses it: "
                                                       "disturbance.0.sample_dt:"),
    (CIRCLE, CIRCLE.replace('kind = "circle",', 'kind = "circle", bogus = 1,'),
     "tasks.circle.reference.bogus: unknown key (allowed: "),
    (CIRCLE, CIRCLE.replace('"circle"', '"bogus"'), "tasks.circle.reference.kind: must be one of "),
    (CIRCLE, CIRCLE.replace("omega = 0.025", "omega = 0.0"), "tasks.circle.reference: starts at rest"),
    ('"plant.preset" = ["remus100_prestero", "remus100_fossen"]', '"plant.preset" = ["remus100_prestero", "bogus"]',
     "tiers.truth6.cycle.plant.preset.1 on task 'helix': the scenario refuses it: plant.preset: unknown 6-DOF "
     "preset"),
])
def test_the_hostile_suites_are_one_line_naming_the_field(tmp_path, old, new, expect):
    msg = _refused(tmp_path, _edit(old, new))
    assert msg.startswith(expect), msg
    assert "set by override" not in msg and "'bogus'" != msg.strip()


def test_a_plan_limit_hint_names_the_suite_key(tmp_path):
    msg = _refused(tmp_path, _edit('"sim.dt" = 0.002', '"sim.dt" = 1e-9'))
    assert msg.endswith('(raise it deliberately with "limits.max_steps" in [base])')


def test_the_cli_refuses_a_bad_suite_before_any_run(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(_edit('[base]', '[base]\n"controller.kind" = "ftsmc"'))
    out = tmp_path / "out"
    assert main(["compare", "--suite", str(path), "--out", str(out), "--quiet"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"auvtrack: error: {path}: base: 'controller.kind'")
    assert not out.exists()


@pytest.mark.parametrize("kind", ["dir", "fifo", "deep"])
def test_unreadable_suite_files_are_one_line(tmp_path, kind):
    path = tmp_path / "s.toml"
    if kind == "dir":
        path.mkdir()
    elif kind == "fifo":
        if not hasattr(os, "mkfifo"):
            pytest.skip("no FIFOs")
        os.mkfifo(path)
    else:
        path.write_text(SHIPPED.replace("[base]", "[base]\n\"a\" = " + "[" * 5000 + "]" * 5000, 1))
    with pytest.raises(SuiteError) as info:
        load_suite(path)
    assert "\n" not in str(info.value) and str(info.value).startswith(f"{path}: ")


# --- the keys a suite cannot set ------------------------------------------------------------------

_OWNED = [".".join(k) for k in RUN_KEYS]
_ABOVE = sorted({".".join(k[:-1]) for k in RUN_KEYS if len(k) > 1})
_BELOW = ["controller.kind", "controller.k1", "reference.radius", "initial.eta.0", "initial.nu.1"]


@given(key=st.sampled_from(_OWNED + _ABOVE + _BELOW), where=st.sampled_from(["base", "set", "random", "cycle"]))
@settings(max_examples=60, deadline=None)
def test_no_suite_key_can_set_what_each_run_sets(tmp_path_factory, key, where):
    """Equal to, above or below a key the comparison sets per run: refused wherever it is given."""
    value = '{ dist = "uniform", low = 0.0, high = 1.0 }' if where == "random" else "[1]" if where == "cycle" \
        else "1"
    section = {"base": "[base]", "set": "[tiers.calm.set]", "random": "[tiers.model.random]",
               "cycle": "[tiers.calm.cycle]"}[where]
    text = TINY.replace(section, f'{section}\n"{key}" = {value}') if section in TINY \
        else TINY + f'\n{section}\n"{key}" = {value}\n'
    msg = _refused(tmp_path_factory.mktemp("k"), text)
    prefix = "base" if where == "base" else f"tiers.{'model' if where == 'random' else 'calm'}.{where}"
    assert msg.startswith(f"{prefix}: '{key}' would overwrite "), msg


@pytest.mark.parametrize("key", [".".join(k) for k in ELL_KEYS])
def test_the_start_offset_cannot_vary_between_seeds(tmp_path, key):
    msg = _refused(tmp_path, TINY + f'\n[tiers.calm.cycle]\n"{key}" = [1.0, 2.0]\n')
    assert msg.startswith(f"tiers.calm.cycle: '{key}' cannot vary between seeds"), msg


def test_a_tier_may_set_its_vehicle_and_its_starts_use_it(tmp_path):
    """ℓ of a tier's set places its starts: the virtual point starts where the tier says."""
    suite = _load(tmp_path, TINY.replace('[tiers.calm.set]', '[tiers.calm.set]\n"vehicle.l" = 0.5'))
    assert suite.ell("calm") == 0.5 and suite.ell("model") == load_scenario({}, ["vehicle.preset=remus100"]).vehicle.l
    from auvtrack.vehicle.kinematics import attitude, virtual_point

    for tier in suite.tiers:
        raw, ov, drawn = suite.scenario(resolve_controllers(["ftsmc"])[0], "line", tier, 1)
        sc = load_scenario(raw, ov)
        eta = sc.initial.eta
        p1 = np.array(virtual_point(eta, attitude(eta[3], eta[4]), sc.vehicle.l))
        # the line starts at [0, 0, 5] heading north: the lateral offset is east of it
        np.testing.assert_allclose(p1, [0.0, drawn["start.lateral"], 5.0], atol=1e-12)


# --- what loads runs what it records ---------------------------------------------------------------

def test_every_run_flies_its_row_and_records_its_seed():
    """Over the shipped suite: each run's scenario has the row's controller, the recorded seed, the
    task's duration and reference (what runs.parquet and the report say)."""
    suite = load_suite()
    entries = resolve_controllers()
    for task in suite.tasks:
        for tier in suite.tiers:
            for i in (0, suite.seeds - 1):
                for e in entries:
                    raw, ov, _ = suite.scenario(e, task, tier, i)
                    sc = load_scenario(raw, ov)
                    assert sc.controller.kind == e.table["kind"]
                    assert sc.seed == raw["seed"] == suite.scenario_seed(task, i)
                    assert sc.sim.duration == suite.duration(task)
                    assert sc.reference == load_scenario({"reference": suite.file.tasks[task].reference}).reference


@given(h=st.fixed_dictionaries({a: st.floats(0, 2e6) for a in ("along", "lateral", "vertical")}
                                | {"heading": st.floats(0, math.pi), "speed": st.floats(0, 0.99)}),
       index=st.integers(0, 2))
@settings(max_examples=40, deadline=None)
def test_a_suite_that_loads_draws_only_valid_starts(tmp_path_factory, h, index):
    """Whatever the half-widths: either the suite is refused at load, naming the tier's start, or
    every start it draws is a valid initial state."""
    start = "{ " + ", ".join(f"{k} = {v!r}" for k, v in h.items()) + " }"
    text = TINY.replace("start = { lateral = 1.0, heading = 0.2 }", f"start = {start}")
    path = tmp_path_factory.mktemp("st") / "s.toml"
    path.write_text(text)
    try:
        suite = load_suite(path)
    except SuiteError as exc:
        assert re.match(rf"{re.escape(str(path))}: tiers\.model\.start: on task '\w+' the start offsets can put "
                        r"initial\.(eta|nu)\.\d", str(exc)), str(exc)
        return
    e = resolve_controllers(["ftsmc"])[0]
    for task in suite.tasks:
        raw, ov, _ = suite.scenario(e, task, "model", index)
        load_scenario(raw, ov)


@pytest.mark.parametrize("std, accepted", [(0.01, True), (0.2, True), (0.4, False)])
def test_a_normal_draw_is_checked_at_three_std(tmp_path, std, accepted):
    """uncertainty.M is allowed in [-0.9, 2.0]: a normal around 0.3 with std s passes iff 0.3 - 3 s >= -0.9."""
    text = TINY.replace('"uncertainty.M" = { dist = "uniform", low = -0.2, high = 0.2 }',
                        f'"uncertainty.M" = {{ dist = "normal", mean = 0.3, std = {std} }}')
    assert (0.3 - NORMAL_PROBE_STD * std >= -0.9) == accepted
    if accepted:
        _load(tmp_path, text)
    else:
        assert _refused(tmp_path, text).startswith("tiers.model.random.uncertainty.M: on task 'helix' mean - 3 std")


def test_values_every_controller_refuses_are_refused_and_some_refusals_are_not(tmp_path):
    """A cell every default competitor refuses fails the suite; a value only one controller refuses
    (the FXTNTSMC's RBF scratch space) stays that controller's set-up failure."""
    msg = _refused(tmp_path, TINY.replace('"sim.dt" = 0.002', '"sim.dt" = 0.002\n"limits.max_steps" = 10'))
    assert msg.startswith("tasks.helix.duration: under tier 'calm' the scenario refuses it: sim.duration:"), msg
    suite = _load(tmp_path, TINY.replace('"sim.dt" = 0.002', '"sim.dt" = 0.002\n"estimator.neurons" = 100000'))
    from auvtrack.simulation.pipeline import prepare

    raw, ov, _ = suite.scenario(resolve_controllers(["fxtntsmc"])[0], "helix", "calm", 0)
    with pytest.raises(ValueError, match="neurons"):
        prepare(load_scenario(raw, ov))


# --- gain presets and scoring weights ---------------------------------------------------------------

@given(pattern=st.text(alphabet="{}kind_x0!r:.>", max_size=14))
@settings(max_examples=200, deadline=None)
def test_any_gain_preset_pattern_loads_and_formats_or_is_one_line(tmp_path_factory, pattern):
    text = TINY.replace('name = "tiny"', f'name = "tiny"\ngain_preset = {pattern!r}'.replace("'", '"'), 1) \
        if '"' not in pattern and "\\" not in pattern else TINY
    path = tmp_path_factory.mktemp("g") / "s.toml"
    path.write_text(text)
    try:
        suite = load_suite(path)
    except SuiteError as exc:
        assert "\n" not in str(exc) and "gain_preset: must be a preset name" in str(exc)
        return
    name = suite.file.gain_preset.format(kind="pid")
    assert "pid" in name and re.fullmatch(r"[A-Za-z0-9_.+\-]+", name)
    resolve_controllers(["pid"], gain_preset=suite.file.gain_preset)


@given(w=st.floats(0, 1e300) | st.sampled_from([MIN_WEIGHT, MAX_WEIGHT, math.nextafter(MAX_WEIGHT, math.inf),
                                                  math.nextafter(MIN_WEIGHT, 0.0), 5e-324]))
@settings(max_examples=60, deadline=None)
def test_weights_are_zero_or_within_the_bounds(tmp_path_factory, w):
    text = TINY + "[scoring]\n" + "\n".join(f"{c} = {w!r}" for c in CRITERIA) + "\n"
    path = tmp_path_factory.mktemp("w") / "s.toml"
    path.write_text(text)
    if MIN_WEIGHT <= w <= MAX_WEIGHT:
        assert load_suite(path, check=False).file.scoring.weights() == {c: w for c in CRITERIA}
    else:
        with pytest.raises(SuiteError, match="scoring: must give at least one criterion a weight > 0" if w == 0
                           else r"scoring\.failure: must be 0 or in \[1e-06, 1e\+06\]"):
            load_suite(path, check=False)


@given(weights=st.fixed_dictionaries({c: st.sampled_from([0.0, MIN_WEIGHT, 1.0, MAX_WEIGHT]) for c in CRITERIA})
       .filter(lambda d: any(d.values())), values=st.lists(st.floats(0, 1e6), min_size=3, max_size=3, unique=True))
@settings(max_examples=60, deadline=None)
def test_any_accepted_weights_give_the_rank_as_score(weights, values):
    """Three controllers ordered alike on every criterion: each cell score is the weighted mean of
    equal ranks, so it is the rank itself, finite, at the extreme accepted weights too."""
    order = sorted(values)
    table = {("x", "t"): {n: {c: v for c in CRITERIA} for n, v in zip("abc", values)}}
    cells = leaderboard.score_table(table, weights)["cells"][("x", "t")]
    for n, v in zip("abc", values):
        assert cells[n]["score"] == pytest.approx(order.index(v) + 1.0, rel=1e-12)
