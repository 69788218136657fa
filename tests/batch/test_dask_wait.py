"""Bounded waits on Dask: a cluster without workers ends a wait with a diagnostic, never a hang."""
import time

import pytest

from auvtrack.batch.dask_wait import ClusterLost, completed, result


@pytest.fixture
def workerless():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=0, processes=False, dashboard_address=":0") as cluster, Client(cluster) as client:
        yield client


def _inc(x):
    return x + 1


def test_result_without_workers_gives_up_after_the_grace_period(workerless):
    fut = workerless.submit(_inc, 1)
    t0 = time.monotonic()
    with pytest.raises(ClusterLost, match="no worker for 1 s while adding one"):
        result(fut, workerless, what="adding one", grace=1.0)
    assert time.monotonic() - t0 < 30


def test_completed_without_workers_gives_up(workerless):
    futs = [workerless.submit(_inc, i) for i in range(3)]
    with pytest.raises(ClusterLost):
        list(completed(futs, workerless, what="adding", grace=1.0))


def test_completed_yields_each_future_once_with_workers():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        futs = [client.submit(_inc, i) for i in range(20)]
        done = list(completed(futs, client, what="adding", grace=1.0))
        assert sorted(f.key for f in done) == sorted(f.key for f in futs)
        assert sorted(f.result() for f in done) == list(range(1, 21))
        assert result(client.submit(_inc, 41), client, what="adding") == 42


def test_a_sweep_on_a_cluster_without_workers_stops_with_a_diagnostic(tmp_path, monkeypatch):
    from distributed import Client, LocalCluster

    from auvtrack.batch import dask_wait
    from auvtrack.batch.sweep import run_sweep
    from auvtrack.batch.sweep_spec import StudyError

    monkeypatch.setattr(dask_wait, "WORKER_GRACE_S", 1.0)
    study = tmp_path / "study.toml"
    study.write_text('name = "lost"\nscenario = "paper"\nset = ["sim.duration=0.2"]\nchunk_size = 1\n\n'
                     '[grid]\n"controller.kind" = ["ftsmc", "fxtntsmc"]\n')
    with LocalCluster(n_workers=0, processes=False, dashboard_address=":0") as cluster, Client(cluster) as client:
        with pytest.raises(StudyError, match="no worker .*--resume"):
            run_sweep(study, tmp_path / "out", client=client, progress=False)
