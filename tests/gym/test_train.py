"""``auvtrack train``: ARS on the vector environment, its seeds, checkpoint and resume, the held-out improvement."""
from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.cli import main
from auvtrack.control.policy import load_policy
from auvtrack.control.policy_observation import OBS
from auvtrack.gym import train as train_mod
from auvtrack.gym.train import TrainConfig, _Stats, train

from .test_env import TINY

SPLITS = "\n[splits.training]\nseeds = [100, 108]\n[splits.validation]\nseeds = [200, 204]\n"


@pytest.fixture
def suite_file(tmp_path):
    path = tmp_path / "tiny_split.toml"
    path.write_text(TINY + SPLITS)
    return path


def _cfg(suite_file, **kw):
    base = dict(suite=str(suite_file), tier="calm", tasks=("line",), iterations=3, directions=2, top=1,
                seeds_per_iteration=1, eval_every=1, duration=0.4, seed=3, step_size=0.05, noise=0.05)
    return TrainConfig(**{**base, **kw})


@given(st.lists(st.integers(1, 6), min_size=1, max_size=5), st.integers(0, 2**16))
@settings(max_examples=25, deadline=None)
def test_running_statistics_equal_the_batch_statistics(sizes, seed):
    rng = np.random.default_rng(seed)
    batches = [rng.normal(3.0, 2.0, (n, OBS.size)) for n in sizes]
    s = _Stats()
    for b in batches:
        s.add(b)
    allx = np.concatenate(batches)
    np.testing.assert_allclose(s.mean, allx.mean(axis=0), rtol=1e-12, atol=1e-12)
    if len(allx) > 1:
        np.testing.assert_allclose(s.std(), allx.std(axis=0, ddof=1), rtol=1e-9)


@pytest.mark.parametrize("method", ["ars", "cmaes"])
def test_killed_and_resumed_equals_uninterrupted(tmp_path, suite_file, method):
    cfg = _cfg(suite_file, method=method)
    whole = train(cfg, tmp_path / "whole")

    def kill(row):
        if row["iteration"] == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        train(cfg, tmp_path / "cut", progress=kill)
    cut = load_policy(tmp_path / "cut" / "policy.npz")  # what was computed is kept: two iterations
    assert cut["header"]["provenance"]["budget"]["iterations"] == 2
    resumed = train(cfg, tmp_path / "cut")
    assert np.array_equal(resumed.M, whole.M) and np.any(whole.M != 0)
    assert np.array_equal(resumed.mean, whole.mean) and np.array_equal(resumed.std, whole.std)
    drop = lambda curve: [{k: v for k, v in r.items() if k != "wall_s"} for r in curve]
    assert drop(resumed.curve) == drop(whole.curve)
    a, b = load_policy(whole.outputs["policy"]), load_policy(resumed.outputs["policy"])
    assert np.array_equal(a["weights"][0], b["weights"][0]) and np.array_equal(a["obs_std"], b["obs_std"])
    more = train(cfg.__class__(**{**cfg.__dict__, "iterations": 4}), tmp_path / "cut")  # a larger budget continues
    assert len(more.curve) == 5 and more.curve[:4][1]["train_return"] == whole.curve[1]["train_return"]
    with pytest.raises(ValueError, match="other settings .*noise"):
        train(cfg.__class__(**{**cfg.__dict__, "noise": 0.1}), tmp_path / "cut")


def test_seeds_come_from_the_splits(tmp_path, suite_file, monkeypatch):
    seen = {"train": set(), "validation": set()}
    real = train_mod.rollout

    def spy(venv, seeds, Ms, mean, std, stats=None):
        seen["train" if stats is not None else "validation"].update(int(s) for s in seeds)
        return real(venv, seeds, Ms, mean, std, stats)

    monkeypatch.setattr(train_mod, "rollout", spy)
    res = train(_cfg(suite_file, iterations=4, seeds_per_iteration=2), tmp_path / "o")
    assert seen["train"] <= set(range(100, 108)) and len(seen["train"]) > 2
    assert seen["validation"] == set(range(200, 204))
    prov = load_policy(res.outputs["policy"])["header"]["provenance"]
    assert prov["training_seeds"] == [100, 108] and prov["validation_seeds"] == [200, 204]
    assert prov["budget"]["episodes"] == res.episodes == 4 * 2 * 2 * 2
    assert prov["command"].startswith("auvtrack train --suite") and "ARS" in prov["method"]
    assert prov["reward"] == {"rmse": [1.0, 100.0]}  # no run score: the error alone, w = s = 1, cap 10 squared


