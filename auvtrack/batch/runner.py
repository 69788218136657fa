"""Batch runner: many prepared scenarios per call, parallel over cores, reduced to metrics in-kernel.

Each run calls the same compiled kernel of its (controller, plant) pair as
:func:`auvtrack.simulation.pipeline.run_prepared`, with the same arrays, so a batch result is
bit-identical to the single-run result of the same scenario.  By default a run keeps no
trajectory: the kernel gets a 0-row log and only its metrics accumulator (49 floats), cause,
stop time and failure state come back, so memory does not grow with the length of a run, and
:func:`iter_batch` keeps it flat in the number of runs too (it prepares and runs lazily, one
block at a time).

Two parallel back ends (measured in ``benchmarks/results.md``):

* ``"threads"`` (default): a thread pool over the ``nogil`` kernel; the arrays of each run are
  passed as they are, so scenarios of any shape can be mixed.
* ``"prange"``: one compiled ``numba.prange`` loop over runs of identical array shapes
  (the kernel's ``run_many``), grouped automatically (its speed: ``benchmarks/results.md``); never
  call it from several Python threads at once:
  Numba's default ``workqueue`` threading layer is not re-entrant and aborts the process.
"""
from __future__ import annotations

import contextlib
import math
import threading
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Iterator, Sequence

import numpy as np
from numba.core.errors import NumbaError

from ..engine import loop as engine
from ..engine import kernels
from ..simulation.compiling import ensure_compiled
from ..simulation.pipeline import (Prepared, call_kernel, failure_record, outputs_for, result_from,
                              status_of)
from ..engine.loop import Outputs
from ..interrupt import abandoned, run_in_thread
from ..metrics import METRICS_SIZE, metrics_finalize, metrics_init
from ..simulation.result import Result

BACKENDS = ("threads", "prange", "serial", "simd")

__all__ = ["RunSummary", "run_metrics", "run_batch", "iter_batch", "BACKENDS", "default_workers", "StopSignal",
           "BatchInterrupted", "preferred_backend", "stoppable_pool"]


@dataclass(frozen=True)
class RunSummary:
    """The outcome of one run reduced to its metrics (no trajectory).

    Attributes
    ----------
    status : str
        ``"ok"``, ``"failed"`` or ``"interrupted"`` (as :attr:`auvtrack.simulation.result.Result.status`).
    failure : dict or None
        Time, cause, detail and state of a failure (as ``Result.failure``).
    metrics : dict of str to float
        Every metric of :data:`auvtrack.metrics.METRIC_NAMES`, over the window
        actually simulated (as ``Result.metrics``).
    t_stop : float
        Simulated time at the stop (s).
    steps : int
        Number of RK4 steps actually run.
    """

    status: str
    failure: dict | None
    metrics: dict[str, float] = field(repr=False)
    t_stop: float
    steps: int

    @property
    def ok(self) -> bool:
        """True when the run reached its end without failure."""
        return self.status == "ok"


def preferred_backend(threads: str = "threads") -> str:
    """The back end for many metrics-only runs: ``"simd"`` where the vector math library is in use, else ``threads``.

    Without libmvec (``auvtrack.jit.vecmath.BACKEND == "scalar"``) every vector math call of a lane
    kernel becomes one scalar call per lane, and the lanes lose most of their advantage.

    Parameters
    ----------
    threads : str, optional
        The back end to use otherwise (``"serial"`` for one core per process, as in a Dask worker).

    Returns
    -------
    str
        A name of :data:`BACKENDS`.
    """
    from ..jit.vecmath import BACKEND

    return "simd" if BACKEND == "avx2" else threads


def default_workers() -> int:
    """Number of worker threads used when none is given: the usable cores (:func:`auvtrack.engine.kernels.usable_cores`)."""
    return kernels.usable_cores()


