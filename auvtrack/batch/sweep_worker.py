"""What a Dask worker runs for ``auvtrack sweep``: one chunk of samples -> one Arrow table.

Everything here is importable on a worker (no jitted function is ever shipped: the worker
imports :mod:`auvtrack.batch.runner`, which loads the compiled kernels from its on-disk
cache).  :func:`run_chunk` is pure: its table depends only on the study and the chunk's sample
indices, so a retried chunk (after a worker died) gives the same rows.
"""
from __future__ import annotations

import math
from typing import Any

from .sweep_spec import SweepSpec

STATUS_OK, STATUS_FAILED, STATUS_INVALID = "ok", "failed", "invalid"
FIXED_COLUMNS = ("sample", "point", "replicate")
TAIL_COLUMNS = ("seed", "status", "cause", "detail", "fail_time")

__all__ = ["run_chunk", "run_samples", "lost_rows", "result_schema", "worker_memory_budget", "WarmupPlugin",
           "worker_warmup", "IgnoreInterruptsPlugin", "STATUS_OK", "STATUS_FAILED", "STATUS_INVALID", "CAUSE_MEMORY", "CAUSE_WORKER_DIED"]


def _grid_type(values: list[Any]):
    import pyarrow as pa

    if all(isinstance(v, bool) for v in values):
        return pa.bool_()
    if all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        return pa.int64()
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return pa.float64()
    return pa.string()


def result_schema(spec: SweepSpec):
    """Arrow schema of the results table of ``spec`` (identical for every chunk).

    Columns: sample, point, replicate, one per varied key (grid values as typed, non-scalar
    values as JSON strings; random draws as float64), seed, status, cause, detail, fail_time and
    every metric of :data:`auvtrack.metrics.METRIC_NAMES`.
    """
    import pyarrow as pa

    from ..metrics import METRIC_NAMES

    fields = [pa.field(c, pa.int64()) for c in FIXED_COLUMNS]
    for key, vals in spec.study.grid.items():
        scalars = all(isinstance(v, (bool, int, float, str)) for v in vals)
        fields.append(pa.field(key, _grid_type(vals) if scalars else pa.string()))
    fields += [pa.field(key, pa.float64()) for key in spec.study.random]
    fields += [pa.field("seed", pa.int64()), pa.field("status", pa.string()), pa.field("cause", pa.string()),
               pa.field("detail", pa.string()), pa.field("fail_time", pa.float64())]
    fields += [pa.field(m, pa.float64()) for m in METRIC_NAMES]
    return pa.schema(fields)


MEMORY_FRACTION = 0.8  # of the worker's limit: Dask pauses a worker there and kills it at 95 %
CAUSE_MEMORY, CAUSE_WORKER_DIED = "memory", "worker_died"


def worker_memory_budget() -> int | None:
    """Bytes a sample may still allocate in this Dask worker, or None outside a worker / without a limit.

    The budget is :data:`MEMORY_FRACTION` of the worker's memory limit minus what the process
    already uses (its resident set: interpreter, libraries, compiled kernels).
    """
    try:
        from distributed import get_worker

        worker = get_worker()
    except (ImportError, ValueError):
        return None
    manager = getattr(worker, "memory_manager", None)
    limit = getattr(manager, "memory_limit", None) or getattr(worker, "memory_limit", None)
    if not limit:
        return None
    import psutil

    return int(MEMORY_FRACTION * limit) - psutil.Process().memory_info().rss


def _prepare_sample(spec: SweepSpec, index: int, budget: int | None):
    """(seed, Prepared, or (status, cause, detail) of a sample that does not run)."""
    import warnings

    from ..scenario import ScenarioError, load_scenario
    from ..scenario.plan import plan_run
    from ..simulation.pipeline import prepare

    seed, ov = spec.overrides(index)
    try:
        sc = load_scenario(spec.base, ov)
        if budget is not None:  # metrics only: no log, the noise and current tables are what grows
            need = plan_run(sc, 0).table_bytes
            if need > budget:
                return seed, (STATUS_FAILED, CAUSE_MEMORY,
                              f"its noise and current tables need an estimated {need / 2 ** 20:.0f} MiB, more than "
                              f"the {budget / 2 ** 20:.0f} MiB this worker has left "
                              f"({MEMORY_FRACTION:.0%} of its memory limit; raise it with --worker-memory)")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return seed, prepare(sc)
    except (ScenarioError, ValueError) as exc:
        return seed, (STATUS_INVALID, "invalid", " ".join(str(exc).split()) or type(exc).__name__)


def _base_row(spec: SweepSpec, i: int, seed: int) -> dict[str, Any]:
    point, rep, _ = spec.sample(i)
    return {"sample": i, "point": point, "replicate": rep, **spec.column_values(i), "seed": seed}


