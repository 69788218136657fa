"""``auvtrack compare``: every controller over a suite's tasks x tiers x seeds, analysed and reported.

:func:`compare` loads the suite (:mod:`auvtrack.benchmark.suite`), resolves the competitors (every
registered tracking controller with its tuned gain preset, or its defaults when it has none, and
any plug-in files), runs every run (:mod:`auvtrack.benchmark.execute`: local batch runner or Dask,
resumable), derives the per-run metrics and the statistics (:mod:`auvtrack.benchmark.leaderboard`,
:mod:`auvtrack.benchmark.statistics`), re-runs one representative seed per cell with its trajectory,
and writes the report (:mod:`auvtrack.benchmark.report`): ``report.md``, ``report.html``,
``results.json``, ``runs.parquet`` and ``figures/``.  Definitions and the scoring rule:
``docs/benchmark.md``.
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .._atomic import atomic_file
from . import execute as runner
from . import leaderboard as lb
from .across_tasks import aggregate_analysis
from .suite import (DEFAULT_SUITE, ControllerEntry, Suite, check_competitor, load_suite,
                    resolve_controllers)

__all__ = ["compare", "CompareOutcome", "analyse", "representative_seeds", "default_out"]


@dataclass(frozen=True)
class CompareOutcome:
    """What :func:`compare` did.

    Attributes
    ----------
    out : Path
        Output folder.
    complete : bool
        Every run is done and the report written.
    report : Path or None
        ``report.md`` when complete.
    execution : auvtrack.benchmark.execute.ExecOutcome
        Runs, chunks and timing of the execution.
    analysis_seconds : float
        Wall time of the statistics, representative runs and report.
    """

    out: Path
    complete: bool
    report: Path | None
    execution: runner.ExecOutcome
    analysis_seconds: float


def _load_average() -> list[float] | None:
    """The 1, 5 and 15 minute load averages (None where the OS has none): the machine's load, for the timing."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def _default_backend() -> str:
    import inspect

    from ..batch.runner import run_batch

    return str(inspect.signature(run_batch).parameters["backend"].default)


def default_out(suite: Suite) -> Path:
    """``compare/<suite>`` (``compare/<suite>-quick`` for the quick variant)."""
    return Path("compare") / (suite.name + ("-quick" if suite.quick else ""))


