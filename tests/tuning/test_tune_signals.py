"""``auvtrack tune`` stopped by SIGTERM: exit 130, the study kept, its worker processes ended, the same command resumes."""
from __future__ import annotations

import re
import signal
import sys

import pytest

from auvtrack.cli import main
from auvtrack.tuning import study as study_mod
from auvtrack.tuning import tune
from cli_process import HANG_S, CliProcess, wait_gone
from tiny_suite import TINY

from tuning_suite import SPLITS

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="POSIX signals, reads /proc")


@pytest.fixture(scope="module")
def suite_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("suite") / "tiny.toml"
    path.write_text(TINY + SPLITS)
    return path


def _study(folder):
    import optuna

    return optuna.load_study(study_name=study_mod.STUDY_NAME, storage=f"sqlite:///{folder / study_mod.STUDY_FILE}")


def _finished(folder):
    """(state, gains, value) of the finished trials, in the order they were asked."""
    return [(t.state.name, t.params, t.value) for t in _study(folder).get_trials()
            if t.state.name in ("COMPLETE", "PRUNED")]


def _done(line: str, at_least: int) -> bool:
    m = re.match(r"trial (\d+)/\d+$", line)
    return m is not None and int(m.group(1)) >= at_least


def _command(suite_path, out, budget, *extra):
    return ["tune", "--controller", "pid", "--suite", str(suite_path), "--budget", str(budget), "--seed", "7",
            "--out", str(out), "--no-validate", *extra]


@pytest.mark.slow
def test_sigterm_keeps_the_study_and_the_same_command_resumes_it(suite_path, tmp_path):
    budget = 12
    tune("pid", suite_path, trials=budget, out=tmp_path / "whole", seed=7, validate=False)
    whole = _finished(tmp_path / "whole")
    assert len(whole) == budget
    cmd = _command(suite_path, tmp_path / "cut", budget)
    with CliProcess(cmd) as p:
        p.wait_for(lambda line: _done(line, 2))  # two trials told, the third one running
        p.proc.send_signal(signal.SIGTERM)
        code, _, err = p.finish(HANG_S)
    assert code == 130, err
    assert "interrupted; the study in" in err and "Traceback" not in err, err
    assert (tmp_path / "cut" / study_mod.STUDY_FILE).is_file()
    cut = _finished(tmp_path / "cut")
    assert 2 <= len(cut) < budget and cut == whole[:len(cut)]  # the completed trials are kept as they were
    with CliProcess(cmd) as p:
        code, _, err = p.finish(HANG_S)
    assert code == 0, err
    assert _finished(tmp_path / "cut") == whole  # resumed: the trials of the uninterrupted tuning
    assert not [t for t in _study(tmp_path / "cut").get_trials() if t.state.name == "RUNNING"]


@pytest.mark.slow
def test_sigterm_ends_the_worker_processes_of_parallel_trials(suite_path, tmp_path):
    budget = 40
    cmd = _command(suite_path, tmp_path / "par", budget, "--parallel", "2")
    with CliProcess(cmd) as p:
        p.wait_for(lambda line: _done(line, 1))  # the workers are flying trials
        children = p.children()
        p.proc.send_signal(signal.SIGTERM)
        code, _, err = p.finish(HANG_S)
    assert len(children) >= 2, children  # two workers (and multiprocessing's resource tracker)
    assert code == 130, err
    assert "Traceback" not in err, err
    assert wait_gone(children, HANG_S) == []
    kept = _finished(tmp_path / "par")
    assert 1 <= len(kept) < budget
    with CliProcess(cmd) as p:
        code, _, err = p.finish(4 * HANG_S)
    assert code == 0, err
    study = _study(tmp_path / "par")
    assert len(_finished(tmp_path / "par")) == budget  # exactly the budget: nothing lost, nothing counted twice
    assert not [t for t in study.get_trials() if t.state.name == "RUNNING"]
    assert all(t in _finished(tmp_path / "par") for t in kept)


class _LostSignal:
    """Deleted, sends SIGTERM from its finaliser: the handler's KeyboardInterrupt is dropped there ("Exception ignored")."""

    def __del__(self):
        signal.raise_signal(signal.SIGTERM)


def test_a_signal_whose_interrupt_was_dropped_stops_after_the_trial_under_way(suite_path, tmp_path, monkeypatch):
    real, calls = study_mod._fly, []

    def fly(*args, **kw):
        calls.append(1)
        if len(calls) == 2:
            _LostSignal()
        return real(*args, **kw)

    monkeypatch.setattr(study_mod, "_fly", fly)
    dropped = []
    monkeypatch.setattr(sys, "unraisablehook", dropped.append)
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        code = main([*_command(suite_path, tmp_path / "lost", 5), "--quiet"])
    finally:  # the command leaves both signals ignored (its process is ending): not this one
        for s, handler in saved.items():
            signal.signal(s, handler)
    assert [type(u.exc_value) for u in dropped] == [KeyboardInterrupt]  # the signal's interrupt was lost
    assert code == 130
    assert len(_finished(tmp_path / "lost")) == 2 and len(calls) == 2
