"""Ctrl-C while the run folder is written keeps the result: the CSV ends at the block being
written, run.json (whole run's status and metrics) records how many rows it holds, the folder is
published atomically and verifies, and ``auvtrack run`` exits 130 at once."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import auvtrack
from auvtrack.cli import EXIT_INTERRUPTED
from auvtrack.simulation.result import CSV_BLOCK_ROWS, Result, verify_run_folder

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "scenarios" / "paper.toml"
ROWS = 3 * CSV_BLOCK_ROWS + 7  # three full blocks and a short one


def _result(rows: int = ROWS) -> Result:
    rng = np.random.default_rng(7)
    base = auvtrack.simulate(PAPER, ["sim.duration=0.01"], warn=False)
    channels = {n: rng.standard_normal(rows) * 10.0 ** rng.integers(-8, 8, rows) for n in base.names}
    channels["t"] = np.arange(rows) * 1e-3
    return Result(channels, base.scenario, base.status, base.failure, base.metrics, base.meta)


def _stop_after(calls: int):
    asked = []
    return lambda: asked.append(1) or len(asked) > calls


@pytest.mark.parametrize("blocks", [0, 1, 3])
def test_a_stop_ends_the_csv_at_a_block_and_the_folder_is_whole(tmp_path, blocks):
    res = _result()
    folder = res.save(tmp_path / "run", mat=True, stop=_stop_after(blocks))
    rows = blocks * CSV_BLOCK_ROWS
    assert verify_run_folder(folder) == []
    doc = json.loads((folder / "run.json").read_text())
    assert doc["files"]["trajectory.csv"]["rows"] == rows and doc["files"]["trajectory.csv"]["rows_in_result"] == ROWS
    assert doc["metrics"].keys() == res.metrics.keys() and doc["status"] == res.status
    assert not (folder / "trajectory.mat").exists()  # the MATLAB file is all or nothing
    back = Result.load(folder)
    assert len(back) == rows
    for name in res.names:
        np.testing.assert_array_equal(back[name], res[name][:rows])  # bit for bit


def test_without_a_stop_the_folder_is_what_it_was(tmp_path):
    res = _result()
    plain, asked = res.save(tmp_path / "plain"), res.save(tmp_path / "asked", stop=lambda: False)
    assert (plain / "trajectory.csv").read_bytes() == (asked / "trajectory.csv").read_bytes()
    for folder in (plain, asked):
        assert json.loads((folder / "run.json").read_text())["files"]["trajectory.csv"].keys() == {"sha256", "bytes"}
        assert len(Result.load(folder)) == ROWS


DRIVER = textwrap.dedent("""
    import os, signal, sys, time
    from auvtrack.cli import main
    from auvtrack.simulation.result import Result
    write = Result._write_csv
    def write_then_ctrl_c(self, fh, stop=None):
        class Fh:
            n = 0
            def write(self, data):
                fh.write(data)
                Fh.n += 1
                if Fh.n == 2:  # the header and the first block are written
                    open(sys.argv[2], "w").write(repr(time.time()))
                    os.kill(os.getpid(), getattr(signal, sys.argv[4]))
        return write(self, Fh(), stop)
    Result._write_csv = write_then_ctrl_c
    sys.exit(main(["run", sys.argv[1], "--out", sys.argv[3], "--set", "sim.duration=10",
                   "--set", "sim.log_dt=0.001"]))
""")


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_ctrl_c_while_the_cli_writes_keeps_the_folder_and_exits_130_at_once(tmp_path, sig):
    auvtrack.simulate(PAPER, ["sim.duration=0.01"], warn=False)  # the subprocess loads the kernel from the cache
    stamp, out = tmp_path / "signalled", tmp_path / "run"
    p = subprocess.run([sys.executable, "-c", DRIVER, str(PAPER), str(stamp), str(out), sig], cwd=tmp_path,
                       env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True, text=True, timeout=600,
                       preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    ended = time.time()
    assert p.returncode == EXIT_INTERRUPTED, p.stderr
    assert ended - float(stamp.read_text()) < 5.0  # no wait for the other 9000 rows
    assert "Traceback" not in p.stderr
    assert f"trajectory.csv holds {CSV_BLOCK_ROWS} of 10001 rows" in p.stderr and str(out) in p.stderr
    assert verify_run_folder(out) == []
    doc = json.loads((out / "run.json").read_text())
    assert doc["status"] == "ok" and doc["files"]["trajectory.csv"]["rows"] == CSV_BLOCK_ROWS
    assert len(Result.load(out)) == CSV_BLOCK_ROWS
