"""The vector environment: each row equals the single environment, and NEXT_STEP autoreset."""
from __future__ import annotations

import numpy as np

from auvtrack.gym.env import TrackEnv
from auvtrack.gym.vector import TrackVectorEnv

from .test_env import SUITE


def test_rows_equal_single_env_and_autoreset():
    n, dur = 3, 0.4  # 20 control steps of 10 x 2 ms
    vec = TrackVectorEnv(n, SUITE, "line", "model", duration=dur)
    obs, info = vec.reset(seed=10)
    assert list(info["seed_index"]) == [10, 11, 12]
    rng = np.random.default_rng(3)
    acts = rng.uniform(-1, 1, (20, n, 3))
    singles = [TrackEnv(SUITE, "line", "model", duration=dur) for _ in range(n)]
    first = [s.reset(seed=10 + i)[0] for i, s in enumerate(singles)]
    np.testing.assert_array_equal(obs, np.array(first))
    for k in range(20):
        obs, rew, term, trunc, _ = vec.step(acts[k])
        for i, s in enumerate(singles):
            o, r, te, tr, _ = s.step(acts[k, i])
            np.testing.assert_array_equal(obs[i], o)
            assert rew[i] == r and term[i] == te and trunc[i] == tr
    assert trunc.all()
    obs, rew, term, trunc, info = vec.step(acts[0])  # the autoreset step: new episodes, reward 0
    assert np.all(rew == 0.0) and not term.any() and not trunc.any()
    assert np.all(vec.carry.ks[:, 0] == 0)


def test_episode_metrics_in_info_and_disabled_autoreset():
    dur = 0.4
    vec = TrackVectorEnv(2, SUITE, "helix", "calm", duration=dur, autoreset="disabled")
    single = TrackEnv(SUITE, "helix", "calm", duration=dur)
    vec.reset(seed=[7, 8])
    single.reset(seed=8)
    rng = np.random.default_rng(4)
    for _ in range(20):
        a = rng.uniform(-1, 1, (2, 3))
        _, _, te, tr, info = vec.step(a)
        _, _, ste, strn, sinfo = single.step(a[1])
    assert tr.all() and list(info["_metrics"]) == [True, True] and (ste or strn)
    assert info["status"][1] == sinfo["status"] == "ok" and info["t"][1] == sinfo["t"]
    assert info["metrics"][1] == sinfo["metrics"]
    ks = vec.carry.ks[:, 0].copy()
    obs, rew, te, tr, info = vec.step(np.zeros((2, 3)))  # ended envs stay ended
    assert np.all(rew == 0.0) and not te.any() and not tr.any() and "metrics" not in info
    assert np.array_equal(vec.carry.ks[:, 0], ks)


def test_a_reset_does_not_recompile_the_replay_law():
    """The plug-in set-up's bounds-checked probe of the replay law is compiled once per process: a reset
    of new seed indices prepares episodes without compiling (the probe's dispatcher is reused and keeps
    its one compiled signature)."""
    from auvtrack.control import plugin
    from auvtrack.gym import replay

    vec = TrackVectorEnv(2, SUITE, "line", "model", duration=0.2)
    vec.reset(seed=[1, 2])
    probe = plugin._PROBED[replay.control]
    vec.reset(seed=[3, 4])
    assert plugin._PROBED[replay.control] is probe and len(probe.signatures) == 1
