"""``auvtrack sweep``: completeness, resume, worker death, chunking invariance and bad study files.

One 2-worker LocalCluster (processes) serves the module; every sweep is a few hundred samples
of 0.2 s each, so the whole module takes seconds once the kernels are cached.
"""
from __future__ import annotations

import os
import signal
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pytest
from distributed.diagnostics.plugin import WorkerPlugin

from auvtrack.cli import main
from auvtrack.scenario import load_scenario
from auvtrack.simulation.pipeline import prepare, run_prepared
from auvtrack.metrics import METRIC_NAMES
from auvtrack.batch.sweep import chunk_path, read_results, run_sweep
from auvtrack.batch.sweep_spec import StudyError, load_study
from auvtrack.batch.sweep_worker import run_chunk


STUDY = """
name = "t"
scenario = "paper"
set = ["sim.duration=0.2", "estimator.neurons=3"]
seed = 11
samples = 60
chunk_size = {chunk}

[grid]
"controller.kind" = ["ftsmc", "fxtntsmc"]
"uncertainty.C" = [0.0, 0.2]

[random."uncertainty.D"]
dist = "uniform"
low = 0.0
high = 0.4

[random."uncertainty.M"]   # about 4 % of the draws fall below -0.9: invalid samples
dist = "normal"
mean = 0.0
std = 0.5

[random."disturbance.0.amplitude"]
dist = "loguniform"
low = 0.5
high = 2.0
"""
N = 2 * 2 * 60


def write_study(folder: Path, chunk: int = 16, text: str = STUDY, name: str = "study.toml") -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text).replace("{chunk}", str(chunk)))
    return path


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    from auvtrack.simulation.compiling import warmup

    warmup(("ftsmc", "fxtntsmc"), ("5dof",))  # the study's kernels, compiled here once: the workers only load them
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                      memory_limit="800MiB") as cluster, Client(cluster) as c:
        yield c


@pytest.fixture(scope="module")
def reference(tmp_path_factory, client):
    """The full sweep, run once without interruption."""
    folder = tmp_path_factory.mktemp("ref")
    outcome = run_sweep(write_study(folder), folder / "out", client=client, progress=False)
    assert outcome.complete
    return outcome, read_results(folder / "out")


def assert_tables_equal(a: pd.DataFrame, b: pd.DataFrame) -> None:
    assert list(a.columns) == list(b.columns)
    pd.testing.assert_frame_equal(a.reset_index(drop=True), b.reset_index(drop=True), check_exact=True)


