"""``auvtrack train`` compiles the environments' step before the first episode (:func:`auvtrack.gym.env.compile_steps`)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from auvtrack.cli import main
from auvtrack.gym import env as env_mod
from auvtrack.gym.env import TrackEnv, compile_steps
from auvtrack.gym.stepping import step_module
from auvtrack.gym.vector import TrackVectorEnv

from .test_train import suite_file  # noqa: F401  (the fixture: the tiny suite with its splits)

NOTICE = "compiling kernels (first run only, about"
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def unmarked(tmp_path, monkeypatch):
    """The step functions read as not compiled (their markers in an empty folder); compiling loads the disk cache."""
    folder = tmp_path / "markers"
    monkeypatch.setattr(env_mod, "_step_marker", lambda key, part: folder / f"gym_{key.name}.{part}.json")
    return folder


def _train(suite_file, out, *extra):
    return main(["train", "--quick", "--suite", str(suite_file), "--tier", "calm", "--task", "line", "--iterations",
                 "1", "--directions", "2", "--top", "1", "--seeds-per-iteration", "1", "--out", str(out), *extra])


def test_the_notice_and_the_bar_come_before_the_first_episode(suite_file, tmp_path, unmarked, monkeypatch, capsys):
    real = TrackEnv._prepare

    def prepare(self, index):  # every episode starts here
        print("EPISODE STARTS", file=sys.stderr, flush=True)
        return real(self, index)

    monkeypatch.setattr(TrackEnv, "_prepare", prepare)
    assert _train(suite_file, tmp_path / "t") == 0
    err = capsys.readouterr().err
    start = err.index("EPISODE STARTS")
    assert err.count(NOTICE) == 1 and err.index(NOTICE) < start, err
    assert "replay on 5dof environment step" in err[:start]
    bar = err[:start].split(NOTICE, 1)[1]
    assert "compiling:" in bar and "kernel" in bar  # the tqdm bar
    assert sorted(p.name.rsplit(".", 2)[1] for p in unmarked.iterdir()) == ["observe_all", "step_serial"]


def test_quiet_prints_neither(suite_file, tmp_path, unmarked, capsys):
    assert _train(suite_file, tmp_path / "q", "--quiet") == 0
    err = capsys.readouterr().err
    assert "compiling" not in err and "kernel" not in err, err
    assert len(list(unmarked.iterdir())) == 2  # compiled all the same


def test_the_episodes_compile_nothing_more(suite_file, unmarked):
    venv = TrackVectorEnv(3, suite_file, "line", "calm", duration=0.2, autoreset="disabled")
    done = compile_steps([venv], index=100)
    assert done == ["replay on 5dof: observe_all", "replay on 5dof: step_serial"]
    module = step_module(_key(suite_file))
    before = (len(module.observe_all.signatures), len(module.step_serial.signatures))
    venv.reset(seed=100)
    venv.step([[0.1, 0.0, 0.0]] * 3)
    TrackEnv(suite_file, "line", "calm", duration=0.2).reset(seed=101)
    assert (len(module.observe_all.signatures), len(module.step_serial.signatures)) == before == (1, 1)
    assert compile_steps([venv], index=100) == []  # marked now: no notice, nothing to do


def _key(suite_file):
    from auvtrack.gym.env import episode_scenario, suite_of
    from auvtrack.simulation.pipeline import prepare

    return prepare(episode_scenario(suite_of(suite_file), "line", "calm", 100)).key


@pytest.mark.slow
def test_a_fresh_kernel_cache_compiles_up_front(suite_file, tmp_path):
    """A real first run (an empty kernel cache): the notice and the bar before the first iteration; nothing under --quiet."""
    errs = {}
    for name, extra in (("loud", []), ("quiet", ["--quiet"])):
        env = {**os.environ, "AUVTRACK_CACHE_DIR": str(tmp_path / f"cache-{name}"), "PYTHONPATH": str(ROOT)}
        p = subprocess.run([sys.executable, "-m", "auvtrack.cli", "train", "--quick", "--suite", str(suite_file),
                            "--tier", "calm", "--task", "line", "--iterations", "1", "--directions", "2", "--top", "1",
                            "--seeds-per-iteration", "1", "--out", str(tmp_path / name), *extra],
                           capture_output=True, text=True, env=env, timeout=600)
        assert p.returncode == 0, p.stderr
        errs[name] = p.stderr
    loud = errs["loud"]
    assert loud.count(NOTICE) == 1 and loud.index(NOTICE) < loud.index("iteration 1/1")
    assert "compiling:" in loud[:loud.index("iteration 1/1")]
    assert "compiling" not in errs["quiet"] and "iteration" not in errs["quiet"], errs["quiet"]
