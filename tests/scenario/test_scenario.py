"""Scenario model, TOML loading, overrides and one-line errors (auvtrack.scenario)."""
from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import pytest

from auvtrack.scenario import Scenario, ScenarioError, load_scenario
from auvtrack.scenario.schema import CONTROLLER_MODELS

PAPER = Path(__file__).resolve().parents[2] / "scenarios" / "paper.toml"


def assert_section4(sc: Scenario) -> None:
    """The numbers of the paper's Section 4 (with the ERRATA choices)."""
    assert sc.seed == 0
    assert (sc.sim.duration, sc.sim.dt, sc.sim.log_dt, sc.sim.control_rate) == (100.0, 0.001, 0.01, 0.0)
    assert sc.sim.theta_limit == 85.0 and sc.sim.integrator == "rk4"
    assert sc.vehicle.preset == "paper" and sc.vehicle.l == 1.0  # ERRATA 5/6 assumption
    assert sc.vehicle.m == (215.0, 265.0, 265.0, 80.0, 80.0)
    assert sc.vehicle.d == (70.0, 100.0, 100.0, 50.0, 50.0)
    assert (sc.uncertainty.C, sc.uncertainty.D, sc.uncertainty.M, sc.uncertainty.G) == (0.1, 0.1, 0.0, 0.0)
    ref = sc.reference
    assert (ref["kind"], ref["radius"], ref["omega"], ref["climb"]) == ("helix", 4.0, 0.1, -0.1)
    assert ref["center"] == [0.0, 0.0, 0.0] and ref["phase"] == 0.0
    assert sc.initial.eta == (0.0, 0.5, 0.0, 0.0, 0.0) and sc.initial.nu == (0.0,) * 5
    c = sc.controller
    assert c.kind == "fxtntsmc"
    assert (c.kappa1, c.kappa2, c.kappa3) == (0.005, 0.8, 0.6)
    assert (c.a1, c.a2, c.a3, c.a4) == (0.8, 0.8, 0.8, 2.0)  # a3 = b1, a4 = b2 (ERRATA 11)
    assert (c.alpha, c.sigma, c.varsigma1) == (0.6, 0.005, 0.05)  # varsigma1 = "zeta1"
    e = sc.envelope
    assert e.kind == "proactive" and e.baseline == "corrected"  # ERRATA 7
    assert e.rho0 == (5.0, 0.5, 0.2) and e.rho_inf == (0.005,) * 3 and e.T == 15.0
    assert (e.delta, e.epsilon, e.lambda1, e.lambda2, e.lambda3) == (2.0, 0.1, 0.5, 0.3, 0.1)
    assert e.widen_start is True and 0 < e.xi0 < 1  # ERRATA 9
    est = sc.estimator
    assert (est.kind, est.neurons, est.width) == ("effective", 7, 1.0)
    assert est.centre_range == (-1.0, 1.0) and est.weight_range == (0.0, 1.0)
    assert sc.disturbance == [{"kind": "paper", "amplitude": 1.0, "phase": 0.0}]
    assert sc.metrics.window == (0.0, math.inf)
    assert sc.output.mat is False


# --- defaults and the paper file ----------------------------------------------------------------

def test_empty_dict_is_paper_defaults():
    sc = load_scenario({})
    assert sc == Scenario()
    assert sc.name == "paper"
    assert_section4(sc)


def test_paper_toml_is_section4():
    sc = load_scenario(PAPER)
    assert_section4(sc)
    assert sc.model_copy(update={"description": ""}) == load_scenario({})


def test_paper_toml_writes_every_key():
    """Every key of the resolved scenario is spelled out in scenarios/paper.toml."""
    raw = tomllib.loads(PAPER.read_text())
    full = load_scenario({}).to_dict()
    for section, value in full.items():
        assert section in raw, section
        if isinstance(value, dict):
            assert set(raw[section]) == set(value), section
    assert set(raw["disturbance"][0]) == set(full["disturbance"][0])


def test_string_and_path_sources_agree():
    assert load_scenario(str(PAPER)) == load_scenario(PAPER)


def test_scenario_source_is_returned_or_overridden():
    sc = load_scenario({})
    assert load_scenario(sc) is sc
    assert load_scenario(sc, ["sim.duration=10"]).sim.duration == 10.0


