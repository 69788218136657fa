"""What a Dask worker runs for ``auvtrack sweep``: one chunk of samples -> one Arrow table.

Everything here is importable on a worker (no jitted function is ever shipped: the worker
imports :mod:`auvtrack.runner.batch`, which loads the compiled kernels from its on-disk
cache).  :func:`run_chunk` is pure: its table depends only on the study and the chunk's sample
indices, so a retried chunk (after a worker died) gives the same rows.
"""
from __future__ import annotations

import math
from typing import Any

from .sweep_schema import StudySpec

STATUS_OK, STATUS_FAILED, STATUS_INVALID = "ok", "failed", "invalid"
FIXED_COLUMNS = ("sample", "point", "replicate")
TAIL_COLUMNS = ("seed", "status", "cause", "detail", "fail_time")

__all__ = ["run_chunk", "result_schema", "WarmupPlugin", "worker_warmup", "STATUS_OK", "STATUS_FAILED",
           "STATUS_INVALID"]


def _grid_type(values: list[Any]):
    import pyarrow as pa

    if all(isinstance(v, bool) for v in values):
        return pa.bool_()
    if all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        return pa.int64()
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return pa.float64()
    return pa.string()


def result_schema(spec: StudySpec):
    """Arrow schema of the results table of ``spec`` (identical for every chunk).

    Columns: sample, point, replicate, one per varied key (grid values as typed, non-scalar
    values as JSON strings; random draws as float64), seed, status, cause, detail, fail_time and
    every metric of :data:`auvtrack.simulation.metrics.METRIC_NAMES`.
    """
    import pyarrow as pa

    from ..simulation.metrics import METRIC_NAMES

    fields = [pa.field(c, pa.int64()) for c in FIXED_COLUMNS]
    for key, vals in spec.study.grid.items():
        scalars = all(isinstance(v, (bool, int, float, str)) for v in vals)
        fields.append(pa.field(key, _grid_type(vals) if scalars else pa.string()))
    fields += [pa.field(key, pa.float64()) for key in spec.study.random]
    fields += [pa.field("seed", pa.int64()), pa.field("status", pa.string()), pa.field("cause", pa.string()),
               pa.field("detail", pa.string()), pa.field("fail_time", pa.float64())]
    fields += [pa.field(m, pa.float64()) for m in METRIC_NAMES]
    return pa.schema(fields)


def _prepare_sample(spec: StudySpec, index: int):
    """(seed, Prepared or error text) of one sample."""
    import warnings

    from ..scenario import ScenarioError, load_scenario
    from ..simulation.api import prepare

    seed, ov = spec.overrides(index)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return seed, prepare(load_scenario(spec.base, ov))
    except (ScenarioError, ValueError) as exc:
        return seed, " ".join(str(exc).split()) or type(exc).__name__


def run_chunk(spec: StudySpec, chunk: int):
    """Run the samples of chunk ``chunk`` (metrics only) and return their rows as an Arrow table.

    Parameters
    ----------
    spec : StudySpec
        The loaded study (plain data).
    chunk : int
        Chunk index, ``0 <= chunk < spec.n_chunks``.

    Returns
    -------
    pyarrow.Table
        One row per sample, schema :func:`result_schema`, in sample order.  A sample whose
        values the scenario rejects has status ``"invalid"`` and the one-line reason in
        ``detail``; a simulation failure has status ``"failed"``, its cause and time.
    """
    import pyarrow as pa

    from .batch import preferred_backend, run_batch
    from ..simulation.metrics import METRIC_NAMES

    schema = result_schema(spec)
    indices = list(spec.chunk_range(chunk))
    prepared = [_prepare_sample(spec, i) for i in indices]
    runnable = [p for _, p in prepared if not isinstance(p, str)]
    # one core per worker: its SIMD lanes (runner.batch.preferred_backend)
    summaries = iter(run_batch(runnable, backend=preferred_backend("serial"), workers=1))
    cols: dict[str, list] = {f.name: [] for f in schema}
    for i, (seed, prep) in zip(indices, prepared):
        point, rep, _ = spec.sample(i)
        row: dict[str, Any] = {"sample": i, "point": point, "replicate": rep, **spec.column_values(i), "seed": seed}
        if isinstance(prep, str):
            row.update(status=STATUS_INVALID, cause="invalid", detail=prep, fail_time=math.nan)
            row.update({m: math.nan for m in METRIC_NAMES})
        else:
            s = next(summaries)
            f = s.failure or {}
            row.update(status=s.status, cause=f.get("cause", ""), detail=f.get("detail", ""),
                       fail_time=f.get("time", math.nan))
            row.update(s.metrics)
        for name in cols:
            cols[name].append(row[name])
    return pa.Table.from_pydict(cols, schema=schema)


def worker_warmup() -> dict:
    """Load (or compile) every kernel a chunk needs in this process; returns timings."""
    from .bench import warmup

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
