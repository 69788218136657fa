"""``auvtrack tune`` compiles its kernels before the first trial, with the notice and bar of the other commands."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from auvtrack.cli import main
from auvtrack.engine import kernels
from auvtrack.tuning import study as study_mod
from tiny_suite import TINY

from tuning_suite import SPLITS

NOTICE = "compiling kernels (first run only, about"
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def suite_path(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY + SPLITS)
    return path


@pytest.fixture
def uncompiled(monkeypatch):
    """Every kernel reads as not compiled until compiled (loaded from the disk cache) in this test.

    Returns the names compiled so far; the markers on disk are left alone.
    """
    done: set[str] = set()
    real = kernels.is_compiled
    monkeypatch.setattr(kernels, "is_compiled", lambda key, lanes=False: key.name in done and real(key, lanes))
    monkeypatch.setattr(kernels, "mark_compiled", lambda key, seconds: done.add(key.name))
    return done


@pytest.fixture
def first_trial(monkeypatch):
    """Each trial writes ``TRIAL STARTS`` to stderr as it starts."""
    real = study_mod._fly

    def fly(*args, **kw):
        print("TRIAL STARTS", file=sys.stderr, flush=True)
        return real(*args, **kw)

    monkeypatch.setattr(study_mod, "_fly", fly)


def _tune(suite_path, out, *extra):
    return main(["tune", "--controller", "pid", "--suite", str(suite_path), "--budget", "2", "--out", str(out),
                 "--no-validate", *extra])


def test_the_notice_and_the_bar_come_before_the_first_trial(suite_path, tmp_path, uncompiled, first_trial, capsys):
    assert _tune(suite_path, tmp_path / "t") == 0
    err = capsys.readouterr().err
    assert err.count(NOTICE) == 1, err  # once, up front: nothing compiles inside a trial
    start = err.index("TRIAL STARTS")
    assert err.index(NOTICE) < start
    assert "pid on 5dof" in err[:start]
    bar = err[:start].split(NOTICE, 1)[1]
    assert "compiling:" in bar and "kernel" in bar  # the tqdm bar over the kernels
    assert any(name.startswith("k_pid__") for name in uncompiled)


def test_quiet_prints_neither_but_still_compiles_first(suite_path, tmp_path, uncompiled, monkeypatch, capsys):
    compiled_at_first_trial: list[set] = []
    real = study_mod._fly

    def fly(*args, **kw):
        compiled_at_first_trial.append(set(uncompiled))
        return real(*args, **kw)

    monkeypatch.setattr(study_mod, "_fly", fly)
    assert _tune(suite_path, tmp_path / "q", "--quiet") == 0
    err = capsys.readouterr().err
    assert "compiling" not in err and "kernel" not in err, err
    assert any(n.startswith("k_pid__") for n in compiled_at_first_trial[0])


def test_cached_kernels_print_no_notice(suite_path, tmp_path, capsys):
    assert _tune(suite_path, tmp_path / "c") == 0
    assert _tune(suite_path, tmp_path / "c2") == 0  # the first call may have compiled; the second finds them cached
    assert NOTICE not in capsys.readouterr().err


def test_optunas_importance_warning_is_one_line_and_silenced_by_quiet(suite_path, tmp_path, capsys):
    # one finished trial: Optuna warns that it cannot compute the importances
    args = ["tune", "--controller", "pid", "--suite", str(suite_path), "--budget", "1", "--no-validate"]
    assert main([*args, "--out", str(tmp_path / "loud")]) == 0
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if "importance" in ln.lower()]
    assert len(lines) == 1 and lines[0].startswith("note: parameter importances:"), err
    assert "Warning" not in err and "optuna" not in err.lower(), err
    assert main([*args, "--out", str(tmp_path / "quiet"), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert err.strip() == "", err


@pytest.mark.slow
def test_a_fresh_kernel_cache_compiles_up_front(suite_path, tmp_path):
    """A real first run (an empty kernel cache): the notice and the bar before the trials; nothing under --quiet."""
    outs = {}
    for name, extra in (("loud", []), ("quiet", ["--quiet"])):
        env = {**os.environ, "AUVTRACK_CACHE_DIR": str(tmp_path / f"cache-{name}"), "PYTHONPATH": str(ROOT)}
        p = subprocess.run([sys.executable, "-m", "auvtrack.cli", "tune", "--controller", "pid", "--suite",
                            str(suite_path), "--budget", "2", "--out", str(tmp_path / name), "--no-validate", *extra],
                           capture_output=True, text=True, env=env, timeout=600)
        assert p.returncode == 0, p.stderr
        outs[name] = p.stderr
    loud = outs["loud"]
    assert loud.count(NOTICE) == 1 and loud.index(NOTICE) < loud.index("trial 1/2")
    assert "compiling:" in loud[:loud.index("trial 1/2")]
    assert "compiling" not in outs["quiet"] and "trial" not in outs["quiet"], outs["quiet"]
