"""The 6-DOF truth plants through the engine: PVS reference, roll stop, channels, CLI, controllers."""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import auvtrack
from auvtrack.scenario import load_scenario
from auvtrack.simulation.pipeline import prepare, run_prepared

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parents[1] / "data"
REMUS = ROOT / "scenarios" / "remus100.toml"


def _pvs_scenario(duration=30.0):
    ref = json.loads((DATA / "remus100_fossen_openloop.json").read_text())
    c = ref["commands"]
    sc = {"sim": {"duration": duration, "dt": 0.005, "log_dt": 0.005},
          "vehicle": {"preset": "remus100", "u0": 1.5},
          "plant": {"model": "6dof", "preset": "remus100_fossen"},
          "initial": {"eta": [0.0, 0.0, 0.0, 0.0, 0.0], "nu": [0.0, 0.0, 0.0, 0.0, 0.0]},
          "controller": {"kind": "open_loop_actuators", "rpm": c["rpm"], "delta_r": c["delta_r"],
                         "delta_s": c["delta_s"]},
          "reference": {"kind": "line", "velocity": [1.0, 0.0, 0.0]}, "disturbance": []}
    return ref, sc


def test_engine_reproduces_the_pvs_reference():
    """The shared PVS case through scenario, allocation pass-through and the compiled RK4 engine."""
    ref, sc = _pvs_scenario()
    res = auvtrack.simulate(sc, warn=False)
    assert res.status == "ok"
    ch = res.channels
    for t, s in ref["states"].items():
        i = int(round(float(t) / 0.005))
        assert ch["t"][i] == pytest.approx(float(t))
        pos = np.array([ch["x"][i], ch["y"][i], ch["z"][i]])
        assert np.abs(pos - s["eta"][0:3]).max() < 0.02, t
        att = np.array([ch["phi"][i], ch["theta"][i], ch["psi"][i]])
        assert np.abs(att - s["eta"][3:6]).max() < 2e-3, t
        nu = np.array([ch["u"][i], ch["v"][i], ch["w"][i], ch["p"][i], ch["q"][i], ch["r"][i]])
        assert np.abs(nu - s["nu"]).max() < 2e-3, t
        assert abs(ch["delta_r"][i] - s["u_actual"][0]) < 2e-3 and abs(ch["delta_s"][i] - s["u_actual"][1]) < 2e-3
        assert abs(ch["rpm"][i] - s["u_actual"][2]) < 2e-3 * ref["commands"]["rpm"]


def test_channels_and_record_of_a_6dof_run():
    res = auvtrack.simulate(REMUS, ["plant.model=6dof", "sim.duration=2", "initial.nu=[1, 0, 0, 0, 0]"], warn=False)
    for name in ("x", "theta", "psi", "u", "q", "r", "tau_u", "tau_q", "tau_r", "phi", "p", "delta_r",
                 "delta_s", "rpm", "tau_u_cmd", "tau_q_cmd", "tau_r_cmd"):
        assert name in res.channels and np.all(np.isfinite(res.channels[name])), name
    rec = res.prepared.resolved if hasattr(res, "prepared") else None
    assert res.channels["rpm"][0] == pytest.approx(1500 * math.sqrt(1.62 / 3.86), rel=1e-9)  # trimmed start
    # the produced tau is the actuators' at the applied states: |tau_q| within the fins' reach
    ch = res.channels
    assert np.all(np.abs(ch["tau_q"]) <= 6.15 * ch["u"] ** 2 * math.radians(15) + 1e-9)
    assert np.all(np.abs(ch["tau_q"] - (-6.15) * ch["u"] ** 2 * ch["delta_s"]) < 1e-9)
    for j in "uqr":
        assert f"t_sat_tau_{j}" in res.metrics
    del rec


def test_roll_limit_stops_the_run_with_its_cause():
    """Started upright inside the 5 deg stop, a 1 rad/s roll rate carries |phi| past it within ~0.1 s."""
    res = auvtrack.simulate(REMUS, ["plant.model=6dof", "sim.duration=5", "initial.p=1.0", "sim.phi_limit=5"],
                            warn=False)
    assert res.status == "failed" and res.failure["cause"] == "roll_limit" and 0.0 < res.failure["time"] < 0.2


