"""The ``policy`` law: the NumPy forward pass to 1e-12, and the environment's observation."""
from __future__ import annotations

import numpy as np
import pytest

from auvtrack.control.contract import evaluate
from auvtrack.control.policy import control, forward, load_policy, pack, save_policy
from auvtrack.control.policy_observation import OBS, OBS_BOUND, observe
from auvtrack.user_modules import load_module
from auvtrack.vehicle.kinematics import attitude

from .test_env import SUITE
from auvtrack.gym.env import TrackEnv


def _random_policy(tmp_path, rng, sizes=(16, 8), acts=("tanh", "relu", "identity")):
    dims = [OBS.size, *sizes, 3]
    ws = [rng.normal(0, 1 / np.sqrt(dims[i]), (dims[i + 1], dims[i])) for i in range(len(dims) - 1)]
    bs = [rng.normal(0, 0.1, dims[i + 1]) for i in range(len(dims) - 1)]
    return load_policy(save_policy(tmp_path / "p.npz", ws, bs, acts, (20.0, 5.0, 5.0), rng.normal(0, 1, OBS.size),
                                   rng.uniform(0.5, 3.0, OBS.size)))


def test_registered_kind_contract_checked():
    from auvtrack.control import BUILTIN_NAMES, CONTROLLERS, check_controller
    from auvtrack.control import policy

    assert check_controller(policy).name == "policy" and CONTROLLERS["policy"].tracks
    assert "policy" not in BUILTIN_NAMES  # named to compete, never a default competitor


def test_missing_policy_file_one_line(tmp_path):
    from auvtrack.cli import main

    scen = tmp_path / "s.toml"
    scen.write_text('[controller]\nkind = "policy"\nfile = "nope.npz"\n[sim]\nduration = 0.1\n')
    import io
    import contextlib

    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["check", str(scen)])
    assert code == 2 and len(err.getvalue().strip().splitlines()) == 1 and "controller.file" in err.getvalue()


def test_law_equals_numpy_forward(tmp_path):
    rng = np.random.default_rng(7)
    pol = _random_policy(tmp_path, rng)
    env = TrackEnv(SUITE, "helix", "calm", duration=0.4)
    env.reset(seed=1)
    path, vp = env.prep.ref_p, env.prep.controller.vp
    for _ in range(20):
        eta = rng.normal(0, 1, 5) + np.array([10.0, 0.0, 20.0, 0.0, 0.0])
        nu = rng.normal(0, 0.5, 5)
        t, applied = float(rng.uniform(0, 30)), tuple(rng.normal(0, 3, 3))
        obs = np.zeros(OBS.size)
        observe(t, tuple(eta), tuple(nu), attitude(eta[3], eta[4]), path, applied, np.array((20.0, 5.0, 5.0)),
                OBS_BOUND, obs)
        status, u, _, _ = evaluate(control, t, eta, nu, np.zeros(0), np.zeros((3, 3)), pack(pol), vp, n_aux=0,
                                   path=path, applied=applied)
        assert status == 0
        np.testing.assert_allclose(u, forward(pol, obs), rtol=0, atol=1e-12)
    assert np.any(np.abs(u) > 0.1)


def test_law_observation_equals_environment_observation(tmp_path):
    """A linear policy that reads three observation entries per file: the law sees what the env gives."""
    env = TrackEnv(SUITE, "helix", "model", duration=0.6)
    env.reset(seed=3)
    rng = np.random.default_rng(2)
    for _ in range(7):
        env.step(rng.uniform(-1, 1, 3))
    obs_env = env.carry.obs[0].copy()
    module = load_module(env.prep.key.plant)
    xp = env.carry.xp[0]
    eta, nu = module.pose(xp)
    _, _, applied = module.feedback(xp, env.carry.cmd[0], env.prep.plant.pp)
    t = int(env.carry.ks[0, 0]) * env.prep.scenario.sim.dt
    std = 1e3 * np.ones(OBS.size)
    seen = np.zeros(OBS.size)
    for start in range(0, OBS.size, 3):
        idx = [min(start + j, OBS.size - 1) for j in range(3)]
        w = np.zeros((3, OBS.size))
        w[range(3), idx] = 1.0
        pol = load_policy(save_policy(tmp_path / "pick.npz", [w], [np.zeros(3)], ["identity"], env.scale,
                                      obs_std=std))
        _, u, _, _ = evaluate(control, t, eta, nu, np.zeros(0), np.zeros((3, 3)), pack(pol),
                              env.prep.controller.vp, n_aux=0, path=env.prep.ref_p, applied=applied)
        seen[idx] = u / env.scale * 1e3
    np.testing.assert_allclose(seen, obs_env, rtol=1e-12, atol=1e-12)


def test_malformed_file_refused(tmp_path):
    with pytest.raises(ValueError, match="controller.file"):
        save_policy(tmp_path / "bad.npz", [np.zeros((3, 5))], [np.zeros(3)], ["tanh"], (1, 1, 1))


def test_policy_runs_in_the_engine_as_the_env_would_fly_it(tmp_path):
    """A policy run (controller.kind = "policy") == the env driven by the NumPy forward pass."""
    from auvtrack.gym.env import episode_scenario
    from auvtrack.scenario import load_scenario
    from auvtrack.simulation.pipeline import simulate

    rng = np.random.default_rng(11)
    env = TrackEnv(SUITE, "helix", "calm", duration=0.5)
    obs, _ = env.reset(seed=4)
    pol = _random_policy(tmp_path, rng, sizes=(8,), acts=("tanh", "tanh"))
    pol_file = save_policy(tmp_path / "run.npz", pol["weights"], pol["biases"], pol["header"]["activations"],
                           env.scale, pol["obs_mean"], pol["obs_std"])
    pol = load_policy(pol_file)
    while True:
        obs, _, te, tr, info = env.step(forward(pol, obs) / env.scale)
        if te or tr:
            break
    sc = episode_scenario(SUITE, "helix", "calm", 4, duration=0.5)
    raw = sc.to_dict()
    raw["controller"] = {"kind": "policy", "file": str(pol_file)}
    res = simulate(load_scenario(raw))
    assert res.status == "ok" and info["status"] == "ok"
    for name in ("rmse_x", "rmse_y", "rmse_z", "energy_tau_u", "energy_tau_r"):
        assert res.metrics[name] == pytest.approx(info["metrics"][name], rel=1e-9, abs=1e-12), name
    assert res.metrics["energy_tau_u"] > 0


def test_shipped_policy_loads_with_its_provenance():
    from auvtrack.control.policy import DEFAULT_POLICY, available_policies

    assert DEFAULT_POLICY in available_policies()
    prov = load_policy(DEFAULT_POLICY)["header"]["provenance"]
    assert prov["suite"] == "auv-track-v2" and prov["tier"] == "design"
    assert prov["command"].startswith("auvtrack train ") and prov["budget"]["env_steps"] > 0
    assert prov["training_seeds"] == [1000, 1016] and prov["validation_seeds"] == [2000, 2008]


def test_policy_enters_a_comparison_when_named_only():
    from auvtrack.benchmark.suite import resolve_controllers, tracking_kinds

    assert "policy" not in tracking_kinds()  # the default competitors are unchanged
    (entry,) = resolve_controllers(["policy"])
    assert entry.table == {"kind": "policy"}
