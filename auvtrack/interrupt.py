"""Running compiled user code (a law, a plant) so that Ctrl-C always reaches the process.

Compiled code holds no Python frame: while it runs in the main thread, a SIGINT waits until it
returns, which an endless loop never does.  :func:`run_in_thread` runs it in a daemon thread (the
compiled functions release the GIL) and waits in the main thread, where Ctrl-C is delivered: the
caller's ``on_interrupt`` asks the work to stop (the engine's stop flag), and if it has not stopped
``grace`` seconds later the thread is abandoned and the wait returns anyway.  A process with an
abandoned thread must end with ``os._exit`` (the command line does), not by unwinding the
interpreter under running compiled code.
"""
from __future__ import annotations

import threading
from typing import Any, Callable

__all__ = ["run_in_thread", "Outcome", "abandoned", "GRACE_S"]

GRACE_S = 2.0
"""Seconds a thread may take to stop after Ctrl-C before it is abandoned."""

_ABANDONED: list[threading.Thread] = []


class Outcome:
    """What :func:`run_in_thread` saw: the value (if any), and whether Ctrl-C came and the work was abandoned."""

    def __init__(self, value: Any, interrupted: bool, abandoned: bool, timed_out: bool = False):
        self.value, self.interrupted, self.abandoned = value, interrupted, abandoned
        self.timed_out = timed_out


def abandoned() -> bool:
    """Whether a thread of this process was abandoned while still running (end it with ``os._exit``)."""
    return any(t.is_alive() for t in _ABANDONED)


def run_in_thread(fn: Callable[[], Any], on_interrupt: Callable[[], None] | None = None, *,
                  grace: float = GRACE_S, reraise: bool = True, timeout: float | None = None) -> Outcome:
    """Run ``fn()`` in a daemon thread; Ctrl-C in the waiting (main) thread calls ``on_interrupt``.

    Parameters
    ----------
    fn : callable
        The work (compiled code that releases the GIL, or Python code).
    on_interrupt : callable, optional
        Called once on the first Ctrl-C (e.g. set the engine's stop flag).  Without it, Ctrl-C
        abandons the work at once.
    grace : float, optional
        Seconds to wait after Ctrl-C before the thread is abandoned.
    reraise : bool, optional
        Re-raise an exception ``fn`` raised (else it is the outcome's value).
    timeout : float, optional
        Seconds after which the work is stopped as on Ctrl-C (``on_interrupt``, then abandoned
        after ``grace``), the outcome marked ``timed_out`` instead of ``interrupted``.

    Returns
    -------
    Outcome
        ``value`` (None when abandoned), ``interrupted``, ``abandoned``.

    Raises
    ------
    Exception
        What ``fn`` raised, when ``reraise``.
    """
    import time

    box: dict[str, Any] = {}
    done = threading.Event()

    def target():
        try:
            box["value"] = fn()
        except BaseException as exc:  # re-raised in the caller's thread
            box["error"] = exc
        finally:
            done.set()

    th = threading.Thread(target=target, name="auvtrack-work", daemon=True)
    th.start()
    interrupted, timed_out, deadline = False, False, None
    give_up = None if timeout is None else time.monotonic() + timeout
    while not done.is_set():
        try:
            done.wait(0.05)
        except KeyboardInterrupt:
            if not interrupted:
                interrupted = True
                if on_interrupt is not None and not timed_out:
                    on_interrupt()
                deadline = time.monotonic() + (grace if on_interrupt is not None else 0.0)
        if give_up is not None and not (interrupted or timed_out) and time.monotonic() >= give_up:
            timed_out = True
            if on_interrupt is not None:
                on_interrupt()
            deadline = time.monotonic() + (grace if on_interrupt is not None else 0.0)
        if deadline is not None and time.monotonic() >= deadline and not done.is_set():
            _ABANDONED.append(th)
            return Outcome(None, interrupted, True, timed_out)
    if "error" in box:
        if reraise:
            raise box["error"]
        return Outcome(box["error"], interrupted, False, timed_out)
    return Outcome(box.get("value"), interrupted, False, timed_out)
