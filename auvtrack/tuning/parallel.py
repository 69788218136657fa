"""Trials flown at once: local processes or Dask tasks adding trials to one SQLite study.

Every worker runs :func:`auvtrack.tuning.study.add_trials` on the same study (``study.db``):
Optuna's storage serialises the asks and tells, TPE's constant liar keeps the workers off each
other's running candidates, and a trial asked once the budget is taken is told ``FAIL`` (surplus)
and not flown, so the study holds exactly the trials asked for.  What is reproducible: each
trial's value is a function of its gains (the runs are seeded by the suite), and the number of
finished trials is exact.  What is not: with more than one worker the gains tried depend on
the order in which the workers finish (one worker reproduces the sequence of trials).

Local workers are processes started with ``spawn`` (the compiled kernels come from the on-disk
cache); a stop (Ctrl-C, SIGTERM) terminates them, and their interrupted trials are asked again
when the tuning is resumed.  On Dask, each task is one worker; the workers must reach the
output folder's file system (SQLite does not work over a network file system's locks).
"""
from __future__ import annotations

from typing import Any, Callable

from .study import TrialJob, add_trials, finished_trials, load_study

__all__ = ["run_workers", "POLL_S"]

POLL_S = 2.0
"""Seconds between two looks at the study while local workers add trials (the progress line)."""


def _local(job: TrialJob, parallel: int, progress: Callable[[int, int], None] | None) -> list[dict]:
    import multiprocessing as mp

    pool = mp.get_context("spawn").Pool(parallel)
    try:
        pending = [pool.apply_async(add_trials, (job, k)) for k in range(parallel)]
        done = -1
        while waiting := [p for p in pending if not p.ready()]:
            waiting[0].wait(POLL_S)
            now = len(finished_trials(load_study(job.study, job.sampler, job.seed)))
            if progress is not None and now != done:
                progress(now, job.trials)
                done = now
        costs = [p.get() for p in pending]
        pool.close()
    except BaseException:
        pool.terminate()  # a stop: the workers' running trials are taken back on resume
        raise
    finally:
        pool.join()
    return costs


def _dask(job: TrialJob, parallel: int | None, scheduler: str | None, client: Any) -> list[dict]:
    own = None
    if client is None:
        from ..batch.scheduler import connect_scheduler

        client = own = connect_scheduler(scheduler)
    try:
        n = parallel or max(sum(client.nthreads().values()), 1)
        futures = [client.submit(add_trials, job, k, pure=False, key=f"tune-worker-{k}") for k in range(n)]
        return client.gather(futures)
    finally:
        if own is not None:
            own.close()


def run_workers(job: TrialJob, *, parallel: int = 1, scheduler: str | None = None, client: Any = None,
                progress: Callable[[int, int], None] | None = None) -> list[dict]:
    """Add trials to ``job``'s study with several local processes or on Dask until it holds ``job.trials``.

    Parameters
    ----------
    job : TrialJob
        The tuning.
    parallel : int, optional
        Local processes; on Dask, tasks (1 there: one per thread of the cluster).
    scheduler : str, optional
        Address of a Dask scheduler (probed with a bounded timeout).
    client : distributed.Client, optional
        An existing Dask client (overrides ``scheduler``; left open).
    progress : callable, optional
        ``progress(done, total)`` as the study's finished trials grow (local workers).

    Returns
    -------
    list of dict
        Each worker's ``runs``, ``steps`` and ``cpu_s``.

    Raises
    ------
    auvtrack.batch.scheduler.SchedulerError
        ``--scheduler`` does not answer (one line).
    """
    if client is not None or scheduler:
        return _dask(job, None if parallel == 1 else parallel, scheduler, client)
    return _local(job, parallel, progress)
