"""``auvtrack.tuning``: the objective is the benchmark's score, splits stay off the evaluation seeds, resume."""
from __future__ import annotations

import math

import pytest

from auvtrack.benchmark.execute import run_chunk
from auvtrack.benchmark.leaderboard import derive_metrics
from auvtrack.benchmark.suite import available_suites, load_suite
from auvtrack.tuning import tune
from auvtrack.tuning import study as study_mod
from auvtrack.tuning.objective import candidate_table, evaluate, split_specs
from tiny_suite import TINY

from tuning_suite import SPLITS


@pytest.fixture(scope="module")
def suite_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("suite") / "tiny.toml"
    path.write_text(TINY + SPLITS)
    return path


def _trials(folder):
    import optuna

    s = optuna.load_study(study_name=study_mod.STUDY_NAME, storage=f"sqlite:///{folder / study_mod.STUDY_FILE}")
    return [(t.state.name, t.params, t.value) for t in s.get_trials()
            if t.state.name in ("COMPLETE", "PRUNED")]


def test_trial_value_is_the_benchmark_score_of_its_runs(suite_path, tmp_path):
    res = tune("pid", suite_path, trials=2, out=tmp_path / "t", seed=3, validate=True)
    assert res.trials == 2 and res.runs > 0 and res.steps > 0
    state, params, value = next(t for t in _trials(tmp_path / "t") if t[0] == "COMPLETE")
    st = load_suite(suite_path)
    specs = split_specs(st, candidate_table({"kind": "pid"}, params), "training")
    assert {(s.task, s.index) for s in specs} == {("line", 10), ("line", 11)} and len(specs) == 4
    df = derive_metrics(run_chunk(specs).to_pandas(), settle=st.file.metrics.settle)
    scores = [st.run_score(r, r["task"]) for r in df.to_dict("records")]
    assert value == pytest.approx(math.fsum(scores) / len(scores), rel=0, abs=0)
    assert math.isfinite(res.validation_score)


def test_the_first_candidate_holds_the_untuned_gains(suite_path, tmp_path):
    # trial 0 is the bare table's controller: its gains and, through designed_base, every other field
    res = tune("pid", suite_path, trials=1, out=tmp_path / "d0", validate=False)
    (state, params, value), = _trials(tmp_path / "d0")
    st = load_suite(suite_path)
    assert value == evaluate(st, split_specs(st, {"kind": "pid"}, "training")).score  # the gains flown untuned
    assert res.best_params == params


def test_tuning_refuses_the_evaluation_split(suite_path):
    with pytest.raises(ValueError, match="never flies the evaluation seeds"):
        split_specs(load_suite(suite_path), {"kind": "pid"}, "evaluation")


@pytest.mark.parametrize("name", available_suites())
def test_training_validation_and_evaluation_seeds_are_disjoint_in_every_shipped_suite(name):
    st = load_suite(name, check=False)
    sets = {s: set(st.split_seeds(s)) for s in ("training", "validation", "evaluation")}
    assert sets["training"] and sets["validation"]
    assert not sets["training"] & sets["validation"]
    assert not (sets["training"] | sets["validation"]) & set(range(st.file.seeds))


def test_a_resumed_tuning_reaches_the_trials_of_an_uninterrupted_one(suite_path, tmp_path, monkeypatch):
    tune("pid", suite_path, trials=4, out=tmp_path / "a", seed=7, validate=False)
    real, calls = study_mod.constraint_violations, []

    def killed_in_the_third_trial(*args, **kw):  # the trial is asked (stored as running), then the stop
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*args, **kw)

    monkeypatch.setattr(study_mod, "constraint_violations", killed_in_the_third_trial)
    with pytest.raises(KeyboardInterrupt):
        tune("pid", suite_path, trials=4, out=tmp_path / "b", seed=7, validate=False)
    monkeypatch.setattr(study_mod, "constraint_violations", real)
    assert len(_trials(tmp_path / "b")) == 2
    tune("pid", suite_path, trials=4, out=tmp_path / "b", seed=7, validate=False)
    full = _trials(tmp_path / "a")
    assert len(full) == 4 and _trials(tmp_path / "b") == full
    resumed = tune("pid", suite_path, trials=4, out=tmp_path / "b", seed=7, validate=False)  # nothing left to do
    again = tune("pid", suite_path, trials=4, out=tmp_path / "a", seed=7, validate=False)
    assert resumed.runs == 0 and resumed.study_cost["runs"] == again.study_cost["runs"] > 0


