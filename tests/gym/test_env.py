"""The Gymnasium environment: the checker, seeding, and equality with an engine run of the same actions."""
from __future__ import annotations

import sys
import tomllib
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import auvtrack.gym  # noqa: F401  (registers the environments)
from auvtrack.benchmark.suite import Suite, SuiteFile
from auvtrack.gym.env import TrackEnv, episode_scenario
from auvtrack.simulation.pipeline import simulate

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tiny_suite import TINY  # noqa: E402

SUITE = Suite(SuiteFile.model_validate(tomllib.loads(TINY)), "tiny")


@pytest.mark.parametrize("task", SUITE.tasks)
@pytest.mark.parametrize("tier", SUITE.tiers)
def test_check_env_every_cell(task, tier):
    env = gym.make("auvtrack/Track-v0", suite=SUITE, task=task, tier=tier, duration=0.4).unwrapped
    check_env(env, skip_render_check=True)


def test_reset_seed_is_deterministic_and_seeds_differ():
    env = TrackEnv(SUITE, "line", "model", duration=0.4)
    rng = np.random.default_rng(0)
    acts = rng.uniform(-1, 1, (20, 3))

    def episode(seed):
        obs = [env.reset(seed=seed)[0]]
        rews = []
        for a in acts:
            o, r, te, tr, _ = env.step(a)
            obs.append(o)
            rews.append(r)
            if te or tr:
                break
        return np.array(obs), np.array(rews)

    o1, r1 = episode(4)
    o2, r2 = episode(4)
    o3, _ = episode(5)
    assert np.array_equal(o1, o2) and np.array_equal(r1, r2)
    assert not np.array_equal(o1[0], o3[0])  # another seed index: another start
    assert np.all(r1 <= 0.0) and np.any(r1 < 0.0)


@pytest.mark.parametrize("tier", ["calm", "model"])
def test_episode_equals_engine_run_of_same_actions(tier):
    """reset(seed=s) + fixed actions == the engine's run of the suite's seed s flown by the replay law."""
    env = TrackEnv(SUITE, "helix", tier, duration=0.6, substeps=10)
    obs, _ = env.reset(seed=2)
    rng = np.random.default_rng(1)
    actions = [tuple(rng.uniform(-1, 1, 3)) for _ in range(40)]
    done = False
    for a in actions:
        _, _, te, tr, info = env.step(np.array(a))
        if te or tr:
            done = True
            break
    assert done and info["status"] == "ok"
    sc = episode_scenario(SUITE, "helix", tier, 2, substeps=10, duration=0.6, scale=tuple(env.scale), actions=actions)
    res = simulate(sc)
    assert res.status == "ok"
    for name, value in info["metrics"].items():  # the same accumulator, the same numbers
        ref = res.metrics[name]
        assert value == ref or (np.isnan(value) and np.isnan(ref)), name
    # the final pose: the engine logs the state at t = duration
    from auvtrack.user_modules import load_module
    eta, nu = load_module(env.prep.key.plant).pose(env.carry.xp[0])
    for j, k in enumerate(("x", "y", "z", "theta", "psi")):
        assert res.channels[k][-1] == pytest.approx(eta[j], abs=1e-12, rel=0), k
    assert res.channels["t"][-1] == pytest.approx(0.6)


@pytest.mark.slow
@pytest.mark.parametrize("action", ["tau", "actuators"])
def test_check_env_six_dof_truth(action):
    """The shipped suite's 6-DOF tier, both action modes (short episodes)."""
    env = TrackEnv("auv-track-v1", "helix", "truth6", action=action, duration=0.2)
    check_env(env, skip_render_check=True)
    obs, _ = env.reset(seed=0)
    for _ in range(10):
        obs, r, te, tr, info = env.step(np.array([0.5, 0.0, 0.1]))
        if te or tr:
            break
    assert tr and info["status"] == "ok" and np.isfinite(r)


SCORED = Suite(SuiteFile.model_validate(tomllib.loads(
    TINY + "\n[run_score]\ncap = 3.0\n[run_score.weights]\nrmse = 1.0\nenergy = 0.5\ntv = 0.25\n"
    "[run_score.scales]\nrmse = 0.04\nenergy = 20.0\ntv = 50.0\n")), "tiny-scored")


