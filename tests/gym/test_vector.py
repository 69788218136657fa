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


def test_reset_and_autoreset_of_many_envs_at_once_are_each_env_s_own_episode():
    """Repeated and new seed indices in one reset, then every env ending on the same step: each row is its
    seed index's single-env episode, and two vector envs with one seed draw the same autoreset indices."""
    seeds, dur = [4, 4, 7, 9, 4], 0.1  # 5 control steps
    vecs = [TrackVectorEnv(5, SUITE, "line", "model", duration=dur) for _ in range(2)]
    obs = [v.reset(seed=seeds)[0] for v in vecs]
    np.testing.assert_array_equal(obs[0], obs[1])
    for i, s in enumerate(seeds):
        np.testing.assert_array_equal(obs[0][i], TrackEnv(SUITE, "line", "model", duration=dur).reset(seed=s)[0])
    acts = np.random.default_rng(9).uniform(-1, 1, (5, 5, 3))
    for k in range(5):
        outs = [v.step(acts[k]) for v in vecs]
    assert outs[0][3].all()  # every env truncated on this step
    outs = [v.step(acts[0]) for v in vecs]  # the autoreset step: five new seed indices, drawn in env order
    drawn = outs[0][4]["seed_index"]
    assert np.array_equal(drawn, outs[1][4]["seed_index"]) and len(set(drawn.tolist()) - set(seeds)) == 5
    np.testing.assert_array_equal(outs[0][0], outs[1][0])
    assert np.all(outs[0][1] == 0.0) and np.all(vecs[0].carry.ks[:, 0] == 0)
    nxt = vecs[0].step(acts[1])
    for i, s in enumerate(drawn):
        single = TrackEnv(SUITE, "line", "model", duration=dur)
        np.testing.assert_array_equal(outs[0][0][i], single.reset(seed=int(s))[0])
        o, r, _, _, _ = single.step(acts[1, i])
        np.testing.assert_array_equal(nxt[0][i], o)
        assert nxt[1][i] == r