@contextlib.contextmanager
def stoppable_pool(workers: int | None = None) -> Iterator[ThreadPoolExecutor]:
    """A thread pool whose queued work is dropped when the block is left by an exception (Ctrl-C, SIGTERM).

    ``with ThreadPoolExecutor(...)`` waits, on any exit, until every submitted job has run: a stop
    during a study would first run all of its remaining simulations.  Here an exception (a
    ``KeyboardInterrupt`` from a signal, or a job's error) cancels the jobs not yet started and
    does not wait; the ones running finish on their own (the interpreter joins them at exit).

    Parameters
    ----------
    workers : int, optional
        Threads (default :func:`default_workers`).

    Yields
    ------
    concurrent.futures.ThreadPoolExecutor
        The pool; on a normal exit it is shut down waiting for its jobs, as a ``with`` block would.
    """
    pool = ThreadPoolExecutor(max_workers=workers or default_workers())
    try:
        yield pool
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


class StopSignal:
    """A stop request shared by the runs of a batch: :meth:`set` stops every run in flight and to come.

    Each run registers its kernel's ``info`` array; the kernel reads its stop flag every 1024 steps.
    """

    def __init__(self) -> None:
        self._infos: list[np.ndarray] = []
        self._lock = threading.Lock()
        self.is_set = False

    def register(self, info: np.ndarray) -> None:
        """Attach one run's ``info`` array (flagged at once if the signal is already set)."""
        with self._lock:
            self._infos.append(info)
            if self.is_set:
                info[..., engine.INFO_STOP] = 1

    def set(self) -> None:
        """Ask every registered (and later) run to stop."""
        with self._lock:
            self.is_set = True
            for info in self._infos:
                info[..., engine.INFO_STOP] = 1


class BatchInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a batch; ``results`` holds every run's outcome (``"interrupted"`` for those cut short).

    Attributes
    ----------
    results : list
        One :class:`RunSummary` (or :class:`~auvtrack.simulation.result.Result`) per input, in order.
    """

    def __init__(self, results: list) -> None:
        super().__init__("batch interrupted")
        self.results = results


def _summary(prep: Prepared, cause: int, t_stop: float, out: Outputs) -> RunSummary:
    failure = None if cause == engine.CAUSE_NONE else failure_record(int(cause), float(t_stop), out.fail_state, prep,
                                                                     int(out.info[engine.INFO_STATUS]))
    t0, t1 = prep.scenario.metrics.window
    metrics = metrics_finalize(out.acc, t0, min(t1, float(t_stop)))
    return RunSummary(status_of(int(cause)), failure, metrics, float(t_stop), int(out.info[engine.INFO_STEPS]))


def run_metrics(prep: Prepared, stop: StopSignal | None = None) -> RunSummary:
    """Run one prepared scenario without logging and return its :class:`RunSummary`.

    Parameters
    ----------
    prep : Prepared
        From :func:`auvtrack.simulation.pipeline.prepare`.
    stop : StopSignal, optional
        Shared stop request; when set, this run stops with status ``"interrupted"``.

    Returns
    -------
    RunSummary
        Bit-identical metrics, status and failure to :func:`~auvtrack.simulation.pipeline.run_prepared`.
    """
    ensure_compiled([prep])
    out = outputs_for(prep, rows=0)
    if stop is not None:
        stop.register(out.info)
    cause, _, t_stop = call_kernel(prep, out)
    return _summary(prep, cause, t_stop, out)


def _trajectory(prep: Prepared, stop: StopSignal | None = None) -> Result:
    ensure_compiled([prep])
    out = outputs_for(prep)
    if stop is not None:
        stop.register(out.info)
    wall = time.perf_counter()
    cause, rows, t_stop = call_kernel(prep, out)
    return result_from(prep, out, cause, rows, t_stop, time.perf_counter() - wall)


def _shape_key(p: Prepared) -> tuple:
    return (p.key, p.plant.x0.shape, p.controller.x0.shape, p.cp.shape, p.plant.pp.shape, p.ref_p.shape,
            p.environment.rows.shape, p.environment.current.shape, p.environment.noise.shape, len(p.channels))


def _stack(arrays: list[np.ndarray]) -> np.ndarray:
    return np.ascontiguousarray(np.stack(arrays))


def _stacked_inputs(ps: Sequence[Prepared]) -> list[list[np.ndarray]]:
    """Each run's input arrays in the field order of :class:`~auvtrack.engine.loop.Stacked`."""
    return [[p.plant.pp for p in ps], [p.plant.x0 for p in ps], [p.cp for p in ps], [p.controller.x0 for p in ps],
            [p.vp_nom for p in ps], [p.environment.rows for p in ps], [p.environment.current for p in ps],
            [p.environment.noise for p in ps], [p.ref_p for p in ps], [p.si for p in ps], [p.sf for p in ps]]


