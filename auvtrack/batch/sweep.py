"""``auvtrack sweep``: parameter sweeps and Monte Carlo studies on Dask distributed.

The study (:mod:`auvtrack.batch.sweep_spec`) is cut into chunks of ``chunk_size`` samples;
:class:`SweepJob` hands it to the chunk executor (:mod:`auvtrack.batch.executor`): each chunk is
one Dask task (:func:`auvtrack.batch.sweep_worker.run_samples`) that runs its samples through
the batch runner and returns an Arrow table, written by the client as
``chunks/chunk-NNNNNN.parquet`` atomically with the sweep's fingerprint and its content hash, so

* ``resume=True`` keeps every chunk that passes verification, recomputes the others (each
  named on one line) and finishes with each sample exactly once;
* a worker that dies mid-chunk costs nothing: its samples run again, one at a time;
* a sample's row depends only on its index and the study, never on chunking or worker.

At the end every chunk is combined into ``results.parquet`` (streamed, memory flat in the
number of chunks) and a summary is written to ``summary.json`` and ``summary.md``.
"""
from __future__ import annotations

import json
import logging
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from .._atomic import atomic_write
from .chunk_files import chunk_path
from .executor import ChunkJob, check_workers, execute_chunks
from .sweep_spec import StudyError, SweepSpec, load_study

MANIFEST = "study.json"
RESULTS = "results.parquet"
QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)

__all__ = ["run_sweep", "SweepOutcome", "SweepJob", "chunk_path", "read_results", "summarize", "counts_text", "MANIFEST", "RESULTS"]


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
        Chunks computed now, chunks found on disk and verified (``resume``).
    summary : dict or None
        The summary (only when complete).
    seconds : float
        Wall time of the computation (excluding cluster start-up and warm-up).
    chunks_redone : tuple of int
        Chunks found on disk that failed verification and were computed again.
    """

    out: Path
    complete: bool
    chunks_run: int
    chunks_skipped: int
    summary: dict | None
    seconds: float
    chunks_redone: tuple[int, ...] = ()


class SweepJob(ChunkJob):
    """A sweep as a job of the chunk executor: samples in chunks of ``chunk_size``, run on Dask.

    Parameters
    ----------
    spec : SweepSpec
        The loaded study.
    """

    kind = "sweep"
    manifest_name = MANIFEST
    results_name = RESULTS
    id_column = "sample"
    unit = "sample"
    lost_hint = " (out of memory? see --worker-memory)"
    error = StudyError

    def __init__(self, spec: SweepSpec) -> None:
        self.spec = spec

    @property
    def label(self) -> str:
        """The study's name."""
        return self.spec.study.name

    @property
    def n_chunks(self) -> int:
        """Chunks of the study."""
        return self.spec.n_chunks

    @property
    def n_rows(self) -> int:
        """Samples of the study."""
        return self.spec.n_samples

    def chunk_ids(self, chunk: int) -> range:
        """Sample indices of chunk ``chunk``."""
        return self.spec.chunk_range(chunk)

    def definition(self) -> dict:
        """The study's fingerprint (file contents and base scenario)."""
        return {"study": self.spec.fingerprint()}

    def schema(self):
        """:func:`auvtrack.batch.sweep_worker.result_schema` of the study."""
        from .sweep_worker import result_schema

        return result_schema(self.spec)

    def manifest(self) -> dict:
        """Name, source, sizes and the study itself."""
        spec = self.spec
        return {"name": spec.study.name, "source": spec.source, "study_fingerprint": spec.fingerprint(),
                "n_samples": spec.n_samples, "chunk_size": spec.study.chunk_size,
                "study": spec.study.model_dump(mode="json")}

    def describe(self, manifest: dict) -> str:
        """The study file another sweep's manifest names."""
        return f"study {manifest.get('name', '?')!r} from {manifest.get('source', '?')}"

    def format1_fingerprint(self) -> str:
        """The study's fingerprint, which format-1 manifests record."""
        return self.spec.fingerprint()

    def run_local(self, ids: range, workers: int | None):
        """The samples ``ids`` run in this process (one core, as on a worker)."""
        from .sweep_worker import run_samples

        return run_samples(self.spec, list(ids))

    def dask_call(self, ids: range) -> tuple:
        """:func:`auvtrack.batch.sweep_worker.run_samples` of the study and the samples."""
        from .sweep_worker import run_samples

        return run_samples, (self.spec, list(ids)), {}

    def lost_rows(self, ids: range, detail: str):
        """:func:`auvtrack.batch.sweep_worker.lost_rows` of the samples."""
        from .sweep_worker import lost_rows

        return lost_rows(self.spec, list(ids), detail)


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
        from .scheduler import SchedulerError, connect_scheduler

        try:
            return connect_scheduler(scheduler), None
        except SchedulerError as exc:
            raise StudyError(str(exc)) from None
    from .runner import default_workers

    n = default_workers() if workers is None else workers
    # a task whose worker dies is not retried on other workers (it would kill them too): its
    # chunk is split into single samples instead (auvtrack.batch.executor)
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                               memory_limit=parse_memory(memory_limit), env={"NUMBA_NUM_THREADS": "1"},
                               silence_logs=logging.ERROR)
    client = Client(cluster)
    from .sweep_worker import IgnoreInterruptsPlugin

    client.register_plugin(IgnoreInterruptsPlugin(), name=IgnoreInterruptsPlugin.name)  # Ctrl-C is the client's
    return client, cluster


