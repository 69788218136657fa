"""``auvtrack sweep``: resume repairs bad chunks, plans are checked against the study's [limits] up front,
the printed resume command works, ``--out`` never writes into the user's files, and Ctrl-C twice is clean.

One in-process Dask cluster (a thread worker on a TCP scheduler) serves the module.
"""
from __future__ import annotations

import os
import shlex
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pandas as pd
import pytest

from auvtrack.batch.sweep import chunk_path, read_results, run_sweep
from auvtrack.cli import main

STUDY = """
name = "r"
set = ["sim.duration=0.2", "estimator.neurons=3", "controller.kind=ftsmc"]
seed = {seed}
samples = 8
chunk_size = 2

[random."uncertainty.D"]
dist = "uniform"
low = 0.0
high = 0.4
"""


def study(folder: Path, seed: int = 3, name: str = "study.toml") -> Path:
    path = folder / name
    path.write_text(STUDY.replace("{seed}", str(seed)))
    return path


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://",
                      dashboard_address=":0") as cluster, Client(cluster) as c:
        yield c


@pytest.fixture(scope="module")
def reference(tmp_path_factory, client):
    folder = tmp_path_factory.mktemp("ref")
    res = run_sweep(study(folder), folder / "out", client=client, progress=False)
    assert res.complete and res.chunks_run == 4
    return read_results(folder / "out")


def test_a_duplicated_truncated_or_foreign_chunk_is_recomputed(tmp_path, client, reference, capsys):
    out = tmp_path / "out"
    run_sweep(study(tmp_path), out, client=client, progress=False, max_chunks=3)
    run_sweep(study(tmp_path, seed=4, name="other.toml"), tmp_path / "other", client=client, progress=False)
    shutil.copy(chunk_path(out, 0), chunk_path(out, 1))  # duplicated: samples 0-1 twice, 2-3 missing
    chunk_path(out, 2).write_bytes(chunk_path(out, 2).read_bytes()[:64])  # truncated
    shutil.copy(chunk_path(tmp_path / "other", 0), chunk_path(out, 0))  # the same chunk of another study seed
    capsys.readouterr()
    res = run_sweep(study(tmp_path), out, client=client, progress=False, resume=True)
    err = capsys.readouterr().err.strip().splitlines()
    assert res.complete and res.chunks_redone == (0, 1, 2) and res.chunks_run == 4 and res.chunks_skipped == 0
    assert len(err) == 3 and all(line.startswith("auvtrack: ") and "recomputing chunk" in line for line in err), err
    assert "belongs to another run" in err[0] and "is a copy of chunk 0" in err[1] and "not a readable" in err[2]
    df = read_results(out)
    assert df["sample"].tolist() == list(range(8))  # each sample once
    pd.testing.assert_frame_equal(df, reference)


def test_the_printed_resume_command_works_verbatim(tmp_path, client, reference, capsys):
    out = tmp_path / "out"
    code = main(["sweep", str(study(tmp_path)), "--out", str(out), "--scheduler", client.scheduler.address,
                 "--max-chunks", "1", "--quiet"])
    assert code == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    argv = shlex.split(line.split("finish with: ", 1)[1])
    assert argv[:2] == ["auvtrack", "sweep"] and "--scheduler" in argv and argv[-1] == "--resume"
    assert main(argv[1:]) == 0
    pd.testing.assert_frame_equal(read_results(out), reference)


GRID = "[grid]\n\"uncertainty.C\" = [" + ", ".join(f"{i * 1e-6:.6f}" for i in range(50_000)) + "]\n"


@pytest.mark.parametrize("old, new, expect", [
    ("samples = 8", "samples = 90000000",
     "samples: 1 grid points x 90000000 samples = 90000000 samples, more than limits.max_samples = 1000000"),
    ("[random.", GRID + "[random.", "grid.uncertainty.C: 50000 values, more than limits.max_grid_values = 1000"),
    ("samples = 8\nchunk_size = 2", "samples = 200000\nchunk_size = 1",
     "chunk_size: 200000 samples in chunks of 1 make 200000 chunks, more than limits.max_chunks = 100000"),
    ("[random.", "[limits]\nmax_samples = 200000000\n[random.", "limits.max_samples: must be <= 100000000"),
])
def test_huge_plans_are_refused_in_about_a_second(old, new, expect, tmp_path, capsys):
    text = STUDY.replace("{seed}", "3")
    assert old in text
    path = tmp_path / "big.toml"
    path.write_text(text.replace(old, new, 1))
    t0 = time.monotonic()
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--quiet"])
    took = time.monotonic() - t0
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and f"{path}: " in err and expect in err, err
    assert not (tmp_path / "o").exists()
    assert took < 5.0, took  # parsing the file is most of it (50 000 grid values: ~0.5 s)
    print(f"refused in {took:.2f} s: {expect}")