def _run_prange(preps: Sequence[Prepared], stop: StopSignal) -> list[RunSummary]:
    groups: dict[tuple, list[int]] = {}
    for i, p in enumerate(preps):
        groups.setdefault(_shape_key(p), []).append(i)
    out: list[RunSummary | None] = [None] * len(preps)
    for idx in groups.values():
        ps = [preps[i] for i in idx]
        n = len(ps)
        ensure_compiled(ps[:1])
        runs = kernels.kernel_module(ps[0].key).run_many
        accs = np.empty((n, METRICS_SIZE))
        for k in range(n):
            metrics_init(accs[k])
        fails = np.zeros((n, 2, ps[0].n_state))
        infos = np.zeros((n, engine.INFO_SIZE), dtype=np.int64)
        stop.register(infos)
        causes = np.zeros(n, dtype=np.int64)
        t_stops = np.zeros(n)
        runs(engine.Stacked(*(_stack(arrays) for arrays in _stacked_inputs(ps))), len(ps[0].channels),
             engine.StackedOutputs(np.empty((n, 0, 0)), accs, fails, infos, causes, t_stops))
        for k, i in enumerate(idx):
            o = Outputs(np.empty((0, len(ps[0].channels))), accs[k], fails[k], infos[k])
            out[i] = _summary(preps[i], int(causes[k]), float(t_stops[k]), o)
    return out  # type: ignore[return-value]


