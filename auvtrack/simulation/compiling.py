"""Which kernels a piece of work needs, and compiling them before it starts.

A kernel is one (controller, plant module) pair of :mod:`auvtrack.engine.kernels`; these
functions name the pairs from the registries and hand them to the engine's compiler.
"""
from __future__ import annotations

import threading
import time
from typing import Callable, Sequence, TypeVar

from ..engine import kernels

__all__ = ["builtin_controllers", "builtin_pairs", "kernel_keys", "compile_first", "ensure_compiled",
           "interruptible", "warmup", "lane_note"]

T = TypeVar("T")


def builtin_controllers(plant: str = "5dof") -> tuple[str, ...]:
    """Kinds of the built-in controllers that run on ``plant`` (their capabilities), in registry order.

    Parameters
    ----------
    plant : str, optional
        A registered plant model.

    Returns
    -------
    tuple of str
        The kinds.
    """
    from ..control import BUILTIN_NAMES, CONTROLLERS
    from ..plant import PLANTS

    return tuple(n for n in BUILTIN_NAMES if CONTROLLERS[n].runs_on(PLANTS[plant]))


def builtin_pairs(controllers: tuple[str, ...] = (), plants: tuple[str, ...] = ()) -> list[tuple[str, str]]:
    """(controller, plant) pairs a run can use: every controller on every plant it runs on.

    Parameters
    ----------
    controllers, plants : tuple of str, optional
        Registered names (default: every built-in controller and every built-in plant).

    Returns
    -------
    list of (str, str)
        The pairs, controllers in registry order, each with the plants its capabilities allow.
    """
    from ..control import BUILTIN_NAMES, CONTROLLERS
    from ..plant import BUILTIN_NAMES as PLANT_NAMES
    from ..plant import PLANTS

    return [(c, p) for c in (controllers or BUILTIN_NAMES) for p in (plants or PLANT_NAMES)
            if CONTROLLERS[c].runs_on(PLANTS[p])]


def ensure_compiled(preps: Sequence, *, progress: bool = False,
                    notice: Callable[[str], None] | None = None) -> None:
    """Compile (or load) the kernels that ``preps`` need, with the "compiling kernels" notice if any is new.

    Parameters
    ----------
    preps : sequence of Prepared
        Runs about to start.
    progress : bool, optional
        Show a progress bar over the kernels being compiled.
    notice : callable, optional
        Receives the notice (default: printed to standard error).
    """
    keys = [p.key for p in preps]
    if any(not kernels.is_compiled(k) for k in keys):
        _warm(keys, progress=progress, notice=notice)


def _warm(keys: list[kernels.KernelKey], *, progress: bool = False, notice: Callable[[str], None] | None = None,
          lanes: bool = False) -> list[kernels.KernelKey]:
    """:func:`auvtrack.engine.kernels.warmup` so that a signal always stops it.

    Kernels compiled in this process (one pending, or one core) compile in a thread
    (:func:`interruptible`); several compile in child processes, which the stop ends.
    """
    pending = {k for k in keys if not kernels.is_compiled(k) or (lanes and not kernels.is_compiled(k, lanes=True))}
    if len(pending) == 1 or (pending and kernels.usable_cores() == 1):
        return interruptible(lambda: kernels.warmup(keys, progress=progress, notice=notice, lanes=lanes))
    return kernels.warmup(keys, progress=progress, notice=notice, lanes=lanes)


def interruptible(fn: Callable[[], T]) -> T:
    """Run ``fn`` (a compilation in this process) in a thread, so that Ctrl-C or SIGTERM stops the wait at once.

    A signal handled while Numba compiles in the main thread can raise inside one of LLVM's ctypes
    callbacks, where the exception is dropped and the library is left half compiled (the command
    then fails with a ``RuntimeError`` instead of stopping).  Here the signal reaches the main
    thread, which only waits: ``KeyboardInterrupt`` is raised at once and the compilation is
    abandoned (the command line then ends the process with ``os._exit``,
    :func:`auvtrack.interrupt.abandoned`).  Outside the main thread ``fn`` simply runs.

    Parameters
    ----------
    fn : callable
        The compilation.

    Returns
    -------
    object
        What ``fn`` returned.

    Raises
    ------
    KeyboardInterrupt
        A signal came while waiting (even if ``fn`` finished meanwhile).
    """
    if threading.current_thread() is not threading.main_thread():
        return fn()
    from ..interrupt import run_in_thread

    outcome = run_in_thread(fn)
    if outcome.interrupted:
        raise KeyboardInterrupt
    return outcome.value


