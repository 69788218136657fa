"""Ctrl-C and SIGTERM for every command: stop once, then let the clean-up finish.

:func:`auvtrack.cli.main` runs every command inside :func:`stop_once`, so that a new command
gets the same handling without a line of its own: the first SIGINT or SIGTERM raises
``KeyboardInterrupt`` in the main thread, so the command stops its work (a run keeps its
partial result, a sweep closes its Dask cluster and keeps its chunks) and exits 130 with one
line.  Later signals are ignored until the process exits: a second Ctrl-C while a cluster
closes would otherwise interrupt the shutdown and print a traceback instead of the one-line
message.  A command that asks whether to stop between its steps (``tune``, ``train``) enters
:func:`stop_once` again and gets the same ``requested()``.  (The workers of a cluster the
command starts ignore SIGINT themselves: :class:`auvtrack.batch.sweep_worker.IgnoreInterruptsPlugin`.)
"""
from __future__ import annotations

import contextlib
import signal
import threading
from typing import Callable, Iterator

__all__ = ["stop_once", "stop_requests"]

_ACTIVE: list[Callable[[], bool]] = []
"""The ``requested()`` of the :func:`stop_once` in force (the outermost), if any."""


@contextlib.contextmanager
def stop_once() -> Iterator[Callable[[], bool]]:
    """Turn the first SIGINT or SIGTERM into ``KeyboardInterrupt`` and ignore the ones after it.

    Outside the main thread (where Python delivers signals) nothing is changed, and inside another
    :func:`stop_once` (the command line's, around every command) neither: the outer one's
    ``requested()`` is yielded.  An exception raised while Python runs a callback (a weak
    reference's, one of LLVM's while Numba compiles) is dropped, so the ``KeyboardInterrupt`` can
    be lost: a command checks ``requested()`` between its steps (trials, iterations) and stops
    there, and compilations in this process run in a thread
    (:func:`auvtrack.simulation.compiling.interruptible`) so that the main thread only waits.

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
    if _ACTIVE:  # nested: the outer handlers stay in force
        yield _ACTIVE[-1]
        return
    stopping = []

    def _stop(signum, frame):
        if stopping:  # already stopping: let the clean-up finish
            return
        stopping.append(signum)
        raise KeyboardInterrupt

    def requested() -> bool:
        return bool(stopping)

    previous = {sig: signal.signal(sig, _stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    _ACTIVE.append(requested)
    try:
        yield requested
    finally:
        _ACTIVE.remove(requested)
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