def _lane_stack(arrays: list[np.ndarray], lanes: int) -> np.ndarray:
    """Stack n equal-shape arrays into blocks of ``lanes`` runs along a last axis: (blocks, *shape, lanes).

    The last block is padded with copies of its first run (padding lanes are computed, never read).
    """
    a = np.stack(arrays)
    n = a.shape[0]
    nb = -(-n // lanes)
    if nb * lanes > n:
        a = np.concatenate([a, np.repeat(a[(nb - 1) * lanes:(nb - 1) * lanes + 1], nb * lanes - n, axis=0)])
    a = a.reshape((nb, lanes) + a.shape[1:])
    return np.ascontiguousarray(np.moveaxis(a, 1, -1))


MIN_LANES = 4
"""Fewer runs than this left over in a group run on the single-run kernel rather than in a block of
mostly empty lanes (a block costs about what 3 single runs cost, ``benchmarks/results.md``)."""


class _LaneGroup:
    """The runs of one group stacked in blocks of LANES along a last axis, with the lane kernel's outputs."""

    def __init__(self, module, ps: list[Prepared], stop: StopSignal) -> None:
        L = engine.LANES
        self.module, self.ps, n = module, ps, len(ps)
        self.nb = nb = -(-n // L)
        accs0 = []
        for _ in range(n):
            a = np.empty(METRICS_SIZE)
            metrics_init(a)
            accs0.append(a)
        self.accs = _lane_stack(accs0, L)
        self.fails = np.zeros((nb, 2, ps[0].n_state, L))
        self.infos = np.zeros((nb, engine.INFO_SIZE, L), dtype=np.int64)
        stop.register(np.moveaxis(self.infos, 1, -1))  # a view: the stop flag reaches every lane
        counts = np.array([min(L, n - b * L) for b in range(nb)], dtype=np.int64)
        self.causes = np.zeros((nb, L), dtype=np.int64)
        self.t_stops = np.zeros((nb, L))
        logs = np.zeros((nb, 0, len(ps[0].channels), L))
        ins = engine.Stacked(*(_lane_stack(arrays, L) for arrays in _stacked_inputs(ps)))
        outs = engine.StackedOutputs(logs, self.accs, self.fails, self.infos, self.causes, self.t_stops)
        self.args = (ins, outs, counts)

    def compile(self) -> None:
        """Type and compile (or load) the lane kernel for these arguments: a call over no block."""
        self.module.run_lanes(*self.args, 0, 0)

    def run_block(self, b: int) -> None:
        """Run block ``b`` (the kernel releases the GIL)."""
        self.module.run_lanes(*self.args, b, b + 1)

    def summary(self, k: int) -> RunSummary:
        """The outcome of the group's run ``k``."""
        b, lane = divmod(k, engine.LANES)
        p = self.ps[k]
        o = Outputs(np.empty((0, len(p.channels))), np.ascontiguousarray(self.accs[b, :, lane]),
                    np.ascontiguousarray(self.fails[b, :, :, lane]), np.ascontiguousarray(self.infos[b, :, lane]))
        return _summary(p, int(self.causes[b, lane]), float(self.t_stops[b, lane]), o)


def _run_simd(preps: Sequence[Prepared], stop: StopSignal, workers: int) -> list[RunSummary]:
    """Runs grouped by kernel and array shapes, each group in blocks of LANES runs (one per SIMD lane).

    Within a group, runs are sorted by length so that a block's lanes end together; the blocks, and
    the runs that go to the single-run kernel (fewer than :data:`MIN_LANES` left over in a group, or
    a group whose law or plant has no lane form, :class:`~auvtrack.engine.lanes.NotLaneable`,
    or one whose lane form Numba cannot type or compile, which is warned about) are spread over
    ``workers`` threads.
    """
    from ..engine.lanes import NotLaneable

    L = engine.LANES
    groups: dict[tuple, list[int]] = {}
    for i, p in enumerate(preps):
        groups.setdefault(_shape_key(p), []).append(i)
    out: list[RunSummary | None] = [None] * len(preps)
    lane_groups: list[tuple[list[int], _LaneGroup]] = []
    singles: list[int] = []
    for idx in groups.values():
        idx = sorted(idx, key=lambda i: preps[i].n_steps)
        rest = len(idx) % L
        if 0 < rest < MIN_LANES:
            singles += idx[len(idx) - rest:]
            idx = idx[:len(idx) - rest]
        if not idx:
            continue
        try:
            group = _LaneGroup(kernels.lanes_module(preps[idx[0]].key), [preps[i] for i in idx], stop)
            group.compile()  # here, once, before the threads: a lane form Numba cannot type is found now
        except (NotLaneable, NumbaError) as exc:
            key = preps[idx[0]].key
            why = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            warnings.warn(f"simd back end: {key.label or key.name} has no lane form ({why}); "
                          "its runs use the thread back end", stacklevel=3)
            singles += idx
            continue
        lane_groups.append((idx, group))
    tasks: list[Callable[[], Any]] = [lambda g=g, b=b: g.run_block(b) for _, g in lane_groups for b in range(g.nb)]
    tasks += [lambda i=i: out.__setitem__(i, run_metrics(preps[i], stop)) for i in singles]
    if workers == 1 or len(tasks) == 1:
        for task in tasks:
            task()
    else:
        with ThreadPoolExecutor(max_workers=min(workers, len(tasks))) as pool:
            for f in [pool.submit(task) for task in tasks]:
                f.result()
    for idx, g in lane_groups:
        for k, i in enumerate(idx):
            out[i] = g.summary(k)
    return out  # type: ignore[return-value]


def run_batch(preps: Sequence[Prepared], *, trajectories: bool = False, workers: int | None = None,
              backend: str = "threads") -> list[RunSummary] | list[Result]:
    """Run many prepared scenarios, in parallel, and return their outcomes in order.

    Parameters
    ----------
    preps : sequence of Prepared
        From :func:`auvtrack.simulation.pipeline.prepare`; any mix of controllers, plants and shapes.
    trajectories : bool, optional
        Return full :class:`~auvtrack.simulation.result.Result` objects (as
        :func:`~auvtrack.simulation.pipeline.run_prepared`) instead of metrics-only summaries.
    workers : int, optional
        Threads (``"threads"`` back end); default :func:`default_workers`.  The ``"prange"``
        back end uses Numba's thread count (``NUMBA_NUM_THREADS``).
    backend : {"threads", "prange", "serial", "simd"}
        How runs are spread over cores (``trajectories`` always uses threads); ``"simd"`` runs
        groups of equal kernel and shapes in the lanes of a SIMD register, falling back to the
        thread back end (with a warning) for a law or plant without a lane form.

    Returns
    -------
    list of RunSummary, or list of Result when ``trajectories``
        One per input, in input order.

    Raises
    ------
    ValueError
        Unknown ``backend`` or ``workers`` < 1.
    BatchInterrupted
        On Ctrl-C: every run in flight stops within about a second; its ``results`` hold every
        outcome (``"interrupted"`` for runs cut short or not started).
    """
    if backend not in BACKENDS:
        raise ValueError(f"backend: must be one of {', '.join(BACKENDS)} (got {backend!r})")
    workers = default_workers() if workers is None else int(workers)
    if workers < 1:
        raise ValueError(f"workers: must be >= 1 (got {workers})")
    preps = list(preps)
    if not preps:
        return []
    ensure_compiled(preps)
    stop = StopSignal()
    fn: Callable[[Prepared, StopSignal], Any] = _trajectory if trajectories else run_metrics
    if backend == "prange" and not trajectories:
        return _guarded(lambda: _run_prange(preps, stop), stop, len(preps))
    if backend == "simd" and not trajectories:
        return _guarded(lambda: _run_simd(preps, stop, workers), stop, len(preps))
    if backend == "serial" or workers == 1 or len(preps) == 1:
        workers = 1
    pool = ThreadPoolExecutor(max_workers=min(workers, len(preps)))
    futures = [pool.submit(fn, p, stop) for p in preps]
    try:
        return _bounded(lambda: [f.result() for f in futures], stop,
                        lambda: [f.result() if f.done() and f.exception() is None else None for f in futures])
    finally:
        pool.shutdown(wait=not abandoned(), cancel_futures=True)


def _guarded(fn, stop: StopSignal, n: int):
    """Run ``fn()`` (``n`` runs) in a worker thread; on Ctrl-C set ``stop`` and raise :class:`BatchInterrupted`."""
    return _bounded(fn, stop, lambda: [None] * n)


def _bounded(work: Callable[[], list], stop: StopSignal, partial: Callable[[], list]) -> list:
    """Wait for ``work()`` in a daemon thread (:func:`auvtrack.interrupt.run_in_thread`), so that Ctrl-C
    always reaches this thread.  On Ctrl-C ``stop`` is set and the runs get
    :data:`auvtrack.interrupt.GRACE_S` to stop; a law or plant that never returns (an endless loop)
    is abandoned, its outcome None in :class:`BatchInterrupted` ``results`` (``partial()``), and the
    process must end with ``os._exit`` (the command line does)."""
    outcome = run_in_thread(work, stop.set)
    if outcome.interrupted:
        raise BatchInterrupted(partial() if outcome.abandoned else outcome.value)
    return outcome.value


def iter_batch(items: Iterable[Any], prepare_fn: Callable[[Any], Prepared], *, block: int = 64,
               workers: int | None = None, backend: str = "threads") -> Iterator[tuple[Any, RunSummary]]:
    """Prepare and run an iterable of items lazily, ``block`` at a time; memory flat in their number.

    Parameters
    ----------
    items : iterable
        Anything ``prepare_fn`` turns into a :class:`~auvtrack.simulation.pipeline.Prepared`.
    prepare_fn : callable
        ``prepare_fn(item) -> Prepared``.
    block : int, optional
        Runs per parallel call, >= 1.
    workers, backend
        As :func:`run_batch`.

    Yields
    ------
    (item, RunSummary)
        In input order.
    """
    if block < 1:
        raise ValueError(f"block: must be >= 1 (got {block})")
    buf: list[Any] = []
    for item in items:
        buf.append(item)
        if len(buf) == block:
            yield from zip(buf, run_batch([prepare_fn(x) for x in buf], workers=workers, backend=backend))
            buf = []
    if buf:
        yield from zip(buf, run_batch([prepare_fn(x) for x in buf], workers=workers, backend=backend))


def runs_per_second(n_runs: int, seconds: float) -> float:
    """Throughput helper for benchmarks (NaN for a zero duration)."""
    return n_runs / seconds if seconds > 0 else math.nan
