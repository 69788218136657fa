"""``auvtrack sweep``: parameter sweeps and Monte Carlo studies on Dask distributed.

The study (:mod:`auvtrack.batch.sweep_spec`) is cut into chunks of ``chunk_size`` samples;
each chunk is one Dask task (:func:`auvtrack.batch.sweep_worker.run_chunk`) that runs its
samples through the batch runner and returns an Arrow table.  The client writes each completed
chunk as ``chunks/chunk-NNNNNN.parquet`` atomically (temporary file + rename), so

* ``resume=True`` skips every chunk whose file exists and finishes with each sample once;
* a worker that dies mid-chunk costs nothing: Dask reruns the task, and the task is pure;
* a sample's row depends only on its index and the study, never on chunking or worker.

At the end every chunk is combined into ``results.parquet`` (streamed, memory flat in the
number of chunks) and a summary is written to ``summary.json`` and ``summary.md``.
"""
from __future__ import annotations

import json
import logging
import math
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from .._atomic import atomic_file, atomic_write
from .dask_wait import ClusterLost
from .sweep_spec import StudyError, StudySpec, load_study

MANIFEST = "study.json"
CHUNK_DIR = "chunks"
RESULTS = "results.parquet"
QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)

__all__ = ["run_sweep", "SweepOutcome", "chunk_path", "read_results", "summarize", "MANIFEST", "RESULTS"]


@dataclass(frozen=True)
class SweepOutcome:
    """What :func:`run_sweep` did.

    Attributes
    ----------
    out : Path
        Output folder.
    complete : bool
        Every chunk has its file (False after ``max_chunks`` stopped the sweep early).
    chunks_run, chunks_skipped : int
        Chunks computed now, chunks found on disk (``resume``).
    summary : dict or None
        The summary (only when complete).
    seconds : float
        Wall time of the computation (excluding cluster start-up and warm-up).
    """

    out: Path
    complete: bool
    chunks_run: int
    chunks_skipped: int
    summary: dict | None
    seconds: float


def chunk_path(out: Path, chunk: int) -> Path:
    """File of chunk ``chunk`` under ``out``."""
    return Path(out) / CHUNK_DIR / f"chunk-{chunk:06d}.parquet"


def _write_atomic_table(table, path: Path) -> None:
    import pyarrow.parquet as pq

    with atomic_file(path) as fh:  # unique, exclusively created temporary name, then rename
        pq.write_table(table, fh)


def _write_atomic_text(text: str, path: Path) -> None:
    atomic_write(path, text)


def _manifest(spec: StudySpec) -> dict:
    from .. import __version__
    from ..jit import source_hash

    return {"fingerprint": spec.fingerprint(), "name": spec.study.name, "source": spec.source,
            "n_samples": spec.n_samples, "n_chunks": spec.n_chunks, "chunk_size": spec.study.chunk_size,
            "study": spec.study.model_dump(mode="json"), "auvtrack_version": __version__,
            "source_hash": source_hash()}


def _prepare_out(spec: StudySpec, out: Path, resume: bool) -> set[int]:
    """Create or check the output folder; return the chunks already done."""
    (out / CHUNK_DIR).mkdir(parents=True, exist_ok=True)
    man_path = out / MANIFEST
    fp = spec.fingerprint()
    done = {c for c in range(spec.n_chunks) if chunk_path(out, c).exists()}
    if man_path.exists():
        try:
            old = json.loads(man_path.read_text())
        except (OSError, ValueError):
            old = {}
        if old.get("fingerprint") != fp:
            raise StudyError(f"--out: {out} holds a different study ({old.get('source', '?')}); "
                             "choose another folder")
        if done and not resume:
            raise StudyError(f"--out: {out} already holds {len(done)} of {spec.n_chunks} chunks of this study; "
                             "pass --resume to finish it or choose another folder")
    elif done:
        raise StudyError(f"--out: {out} holds chunk files but no {MANIFEST}; choose another folder")
    _write_atomic_text(json.dumps(_manifest(spec), indent=2), man_path)
    for stale in (out / CHUNK_DIR).glob(".chunk-*.tmp"):  # left by an interrupted write
        stale.unlink(missing_ok=True)
    return done


DEFAULT_WORKER_MEMORY = "1GiB"