def kernel_keys(pairs: Sequence[tuple[str, str]]) -> list[kernels.KernelKey]:
    """The kernels of (controller kind, plant model) pairs, one each.

    Parameters
    ----------
    pairs : sequence of (str, str)
        Registered controller kinds and plant models, e.g. ``[("fxtntsmc", "5dof")]``.

    Returns
    -------
    list of KernelKey
        In the order of ``pairs``.
    """
    from ..control import CONTROLLERS
    from ..plant import PLANTS

    return [kernels.KernelKey(CONTROLLERS[c].module, PLANTS[p].module, f"{c} on {p}") for c, p in pairs]


def compile_first(pairs: Sequence[tuple[str, str]], *, progress: bool = False) -> list[kernels.KernelKey]:
    """Compile (or load) the kernels a piece of work needs before it starts its own progress bars.

    Studies and ``reproduce`` call this first, so that a first run shows its "compiling kernels
    (first run only, about N s)" step, with its own progress bar, before the work's bar.

    Parameters
    ----------
    pairs : sequence of (str, str)
        (controller kind, plant model) pairs, see :func:`kernel_keys`.
    progress : bool, optional
        Show a progress bar over the kernels being compiled.

    Returns
    -------
    list of KernelKey
        The kernels compiled now (empty when every one was cached).
    """
    return _warm(kernel_keys(pairs), progress=progress)


def warmup(controllers: tuple[str, ...] = (), plants: tuple[str, ...] = (), *, progress: bool = False,
           simd: bool = False, notice: Callable[[str], None] | None = None) -> dict:
    """Compile (or load from the on-disk cache) the kernel of every controller on every plant.

    Kernels that are not cached compile in parallel, one process per core
    (:func:`auvtrack.engine.kernels.warmup`); the ``prange`` batch form of a kernel compiles
    on its first use.

    Parameters
    ----------
    controllers, plants : tuple of str, optional
        Registered names (default: every built-in controller on every plant it runs on,
        :func:`builtin_pairs`; a 6-DOF plant's kernels one per preset module).
    progress : bool, optional
        Show a progress bar while compiling.
    simd : bool, optional
        Also compile each pair's SIMD batch kernel (``run_batch(..., backend="simd")``), which
        otherwise compiles on first use.
    notice : callable, optional
        Receives the "compiling kernels (first run only, about N s)" line when a kernel is not
        cached (default: standard error).

    Returns
    -------
    dict
        ``{"kernels": [...], "compiled": [...], "seconds": wall time}``.
    """
    keys = kernel_keys(builtin_pairs(controllers, plants))
    t0 = time.perf_counter()
    done = _warm(keys, progress=progress, lanes=simd, notice=notice)
    return {"kernels": [k.label for k in keys], "compiled": [k.label for k in done],
            "seconds": round(time.perf_counter() - t0, 2)}


def lane_note(key: kernels.KernelKey) -> str | None:
    """Whether a kernel's law and plant have a SIMD lane form, said at set-up (nothing is compiled).

    The lane rewrite (:func:`auvtrack.engine.lanes.lane_version`) of the kernel's loop reads the
    source of every function it calls; a construct outside the subset it handles (``try``,
    iterating over a tuple, keyword arguments between compiled functions) means that the ``simd``
    batch back end runs this pair on threads instead.

    Parameters
    ----------
    key : auvtrack.engine.kernels.KernelKey
        The pair.

    Returns
    -------
    str or None
        ``"<label>: no SIMD lane form (<why>); the simd batch back end runs it on threads"``, or
        None when it has one.
    """
    from ..engine.lanes import NotLaneable, lane_version

    try:
        lane_version(kernels.kernel_module(key).run)
    except NotLaneable as exc:
        why = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        return f"{key.label or key.name}: no SIMD lane form ({why}); the simd batch back end runs it on threads"
    return None
