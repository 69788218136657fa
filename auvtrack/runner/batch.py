"""Batch runner: many prepared scenarios per call, parallel over cores, reduced to metrics in-kernel.

Each run calls the same compiled :func:`auvtrack.simulation.engine.run_kernel` as
:func:`auvtrack.simulation.api.run_prepared`, with the same arrays, so a batch result is
bit-identical to the single-run result of the same scenario.  By default a run keeps no
trajectory: the kernel gets a 0-row log and only its metrics accumulator (46 floats), cause,
stop time and failure state come back, so memory does not grow with the length of a run, and
:func:`iter_batch` keeps it flat in the number of runs too (it prepares and runs lazily, one
block at a time).

Two parallel back ends (measured in ``benchmarks/results.md``):

* ``"threads"`` (default): a thread pool over the ``nogil`` kernel; the arrays of each run are
  passed as they are, so scenarios of any shape can be mixed.
* ``"prange"``: one compiled ``numba.prange`` loop over runs of identical array shapes
  (:func:`batch_kernel`), grouped automatically.  About 1.4-1.8x serial on 2 cores, like the threads
  (``benchmarks/results.md``), but never call it from several Python threads at once:
  Numba's default ``workqueue`` threading layer is not re-entrant and aborts the process.
"""
from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Iterator, Sequence

import numba
import numpy as np

from .._jit import njit
from ..simulation import engine
from ..simulation.api import Prepared, _failure, run_prepared
from ..simulation.metrics import METRICS_SIZE, metrics_finalize, metrics_init
from ..simulation.result import Result

BACKENDS = ("threads", "prange", "serial")

__all__ = ["RunSummary", "run_metrics", "run_batch", "iter_batch", "batch_kernel", "BACKENDS",
           "default_workers"]


@dataclass(frozen=True)
class RunSummary:
    """The outcome of one run reduced to its metrics (no trajectory).

    Attributes
    ----------
    status : str
        ``"ok"`` or ``"failed"`` (as :attr:`auvtrack.simulation.result.Result.status`).
    failure : dict or None
        Time, cause, detail and state of a failure (as ``Result.failure``).
    metrics : dict of str to float
        Every metric of :data:`auvtrack.simulation.metrics.METRIC_NAMES`, over the window
        actually simulated (as ``Result.metrics``).
    t_stop : float
        Simulated time at the stop (s).
    steps : int
        Number of RK4 steps requested.
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


def default_workers() -> int:
    """Number of worker threads used when none is given: the number of usable cores."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def _summary(prep: Prepared, cause: int, t_stop: float, acc: np.ndarray, fail_state: np.ndarray) -> RunSummary:
    failure = None if cause == engine.CAUSE_NONE else _failure(int(cause), float(t_stop), fail_state, prep)
    t0, t1 = prep.scenario.metrics.window
    metrics = metrics_finalize(acc, t0, min(t1, float(t_stop)))
    return RunSummary("ok" if failure is None else "failed", failure, metrics, float(t_stop),
                      int(prep.si[engine.SI_NSTEPS]))


def run_metrics(prep: Prepared) -> RunSummary:
    """Run one prepared scenario without logging and return its :class:`RunSummary`.

    Parameters
    ----------
    prep : Prepared
        From :func:`auvtrack.simulation.api.prepare`.

    Returns
    -------
    RunSummary
        Bit-identical metrics, status and failure to :func:`~auvtrack.simulation.api.run_prepared`.
    """
    log = np.empty((0, len(prep.channels)))
    acc = np.empty(METRICS_SIZE)
    metrics_init(acc)
    fail_state = np.zeros(prep.X0.size)
    cause, _, t_stop = engine.run_kernel(int(prep.si[engine.SI_CODE]), prep.X0, prep.si, prep.sf, prep.cp,
                                         prep.vp_nom, prep.vp_true, prep.ref_p, prep.d_rows, prep.d_cur,
                                         prep.noise, log, acc, fail_state)
    return _summary(prep, cause, t_stop, acc, fail_state)