KERNEL_KEYS = ("controller", "plant")
"""Sections whose grid values may change a sample's kernel (the law, the plant)."""


def study_kernels(spec: SweepSpec) -> list:
    """One prepared sample per kernel the study's grid may use, for compiling them before the workers start.

    The built-in kernels are what a worker's warm-up loads; a study may fly others (a ``policy``, a
    plug-in law, a 6-DOF preset), which each worker would otherwise compile on its first sample.
    One grid point is prepared per distinct combination of the grid's ``controller.*`` and
    ``plant.*`` values (its first sample that the scenario accepts).

    Parameters
    ----------
    spec : SweepSpec
        The study.

    Returns
    -------
    list of Prepared
        The prepared samples (their ``key`` is the kernel), one per combination that prepares.
    """
    from ..scenario import load_scenario
    from ..simulation.pipeline import prepare

    keys = [k for k in spec.study.grid if k.split(".", 1)[0] in KERNEL_KEYS]
    seen, preps = set(), []
    for point in range(spec.study.n_points):
        first = point * spec.study.samples
        combo = tuple(json.dumps(spec.sample(first)[2][k], sort_keys=True, default=str) for k in keys)
        if combo in seen:
            continue
        for index in range(first, first + spec.study.samples):
            try:
                preps.append(prepare(load_scenario(spec.base, spec.overrides(index)[1])))
            except ValueError:  # ScenarioError is one
                continue  # an invalid draw: the next replicate of the point
            seen.add(combo)
            break
    return preps


def run_sweep(study: str | Path | SweepSpec, out: str | Path, *, workers: int | None = None,
              scheduler: str | None = None, resume: bool = False, max_chunks: int | None = None,
              progress: bool = True, client: Any = None, memory_limit: str | int = DEFAULT_WORKER_MEMORY,
              on_chunk: Callable[[int, Any], None] | None = None) -> SweepOutcome:
    """Run (or resume) a sweep on Dask and write its results under ``out``.

    Parameters
    ----------
    study : str, Path or SweepSpec
        Study file or a loaded study.
    out : str or Path
        Output folder: ``study.json``, ``chunks/``, ``results.parquet``, ``summary.{json,md}``.
    workers : int, optional
        Worker processes of the LocalCluster started here (default: one per core).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:port``); no cluster is started.
    resume : bool, optional
        Continue a sweep in ``out``: chunks whose file passes verification (this sweep's
        fingerprint, this chunk, its content hash) are kept; the others are named on one line
        and run again.
    max_chunks : int, optional
        Stop after this many chunks have been written (the rest stay to ``resume``).
    progress : bool, optional
        Show a tqdm bar (samples done, rate, ETA) and, when kernels compile first, their notice and
        bar; without it nothing is printed.
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
        Whether the sweep is complete (then with its summary), chunks run, kept and recomputed,
        and the time the chunks took.

    Raises
    ------
    StudyError
        Invalid study file, an output folder holding another study or other files, a
        ``--scheduler`` address where no Dask scheduler answers, or a cluster that lost every worker.
    """
    spec = study if isinstance(study, SweepSpec) else load_study(study)
    check_workers(workers, StudyError)
    parse_memory(memory_limit)
    cluster = None if client is not None or scheduler else (lambda: _client(workers, None, memory_limit))
    if cluster is not None:  # local workers load the kernels from the disk cache: compile them here, visibly
        from ..simulation.compiling import ensure_compiled, warmup

        # what each worker's warm-up loads (sweep_worker.worker_warmup), then the study's own kernels (a
        # policy, a plug-in); without progress, silently
        quiet = None if progress else (lambda text: None)
        warmup(progress=progress, notice=quiet)
        ensure_compiled(study_kernels(spec), progress=progress, notice=quiet)
    res = execute_chunks(SweepJob(spec), out, resume=resume, client=client, scheduler=scheduler,
                         start_cluster=cluster, max_chunks=max_chunks, progress=progress, on_chunk=on_chunk)
    summary = None
    if res.complete:
        summary = summarize(res.out / RESULTS, spec)
        summary["seconds"] = res.seconds
        atomic_write(res.out / "summary.json", json.dumps(summary, indent=2, default=_json_default))
        atomic_write(res.out / "summary.md", summary_markdown(summary))
    return SweepOutcome(res.out, res.complete, res.chunks_run, res.chunks_kept, summary, res.seconds,
                        res.chunks_redone)


def read_results(out: str | Path):
    """The combined results of a finished sweep as a pandas DataFrame (one row per sample)."""
    import pandas as pd

    return pd.read_parquet(Path(out) / RESULTS)


def _json_default(x: Any) -> Any:
    return float(x) if isinstance(x, (int, float)) else str(x)


def _finite_or_none(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def group_keys(spec: SweepSpec) -> list[str]:
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


def summarize(results: Path, spec: SweepSpec) -> dict:
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
             f"Samples: {s['samples']} — " + counts_text(s), ""]
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
        lines += [f"## {name}", "", f"Samples: {g['samples']} — " + counts_text(g), ""]
        if g["causes"]:
            lines += ["Failure causes: " + ", ".join(f"{k} ({v})" for k, v in sorted(g["causes"].items())) + ".", ""]
        lines += _quantile_table(g, s["quantile_levels"]) + [""]
    return "\n".join(lines).rstrip("\n") + "\n"


def counts_text(s: dict) -> str:
    """One plain sentence of a summary's (or a group's) status counts and failure rate."""
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
