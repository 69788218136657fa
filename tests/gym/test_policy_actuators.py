"""Actuator-command actions and policies on a 6-DOF truth: the checker, the env == the engine, the kinds refused."""
from __future__ import annotations

import contextlib
import io
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from auvtrack.benchmark.suite import Suite, SuiteFile
from auvtrack.control.policy import forward, load_policy, save_policy
from auvtrack.control.policy_observation import OBS
from auvtrack.gym.env import TrackEnv, episode_scenario
from auvtrack.scenario import load_scenario
from auvtrack.scenario.toml_writer import dumps
from auvtrack.simulation.pipeline import simulate

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tiny_suite import TINY  # noqa: E402

SIX = Suite(SuiteFile.model_validate(tomllib.loads(
    TINY + '[tiers.six]\nstart = { lateral = 0.3 }\n[tiers.six.set]\n"plant.model" = "6dof"\n'
    '"plant.preset" = "remus100_prestero"\n')), "tiny-six")


def _actuator_policy(tmp_path, scale, seed=3):
    rng = np.random.default_rng(seed)
    ws = [rng.normal(0, 0.3 / np.sqrt(OBS.size), (8, OBS.size)), rng.normal(0, 0.3, (3, 8))]
    bs = [rng.normal(0, 0.1, 8), np.array([0.6, 0.0, 0.0])]  # the propeller turning ahead
    return save_policy(tmp_path / "act.npz", ws, bs, ["tanh", "identity"], scale, rng.normal(0, 1, OBS.size),
                       rng.uniform(0.5, 3.0, OBS.size), commands="actuators")


def test_check_env_actuator_actions_on_a_6dof_tier():
    env = TrackEnv(SIX, "helix", "six", action="actuators", duration=0.2)
    check_env(env, skip_render_check=True)
    _, _ = env.reset(seed=0)
    module_hi = env.scale
    assert module_hi[0] > 100.0 and 0.0 < module_hi[1] < 1.0  # rpm, rad: the plant's actuator limits


def test_actuator_actions_refused_on_a_5dof_tier():
    with pytest.raises(ValueError):
        TrackEnv(SIX, "helix", "calm", action="actuators", duration=0.2)


def test_actuator_policy_runs_in_the_engine_as_the_env_flies_it(tmp_path):
    """controller.kind = "policy_actuators" with an actuator file == the env (action="actuators") driven
    by the NumPy forward pass of the same file, metric for metric."""
    env = TrackEnv(SIX, "helix", "six", action="actuators", duration=0.5)
    obs, _ = env.reset(seed=2)
    pol_file = _actuator_policy(tmp_path, env.scale)
    pol = load_policy(pol_file)
    assert pol["header"]["commands"] == "actuators"
    moved = []
    while True:
        a = forward(pol, obs) / env.scale
        moved.append(np.abs(a).max())
        obs, _, te, tr, info = env.step(a)
        if te or tr:
            break
    assert info["status"] == "ok" and max(moved) > 0.1
    raw = episode_scenario(SIX, "helix", "six", 2, action="actuators", duration=0.5).to_dict()
    raw["controller"] = {"kind": "policy_actuators", "file": str(pol_file)}
    res = simulate(load_scenario(raw))
    assert res.status == "ok"
    for name in ("rmse_x", "rmse_y", "rmse_z", "energy_tau_u", "energy_tau_q", "xtrack_rmse"):
        assert res.metrics[name] == pytest.approx(info["metrics"][name], rel=1e-9, abs=1e-12), name


def test_actuator_policy_file_runs_in_auvtrack_run_and_the_wrong_kind_is_one_line(tmp_path):
    from auvtrack.cli import main

    env = TrackEnv(SIX, "helix", "six", action="actuators", duration=0.2)
    env.reset(seed=0)
    pol_file = _actuator_policy(tmp_path, env.scale)
    raw = episode_scenario(SIX, "helix", "six", 0, action="actuators", duration=0.2).to_dict()
    def scenario(kind):
        r = {**raw, "controller": {"kind": kind, "file": str(pol_file)}}
        path = tmp_path / f"{kind}.toml"
        path.write_text(dumps(r))
        return str(path)

    assert main(["run", scenario("policy_actuators"), "--out", str(tmp_path / "run")]) == 0
    for argv in (["check", scenario("policy")], ["run", scenario("policy"), "--out", str(tmp_path / "bad")]):
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            code = main(argv)
        lines = err.getvalue().strip().splitlines()
        assert code == 2 and len(lines) == 1 and "controller.file" in lines[0] and "policy_actuators" in lines[0]


def test_save_policy_refuses_an_unknown_command_kind(tmp_path):
    with pytest.raises(ValueError, match="commands"):
        save_policy(tmp_path / "x.npz", [np.zeros((3, OBS.size))], [np.zeros(3)], ["identity"], (1, 1, 1),
                    commands="fins")