def test_quick_improves_the_held_out_return(tmp_path, suite_file, capsys):
    """CI-sized: tiny suite (calm tier, both tasks, 1 s quick episodes), seed 0, 8 iterations x 4 directions x 1 seed."""
    out = tmp_path / "quick"
    code = main(["train", "--quick", "--suite", str(suite_file), "--tier", "calm", "--directions", "4", "--top", "2",
                 "--seeds-per-iteration", "1", "--eval-every", "4", "--seed", "0", "--out", str(out), "--quiet"])
    assert code == 0
    rows = (out / "curve.csv").read_text().splitlines()
    assert rows[0] == ",".join(train_mod.CURVE) and len(rows) == 1 + 9
    ck = np.load(out / "checkpoint.npz")
    curve = json.loads(str(ck["curve"]))
    first, last = curve[0]["validation_return"], curve[-1]["validation_return"]
    assert last > first, (first, last)
    assert (out / "curve.png").stat().st_size > 1000
    assert "held-out return: initial policy" in capsys.readouterr().out


def test_cmaes_quick_improves_the_held_out_return(tmp_path, suite_file):
    """CI-sized CMA-ES: tiny suite (calm tier, both tasks, 1 s quick episodes), seed 0, 8 iterations, lambda = 8."""
    out = tmp_path / "cma"
    code = main(["train", "--quick", "--method", "cmaes", "--suite", str(suite_file), "--tier", "calm",
                 "--directions", "4", "--noise", "0.05", "--seeds-per-iteration", "1", "--eval-every", "4",
                 "--seed", "0", "--out", str(out), "--quiet"])
    assert code == 0
    curve = json.loads(str(np.load(out / "checkpoint.npz")["curve"]))
    first, last = curve[0]["validation_return"], curve[-1]["validation_return"]
    assert last > first, (first, last)
    prov = load_policy(out / "policy.npz")["header"]["provenance"]
    assert "CMA-ES" in prov["method"] and "--method cmaes" in prov["command"]


@pytest.mark.parametrize("args, field", [(["--top", "9"], "--top"), (["--noise", "0"], "--noise"),
                                        (["--method", "sgd"], "--method"), (["--action", "fins"], "--action"),
                                        (["--tier", "nope"], "tier"), (["--task", "nope"], "tasks")])
def test_bad_settings_one_line(tmp_path, suite_file, capsys, args, field):
    code = main(["train", "--suite", str(suite_file), "--out", str(tmp_path / "o"), *args])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and field in err, err


def test_suite_without_splits_refused(tmp_path, capsys):
    path = tmp_path / "nosplit.toml"
    path.write_text(TINY)
    assert main(["train", "--suite", str(path), "--out", str(tmp_path / "o")]) == 2
    assert "splits.training" in capsys.readouterr().err


@pytest.fixture
def dask_client():
    """A local Dask cluster (two worker threads), always closed."""
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        yield client


@pytest.mark.parametrize("method", ["ars", "cmaes"])
def test_rollouts_on_dask_equal_the_local_training(tmp_path, suite_file, dask_client, method):
    """Both training tasks' rollouts on the cluster: the same policy, statistics and curve bit for bit."""
    cfg = _cfg(suite_file, method=method, tasks=("line", "helix"))
    local = train(cfg, tmp_path / "local")
    remote = train(cfg, tmp_path / "dask", client=dask_client)
    assert np.any(local.M != 0)
    assert np.array_equal(remote.M, local.M) and np.array_equal(remote.mean, local.mean)
    assert np.array_equal(remote.std, local.std)
    drop = lambda curve: [{k: v for k, v in r.items() if k != "wall_s"} for r in curve]
    assert drop(remote.curve) == drop(local.curve)
    assert train_mod._REMOTE_ENVS  # the worker threads of this process kept their environments


def test_scheduler_nobody_answers_is_one_line(tmp_path, suite_file, capsys):
    import socket

    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    sock.close()  # a closed port
    code = main(["train", "--suite", str(suite_file), "--out", str(tmp_path / "o"), "--scheduler",
                 f"tcp://127.0.0.1:{port}"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "--scheduler" in err, err
