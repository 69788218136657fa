"""Trials flown at once (local processes, Dask tasks) on one SQLite study: exact count, reproducible values."""
from __future__ import annotations

import pytest

from auvtrack.benchmark.suite import load_suite
from auvtrack.control import CONTROLLERS
from auvtrack.tuning import search_space, tune
from auvtrack.tuning import study as study_mod
from auvtrack.tuning.objective import candidate_table, evaluate, split_specs
from tiny_suite import TINY

from tuning_suite import SPLITS


@pytest.fixture(scope="module")
def suite_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("suite") / "tiny.toml"
    path.write_text(TINY + SPLITS)
    return path


def _all_trials(folder):
    import optuna

    s = optuna.load_study(study_name=study_mod.STUDY_NAME, storage=f"sqlite:///{folder / study_mod.STUDY_FILE}")
    return s.get_trials()


def _check_study(folder, suite_path, trials):
    """The study holds exactly ``trials`` finished trials, nothing running, and each value is its gains' score."""
    every = _all_trials(folder)
    done = [t for t in every if t.state.name in ("COMPLETE", "PRUNED")]
    assert len(done) == trials
    assert not [t for t in every if t.state.name in ("RUNNING", "WAITING")]
    assert all(t.user_attrs.get("surplus") and "runs" not in t.user_attrs
               for t in every if t.state.name == "FAIL")  # surplus asks are not flown
    space = search_space(CONTROLLERS["pid"].params)
    assert len({tuple(sorted(t.params.items())) for t in done}) == trials  # no candidate flown twice
    st = load_suite(suite_path)
    for t in done:
        assert all(space[k].contains(v) for k, v in t.params.items())
        if t.state.name == "COMPLETE" and not t.user_attrs["violations"]:
            again = evaluate(st, split_specs(st, candidate_table({"kind": "pid"}, t.params), "training"))
            assert t.value == again.score  # a trial's value is a function of its gains, whoever flew it
    return done


@pytest.mark.slow
def test_two_local_processes_fill_one_study_with_exactly_the_budget(suite_path, tmp_path):
    res = tune("pid", suite_path, trials=5, out=tmp_path / "p", seed=2, validate=False, parallel=2)
    done = _check_study(tmp_path / "p", suite_path, 5)
    assert res.trials == 5 and res.runs == res.study_cost["runs"] == sum(t.user_attrs.get("runs", 0) for t in done)
    assert res.steps == res.study_cost["steps"] > 0
    owners = {t.user_attrs["owner"] for t in done}
    assert len(owners) == 2  # both processes added trials
    assert (tmp_path / "p" / "results.json").is_file()


def test_dask_workers_fill_one_study_with_exactly_the_budget(suite_path, tmp_path):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        res = tune("pid", suite_path, trials=4, out=tmp_path / "d", seed=4, validate=False, client=client)
    _check_study(tmp_path / "d", suite_path, 4)
    assert res.trials == 4 and res.runs == res.study_cost["runs"]


def test_one_worker_keeps_the_seeded_sequence_and_other_workers_get_their_own_streams():
    assert [study_mod.trial_seed(7, 0, n) for n in range(3)] == [7, 8, 9]
    seeds = {study_mod.trial_seed(7, w, n) for w in range(1, 4) for n in range(50)}
    assert len(seeds) == 150 and not seeds & set(range(7, 7 + 50))


def test_parallel_out_of_range_is_refused(suite_path, tmp_path):
    with pytest.raises(ValueError, match="--parallel"):
        tune("pid", suite_path, trials=2, out=tmp_path / "x", parallel=0)
    assert not (tmp_path / "x").exists()  # refused before anything is stored