def test_return_is_the_capped_benchmark_cost():
    """Sum of rewards == -(w_rmse min((rmse/s)^2, cap^2) + w_E min(E/s, cap) + w_TV min(TV/s, cap)), from the metrics."""
    rng = np.random.default_rng(5)
    capped = []
    for seed, amp in ((0, 0.1), (1, 1.0)):
        env = TrackEnv(SCORED, "helix", "calm", duration=1.0)
        env.reset(seed=seed)
        ret, done = 0.0, False
        while not done:
            _, r, te, tr, info = env.step(amp * rng.uniform(-1, 1, 3))
            ret += r
            done = te or tr
        assert info["status"] == "ok"
        m = info["metrics"]
        dur = info["t"] - env.prep.scenario.metrics.window[0]
        ms2 = sum(m[f"rmse_{a}"] ** 2 for a in "xyz") * dur / 1.0  # integral of |e|^2 over T = 1 s
        energy = sum(v for k, v in m.items() if k.startswith("energy_tau_"))
        tv = sum(v for k, v in m.items() if k.startswith("tv_tau_")) * dur / 1.0  # per second over T = 1 s
        cost = min(ms2 / 0.04 ** 2, 9.0) + 0.5 * min(energy / 20.0, 3.0) + 0.25 * min(tv / 50.0, 3.0)
        assert ret == pytest.approx(-cost, rel=1e-9)
        capped.append((ms2 / 0.04 ** 2 > 9.0, energy / 20.0 > 3.0, tv / 50.0 > 3.0))
        assert cost > 0
    assert capped == [(True, False, False), (False, False, True)]  # the caps are met


def test_a_failed_episode_returns_less_than_any_completed_one():
    env = TrackEnv(SCORED, "line", "calm", duration=30.0)
    env.reset(seed=0)
    ret, done = 0.0, False
    while not done:  # full surge and pitch torque: the pitch limit
        _, r, te, tr, info = env.step(np.array([1.0, 1.0, 0.0]))
        ret += r
        done = te or tr
    assert te and info["status"] == "pitch_limit"
    worst_completed = -(9.0 + 0.5 * 3.0 + 0.25 * 3.0)  # every capped term at its cap
    assert ret < worst_completed - 1.0 + 1e-9


PATHED = Suite(SuiteFile.model_validate(tomllib.loads(
    TINY + "\n[run_score]\ncap = 3.0\n[run_score.weights]\nrmse = 0.25\nenergy = 0.1\nxtrack_rmse = 1.0\n"
    "vtrack_rmse = 0.5\nalong_rmse = 0.25\n[run_score.scales]\nrmse = 1.0\nenergy = 500.0\nxtrack_rmse = 0.1\n"
    "vtrack_rmse = 0.2\nalong_rmse = 2.0\n")), "tiny-pathed")


def test_return_charges_the_path_metrics_of_the_run_score():
    """With path weights: the return == -(capped squared-RMS terms of rmse, xtrack, vtrack, along + energy), from the metrics."""
    env = TrackEnv(PATHED, "helix", "model", duration=1.0)
    env.reset(seed=1)
    rng = np.random.default_rng(3)
    ret, done = 0.0, False
    while not done:
        _, r, te, tr, info = env.step(0.3 * rng.uniform(-1, 1, 3))
        ret += r
        done = te or tr
    assert info["status"] == "ok"
    m, dur = info["metrics"], info["t"] - env.prep.scenario.metrics.window[0]
    terms = {"xtrack_rmse": (1.0, 0.1), "vtrack_rmse": (0.5, 0.2), "along_rmse": (0.25, 2.0)}
    path = {k: w * min((m[k] / s) ** 2 * dur / 1.0, 9.0) for k, (w, s) in terms.items()}
    assert all(v > 0 for v in path.values())  # the episode is charged for each path error
    ms2 = sum(m[f"rmse_{a}"] ** 2 for a in "xyz") * dur
    energy = sum(v for k, v in m.items() if k.startswith("energy_tau_"))
    cost = 0.25 * min(ms2, 9.0) + 0.1 * min(energy / 500.0, 3.0) + sum(path.values())
    assert ret == pytest.approx(-cost, rel=1e-9)


def _v2_cells():
    from auvtrack.gym.env import suite_of

    suite = suite_of("auv-track-v2")
    six = {t for t in suite.tiers if suite.file.tiers[t].requires_plant == "6dof"}
    return [(task, tier, action) for task in suite.tasks for tier in suite.tiers
            for action in (("tau", "actuators") if tier in six else ("tau",))]


@pytest.mark.slow
@pytest.mark.parametrize("task, tier, action", _v2_cells())
def test_check_env_every_cell_and_action_mode_of_auv_track_v2(task, tier, action):
    """The checker on every task x tier of the shipped v2 suite, both action modes on the 6-DOF tiers (0.2 s episodes)."""
    env = TrackEnv("auv-track-v2", task, tier, action=action, duration=0.2)
    check_env(env, skip_render_check=True)