def test_a_candidate_breaking_a_setup_condition_is_a_failed_trial(suite_path, tmp_path):
    import optuna

    folder = tmp_path / "c"
    folder.mkdir()
    s = optuna.create_study(study_name=study_mod.STUDY_NAME, storage=f"sqlite:///{folder / study_mod.STUDY_FILE}")
    s.enqueue_trial({"kp": 0.1, "ki": 20.0, "kd": 0.1, "kaw": 1.0})  # ki >= kd kp: Routh-Hurwitz broken
    res = tune("pid", suite_path, trials=1, out=folder, validate=False)
    t = optuna.load_study(study_name=study_mod.STUDY_NAME,
                          storage=f"sqlite:///{folder / study_mod.STUDY_FILE}").get_trials()[0]
    assert res.refused == 1 and res.complete == 0 and res.runs == 0
    assert t.value == load_suite(suite_path).file.run_score.cap + 2.0
    assert any("controller.ki" in p for p in t.user_attrs["constraint"])


def test_a_failing_candidate_stops_after_the_first_batch_with_a_failure(suite_path):
    from auvtrack.tuning.objective import evaluate

    st = load_suite(suite_path)
    bad = split_specs(st, {"kind": "pid", "kp": 0.1, "kd": 0.1, "ki": 20.0}, "training")  # set-up refused
    ev = evaluate(st, bad, chunk=2, stop_on_failure=True)
    assert ev.stopped_early and ev.runs == 2 and ev.failed == 2 and len(bad) == 4
    assert ev.score == st.file.run_score.cap + 2.0  # the benchmark's score of a refused set-up
    assert evaluate(st, bad, chunk=2).runs == 4  # without pruning every run is flown


def test_cmaes_sampler_runs_and_stays_in_the_space(suite_path, tmp_path):
    from auvtrack.control import CONTROLLERS
    from auvtrack.tuning import search_space

    tune("ftsmc", suite_path, trials=2, out=tmp_path / "cma", sampler="cmaes", seed=1, validate=False)
    space = search_space(CONTROLLERS["ftsmc"].params)
    for _, params, _ in _trials(tmp_path / "cma"):
        assert set(params) == set(space) and all(space[k].contains(v) for k, v in params.items())


def test_a_running_trial_of_a_live_process_is_not_taken_back(tmp_path):
    import os
    import socket

    import optuna

    folder = tmp_path / "live"
    folder.mkdir()
    url = f"sqlite:///{folder / study_mod.STUDY_FILE}"
    s = optuna.create_study(study_name=study_mod.STUDY_NAME, storage=url)
    live = s.ask({"x": optuna.distributions.FloatDistribution(0, 1)})
    live.set_user_attr("owner", f"{socket.gethostname()}:{os.getpid()}")
    dead = s.ask({"x": optuna.distributions.FloatDistribution(0, 1)})
    dead.set_user_attr("owner", f"{socket.gethostname()}:{2**22 + 12345}")  # above pid_max: no such process
    study_mod._requeue_interrupted(s)
    states = {t.number: t.state.name for t in s.get_trials()}
    assert states[live.number] == "RUNNING" and states[dead.number] == "FAIL"
    waiting = [t for t in s.get_trials() if t.state.name == "WAITING"]
    assert len(waiting) == 1 and s.ask({"x": optuna.distributions.FloatDistribution(0, 1)}).params == dead.params  # asked again with the same gains


def test_a_resumed_tuning_reports_the_whole_studys_cost(suite_path, tmp_path):
    import tomllib

    first = tune("pid", suite_path, trials=2, out=tmp_path / "c", validate=False)
    again = tune("pid", suite_path, trials=2, out=tmp_path / "c", validate=False)  # nothing left to fly
    assert again.runs == 0 and first.runs > 0 and again.study_cost["runs"] == first.study_cost["runs"] == first.runs
    prov = tomllib.loads(again.outputs["preset"].read_text())["provenance"]
    assert prov["study_runs"] == first.runs and prov["study_rk4_steps"] == first.steps
    assert prov["wall_s"] >= round(first.wall_s, 3) and prov["cpu_s"] > 0
    assert (prov["suite"], prov["suite_version"]) == ("tiny", 1)  # name and version, not one "tiny v1" label
