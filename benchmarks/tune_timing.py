"""Cost of ``auvtrack tune``: trials per second and the share of the time spent outside the compiled kernels.

Usage::

    python benchmarks/tune_timing.py --controller pid --suite auv-track-v2 --budget 10 --repeat 3 \
        --out /tmp/tune-timing --json benchmarks/tune_timing.json

Runs ``--repeat`` tunings of ``--budget`` trials, each in a fresh output folder, after a warm-up
that compiles the kernels (:func:`auvtrack.tuning.study.warm_trials`, outside the timed part: the
acceptance is "after compilation").  With ``--parallel 1`` every phase of a trial is timed by
wrapping the functions that do it:

* ``suite``: reading (and checking) the suite in the trials' loop (:func:`auvtrack.benchmark.suite.load_suite`);
* ``plan``: the training runs' specs of a candidate (:func:`auvtrack.tuning.objective.split_specs`);
* ``constraints``: the set-up conditions of a candidate (:func:`auvtrack.tuning.space.constraint_violations`);
* ``setup``: each run's scenario validation and preparation (``auvtrack.benchmark.execute._prepare``);
* ``kernel``: the batch runner (:func:`auvtrack.batch.runner.run_batch`, which runs the compiled
  kernels; its own Python set-up is small and counted as inside);
* ``scoring``: the benchmark's run scores (:func:`auvtrack.tuning.objective.score_table`);
* ``other``: the rest (Optuna's sampler, SQLite, the rows of the runs table, bookkeeping).

With ``--parallel N > 1`` the trials fly in worker processes and only the totals are measured.
The record (printed, and written to ``--json``) holds each repeat's trials, runs, RK4 steps, wall
seconds, trials/s, runs/s, the shares, the load average before and after, and the medians over
the repeats; ``--profile FILE`` also writes a cProfile of the first repeat's trials.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

PHASES = ("suite", "plan", "constraints", "setup", "kernel", "scoring")


def _timed(module: Any, name: str, phase: str, clock: dict[str, float]) -> Callable[[], None]:
    """Wrap ``module.name`` so that its calls add their wall time to ``clock[phase]``; returns the undo."""
    real = getattr(module, name)

    def timed(*args: Any, **kw: Any) -> Any:
        t = time.perf_counter()
        try:
            return real(*args, **kw)
        finally:
            clock[phase] += time.perf_counter() - t

    setattr(module, name, timed)
    return lambda: setattr(module, name, real)


def _instrument(clock: dict[str, float]) -> list[Callable[[], None]]:
    """Timers on every phase of a trial (the names the callers look up at call time)."""
    from auvtrack.batch import runner
    from auvtrack.benchmark import execute, suite
    from auvtrack.tuning import objective, study

    undo = [_timed(runner, "run_batch", "kernel", clock), _timed(execute, "_prepare", "setup", clock),
            _timed(objective, "score_table", "scoring", clock), _timed(suite, "load_suite", "suite", clock)]
    for name, phase in (("split_specs", "plan"), ("constraint_violations", "constraints")):
        if hasattr(study, name):
            undo.append(_timed(study, name, phase, clock))
    real = study.add_trials

    def trials_only(*args: Any, **kw: Any) -> Any:  # the phases of the trials, not of tune's warm-up
        for k in clock:
            clock[k] = 0.0
        return real(*args, **kw)

    study.add_trials = trials_only
    undo.append(lambda: setattr(study, "add_trials", real))
    return undo


def _one(a: argparse.Namespace, out: Path, profile: str | None) -> dict[str, Any]:
    from auvtrack.tuning import tune

    clock = dict.fromkeys(PHASES, 0.0)
    undo = _instrument(clock) if a.parallel == 1 else []
    load0 = os.getloadavg()
    prof = None
    if profile:
        import cProfile

        prof = cProfile.Profile()
        prof.enable()
    t0 = time.perf_counter()
    try:
        res = tune(a.controller, a.suite, trials=a.budget, out=out, workers=a.workers, backend=a.backend,
                   parallel=a.parallel, chunk=a.chunk, validate=False, quiet=True)
    finally:
        if prof is not None:
            prof.disable()
            prof.dump_stats(profile)
        for u in undo:
            u()
    total = time.perf_counter() - t0
    load1 = os.getloadavg()
    wall = res.wall_s  # the trials only (after the warm-up, before the outputs)
    rec: dict[str, Any] = {"trials": res.trials, "complete": res.complete, "pruned": res.pruned,
                           "refused": res.refused, "runs": res.runs, "steps": res.steps,
                           "wall_s": round(wall, 2), "call_s": round(total, 2), "cpu_s": round(res.cpu_s, 2),
                           "trials_per_s": round(res.trials / wall, 4), "runs_per_s": round(res.runs / wall, 2),
                           "steps_per_s": round(res.steps / wall), "best_score": res.best_score,
                           "load_before": [round(x, 2) for x in load0], "load_after": [round(x, 2) for x in load1]}
    if a.parallel == 1:
        rec["phase_s"] = {k: round(v, 2) for k, v in clock.items()}  # from the first trial on
        rec["phase_s"]["other"] = round(wall - sum(clock.values()), 2)
        rec["kernel_share"] = round(clock["kernel"] / wall, 3)
        rec["outside_share"] = round(1 - clock["kernel"] / wall, 3)
    return rec


def summary(record: dict[str, Any]) -> str:
    """The sentence docs/tuning.md quotes from a record (a test checks the doc holds it).

    Parameters
    ----------
    record : dict
        A record of this script (``benchmarks/tune_timing.json``).

    Returns
    -------
    str
        Trials/s, runs/s, the shares and the load, with the budget, back end and workers.
    """
    med, reps = record["median"], record["repeats"]
    loads = [x for r in reps for x in (r["load_before"][0], r["load_after"][0])]
    cpu = statistics.median(r["cpu_s"] / r["runs"] for r in reps if r["runs"])
    return (f"{record['controller']} on {record['suite']}'s training split ({record['runs_per_trial']} runs a "
            f"trial), {record['budget']} trials x {record['repeat']}, back end {record['backend']}, "
            f"{record['workers']} workers: {med['trials_per_s']:g} trials/s, {med['runs_per_s']:g} runs/s, "
            f"{100 * med['kernel_share']:.0f} % of the trials' wall time in the batch runner's kernels and "
            f"{100 * med['outside_share']:.0f} % outside them, {1000 * cpu:.0f} ms of CPU a run, at a load average of {min(loads):.1f}-"
            f"{max(loads):.1f} on {record['cpu_count']} cores ({record['measured']})")


def main() -> None:
    """Time the tunings and print (and write) the record."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--controller", default="pid")
    ap.add_argument("--suite", default="auv-track-v2")
    ap.add_argument("--budget", type=int, default=10, help="trials of each timed tuning")
    ap.add_argument("--repeat", type=int, default=1, help="timed tunings (medians reported)")
    ap.add_argument("--out", default=None, help="folder of the studies (default: a temporary one)")
    ap.add_argument("--workers", type=int, default=None,
                    help="threads of the batch runner in a trial (default: tune's, every core)")
    ap.add_argument("--backend", default=None, help="back end of the batch runner (default: tune's, "
                    "auvtrack.batch.runner.preferred_backend)")
    ap.add_argument("--parallel", type=int, default=1, help="trials flown at once (tune --parallel)")
    ap.add_argument("--chunk", type=int, default=None, help="runs per batch inside a trial (default: tune's)")
    ap.add_argument("--profile", default=None, help="write a cProfile of the first repeat to this file")
    ap.add_argument("--json", default=None, help="also write the record to this file")
    ap.add_argument("--note", default="", help="a note stored in the record")
    a = ap.parse_args()

    from auvtrack.benchmark.suite import load_suite
    from auvtrack.tuning.objective import split_specs
    from auvtrack.tuning.study import _params_model, controller_base, designed_base, warm_trials
    from auvtrack.tuning.space import search_space

    root = Path(a.out) if a.out else Path(tempfile.mkdtemp(prefix="tune-timing-"))
    st = load_suite(a.suite)
    base = controller_base(a.controller)
    space = search_space(_params_model(base))
    probe = split_specs(st, base, "training")
    fixed = designed_base(probe[0], base, space)
    backend = a.backend
    if backend is None:  # tune's default
        from auvtrack.batch.runner import preferred_backend

        backend = preferred_backend()
    w0 = time.perf_counter()
    warm_trials(st, fixed, space, probe[0], ["training"], False, workers=a.workers, backend=backend,
                notify=lambda text: None)
    warm = time.perf_counter() - w0
    reps = []
    for k in range(a.repeat):
        reps.append(_one(a, root / f"rep{k}", a.profile if k == 0 else None))
        print(json.dumps(reps[-1]), flush=True)
    med = {key: round(statistics.median(r[key] for r in reps), 4)
           for key in ("wall_s", "cpu_s", "trials_per_s", "runs_per_s", "steps_per_s", "kernel_share", "outside_share")
           if all(key in r for r in reps)}
    if a.parallel == 1:
        med["phase_s"] = {p: round(statistics.median(r["phase_s"][p] for r in reps), 2) for p in reps[0]["phase_s"]}
    from auvtrack import __version__
    from auvtrack.batch.runner import default_workers

    record = {"measured": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="minutes"),
              "machine": f"{platform.machine()} / {platform.processor() or platform.node()} / Python "
                         f"{platform.python_version()}",
              "cpu_count": os.cpu_count(), "version": __version__, "controller": a.controller, "suite": st.name,
              "split": "training", "runs_per_trial": len(probe), "budget": a.budget, "repeat": a.repeat,
              "workers": a.workers if a.workers else (default_workers() if a.parallel == 1 else 1), "backend": backend, "parallel": a.parallel, "chunk": a.chunk,
              "warm_s": round(warm, 2), "note": a.note, "repeats": reps, "median": med}
    trials_s = med["trials_per_s"]
    record["estimate_budget_200_s"] = round(200 / trials_s, 1) if trials_s else None
    text = json.dumps(record, indent=1)
    print(text)
    print(summary(record))
    if a.json:
        Path(a.json).write_text(text + "\n")


if __name__ == "__main__":
    main()
