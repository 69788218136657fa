"""``auvtrack train`` stopped by SIGTERM: exit 130, the checkpoint kept, the same command ends where an uninterrupted one does."""
from __future__ import annotations

import json
import re
import signal
import sys

import numpy as np
import pytest

from auvtrack.cli import main
from auvtrack.gym import train as train_mod
from cli_process import HANG_S, CliProcess

from .test_train import suite_file  # noqa: F401  (the fixture: the tiny suite with its splits)

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="POSIX signals")


def _args(suite_file, out):
    return ["train", "--quick", "--suite", str(suite_file), "--tier", "calm", "--task", "line", "--iterations", "12",
            "--directions", "2", "--top", "1", "--seeds-per-iteration", "1", "--eval-every", "3", "--seed", "5",
            "--out", str(out)]


def _checkpoint(folder):
    with np.load(folder / "checkpoint.npz") as z:
        curve = [{k: v for k, v in r.items() if k != "wall_s"} for r in json.loads(str(z["curve"]))]
        return int(z["iteration"]), z["M"].copy(), z["mean"].copy(), z["m2"].copy(), curve


@pytest.mark.slow
def test_sigterm_keeps_the_checkpoint_and_the_same_command_resumes(suite_file, tmp_path):
    assert main([*_args(suite_file, tmp_path / "whole"), "--quiet"]) == 0
    whole = _checkpoint(tmp_path / "whole")
    with CliProcess(_args(suite_file, tmp_path / "cut")) as p:
        p.wait_for(lambda line: re.match(r"iteration 2/12:", line) is not None)
        p.proc.send_signal(signal.SIGTERM)
        code, _, err = p.finish(HANG_S)
    assert code == 130, err
    assert "holds every completed iteration" in err and "Traceback" not in err, err
    j, *_, curve = _checkpoint(tmp_path / "cut")
    assert 2 <= j < 12 and curve == whole[-1][:j + 1]  # the completed iterations, as the uninterrupted run's
    assert (tmp_path / "cut" / "policy.npz").is_file()
    with CliProcess(_args(suite_file, tmp_path / "cut")) as p:
        code, _, err = p.finish(HANG_S)
    assert code == 0, err
    resumed = _checkpoint(tmp_path / "cut")
    assert resumed[0] == whole[0] == 12 and resumed[-1] == whole[-1]
    for a, b in zip(resumed[1:4], whole[1:4]):
        assert np.array_equal(a, b)


class _LostSignal:
    """Deleted, sends SIGTERM from its finaliser: the handler's KeyboardInterrupt is dropped there ("Exception ignored")."""

    def __del__(self):
        signal.raise_signal(signal.SIGTERM)


def test_a_signal_whose_interrupt_was_dropped_stops_at_the_next_iteration(suite_file, tmp_path, monkeypatch):
    real = train_mod._Trainer.iteration

    def iteration(self, j, M, stats):
        if j == 1:
            _LostSignal()
        return real(self, j, M, stats)

    monkeypatch.setattr(train_mod._Trainer, "iteration", iteration)
    dropped = []
    monkeypatch.setattr(sys, "unraisablehook", dropped.append)
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        code = main([*_args(suite_file, tmp_path / "lost"), "--quiet"])
    finally:  # the command leaves both signals ignored (its process is ending): not this one
        for s, handler in saved.items():
            signal.signal(s, handler)
    assert [type(u.exc_value) for u in dropped] == [KeyboardInterrupt]  # the signal's interrupt was lost
    assert code == 130
    assert _checkpoint(tmp_path / "lost")[0] == 2  # the iteration under way completed, then the stop
