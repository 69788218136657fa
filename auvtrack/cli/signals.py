"""Ctrl-C and SIGTERM for long commands (``sweep``, ``compare``): stop once, then let the clean-up finish.

The first SIGINT or SIGTERM raises ``KeyboardInterrupt`` in the main thread, so the command
stops its work, closes its Dask cluster or its batch and keeps what it finished.  Later signals
are ignored until the process exits: a second Ctrl-C while a cluster closes would otherwise
interrupt the shutdown and print a traceback instead of the one-line message.  (The workers of
a cluster the command starts ignore SIGINT themselves:
:class:`auvtrack.batch.sweep_worker.IgnoreInterruptsPlugin`.)
"""
from __future__ import annotations

import contextlib
import signal
import threading
from typing import Callable, Iterator

__all__ = ["stop_once", "stop_requests"]


@contextlib.contextmanager
def stop_once() -> Iterator[Callable[[], bool]]:
    """Turn the first SIGINT or SIGTERM into ``KeyboardInterrupt`` and ignore the ones after it.

    Outside the main thread (where Python delivers signals) nothing is changed.  An exception
    raised while Python runs a callback (a weak reference's, one of LLVM's while Numba compiles)
    is dropped, so the ``KeyboardInterrupt`` can be lost: a command checks ``requested()`` between
    its steps (trials, iterations) and stops there.

    Yields
    ------
    callable
        ``requested()``: True once a signal arrived (always False outside the main thread).  The
        previous handlers are restored on exit, unless a signal stopped the command: the
        process is then ending (its clean-up at exit closes Dask's loops too), and both
        signals stay ignored until it exits.
    """
    if threading.current_thread() is not threading.main_thread():
        yield lambda: False
        return
    stopping = []

    def _stop(signum, frame):
        if stopping:  # already stopping: let the clean-up finish
            return
        stopping.append(signum)
        raise KeyboardInterrupt

    previous = {sig: signal.signal(sig, _stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield lambda: bool(stopping)
    finally:
        for sig, handler in previous.items():  # once stopping, the process is ending: stay deaf until it exits
            signal.signal(sig, signal.SIG_IGN if stopping else handler)


@contextlib.contextmanager
def stop_requests() -> Iterator[Callable[[], bool]]:
    """Record SIGINT and SIGTERM instead of raising, for work that must end in a consistent state.

    Writing a run folder is such work: an exception in the middle would throw away a result that
    is already computed, so the writer asks between blocks whether to stop and keeps what it wrote.

    Yields
    ------
    callable
        ``requested()``: True once a signal arrived.  Outside the main thread it is always False.
        The previous handlers are restored on exit.
    """
    got: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield lambda: False
        return
    previous = {sig: signal.signal(sig, lambda signum, frame: got.append(signum))
                for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield lambda: bool(got)
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
