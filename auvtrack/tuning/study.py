"""``auvtrack tune``: an Optuna study of one controller's gains on a suite's training split.

The study lives in SQLite in the output folder (``study.db``), so a tuning stopped by Ctrl-C or
SIGTERM resumes where it stopped: a trial the stop interrupted is asked again with the same gains
(nothing lost, nothing counted twice).  The sampler (TPE by default, CMA-ES as an option) is seeded
per trial from the fixed sampler seed and the number of trials already finished, so the sequence of
trials depends on the seed and the history only: a resumed tuning reaches the same trials as an
uninterrupted one with one worker.  A candidate breaking a set-up condition
(:func:`auvtrack.tuning.space.constraint_violations`) is a failed trial scored like the benchmark
scores a refused set-up (every run failed at t = 0); a candidate whose runs fail is pruned after the
first batch holding a failure.  The objective is :mod:`auvtrack.tuning.objective`'s.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from .objective import candidate_table, evaluate, split_specs
from .space import constraint_violations, distributions, search_space

__all__ = ["SAMPLERS", "STUDY_NAME", "TuneResult", "tune", "controller_base"]

SAMPLERS = ("tpe", "cmaes")
STUDY_NAME = "tune"
STUDY_FILE = "study.db"


@dataclass
class TuneResult:
    """What a tuning found and what it cost.

    Attributes
    ----------
    controller : dict
        The base ``[controller]`` table tuned.
    suite, split : str
        The suite's name and version, and the split tuned on.
    trials : int
        Trials finished (complete, pruned, or refused by a constraint).
    complete, pruned, refused : int
        Their breakdown.
    runs, steps : int
        Runs flown and RK4 steps integrated by this process (the resumed part only on a resume).
    cpu_s, wall_s : float
        CPU and wall time of this process's trials.
    best_params : dict
        Gains of the best complete trial (empty if none completed).
    best_score : float
        Its training score (mean benchmark run score; NaN if none completed).
    validation_score : float
        The best gains' score on the validation split (NaN when it was not flown).
    study : str
        The Optuna storage URL.
    runs_per_trial : int
        Runs of the split one trial flies (the budget is trials x runs_per_trial).
    study_cost : dict
        Runs, RK4 steps, CPU and wall seconds summed over every finished trial of the study (all
        the processes that added to it; trials recorded before this accounting existed excluded).
    validation_runs : list of dict
        The best gains' validation runs: task, tier, seed index, status, cause, t_stop, score.
    outputs : dict
        Paths written: ``preset``, ``results``, ``report``.
    """

    controller: dict
    suite: str
    split: str
    trials: int = 0
    complete: int = 0
    pruned: int = 0
    refused: int = 0
    runs: int = 0
    steps: int = 0
    cpu_s: float = 0.0
    wall_s: float = 0.0
    best_params: dict = field(default_factory=dict)
    best_score: float = math.nan
    validation_score: float = math.nan
    study: str = ""
    runs_per_trial: int = 0
    study_cost: dict = field(default_factory=dict)
    validation_runs: list = field(default_factory=list)
    outputs: dict = field(default_factory=dict)


def controller_base(controller: str) -> dict:
    """The ``[controller]`` table of a built-in kind or a plug-in ``.py`` file.

    Parameters
    ----------
    controller : str
        A registered tracking controller's kind, or a path to a plug-in file.

    Returns
    -------
    dict
        ``{"kind": kind}`` or ``{"kind": "plugin", "module": <absolute path>}``.

    Raises
    ------
    ValueError
        ``controller: ...`` an unknown kind, a controller that does not track, or a missing file.
    """
    from ..control import CONTROLLERS

    if controller.endswith(".py"):
        p = Path(controller).expanduser().resolve()
        if not p.is_file():
            raise ValueError(f"controller: no such plug-in file {controller!r}")
        return {"kind": "plugin", "module": str(p)}
    spec = CONTROLLERS.get(controller)
    if spec is None or not spec.tracks or controller == "plugin":
        allowed = ", ".join(k for k, s in CONTROLLERS.items() if s.tracks and k != "plugin")
        raise ValueError(f"controller: must be one of {allowed} or a plug-in .py file (got {controller!r})")
    return {"kind": controller}


def _params_model(base: Mapping[str, Any]):
    from ..control import CONTROLLERS
    from ..control.plugin import load

    if base["kind"] == "plugin":
        return load(base["module"])[1].params
    return CONTROLLERS[base["kind"]].params


def _sampler(name: str, seed: int):
    import optuna

    if name == "tpe":  # reads the trials' constraint values (Trial.set_constraint)
        return optuna.samplers.TPESampler(seed=seed)
    if name == "cmaes":
        return optuna.samplers.CmaEsSampler(seed=seed, warn_independent_sampling=False)
    raise ValueError(f"--sampler: must be one of {', '.join(SAMPLERS)} (got {name!r})")


def _open_study(out: Path, sampler: str, seed: int):
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    url = f"sqlite:///{(out / STUDY_FILE).resolve()}"
    study = optuna.create_study(study_name=STUDY_NAME, storage=url, direction="minimize", load_if_exists=True,
                                sampler=_sampler(sampler, seed))
    return study, url


def _owner() -> str:
    import os
    import socket

    return f"{socket.gethostname()}:{os.getpid()}"


def _alive(owner: str) -> bool:
    """Whether the process ``host:pid`` that asked a trial still runs (another host's: assumed alive)."""
    import os
    import socket

    host, _, pid = owner.rpartition(":")
    if host != socket.gethostname() or not pid.isdigit():
        return bool(owner)
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _requeue_interrupted(study) -> None:
    """Trials a stopped process left running: failed, and their gains asked again first.

    Only trials whose process has ended are taken back: another process adding trials to the
    same study keeps its running ones (nothing lost, nothing counted twice).
    """
    from optuna.trial import TrialState

    for t in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        if _alive(str(t.user_attrs.get("owner", ""))):
            continue
        study._storage.set_trial_state_values(t._trial_id, TrialState.FAIL)
        study.enqueue_trial(t.params, user_attrs={"requeued_from": t.number}, skip_if_exists=False)


def _finished(study) -> list:
    from optuna.trial import TrialState

    return study.get_trials(deepcopy=False, states=(TrialState.COMPLETE, TrialState.PRUNED))


def tune(controller: str, suite: str | Path = "auv-track-v1", *, trials: int, out: str | Path,
         sampler: str = "tpe", seed: int = 0, split: str = "training", validate: bool = True,
         workers: int | None = 1, backend: str | None = None, chunk: int | None = None,
         progress=None) -> TuneResult:
    """Tune one controller's declared gains on a suite's split; resumes the study found in ``out``.

    Parameters
    ----------
    controller : str
        A built-in tracking kind or a plug-in ``.py`` file.
    suite : str or Path, optional
        Suite name or file (its ``[splits.training]`` and ``[splits.validation]``).
    trials : int
        Trials to reach in the study (the budget is trials x training runs).
    out : str or Path
        Output folder (``study.db`` is the study).
    sampler : {"tpe", "cmaes"}, optional
        Optuna sampler.
    seed : int, optional
        Sampler seed.
    split : str, optional
        The split tuned on (``training``; never the evaluation seeds).
    validate : bool, optional
        Fly the best gains on the validation split when it is declared.
    workers : int or None, optional
        Threads of the batch runner within a trial.
    backend : str, optional
        Back end of the batch runner.
    chunk : int, optional
        Runs per batch inside a trial (a failing candidate is pruned after the first batch
        holding a failure; default: one (task, tier) cell).
    progress : callable, optional
        ``progress(done, total)`` after each trial.

    Returns
    -------
    TuneResult
        Best gains, scores and cost.

    Raises
    ------
    ValueError
        One line: bad controller, sampler, split or trials; a controller declaring no tunable gain.
    """
    import optuna

    from ..benchmark.suite import load_suite

    if isinstance(trials, bool) or not isinstance(trials, int) or trials < 1:
        raise ValueError(f"--budget: must be a number of trials >= 1 (got {trials!r})")
    base = controller_base(controller)
    space = search_space(_params_model(base))
    if not space:
        raise ValueError(f"controller: {controller} declares no tunable gain (tunable(...) on its Params fields)")
    st = load_suite(suite)
    probe = split_specs(st, base, split)  # refuses the evaluation split before anything is stored
    per_cell = max(len(st.split_seeds(split)), 1)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    study, url = _open_study(out, sampler, seed)
    study.set_user_attr("controller", base)
    study.set_user_attr("suite", f"{st.name} v{st.file.version}")
    _requeue_interrupted(study)
    dists = distributions(space)
    cap = st.file.run_score.cap
    res = TuneResult(controller=base, suite=f"{st.name} v{st.file.version}", split=split, study=url)
    t_wall, t_cpu = time.perf_counter(), time.process_time()
    while len(_finished(study)) < trials:
        study.sampler = _sampler(sampler, seed + len(_finished(study)))
        trial = study.ask(dists)
        trial.set_user_attr("owner", _owner())
        w0, c0 = time.perf_counter(), time.process_time()
        gains = dict(trial.params)
        table = candidate_table(base, gains)
        specs = split_specs(st, table, split)
        from ..scenario import load_scenario

        problems = constraint_violations(load_scenario(specs[0].raw, specs[0].overrides))
        if problems:
            # scored as the benchmark scores a refused set-up: every run failed at t = 0
            trial.set_user_attr("violations", len(problems))
            trial.set_user_attr("constraint", problems)
            if sampler == "tpe":  # CMA-ES has no constraint handling: it sees the failure score only
                trial.set_constraint("setup", float(len(problems)))
            study.tell(trial, cap + 2.0)
        else:
            trial.set_user_attr("violations", 0)
            if sampler == "tpe":
                trial.set_constraint("setup", 0.0)

            def report(ev, trial=trial):
                trial.report(ev.score, ev.runs)

            ev = evaluate(st, specs, chunk=chunk or per_cell, stop_on_failure=True, workers=workers,
                          backend=backend, on_chunk=report)
            res.runs += ev.runs
            res.steps += ev.steps
            trial.set_user_attr("runs", ev.runs)
            trial.set_user_attr("steps", ev.steps)
            trial.set_user_attr("failed_runs", ev.failed)
            first = next((r for r in ev.rows if r["status"] != "ok"), None)
            if first is not None:  # why the candidate failed: the mechanism, for the report
                trial.set_user_attr("first_failure", {k: first[k] for k in ("task", "tier", "seed_index", "cause",
                                                                             "detail", "t_stop")})
            trial.set_user_attr("wall_s", time.perf_counter() - w0)
            trial.set_user_attr("cpu_s", time.process_time() - c0)
            if ev.stopped_early:
                study.tell(trial, state=optuna.trial.TrialState.PRUNED)
            else:
                study.tell(trial, ev.score)
        if progress is not None:
            progress(len(_finished(study)), trials)
    res.wall_s, res.cpu_s = time.perf_counter() - t_wall, time.process_time() - t_cpu
    _summarise(study, res)
    if validate and res.best_params and st.file.splits.validation is not None:
        ev = evaluate(st, split_specs(st, candidate_table(base, res.best_params), "validation"),
                      workers=workers, backend=backend)
        res.validation_score = ev.score
        res.validation_runs = [{**{k: r[k] for k in ("task", "tier", "seed_index", "status", "cause", "t_stop")},
                                "score": sc} for r, sc in zip(ev.rows, ev.scores)]
    res.runs_per_trial = len(probe)
    from .outputs import write_outputs

    vehicle = str(st.file.base.get("vehicle.preset", "paper"))
    res.outputs = write_outputs(res, out, vehicle=vehicle, suite_name=st.name, sampler=sampler, seed=seed,
                                runs_per_trial=len(probe))
    return res


def _summarise(study, res: TuneResult) -> None:
    from optuna.trial import TrialState

    done = _finished(study)
    res.trials = len(done)
    res.complete = sum(t.state == TrialState.COMPLETE and not t.user_attrs.get("violations") for t in done)
    res.refused = sum(bool(t.user_attrs.get("violations")) for t in done)
    res.pruned = sum(t.state == TrialState.PRUNED for t in done)
    res.study_cost = {k: sum(t.user_attrs.get(k, 0) for t in done) for k in ("runs", "steps", "cpu_s", "wall_s")
                      if k in ("runs", "steps") or any(k in t.user_attrs for t in done)}
    ok = [t for t in done if t.state == TrialState.COMPLETE and not t.user_attrs.get("violations")]
    if ok:
        best = min(ok, key=lambda t: (t.value, t.number))
        res.best_params, res.best_score = dict(best.params), float(best.value)
