"""The studies' thread pool: a stop (Ctrl-C, SIGTERM) drops the queued runs instead of running them first."""
from __future__ import annotations

import threading
import time

import pytest

from auvtrack.batch.runner import stoppable_pool


def test_a_stop_drops_the_queued_jobs_and_does_not_wait_for_them():
    started, release = [], threading.Event()

    def job(i):
        started.append(i)
        release.wait(0.2)  # each job would take 0.2 s: 50 of them on one thread, 10 s
        return i

    t0 = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        with stoppable_pool(1) as pool:
            for i in pool.map(job, range(50)):
                if i == 1:
                    raise KeyboardInterrupt  # the signal's exception in the waiting (main) thread
    left = time.monotonic() - t0
    release.set()
    time.sleep(0.3)  # a job running at the stop finishes on its own; none is started after it
    assert len(started) <= 3, started
    assert left < 2.0, left


def test_without_a_stop_every_job_runs_and_the_pool_waits():
    done = []
    with stoppable_pool(2) as pool:
        for i in range(20):
            pool.submit(lambda k: (time.sleep(0.01), done.append(k)), i)
    assert sorted(done) == list(range(20))  # all of them, before the block ended