def analyse(df, suite: Suite) -> dict[str, Any]:
    """Every statistic of the report from the runs table (pure: same runs, same numbers).

    Parameters
    ----------
    df : pandas.DataFrame
        Runs with the derived metrics (:func:`auvtrack.benchmark.leaderboard.derive_metrics`).
    suite : Suite
        The suite (seed, confidence, bootstrap size, weights).

    Returns
    -------
    dict
        ``cells``, ``pooled_tier``, ``pooled``, ``scores`` (``cells`` keyed ``"tier/task"``),
        ``weights``, ``criteria`` and ``metrics`` (the weighted criteria, without ``failure``),
        ``rank_intervals``, ``paired`` and ``aggregates`` (across tasks:
        :func:`~auvtrack.benchmark.across_tasks.aggregate_analysis`).
    """
    f = suite.file
    metrics = f.scoring.metrics()
    cells = lb.cell_statistics(df, seed=f.seed, confidence=f.confidence, n_resamples=suite.bootstrap_resamples,
                               metrics=metrics)
    weights = f.scoring.weights()
    scores = lb.score_table(lb.criteria_table(cells, metrics), weights)
    ranks = lb.rank_bootstrap(df, weights, seed=f.seed, n_resamples=max(50, suite.bootstrap_resamples // 10),
                              confidence=f.confidence)
    return {
        "cells": cells,
        "pooled_tier": lb.pooled_failures(df, ("tier", "controller"), f.confidence),
        "pooled": lb.pooled_failures(df, ("controller",), f.confidence),
        "scores": {"cells": {f"{k[0]}/{k[1]}": v for k, v in scores["cells"].items()},
                   "tiers": scores["tiers"], "overall": scores["overall"], "order": scores["order"]},
        "weights": weights,
        "criteria": list(f.scoring.criteria()),
        "metrics": list(metrics),
        "rank_intervals": ranks,
        "paired": lb.paired_comparisons(df, criteria=("failure", *metrics)),
        "aggregates": aggregate_analysis(df, suite, list(dict.fromkeys(df["controller"]))),
    }


def representative_seeds(df, metric: str = "rmse") -> dict[tuple[str, str], int]:
    """The typical seed index of each (tier, task): the median, over seeds, of the controllers' median error.

    For each seed index the median of ``metric`` over the controllers is taken (failures ``inf``); the
    representative seed is the one at the lower median of these values (ties: the smallest
    index), so every controller is shown on the same, typical conditions.

    Parameters
    ----------
    df : pandas.DataFrame
        Runs with the derived metrics.
    metric : str, optional
        The error (the suite's primary metric, :meth:`~auvtrack.benchmark.suite.Scoring.primary`).

    Returns
    -------
    dict
        ``{(tier, task): seed index}``.
    """
    out = {}
    for (tier, task), g in df.groupby(["tier", "task"], sort=False):
        per = g.groupby("seed_index")[metric].median().sort_index()
        order = np.lexsort((per.index.to_numpy(), per.to_numpy()))
        out[(tier, task)] = int(per.index[order[(len(order) - 1) // 2]])
    return out


def _representative_runs(suite: Suite, entries: Sequence[ControllerEntry], seeds: dict, workers: int | None):
    """{(tier, task): {controller: Result}} of the representative seeds, with trajectories."""
    from ..batch.runner import run_batch

    specs, keys = [], []
    by_label = {e.label: e for e in entries}
    for (tier, task), i in seeds.items():
        for label, e in by_label.items():
            raw, ov, drawn = suite.scenario(e, task, tier, i)
            spec = runner.RunSpec(-1, label, task, tier, i, raw, ov, drawn)
            prep = runner._prepare(spec)
            if not isinstance(prep, str):
                specs.append(prep)
                keys.append((tier, task, label))
    results = run_batch(specs, trajectories=True, workers=workers) if specs else []
    out: dict[tuple[str, str], dict[str, Any]] = {}
    for (tier, task, label), res in zip(keys, results):
        out.setdefault((tier, task), {})[label] = res
    return out


def compare(suite: str | Path | Suite = DEFAULT_SUITE, *, controllers: Sequence[str] | None = None,
            plugins: Sequence[str | Path] | None = None, quick: bool = False, out: str | Path | None = None,
            scheduler: str | None = None, client: Any = None, workers: int | None = None,
            backend: str | None = None, resume: bool = False,
            progress: bool = True, max_chunks: int | None = None, chunk_size: int = 48,
            entries: Sequence[ControllerEntry] | None = None, max_runs: int = runner.DEFAULT_MAX_RUNS,
            notify: Any = None, tuned_dir: str | Path | None = None) -> CompareOutcome:
    """Run a benchmark comparison and write its report.

    Parameters
    ----------
    suite : str, Path or Suite
        A shipped suite's name, a suite file, or a loaded suite.
    controllers : sequence of str, optional
        Built-in kinds to compare (None: every registered tracking controller; an empty list is
        refused, and so is a kind that does not track a reference).
    plugins : sequence of path, optional
        Plug-in controller files; each enters under its file name.
    quick : bool, optional
        The suite's quick variant (few seeds, short runs; every controller, task and tier).
    out : str or Path, optional
        Output folder (default :func:`default_out`).
    scheduler : str, optional
        Dask scheduler address; without it the local batch runner is used.
    client : distributed.Client, optional
        An existing Dask client (tests).
    workers : int, optional
        Local threads.
    backend : str, optional
        Back end of the batch runner (:data:`auvtrack.batch.runner.BACKENDS`); default its default.
    resume : bool, optional
        Finish an interrupted comparison in ``out``.
    progress : bool, optional
        Progress bar.
    max_chunks : int, optional
        Stop after this many chunks (tests of the resume path).
    chunk_size : int, optional
        Runs per chunk.
    entries : sequence of ControllerEntry, optional
        Explicit competitors (overrides ``controllers`` and ``plugins``; tests); each must track a
        reference (:func:`~auvtrack.benchmark.suite.check_competitor`).
    max_runs : int, optional
        Refuse a plan of more runs (``--max-runs``), before anything is planned.
    notify : callable, optional
        Receives the one-line notices of the execution (chunks that failed verification).
    tuned_dir : str or Path, optional
        Where ``compare --tune`` tuned the plug-ins (``<out>-tune``): the report's tuning table reads
        their tuning there.

    Returns
    -------
    CompareOutcome
        The folder, whether it is complete (``report`` is then ``report.md``) and the timing.
    """
    from .report import write_report

    s = suite if isinstance(suite, Suite) else load_suite(suite)
    if quick and not s.quick:
        s = s.quick_variant()
    if entries is not None:
        ents = list(entries)
        for e in ents:
            check_competitor(e)
    else:
        ents = resolve_controllers(None if controllers is None else list(controllers), list(plugins or []),
                                   s.file.gain_preset)
    folder = Path(out) if out is not None else default_out(s)
    load0 = _load_average()
    ex = runner.execute(s, ents, folder, resume=resume, scheduler=scheduler, client=client, workers=workers,
                        backend=backend, chunk_size=chunk_size, max_chunks=max_chunks, max_runs=max_runs,
                        progress=progress, notify=notify)
    load1 = _load_average()
    if not ex.complete:
        return CompareOutcome(folder, False, None, ex, 0.0)
    t0 = time.perf_counter()
    df = lb.derive_metrics(runner.read_runs(folder), s.file.metrics.settle, s.file.scoring.criteria())
    with atomic_file(folder / runner.RUNS_FILE) as fh:  # the runs with the benchmark's metrics
        df.to_parquet(fh, index=False)
    analysis = analyse(df, s)
    seeds = representative_seeds(df, s.file.scoring.primary())
    reps = _representative_runs(s, ents, seeds, workers)
    timing = {"runs_seconds": ex.seconds, "compile_seconds": ex.compile_seconds, "chunks_run": ex.chunks_run,
              "chunks_resumed": ex.chunks_skipped, "runs": ex.runs, "backend": "dask" if (scheduler or client)
              else "local threads", "workers": workers, "batch_backend": backend or _default_backend(), "cpu_count": os.cpu_count(),
              "load_average_start": load0, "load_average_end": load1}
    report = write_report(folder, s, ents, df, analysis, seeds, reps, timing, t0,
                          None if tuned_dir is None else Path(tuned_dir))
    return CompareOutcome(folder, True, report, ex, time.perf_counter() - t0)