# --- overrides ----------------------------------------------------------------------------------

def test_override_scalar_and_list():
    sc = load_scenario(PAPER, ["sim.dt=0.002", "initial.eta=[0,1,0,0,0]", "seed=7", "output.mat=true"])
    assert sc.sim.dt == 0.002 and sc.initial.eta == (0.0, 1.0, 0.0, 0.0, 0.0)
    assert sc.seed == 7 and sc.output.mat is True


def test_override_dict_form():
    sc = load_scenario({}, {"sim.dt": 0.002, "envelope.rho0": 1.0})
    assert sc.sim.dt == 0.002 and sc.envelope.rho0 == (1.0, 1.0, 1.0)


def test_override_kind_switch_resets_section():
    sc = load_scenario(PAPER, ["controller.kind=ftsmc", "controller.k1=0.1"])
    assert sc.controller.kind == "ftsmc" and sc.controller.k1 == 0.1
    sc = load_scenario(PAPER, ['controller.kind="ftsmc"'])
    assert sc.controller.kind == "ftsmc"
    ref = load_scenario(PAPER, ["reference.kind=circle", "reference.radius=3",
                                      "reference.omega=0.2", "reference.depth=2"]).reference
    assert ref["kind"] == "circle" and ref["radius"] == 3.0 and ref["depth"] == 2.0


def test_override_same_kind_keeps_section():
    sc = load_scenario({"controller": {"kappa1": 0.01}}, ["controller.kind=fxtntsmc"])
    assert sc.controller.kappa1 == 0.01
    sc = load_scenario({"envelope": {"rho0": [1, 1, 1]}}, ["envelope.kind=rigid"])  # shared keys
    assert sc.envelope.kind == "rigid" and sc.envelope.rho0 == (1.0, 1.0, 1.0)


def test_override_list_index_and_append():
    sc = load_scenario(PAPER, ["disturbance.0.amplitude=2"])
    assert sc.disturbance[0]["amplitude"] == 2.0
    sc = load_scenario({}, ["disturbance.0.amplitude=2", "initial.eta.1=0.7", "vehicle.m.0=300"])
    assert sc.disturbance[0]["amplitude"] == 2.0  # the default list is materialised
    assert sc.initial.eta[1] == 0.7 and sc.vehicle.m[0] == 300.0 and sc.vehicle.m[1] == 265.0
    sc = load_scenario(PAPER, ["disturbance.1.kind=pulse", "disturbance.1.start=10",
                               "disturbance.1.duration=inf", "disturbance.1.force=[5,0,0,0,0]"])
    assert [d["kind"] for d in sc.disturbance] == ["paper", "pulse"]
    assert load_scenario(PAPER, ["disturbance.0.kind=pulse", "disturbance.0.start=1",
                                 "disturbance.0.duration=2", "disturbance.0.force=[1,0,0,0,0]"]
                         ).disturbance[0]["kind"] == "pulse"


def test_override_inline_table_and_empty_list():
    sc = load_scenario(PAPER, ['controller={kind="ftsmc", k2=2.0}', "disturbance=[]"])
    assert sc.controller.kind == "ftsmc" and sc.controller.k2 == 2.0 and sc.disturbance == []


def test_override_bare_word_is_string():
    assert load_scenario({}, ["name=run-1"]).name == "run-1"


@pytest.mark.parametrize("override, needle", [
    ("sim.dt", "expected dotted.key=value"),
    ("sim.dt=", "missing value"),
    ("sim..dt=1", "bad key segment"),
    ("name=two words", "not a TOML value"),
    ("disturbance.5.amplitude=1", "index out of range"),
    ("sim.0=1", "sim is a table"),
    ("=3", "expected dotted.key=value"),
])
def test_malformed_override(override, needle):
    with pytest.raises(ScenarioError) as err:
        load_scenario(PAPER, [override])
    assert "\n" not in str(err.value) and needle in str(err.value)
    assert repr(override) in str(err.value)


def test_override_error_names_the_override():
    with pytest.raises(ScenarioError, match=r"paper\.toml: sim\.dt: must be > 0 \(got -1\) "
                                            r"\(set by override 'sim\.dt=-1'\)"):
        load_scenario(PAPER, ["sim.dt=-1"])