def parse_memory(value: str | int) -> int:
    """Bytes of a memory size such as ``"1GiB"``, ``"512MB"`` or an integer number of bytes.

    Parameters
    ----------
    value : str or int
        The size.

    Returns
    -------
    int
        Bytes, >= 64 MiB (a worker needs about 300 MB for Python, NumPy, Numba and the kernels).

    Raises
    ------
    StudyError
        One line naming ``--worker-memory`` for anything else.
    """
    from dask.utils import parse_bytes

    try:
        n = value if isinstance(value, int) and not isinstance(value, bool) else parse_bytes(str(value))
    except (ValueError, TypeError):
        raise StudyError(f"--worker-memory: must be a size such as 2GiB or 512MB (got {value!r})") from None
    if n < 64 * 2 ** 20:
        raise StudyError(f"--worker-memory: must be >= 64MiB (got {value!r})")
    return int(n)


def _client(workers: int | None, scheduler: str | None, memory_limit: str | int):
    """(client, cluster or None): a LocalCluster of ``workers`` processes or an existing scheduler."""
    import dask
    from dask.distributed import Client, LocalCluster

    if scheduler:
        return Client(scheduler), None
    from .runner import default_workers

    n = default_workers() if workers is None else workers
    # a task whose worker dies is not retried on other workers (it would kill them too): its
    # chunk is split into single samples instead (_compute)
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                               memory_limit=parse_memory(memory_limit), env={"NUMBA_NUM_THREADS": "1"},
                               silence_logs=logging.ERROR)
    return Client(cluster), cluster


def run_sweep(study: str | Path | StudySpec, out: str | Path, *, workers: int | None = None,
              scheduler: str | None = None, resume: bool = False, max_chunks: int | None = None,
              progress: bool = True, client: Any = None, memory_limit: str | int = DEFAULT_WORKER_MEMORY,
              on_chunk: Callable[[int, Any], None] | None = None) -> SweepOutcome:
    """Run (or resume) a sweep on Dask and write its results under ``out``.

    Parameters
    ----------
    study : str, Path or StudySpec
        Study file or a loaded study.
    out : str or Path
        Output folder: ``study.json``, ``chunks/``, ``results.parquet``, ``summary.{json,md}``.
    workers : int, optional
        Worker processes of the LocalCluster started here (default: one per core).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:port``); no cluster is started.
    resume : bool, optional
        Continue a sweep in ``out``: chunks whose file exists are not run again.
    max_chunks : int, optional
        Stop after this many chunks have been written (the rest stay to ``resume``).
    progress : bool, optional
        Show a tqdm bar (samples done, rate, ETA).
    client : distributed.Client, optional
        Use this client (its cluster is left running); overrides ``workers``/``scheduler``.
    memory_limit : str or int, optional
        Per-worker memory limit of the LocalCluster (``"1GiB"``, ``"512MB"``, bytes).  A sample
        whose tables would not fit is recorded as failed (cause ``memory``) without running; a
        sample whose worker still dies is recorded as failed (cause ``worker_died``).
    on_chunk : callable, optional
        ``on_chunk(chunks_written_now, client)`` after each chunk file is written (a hook for
        tests and monitoring).

    Returns
    -------
    SweepOutcome

    Raises
    ------
    StudyError
        Invalid study file or an output folder holding another study.
    """
    spec = study if isinstance(study, StudySpec) else load_study(study)
    if workers is not None and workers < 1:
        raise StudyError(f"--workers: must be >= 1 (got {workers})")
    if max_chunks is not None and max_chunks < 1:
        raise StudyError(f"max_chunks: must be >= 1 (got {max_chunks})")
    parse_memory(memory_limit)
    out = Path(out)
    done = _prepare_out(spec, out, resume)
    todo = [c for c in range(spec.n_chunks) if c not in done]
    own = client is None
    cluster = None
    seconds = 0.0
    written = 0
    if todo:
        if own:
            client, cluster = _client(workers, scheduler, memory_limit)
        try:
            written, seconds = _compute(spec, out, todo, client, max_chunks, progress, on_chunk,
                                        n_done=sum(len(spec.chunk_range(c)) for c in done))
        except ClusterLost as exc:
            kept = sum(1 for c in range(spec.n_chunks) if chunk_path(out, c).exists())
            raise StudyError(f"{exc}; {kept} of {spec.n_chunks} chunks are kept in {out}: "
                             "finish with --resume once the cluster has workers") from None
        finally:
            if own:
                client.close()
                if cluster is not None:
                    cluster.close()
    complete = all(chunk_path(out, c).exists() for c in range(spec.n_chunks))
    summary = None
    if complete:
        combine(spec, out)
        summary = summarize(out / RESULTS, spec)
        summary["seconds"] = seconds
        _write_atomic_text(json.dumps(summary, indent=2, default=_json_default), out / "summary.json")
        _write_atomic_text(summary_markdown(summary), out / "summary.md")
    return SweepOutcome(out, complete, written, len(done), summary, seconds)