def test_sweep_runs_every_sample_exactly_once(reference):
    outcome, df = reference
    assert len(df) == N
    assert df["sample"].tolist() == list(range(N))
    assert outcome.chunks_run == -(-N // 16) and outcome.chunks_skipped == 0
    counts = df["status"].value_counts().to_dict()
    assert counts.get("ok", 0) > N // 2 and counts.get("invalid", 0) > 0, counts
    assert set(counts) <= {"ok", "failed", "invalid"}
    bad = df[df["status"] == "invalid"]
    assert (bad["uncertainty.M"] < -0.9).all() and bad["detail"].str.contains("uncertainty.M").all()
    assert df["seed"].nunique() == N  # one seed per sample
    summary = outcome.summary
    assert summary["samples"] == N and sum(summary["counts"].values()) == N
    assert summary["metrics"]["rmse_x"]["n_finite"] == counts["ok"]
    for name in ("summary.json", "summary.md", "results.parquet", "study.json"):
        assert (outcome.out / name).is_file()


def test_sweep_rows_equal_single_runs(reference):
    """A row's metrics are bit-identical to simulating that sample on its own."""
    _, df = reference
    spec = load_study(outcome_path(reference))
    for i in (0, 61, 130, 239):
        row = df.iloc[i]
        seed, ov = spec.overrides(i)
        assert row["seed"] == seed
        res = run_prepared(prepare(load_scenario(spec.base, ov)))
        assert row["status"] == res.status
        np.testing.assert_array_equal(row[list(METRIC_NAMES)].to_numpy(float),
                                      np.array([res.metrics[m] for m in METRIC_NAMES]))


def outcome_path(reference) -> Path:
    return reference[0].out.parent / "study.toml"


def test_interrupted_sweep_resumes_to_identical_table(tmp_path, client, reference):
    study = write_study(tmp_path)
    out = tmp_path / "out"
    first = run_sweep(study, out, client=client, progress=False, max_chunks=4)
    assert not first.complete and first.chunks_run == 4
    assert not (out / "results.parquet").exists()
    assert len(list((out / "chunks").glob("chunk-*.parquet"))) == 4
    with pytest.raises(StudyError, match="--resume"):
        run_sweep(study, out, client=client, progress=False)
    second = run_sweep(study, out, client=client, progress=False, resume=True)
    assert second.complete and second.chunks_skipped == 4 and second.chunks_run == -(-N // 16) - 4
    assert_tables_equal(read_results(out), reference[1])


def test_worker_killed_mid_sweep_gives_identical_table(tmp_path, client, reference):
    pids_before = client.run(os.getpid)
    killed = []

    def kill_one(written: int, c) -> None:
        if not killed:  # after the first chunk: both workers hold queued or running chunks
            addr, pid = sorted(pids_before.items())[0]
            os.kill(pid, signal.SIGKILL)
            killed.append(addr)

    study = write_study(tmp_path, chunk=24)  # other chunking: same rows expected
    outcome = run_sweep(study, tmp_path / "out", client=client, progress=False, on_chunk=kill_one)
    assert killed and outcome.complete
    client.wait_for_workers(2, timeout=60)
    assert set(client.run(os.getpid).values()) != set(pids_before.values())  # a worker was replaced
    assert_tables_equal(read_results(tmp_path / "out"), reference[1])


def test_identical_seeds_bit_identical_across_chunk_sizes(tmp_path):
    """In-process: chunks of 7 and of 50 give the same rows (no Dask involved)."""
    text = STUDY.replace("samples = 60", "samples = 10")
    a = load_study(write_study(tmp_path, chunk=7, text=text, name="a.toml"))
    b = load_study(write_study(tmp_path, chunk=50, text=text, name="b.toml"))
    ta = pa.concat_tables([run_chunk(a, c) for c in range(a.n_chunks)]).to_pandas()
    tb = pa.concat_tables([run_chunk(b, c) for c in reversed(range(b.n_chunks))]).to_pandas().sort_values("sample")
    assert a.n_chunks == 6 and b.n_chunks == 1 and len(ta) == 40
    assert_tables_equal(ta, tb)
    assert a.sample_seed(3) == b.sample_seed(3) and a.sample_seed(3) != a.sample_seed(4)


def test_common_seeds_pair_samples_across_grid_points(tmp_path):
    text = STUDY.replace("samples = 60", "samples = 5\ncommon_seeds = true")
    spec = load_study(write_study(tmp_path, text=text))
    assert spec.sample_seed(2) == spec.sample_seed(7) == spec.sample_seed(12)
    assert spec.sample(2)[2]["uncertainty.D"] == spec.sample(7)[2]["uncertainty.D"]
    assert spec.sample(2)[2]["controller.kind"] == "ftsmc" and spec.sample(12)[2]["controller.kind"] == "fxtntsmc"


def test_cli_sweep_on_existing_scheduler(tmp_path, client, capsys):
    text = STUDY.replace("samples = 60", "samples = 5")
    study = write_study(tmp_path, text=text)
    code = main(["sweep", str(study), "--out", str(tmp_path / "o"), "--scheduler", client.scheduler.address,
                 "--quiet"])
    assert code == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert out.startswith("sweep t: 20 samples, ") and "written: " in out, out
    assert not [ln for ln in out.splitlines() if ln.lstrip().startswith(("#", "|"))], out  # no Markdown
    assert chunk_path(tmp_path / "o", 1).is_file() and len(read_results(tmp_path / "o")) == 20


BAD = [
    ("samples = 60", "samples = 0", "samples: must be >= 1 (got 0)"),
    ("high = 0.4", "high = -1.0", "random.uncertainty.D"),
    ('"uncertainty.C" = [0.0, 0.2]', '"uncertainty.C" = [0.0, 5.0]', "grid.uncertainty.C.1: the scenario rejects it"),
    ('dist = "normal"', 'dist = "cauchy"', "random.uncertainty.M.dist: unknown dist (allowed: 'uniform', 'normal'"),
    ('scenario = "paper"', 'scenario = "paper"\nworkers = 3', "workers: unknown key"),
    ('"uncertainty.C" = [0.0, 0.2]', '"uncertainty.C" = []', "grid.uncertainty.C: must have at least 1 item (got 0)"),
    # a value `auvtrack run` would refuse (the run plan's limits, the controller's set-up) refuses the study
    ('"uncertainty.C" = [0.0, 0.2]', '"uncertainty.C" = [0.0, 0.2]\n"sim.duration" = [1e9]',
     "grid.sim.duration.0: the scenario rejects it: sim.duration: "),
    # the name becomes the folder sweeps/<name>: the rule of scenario names
    ('name = "t"', 'name = "../../x"', "name: must be 1 to 100 characters"),
    ('name = "t"', 'name = "/tmp/abs"', "name: must be 1 to 100 characters"),
    ('name = "t"', 'name = ".."', "name: must be 1 to 100 characters"),
    ('name = "t"', 'name = "a\\u0000b"', "name: must be 1 to 100 characters"),
    ('scenario = "paper"', 'scenario = "missing.toml"', "scenario: must be a packaged scenario's name or a readable"),
    ('set = ["sim.duration=0.2", "estimator.neurons=3"]', 'set = ["sim.dt=-1"]', "sim.dt"),
    ('"controller.kind"', '"controller..kind"', "not a dotted scenario key"),
]


@pytest.mark.parametrize("old,new,expect", BAD)
def test_invalid_study_file_one_line_exit_2(tmp_path, capsys, old, new, expect):
    assert old in STUDY
    study = write_study(tmp_path, text=STUDY.replace(old, new))
    code = main(["sweep", str(study), "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("auvtrack: error: ") and "Traceback" not in err, err
    assert expect in err, err
    assert not (tmp_path / "o").exists()


def test_bad_cli_options_exit_2(tmp_path, capsys):
    study = write_study(tmp_path)
    (tmp_path / "afile").write_text("x")
    assert main(["sweep", str(study), "--workers", "0"]) == 2
    assert main(["sweep", str(study), "--workers", "1", "--scheduler", "tcp://x:1"]) == 2
    assert main(["sweep", str(tmp_path / "nope.toml")]) == 2
    assert main(["sweep", str(study), "--worker-memory", "lots"]) == 2
    assert main(["sweep", str(study), "--worker-memory", "1MB"]) == 2
    assert main(["sweep", str(study), "--out", str(tmp_path / "afile")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 6 and all(line.startswith("auvtrack: error: ") for line in err), err
    assert "--worker-memory" in err[3] and "--out" in err[5] and "is a file" in err[5]


MEMORY_STUDY = """
name = "mem-hog"
scenario = "paper"
set = ["sim.duration=0.2", "estimator.neurons=3", "disturbance.1.kind=current"]
samples = 1
chunk_size = 4

[grid]                            # sample 1: 5e6 current samples (~640 MB of tables)
"disturbance.1.sample_dt" = [0.01, 4e-8, 0.005, 0.02]
"""
HOG = 2  # the sample whose worker runs out of memory (see MemoryHog)


class MemoryHog(WorkerPlugin):
    """Worker plugin of the test: sample HOG of study "mem-hog" allocates more than the worker's
    memory limit while it runs, as a sample whose real use exceeds its estimate would, so that
    Dask's nanny kills the worker (also every restarted one: plugins run on each)."""

    name = "test-memory-hog"

    def setup(self, worker):
        import time

        import numpy as np

        from auvtrack.batch import sweep_worker

        limit = worker.memory_manager.memory_limit
        original = sweep_worker.run_samples

        def run_samples(spec, indices):
            if spec.study.name == "mem-hog" and HOG in indices:
                hog = np.ones(int(1.2 * limit) // 8)  # written, so resident
                time.sleep(60)
                del hog
            return original(spec, indices)

        sweep_worker.run_samples = run_samples


def test_sweep_survives_samples_over_the_memory_limit(tmp_path):
    """One sample refused up front by its memory estimate, one that kills its worker anyway:
    both recorded as failed with their cause, every other sample computed, the sweep complete."""
    from auvtrack.batch.sweep import _client

    study = write_study(tmp_path, text=MEMORY_STUDY)
    client, cluster = _client(1, None, "1GiB")  # the CLI's own cluster settings
    try:
        client.register_plugin(MemoryHog())
        outcome = run_sweep(study, tmp_path / "out", client=client, progress=False)
    finally:
        client.close()
        cluster.close()
    assert outcome.complete
    df = read_results(tmp_path / "out")
    assert df["sample"].tolist() == [0, 1, 2, 3]
    assert df["status"].tolist() == ["ok", "failed", "failed", "ok"]
    assert df["cause"].tolist()[1:3] == ["memory", "worker_died"]
    assert "MiB" in df["detail"][1] and "--worker-memory" in df["detail"][1]
    assert "worker process died" in df["detail"][2]
    assert outcome.summary["causes"] == {"memory": 1, "worker_died": 1}
    # the computed rows are those of the samples run on their own
    spec = load_study(study)
    for i in (0, 3):
        res = run_prepared(prepare(load_scenario(spec.base, spec.overrides(i)[1])))
        np.testing.assert_array_equal(df.loc[i, list(METRIC_NAMES)].to_numpy(float),
                                      np.array([res.metrics[m] for m in METRIC_NAMES]))


def test_a_local_sweep_compiles_its_kernels_in_the_client_with_a_progress_bar(tmp_path, monkeypatch):
    """The workers of a local cluster only load kernels from the disk cache when the client compiled
    them first, with its "compiling kernels" notice and (with progress) a bar; nothing is compiled
    here for a scheduler the caller gives (its workers may be other machines)."""
    from auvtrack.batch import sweep as sweep_module
    from auvtrack.simulation import compiling

    calls = []

    class Stop(Exception):
        pass

    def fake_warmup(*args, **kw):
        calls.append(kw)
        raise Stop

    monkeypatch.setattr(compiling, "warmup", fake_warmup)
    monkeypatch.setattr(sweep_module, "_client", lambda *a, **k: (_ for _ in ()).throw(AssertionError("cluster first")))
    example = Path(__file__).resolve().parents[2] / "scenarios" / "sweep_example.toml"
    with pytest.raises(Stop):
        sweep_module.run_sweep(example, tmp_path / "out", workers=1, progress=True)
    assert calls == [{"progress": True, "notice": None}]  # the notice on standard error, and a bar
    with pytest.raises(Stop):  # --quiet: no bar, and the notice goes nowhere
        sweep_module.run_sweep(example, tmp_path / "out-quiet", workers=1, progress=False)
    quiet = calls.pop()
    assert quiet["progress"] is False and callable(quiet["notice"]) and quiet["notice"]("compiling kernels") is None
    monkeypatch.setattr(sweep_module, "execute_chunks", lambda *a, **k: (_ for _ in ()).throw(Stop()))
    with pytest.raises(Stop):
        sweep_module.run_sweep(example, tmp_path / "out2", scheduler="tcp://127.0.0.1:1", progress=True)
    assert len(calls) == 1