# --- round trip ---------------------------------------------------------------------------------

@pytest.mark.parametrize("overrides", [
    [],
    ["controller.kind=ftsmc", "sim.control_rate=100"],
    ["reference.kind=line", "reference.start=[0,0,0]", "reference.velocity=[1,0,0]",
     "disturbance.1.kind=pulse", "disturbance.1.start=5", "disturbance.1.duration=inf",
     "disturbance.1.force=[1,0,0,0,0]", "metrics.window=[10, 50]", "vehicle.l=2.5"],
    ["envelope.kind=none", "estimator.kind=none", "disturbance=[]", "uncertainty.M=-0.2"],
])
def test_to_dict_round_trip(overrides):
    sc = load_scenario(PAPER, overrides)
    d = sc.to_dict()
    json.dumps(d, allow_nan=False)  # JSON-serialisable, no NaN/inf literals
    assert load_scenario(d) == sc
    assert load_scenario(json.loads(json.dumps(d))) == sc
    assert load_scenario(d).to_dict() == d


def test_to_dict_writes_inf_as_string():
    d = load_scenario({}).to_dict()
    assert d["metrics"]["window"] == [0.0, "inf"]
    assert load_scenario({"metrics": {"window": [1.0]}}).metrics.window == (1.0, math.inf)
    assert load_scenario({"metrics": {"window": [1.0, None]}}).metrics.window == (1.0, math.inf)


def test_to_dict_resolves_vehicle():
    d = load_scenario({"vehicle": {"l": 2.0}}).to_dict()["vehicle"]
    assert d == {"preset": "paper", "m": [215.0, 265.0, 265.0, 80.0, 80.0],
                 "d": [70.0, 100.0, 100.0, 50.0, 50.0], "wgml": 30.0, "l": 2.0}


def test_vehicle_resolve_sources():
    r = load_scenario({"vehicle": {"l": 2.0}}).vehicle.resolve()
    assert r["l"] == 2.0 and r["sources"]["l"]["origin"] == "scenario"
    assert r["sources"]["m"]["origin"] == "preset" and "ERRATA 5" in r["sources"]["m"]["source"]
    assert r["sources"]["m"]["unit"].startswith("kg")


# --- bad input: one line, naming the field ------------------------------------------------------