def _benchmark_terms(suite: Suite, metrics: dict) -> dict[str, float]:
    """The run score's capped terms of a completed run's metrics: the benchmark's derivation and scoring."""
    import pandas as pd

    from auvtrack.benchmark.leaderboard import derive_metrics
    from auvtrack.benchmark.scoring import run_score_terms

    rs = suite.file.run_score
    row = derive_metrics(pd.DataFrame([{**metrics, "status": "ok"}]), criteria=tuple(rs.weights)).iloc[0]
    return run_score_terms(row.to_dict(), rs.weights, rs.scales, cap=rs.cap)


@pytest.mark.parametrize("tier, action, duration", [("design", "tau", 2.0), ("truth_fossen", "actuators", 4.0)])
def test_return_charges_every_term_of_the_v2_run_score(tier, action, duration):
    """The return == -sum_c w_c t_c^p (p = 2 for the RMS criteria, else 1), t_c the benchmark's run-score term."""
    from auvtrack.gym.env import SQUARED

    from auvtrack.gym.env import suite_of

    suite = suite_of("auv-track-v2")
    env = TrackEnv(suite, "helix", tier, action=action, duration=duration)
    env.reset(seed=0)
    rng = np.random.default_rng(7)
    ret, done, k = 0.0, False, 0
    while not done:  # the fins moved, then held at a limit (reached after the lag: 2 s on the 6-DOF plant)
        a = np.array([0.8, 0.2 * rng.uniform(-1, 1) if k < 20 else 1.0, 0.2 * rng.uniform(-1, 1) if k < 20 else -1.0])
        _, r, te, tr, info = env.step(a)
        ret += r
        done, k = te or tr, k + 1
    assert info["status"] == "ok"
    rs = suite.file.run_score
    weighted = {c for c, w in rs.weights.items() if w > 0}
    assert {"act_rate_q", "act_rate_r", "t_act_limit_q", "t_act_limit_r"} <= weighted
    terms = _benchmark_terms(suite, info["metrics"])
    assert set(terms) == weighted
    cost = sum(rs.weights[c] * (t ** 2 if c in SQUARED else t) for c, t in terms.items())
    assert ret == pytest.approx(-cost, rel=1e-9)
    fins = [terms[c] for c in ("act_rate_q", "act_rate_r", "t_act_limit_q", "t_act_limit_r")]
    if tier == "design":  # the 5-DOF plant without limits: no actuator position, the benchmark's terms are 0
        assert fins == [0.0, 0.0, 0.0, 0.0]
    else:
        assert all(f > 0 for f in fins), fins


PEAKS = Suite(SuiteFile.model_validate(tomllib.loads(
    TINY + "\n[run_score]\ncap = 3.0\n[run_score.weights]\nrmse = 0.5\ntv = 0.25\nmax_error = 1.0\nxtrack_max = 0.5\n"
    "[run_score.scales]\nrmse = 0.2\ntv = 100.0\nmax_error = 0.5\nxtrack_max = 0.4\n")), "tiny-peaks")


def test_return_charges_the_peak_terms_and_tv_per_second():
    """max_error and xtrack_max as the run score's terms; tv per second over T = 2 s (the benchmark's tv)."""
    from auvtrack.gym.env import SQUARED

    env = TrackEnv(PEAKS, "helix", "model", duration=2.0)
    env.reset(seed=0)
    rng = np.random.default_rng(11)
    ret, done = 0.0, False
    while not done:
        _, r, te, tr, info = env.step(0.5 * rng.uniform(-1, 1, 3))
        ret += r
        done = te or tr
    assert info["status"] == "ok"
    terms = _benchmark_terms(PEAKS, info["metrics"])
    assert set(terms) == {"rmse", "tv", "max_error", "xtrack_max"} and all(0 < t < 3.0 for t in terms.values())
    w = PEAKS.file.run_score.weights
    assert ret == pytest.approx(-sum(w[c] * (t ** 2 if c in SQUARED else t) for c, t in terms.items()), rel=1e-9)


def test_a_run_score_weighing_a_criterion_the_reward_cannot_charge_is_refused():
    itae = Suite(SuiteFile.model_validate(tomllib.loads(
        TINY + "\n[run_score]\n[run_score.weights]\nrmse = 1.0\nitae = 0.5\n[run_score.scales]\nrmse = 1.0\nitae = 10.0\n")),
        "tiny-itae")
    with pytest.raises(ValueError, match="itae"):
        TrackEnv(itae, "helix", "calm", duration=0.4)