@njit(nogil=True, parallel=True)
def batch_kernel(codes, X0s, sis, sfs, cps, vp_noms, vp_trues, ref_ps, d_rows, d_curs, noises, ncols, accs,
                 fail_states, causes, t_stops):
    """Run ``len(codes)`` closed loops of identical array shapes in a ``prange`` loop, metrics only.

    Row ``i`` of every stacked argument is run ``i``'s array for
    :func:`~auvtrack.simulation.engine.run_kernel`; ``accs`` (n, METRICS_SIZE) must be
    initialised by :func:`~auvtrack.simulation.metrics.metrics_init`.  Writes ``causes``,
    ``t_stops``, ``accs`` and ``fail_states``.
    """
    n = codes.shape[0]
    for i in numba.prange(n):
        log = np.empty((0, ncols))
        cause, _, t_stop = engine.run_kernel(codes[i], X0s[i], sis[i], sfs[i], cps[i], vp_noms[i], vp_trues[i],
                                             ref_ps[i], d_rows[i], d_curs[i], noises[i], log, accs[i], fail_states[i])
        causes[i] = cause
        t_stops[i] = t_stop


def _shape_key(p: Prepared) -> tuple:
    return (p.X0.shape, p.cp.shape, p.ref_p.shape, p.d_rows.shape, p.d_cur.shape, p.noise.shape, len(p.channels))


def _run_prange(preps: Sequence[Prepared]) -> list[RunSummary]:
    groups: dict[tuple, list[int]] = {}
    for i, p in enumerate(preps):
        groups.setdefault(_shape_key(p), []).append(i)
    out: list[RunSummary | None] = [None] * len(preps)
    for idx in groups.values():
        ps = [preps[i] for i in idx]
        n = len(ps)
        stack = lambda name: np.ascontiguousarray(np.stack([getattr(p, name) for p in ps]))  # noqa: E731
        accs = np.empty((n, METRICS_SIZE))
        for k in range(n):
            metrics_init(accs[k])
        fails = np.zeros((n, ps[0].X0.size))
        causes = np.zeros(n, dtype=np.int64)
        t_stops = np.zeros(n)
        codes = np.array([int(p.si[engine.SI_CODE]) for p in ps], dtype=np.int64)
        batch_kernel(codes, stack("X0"), stack("si"), stack("sf"), stack("cp"), stack("vp_nom"), stack("vp_true"),
                     stack("ref_p"), stack("d_rows"), stack("d_cur"), stack("noise"), len(ps[0].channels), accs,
                     fails, causes, t_stops)
        for k, i in enumerate(idx):
            out[i] = _summary(preps[i], causes[k], t_stops[k], accs[k], fails[k])
    return out  # type: ignore[return-value]


def run_batch(preps: Sequence[Prepared], *, trajectories: bool = False, workers: int | None = None,
              backend: str = "threads") -> list[RunSummary] | list[Result]:
    """Run many prepared scenarios, in parallel, and return their outcomes in order.

    Parameters
    ----------
    preps : sequence of Prepared
        From :func:`auvtrack.simulation.api.prepare`; any mix of controllers and shapes.
    trajectories : bool, optional
        Return full :class:`~auvtrack.simulation.result.Result` objects (as
        :func:`~auvtrack.simulation.api.run_prepared`) instead of metrics-only summaries.
    workers : int, optional
        Threads (``"threads"`` back end); default :func:`default_workers`.  The ``"prange"``
        back end uses Numba's thread count (``NUMBA_NUM_THREADS``).
    backend : {"threads", "prange", "serial"}
        How runs are spread over cores (``trajectories`` always uses threads).

    Returns
    -------
    list of RunSummary, or list of Result when ``trajectories``
        One per input, in input order.

    Raises
    ------
    ValueError
        Unknown ``backend`` or ``workers`` < 1.
    """
    if backend not in BACKENDS:
        raise ValueError(f"backend: must be one of {', '.join(BACKENDS)} (got {backend!r})")
    workers = default_workers() if workers is None else int(workers)
    if workers < 1:
        raise ValueError(f"workers: must be >= 1 (got {workers})")
    preps = list(preps)
    if not preps:
        return []
    fn: Callable[[Prepared], Any] = run_prepared if trajectories else run_metrics
    if backend == "prange" and not trajectories:
        return _run_prange(preps)
    if backend == "serial" or workers == 1 or len(preps) == 1:
        return [fn(p) for p in preps]
    with ThreadPoolExecutor(max_workers=min(workers, len(preps))) as pool:
        return list(pool.map(fn, preps))


def iter_batch(items: Iterable[Any], prepare_fn: Callable[[Any], Prepared], *, block: int = 64,
               workers: int | None = None, backend: str = "threads") -> Iterator[tuple[Any, RunSummary]]:
    """Prepare and run an iterable of items lazily, ``block`` at a time; memory flat in their number.

    Parameters
    ----------
    items : iterable
        Anything ``prepare_fn`` turns into a :class:`~auvtrack.simulation.api.Prepared`.
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