BAD = [
    ({"sim": {"dt": -0.001}}, "sim.dt", "must be > 0 (got -0.001)"),
    ({"sim": {"dt": 0.0}}, "sim.dt", "must be > 0"),
    ({"vehicle": {"l": 0}}, "vehicle.l", "must be > 0 (got 0)"),
    ({"vehicle": {"m": [215, 265, -1, 80, 80]}}, "vehicle.m.2", "must be >= 0.001"),
    ({"vehicle": {"m": [215, 265, 1e-300, 80, 80]}}, "vehicle.m.2", "must be >= 0.001"),
    ({"vehicle": {"d": [70, 1e300, 100, 50, 50]}}, "vehicle.d.1", "must be <= 1e+07"),
    ({"vehicle": {"m": [215, 265, 265, 80]}}, "vehicle.m", "must have 5 items"),
    ({"sim": {"bogus": 1}}, "sim.bogus", "unknown key (allowed: duration, dt, log_dt"),
    ({"bogus": 1}, "bogus", "unknown key (allowed: name"),
    ({"controller": {"bogus": 1}}, "controller.bogus", "unknown key (allowed: kind, kappa1"),
    ({"sim": {"dt": "fast"}}, "sim.dt", "must be a number (got 'fast')"),
    ({"controller": {"kappa1": "0.005"}}, "controller.kappa1", "must be a number"),
    ({"seed": 1.5}, "seed", "must be an integer"),
    ({"output": {"mat": "yes"}}, "output.mat", "must be true or false"),
    ({"sim": {"log_dt": 0.0015}}, "sim.log_dt", "integer multiple of dt"),
    ({"sim": {"log_dt": 0.0005}}, "sim.log_dt", "must be >= dt"),
    ({"sim": {"duration": 0.0005}}, "sim.dt", "must be <= duration"),
    ({"sim": {"control_rate": 300}}, "sim.control_rate", "integer multiple of dt"),
    ({"vehicle": {"preset": "nautilus"}}, "vehicle.preset", "unknown preset (allowed: paper"),
    ({"controller": {"kind": "lqr"}}, "controller.kind", "unknown kind (allowed: 'fxtntsmc', 'ftsmc'"),
    ({"reference": {"kind": "spiral"}}, "reference.kind", "spiral"),
    ({"reference": {"radius": -4}}, "reference.radius", "(got -4"),
    ({"disturbance": [{"kind": "paper", "amplitude": -1}]}, "disturbance.0.amplitude", "got -1"),
    ({"disturbance": [{"amplitude": 1}]}, "disturbance.0.kind", "required"),
    ({"disturbance": {"kind": "paper"}}, "disturbance", "array of tables"),
    ({"initial": {"eta": [0, 0, 0, 1.6, 0]}}, "initial.eta.3", "must be in (-1.5708, 1.5708) rad"),
    ({"initial": {"eta": [0, 0, 0, 1.5, 0]}}, "initial.eta.3", "must be < sim.theta_limit = 85 deg"),
    ({"initial": {"nu": [1e300, 0, 0, 0, 0]}}, "initial.nu.0", "must be in [-100, 100] m/s (got 1e+300)"),
    ({"initial": {"nu": [0, 0, 0, 0, -11]}}, "initial.nu.4", "must be in [-10, 10] rad/s"),
    ({"sim": {"duration": 2, "log_dt": 5}}, "sim.log_dt", "must be <= duration = 2 s"),
    ({"sim": {"duration": 1, "log_dt": 0.3}}, "sim.log_dt", "must divide duration = 1 s"),
    ({"sim": {"duration": 10, "control_rate": 0.01}}, "sim.control_rate", "must be >= 1/duration = 0.1 Hz"),
    ({"seed": 2**63}, "seed", "must be <= 9223372036854775807"),
    ({"limits": {"max_steps": 1e9}}, "limits.max_steps", "must be an integer"),
    ({"limits": {"max_steps": 0}}, "limits.max_steps", "must be >= 1"),
    ({"envelope": {"rho_inf": [0.005, 0.6, 0.005]}}, "envelope.rho_inf.1", "must be < rho0.1"),
    ({"envelope": {"xi0": 1.0}}, "envelope.xi0", "must be < 1"),
    ({"estimator": {"neurons": 0}}, "estimator.neurons", "must be >= 1"),
    ({"estimator": {"centre_range": [1, -1]}}, "estimator.centre_range", "lo < hi"),
    ({"metrics": {"window": [5, 1]}}, "metrics.window.1", "must be > t0"),
    ({"uncertainty": {"C": 3.0}}, "uncertainty.C", "must be <= 2"),
    ({"sim": {"theta_limit": 90}}, "sim.theta_limit", "must be < 90"),
    ({"sim": {"dt": math.nan}}, "sim.dt", "got nan"),
    ({"sim": 3}, "sim", "must be a table"),
    ({"name": ""}, "name", "must be 1 to 100 characters"),
    ({"name": "../x"}, "name", "must be 1 to 100 characters"),
    ({"name": "a\x00b"}, "name", "must be 1 to 100 characters"),
    ({"name": "x" * 101}, "name", "must be 1 to 100 characters"),
    ({"name": "-rf"}, "name", "starting with a letter, digit or _"),
]


@pytest.mark.parametrize("data, path, text", BAD, ids=[b[1] + ":" + b[2][:20] for b in BAD])
def test_bad_input_one_line(data, path, text):
    with pytest.raises(ScenarioError) as err:
        load_scenario(data)
    msg = str(err.value)
    assert "\n" not in msg
    assert msg.startswith(f"<dict>: {path}: "), msg
    assert text in msg, msg
    assert err.value.path == path


def test_bad_file_names_the_file_and_field(tmp_path):
    f = tmp_path / "paper.toml"
    f.write_text("[sim]\ndt = -0.001\n")
    with pytest.raises(ScenarioError) as err:
        load_scenario(f)
    assert str(err.value) == f"{f}: sim.dt: must be > 0 (got -0.001)"