def _table(spec: SweepSpec, rows: list[dict[str, Any]]):
    import pyarrow as pa

    schema = result_schema(spec)
    return pa.Table.from_pydict({f.name: [r[f.name] for r in rows] for f in schema}, schema=schema)


def _not_run(row: dict[str, Any], status: str, cause: str, detail: str) -> dict[str, Any]:
    from ..metrics import METRIC_NAMES

    row.update(status=status, cause=cause, detail=detail, fail_time=math.nan)
    row.update({m: math.nan for m in METRIC_NAMES})
    return row


def run_samples(spec: SweepSpec, indices: list[int]):
    """Run the samples ``indices`` (metrics only) and return their rows as an Arrow table.

    Parameters
    ----------
    spec : SweepSpec
        The loaded study (plain data).
    indices : list of int
        Sample indices, in the order of the rows.

    Returns
    -------
    pyarrow.Table
        One row per sample, schema :func:`result_schema`.  A sample whose values the scenario
        rejects has status ``"invalid"`` and the one-line reason in ``detail``; a sample whose
        tables would not fit in this worker's memory (:func:`worker_memory_budget`) has status
        ``"failed"`` and cause ``"memory"`` and is not run; a simulation failure has status
        ``"failed"``, its cause and time.
    """
    from .runner import preferred_backend, run_batch

    budget = worker_memory_budget()
    prepared = [_prepare_sample(spec, i, budget) for i in indices]
    runnable = [p for _, p in prepared if not isinstance(p, tuple)]
    # one core per worker: its SIMD lanes (runner.batch.preferred_backend)
    summaries = iter(run_batch(runnable, backend=preferred_backend("serial"), workers=1))
    rows = []
    for i, (seed, prep) in zip(indices, prepared):
        row = _base_row(spec, i, seed)
        if isinstance(prep, tuple):
            rows.append(_not_run(row, *prep))
            continue
        s = next(summaries)
        f = s.failure or {}
        row.update(status=s.status, cause=f.get("cause", ""), detail=f.get("detail", ""),
                   fail_time=f.get("time", math.nan))
        row.update(s.metrics)
        rows.append(row)
    return _table(spec, rows)


def run_chunk(spec: SweepSpec, chunk: int):
    """Run the samples of chunk ``chunk`` (metrics only) and return their rows as an Arrow table.

    Parameters
    ----------
    spec : SweepSpec
        The loaded study (plain data).
    chunk : int
        Chunk index, ``0 <= chunk < spec.n_chunks``.

    Returns
    -------
    pyarrow.Table
        One row per sample, schema :func:`result_schema`, in sample order (see :func:`run_samples`).
    """
    return run_samples(spec, list(spec.chunk_range(chunk)))


def lost_rows(spec: SweepSpec, indices: list[int], detail: str):
    """Rows recording samples that could not be computed because their worker process died.

    Parameters
    ----------
    spec : SweepSpec
        The loaded study.
    indices : list of int
        The samples.
    detail : str
        Why (one line), stored in ``detail``.

    Returns
    -------
    pyarrow.Table
        Status ``"failed"``, cause ``"worker_died"``, metrics NaN.
    """
    return _table(spec, [_not_run(_base_row(spec, i, spec.sample_seed(i)), STATUS_FAILED, CAUSE_WORKER_DIED, detail)
                         for i in indices])


def worker_warmup() -> dict:
    """Load (or compile) every kernel a chunk needs in this process; returns timings."""
    from ..simulation.compiling import warmup

    return warmup()


try:  # the plugin base class only exists with distributed installed
    from distributed.diagnostics.plugin import WorkerPlugin as _WorkerPlugin
except ImportError:  # pragma: no cover
    _WorkerPlugin = object  # type: ignore[assignment,misc]


class WarmupPlugin(_WorkerPlugin):  # type: ignore[misc,valid-type]
    """Dask worker plugin: run :func:`worker_warmup` once on every worker, restarted ones included."""

    name = "auvtrack-warmup"

    async def setup(self, worker) -> None:  # noqa: D102
        import asyncio

        await asyncio.get_running_loop().run_in_executor(None, worker_warmup)


class IgnoreInterruptsPlugin(_WorkerPlugin):  # type: ignore[misc,valid-type]
    """Dask worker plugin for the workers of a cluster the command started itself: SIGINT is ignored.

    A terminal's Ctrl-C reaches every process of its process group, the local workers too; the
    command closes them itself.  Without this, a second Ctrl-C while the cluster closes interrupts
    each worker's event loop in its shutdown and prints asyncio ``CancelledError`` tracebacks.
    Never registered on a cluster the user runs (``--scheduler``): its workers keep their Ctrl-C.
    """

    name = "auvtrack-ignore-interrupts"

    def setup(self, worker) -> None:  # noqa: D102
        import signal
        import threading

        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.SIG_IGN)
