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

import contextlib
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping

from .objective import candidate_table, evaluate, split_conditions, split_specs
from .space import Dimension, constraint_violations, distributions, field_values, search_space, searched_fields

__all__ = ["SAMPLERS", "STUDY_NAME", "TrialJob", "TuneResult", "add_trials", "controller_base", "designed_base",
           "trial_seed", "tune", "warm_trials"]

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
        The suite's name and the split tuned on.
    suite_version : int
        The suite file's ``version``.
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
    table : dict
        The best candidate's whole ``[controller]`` table: its gains and every unsearched field
        (:func:`designed_base`); empty if none completed.
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
        the processes that added to it; trials recorded before this accounting existed excluded),
        and ``elapsed_s``: the wall time of every ``tune`` call on the study, summed (a resumed
        tuning's cost is the whole study's, not the last call's).
    validation_runs : list of dict
        The best gains' validation runs: task, tier, seed index, status, cause, t_stop, score.
    outputs : dict
        Paths written: ``preset``, ``results``, ``report``.
    """

    controller: dict
    suite: str
    split: str
    suite_version: int = 0
    trials: int = 0
    complete: int = 0
    pruned: int = 0
    refused: int = 0
    runs: int = 0
    steps: int = 0
    cpu_s: float = 0.0
    wall_s: float = 0.0
    best_params: dict = field(default_factory=dict)
    table: dict = field(default_factory=dict)
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


SQLITE_TIMEOUT_S = 120.0
"""Seconds a process waits for another's write lock on ``study.db`` before giving up."""


def _storage(url: str):
    import optuna

    return optuna.storages.RDBStorage(url, engine_kwargs={"connect_args": {"timeout": SQLITE_TIMEOUT_S}})


def _log_level() -> None:
    """Optuna's log at warnings and above (a quieter level set by ``--quiet`` is kept)."""
    import optuna

    optuna.logging.set_verbosity(max(optuna.logging.get_verbosity(), optuna.logging.WARNING))


@contextlib.contextmanager
def silenced() -> Iterator[None]:
    """Optuna's log messages and warnings silenced (``tune --quiet``); both are restored on exit.

    Yields
    ------
    None
        With Optuna's log at errors only and warnings ignored.
    """
    import warnings

    import optuna

    level = optuna.logging.get_verbosity()
    optuna.logging.set_verbosity(optuna.logging.ERROR)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            yield
    finally:
        optuna.logging.set_verbosity(level)


def _open_study(out: Path, sampler: str, seed: int):
    import optuna

    _log_level()
    url = f"sqlite:///{(out / STUDY_FILE).resolve()}"
    study = optuna.create_study(study_name=STUDY_NAME, storage=_storage(url), direction="minimize",
                                load_if_exists=True, sampler=_sampler(sampler, seed))
    return study, url


def load_study(url: str, sampler: str, seed: int):
    """The tuning's Optuna study at ``url`` with a fresh sampler (a lock wait of :data:`SQLITE_TIMEOUT_S`).

    Parameters
    ----------
    url : str
        SQLite storage URL.
    sampler : str
        ``tpe`` or ``cmaes``.
    seed : int
        The sampler's seed.

    Returns
    -------
    optuna.Study
        The study.
    """
    import optuna

    _log_level()
    return optuna.load_study(study_name=STUDY_NAME, storage=_storage(url), sampler=_sampler(sampler, seed))


@contextlib.contextmanager
def asking(url: str) -> Iterator[None]:
    """Hold the study's ask lock (``study.db.lock``, an exclusive ``flock``) while trials are asked.

    Python's SQLite driver reads outside its write transactions, so two workers asking at once
    could both take the same waiting (enqueued) trial; asks, the budget check and the hand-back
    of interrupted trials go one at a time instead.  Without ``fcntl`` (not POSIX) nothing is locked.

    Parameters
    ----------
    url : str
        The study's ``sqlite:///`` URL.

    Yields
    ------
    None
        With the lock held.
    """
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    with open(url.removeprefix("sqlite:///") + ".lock", "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


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
        _give_back(study, t)


def _give_back(study, trial) -> None:
    """Fail an interrupted trial and ask its gains again first (nothing lost, nothing counted twice)."""
    from optuna.trial import TrialState

    if study._storage.get_trial(trial._trial_id).state != TrialState.RUNNING:
        return  # already told
    study._storage.set_trial_state_values(trial._trial_id, TrialState.FAIL)
    study.enqueue_trial(trial.params, user_attrs={"requeued_from": trial.number}, skip_if_exists=False)


def finished_trials(study) -> list:
    """The study's finished trials (complete, pruned, refused), the ones the budget counts.

    Parameters
    ----------
    study : optuna.Study
        The study.

    Returns
    -------
    list of optuna.trial.FrozenTrial
        Complete and pruned trials (a refused candidate is a complete trial with violations).
    """
    from optuna.trial import TrialState

    return study.get_trials(deepcopy=False, states=(TrialState.COMPLETE, TrialState.PRUNED))


@dataclass(frozen=True)
class TrialJob:
    """What a process or a Dask worker needs to add trials to a tuning's study (picklable).

    Attributes
    ----------
    base : dict
        The ``[controller]`` table the candidates are built on (:func:`designed_base`).
    suite : str
        Suite name or absolute file path.
    split : str
        The split flown.
    trials : int
        Finished trials the study is to hold.
    study : str
        The Optuna storage URL (SQLite file of the output folder).
    sampler : str
        ``tpe`` or ``cmaes``.
    seed : int
        Sampler seed.
    workers : int or None
        Threads of the batch runner inside a trial.
    backend : str or None
        Back end of the batch runner.
    chunk : int or None
        Runs per batch inside a trial (default one (task, tier) cell).
    quiet : bool
        Optuna's log and warnings silenced in the worker (:func:`silenced`).
    """

    base: dict
    suite: str
    split: str
    trials: int
    study: str
    sampler: str
    seed: int
    workers: int | None = 1
    backend: str | None = None
    chunk: int | None = None
    quiet: bool = False


def designed_base(spec, base: Mapping[str, Any], space: Mapping[str, Dimension]) -> dict:
    """The ``[controller]`` table every candidate is built on: each unsearched field at its designed value.

    The bare table ``base`` resolves, for the run ``spec``, to the controller the suite flies
    untuned (designed for the vehicle when it has a reach, :mod:`auvtrack.scenario.designed`:
    e.g. ``saturation = "compensated"``).  Every field of it that the search does not set
    (numeric or not) is copied into the table, so a candidate differs from that controller in
    the searched gains only, and a preset of the table reproduces the tuned controller.

    Parameters
    ----------
    spec : RunSpec
        A run of the split with the bare ``[controller]`` table (the split's first: designed
        values depend on the run's vehicle speed, so the candidates take one run's).
    base : mapping
        The bare table (``kind``, and ``module`` for a plug-in).
    space : mapping of str to Dimension
        The search space (its fields are left out).

    Returns
    -------
    dict
        ``base`` with every unsearched field (a plug-in's under ``params``).
    """
    from ..scenario import load_scenario

    searched = searched_fields(space)
    section = load_scenario(spec.raw, spec.overrides).to_dict()["controller"]
    if section.get("kind") == "plugin":
        params = {k: v for k, v in (section.get("params") or {}).items() if k not in searched}
        return {**dict(base), "params": params}
    return {**dict(base), **{k: v for k, v in section.items() if k not in searched}}


def untuned_gains(spec, space: Mapping[str, Dimension]) -> dict[str, float]:
    """The tunable gains a bare ``[controller]`` table resolves to for the run's vehicle, in the space.

    With :func:`designed_base`'s other fields, a candidate holding them is the controller the
    bare table flies on ``spec`` (up to the clipping to the space).

    Parameters
    ----------
    spec : RunSpec
        A run of the split with the bare ``[controller]`` table.
    space : mapping of str to Dimension
        The search space (a value outside it is clipped to its range).

    Returns
    -------
    dict of str to float
        One value per dimension: a vector field's item, or the mean of its items when shared.
    """
    from ..scenario import load_scenario

    section = load_scenario(spec.raw, spec.overrides).controller
    values = getattr(section, "params", None) if getattr(section, "kind", "") == "plugin" else None
    get = (lambda k: values[k]) if isinstance(values, Mapping) else (lambda k: getattr(section, k))
    out = {}
    for k, d in space.items():
        try:
            v = get(d.target)
            v = float(v) if d.size == 0 else (float(v[d.item]) if d.item is not None else math.fsum(v) / len(v))
        except (AttributeError, KeyError, TypeError, IndexError):
            v = d.default
        out[k] = min(max(v, d.low), d.high)
    return out


def trial_seed(seed: int, worker: int, finished: int) -> int:
    """The sampler seed of the next trial a worker asks.

    Worker 0 uses ``seed + finished`` (with one worker the sequence of trials is a function of
    the seed and the history); another worker draws its seed from ``SeedSequence([seed, worker,
    finished])``, so two workers never sample from the same stream.

    Parameters
    ----------
    seed : int
        The tuning's sampler seed.
    worker : int
        Index of the process or Dask task adding trials (0 for a single process).
    finished : int
        Trials finished in the study when the trial is asked.

    Returns
    -------
    int
        A seed in [0, 2**32).
    """
    if worker == 0:
        return seed + finished
    import numpy as np

    return int(np.random.SeedSequence([seed, worker, finished]).generate_state(1)[0])


def _running(study) -> list:
    from optuna.trial import TrialState

    return study.get_trials(deepcopy=False, states=(TrialState.RUNNING,))


def _fly(study, trial, job: TrialJob, st, cost: dict, space: Mapping[str, Dimension], conditions: list,
         plants: dict) -> None:
    """Fly one asked trial on the split (or refuse it on a set-up condition) and tell the study.

    ``conditions`` are the split's (:func:`~auvtrack.tuning.objective.split_conditions`) and
    ``plants`` its plant set-ups (:func:`auvtrack.simulation.pipeline.prepare`), made once per
    worker: only the controller differs between trials.
    """
    import optuna

    from ..scenario import load_scenario

    w0, c0 = time.perf_counter(), time.process_time()
    table = candidate_table(job.base, field_values(space, trial.params))
    specs = split_specs(st, table, job.split, conditions=conditions)
    problems = constraint_violations(load_scenario(specs[0].raw, specs[0].overrides))
    if problems:
        # scored as the benchmark scores a refused set-up: every run failed at t = 0
        trial.set_user_attr("violations", len(problems))
        trial.set_user_attr("constraint", problems)
        if job.sampler == "tpe":  # CMA-ES has no constraint handling: it sees the failure score only
            trial.set_constraint("setup", float(len(problems)))
        trial.set_user_attr("wall_s", time.perf_counter() - w0)
        trial.set_user_attr("cpu_s", time.process_time() - c0)
        study.tell(trial, st.file.run_score.cap + 2.0)
    else:
        trial.set_user_attr("violations", 0)
        if job.sampler == "tpe":
            trial.set_constraint("setup", 0.0)

        def report(ev, trial=trial):
            trial.report(ev.score, ev.runs)

        per_cell = max(len(st.split_seeds(job.split)), 1)
        ev = evaluate(st, specs, chunk=job.chunk or per_cell, stop_on_failure=True, workers=job.workers,
                      backend=job.backend, on_chunk=report, plant_cache=plants)
        cost["runs"] += ev.runs
        cost["steps"] += ev.steps
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


def add_trials(job: TrialJob, worker: int = 0, progress=None, *, suite=None) -> dict:
    """Ask, fly and tell trials until the study holds ``job.trials`` finished ones (counting those running).

    Several processes or Dask tasks may call this on one study at once (each with its own
    ``worker`` index): a trial asked when the trials finished or running before it already reach
    the budget is told ``FAIL`` with the user attribute ``surplus`` and not flown, so the study
    ends with exactly ``job.trials`` finished trials.

    Parameters
    ----------
    job : TrialJob
        The tuning.
    worker : int, optional
        This worker's index (its sampler seeds, :func:`trial_seed`).
    progress : callable, optional
        ``progress(done, total)`` after each trial.
    suite : auvtrack.benchmark.suite.Suite, optional
        ``job.suite`` already loaded (by :func:`tune`, in this process).  Default: read again
        without the feasibility check (:func:`auvtrack.benchmark.suite.load_suite`'s ``check``),
        which :func:`tune` made before any worker started.

    Returns
    -------
    dict
        ``runs``, ``steps`` and ``cpu_s`` this worker spent.
    """
    if job.quiet:
        with silenced():
            return _add_trials(job, worker, progress, suite)
    return _add_trials(job, worker, progress, suite)


def _add_trials(job: TrialJob, worker: int, progress, suite) -> dict:
    from optuna.trial import TrialState

    from ..benchmark.suite import load_suite

    # the feasibility check of every cell takes tens of seconds and tune made it already
    st = suite if suite is not None else load_suite(job.suite, check=False)
    study = load_study(job.study, job.sampler, job.seed)
    space = search_space(_params_model(job.base))
    dists = distributions(space)
    cost = {"runs": 0, "steps": 0, "cpu_s": 0.0}
    conditions, plants = split_conditions(st, job.split), {}
    while len(finished_trials(study)) + len(_running(study)) < job.trials:
        with asking(job.study):
            study.sampler = _sampler(job.sampler, trial_seed(job.seed, worker, len(finished_trials(study))))
            trial = study.ask(dists)
            trial.set_user_attr("owner", _owner())
            ahead = [t for t in study.get_trials(deepcopy=False, states=(TrialState.COMPLETE, TrialState.PRUNED,
                                                                        TrialState.RUNNING)) if t.number < trial.number]
            if len(ahead) >= job.trials:  # another worker asked the last trial of the budget first
                trial.set_user_attr("surplus", True)
                study.tell(trial, state=TrialState.FAIL)
                break
        c0 = time.process_time()
        try:
            _fly(study, trial, job, st, cost, space, conditions, plants)
        except BaseException:  # a stop: the trial's gains are asked again when the tuning resumes
            with asking(job.study):
                _give_back(study, trial)
            raise
        cost["cpu_s"] += time.process_time() - c0
        if progress is not None:
            progress(len(finished_trials(study)), job.trials)
    return cost


def warm_trials(st, base: Mapping[str, Any], space: Mapping[str, Dimension], first, splits: list[str],
                validation: bool, *, workers: int | None = 1, backend: str | None = None,
                notify: Callable[[str], None] | None = None, bar: bool = False) -> float:
    """Compile or load the kernels a tuning's trials fly, before the first trial.

    The untuned candidate's runs of the splits (one per tier and plant preset) go through
    :func:`auvtrack.benchmark.execute.warm_runs`: the other candidates differ in their gains only,
    so they fly the same kernels.

    Parameters
    ----------
    st : auvtrack.benchmark.suite.Suite
        The suite.
    base : mapping
        The candidates' ``[controller]`` table without the gains (:func:`designed_base`).
    space : mapping of str to Dimension
        The search space.
    first : RunSpec
        A run of the split with the bare table (:func:`untuned_gains`).
    splits : list of str
        The splits the trials fly in this process (empty when they fly on Dask).
    validation : bool
        Also the validation split's runs (the best gains are flown there at the end).
    workers : int or None, optional
        Threads of the batch runner.
    backend : str, optional
        Back end of the batch runner.
    notify : callable, optional
        Receives the "compiling kernels" notice (default: standard error).
    bar : bool, optional
        A progress bar over the kernels compiled.

    Returns
    -------
    float
        Wall seconds of the warm-up.
    """
    from ..benchmark.execute import warm_runs

    table = candidate_table(base, field_values(space, untuned_gains(first, space)))
    specs = [s for name in [*splits, *(["validation"] if validation else [])] for s in split_specs(st, table, name)]
    return warm_runs(specs, workers, backend, progress=bar, notice=notify)


def tune(controller: str, suite: str | Path = "auv-track-v1", *, trials: int, out: str | Path,
         sampler: str = "tpe", seed: int = 0, split: str = "training", validate: bool = True,
         workers: int | None = 1, backend: str | None = None, chunk: int | None = None,
         parallel: int = 1, scheduler: str | None = None, client: Any = None, progress=None,
         notify: Callable[[str], None] | None = None, compile_bar: bool = False, quiet: bool = False) -> TuneResult:
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
        Back end of the batch runner (default: :func:`auvtrack.batch.runner.preferred_backend`,
        the ``simd`` lanes where the vector math library is in use, whose runs are bit-identical
        to the thread back end's; else threads).
    chunk : int, optional
        Runs per batch inside a trial (a failing candidate is pruned after the first batch
        holding a failure; default: one (task, tier) cell).
    parallel : int, optional
        Trials flown at once: local processes adding trials to the study (1: this process);
        on Dask, the number of tasks (default there: the cluster's threads).
    scheduler : str, optional
        Address of a Dask scheduler whose workers add the trials (they must reach ``out``).
    client : distributed.Client, optional
        An existing Dask client (overrides ``scheduler``; left open).
    progress : callable, optional
        ``progress(done, total)`` after each trial (in this process only).
    notify : callable, optional
        Receives the one-line notices: "compiling kernels (first run only, about N s)" when a kernel
        the trials need is not cached, and why the parameter importances are not computed (default:
        standard error).
    compile_bar : bool, optional
        A progress bar over the kernels compiled before the first trial.
    quiet : bool, optional
        Print nothing: no notice, no bar, Optuna's log and warnings silenced (:func:`silenced`, in
        the local worker processes too).

    Returns
    -------
    TuneResult
        Best gains, scores and cost.

    Raises
    ------
    ValueError
        One line: bad controller, sampler, split, trials or parallel; a controller declaring no
        tunable gain; a scheduler that does not answer.
    """
    if not quiet:
        return _tune(controller, suite, trials, out, sampler, seed, split, validate, workers, backend, chunk,
                     parallel, scheduler, client, progress, notify, compile_bar, False)
    with silenced():
        return _tune(controller, suite, trials, out, sampler, seed, split, validate, workers, backend, chunk,
                     parallel, scheduler, client, progress, lambda text: None, False, True)


def _tune(controller, suite, trials, out, sampler, seed, split, validate, workers, backend, chunk, parallel,
          scheduler, client, progress, notify, compile_bar, quiet) -> TuneResult:
    from ..benchmark.suite import load_suite
    from .parallel import run_workers

    if isinstance(trials, bool) or not isinstance(trials, int) or trials < 1:
        raise ValueError(f"--budget: must be a number of trials >= 1 (got {trials!r})")
    if isinstance(parallel, bool) or not isinstance(parallel, int) or not 1 <= parallel <= 256:
        raise ValueError(f"--parallel: must be an integer in [1, 256] (got {parallel!r})")
    base = controller_base(controller)
    space = search_space(_params_model(base))
    if not space:
        raise ValueError(f"controller: {controller} declares no tunable gain (tunable(...) on its Params fields)")
    _sampler(sampler, seed)  # refuses an unknown sampler before anything is stored
    if backend is None:  # the lanes: same runs, same bits, several runs per core at once
        from ..batch.runner import preferred_backend

        backend = preferred_backend()
    if scheduler and client is None:
        from ..batch.scheduler import probe_scheduler

        probe_scheduler(scheduler)  # one line, before anything is stored
    st = load_suite(suite)
    probe = split_specs(st, base, split)  # refuses the evaluation split before anything is stored
    fixed = designed_base(probe[0], base, space)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    study, url = _open_study(out, sampler, seed)
    study.set_user_attr("controller", base)
    study.set_user_attr("suite", st.name)
    study.set_user_attr("suite_version", st.file.version)
    with asking(url):
        _requeue_interrupted(study)
        if not study.get_trials(deepcopy=False):  # the first candidate: the untuned (designed) gains
            study.enqueue_trial(untuned_gains(probe[0], space), user_attrs={"first_candidate": "untuned"})
    suite_ref = str(Path(suite).resolve()) if Path(str(suite)).suffix == ".toml" else str(suite)
    job = TrialJob(fixed, suite_ref, split, trials, url, sampler, seed, workers, backend, chunk, quiet)
    res = TuneResult(controller=base, suite=st.name, suite_version=st.file.version, split=split, study=url)
    local = scheduler is None and client is None  # the trials fly on this machine
    validating = validate and st.file.splits.validation is not None
    if local or validating:  # compile here, before the first trial (the local workers load the cached kernels)
        warm_trials(st, fixed, space, probe[0], [split] if local else [], validating, workers=workers,
                    backend=backend, notify=notify, bar=compile_bar)
    t_wall, t_cpu = time.perf_counter(), time.process_time()
    if parallel == 1 and scheduler is None and client is None:
        costs = [add_trials(job, 0, progress, suite=st)]
    else:
        costs = run_workers(job, parallel=parallel, scheduler=scheduler, client=client, progress=progress)
    res.runs = sum(c["runs"] for c in costs)
    res.steps = sum(c["steps"] for c in costs)
    res.wall_s = time.perf_counter() - t_wall
    res.cpu_s = time.process_time() - t_cpu if len(costs) == 1 and parallel == 1 else sum(c["cpu_s"] for c in costs)
    final = load_study(url, sampler, seed)
    final.set_user_attr("elapsed_s", float(final.user_attrs.get("elapsed_s", 0.0)) + res.wall_s)
    _summarise(final, res)
    if res.best_params:
        res.table = candidate_table(fixed, field_values(space, res.best_params))
    if validate and res.best_params and st.file.splits.validation is not None:
        ev = evaluate(st, split_specs(st, res.table, "validation"),
                      workers=workers, backend=backend)
        res.validation_score = ev.score
        res.validation_runs = [{**{k: r[k] for k in ("task", "tier", "seed_index", "status", "cause", "t_stop")},
                                "score": sc} for r, sc in zip(ev.rows, ev.scores)]
    res.runs_per_trial = len(probe)
    from .outputs import write_outputs

    vehicle = str(st.file.base.get("vehicle.preset", "paper"))
    res.outputs = write_outputs(res, out, vehicle=vehicle, suite_name=st.name, sampler=sampler, seed=seed,
                                runs_per_trial=len(probe), notify=notify)
    return res


def _summarise(study, res: TuneResult) -> None:
    from optuna.trial import TrialState

    done = finished_trials(study)
    res.trials = len(done)
    res.complete = sum(t.state == TrialState.COMPLETE and not t.user_attrs.get("violations") for t in done)
    res.refused = sum(bool(t.user_attrs.get("violations")) for t in done)
    res.pruned = sum(t.state == TrialState.PRUNED for t in done)
    res.study_cost = {k: sum(t.user_attrs.get(k, 0) for t in done) for k in ("runs", "steps", "cpu_s", "wall_s")
                      if k in ("runs", "steps") or any(k in t.user_attrs for t in done)}
    res.study_cost["elapsed_s"] = float(study.user_attrs.get("elapsed_s", res.wall_s))
    ok = [t for t in done if t.state == TrialState.COMPLETE and not t.user_attrs.get("violations")]
    if ok:
        best = min(ok, key=lambda t: (t.value, t.number))
        res.best_params, res.best_score = dict(best.params), float(best.value)