def _compute(spec: StudySpec, out: Path, todo: list[int], client, max_chunks: int | None, progress: bool,
             on_chunk, n_done: int) -> tuple[int, float]:
    from tqdm.auto import tqdm

    from .dask_wait import completed
    from .sweep_worker import WarmupPlugin, run_chunk

    client.register_plugin(WarmupPlugin(), name=WarmupPlugin.name)
    token = f"{spec.fingerprint()[:12]}-{uuid.uuid4().hex[:8]}"  # fresh keys: never reuse cancelled tasks
    t0 = time.perf_counter()
    futures = [client.submit(run_chunk, spec, c, key=f"auvtrack-sweep-{token}-{c}", retries=1) for c in todo]
    chunk_of = {f.key: c for f, c in zip(futures, todo)}
    written = 0
    bar = tqdm(total=spec.n_samples, initial=n_done, unit="sample", desc=spec.study.name, disable=not progress,
               smoothing=0.1)
    try:
        for fut in completed(futures, client, what="running the sweep's chunks"):
            c = chunk_of[fut.key]
            table = _chunk_table(spec, c, fut, client, token)
            path = chunk_path(out, c)
            if not path.exists():  # idempotent: a chunk is written once
                _write_atomic_table(table, path)
            fut.release()
            written += 1
            bar.update(table.num_rows)
            if on_chunk is not None:
                on_chunk(written, client)
            if max_chunks is not None and written >= max_chunks:
                break
    finally:
        bar.close()
        pending = [f for f in futures if not f.done()]
        if pending:
            client.cancel(pending)
    return written, time.perf_counter() - t0


def _chunk_table(spec: StudySpec, chunk: int, fut, client, token: str, attempts: int = 2):
    """The table of a finished chunk task; when its worker died, run its samples one at a time.

    A worker that dies fails every task queued on it, so a sample is blamed only when it kills a
    worker ``attempts`` times running on its own: it is then recorded as failed (cause
    ``worker_died``), and one memory-hungry sample costs its own row, never the sweep.
    """
    from distributed import KilledWorker

    from .dask_wait import result
    from .sweep_worker import lost_rows, run_samples

    try:
        return result(fut, client, what=f"running chunk {chunk}")
    except KilledWorker:
        pass
    import pyarrow as pa

    tables = []
    for i in spec.chunk_range(chunk):
        for attempt in range(attempts):
            single = client.submit(run_samples, spec, [i], key=f"auvtrack-sample-{token}-{i}-{attempt}", retries=0)
            try:
                tables.append(result(single, client, what=f"running sample {i} alone"))
                break
            except KilledWorker as exc:
                reason = " ".join(str(exc).split())[:200]
            finally:
                single.release()
        else:
            tables.append(lost_rows(spec, [i], f"the worker process died running this sample alone, {attempts} times "
                                               f"(out of memory? see --worker-memory): {reason}"))
    return pa.concat_tables(tables)


def combine(spec: StudySpec, out: Path) -> Path:
    """Stream every chunk file, in chunk order, into ``out/results.parquet`` (atomic)."""
    import pyarrow.parquet as pq

    from .sweep_worker import result_schema

    schema = result_schema(spec)
    path = out / RESULTS
    with atomic_file(path) as fh, pq.ParquetWriter(fh, schema) as writer:
        for c in range(spec.n_chunks):
            writer.write_table(pq.read_table(chunk_path(out, c), schema=schema))
    return path


def read_results(out: str | Path):
    """The combined results of a finished sweep as a pandas DataFrame (one row per sample)."""
    import pandas as pd

    return pd.read_parquet(Path(out) / RESULTS)


def _json_default(x: Any) -> Any:
    return float(x) if isinstance(x, (int, float)) else str(x)


