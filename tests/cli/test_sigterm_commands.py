"""SIGTERM (``kill``, a batch system's stop) to ``check``, ``reproduce`` and ``study``, as Ctrl-C: exit 130 with
one line and no traceback, child processes ended, what was already written kept.

Each command is signalled on observed progress (a file a plug-in writes, a progress line) and every
wait is bounded (:data:`cli_process.HANG_S`), so a command that ignores the signal fails the test.
"""
from __future__ import annotations

import signal
import sys
import time
from pathlib import Path

import pytest

from auvtrack.cli import EXIT_INTERRUPTED
from auvtrack.simulation.result import verify_run_folder
from cli_process import HANG_S, CliProcess, wait_gone

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="POSIX signals, /proc")

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "plugin_controller.py"


def _stopped(p: CliProcess, t_signal: float) -> tuple[str, float]:
    """Exit 130, the stop's one line last, no traceback: stderr and the seconds from the signal to the exit."""
    code, _, err = p.finish(HANG_S)
    elapsed = time.monotonic() - t_signal
    assert code == EXIT_INTERRUPTED, err
    assert "Traceback" not in err and "Error" not in err, err
    assert err.splitlines()[-1] == "auvtrack: interrupted", err
    return err, elapsed


@pytest.mark.parametrize("loop", ["time.sleep(0.05)", "pass"], ids=["sleeping", "spinning"])
def test_sigterm_stops_check_of_a_plugin_that_loops_at_import(tmp_path, loop):
    mark = tmp_path / "importing"
    law = tmp_path / "endless_import.py"
    law.write_text(f"import pathlib, time\npathlib.Path({str(mark)!r}).write_text('x')\nwhile True:\n    {loop}\n"
                   + EXAMPLE.read_text())
    with CliProcess(["check", "paper", "--set", "controller.kind=plugin", "--set",
                     f"controller.module={str(law)!r}"], cwd=tmp_path) as p:
        deadline = time.monotonic() + HANG_S
        while not mark.exists():
            assert p.proc.poll() is None and time.monotonic() < deadline, p.finish(1)
            time.sleep(0.05)
        t0 = time.monotonic()
        p.proc.send_signal(signal.SIGTERM)
        _, elapsed = _stopped(p, t0)
    assert elapsed < 10.0, elapsed  # a Python loop sees the signal at once: the rest is the exit
    assert sorted(f.name for f in tmp_path.iterdir()) == ["endless_import.py", "importing"]  # nothing of its own


@pytest.mark.slow
def test_sigterm_stops_reproduce_ends_its_figure_processes_and_keeps_the_run_folders(tmp_path):
    out = tmp_path / "rep"
    with CliProcess(["reproduce", "--quick", "--out", str(out)]) as p:
        p.wait_for(lambda line: line.startswith("reproduce:") and " 4/10 " in line)  # both runs of each controller
        deadline = time.monotonic() + HANG_S
        while not (kids := p.children()):  # the figure processes
            assert p.proc.poll() is None and time.monotonic() < deadline, "no figure process"
            time.sleep(0.02)
        t0 = time.monotonic()
        p.proc.send_signal(signal.SIGTERM)
        _, elapsed = _stopped(p, t0)
    assert wait_gone(kids, HANG_S) == []
    assert elapsed < HANG_S, elapsed
    for kind in ("fxtntsmc", "ftsmc", "tuned/fxtntsmc", "tuned/ftsmc"):  # written before the signal: kept, whole
        assert verify_run_folder(out / kind) == [], kind
    assert not (out / "metrics.json").exists()  # the report was not written half


@pytest.mark.slow
def test_sigterm_stops_a_study(tmp_path):
    out = tmp_path / "ft"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    with CliProcess(["study", "fixed-time", "--quick", "--out", str(out)]) as p:
        p.wait_for(lambda line: line.startswith("fixed-time:"))  # its runs are under way
        t0 = time.monotonic()
        p.proc.send_signal(signal.SIGTERM)
        _, elapsed = _stopped(p, t0)
        left = p.children()
    assert wait_gone(left, HANG_S) == []
    assert elapsed < HANG_S, elapsed
    assert (out / "keep.txt").read_text() == "mine"
    assert not (out / "report.md").exists()