def test_an_out_folder_of_the_user_s_own_files_is_refused(tmp_path, capsys):
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "data.csv").write_text("1,2\n")
    assert main(["sweep", str(study(tmp_path)), "--out", str(mine), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"--out: {mine} already holds files that are not an auvtrack sweep (data.csv)" in err, err
    assert [p.name for p in mine.iterdir()] == ["data.csv"]


def test_the_cli_default_worker_memory_is_the_library_s():
    from auvtrack.batch.sweep import DEFAULT_WORKER_MEMORY
    from auvtrack.cli import sweep as cli_sweep

    assert cli_sweep.DEFAULT_WORKER_MEMORY == DEFAULT_WORKER_MEMORY


def _descendants(pid: int) -> list[int]:
    """Every process under ``pid`` (Linux: read from /proc): a local cluster's nannies and workers."""
    parent = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                parent[int(entry.name)] = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, ValueError, IndexError):
                continue
    found, todo = [], [pid]
    while todo:
        here = todo.pop()
        kids = [c for c, p in parent.items() if p == here]
        found += kids
        todo += kids
    return found


def _chunks(out: Path) -> dict[str, bytes]:
    return {f.name: f.read_bytes() for f in sorted((out / "chunks").glob("chunk-*.parquet"))}


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="POSIX signals, /proc")
@pytest.mark.parametrize("sig, to_group", [(signal.SIGINT, True), (signal.SIGTERM, False)], ids=["ctrl-c", "kill"])
def test_a_second_signal_while_the_cluster_closes_exits_130_promptly_and_resume_finishes(tmp_path, sig, to_group):
    """A stop, then the same signal again while the sweep shuts down: exit 130 without a traceback, within
    seconds, the cluster's processes ended, every chunk written before the stop kept as it was, and the
    printed resume command, run verbatim, completes the sweep.

    Ctrl-C reaches the whole process group (a terminal's foreground job: the command and its workers);
    ``kill`` reaches the command only, which must end its workers itself.
    """
    from cli_process import HANG_S, wait_gone

    samples = 12
    path = tmp_path / "slow.toml"
    path.write_text(textwrap.dedent(f"""
        name = "twice"
        set = ["sim.duration=300", "sim.log_dt=1", "controller.kind=ftsmc"]
        samples = {samples}
        chunk_size = 1
    """))
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2]))
    cmd = [sys.executable, "-m", "auvtrack.cli", "sweep", str(path), "--out", str(out), "--workers", "1", "--quiet"]
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    send = (lambda: os.killpg(p.pid, sig)) if to_group else (lambda: p.send_signal(sig))
    try:
        t0 = time.monotonic()
        while not (out / "chunks").is_dir() or not list((out / "chunks").glob("chunk-*.parquet")):
            assert p.poll() is None and time.monotonic() - t0 < 600, p.stderr.read()
            time.sleep(0.2)
        workers = _descendants(p.pid)
        before = _chunks(out)
        assert workers and before
        t_stop = time.monotonic()
        send()
        time.sleep(0.05)
        assert p.poll() is None  # the shutdown is under way: the second signal lands in it
        send()
        for delay in (0.3, 0.5):  # and again, while the cluster is closing
            time.sleep(delay)
            if p.poll() is None:
                send()
        _, err = p.communicate(timeout=HANG_S)
        elapsed = time.monotonic() - t_stop
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
    assert p.returncode == 130, err
    assert "Traceback" not in err and "CancelledError" not in err, err
    assert "sweep interrupted" in err and "--resume" in err
    assert elapsed < HANG_S, elapsed
    assert wait_gone(workers, HANG_S) == []  # no nanny or worker left behind
    after = _chunks(out)
    assert {k: after.get(k) for k in before} == before  # written before the stop: kept, byte for byte
    assert len(after) < samples and not (out / "results.parquet").exists()
    import pyarrow.parquet as pq

    for name in after:  # every chunk on disk is whole
        assert pq.read_table(out / "chunks" / name).num_rows == 1
    command = err.strip().splitlines()[-1].split("finish with: ", 1)[1]
    q = subprocess.run([sys.executable, "-m", "auvtrack.cli", *shlex.split(command)[1:]], env=env,
                       capture_output=True, text=True, timeout=1800)
    assert q.returncode == 0, q.stderr
    df = read_results(out)
    assert df["sample"].tolist() == list(range(samples)) and (df["status"] == "ok").all()


def test_the_limits_table_and_messages_of_the_docs_are_the_code_s(tmp_path, monkeypatch):
    """docs/sweeps.md's [limits] rows are StudyLimits' defaults and ceilings; its example lines are the messages."""
    import re

    from auvtrack.batch import sweep_spec
    from auvtrack.batch.sweep_spec import StudyError, StudyLimits, load_study

    doc = (Path(__file__).resolve().parents[2] / "docs" / "sweeps.md").read_text()
    rows = dict((k, (int(d), int(c))) for k, d, c in re.findall(r"^\| `(max_\w+)` \| (\d+) \| (\d+) \|", doc, re.M))
    ceilings = {"max_samples": sweep_spec.MAX_SAMPLES, "max_grid_values": sweep_spec.MAX_GRID_VALUES,
                "max_chunks": sweep_spec.MAX_CHUNK_FILES}
    assert rows == {k: (f.default, ceilings[k]) for k, f in StudyLimits.model_fields.items()}
    for field in StudyLimits.model_fields.values():  # the model refuses what the ceiling says
        assert [m.le for m in field.metadata if hasattr(m, "le")][0] in ceilings.values()
    monkeypatch.chdir(tmp_path)
    text = STUDY.replace("{seed}", "3")
    for old, new in [("samples = 8", "samples = 90000000"), ("[random.", GRID + "[random.")]:
        Path("big.toml").write_text(text.replace(old, new, 1))
        with pytest.raises(StudyError) as info:
            load_study("big.toml")
        assert f"auvtrack: error: {info.value}\n" in doc


def test_the_executor_runs_a_sweep_locally_with_the_rows_of_dask(tmp_path, reference):
    from auvtrack.batch.executor import execute_chunks
    from auvtrack.batch.sweep import SweepJob
    from auvtrack.batch.sweep_spec import load_study

    res = execute_chunks(SweepJob(load_study(study(tmp_path))), tmp_path / "local", progress=False)
    assert res.complete and res.chunks_run == 4
    pd.testing.assert_frame_equal(read_results(tmp_path / "local"), reference)
