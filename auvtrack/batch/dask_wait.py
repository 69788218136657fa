"""Bounded waits on Dask futures: a lost cluster ends a wait with a diagnostic, never a hang.

A plain ``future.result()`` or ``as_completed(futures)`` waits for ever when every worker of the
cluster is gone and none comes back (a worker killed for its memory and not restarted, a remote
cluster shut down).  The waits here poll the futures and the scheduler: when the cluster has had
no worker for ``grace`` seconds, they raise :class:`ClusterLost`, whose message says what was
lost and how to continue.
"""
from __future__ import annotations

import time
from typing import Iterable, Iterator

__all__ = ["ClusterLost", "WORKER_GRACE_S", "completed", "result"]

WORKER_GRACE_S = 60.0
"""Seconds a cluster may have no worker (e.g. while a killed one restarts) before a wait gives up."""
POLL_S = 0.5


class ClusterLost(RuntimeError):
    """The Dask cluster had no worker for longer than the grace period (or its scheduler is gone)."""


def _workers(client) -> int:
    """Workers the scheduler knows of now (0 when the scheduler does not answer)."""
    try:
        return len(client.nthreads())
    except Exception:  # noqa: BLE001 - a scheduler that does not answer has no worker for us
        return 0


class _Watch:
    """Tracks how long the cluster has been without a worker."""

    def __init__(self, client, grace: float):
        self.client, self.grace, self.since = client, grace, None

    def check(self, what: str) -> None:
        if _workers(self.client) > 0:
            self.since = None
            return
        now = time.monotonic()
        if self.since is None:
            self.since = now
        elif now - self.since > self.grace:
            raise ClusterLost(f"the Dask cluster has had no worker for {self.grace:.0f} s while {what} "
                              "(workers killed and not restarted, or the scheduler shut down)")


def completed(futures: Iterable, client, *, what: str, grace: float | None = None) -> Iterator:
    """Yield ``futures`` as they finish, like ``distributed.as_completed``, with a bound.

    Parameters
    ----------
    futures : iterable of distributed.Future
        The tasks.
    client : distributed.Client
        Their client (asked how many workers the cluster has).
    what : str
        What is being waited for, for the message ("running the sweep's chunks").
    grace : float, optional
        Seconds without any worker after which the wait gives up (default :data:`WORKER_GRACE_S`).

    Yields
    ------
    distributed.Future
        Each future once, when it is done (finished, failed or cancelled).

    Raises
    ------
    ClusterLost
        When the cluster has had no worker for ``grace`` seconds.
    """
    from distributed import wait

    pending = list(futures)
    watch = _Watch(client, WORKER_GRACE_S if grace is None else grace)
    while pending:
        done = [f for f in pending if f.done()]
        if not done:
            try:
                wait(pending, timeout=POLL_S, return_when="FIRST_COMPLETED")
            except TimeoutError:
                watch.check(what)
                continue
            done = [f for f in pending if f.done()]
        watch.since = None
        ids = {id(f) for f in done}
        pending = [f for f in pending if id(f) not in ids]
        yield from done


def result(future, client, *, what: str, grace: float | None = None):
    """``future.result()``, giving up with :class:`ClusterLost` when the cluster has no worker left.

    Parameters
    ----------
    future : distributed.Future
        The task.
    client : distributed.Client
        Its client.
    what : str
        What the task does, for the message.
    grace : float, optional
        Seconds without any worker after which the wait gives up (default :data:`WORKER_GRACE_S`).

    Returns
    -------
    object
        The task's result (its exception is raised as ``future.result()`` would).
    """
    for done in completed([future], client, what=what, grace=grace):
        return done.result()
    raise AssertionError("unreachable")  # pragma: no cover