def test_missing_file():
    with pytest.raises(ScenarioError, match=r"^nope/missing\.toml: file not found$"):
        load_scenario("nope/missing.toml")


def test_toml_syntax_error(tmp_path):
    f = tmp_path / "broken.toml"
    f.write_text("[sim]\ndt = = 0.1\n")
    with pytest.raises(ScenarioError) as err:
        load_scenario(f)
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith(f"{f}: TOML syntax error") and "line 2" in msg


def test_directory_and_bad_source(tmp_path):
    with pytest.raises(ScenarioError, match="is a directory"):
        load_scenario(tmp_path)
    with pytest.raises(ScenarioError, match="scenario source must be"):
        load_scenario(42)  # type: ignore[arg-type]


def test_several_problems_are_counted():
    with pytest.raises(ScenarioError) as err:
        load_scenario({"sim": {"dt": -1, "duration": -1, "bogus": 0}})
    msg = str(err.value)
    assert "\n" not in msg and msg.endswith("(and 2 more problems)")


def test_scenario_error_is_value_error():
    assert issubclass(ScenarioError, ValueError)


# --- schema details ----------------------------------------------------------------------------

def test_scalar_rho_is_broadcast():
    assert load_scenario({"envelope": {"rho0": 2, "rho_inf": 0.01}}).envelope.rho0 == (2.0, 2.0, 2.0)


def test_sim_step_counts():
    sim = load_scenario({"sim": {"duration": 10, "dt": 0.002, "log_dt": 0.01, "control_rate": 50}}).sim
    assert (sim.n_steps, sim.log_every, sim.control_every) == (5000, 5, 10)
    assert load_scenario({}).sim.control_every == 0


def test_controller_union_covers_registry():
    from auvtrack.control import CONTROLLERS
    from auvtrack.plant import get as get_plant

    kinds = {m.model_fields["kind"].default for m in CONTROLLER_MODELS}
    assert kinds == set(CONTROLLERS)
    example = Path(__file__).resolve().parents[2] / "examples" / "plugin_controller.py"
    for kind in kinds:  # a plug-in needs its module; a law commanding the actuators needs a plant that has them
        extra = [f"controller.module=\"{example}\""] if kind == "plugin" else []
        extra += [] if CONTROLLERS[kind].runs_on(get_plant("5dof")) else ["plant.model=6dof"]
        assert load_scenario({}, [f"controller.kind={kind}", *extra]).controller.kind == kind
    with pytest.raises(ScenarioError, match="controller.module: required key is missing"):
        load_scenario({}, ["controller.kind=plugin"])


def test_frozen():
    sc = load_scenario({})
    with pytest.raises(Exception):
        sc.seed = 3  # type: ignore[misc]
    with pytest.raises(Exception):
        sc.sim.dt = 0.1  # type: ignore[misc]


def test_cli_prints_one_line(capsys):
    from auvtrack.cli import main

    assert main(["check", str(PAPER), "--set", "sim.dt=-1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "sim.dt: must be > 0" in err


def test_packaged_copy_matches():
    """auvtrack/data/scenarios/paper.toml (used by the benchmarks) must stay the same scenario."""
    packaged = PAPER.parents[1] / "auvtrack" / "data" / "scenarios" / "paper.toml"
    if not packaged.exists():
        pytest.skip("no packaged copy")
    assert load_scenario(packaged) == load_scenario(PAPER)


def test_read_toml_sees_an_edit_and_hands_out_independent_copies(tmp_path):
    """Parsed files are cached by content: an edit of the same size is read again, and a caller
    mutating its dict does not change what the next caller gets."""
    from auvtrack.scenario import read_toml

    f = tmp_path / "s.toml"
    f.write_text('name = "a"\nseed = 1\n')
    first = read_toml(f)
    first["seed"] = 99
    assert read_toml(f) == {"name": "a", "seed": 1}
    f.write_text('name = "b"\nseed = 2\n')  # same size, possibly the same mtime
    assert read_toml(f) == {"name": "b", "seed": 2}


def test_vehicle_presets_are_independent_copies():
    from auvtrack.vehicle.presets import get_preset

    a = get_preset("paper")
    a.sources["m"]["source"] = "changed"
    assert get_preset("paper").sources["m"]["source"] != "changed"