def test_every_controller_flies_the_truth_with_noise_sampling_and_current():
    """Sensor noise and sampled-data control act on the measured projection; the current through
    relative velocity; every tracking controller runs (or stops with a named cause)."""
    from auvtrack.studies.model_gap import controllers
    for kind in controllers():
        for preset in ("remus100_prestero", "remus100_fossen"):
            res = auvtrack.simulate(REMUS, [
                "plant.model=6dof", f"plant.preset={preset}", f"controller.kind={kind}", "sim.duration=2",
                "initial.nu=[1, 0, 0, 0, 0]", "sim.control_rate=100", "sensor.sigma_eta=[0.01, 0.01, 0.01, 0.003, 0.003]",
                "sensor.sigma_nu=[0.01, 0.01, 0.01, 0.003, 0.003]",
                "disturbance=[{kind = 'current', mean = [0.2, 0.1, 0.0], sigma = [0.0, 0.0, 0.0]}]"], warn=False)
            assert res.status == "ok" or res.failure["cause"], (kind, preset)
            assert res.channels["t"].size > 0


def test_current_acts_through_relative_velocity():
    """A steady current carries the vehicle: with the propeller off and fins at zero, Fossen's
    model drifts with the (heading-rotated) current and its relative surge velocity decays."""
    sc = {"sim": {"duration": 60.0, "dt": 0.01, "log_dt": 0.1}, "vehicle": {"preset": "remus100", "u0": 1.5},
          "plant": {"model": "6dof", "preset": "remus100_fossen"},
          "controller": {"kind": "open_loop_actuators"}, "reference": {"kind": "line", "velocity": [1.0, 0.0, 0.0]},
          "initial": {"eta": [0.0, 0.0, 0.0, 0.0, 0.0], "nu": [0.0, 0.0, 0.0, 0.0, 0.0]},
          "disturbance": [{"kind": "current", "mean": [0.3, 0.0, 0.0], "sigma": [0.0, 0.0, 0.0]}]}
    ch = auvtrack.simulate(sc, warn=False).channels
    assert ch["u"][-1] == pytest.approx(0.3, abs=0.02)


def test_open_loop_actuator_bad_input():
    """Commands beyond the plant's actuators are refused at set-up (check and run alike), a plant
    that takes no actuator commands when the scenario is loaded."""
    from auvtrack.scenario import ScenarioError
    from auvtrack.simulation.pipeline import prepare
    with pytest.raises(ValueError, match=r"controller.delta_r: beyond the actuator limit plant.delta_max = 0.237365"):
        prepare(load_scenario(REMUS, ["plant.model=6dof", "controller.kind=open_loop_actuators", "controller.delta_r=0.5"]))
    with pytest.raises(ValueError, match=r"controller.rpm: beyond the actuator limit plant.n_max = 1525"):
        prepare(load_scenario(REMUS, ["plant.model=6dof", "controller.kind=open_loop_actuators", "controller.rpm=2000"]))
    with pytest.raises(ScenarioError, match=r"controller.kind: open_loop_actuators commands the actuators; plant.model "
                                            r"'5dof' accepts tau"):
        load_scenario(REMUS, ["controller.kind=open_loop_actuators"])


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "auvtrack.cli", *args], capture_output=True, text=True,
                          cwd=ROOT, env={**__import__("os").environ, "PYTHONPATH": str(ROOT)})


def test_cli_set_plant_model_6dof_as_typed_and_bad_input_exit_2():
    ok = _cli("check", str(REMUS), "--set", "plant.model=6dof")
    assert ok.returncode == 0, ok.stderr
    bad = _cli("check", str(REMUS), "--set", "plant.model=6dof", "--set", "plant.n_max=-5")
    assert bad.returncode == 2 and "plant.n_max" in bad.stderr and "Traceback" not in bad.stderr
    assert len(bad.stderr.strip().splitlines()) == 1


def test_zigzag_relay_reverses_the_rudder():
    from auvtrack.studies.manoeuvres import scenario_path, zigzag_metrics
    res = auvtrack.simulate(scenario_path("zigzag"), ["sim.duration=60"], warn=False)
    ch = res.channels
    m = zigzag_metrics(ch["t"], ch["psi"], ch["delta_r"], math.radians(20), 5.0)
    assert m["reversals"] >= 4
    # between reversals the rudder holds +-15 deg (the fin servo, T = 0.1 s, takes ~0.6 s to come
    # within 1e-3 rad after each 30 deg reversal, i.e. < 15 % of the ~4.7 s half-periods)
    held = np.abs(np.abs(ch["delta_r"][ch["t"] > 5.5]) - math.radians(15)) < 1e-3
    assert held.mean() > 0.85
    assert np.all(np.abs(ch["delta_r"]) <= math.radians(15) + 1e-12)