def _finite_or_none(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def group_keys(spec: StudySpec) -> list[str]:
    """Grid keys whose values are names (``controller.kind``, ``vehicle.preset``...): one summary each.

    Pooling the metrics of different controllers or vehicles gives quantiles of neither, so the
    summary is grouped by every grid key whose values are all strings.
    """
    return [k for k, vals in spec.study.grid.items() if vals and all(isinstance(v, str) for v in vals)]


def _stats(status, cause, columns: dict, mask) -> dict:
    """Counts, causes and per-metric quantiles (over the ok samples) of the rows in ``mask``."""
    import numpy as np

    st, ca = status[mask], cause[mask]
    counts = {str(k): int(v) for k, v in zip(*np.unique(st, return_counts=True))}
    causes = {str(k): int(v) for k, v in zip(*np.unique(ca[ca != None], return_counts=True)) if k}  # noqa: E711
    ok = st == "ok"
    metrics: dict[str, dict] = {}
    for name, col in columns.items():
        col = col[mask][ok]
        fin = col[np.isfinite(col)]
        entry: dict[str, Any] = {"n_finite": int(fin.size), "n_inf": int(np.isinf(col).sum())}
        if fin.size:
            entry["mean"] = float(fin.mean())
            entry["min"] = float(fin.min())
            for q, v in zip(QUANTILES, np.quantile(fin, QUANTILES)):
                entry[f"q{int(round(q * 100)):02d}"] = float(v)
            entry["max"] = float(fin.max())
        metrics[name] = entry
    n = int(mask.sum())
    return {"samples": n, "counts": counts, "failure_rate": counts.get("failed", 0) / n if n else math.nan,
            "invalid_rate": counts.get("invalid", 0) / n if n else math.nan, "causes": causes, "metrics": metrics}


def summarize(results: Path, spec: StudySpec) -> dict:
    """Counts, failure rate, causes and per-metric quantiles (over "ok" samples) of a results file.

    The top level pools every sample; ``groups`` repeats the statistics for each combination of
    the :func:`group_keys` values (e.g. one entry per controller), in grid order.
    """
    import itertools

    import numpy as np
    import pyarrow.parquet as pq

    from ..metrics import METRIC_NAMES

    keys = group_keys(spec)
    table = pq.read_table(results, columns=["status", "cause", *keys, *METRIC_NAMES])
    status = table.column("status").to_numpy(zero_copy_only=False)
    cause = table.column("cause").to_numpy(zero_copy_only=False)
    columns = {m: table.column(m).to_numpy() for m in METRIC_NAMES}
    out = {"study": spec.study.name, "source": spec.source,
           **_stats(status, cause, columns, np.ones(len(status), dtype=bool)),
           "varied": list(spec.varied), "quantile_levels": list(QUANTILES), "group_keys": keys, "groups": []}
    values = {k: table.column(k).to_numpy(zero_copy_only=False) for k in keys}
    for combo in itertools.product(*(spec.study.grid[k] for k in keys)) if keys else ():
        mask = np.logical_and.reduce([values[k] == v for k, v in zip(keys, combo)])
        out["groups"].append({"key": dict(zip(keys, combo)), **_stats(status, cause, columns, mask)})
    return out


def summary_markdown(s: dict) -> str:
    """Render a summary (from :func:`summarize`) as Markdown: one quantile table per group."""
    lines = [f"# Sweep {s['study']}", "", f"Study file: `{s['source']}`; varied: "
             f"{', '.join(f'`{k}`' for k in s['varied']) or 'nothing (replicates only)'}.", "",
             f"Samples: {s['samples']} — " + _counts_text(s), ""]
    if s["causes"]:
        lines += ["Failure causes: " + ", ".join(f"{k} ({v})" for k, v in sorted(s["causes"].items())) + ".", ""]
    if "seconds" in s and s["seconds"]:
        lines += [f"Computed in {s['seconds']:.1f} s.", ""]
    groups = s.get("groups") or []
    if not groups:
        return "\n".join(lines + _quantile_table(s, s["quantile_levels"])) + "\n"
    lines += [f"Grouped by {', '.join(f'`{k}`' for k in s['group_keys'])}: the samples of different "
              "groups are never pooled.", ""]
    for g in groups:
        name = ", ".join(f"{k} = {v}" for k, v in g["key"].items())
        lines += [f"## {name}", "", f"Samples: {g['samples']} — " + _counts_text(g), ""]
        if g["causes"]:
            lines += ["Failure causes: " + ", ".join(f"{k} ({v})" for k, v in sorted(g["causes"].items())) + ".", ""]
        lines += _quantile_table(g, s["quantile_levels"]) + [""]
    return "\n".join(lines).rstrip("\n") + "\n"


def _counts_text(s: dict) -> str:
    return (", ".join(f"{k}: {v}" for k, v in sorted(s["counts"].items())) + f"; failure rate {s['failure_rate']:.2%}"
            + (f", invalid {s['invalid_rate']:.2%}" if s["invalid_rate"] else "") + ".")


def _quantile_table(s: dict, levels) -> list[str]:
    qs = [f"q{int(round(q * 100)):02d}" for q in levels]
    lines = ["Metric quantiles over the ok samples (finite values; `inf` = never settled):", "",
             "| metric | n | inf | mean | " + " | ".join(qs) + " |", "|---" * (4 + len(qs)) + "|"]
    for name, e in s["metrics"].items():
        vals = [f"{e[k]:.4g}" if k in e else "–" for k in ["mean"] + qs]
        lines.append(f"| {name} | {e['n_finite']} | {e['n_inf']} | " + " | ".join(vals) + " |")
    return lines
